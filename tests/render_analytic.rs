//! Whole renders against analytic truths (the method of pbrt-v4's `integrators_test.cpp`):
//! each scene's expected radiance is derived in its comment, and the image mean must match
//! within 4 standard errors (from the film's per-pixel variance) plus a small stated margin.

mod common;

use common::{mean_and_error, render_film, scene};
use std::f64::consts::PI;

fn assert_mean(toml: &str, files: &[(&str, &[u8])], expected: f64, margin: f64, what: &str) {
    let (_dir, scene) = scene(toml, files);
    let film = render_film(&scene);
    assert_eq!(film.invalid_sample_count(), 0, "{what}: non-finite samples");
    let (mean, error) = mean_and_error(&film, scene.settings.spp);
    assert!(
        (mean - expected).abs() <= 4.0 * error + margin,
        "{what}: mean {mean:.5} +- {error:.5}, expected {expected:.5} (margin {margin})"
    );
}

/// A camera inside a closed sphere whose inside is diffuse (albedo a) and emits L_e. Every
/// ray hits the enclosure, so a path of d segments collects L_e from each of its d vertices,
/// weighted a^k at the k-th: L = L_e (1 + a + ... + a^(d-1)), and L_e / (1 - a) without a
/// limit (Russian roulette must leave it unbiased). This holds for any closed shape with flat
/// shading. (A UV sphere's smooth vertex normals break it slightly: directions near the
/// geometric horizon fall outside the shading hemisphere, and the images come out 0.05-0.1%
/// dark at 64 x 32 and 24 x 12 segments, as in Mitsuba. So the enclosure is a cube.)
fn enclosure(shape: &str, albedo: f64, max_depth: i64) -> String {
    format!(
        r#"
        [render]
        width = 12
        height = 12
        spp = 256
        max_depth = {max_depth}
        [camera]
        fov = 70
        eye = [0.1, 0.2, 0.05]
        target = [0.5, 0.3, -1]
        [materials.inside]
        type = "diffuse"
        reflectance = {albedo}
        [[shapes]]
        type = "{shape}"
        flip_normals = true
        material = "inside"
        emission = 1
        "#
    )
}

#[test]
fn enclosure_radiance_counts_path_segments_like_mitsuba() {
    let a = 0.5;
    assert_mean(&enclosure("cube", a, 1), &[], 1.0, 1e-6, "max_depth 1: emission only");
    assert_mean(&enclosure("cube", a, 2), &[], 1.0 + a, 1e-4, "max_depth 2: direct light");
    assert_mean(&enclosure("cube", a, 4), &[], 1.0 + a + a * a + a * a * a, 1e-4, "max_depth 4");
}

/// The same inside an exact sphere turned inside out: its normals are exact, so it holds as
/// for the cube (light sampling from inside picks points by area).
#[test]
fn enclosure_radiance_inside_an_exact_sphere() {
    let a = 0.5;
    assert_mean(&enclosure("sphere", a, 2), &[], 1.0 + a, 1e-4, "exact sphere, max_depth 2");
    assert_mean(&enclosure("sphere", a, 4), &[], 1.0 + a + a * a + a * a * a, 1e-4, "exact sphere, max_depth 4");
}

#[test]
fn enclosure_furnace_with_russian_roulette_is_unbiased() {
    let a = 0.7;
    assert_mean(&enclosure("cube", a, -1), &[], 1.0 / (1.0 - a), 1e-3, "unlimited depth, albedo 0.7");
}

/// A diffuse floor (albedo rho) lit by a 2 x 2 square emitter (radiance L_e) 1 unit above,
/// seen straight down through a 1-degree field of view. The form factor from a point under
/// the centre of a square of half-side a at height h, by four corner rectangles (Howell's
/// catalogue, B-3, with X = Y = a / h):
///   F = 4 / (2 pi) [ 2 X / sqrt(1 + X^2) atan(X / sqrt(1 + X^2)) ]
/// and the reflected radiance is rho L_e F (direct light only: max_depth 2).
#[test]
fn square_light_over_diffuse_floor_matches_form_factor() {
    let x: f64 = 1.0;
    let s = (1.0 + x * x).sqrt();
    let form_factor = 4.0 / (2.0 * std::f64::consts::PI) * (2.0 * x / s * (x / s).atan());
    let (rho, le) = (0.5, 3.0);
    let light = format!(
        "[[shapes]]\ntype = \"rectangle\"\nemission = {le}\n\
         transform = [{{ rotate = [1, 0, 0], angle = 90 }}, {{ translate = [0, 1, 0] }}]"
    );
    let toml = lit_floor(rho, "", &light);
    assert_mean(&toml, &[], rho * le * form_factor, 1e-4, "floor under a square light");
}

