//! The WGSL port of tiling and blending against the CPU, texel by texel (feature `gpu`; CI runs
//! it on Mesa's lavapipe). Regime (a) of docs/gpu.md: filtering done in the shader in f32 with
//! textureLoad must agree with the CPU bake to 1e-4 in every channel of every texel, for every
//! paving, operator, filter and deformation factor the port takes. A machine with the feature
//! on and no Vulkan driver fails here with what to install: these tests never pass without
//! running.

mod common;

use glam::{Mat2, Vec2};
use std::sync::Arc;
use tessera::gpu::{Gpu, GpuBake};
use tessera::image::Bitmap;
use tessera::image::compare::TexelDifference;
use tessera::texture::tiling_blending::{
    Blend, Deformation, DeformationField, PriorityMap, Synthesis, Tiling, TilingBlending,
};
use tessera::texture::{BakeFootprint, Filter, ImageTexture, MipMap, Texture, bake_rect};

/// Regime (a)'s tolerance: largest absolute difference in any channel of any texel.
const TOLERANCE: f32 = 1e-4;

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("the GPU tests need a Vulkan device: {e}"))
}

/// A 96 x 64 RGBA exemplar with structure at several scales (not a power of two, so that the
/// pyramid's odd levels are exercised), values in [0, 1], each channel's histogram without
/// wide gaps (see [`histogram_preservation_amplifies_rounding_by_the_slope_of_its_inverse`]).
fn exemplar_image() -> Bitmap {
    let (w, h) = (96, 64);
    let mut b = Bitmap::new(w, h, 4);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f32 / w as f32, y as f32 / h as f32);
            let r = 0.5 + 0.5 * (std::f32::consts::TAU * (3.0 * u + v)).sin();
            let g = 0.5 + 0.4 * (std::f32::consts::TAU * u * 4.0).sin() * (std::f32::consts::TAU * v * 3.0).cos();
            let bl =
                0.5 + 0.3 * (std::f32::consts::TAU * (u * u + 2.0 * v)).cos() * (std::f32::consts::TAU * 5.0 * u).sin();
            let a = 0.25 + 0.5 * v;
            b.values_mut(x, y).copy_from_slice(&[r, g, bl, a]);
        }
    }
    b
}

fn image(bitmap: Bitmap, filter: Filter) -> ImageTexture {
    ImageTexture { mipmap: Arc::new(MipMap::new(bitmap)), filter, scale: Vec2::ONE, offset: Vec2::ZERO }
}

/// A 16 x 16 F map: rotation by an angle growing along u and a scale growing along v.
fn f_map() -> MipMap {
    let n = 16;
    let mut b = Bitmap::new(n, n, 4);
    for y in 0..n {
        for x in 0..n {
            let angle = x as f32 / n as f32 * 2.0;
            let s = 1.0 + y as f32 / n as f32;
            let (sn, cs) = angle.sin_cos();
            b.values_mut(x, y).copy_from_slice(&[s * cs, -s * sn, s * sn, s * cs]);
        }
    }
    MipMap::new(b)
}

fn deformations() -> Vec<(&'static str, Option<DeformationField>)> {
    let field = |factors| Some(DeformationField::new(factors));
    vec![
        ("none", None),
        ("constant", field(vec![Deformation::Constant(Mat2::from_cols_array(&[1.5, 0.3, -0.2, 0.8]))])),
        ("rotation", field(vec![Deformation::Rotation { angle: 0.3, gradient: Vec2::new(2.5, -1.0) }])),
        ("scale", field(vec![Deformation::Scale { scale: Vec2::new(2.0, 0.7), gradient: Vec2::new(0.5, 1.0) }])),
        ("shear", field(vec![Deformation::Shear { shear: 0.4, gradient: Vec2::new(0.0, 1.5) }])),
        ("map", field(vec![Deformation::Map(f_map())])),
        (
            "map, rotation, scale",
            field(vec![
                Deformation::Map(f_map()),
                Deformation::Rotation { angle: -0.5, gradient: Vec2::new(0.0, 3.0) },
                Deformation::Scale { scale: Vec2::splat(1.5), gradient: Vec2::ZERO },
            ]),
        ),
    ]
}

