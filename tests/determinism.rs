//! The same scene and seed give a bit-identical EXR whatever the number of threads, and whatever
//! passes the samples are rendered in.

mod common;

use std::sync::atomic::AtomicBool;
use tessera::image::Aov;
use tessera::image::write_image;
use tessera::integrator::{
    Crop, Ending, PassLimits, Path, PathTracer, WaveBuffers, render, render_in_passes, render_samples,
};
use tessera::sampling::PixelKey;

/// The shapes the test scenes share: a floor of material `floor`, and two emitters, an exact
/// sphere and a rectangle.
const FLOOR_AND_EMITTERS: &str = r#"
        [[shapes]]
        type = "rectangle"
        material = "floor"
        transform = [{ scale = 5 }, { rotate = [1, 0, 0], angle = -90 }, { translate = [0, -1, 0] }]
        [[shapes]]
        type = "sphere"
        center = [-1, 2, 1]
        radius = 0.3
        emission = 4
        [[shapes]]
        type = "rectangle"
        emission = 5
        transform = [{ scale = 0.5 }, { lookat = { origin = [1, 3, 1], target = [0, 0, 0] } }]
"#;

/// A 24 x 20 scene with everything that draws random numbers: area light and environment map
/// sampling, textures with every filter, glass, plastic, metal, glTF-style PBR and a normal map,
/// an emitting exact sphere, and Gaussian pixel filtering (samples around each pixel's centre).
fn everything_scene() -> String {
    let root = common::repo().join("scenes");
    format!(
        r#"
        [render]
        width = 24
        height = 20
        spp = 6
        seed = 7
        filter = {{ type = "gaussian" }}
        [camera]
        fov = 45
        eye = [0, 1.5, 4]
        target = [0, 0, 0]
        [environment]
        type = "envmap"
        filename = "{root}/textures/sky_512x256.exr"
        [textures.checker]
        type = "image"
        filename = "{root}/textures/checker.png"
        filter = "trilinear"
        [textures.brick]
        type = "image"
        filename = "{root}/textures/brick.png"
        filter = "ewa"
        scale = [2, 2]
        [materials.floor]
        type = "diffuse"
        reflectance = "checker"
        normal_map = "brick"
        [materials.glass]
        type = "dielectric"
        alpha = 0.1
        [materials.metal]
        type = "conductor"
        material = "Al"
        alpha_u = "brick"
        alpha_v = 0.3
        [materials.plastic]
        type = "plastic"
        diffuse_reflectance = "brick"
        [materials.pbr]
        type = "pbr"
        base_color = [0.8, 0.3, 0.2]
        metallic = 0.5
        roughness = "checker"
        [[shapes]]
        type = "uv_sphere"
        material = "glass"
        transform = [{{ scale = 0.5 }}, {{ translate = [-1.2, -0.5, 0] }}]
        [[shapes]]
        type = "uv_sphere"
        material = "metal"
        transform = [{{ scale = 0.5 }}, {{ translate = [0, -0.5, 0] }}]
        [[shapes]]
        type = "cube"
        material = "plastic"
        transform = [{{ scale = 0.4 }}, {{ translate = [1.2, -0.6, 0] }}]
        [[shapes]]
        type = "uv_sphere"
        material = "pbr"
        transform = [{{ scale = 0.3 }}, {{ translate = [0.6, 0.4, 0.5] }}]
        {FLOOR_AND_EMITTERS}
        "#,
        root = root.display()
    )
}

