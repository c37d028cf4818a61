//! `tessera bench`: throughput figures, each the median of repeated runs (the machines this
//! runs on are small and noisy).
//!
//! - Ray casting on a procedural mesh of 261k triangles (a UV sphere 512 x 256 with folds):
//!   closest-hit Mrays/s for coherent primary rays (a 1024 x 1024 pinhole view) and for incoherent
//!   rays (cosine-distributed bounces from the primary hits), on one thread and on all.
//! - A full render of `scenes/brushed_metal.toml` (Mitsuba scene A: 512 x 512, 64 spp, max
//!   depth 8): samples per second, against Mitsuba 3's figures measured on this kind of machine.

use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;
use tessera::accel::Accel;
use tessera::camera::{FovAxis, PerspectiveCamera};
use tessera::error::{Error, Result};
use tessera::geometry::{Frame, Ray, offset_ray_origin, shapes};
use tessera::integrator::render;
use tessera::sampling::{Sampler, warp};
use tessera::scene::{SceneOverrides, load_scene};

/// Mitsuba 3.9.1 on scene A, 512 x 512 at 64 spp on 2 cores (`../shared/tools/mitsuba/README.md`).
const MITSUBA_LLVM_MSAMPLES: f64 = 5.0;
const MITSUBA_SCALAR_MSAMPLES: f64 = 2.0;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

/// The benchmark mesh: a UV sphere whose radius is modulated, so that the BVH sees folds.
fn folded_sphere() -> Vec<[glam::Vec3; 3]> {
    let mut mesh = shapes::uv_sphere(512, 256);
    for p in &mut mesh.positions {
        let (theta, phi) = (p.y.clamp(-1.0, 1.0).acos(), p.z.atan2(p.x));
        *p *= 1.0 + 0.08 * (9.0 * theta).sin() * (13.0 * phi).sin();
    }
    (0..mesh.triangle_count()).map(|i| mesh.triangle(i)).collect()
}

/// Time `f(rays)` over `runs` runs; Mrays/s per run.
fn rays_per_second(runs: usize, rays: &[Ray], f: impl Fn(&[Ray]) -> usize) -> (f64, usize) {
    let mut rates = Vec::new();
    let mut hits = 0;
    for _ in 0..runs {
        let start = Instant::now();
        hits = f(rays);
        rates.push(rays.len() as f64 / start.elapsed().as_secs_f64() / 1e6);
    }
    (median(rates), hits)
}

/// Run the benchmarks and print a table. `scene_dir` holds the shipped scenes.
pub fn run(scene_dir: &Path, runs: usize, threads: usize) -> Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::param("--threads", e.to_string()))?;
    let threads = pool.current_num_threads();
    println!("tessera bench: medians of {runs} runs, {threads} threads where parallel");

    let tris = folded_sphere();
    let start = Instant::now();
    let accel = Accel::build(&tris);
    println!("accel      build {} triangles: {:.3} s", tris.len(), start.elapsed().as_secs_f64());

    // Primary rays: 1024 x 1024 pixel centres of a camera looking at the mesh.
    let view = PerspectiveCamera::look_at(glam::Vec3::new(0.4, 0.9, 3.2), glam::Vec3::ZERO, glam::Vec3::Y)?;
    let camera = PerspectiveCamera::new(view, 45.0, FovAxis::Y, 1024, 1024, 1)?;
    let primary: Vec<Ray> = (0..1024 * 1024)
        .map(|i| camera.generate_ray(glam::Vec2::new((i % 1024) as f32 + 0.5, (i / 1024) as f32 + 0.5)).0)
        .collect();
    // Incoherent rays: a cosine-distributed bounce from each primary hit.
    let incoherent: Vec<Ray> = primary
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let hit = accel.intersect(r)?;
            let [a, b, c] = tris[hit.triangle as usize];
            let n = (b - a).cross(c - a).normalize();
            let n = if n.dot(r.d) > 0.0 { -n } else { n };
            let p = r.at(hit.t);
            let d = Frame::from_normal(n)
                .to_world(warp::square_to_cosine_hemisphere(Sampler::new(1, i as u64, 0).next_2d()));
            Some(Ray::new(offset_ray_origin(p, n, d), d))
        })
        .collect();
    let closest_serial = |rays: &[Ray]| rays.iter().filter(|r| accel.intersect(r).is_some()).count();
    let closest_parallel =
        |rays: &[Ray]| pool.install(|| rays.par_iter().filter(|r| accel.intersect(r).is_some()).count());
    for (name, rays) in [("primary", &primary), ("incoherent", &incoherent)] {
        let (one, hits) = rays_per_second(runs, rays, closest_serial);
        let (all, _) = rays_per_second(runs, rays, closest_parallel);
        println!(
            "rays       {name:<10} {:>8} rays ({:>3.0}% hit): {one:6.2} Mrays/s on 1 thread, {all:6.2} on {threads}",
            rays.len(),
            100.0 * hits as f64 / rays.len() as f64
        );
    }

    let scene_path = scene_dir.join("brushed_metal.toml");
    let scene = load_scene(&scene_path, &SceneOverrides::default())?;
    let s = scene.settings;
    let mut rates = Vec::new();
    for _ in 0..runs {
        let start = Instant::now();
        let film = pool.install(|| render(&scene, None, &[], &|_, _| {}));
        rates.push(film.sample_count() as f64 / start.elapsed().as_secs_f64() / 1e6);
    }
    let rate = median(rates);
    println!(
        "render     {} ({}x{}, {} spp, max depth {}): {rate:.2} M samples/s on {threads} threads",
        scene_path.display(),
        s.width,
        s.height,
        s.spp,
        s.max_depth.map_or("unlimited".into(), |d| d.to_string())
    );
    println!(
        "           vs Mitsuba 3.9.1 on 2 cores (measured separately): llvm_ad_rgb {MITSUBA_LLVM_MSAMPLES} -> {:.2}x, \
         scalar_rgb {MITSUBA_SCALAR_MSAMPLES} -> {:.2}x (target 1.5x llvm)",
        rate / MITSUBA_LLVM_MSAMPLES,
        rate / MITSUBA_SCALAR_MSAMPLES
    );
    Ok(())
}