fn blends(filter: Filter) -> Vec<(&'static str, Blend)> {
    let priority = PriorityMap::new(&image(exemplar_image(), filter));
    vec![
        ("linear", Blend::Linear),
        ("variance_preserving", Blend::VariancePreserving),
        ("histogram_preserving", Blend::HistogramPreserving),
        ("mix_max", Blend::MixMax { priority: priority.clone(), contrast: 4.0, lambda: 0.05 }),
        ("mix_max, hard", Blend::MixMax { priority, contrast: 4.0, lambda: 0.0 }),
    ]
}

/// A hexagonal synthesis of `exemplar` with `blend` and `deformation`, no cut bands.
fn hexagonal(exemplar: Arc<Texture>, blend: Blend, deformation: Option<DeformationField>, seed: u64) -> TilingBlending {
    let synthesis =
        Synthesis { tiling: Tiling::Hexagonal, tile_size: 0.23, seed, deformation, cuts: None, blend, inset: false };
    TilingBlending::new(Arc::new(synthesis), exemplar).unwrap()
}

/// The GPU and CPU bakes of `texture` at `width` x `height` and their difference.
fn compare(gpu: &Gpu, texture: &TilingBlending, width: u32, height: u32, footprint: BakeFootprint) -> TexelDifference {
    let baker = GpuBake::new(gpu, texture).unwrap_or_else(|e| panic!("{e}"));
    let on_gpu = baker.bake(width, height, footprint).unwrap_or_else(|e| panic!("{e}"));
    let on_cpu = bake_rect(&Texture::TilingBlending(texture.clone()), width as usize, height as usize, footprint);
    TexelDifference::new(&on_gpu, &on_cpu, 3).unwrap()
}