#[test]
fn exr_is_bit_identical_with_one_and_two_threads() {
    let (dir, scene) = common::scene(&everything_scene(), &[]);
    let mut files = Vec::new();
    for threads in [1, 2, 1] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let film = pool.install(|| render(&scene, None, &[], &|_, _| {}));
        let path = dir.path().join(format!("{threads}-{}.exr", files.len()));
        write_image(&path, &film.radiance(), &[]).unwrap();
        files.push(std::fs::read(&path).unwrap());
    }
    assert!(files[0] == files[1], "1 and 2 threads give different files");
    assert!(files[0] == files[2], "two runs with 1 thread give different files");
    // And the seed matters.
    let other = common::load(dir.path()).map(|mut s| {
        s.settings.seed = 8;
        render(&s, None, &[], &|_, _| {}).radiance()
    });
    let first = render(&scene, None, &[], &|_, _| {}).radiance();
    assert_ne!(other.unwrap().data, first.data, "a different seed should change the noise");

    // Rendered in passes (--time-limit, --checkpoint, Ctrl-C), with AOVs and a crop: the same
    // radiance, variance and AOVs, bit for bit, however 0..spp is split; a stopped pass leaves
    // the film as it was.
    let crop = Crop { x0: 3, y0: 2, x1: 21, y1: 17 };
    let aovs = [Aov::Albedo, Aov::Uv];
    let whole = render(&scene, Some(crop), &aovs, &|_, _| {});
    let never = AtomicBool::new(false);
    for splits in [&[0u32, 6][..], &[0, 1, 6], &[0, 2, 3, 5, 6], &[0, 1, 2, 3, 4, 5, 6]] {
        let mut film = tessera::image::Film::new(18, 15, &aovs);
        for range in splits.windows(2) {
            film = render_samples(&scene, crop, &film, range[0]..range[1], &|_, _| {}, &never).unwrap();
        }
        assert_eq!(film.samples_per_pixel(), Some(6));
        let same = |a: tessera::image::Bitmap, b: tessera::image::Bitmap| a.data == b.data;
        assert!(same(film.radiance(), whole.radiance()) && same(film.variance(), whole.variance()), "{splits:?}");
        assert!(aovs.iter().all(|a| same(film.aov(*a).unwrap(), whole.aov(*a).unwrap())), "{splits:?}");
    }
    let half = render_samples(&scene, crop, &tessera::image::Film::new(18, 15, &aovs), 0..3, &|_, _| {}, &never);
    let stopped = render_samples(&scene, crop, &half.unwrap(), 3..6, &|_, _| {}, &AtomicBool::new(true));
    assert!(stopped.is_none(), "a stopped pass gives no film");
    // In passes under a time limit, whole samples per pixel, as many as fit.
    let limits = PassLimits { time_limit: None, longest_pass: std::time::Duration::from_secs(30) };
    let empty = tessera::image::Film::new(18, 15, &aovs);
    let (film, spp, ending) = render_in_passes(&scene, crop, empty, limits, &never, &|_, _| {}, |_, _| Ok(())).unwrap();
    assert_eq!((spp, ending), (6, Ending::Complete));
    assert!(film.radiance().data == whole.radiance().data);
}

#[test]
fn a_path_traced_in_a_wave_is_the_path_traced_alone() {
    // The wavefront traces its camera rays as packets, then shades, shadow-tests and traces its
    // paths stage by stage; each path's radiance and first hit must be what it gives traced on
    // its own, bit for bit.
    let (_dir, scene) = common::scene(&everything_scene(), &[]);
    assert_wave_traces_each_path_as_alone(&scene, &PathTracer::new(&scene, true, true), 7);
}

/// Trace three samples of every pixel of `scene` (seed `seed`) as one wave with `tracer`, then
/// each path alone, and assert that each path's radiance and first hit are the same bit for bit
/// (and that most paths gathered light).
fn assert_wave_traces_each_path_as_alone(scene: &tessera::scene::Scene, tracer: &PathTracer, seed: u64) {
    let width = scene.settings.width;
    let start = |pixel: u32, sample: u32| -> Path {
        let mut sampler = PixelKey::new(seed, pixel as u64).sampler(sample);
        let film = glam::Vec2::new((pixel % width) as f32, (pixel / width) as f32) + sampler.next_2d();
        let (ray, diff) = scene.camera.generate_ray(film, glam::Vec2::ZERO);
        tracer.start(ray, diff, sampler)
    };
    let pixels = width * scene.settings.height;
    let starts: Vec<(u32, u32)> = (0..pixels).flat_map(|pixel| (0..3).map(move |sample| (pixel, sample))).collect();
    let mut wave: Vec<Path> = starts.iter().map(|&(pixel, sample)| start(pixel, sample)).collect();
    tracer.trace_wave(&mut wave, &mut WaveBuffers::default());
    let bits = |path: &Path| {
        let hit = path.first_hit.map(|h| (h.albedo.to_array(), h.normal.to_array(), h.uv.to_array(), h.depth));
        (path.radiance.to_array().map(f32::to_bits), format!("{hit:?}"))
    };
    let mut lit = 0;
    for (&(pixel, sample), together) in starts.iter().zip(&wave) {
        let mut alone = [start(pixel, sample)];
        tracer.trace_wave(&mut alone, &mut WaveBuffers::default());
        assert_eq!(bits(&alone[0]), bits(together), "pixel {pixel}, sample {sample}");
        lit += (together.radiance.max_element() > 0.0) as u32;
    }
    assert!(lit > 1000, "only {lit} of {} paths gathered light", wave.len());
}

