//! Chi-square goodness of fit of every sampling routine against its density (the method of
//! pbrt-v4's `bsdfs_test.cpp` and Mitsuba 3's `chi2.py`), and the consistency of sample
//! weights with eval / pdf.
//!
//! Settings (see `common::Chi2`): 400k samples per test, 40 x 80 equal-area cells in
//! (cos theta, phi), densities integrated with 16 x 16 Gauss-Legendre nodes per cell (6 x 6 was too
//! coarse where a rough dielectric lobe ends abruptly: it failed correct samplers), cells with
//! fewer than 5 expected samples pooled. The overall significance level is 0.01, Sidak-corrected
//! over the tests of this file.

mod common;

use common::{Chi2, dir, sidak};
use glam::{Vec2, Vec3};
use tessera::bsdf::{Bsdf, Conductor, ConductorFresnel, Dielectric, Diffuse, Ggx, Pbr, Plastic, PlasticTables};
use tessera::color::Rgb;

/// Number of chi-square tests in this file (for the Sidak correction).
const TESTS: usize = 72;

fn conductor(au: f32, av: f32) -> Bsdf<'static> {
    Bsdf::Conductor(Conductor {
        ggx: Some(Ggx::new(au, av)),
        fresnel: ConductorFresnel::Complex {
            eta: Rgb::new(1.6575, 0.880405, 0.521244),
            k: Rgb::new(9.22381, 6.2695, 4.837),
        },
        specular_reflectance: Rgb::ONE,
    })
}

fn dielectric(eta: f32, au: f32, av: f32) -> Bsdf<'static> {
    Bsdf::Dielectric(Dielectric {
        eta,
        ggx: Some(Ggx::new(au, av)),
        specular_reflectance: Rgb::ONE,
        specular_transmittance: Rgb::ONE,
    })
}

/// Plastic tables live for the whole test run.
fn tables(eta: f32, alphas: &[f32]) -> &'static PlasticTables {
    Box::leak(Box::new(PlasticTables::new(eta, alphas)))
}

/// The configurations under test, with a name each.
fn configurations() -> Vec<(String, Bsdf<'static>)> {
    let plastic_tables = tables(1.49, &[0.2]);
    let pbr_tables = tables(1.5, &PlasticTables::alpha_grid());
    let mut v: Vec<(String, Bsdf<'static>)> = vec![
        ("diffuse".into(), Bsdf::Diffuse(Diffuse { reflectance: Rgb::new(0.7, 0.5, 0.3) })),
        ("conductor a=0.2".into(), conductor(0.2, 0.2)),
        ("conductor a=0.6".into(), conductor(0.6, 0.6)),
        ("conductor au=0.1 av=0.4".into(), conductor(0.1, 0.4)),
        ("conductor au=0.5 av=0.15".into(), conductor(0.5, 0.15)),
        ("dielectric eta=1.5 a=0.3".into(), dielectric(1.5, 0.3, 0.3)),
        ("dielectric eta=1.5 au=0.15 av=0.5".into(), dielectric(1.5, 0.15, 0.5)),
        ("dielectric eta=0.75 a=0.4".into(), dielectric(0.75, 0.4, 0.4)),
        (
            "plastic a=0.2".into(),
            Bsdf::Plastic(Plastic {
                diffuse_reflectance: Rgb::new(0.6, 0.3, 0.1),
                specular_reflectance: Rgb::ONE,
                alpha: 0.2,
                tables: plastic_tables,
            }),
        ),
    ];
    v.push((
        "pbr anisotropic metallic=0.7 alpha=(0.5, 0.08) occlusion=0.5".into(),
        Bsdf::Pbr(Pbr {
            base_color: Rgb::new(0.8, 0.6, 0.2),
            metallic: 0.7,
            alpha_u: 0.5,
            alpha_v: 0.08,
            occlusion: 0.5,
            tables: pbr_tables,
        }),
    ));
    for metallic in [0.0, 0.4, 1.0] {
        v.push((
            format!("pbr metallic={metallic} roughness=0.6"),
            Bsdf::Pbr(Pbr::isotropic(Rgb::new(0.8, 0.6, 0.2), metallic, 0.36, pbr_tables)),
        ));
    }
    v
}