/// A perfect glass sphere and a perfect mirror sphere in a uniform white sky, as a mesh and
/// exact: lossless scattering preserves radiance (refraction's 1/eta^2 in and eta^2 out
/// cancel), so every pixel is 1 with unlimited depth.
#[test]
fn lossless_spheres_in_white_sky_are_invisible() {
    let materials =
        ["type = \"dielectric\"\nint_ior = 1.5\next_ior = 1.0", "type = \"conductor\"\nmaterial = \"none\""];
    for (material, shape) in materials.iter().flat_map(|m| ["uv_sphere", "sphere"].map(|s| (m, s))) {
        let toml = format!(
            r#"
            [render]
            width = 10
            height = 10
            spp = 128
            [camera]
            fov = 30
            eye = [0, 0, 4]
            target = [0, 0, 0]
            [environment]
            type = "constant"
            radiance = 1
            [materials.m]
            {material}
            [[shapes]]
            type = "{shape}"
            material = "m"
            "#
        );
        assert_mean(&toml, &[], 1.0, 1e-3, &format!("{shape}: {material}"));
    }
}

/// A horizontal rough mirror (Fresnel 1) under a uniform sky of radiance 1 reflects its
/// directional albedo int f |cos| dw at the viewing angle, computed here by quadrature of the
/// BSDF: the render must combine light sampling (uniform sphere) and BSDF sampling correctly.
#[test]
fn rough_mirror_under_uniform_sky_reflects_its_albedo() {
    use tessera::bsdf::{Bsdf, Conductor, ConductorFresnel, Ggx};
    use tessera::color::Rgb;
    let (au, av) = (0.3f32, 0.1f32);
    // The camera looks down at 45 degrees along -z; the plane's tangent s = dp/du is world +x.
    let elevation = 45f32.to_radians();
    let wo = glam::Vec3::new(0.0, -elevation.cos(), elevation.sin());
    let b = Bsdf::Conductor(Conductor {
        ggx: Some(Ggx::new(au, av)),
        fresnel: ConductorFresnel::Complex { eta: Rgb::ZERO, k: Rgb::ONE },
        specular_reflectance: Rgb::ONE,
    });
    let albedo = common::integrate_sphere(200, |wi| b.eval(wo, wi).x as f64);
    let toml = format!(
        r#"
        [render]
        width = 8
        height = 8
        spp = 1024
        [camera]
        fov = 0.5
        eye = [0, 1, 1]
        target = [0, 0, 0]
        [environment]
        type = "constant"
        radiance = 1
        [materials.m]
        type = "conductor"
        material = "none"
        alpha_u = {au}
        alpha_v = {av}
        [[shapes]]
        type = "rectangle"
        material = "m"
        transform = [{{ scale = 10 }}, {{ rotate = [1, 0, 0], angle = -90 }}]
        "#
    );
    assert_mean(&toml, &[], albedo, 1e-3, "rough mirror");
}

