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
        type = "rectangle"
        material = "floor"
        transform = [{{ scale = 5 }}, {{ rotate = [1, 0, 0], angle = -90 }}, {{ translate = [0, -1, 0] }}]
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
        [[shapes]]
        type = "sphere"
        center = [-1, 2, 1]
        radius = 0.3
        emission = 4
        [[shapes]]
        type = "rectangle"
        emission = 5
        transform = [{{ scale = 0.5 }}, {{ lookat = {{ origin = [1, 3, 1], target = [0, 0, 0] }} }}]
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
    let tracer = PathTracer::new(&scene, true, true);
    let start = |pixel: u32, sample: u32| -> Path {
        let mut sampler = PixelKey::new(7, pixel as u64).sampler(sample);
        let film = glam::Vec2::new((pixel % 24) as f32, (pixel / 24) as f32) + sampler.next_2d();
        let (ray, diff) = scene.camera.generate_ray(film, glam::Vec2::ZERO);
        tracer.start(ray, diff, sampler)
    };
    let starts: Vec<(u32, u32)> = (0..24 * 20).flat_map(|pixel| (0..3).map(move |sample| (pixel, sample))).collect();
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