/// Viewing directions: near normal, oblique, grazing; for glass also from inside.
fn viewing_directions(two_sided: bool) -> Vec<Vec3> {
    let mut v = vec![dir(10.0, 30.0), dir(50.0, 200.0), dir(80.0, 110.0)];
    if two_sided {
        v.extend([dir(150.0, 60.0), dir(100.0, 300.0)]);
    }
    v
}

#[test]
fn bsdf_sampling_matches_pdf_chi2() {
    let level = sidak(TESTS);
    let mut failures = Vec::new();
    let mut count = 0;
    for (name, bsdf) in configurations() {
        for wo in viewing_directions(bsdf.is_two_sided_by_nature()) {
            count += 1;
            let outcome = Chi2::default().run(
                count as u64,
                |u1, u2| bsdf.sample(wo, u1, u2).filter(|s| !s.delta).map(|s| s.wi),
                |wi| bsdf.pdf(wo, wi),
            );
            let ok = outcome.p_value > level && outcome.in_zero_cells == 0;
            // The density integrates to the probability that a sample is produced.
            let valid_fraction = outcome.valid as f64 / 400_000.0;
            let mass_ok = (outcome.integral - valid_fraction).abs() < 0.01;
            if !ok || !mass_ok {
                failures.push(format!("{name}, wo = {wo}: {outcome:?} (valid fraction {valid_fraction:.4})"));
            }
        }
    }
    assert!(count <= TESTS, "raise TESTS to {count}");
    assert!(failures.is_empty(), "chi-square failures at level {level:.2e}:\n{}", failures.join("\n"));
}

#[test]
fn ggx_visible_normal_sampling_matches_pdf_chi2() {
    let level = sidak(TESTS);
    for (au, av) in [(0.3, 0.3), (0.1, 0.6), (0.8, 0.25)] {
        let ggx = Ggx::new(au, av);
        for w in [dir(5.0, 0.0), dir(60.0, 45.0), dir(85.0, 250.0)] {
            let outcome = Chi2::default().run(7, |_, u| Some(ggx.sample_visible(w, u)), |m| ggx.pdf_visible(w, m));
            assert!(
                outcome.p_value > level && outcome.in_zero_cells == 0 && (outcome.integral - 1.0).abs() < 0.01,
                "GGX ({au}, {av}) from {w}: {outcome:?}"
            );
        }
    }
}

#[test]
fn cosine_hemisphere_sampling_matches_pdf_chi2() {
    use tessera::sampling::warp;
    let outcome =
        Chi2::default().run(3, |_, u| Some(warp::square_to_cosine_hemisphere(u)), warp::cosine_hemisphere_pdf);
    assert!(outcome.p_value > sidak(TESTS) && (outcome.integral - 1.0).abs() < 1e-3, "{outcome:?}");
    let outcome = Chi2::default().run(4, |_, u| Some(warp::square_to_uniform_sphere(u)), |_| warp::UNIFORM_SPHERE_PDF);
    assert!(outcome.p_value > sidak(TESTS) && (outcome.integral - 1.0).abs() < 1e-3, "{outcome:?}");
}

#[test]
fn bsdf_sample_weight_is_eval_over_pdf() {
    // For every non-delta sample: weight = eval / pdf and pdf(wo, wi) equals the sample's pdf.
    for (name, bsdf) in configurations() {
        for wo in viewing_directions(bsdf.is_two_sided_by_nature()) {
            for i in 0..20_000u32 {
                let mut s = tessera::sampling::Sampler::new(99, 1, i);
                let (u1, u2) = (s.next_1d(), s.next_2d());
                let Some(bs) = bsdf.sample(wo, u1, u2) else { continue };
                assert!(!bs.delta);
                let pdf = bsdf.pdf(wo, bs.wi);
                let f = bsdf.eval(wo, bs.wi);
                assert!(
                    (pdf - bs.pdf).abs() <= 1e-3 * pdf.max(1e-3),
                    "{name} {wo} -> {}: pdf {pdf} vs {}",
                    bs.wi,
                    bs.pdf
                );
                let expected = f / pdf;
                let diff = (expected - bs.weight).abs().max_element();
                assert!(
                    diff <= 2e-3 * expected.max_element().max(1e-2),
                    "{name} {wo} -> {}: weight {} vs eval/pdf {expected}",
                    bs.wi,
                    bs.weight
                );
                assert!(bs.weight.is_finite() && bs.weight.min_element() >= 0.0);
            }
        }
    }
}

