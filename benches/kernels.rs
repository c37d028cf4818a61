//! Micro-benchmarks of the renderer's hot kernels (criterion): BVH queries on the geometry of
//! `scenes/brushed_metal.toml`, BSDF sampling, and texture lookups per filter. Whole-render and
//! ray-throughput figures are `tessera bench`.
//!
//! Run with `cargo bench --bench kernels`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use std::hint::black_box;
use tessera::bsdf::{Bsdf, Conductor, ConductorFresnel, Diffuse, Ggx, PlasticTables};
use tessera::color::Rgb;
use tessera::geometry::Ray;
use tessera::image::{ColorSpace, read_bitmap};
use tessera::sampling::{Sampler, warp};
use tessera::scene::{SceneOverrides, load_scene};
use tessera::texture::{Filter, MipMap};

fn accel(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/brushed_metal.toml");
    let scene = load_scene(&path, &SceneOverrides::default()).expect("shipped scene");
    let (w, h) = (128u32, 128u32);
    let camera_rays: Vec<Ray> = (0..w * h)
        .map(|i| {
            let film = Vec2::new((i % w) as f32 * 4.0 + 2.0, (i / w) as f32 * 4.0 + 2.0);
            scene.camera.generate_ray(film, glam::Vec2::ZERO).0
        })
        .collect();
    let bounce_rays: Vec<Ray> = camera_rays
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let si = scene.intersect(r)?;
            let d = si.frame.to_world(warp::square_to_cosine_hemisphere(Sampler::new(0, i as u64, 0).next_2d()));
            Some(si.spawn_ray(d))
        })
        .collect();
    c.bench_function("accel/closest camera rays (16k)", |b| {
        b.iter(|| camera_rays.iter().filter(|r| scene.accel.intersect(black_box(r)).is_some()).count())
    });
    c.bench_function("accel/closest bounce rays", |b| {
        b.iter(|| bounce_rays.iter().filter(|r| scene.accel.intersect(black_box(r)).is_some()).count())
    });
    c.bench_function("accel/occluded bounce rays", |b| {
        b.iter(|| bounce_rays.iter().filter(|r| scene.accel.occluded(black_box(r))).count())
    });
}

fn bsdf(c: &mut Criterion) {
    let tables = PlasticTables::new(1.5, &PlasticTables::alpha_grid());
    let models = [
        ("diffuse", Bsdf::Diffuse(Diffuse { reflectance: Rgb::splat(0.5) })),
        (
            "conductor aniso",
            Bsdf::Conductor(Conductor {
                ggx: Some(Ggx::new(0.05, 0.3)),
                fresnel: ConductorFresnel::Complex { eta: Rgb::new(1.66, 0.88, 0.52), k: Rgb::new(9.22, 6.27, 4.84) },
                specular_reflectance: Rgb::ONE,
            }),
        ),
        ("pbr", Bsdf::Pbr(tessera::bsdf::Pbr::isotropic(Rgb::splat(0.7), 0.5, 0.2, &tables))),
    ];
    let wo = Vec3::new(0.3, 0.2, 0.93).normalize();
    for (name, b) in &models {
        c.bench_function(&format!("bsdf/{name} sample+eval+pdf"), |bench| {
            let mut i = 0u32;
            bench.iter(|| {
                i = i.wrapping_add(1);
                let mut s = Sampler::new(0, 0, i);
                let sample = b.sample(black_box(wo), s.next_1d(), s.next_2d());
                sample.map(|x| (b.eval(wo, x.wi), b.pdf(wo, x.wi)))
            })
        });
    }
}

fn texture(c: &mut Criterion) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/textures/brick.png");
    let mip = MipMap::new(read_bitmap(&path, ColorSpace::Srgb).expect("shipped texture"));
    for filter in [Filter::None, Filter::Trilinear, Filter::Ewa] {
        c.bench_function(&format!("texture/{filter:?} lookup (footprint 3 x 1 texels)"), |b| {
            let mut i = 0u32;
            b.iter(|| {
                i = i.wrapping_add(1);
                let st = Sampler::new(1, 0, i).next_2d();
                mip.lookup(
                    filter,
                    black_box(st),
                    Vec2::new(3.0 / 512.0, 0.5 / 512.0),
                    Vec2::new(-0.3 / 512.0, 1.0 / 512.0),
                )
            })
        });
    }
}

criterion_group!(benches, accel, bsdf, texture);
criterion_main!(benches);