/// A 24 x 20 scene whose surfaces the lanes shade (`integrator::lanes`): a rough conductor, a
/// textured diffuse floor and a two-sided diffuse card, under every kind of light the lanes
/// sample, in lanes (a mesh light, a constant sky) or lane by lane (a sphere light, a point
/// light, a sun).
fn lanes_scene() -> String {
    let root = common::repo().join("scenes");
    format!(
        r#"
        [render]
        width = 24
        height = 20
        spp = 6
        seed = 3
        [camera]
        fov = 45
        eye = [0, 1.5, 4]
        target = [0, 0, 0]
        [environment]
        type = "constant"
        radiance = [0.2, 0.3, 0.4]
        [textures.checker]
        type = "image"
        filename = "{root}/textures/checker.png"
        [materials.floor]
        type = "diffuse"
        reflectance = "checker"
        [materials.card]
        type = "diffuse"
        reflectance = [0.7, 0.6, 0.3]
        two_sided = true
        [materials.metal]
        type = "conductor"
        material = "Al"
        alpha_u = 0.05
        alpha_v = 0.3
        [[lights]]
        type = "point"
        position = [-2, 2.5, 1.5]
        intensity = [6, 5, 4]
        [[lights]]
        type = "directional"
        direction = [0.3, -1, -0.2]
        irradiance = 2
        [[shapes]]
        type = "uv_sphere"
        material = "metal"
        transform = [{{ scale = 0.6 }}, {{ translate = [-0.4, -0.4, 0] }}]
        [[shapes]]
        type = "rectangle"
        material = "card"
        transform = [{{ scale = 0.5 }}, {{ rotate = [0, 1, 0], angle = 120 }}, {{ translate = [1.0, -0.3, 0.3] }}]
        {FLOOR_AND_EMITTERS}
        "#,
        root = root.display()
    )
}

#[test]
fn a_path_shaded_in_lanes_is_the_path_shaded_alone() {
    // In a wave, the lanes shade eight paths at a time; alone, a path fills one lane of eight.
    // Nothing a lane computes may depend on the others: radiance bit for bit.
    let (_dir, scene) = common::scene(&lanes_scene(), &[]);
    let tracer = PathTracer::new(&scene, false, false);
    for (m, material) in scene.materials.iter().enumerate() {
        if material.name.starts_with("materials.") {
            assert!(tracer.shades_in_lanes(m as u32), "{} is not shaded in lanes", material.name);
        }
    }
    assert_wave_traces_each_path_as_alone(&scene, &tracer, 3);
}

#[test]
fn lanes_give_the_same_image_with_either_instruction_set() {
    // TESSERA_SIMD forces the lanes' instruction set: AVX2 and the portable SSE2 lanes run the
    // same IEEE operations in the same order, so the images are the same bit for bit.
    let dir = tempfile::tempdir().unwrap();
    let scene = common::repo().join("scenes/brushed_metal.toml");
    let render = |isa: &str| {
        let out = dir.path().join(format!("{isa}.exr"));
        let run = std::process::Command::new(env!("CARGO_BIN_EXE_tessera"))
            .env("TESSERA_SIMD", isa)
            .args(["render", "--quiet", "--spp", "2", "--crop", "96,160,416,352", "-o"])
            .arg(&out)
            .arg(&scene)
            .output()
            .unwrap();
        (run.status.success(), String::from_utf8_lossy(&run.stderr).into_owned(), out)
    };
    let (ok, stderr, portable) = render("portable");
    assert!(ok, "{stderr}");
    if tessera::simd::Isa::Avx2.available() {
        let (ok, stderr, avx2) = render("avx2");
        assert!(ok, "{stderr}");
        assert!(std::fs::read(&portable).unwrap() == std::fs::read(&avx2).unwrap(), "AVX2 and portable images differ");
    } else {
        eprintln!("this CPU has no AVX2: only the portable lanes were rendered");
    }
    let (ok, stderr, _) = render("sse4");
    assert!(!ok && stderr.contains("TESSERA_SIMD") && stderr.contains("expected avx2 or portable"), "{stderr}");
}