#[test]
fn every_configuration_matches_the_cpu_bake() {
    let gpu = gpu();
    eprintln!("GPU: {}", gpu.describe());
    let mut failures = Vec::new();
    let mut cases = 0;
    for filter in [Filter::None, Filter::Trilinear, Filter::Ewa] {
        let exemplar = Arc::new(Texture::Image(image(exemplar_image(), filter)));
        for (blend_name, blend) in blends(filter) {
            for (deformation_name, deformation) in deformations() {
                for tiling in [Tiling::Hexagonal, Tiling::Square] {
                    let inset = cases % 3 == 0;
                    let synthesis = Arc::new(Synthesis {
                        tiling,
                        tile_size: 0.23,
                        seed: 5 + cases as u64,
                        deformation: deformation.clone(),
                        cuts: None,
                        blend: blend.clone(),
                        inset,
                    });
                    let texture = TilingBlending::new(synthesis, exemplar.clone()).unwrap();
                    for footprint in [BakeFootprint::Texel, BakeFootprint::Point] {
                        cases += 1;
                        let diff = compare(&gpu, &texture, 48, 40, footprint);
                        let case = format!(
                            "{filter:?} {blend_name} {deformation_name} {tiling:?} inset {inset} {footprint:?}: max {:.2e}",
                            diff.max()
                        );
                        if !diff.within(TOLERANCE) {
                            failures.push(format!("{case}, worst {:?}", diff.worst[0]));
                        }
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {cases} cases differ by more than {TOLERANCE}:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn shipped_scenes_match_the_cpu_bake() {
    let gpu = gpu();
    // sphere_deformed's `deformed` texture has the cut bands `tessera deform` derived from a
    // lat-long sphere's seam.
    let scenes =
        ["fig2_rotation", "fig2_scaling", "fig2_shearing", "brushed_tb", "pbr_rocks", "fig4/fig4", "sphere_deformed"];
    let mut checked = 0;
    for name in scenes {
        let path = common::repo().join(format!("scenes/{name}.toml"));
        let text = std::fs::read_to_string(&path).unwrap();
        let table: toml::Table = text.parse().unwrap();
        for (texture_name, item) in table["textures"].as_table().unwrap() {
            if item.get("type").and_then(|t| t.as_str()) != Some("tiling_blending") {
                continue;
            }
            let texture = tessera::scene::load_texture(&path, texture_name, true).unwrap();
            let Texture::TilingBlending(t) = &texture else { unreachable!() };
            let diff = compare(&gpu, t, 96, 96, BakeFootprint::Texel);
            eprintln!("{name} {texture_name}: max |gpu - cpu| {:.2e}", diff.max());
            assert!(diff.within(TOLERANCE), "{name} {texture_name}: {:?}", diff.worst);
            checked += 1;
        }
    }
    assert!(checked >= 10, "only {checked} textures checked");
}

#[test]
fn what_the_port_lacks_is_an_error_naming_it() {
    let gpu = gpu();
    let exemplar = Arc::new(Texture::Image(image(exemplar_image(), Filter::None)));
    let sharpened = Blend::Sharpened { exponent: 7.0, luminance_contrast: 0.6, source: exemplar.clone() };
    let texture = hexagonal(exemplar, sharpened, None, 1);
    let error = GpuBake::new(&gpu, &texture).err().expect("the sharpened operator is not ported");
    assert!(error.0.contains("sharpened"), "{error}");
}

#[test]
fn gpu_bakes_are_deterministic() {
    let gpu = gpu();
    let exemplar = Arc::new(Texture::Image(image(exemplar_image(), Filter::Ewa)));
    let texture = hexagonal(exemplar, Blend::HistogramPreserving, deformations().pop().unwrap().1, 1);
    let baker = GpuBake::new(&gpu, &texture).unwrap();
    let a = baker.bake(64, 64, BakeFootprint::Texel).unwrap();
    let b = baker.bake(64, 64, BakeFootprint::Texel).unwrap();
    assert_eq!(a, b);
}

/// The exported GLSL compiles with a stock compiler (Khronos' glslangValidator, Debian
/// glslang-tools), as an engine's build would.
#[test]
fn exported_glsl_compiles_with_glslang() {
    use tessera::shader::{ShaderEntry, ShaderLanguage, export};
    let dir = tempfile::tempdir().unwrap();
    // glslangValidator takes the stage from the extension.
    for (entry, file) in [(ShaderEntry::Bake, "bake.comp"), (ShaderEntry::View, "view.frag")] {
        let path = dir.path().join(file);
        std::fs::write(&path, export(ShaderLanguage::Glsl, entry).unwrap()).unwrap();
        let output = std::process::Command::new("glslangValidator")
            .arg("-V")
            .arg(&path)
            .arg("-o")
            .arg(dir.path().join(format!("{file}.spv")))
            .output()
            .unwrap_or_else(|e| panic!("glslangValidator (Debian glslang-tools) is needed: {e}"));
        assert!(
            output.status.success(),
            "glslangValidator rejected the exported GLSL of {entry:?}:\n{}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// Histogram preservation reads T^-1 from a table: where the exemplar's histogram has a gap, the
/// table is steep (a binary channel jumps from 0.1 to 0.9 within one entry, a slope of about
/// 0.8 x 255), and the few-ulp differences between the CPU's and the GPU's blended Gaussian
/// value g (exp, sqrt and summation order) come out multiplied by that slope. This measures
/// the effect on a binary checker and holds it to the bound the slope gives (|dg| <= 2e-6);
/// docs/gpu.md tells shader authors what to expect.
#[test]
fn histogram_preservation_amplifies_rounding_by_the_slope_of_its_inverse() {
    let gpu = gpu();
    let (w, h) = (64, 64);
    let mut checker = Bitmap::new(w, h, 4);
    for y in 0..h {
        for x in 0..w {
            let g = if (x / 8 + y / 8) % 2 == 0 { 0.9 } else { 0.1 };
            checker.values_mut(x, y).copy_from_slice(&[g, g, g, 1.0]);
        }
    }
    let exemplar = Arc::new(Texture::Image(image(checker, Filter::Ewa)));
    let texture = hexagonal(exemplar, Blend::HistogramPreserving, deformations().pop().unwrap().1, 3);
    let diff = compare(&gpu, &texture, 64, 64, BakeFootprint::Point);
    let slope = 0.8 * 255.0;
    eprintln!("binary checker, histogram-preserving: max |gpu - cpu| {:.2e} (slope of T^-1 {slope})", diff.max());
    assert!(diff.max() <= slope * 2e-6, "{:?}", diff.worst);
}

/// A mesh scene for the rasterised view: a floor seen at grazing angles towards the horizon, a
/// sphere, and a quad of the other handedness than the floor's (its u runs right to left, the
/// floor's v runs down), so that the F map is mirrored to the surface's handedness on some. The scene's materials do not matter: the view
/// draws the texture under test on every surface.
fn view_scene() -> (tempfile::TempDir, tessera::scene::Scene) {
    let toml = r#"
        [render]
        width = 96
        height = 64
        [camera]
        fov = 50
        eye = [0, 0.6, 3]
        target = [0, 0.1, 0]
        [materials.grey]
        type = "diffuse"
        reflectance = 0.5
        [[shapes]]
        type = "rectangle"
        material = "grey"
        transform = [{ scale = 8 }, { rotate = [1, 0, 0], angle = -90 }, { translate = [0, -0.5, -4] }]
        [[shapes]]
        type = "uv_sphere"
        material = "grey"
        transform = [{ scale = 0.45 }, { translate = [-0.6, 0, 0] }]
        [[shapes]]
        type = "obj"
        filename = "mirrored.obj"
        material = "grey"
        transform = [{ scale = 0.5 }, { translate = [0.6, 0.1, 0.2] }]
    "#;
    let obj = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 1 0\nvt 0 0\nvt 0 1\nvt 1 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
    common::scene(toml, &[("mirrored.obj", obj.as_bytes())])
}

#[test]
fn the_rasterised_view_with_ray_differentials_matches_tessera() {
    use tessera::gpu::GpuView;
    use tessera::integrator::primary::{Derivatives, SURFACE_MIRRORED, ViewDifference, primary_view, view_geometry};
    let gpu = gpu();
    let (_dir, scene) = view_scene();
    let camera = scene.camera.with_resolution(96, 64).unwrap();
    let mirrored: Vec<bool> = view_geometry(&scene.geometry).1.iter().map(|t| t.surface == SURFACE_MIRRORED).collect();
    let priority = PriorityMap::new(&image(exemplar_image(), Filter::Trilinear));
    let cases = [
        ("hexagonal, linear, F map, EWA", Tiling::Hexagonal, Blend::Linear, Filter::Ewa, 5),
        (
            "square, histogram-preserving, map + rotation + scale, trilinear",
            Tiling::Square,
            Blend::HistogramPreserving,
            Filter::Trilinear,
            6,
        ),
        (
            "hexagonal, Mix-Max, F map, trilinear",
            Tiling::Hexagonal,
            Blend::MixMax { priority, contrast: 4.0, lambda: 0.05 },
            Filter::Trilinear,
            5,
        ),
    ];
    for (name, tiling, blend, filter, deformation) in cases {
        let exemplar = Arc::new(Texture::Image(image(exemplar_image(), filter)));
        let deformation = deformations()[deformation].1.clone();
        let synthesis = Synthesis { tiling, tile_size: 0.23, seed: 3, deformation, cuts: None, blend, inset: false };
        let texture = TilingBlending::new(Arc::new(synthesis), exemplar).unwrap();
        let on_gpu = GpuView::new(&gpu, &scene, &camera, &texture, None)
            .and_then(|view| view.render(Derivatives::Ray))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let on_cpu = primary_view(&scene, &camera, &Texture::TilingBlending(texture));
        let diff = ViewDifference::new(&on_gpu, &on_cpu, 3).unwrap();
        let seen = on_cpu.triangle.iter().filter(|&&t| t != 0).count();
        let mirrored_seen = on_cpu.triangle.iter().filter(|&&t| t != 0 && mirrored[t as usize - 1]).count();
        eprintln!(
            "{name}: {} of {seen} pixels compared ({} mirrored), max |gpu - cpu| {:.2e}, footprint error max {:.2e}",
            diff.compared,
            mirrored_seen,
            diff.value.max(),
            diff.footprint.max
        );
        // The rasteriser and the rays see the same triangles but for a few pixels on edges.
        assert!(diff.compared as f64 >= 0.98 * seen as f64 && seen > 3000, "{name}: {diff:?}");
        // Both handednesses are seen, so that both branches of the F map's mirroring are
        // checked: the floor's UV map is mirrored (Mitsuba's rectangle: v runs down), the
        // quad's is not (its u runs right to left as well).
        assert!(mirrored_seen > 200 && seen - mirrored_seen > 200, "{name}: {mirrored_seen} of {seen} mirrored");
        assert!(diff.value.within(TOLERANCE), "{name}: {:?}", diff.value.worst);
        assert!(diff.footprint.max < 1e-4, "{name}: footprint error {:?}", diff.footprint);
    }
}

#[test]
fn screen_space_derivatives_are_exact_where_uv_is_affine_on_the_screen() {
    use tessera::gpu::GpuView;
    use tessera::integrator::primary::{Derivatives, ViewDifference, primary_view};
    // A rectangle facing the camera squarely: UV is affine in screen position, so the
    // differences of neighbouring pixels are the exact derivatives, coarse or fine. On the
    // grazing floor of `view_scene` they are not (the measured error is in docs/gpu.md).
    let toml = r#"
        [render]
        width = 64
        height = 64
        [camera]
        fov = 40
        eye = [0, 0, 4]
        target = [0, 0, 0]
        [materials.grey]
        type = "diffuse"
        reflectance = 0.5
        [[shapes]]
        type = "rectangle"
        material = "grey"
        transform = [{ rotate = [0, 0, 1], angle = 30 }]
    "#;
    let (_dir, scene) = common::scene(toml, &[]);
    let camera = scene.camera.with_resolution(64, 64).unwrap();
    let gpu = gpu();
    let exemplar = Arc::new(Texture::Image(image(exemplar_image(), Filter::Trilinear)));
    let texture = hexagonal(exemplar, Blend::Linear, deformations()[5].1.clone(), 2);
    let view = GpuView::new(&gpu, &scene, &camera, &texture, None).unwrap();
    let on_cpu = primary_view(&scene, &camera, &Texture::TilingBlending(texture));
    for derivatives in [Derivatives::Dpdx, Derivatives::Coarse, Derivatives::Fine] {
        let diff = ViewDifference::new(&view.render(derivatives).unwrap(), &on_cpu, 3).unwrap();
        eprintln!(
            "{}: footprint error {:?}, max |gpu - cpu| {:.2e}",
            derivatives.name(),
            diff.footprint,
            diff.value.max()
        );
        assert!(diff.compared > 1000, "{diff:?}");
        assert!(diff.footprint.max < 1e-4, "{}: {:?}", derivatives.name(), diff.footprint);
    }
}

#[test]
fn hardware_bilinear_sampling_is_within_the_bound_of_fixed_point_weights() {
    use tessera::texture::tiling_blending::params::HardwareSampling;
    // Regime (b) with point lookups: the texture unit filters level 0 bilinearly, with weights
    // in fixed point (8 fractional bits on NVIDIA, AMD and Intel GPUs; lavapipe computes them
    // in f32). A weight off by at most 2^-8 per axis moves a value by at most 2^-8 of the
    // largest difference between neighbouring texels per axis, and linear blending of tiles
    // (weights summing to 1) keeps that bound.
    let bitmap = exemplar_image();
    let mut contrast = 0.0f32;
    for y in 0..bitmap.height {
        for x in 0..bitmap.width {
            let p = bitmap.pixel(x, y);
            let right = bitmap.pixel((x + 1) % bitmap.width, y);
            let down = bitmap.pixel(x, (y + 1) % bitmap.height);
            contrast = contrast.max((right - p).abs().max_element()).max((down - p).abs().max_element());
        }
    }
    let gpu = gpu();
    let exemplar = Arc::new(Texture::Image(image(bitmap, Filter::Trilinear)));
    let texture = hexagonal(exemplar, Blend::Linear, deformations()[5].1.clone(), 4);
    let sampling = HardwareSampling { anisotropy: 1, gradient_scale: 1.0 };
    let baker = GpuBake::with_sampling(&gpu, &texture, Some(sampling)).unwrap_or_else(|e| panic!("{e}"));
    let on_gpu = baker.bake(64, 48, BakeFootprint::Point).unwrap();
    let on_cpu = bake_rect(&Texture::TilingBlending(texture), 64, 48, BakeFootprint::Point);
    let diff = TexelDifference::new(&on_gpu, &on_cpu, 3).unwrap();
    let bound = 2.0 * contrast / 256.0;
    eprintln!(
        "hardware bilinear: max |gpu - cpu| {:.2e}, bound {bound:.2e} (texel contrast {contrast:.3})",
        diff.max()
    );
    assert!(diff.within(bound), "{:?}", diff.worst);
}

#[test]
fn cut_bands_match_the_cpu_bake() {
    use tessera::texture::tiling_blending::{CutBands, CutCurve, CutPoint};
    // Two cuts of the F map's square: a straight one seen at u = 0.3 and u = 0.7 (g along its
    // length), and a bent one crossing it, so that points lie in two bands at once.
    let straight = (0..=8)
        .map(|k| {
            let v = k as f32 / 8.0;
            CutPoint { uv: [Vec2::new(0.3, v), Vec2::new(0.7, 1.0 - v)], s: v, g: Vec2::new(v, 0.1 * v) }
        })
        .collect();
    let bent = (0..=6)
        .map(|k| {
            let t = k as f32 / 6.0;
            let a = Vec2::new(0.1 + 0.8 * t, 0.5 + 0.2 * (3.0 * t).sin());
            CutPoint { uv: [a, a + Vec2::new(0.0, 0.1)], s: 0.9 * t, g: Vec2::new(0.0, 0.9 * t) }
        })
        .collect();
    let curves = vec![CutCurve::new(straight, 1.3).unwrap(), CutCurve::new(bent, 0.8).unwrap()];
    let map = f_map();
    // The bands cover a good part of the square (and so of the bakes below).
    let bands = CutBands::new(curves.clone(), map.level(0), 0.12).unwrap();
    let near = (0..64 * 64).filter(|i| bands.near((Vec2::new((i % 64) as f32, (i / 64) as f32) + 0.5) / 64.0)).count();
    assert!(near > 64 * 64 / 4, "{near} of {} texels near a cut", 64 * 64);
    let gpu = gpu();
    let mut failures = Vec::new();
    for (blend_name, blend) in blends(Filter::Trilinear) {
        for inset in [false, true] {
            let tile_size = 0.12;
            let bands = CutBands::new(curves.clone(), map.level(0), tile_size).unwrap();
            let exemplar = Arc::new(Texture::Image(image(exemplar_image(), Filter::Trilinear)));
            let deformation = Some(DeformationField::new(vec![
                Deformation::Map(f_map()),
                Deformation::Rotation { angle: 0.2, gradient: Vec2::ZERO },
            ]));
            let synthesis = Synthesis {
                tiling: Tiling::Square,
                tile_size,
                seed: 5,
                deformation,
                cuts: Some(bands),
                blend: blend.clone(),
                inset,
            };
            let texture = TilingBlending::new(Arc::new(synthesis), exemplar).unwrap();
            for footprint in [BakeFootprint::Texel, BakeFootprint::Point] {
                let diff = compare(&gpu, &texture, 64, 64, footprint);
                if !diff.within(TOLERANCE) {
                    failures.push(format!(
                        "{blend_name}, inset {inset}, {footprint:?}: {:.2e} {:?}",
                        diff.max(),
                        diff.worst
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