/// A diffuse floor (albedo rho) under the shipped sky map: L = rho / pi int_{upper} L(w) cos dw,
/// computed by quadrature of the map. The sun (22672) makes this a test of importance sampling
/// and MIS: the estimate must converge to the integral, not just be plausible.
#[test]
fn diffuse_floor_under_sky_map_matches_quadrature() {
    use tessera::image::{ColorSpace, read_bitmap};
    use tessera::light::{Environment, EnvironmentMap};
    let sky = common::repo().join("scenes/textures/sky_512x256.exr");
    let env = Environment::Map(EnvironmentMap::new(read_bitmap(&sky, ColorSpace::Linear).unwrap(), 1.0));
    let rho = 0.5;
    let irradiance = common::integrate_sphere(300, |w| {
        // The sky's up is +y; the chi-square helpers' sphere is z-up: use w as given.
        if w.y > 0.0 { env.radiance(w).x as f64 * w.y as f64 } else { 0.0 }
    });
    let expected = rho / std::f64::consts::PI * irradiance;
    let toml = format!(
        r#"
        [render]
        width = 8
        height = 8
        spp = 512
        max_depth = 2
        [camera]
        fov = 1
        eye = [0, 1, 0.6]
        target = [0, 0, 0]
        [environment]
        type = "envmap"
        filename = "{}"
        [materials.floor]
        type = "diffuse"
        reflectance = {rho}
        [[shapes]]
        type = "rectangle"
        material = "floor"
        transform = [{{ scale = 100 }}, {{ rotate = [1, 0, 0], angle = -90 }}]
        "#,
        sky.display()
    );
    assert_mean(&toml, &[], expected, 2e-3 * expected, "floor under sky");
}

/// A normal-mapped rough mirror (the map's normal tilted 45 degrees) under a uniform sky of
/// radiance 1 reflects int f(wo, wi) G(wi) dw over the directions above both the perturbed and
/// the real surface, G the terminator shadowing: computed here by quadrature of the material at
/// the centre pixel's hit. (A missing side check once let samples escape below the surface and
/// doubled this image.)
#[test]
fn normal_mapped_mirror_under_uniform_sky_matches_its_model() {
    use glam::Vec2;
    use tessera::texture::TexCtx;
    let tilted = image::RgbImage::from_pixel(4, 4, image::Rgb([218, 128, 218]));
    let mut png = Vec::new();
    tilted.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    let toml = "[render]\nwidth = 9\nheight = 9\nspp = 2048\nmax_depth = 2\n\
        [camera]\nfov = 1\neye = [0, 3, 1.5]\ntarget = [0, 0, 0]\n\
        [environment]\ntype = \"constant\"\nradiance = 1\n\
        [textures.n]\ntype = \"image\"\nfilename = \"n.png\"\n\
        [materials.m]\ntype = \"conductor\"\nmaterial = \"none\"\nalpha = 0.3\nnormal_map = \"n\"\n\
        [[shapes]]\ntype = \"rectangle\"\nmaterial = \"m\"\ntransform = [{ rotate = [1, 0, 0], angle = -90 }]\n";
    let (_dir, scene) = common::scene(toml, &[("n.png", &png)]);
    let (ray, _) = scene.camera.generate_ray(Vec2::new(4.5, 4.5), glam::Vec2::ZERO);
    let si = scene.intersect(&ray).unwrap();
    let material = &scene.materials[scene.shape_of(si.primitive).material as usize];
    let ctx = TexCtx { uv: si.uv, ..Default::default() };
    let bsdf = material.bsdf(&scene.textures, &ctx);
    let shading = material.shading(&scene.textures, &ctx, si.frame, si.dpdu, si.dpdv);
    let wo = shading.frame.to_local(si.wo);
    let expected = common::integrate_sphere(400, |w| {
        (bsdf.eval(wo, shading.frame.to_local(w)).x * shading.light_factor(w)) as f64
    });
    assert_mean(toml, &[("n.png", &png)], expected, 2e-3, "normal-mapped mirror");
}