#[test]
fn smooth_dielectric_chooses_reflection_with_fresnel_probability() {
    use tessera::bsdf::fresnel::fresnel_dielectric;
    let glass = Bsdf::Dielectric(Dielectric {
        eta: 1.5,
        ggx: None,
        specular_reflectance: Rgb::ONE,
        specular_transmittance: Rgb::ONE,
    });
    for wo in [dir(20.0, 10.0), dir(75.0, 100.0), dir(160.0, 0.0), dir(120.0, 40.0)] {
        let n = 200_000;
        let mut reflected = 0;
        for i in 0..n {
            let mut s = tessera::sampling::Sampler::new(5, 0, i);
            let bs = glass.sample(wo, s.next_1d(), s.next_2d()).unwrap();
            assert!(bs.delta);
            if bs.wi.z * wo.z > 0.0 {
                reflected += 1;
                assert!(bs.wi.distance(Vec3::new(-wo.x, -wo.y, wo.z)) < 1e-5);
            } else {
                // Snell's law and the radiance scaling 1 / eta_it^2.
                let (ni, nt) = if wo.z > 0.0 { (1.0, 1.5) } else { (1.5, 1.0) };
                let sin_o = (1.0 - wo.z * wo.z).sqrt();
                let sin_i = (1.0 - bs.wi.z * bs.wi.z).sqrt();
                assert!((ni * sin_o - nt * sin_i).abs() < 1e-4);
                assert!((bs.weight.x - (ni / nt).powi(2)).abs() < 1e-4);
            }
        }
        let f = fresnel_dielectric(wo.z, 1.5).r as f64;
        let observed = reflected as f64 / n as f64;
        let sigma = (f * (1.0 - f) / n as f64).sqrt().max(1e-6);
        assert!((observed - f).abs() < 5.0 * sigma, "wo {wo}: reflected {observed}, Fresnel {f}");
    }
}

#[test]
fn smooth_conductor_reflects_specularly_with_fresnel_weight() {
    let mirror = Bsdf::Conductor(Conductor {
        ggx: None,
        fresnel: ConductorFresnel::Complex {
            eta: Rgb::new(1.6575, 0.880405, 0.521244),
            k: Rgb::new(9.22381, 6.2695, 4.837),
        },
        specular_reflectance: Rgb::ONE,
    });
    let wo = dir(40.0, 70.0);
    let bs = mirror.sample(wo, 0.3, Vec2::new(0.2, 0.9)).unwrap();
    assert!(bs.delta && bs.wi.distance(Vec3::new(-wo.x, -wo.y, wo.z)) < 1e-6);
    let f = tessera::bsdf::fresnel::fresnel_conductor(
        wo.z,
        Rgb::new(1.6575, 0.880405, 0.521244),
        Rgb::new(9.22381, 6.2695, 4.837),
    );
    assert!((bs.weight - f).abs().max_element() < 1e-6);
    assert_eq!(mirror.eval(wo, bs.wi), Rgb::ZERO);
    assert_eq!(mirror.pdf(wo, bs.wi), 0.0);
}

#[test]
fn chi2_rejects_a_slightly_wrong_density() {
    // The harness has power: sampling GGX alpha 0.30 but claiming the density of alpha 0.32
    // (or the right density scaled by 1.03) must fail.
    let level = sidak(TESTS);
    let (sampled, claimed) = (Ggx::new(0.3, 0.3), Ggx::new(0.32, 0.32));
    let w = dir(40.0, 10.0);
    let wrong_alpha = Chi2::default().run(11, |_, u| Some(sampled.sample_visible(w, u)), |m| claimed.pdf_visible(w, m));
    assert!(wrong_alpha.p_value < level, "{wrong_alpha:?}");
    let scaled =
        Chi2::default().run(12, |_, u| Some(sampled.sample_visible(w, u)), |m| 1.03 * sampled.pdf_visible(w, m));
    assert!(scaled.p_value < level, "{scaled:?}");
}
