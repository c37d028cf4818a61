//! Chi-square goodness of fit of light sampling against the densities the integrator uses for
//! multiple importance sampling: environment maps, area lights and emitting spheres.

mod common;

use common::{Chi2, sidak};
use glam::{Vec2, Vec3};
use tessera::accel::Accel;
use tessera::geometry::{Ray, Sphere};
use tessera::image::{Bitmap, ColorSpace, read_bitmap};
use tessera::light::{AreaLight, Environment, EnvironmentMap};

const TESTS: usize = 6;

#[test]
fn environment_map_sampling_matches_pdf_chi2() {
    // A coarse map (each texel spans many chi-square nodes, so the density's jumps at texel
    // edges integrate accurately), with a bright "sun" texel and a dark band.
    let mut image = Bitmap::new(16, 8, 3);
    for y in 0..8 {
        for x in 0..16 {
            let v = 0.2 + 0.1 * ((x * 7 + y * 3) % 5) as f32 + if y == 6 { -0.15 } else { 0.0 };
            let sun = if (x, y) == (11, 2) { 40.0 } else { 0.0 };
            image.values_mut(x, y).copy_from_slice(&[v + sun, v, v * 0.5 + sun]);
        }
    }
    let env = Environment::Map(EnvironmentMap::new(image, 1.0));
    let outcome = Chi2::default().run(21, |_, u| env.sample(u).map(|s| s.wi), |w| env.pdf(w));
    assert!(outcome.p_value > sidak(TESTS) && outcome.in_zero_cells == 0, "{outcome:?}");
    assert!((outcome.integral - 1.0).abs() < 2e-3, "{outcome:?}");
}

#[test]
fn environment_map_sample_pdf_and_radiance_are_consistent() {
    // On the shipped sky map (sun 22672): each sample's pdf equals pdf(direction), and the
    // importance-sampled estimate of the mean radiance matches a quadrature of the map.
    let image = read_bitmap(&common::repo().join("scenes/textures/sky_512x256.exr"), ColorSpace::Linear).unwrap();
    let env = Environment::Map(EnvironmentMap::new(image, 1.0));
    let n = 200_000;
    let mut estimate = 0.0f64;
    for i in 0..n {
        let mut s = tessera::sampling::Sampler::new(8, 0, i);
        let ls = env.sample(s.next_2d()).expect("the map has energy");
        let pdf = env.pdf(ls.wi);
        assert!((pdf - ls.pdf).abs() <= 2e-3 * pdf, "{pdf} vs {}", ls.pdf);
        estimate += (ls.radiance.y / ls.pdf) as f64;
    }
    estimate /= n as f64;
    let quadrature = common::integrate_sphere(400, |w| env.radiance(w).y as f64);
    // Importance sampling by luminance leaves little variance in the green channel.
    assert!((estimate - quadrature).abs() < 0.01 * quadrature, "estimate {estimate}, quadrature {quadrature}");
}

#[test]
fn constant_environment_sampling_is_uniform_chi2() {
    let env = Environment::Constant(tessera::color::Rgb::ONE);
    let outcome = Chi2::default().run(22, |_, u| env.sample(u).map(|s| s.wi), |w| env.pdf(w));
    assert!(outcome.p_value > sidak(TESTS) && (outcome.integral - 1.0).abs() < 1e-3, "{outcome:?}");
}

#[test]
fn area_light_sampling_matches_pdf_chi2() {
    // A tilted quad facing the point, a triangle of another size facing it, and a triangle
    // showing it its back (never sampled: zero density there).
    let quad = [
        [Vec3::new(-1.0, -0.5, 1.0), Vec3::new(1.0, 0.5, 1.2), Vec3::new(1.0, -0.5, 1.2)],
        [Vec3::new(-1.0, -0.5, 1.0), Vec3::new(-1.0, 0.5, 1.0), Vec3::new(1.0, 0.5, 1.2)],
        [Vec3::new(0.5, 1.0, 0.3), Vec3::new(0.8, 2.0, 0.4), Vec3::new(1.5, 1.2, 0.5)],
        [Vec3::new(-1.5, -1.0, 0.2), Vec3::new(-1.0, -2.0, 0.2), Vec3::new(-0.5, -1.5, 0.3)],
    ];
    let light = AreaLight::new(quad.to_vec(), tessera::color::Rgb::ONE);
    let accel = Accel::build(&quad, &[true; 4], &[]);
    let p = Vec3::new(0.1, 0.2, -0.3);
    let pdf = |w: Vec3| {
        let Some(hit) = accel.intersect(&Ray::new(p, w)) else { return 0.0 };
        let [a, b, c] = quad[hit.primitive as usize];
        let q = a * (1.0 - hit.b1 - hit.b2) + b * hit.b1 + c * hit.b2;
        light.pdf(p, w.normalize(), q, (b - a).cross(c - a).normalize())
    };
    // The density ends abruptly at the triangles' edges: integrate finely (40 x 40 nodes).
    let chi2 = Chi2 { nodes: 40, ..Chi2::default() };
    let outcome = chi2.run(23, |_, u: Vec2| light.sample(p, u).map(|s| s.wi), pdf);
    assert!(outcome.p_value > sidak(TESTS) && outcome.in_zero_cells == 0, "{outcome:?}");
    // The back-facing triangle's share of the area produces no samples.
    let facing: f32 = quad[..3].iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).sum();
    let expected = facing / light.area();
    let fraction = outcome.valid as f32 / 400_000.0;
    assert!(
        (fraction - expected).abs() < 0.005 && (outcome.integral as f32 - expected).abs() < 0.005,
        "{outcome:?}, expected {expected}"
    );
}

/// An emitting sphere seen from outside (its directions uniform over the cone it subtends) and
/// from inside (its points uniform by area): samples against the density the integrator weighs
/// a path's hit with, found by tracing each direction to the sphere.
#[test]
fn sphere_light_sampling_matches_pdf_chi2() {
    let to_world = glam::Mat4::from_translation(Vec3::new(0.3, -0.2, 1.5)) * glam::Mat4::from_scale(Vec3::splat(0.9));
    for (seed, p, flip) in [(24, Vec3::new(0.1, 0.2, -0.3), false), (25, Vec3::new(0.5, 0.1, 1.2), true)] {
        let sphere = Sphere::new(to_world, flip).unwrap();
        let light = AreaLight::sphere(sphere.clone(), tessera::color::Rgb::ONE);
        let accel = Accel::build(&[], &[], std::slice::from_ref(&sphere));
        let pdf = |w: Vec3| {
            let ray = Ray::new(p, w);
            let Some(hit) = accel.intersect(&ray) else { return 0.0 };
            let q = ray.at(hit.t);
            let n = (q - sphere.center()).normalize() * if flip { -1.0 } else { 1.0 };
            light.pdf(p, w.normalize(), q, n)
        };
        let outcome =
            Chi2 { nodes: 40, ..Chi2::default() }.run(seed, |_, u: Vec2| light.sample(p, u).map(|s| s.wi), pdf);
        assert!(outcome.p_value > sidak(TESTS) && outcome.in_zero_cells == 0, "flip {flip}: {outcome:?}");
        assert!((outcome.integral - 1.0).abs() < 5e-3, "flip {flip}: {outcome:?}");
    }
}