/// A plane z = -3 seen head-on from the origin: the depth AOV of the ray through film point
/// (x, y) on the image plane at distance 1 (tan of half the field of view t) is
/// 3 sqrt(1 + x^2 + y^2) and its position (3x, 3y, -3); a pixel's AOVs average its samples, so
/// the expected values are averaged over the same jittered film points.
#[test]
fn depth_and_position_aovs_are_the_first_hit_s() {
    use tessera::image::Aov;
    let toml = r#"
        [render]
        width = 8
        height = 8
        spp = 16
        [camera]
        fov = 60
        eye = [0, 0, 0]
        target = [0, 0, -1]
        [environment]
        type = "constant"
        radiance = 1
        [materials.m]
        type = "diffuse"
        reflectance = 0.5
        [[shapes]]
        type = "rectangle"
        material = "m"
        transform = [{ scale = 20 }, { translate = [0, 0, -3] }]
    "#;
    let (_dir, scene) = scene(toml, &[]);
    let film = tessera::integrator::render(&scene, None, &[Aov::Depth, Aov::Position], &|_, _| {});
    let (depth, position) = (film.aov(Aov::Depth).unwrap(), film.aov(Aov::Position).unwrap());
    let t = (30.0f32).to_radians().tan();
    for (x, y) in [(0usize, 0usize), (3, 4), (7, 2)] {
        let p = position.pixel(x, y);
        // Every sample hits z = -3, and depth = |p| exactly for each; the pixel means keep
        // z = -3 and bound the depth between the nearest and farthest corner of the pixel.
        assert!((p.z + 3.0).abs() < 1e-5, "({x}, {y}): {p}");
        let corner = |i: f32, j: f32| {
            let (fx, fy) = ((2.0 * i / 8.0 - 1.0) * t, (1.0 - 2.0 * j / 8.0) * t);
            3.0 * (1.0 + fx * fx + fy * fy).sqrt()
        };
        let corners = [
            corner(x as f32, y as f32),
            corner(x as f32 + 1.0, y as f32),
            corner(x as f32, y as f32 + 1.0),
            corner(x as f32 + 1.0, y as f32 + 1.0),
        ];
        let (lo, hi) = corners.iter().fold((f32::MAX, 0.0f32), |(l, h), c| (l.min(*c), h.max(*c)));
        let d = depth.pixel(x, y).x;
        assert!(d >= lo - 1e-4 && d <= hi + 1e-4, "({x}, {y}): depth {d} outside [{lo}, {hi}]");
        // And the mean position's distance is within the same bounds.
        assert!(p.truncate().length() <= hi + 1e-4 && p.truncate().length() >= 3.0, "({x}, {y}): {p}");
    }
}

/// A diffuse floor (albedo rho, facing +y) seen straight down through a 1-degree field of view
/// around the origin, with direct light only, lit by `lights` (TOML) and `shapes` (extra
/// TOML shapes). Its radiance is rho / pi times the irradiance at the origin.
fn lit_floor(rho: f64, lights: &str, shapes: &str) -> String {
    format!(
        r#"
        [render]
        width = 8
        height = 8
        spp = 256
        max_depth = 2
        [camera]
        fov = 1
        eye = [0, 0.5, 0]
        target = [0, 0, 0]
        up = [0, 0, -1]
        [materials.floor]
        type = "diffuse"
        reflectance = {rho}
        [[shapes]]
        type = "rectangle"
        material = "floor"
        transform = [{{ scale = 10 }}, {{ rotate = [1, 0, 0], angle = -90 }}]
        {shapes}
        {lights}
        "#
    )
}

/// An emitting exact sphere (radius r, radiance L) whose centre is at distance d from the
/// floor's origin, at the angle beta from the normal, wholly above the horizon: it subtends a
/// cap of sin alpha = r / d, and E = pi L (r / d)^2 cos beta (the sphere's irradiance is that of
/// a point of intensity L pi r^2 at its centre). Light sampling picks directions in that cap;
/// BSDF samples hit it often, so the MIS weights of both must add up.
#[test]
fn sphere_light_over_a_floor_matches_its_irradiance() {
    let (rho, l, r) = (0.5, 2.0, 0.5);
    let (x, h) = (0.8f64, 1.5f64);
    let d = x.hypot(h);
    let light = format!("[[shapes]]\ntype = \"sphere\"\ncenter = [{x}, {h}, 0]\nradius = {r}\nemission = {l}");
    let expected = rho / PI * PI * l * (r / d).powi(2) * (h / d);
    assert_mean(&lit_floor(rho, "", &light), &[], expected, 1e-4, "sphere light");
}

/// Point and spot lights at height h = 2 over the floor: E = I s(theta) / h^2, with the spot's
/// profile s at the angle theta = 20 degrees between its axis and the floor's origin (beam 10,
/// cutoff 30): Mitsuba's (30 - 20) / (30 - 10) = 1/2, glTF's ((cos 20 - cos 30) /
/// (cos 10 - cos 30))^2. Delta lights are reached by light sampling alone, at full weight.
#[test]
fn point_and_spot_lights_over_a_floor_match_the_inverse_square_law() {
    let (rho, i, h) = (0.6, 5.0, 2.0);
    let point = "[[lights]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 5";
    assert_mean(&lit_floor(rho, point, ""), &[], rho / PI * i / (h * h), 1e-4, "point light");
    let t = 20f64.to_radians();
    let (sin, cos) = t.sin_cos();
    let spot = |falloff: &str| {
        format!(
            "[[lights]]\ntype = \"spot\"\nposition = [0, 2, 0]\ndirection = [{sin}, {}, 0]\nintensity = 5\n\
             cutoff_angle = 30\nbeam_width = 10\nfalloff = \"{falloff}\"",
            -cos
        )
    };
    let expected = rho / PI * i * 0.5 / (h * h);
    assert_mean(&lit_floor(rho, &spot("mitsuba"), ""), &[], expected, 1e-4, "Mitsuba's spot");
    let (c10, c30) = (10f64.to_radians().cos(), 30f64.to_radians().cos());
    let s = ((cos - c30) / (c10 - c30)).powi(2);
    assert_mean(&lit_floor(rho, &spot("gltf"), ""), &[], rho / PI * i * s / (h * h), 1e-4, "glTF's spot");
}

/// A directional light and suns 50 degrees from the zenith: E = E_n cos 50 (exact for a disc
/// wholly above the horizon). The 30-degree sun is large enough that BSDF samples hit it often,
/// so the two strategies' MIS weights must add up; the real sun's 0.533 degrees are reached by
/// light sampling almost alone.
#[test]
fn directional_lights_and_suns_over_a_floor_match_the_cosine_law() {
    let (rho, e) = (0.5, 3.0);
    let t = 50f64.to_radians();
    let direction = format!("[{}, {}, 0]", -t.sin(), -t.cos());
    let expected = rho / PI * e * t.cos();
    let directional = format!("[[lights]]\ntype = \"directional\"\ndirection = {direction}\nirradiance = 3");
    assert_mean(&lit_floor(rho, &directional, ""), &[], expected, 1e-4, "directional light");
    for diameter in [0.533, 30.0] {
        let sun = format!(
            "[[lights]]\ntype = \"sun\"\ndirection = {direction}\nirradiance = 3\nangular_diameter = {diameter}"
        );
        assert_mean(&lit_floor(rho, &sun, ""), &[], expected, 1e-4, &format!("sun of {diameter} degrees"));
    }
}

/// glTF `KHR_lights_punctual`, in the spec's units: a point light of 683 candela with a range
/// of 4 at height 2, and a spot of 683 cd pointing straight down (node rotated -90 degrees about
/// x; local -z is the spot's axis) at height 1 through the shape's own translation. At 683 lm/W
/// these are 1 W/sr; the range windows the point by (1 - (2/4)^4)^2.
#[test]
fn gltf_punctual_lights_arrive_in_the_spec_s_units_and_range() {
    let gltf = r#"{
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 683, "range": 4},
            {"type": "spot", "intensity": 683, "color": [0.5, 0.5, 0.5],
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}}
        ]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"translation": [0, 1.5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [0, 0.5, 0], "rotation": [-0.70710678, 0, 0, 0.70710678],
             "extensions": {"KHR_lights_punctual": {"light": 1}}}
        ]
    }"#;
    let rho = 0.5;
    let shape = "[[shapes]]\ntype = \"gltf\"\nfilename = \"lights.gltf\"\ntransform = [{ translate = [0, 0.5, 0] }]";
    let window = (1.0 - 0.5f64.powi(4)).powi(2);
    let expected = rho / PI * (window / 4.0 + 0.5 / 1.0);
    assert_mean(&lit_floor(rho, "", shape), &[("lights.gltf", gltf.as_bytes())], expected, 1e-4, "glTF lights");
    let without = shape.replace("transform", "lights = false\ntransform");
    // Without its lights the file holds nothing to render: an error that says so.
    let dir = common::scene_dir(&lit_floor(rho, "", &without), &[("lights.gltf", gltf.as_bytes())]);
    let err = common::load(dir.path()).err().expect("lights = false leaves the file's lights out").to_string();
    assert!(err.contains("lights.gltf") && err.contains("no triangle meshes and no punctual lights"), "{err}");
}
