//! `tessera bench`: throughput figures, each the median of repeated runs (the machines this
//! runs on are small and noisy).
//!
//! - Ray casting on a procedural mesh of 261k triangles (a UV sphere 512 x 256 with folds):
//!   closest-hit Mrays/s for coherent primary rays (a 1024 x 1024 pinhole view) and for incoherent
//!   rays (cosine-distributed bounces from the primary hits), on one thread and on all. And scene
//!   A's first bounces from its ground ([`ground_bounces`]), traced as the wavefront's batches
//!   are, closest hits and occlusion, on all threads: `reference/time_mitsuba_rays.py` times
//!   Mitsuba 3 (Embree) on rays drawn alike.
//! - A full render of `scenes/brushed_metal.toml` (Mitsuba scene A: 512 x 512, 64 spp, max
//!   depth 8): samples per second, against Mitsuba 3's figures measured on this kind of machine.
//! - Shading arithmetic in SIMD lanes (issue 19): scene A's aluminium at 1M directions, GGX
//!   visible-normal sampling alone, the conductor's sample and evaluation with their Fresnel
//!   colours, and the diffuse BSDF's, one at a time as the path tracer calls them and eight at a time in lanes
//!   (portable, and AVX2 where the CPU has it), on one thread, as ratios to the first.
//! - `tessera deform`'s computation (deformation gradients, polar decompositions, orientation,
//!   a 256 x 256 smoothing grid, a 1024 x 1024 F map) on a lat-long UV sphere of 262k
//!   triangles, one thread.
//! - Texture lookups on one thread, all on the same exemplar (`scenes/textures/bark.jpg`,
//!   trilinear) and the same 1M lookups (a raster in scanline order, random footprints): the bitmap itself, classical
//!   tiling and blending, and deformed tiling and blending with a 256 x 256 F map, for the
//!   linear and Mix-Max operators; printed as lookups per second and as cost ratios to the bitmap
//!   measured in the same run.
//! - Paper 001's tiles: `tessera tiles map`'s mapping (edge adjacency, AssignBoundaries,
//!   AssignTextureCoordinates) of a generated torus of 1M quads on one thread, with the peak
//!   memory it adds (Linux), against pairing the same edges through a hash map; and the
//!   synthesis of a 4 x 4 tile image of 256-texel tiles from `scenes/textures/rocks_basecolor.jpg`,
//!   against resampling as many texels bilinearly.
//! - The WGSL port (feature `gpu`): bakes of 4096 x 4096 point lookups of tiling and blending
//!   of a 1024 x 1024 RGBA f32 exemplar (bilinear), classical and deformed by a 256 x 256 F map,
//!   linear and Mix-Max, as `../shared/tools/gpu/tb_cuda.py` measures its CUDA yardstick; and
//!   the deformed texture with EWA at one-texel footprints. Printed as lookups per second and
//!   as ratios to the CPU bake of the same texture (512 x 512, all threads) in the same run.
//! - Paper 002's PUPs: the paper's case, a 1000 x 1000 image of the `noise` preset from 700
//!   control points (the paper reports 30 s), and single lookups per second against the bitmap
//!   lookup of the texture figures, measured in the same run.

use glam::{Mat2, Vec2, Vec3};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;
use tessera::accel::{Accel, AccelKind, Queries};
use tessera::bsdf::fresnel::fresnel_conductor_of;
use tessera::bsdf::{Conductor, ConductorFresnel, Diffuse, Ggx};
use tessera::camera::{Camera, CameraModel, FovAxis};
use tessera::color::Rgb;
use tessera::error::{Error, Result};
use tessera::geometry::{Frame, Ray, offset_ray_origin, shapes};
use tessera::image::{Bitmap, ColorSpace, read_bitmap};
use tessera::integrator::render;
use tessera::sampling::{Sampler, warp};
use tessera::scene::{SceneOverrides, load_scene};
use tessera::simd::{F32x8, Isa, Real, V3};
use tessera::texture::tiling_blending::{Blend, Deformation, DeformationField, PriorityMap, Synthesis, Tiling};
use tessera::texture::{Filter, ImageTexture, MipMap, TexCtx, Texture, TilingBlending};

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

/// Which figures `tessera bench` measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Suite {
    /// Ray casting throughput.
    Rays,
    /// The full render of scene A.
    Render,
    /// Texture lookups: bitmap, classical and deformed tiling and blending.
    Textures,
    /// Shading arithmetic in SIMD lanes: scene A's conductor one path at a time and eight at a
    /// time, portable and AVX2.
    Lanes,
    /// `tessera deform` on a mesh of 262k triangles.
    Deform,
    /// Paper 001: mapping 1M quads, synthesising 16 tiles of 256 texels.
    Tiles,
    /// Paper 002: a 1000 x 1000 PUPs image from 700 points; lookups per second.
    Pups,
    /// The WGSL port on the GPU (feature `gpu`): deformed T&B lookups per second against the
    /// CPU bake of the same texture.
    Gpu,
}

/// Run the benchmarks of `suites` and print a table. `scene_dir` holds the shipped scenes.
pub fn run(scene_dir: &Path, runs: usize, threads: usize, suites: &[Suite]) -> Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::param("--threads", e.to_string()))?;
    let threads = pool.current_num_threads();
    println!("tessera bench: medians of {runs} runs, {threads} threads where parallel");
    if suites.contains(&Suite::Rays) {
        rays(runs, &pool)?;
        scene_a_bounces(scene_dir, runs, &pool)?;
    }
    if suites.contains(&Suite::Render) {
        render_scene_a(scene_dir, runs, &pool)?;
    }
    if suites.contains(&Suite::Textures) {
        textures(scene_dir, runs)?;
    }
    if suites.contains(&Suite::Lanes) {
        lanes(runs);
    }
    if suites.contains(&Suite::Deform) {
        deform(runs)?;
    }
    if suites.contains(&Suite::Tiles) {
        tiles(scene_dir, runs, &pool)?;
    }
    if suites.contains(&Suite::Pups) {
        pups(scene_dir, runs, &pool)?;
    }
    if suites.contains(&Suite::Gpu) {
        gpu(runs, &pool)?;
    }
    Ok(())
}

fn rays(runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    let threads = pool.current_num_threads();

    let tris = folded_sphere();
    let builds: Vec<(AccelKind, Accel, f64)> = AccelKind::ALL
        .iter()
        .map(|&kind| {
            let start = Instant::now();
            let accel = Accel::build_kind(&tris, &[], &[], kind);
            (kind, accel, start.elapsed().as_secs_f64())
        })
        .collect();
    // The rays are made with the first kind (tessera's own), so that every kind sees the same.
    let accel = &builds[0].1;

    // Primary rays: 1024 x 1024 pixel centres of a camera looking at the mesh.
    let view = Camera::look_at(glam::Vec3::new(0.4, 0.9, 3.2), glam::Vec3::ZERO, glam::Vec3::Y)?;
    let camera = Camera::new(view, CameraModel::pinhole(45.0, FovAxis::Y), 1024, 1024, 1)?;
    let primary: Vec<Ray> = (0..1024 * 1024)
        .map(|i| {
            camera.generate_ray(glam::Vec2::new((i % 1024) as f32 + 0.5, (i / 1024) as f32 + 0.5), glam::Vec2::ZERO).0
        })
        .collect();
    // Incoherent rays: a cosine-distributed bounce from each primary hit.
    let incoherent: Vec<Ray> = primary
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let hit = accel.intersect(r)?;
            let [a, b, c] = tris[hit.primitive as usize];
            let n = (b - a).cross(c - a).normalize();
            let n = if n.dot(r.d) > 0.0 { -n } else { n };
            let p = r.at(hit.t);
            let d = Frame::from_normal(n)
                .to_world(warp::square_to_cosine_hemisphere(Sampler::new(1, i as u64, 0).next_2d()));
            Some(Ray::new(offset_ray_origin(p, n, d), d))
        })
        .collect();
    // A pixel's camera rays: 8 jittered rays through each of 512 x 512 pixels, traced one by one
    // and as the batches the renderer hands `intersect_many`.
    let pixel_samples: Vec<Ray> = (0..512 * 512 * 8)
        .map(|i| {
            let pixel = i / 8;
            let jitter = Sampler::new(2, pixel as u64, i as u32 % 8).next_2d();
            let film = glam::Vec2::new((pixel % 512) as f32 * 2.0, (pixel / 512) as f32 * 2.0) + jitter;
            camera.generate_ray(film, glam::Vec2::ZERO).0
        })
        .collect();
    for (kind, accel, build_seconds) in &builds {
        println!("accel      {kind:?} build, {} triangles: {build_seconds:.3} s", tris.len());
        let closest_serial = |rays: &[Ray]| rays.iter().filter(|r| accel.intersect(r).is_some()).count();
        let closest_parallel =
            |rays: &[Ray]| pool.install(|| rays.par_iter().filter(|r| accel.intersect(r).is_some()).count());
        for (name, rays) in [("primary", &primary), ("incoherent", &incoherent)] {
            let (one, hits) = rays_per_second(runs, rays, closest_serial);
            let (all, _) = rays_per_second(runs, rays, closest_parallel);
            println!(
                "rays       {kind:?} {name:<10} {:>8} rays ({:>3.0}% hit): {one:6.2} Mrays/s on 1 thread, {all:6.2} on {threads}",
                rays.len(),
                100.0 * hits as f64 / rays.len() as f64
            );
        }
        let batched = |rays: &[Ray]| {
            let mut hits = [None; 8];
            rays.chunks(8)
                .map(|batch| {
                    accel.intersect_many(batch, &mut hits[..batch.len()]);
                    hits[..batch.len()].iter().filter(|h| h.is_some()).count()
                })
                .sum()
        };
        let (alone, _) = rays_per_second(runs, &pixel_samples, closest_serial);
        let (together, _) = rays_per_second(runs, &pixel_samples, batched);
        println!(
            "rays       {kind:?} 8 per pixel {:>8} rays: {alone:6.2} Mrays/s one by one, {together:6.2} in batches ({:.2}x), 1 thread",
            pixel_samples.len(),
            together / alone
        );
    }
    Ok(())
}

/// Rays of scene A's first bounces from its ground, as `reference/time_mitsuba_rays.py` draws
/// them for Mitsuba: `count` origins uniform over x, z in [-3, 3], 1e-4 above the ground
/// (y = -1), in cosine-distributed directions about +y. Most leave the scene at once.
fn ground_bounces(count: usize) -> Vec<Ray> {
    (0..count)
        .map(|i| {
            let mut sampler = Sampler::new(5, i as u64, 0);
            let at = sampler.next_2d() * 6.0 - 3.0;
            let d = warp::square_to_cosine_hemisphere(sampler.next_2d());
            Ray::new(Vec3::new(at.x, -1.0 + 1e-4, at.y), Vec3::new(d.x, d.z, d.y))
        })
        .collect()
}

/// Scene A's first bounces from the ground ([`ground_bounces`], 2^21 rays) traced in batches of
/// 1,024, as the wavefront hands them to `Queries::intersect_each` and `occluded_each`, on all
/// threads: Mrays/s for each backend.
fn scene_a_bounces(scene_dir: &Path, runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    let scene = load_scene(&scene_dir.join("brushed_metal.toml"), &SceneOverrides::default())?;
    let triangles = scene.geometry.all_triangle_positions();
    let rays = ground_bounces(1 << 21);
    for &kind in AccelKind::ALL {
        let accel = Accel::build_kind(&triangles, &scene.geometry.emitting_triangles(), &scene.geometry.spheres, kind);
        let closest = |rays: &[Ray]| {
            in_batches(pool, &accel, rays, None, |q, batch, hits| q.intersect_each(batch, hits), Option::is_some)
        };
        let blocked = |rays: &[Ray]| {
            in_batches(pool, &accel, rays, false, |q, batch, blocked| q.occluded_each(batch, blocked), |&b| b)
        };
        let (closest, hits) = rays_per_second(runs, &rays, closest);
        let (occluded, _) = rays_per_second(runs, &rays, blocked);
        println!(
            "rays       {kind:?} scene A ground bounces {} rays ({:.0}% hit): closest {closest:6.2} Mrays/s, occluded {occluded:6.2}, {} threads",
            rays.len(),
            100.0 * hits as f64 / rays.len() as f64,
            pool.current_num_threads()
        );
    }
    Ok(())
}

/// `query` over `rays` in batches of 1,024 on `pool`, as the wavefront hands its rays over
/// (each answer starting as `empty`); how many answers `counted` picks.
fn in_batches<A: Copy + Send + Sync>(
    pool: &rayon::ThreadPool,
    accel: &Accel,
    rays: &[Ray],
    empty: A,
    query: impl Fn(&mut Queries, &[Ray], &mut [A]) + Sync,
    counted: impl Fn(&A) -> bool + Sync,
) -> usize {
    pool.install(|| {
        rays.par_chunks(1024)
            .map_init(Vec::new, |answers, batch| {
                answers.clear();
                answers.resize(batch.len(), empty);
                accel.queries(|q| query(q, batch, answers));
                answers.iter().filter(|a| counted(a)).count()
            })
            .sum()
    })
}

fn render_scene_a(scene_dir: &Path, runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    let threads = pool.current_num_threads();
    let scene_path = scene_dir.join("brushed_metal.toml");
    let mut scene = load_scene(&scene_path, &SceneOverrides::default())?;
    let s = scene.settings;
    let triangles = scene.geometry.all_triangle_positions();
    for &kind in AccelKind::ALL {
        scene.accel =
            Accel::build_kind(&triangles, &scene.geometry.emitting_triangles(), &scene.geometry.spheres, kind);
        let mut rates = Vec::new();
        for _ in 0..runs {
            let start = Instant::now();
            let film = pool.install(|| render(&scene, None, &[], &|_, _| {}));
            rates.push(film.sample_count() as f64 / start.elapsed().as_secs_f64() / 1e6);
        }
        let rate = median(rates);
        println!(
            "render     {} ({}x{}, {} spp, max depth {}), {kind:?}: {rate:.2} M samples/s on {threads} threads",
            scene_path.display(),
            s.width,
            s.height,
            s.spp,
            s.max_depth.map_or("unlimited".into(), |d| d.to_string()),
        );
        println!(
            "           vs Mitsuba 3.9.1 on 2 cores (measured separately): llvm_ad_rgb {MITSUBA_LLVM_MSAMPLES} -> {:.2}x, \
             scalar_rgb {MITSUBA_SCALAR_MSAMPLES} -> {:.2}x (target 1.5x llvm); \
             measured in one session, alternating: python3 reference/bench.py",
            rate / MITSUBA_LLVM_MSAMPLES,
            rate / MITSUBA_SCALAR_MSAMPLES
        );
    }
    Ok(())
}

/// Lookups per second (millions) of `texture` over `lookups`, median of `runs`.
fn lookups_per_second(runs: usize, texture: &Texture, lookups: &[TexCtx]) -> f64 {
    median((0..runs).map(|_| lookup_rate(texture, lookups)).collect())
}

/// Lookups per second (millions) of `texture` over `lookups`, once.
fn lookup_rate(texture: &Texture, lookups: &[TexCtx]) -> f64 {
    let start = Instant::now();
    let sum: f32 = lookups.iter().map(|ctx| texture.eval(std::hint::black_box(ctx)).x).sum();
    std::hint::black_box(sum);
    lookups.len() as f64 / start.elapsed().as_secs_f64() / 1e6
}

/// Each texture's lookups per second (millions) over `lookups` in `runs` alternating rounds (a
/// round times each texture once, one after the other): per texture, the rate of each round.
/// Ratios taken round by round cancel a machine whose speed drifts over the benchmark.
fn lookup_rates_alternating(runs: usize, textures: &[&Texture], lookups: &[TexCtx]) -> Vec<Vec<f64>> {
    let mut rates = vec![Vec::with_capacity(runs); textures.len()];
    for _ in 0..runs {
        for (texture, rates) in textures.iter().zip(&mut rates) {
            rates.push(lookup_rate(texture, lookups));
        }
    }
    rates
}

/// The median over rounds of the ratio `numerator[r] / denominator[r]`.
fn median_ratio(numerator: &[f64], denominator: &[f64]) -> f64 {
    median(numerator.iter().zip(denominator).map(|(n, d)| n / d).collect())
}

fn textures(scene_dir: &Path, runs: usize) -> Result<()> {
    let file = scene_dir.join("textures/bark.jpg");
    let exemplar = Arc::new(Texture::Image(ImageTexture {
        mipmap: Arc::new(MipMap::new(read_bitmap(&file, ColorSpace::Srgb)?)),
        filter: Filter::Trilinear,
        scale: Vec2::ONE,
        offset: Vec2::ZERO,
    }));
    let Texture::Image(image) = exemplar.as_ref() else { unreachable!("built as an image") };
    // An F map of a smooth rotation-and-scale field, as `tessera deform` would write one.
    let n = 256;
    let mut map = Bitmap::new(n, n, 4);
    for (i, px) in map.data.chunks_exact_mut(4).enumerate() {
        let (x, y) = ((i % n) as f32 / n as f32, (i / n) as f32 / n as f32);
        let f = Mat2::from_angle(3.0 * x + y);
        px.copy_from_slice(&[f.x_axis.x, f.y_axis.x, f.x_axis.y, f.y_axis.y]);
    }
    let deformation = DeformationField::new(vec![Deformation::Map(MipMap::new(map))]);
    // The points of a 1024 x 1024 raster over 4 x 4 UV units, in scanline order as a render
    // reaches them, each with a footprint 1/4 to 4 raster steps wide in any direction.
    let lookups: Vec<TexCtx> = (0..1024 * 1024)
        .map(|i| {
            let mut s = Sampler::new(7, i, 0);
            let uv = (Vec2::new((i % 1024) as f32, (i / 1024) as f32) + s.next_2d()) * (4.0 / 1024.0);
            let width = (4.0 / 1024.0) * 0.25 * 16f32.powf(s.next_1d());
            let dx = Vec2::from_angle(s.next_1d() * std::f32::consts::TAU) * width;
            TexCtx { uv, duv_dx: dx, duv_dy: dx.perp() * (0.3 + 0.7 * s.next_1d()), uv_mirrored: None }
        })
        .collect();
    let blends = [
        ("linear", Blend::Linear),
        ("mix-max", Blend::MixMax { priority: PriorityMap::new(image), contrast: 4.0, lambda: 0.05 }),
    ];
    // Per blend, the classical and the deformed synthesis.
    let mut syntheses = Vec::new();
    for (name, blend) in &blends {
        let synthesis = |deformation: Option<DeformationField>| {
            let s = Synthesis {
                tiling: Tiling::Hexagonal,
                tile_size: 0.25,
                seed: 1,
                deformation,
                cuts: None,
                blend: blend.clone(),
                inset: false,
            };
            TilingBlending::new(Arc::new(s), exemplar.clone())
                .map(Texture::TilingBlending)
                .map_err(|e| Error::param("bench", e))
        };
        syntheses.push((name, synthesis(None)?, synthesis(Some(deformation.clone()))?));
    }
    let mut textures = vec![exemplar.as_ref()];
    for (_, classical, deformed) in &syntheses {
        textures.extend([classical, deformed]);
    }
    let rates = lookup_rates_alternating(runs, &textures, &lookups);
    let bitmap = &rates[0];
    println!(
        "textures   {} lookups on 1 thread, exemplar {} (trilinear), {runs} alternating rounds: medians, and \
         costs as medians of each round's ratio:",
        lookups.len(),
        file.display()
    );
    println!(
        "           bitmap                         {:7.2} M lookups/s  (1.00x the bitmap's cost)",
        median(bitmap.clone())
    );
    for ((name, _, _), rates) in syntheses.iter().zip(rates[1..].chunks(2)) {
        let [classical, deformed] = rates else { unreachable!("two syntheses a blend") };
        println!(
            "           classical T&B, {name:<8}        {:7.2} M lookups/s  ({:.2}x the bitmap's cost)",
            median(classical.clone()),
            median_ratio(bitmap, classical)
        );
        println!(
            "           deformed T&B (F map), {name:<8} {:7.2} M lookups/s  ({:.2}x the bitmap's cost, {:.2}x classical; targets 4x, 1.3x)",
            median(deformed.clone()),
            median_ratio(bitmap, deformed),
            median_ratio(classical, deformed)
        );
    }
    Ok(())
}

/// Scene A's aluminium (alpha 0.05 x 0.3) at 1M directions wo over the upper hemisphere, one
/// at a time as the path tracer calls it and eight at a time in lanes with each instruction set
/// this CPU has: GGX's visible-normal sampling alone, and what a path's vertex asks of the
/// conductor and of the floor's diffuse BSDF (a sample, with its colour, and f and the density
/// at a light's direction).
fn lanes(runs: usize) {
    let ggx = Ggx::new(0.05, 0.3);
    let (eta, k) = tessera::material::named_conductor("Al").expect("a named conductor");
    let conductor =
        Conductor { ggx: Some(ggx), fresnel: ConductorFresnel::Complex { eta, k }, specular_reflectance: Rgb::ONE };
    let n = 1 << 20;
    let mut sampler = Sampler::new(3, 0, 0);
    let mut direction = || warp::square_to_cosine_hemisphere(sampler.next_2d());
    let inputs: Vec<[Vec3; 3]> = (0..n).map(|_| [direction(), direction(), direction()]).collect();
    let lanes: Vec<[V3<F32x8>; 3]> = inputs
        .chunks_exact(8)
        .map(|c| {
            std::array::from_fn(|j| {
                V3::new(F32x8::from_fn(|i| c[i][j].x), F32x8::from_fn(|i| c[i][j].y), F32x8::from_fn(|i| c[i][j].z))
            })
        })
        .collect();
    // The sample numbers are the third direction's x and y, mapped to [0, 1).
    let u = |w: Vec3| Vec2::new(0.5 + 0.5 * w.x, 0.5 + 0.5 * w.y);
    let u_lanes =
        |w: V3<F32x8>| [F32x8::splat(0.5) + F32x8::splat(0.5) * w.x, F32x8::splat(0.5) + F32x8::splat(0.5) * w.y];
    let isas: Vec<Isa> = [Isa::Portable, Isa::Avx2].into_iter().filter(|isa| isa.available()).collect();
    println!(
        "lanes      scene A's BSDFs (aluminium, alpha 0.05 x 0.3; the floor's diffuse), {n} directions on 1 thread:"
    );
    let figures = |name: &str, scalar: f64, lane_rate: &dyn Fn(Isa) -> f64| {
        println!("           {name:<38} one at a time {scalar:6.1} M/s, eight lanes:");
        for isa in &isas {
            let rate = lane_rate(*isa);
            println!("           {:<38}   {:<8} {rate:6.1} M/s ({:.2}x)", "", format!("{isa:?}"), rate / scalar);
        }
    };
    // Each kernel reads (wo, a light's direction, a direction whose x and y give the sample
    // numbers) and returns a sum of what it computed, so that none of it is optimised away. The
    // kernels are passed by type, not as `dyn Fn`, so that they inline: into the loop one at a
    // time, and into the AVX2 function in lanes (src/simd/lanes.rs).
    let scalar = |kernel: &dyn Fn(&[[Vec3; 3]]) -> f32| rate(runs, n, &|| kernel(std::hint::black_box(&inputs)));
    let one = scalar(&|inputs| inputs.iter().map(|&[wo, _, w]| ggx.sample_visible(wo, u(w)).z).sum());
    figures("GGX visible-normal sampling", one, &|isa| {
        rate(runs, n, &|| lane_sum(isa, &lanes, |[wo, _, w]| ggx.sample_visible_of(wo, u_lanes(w)).z))
    });
    let (eta, k) = (eta.to_array().map(F32x8::splat), k.to_array().map(F32x8::splat));
    let one = scalar(&|inputs| {
        inputs
            .iter()
            .map(|&[wo, wl, w]| {
                let weight = conductor.sample(wo, u(w)).map_or(0.0, |s| s.weight.element_sum() + s.pdf);
                let (f, pdf) = conductor.eval_pdf(wo, wl);
                weight + f.element_sum() + pdf
            })
            .sum()
    });
    figures("conductor sample + eval_pdf, with F", one, &|isa| {
        rate(runs, n, &|| {
            lane_sum(isa, &lanes, |[wo, wl, w]| {
                let zero = F32x8::splat(0.0);
                let colour_sum = |cos: F32x8| {
                    fresnel_conductor_of(cos, eta[0], k[0])
                        + fresnel_conductor_of(cos, eta[1], k[1])
                        + fresnel_conductor_of(cos, eta[2], k[2])
                };
                let sample = Conductor::sample_terms(&ggx, wo, u_lanes(w));
                let eval = Conductor::eval_terms(&ggx, wo, wl);
                F32x8::select(sample.valid, colour_sum(sample.cos_m) * sample.factor + sample.pdf, zero)
                    + F32x8::select(eval.valid, colour_sum(eval.cos_m) * eval.factor + eval.pdf, zero)
            })
        })
    });
    let diffuse = Diffuse { reflectance: Rgb::new(0.8, 0.6, 0.4) };
    let albedo = F32x8::splat(diffuse.reflectance.element_sum());
    let one = scalar(&|inputs| {
        inputs
            .iter()
            .map(|&[wo, wl, w]| {
                let weight = diffuse.sample(wo, u(w)).map_or(0.0, |s| s.weight.element_sum() + s.wi.z + s.pdf);
                let (f, pdf) = diffuse.eval_pdf(wo, wl);
                weight + f.element_sum() + pdf
            })
            .sum()
    });
    figures("diffuse sample + eval_pdf", one, &|isa| {
        rate(runs, n, &|| {
            lane_sum(isa, &lanes, |[wo, wl, w]| {
                let zero = F32x8::splat(0.0);
                let (wi, pdf, valid) = Diffuse::sample_terms(wo, u_lanes(w));
                let (factor, eval_pdf, lit) = Diffuse::eval_terms(wo, wl);
                F32x8::select(valid, albedo + wi.z + pdf, zero) + F32x8::select(lit, albedo * factor + eval_pdf, zero)
            })
        })
    });
}

/// Millions of items per second of `f` over `n` items, median of `runs`.
fn rate(runs: usize, n: usize, f: &dyn Fn() -> f32) -> f64 {
    median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                std::hint::black_box(f());
                n as f64 / start.elapsed().as_secs_f64() / 1e6
            })
            .collect(),
    )
}

/// The sum of `kernel` over `inputs`, eight at a time with the instruction set `isa`.
fn lane_sum(isa: Isa, inputs: &[[V3<F32x8>; 3]], kernel: impl Fn([V3<F32x8>; 3]) -> F32x8) -> f32 {
    isa.run(|| {
        let mut sum = F32x8::splat(0.0);
        for &x in std::hint::black_box(inputs) {
            sum = sum + kernel(x);
        }
        sum.0.iter().sum()
    })
}

fn deform(runs: usize) -> Result<()> {
    let mesh = shapes::uv_sphere(512, 256);
    let orientation = tessera::deform::Orientation::Parallels(glam::Vec3::Y);
    let mut times = Vec::new();
    for _ in 0..runs {
        let start = Instant::now();
        let maps =
            tessera::deform::deformation_maps(&mesh, &orientation, tessera::deform::Smoothing::Vertices(1), 1024, 0.25)
                .map_err(|msg| Error::param("bench deform", msg))?;
        std::hint::black_box(maps.f_map.data.len());
        times.push(start.elapsed().as_secs_f64());
    }
    let seconds = median(times);
    println!(
        "deform     UV sphere of {} triangles, 1 round of smoothing, F map 1024x1024, cut bands: {seconds:.3} s on 1 thread (target < 1 s)",
        mesh.indices.len()
    );
    Ok(())
}

/// Resident memory figures of this process from /proc/self/status, in bytes (Linux only).
fn resident_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Run `f` and return what it returns and the most resident memory it added (Linux: the peak
/// is reset through /proc/self/clear_refs first; None elsewhere).
fn with_peak_memory<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
    let before = resident_bytes("VmRSS:");
    let out = f();
    let peak = resident_bytes("VmHWM:");
    (out, before.zip(peak).filter(|_| reset).map(|(b, p)| p.saturating_sub(b)))
}

/// A torus of `m` x `n` quads (every vertex of valence 4, every edge shared by two quads).
fn torus_quads(m: u32, n: u32) -> Vec<[u32; 4]> {
    let id = |i: u32, j: u32| (j % n) * m + (i % m);
    (0..n).flat_map(|j| (0..m).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])).collect()
}

fn tiles(scene_dir: &Path, runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    use tessera::geometry::Topology;
    use tessera::tiles::{TileLayout, TileTemplates, assign_boundaries, assign_tiles, texture_coordinates};
    let quads = torus_quads(1000, 1000);
    let layout = TileLayout::new(1, 256).expect("a valid layout");
    let (mut times, mut baseline, mut peak) = (Vec::new(), Vec::new(), 0u64);
    for run in 0..runs {
        let start = Instant::now();
        let (uvs, added) = with_peak_memory(|| {
            let topology = Topology::new(&quads);
            let tiles = assign_tiles(&topology, &assign_boundaries(&topology, 1, run as u64));
            texture_coordinates(&layout, &tiles)
        });
        times.push(start.elapsed().as_secs_f64());
        peak = peak.max(added.unwrap_or(0));
        std::hint::black_box(uvs.len());
        let start = Instant::now();
        let mut pairs: std::collections::HashMap<(u32, u32), [u32; 2]> = std::collections::HashMap::new();
        for (f, q) in quads.iter().enumerate() {
            for k in 0..4 {
                let (a, b) = (q[k], q[(k + 1) % 4]);
                pairs.entry((a.min(b), a.max(b))).or_insert([u32::MAX; 2])[usize::from(a > b)] = f as u32;
            }
        }
        std::hint::black_box(pairs.len());
        baseline.push(start.elapsed().as_secs_f64());
    }
    let (seconds, hashing) = (median(times), median(baseline));
    let memory = if peak > 0 { format!("{:.0} MB peak added", peak as f64 / 1e6) } else { "peak memory n/a".into() };
    println!(
        "tiles map  torus of {} quads, 1 thread: {seconds:.3} s, {memory} (targets < 0.5 s, < 300 MB); {:.2}x the time of \
         pairing its edges through a hash map ({hashing:.3} s)",
        quads.len(),
        seconds / hashing
    );

    let image = read_bitmap(&scene_dir.join("textures/rocks_basecolor.jpg"), ColorSpace::Srgb)?;
    let templates = TileTemplates::new(&image, 1, &[], None).map_err(|m| Error::param("bench", m))?;
    let mipmap = MipMap::new(image.clone());
    let texels = layout.tile_count() * layout.tile_res() * layout.tile_res();
    let (mut times, mut baseline) = (Vec::new(), Vec::new());
    for run in 0..runs {
        let start = Instant::now();
        let atlas = pool.install(|| tessera::tiles::synthesize_tiles(&image, &templates, &layout, run as u64));
        times.push(start.elapsed().as_secs_f64());
        std::hint::black_box(atlas.data.len());
        let start = Instant::now();
        let sum: f32 = pool.install(|| {
            (0..texels)
                .into_par_iter()
                .map(|t| mipmap.bilinear(0, Vec2::new((t % 4096) as f32 / 4096.0, (t / 4096) as f32 / 256.0)).x)
                .sum()
        });
        std::hint::black_box(sum);
        baseline.push(start.elapsed().as_secs_f64());
    }
    let (seconds, resampling) = (median(times), median(baseline));
    println!(
        "tiles synth 16 tiles of 256 texels, {} threads: {seconds:.3} s, {:.1}x the time of resampling as many texels \
         bilinearly ({resampling:.4} s)",
        pool.current_num_threads(),
        seconds / resampling
    );
    Ok(())
}

fn pups(scene_dir: &Path, runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    use tessera::pups::{Preset, PresetParams, PupsTexture};
    let params = PresetParams { points: 700, ..Default::default() };
    let texture = Arc::new(PupsTexture::preset(Preset::Noise, &params).map_err(|m| Error::param("bench", m))?);
    let pups = Texture::Pups(tessera::texture::PupsLookup {
        texture: texture.clone(),
        scale: Vec2::ONE,
        filter: tessera::pups::PupsFilter::None,
    });
    let mut times = Vec::new();
    for _ in 0..runs {
        let start = Instant::now();
        let image =
            pool.install(|| tessera::texture::bake_rect(&pups, 1000, 1000, tessera::texture::BakeFootprint::Point));
        times.push(start.elapsed().as_secs_f64());
        std::hint::black_box(image.data.len());
    }
    let seconds = median(times);
    println!(
        "pups       1000 x 1000 image of `noise` from {} control points, {} threads: {seconds:.3} s ({:.0}x the paper's 30 s; \
         target < 0.1 s)",
        texture.point_count(),
        pool.current_num_threads(),
        30.0 / seconds
    );
    // Lookups one at a time on one thread, against the bitmap's, over the same raster.
    let bitmap = Texture::Image(ImageTexture {
        mipmap: Arc::new(MipMap::new(read_bitmap(&scene_dir.join("textures/bark.jpg"), ColorSpace::Srgb)?)),
        filter: Filter::None,
        scale: Vec2::ONE,
        offset: Vec2::ZERO,
    });
    let lookups: Vec<TexCtx> = (0..1_000_000)
        .map(|i| TexCtx {
            uv: Vec2::new((i % 1000) as f32 + 0.5, (i / 1000) as f32 + 0.5) / 1000.0,
            ..Default::default()
        })
        .collect();
    let (pups_rate, bitmap_rate) =
        (lookups_per_second(runs, &pups, &lookups), lookups_per_second(runs, &bitmap, &lookups));
    println!(
        "pups       lookups on 1 thread: {:.2} M/s, {:.1}x the cost of a bilinear bitmap lookup ({:.1} M/s)",
        pups_rate,
        bitmap_rate / pups_rate,
        bitmap_rate
    );
    Ok(())
}

/// The GPU figures (see the module's documentation).
#[cfg(feature = "gpu")]
fn gpu(runs: usize, pool: &rayon::ThreadPool) -> Result<()> {
    use tessera::gpu::{Gpu, GpuBake};
    use tessera::texture::tiling_blending::{CutBands, CutCurve, CutPoint};
    use tessera::texture::{BakeFootprint, bake_rect};
    let device = Gpu::new().map_err(|e| Error::param("gpu", e.0))?;
    // A 1024 x 1024 RGBA exemplar of uniform noise, as the yardstick's.
    let n = 1024;
    let mut noise = Bitmap::new(n, n, 4);
    for (i, v) in noise.data.iter_mut().enumerate() {
        *v = Sampler::new(3, i as u64, 0).next_1d();
    }
    // One pyramid, read through each case's filter.
    let pyramid = Arc::new(MipMap::new(noise));
    let exemplar = |filter| {
        Arc::new(Texture::Image(ImageTexture { mipmap: pyramid.clone(), filter, scale: Vec2::ONE, offset: Vec2::ZERO }))
    };
    // The yardstick's F map: 256 x 256, a rotation growing along u to 1.5 rad, times 1.3.
    let m = 256;
    let mut map = Bitmap::new(m, m, 4);
    for (i, px) in map.data.chunks_exact_mut(4).enumerate() {
        let f = Mat2::from_angle(1.5 * (i % m) as f32 / (m - 1) as f32) * 1.3;
        px.copy_from_slice(&[f.x_axis.x, f.y_axis.x, f.x_axis.y, f.y_axis.y]);
    }
    // Cut bands along a cut seen at u = 1/4 and u = 3/4 (the bands cover about a sixth of the
    // square).
    let seam = (0..=16)
        .map(|k| {
            let v = k as f32 / 16.0;
            CutPoint { uv: [Vec2::new(0.25, v), Vec2::new(0.75, v)], s: v, g: Vec2::new(0.0, v) }
        })
        .collect();
    let seam = CutCurve::new(seam, 1.3).map_err(|e| Error::param("bench", e))?;
    let cuts = CutBands::new(vec![seam], &map, 0.036_084_39).map_err(|e| Error::param("bench", e))?;
    let deformation = DeformationField::new(vec![Deformation::Map(MipMap::new(map))]);
    let Texture::Image(plain) = exemplar(Filter::None).as_ref().clone() else { unreachable!("an image") };
    let mix_max = Blend::MixMax { priority: PriorityMap::new(&plain), contrast: 4.0, lambda: 0.05 };
    let d = Some(deformation.clone());
    let cases = [
        ("classical, linear", None, None, Blend::Linear, Filter::None, BakeFootprint::Point),
        ("deformed, linear", d.clone(), None, Blend::Linear, Filter::None, BakeFootprint::Point),
        ("deformed, mix-max", d.clone(), None, mix_max, Filter::None, BakeFootprint::Point),
        ("deformed, linear, EWA", d.clone(), None, Blend::Linear, Filter::Ewa, BakeFootprint::Texel),
        ("deformed, linear, cut", d, Some(cuts), Blend::Linear, Filter::None, BakeFootprint::Point),
    ];
    println!("gpu        {}", device.describe());
    println!("           CPU: 512 x 512 bakes on {} threads", pool.current_num_threads());
    for (name, deformation, cuts, blend, filter, footprint) in cases {
        // The yardstick's lattice: spacing 1 / (8 sqrt 12) in UV.
        let synthesis = Synthesis {
            tiling: Tiling::Hexagonal,
            tile_size: 0.036_084_39,
            seed: 1,
            deformation,
            cuts,
            blend,
            inset: false,
        };
        let texture =
            TilingBlending::new(Arc::new(synthesis), exemplar(filter)).map_err(|e| Error::param("bench", e))?;
        let baker = GpuBake::new(&device, &texture).map_err(|e| Error::param("gpu", e.0))?;
        // The yardstick's 4096 x 4096 bakes, as many per submission as fill about 0.2 s, on a
        // GPU fast enough; 1024 x 1024 one at a time on a slow one (lavapipe).
        let probe = median(baker.time(1024, 1024, footprint, 1, 1).map_err(|e| Error::param("gpu", e.0))?);
        let (res, launches) =
            if probe < 0.01 { (4096u32, ((0.2 / (16.0 * probe)) as usize).clamp(1, 50)) } else { (1024, 1) };
        let seconds = baker.time(res, res, footprint, launches, runs).map_err(|e| Error::param("gpu", e.0))?;
        let gpu_rate = (res as f64 * res as f64) / median(seconds);
        let cpu_texture = Texture::TilingBlending(texture);
        let cpu_rates = (0..runs)
            .map(|_| {
                let start = Instant::now();
                pool.install(|| bake_rect(&cpu_texture, 512, 512, footprint));
                512.0 * 512.0 / start.elapsed().as_secs_f64()
            })
            .collect();
        let cpu_rate = median(cpu_rates);
        println!(
            "           {name:<24} {gpu_rate:9.3e} lookups/s on the GPU ({res} x {res}, {launches} per submission), \
             {cpu_rate:9.3e} on the CPU ({:.2}x)",
            gpu_rate / cpu_rate
        );
    }
    gpu_view(&device, exemplar(Filter::Trilinear), deformation, runs, pool)
}

/// Frames per second of `tessera gpu-view`'s rasterised view at 1920 x 1080: a floor to the
/// horizon and a sphere, the deformed T&B texture (F map, linear blending, trilinear exemplar)
/// on every surface, against tessera's pixel-centre lookups on the CPU in the same run.
#[cfg(feature = "gpu")]
fn gpu_view(
    device: &tessera::gpu::Gpu,
    exemplar: Arc<Texture>,
    deformation: DeformationField,
    runs: usize,
    pool: &rayon::ThreadPool,
) -> Result<()> {
    use tessera::gpu::GpuView;
    use tessera::integrator::primary::{Derivatives, primary_view};
    let scene = tessera::scene::load_scene_str(
        r#"
        [render]
        width = 1920
        height = 1080
        [camera]
        fov = 40
        eye = [0, 0.8, 3.2]
        target = [0, 0.1, 0]
        [materials.grey]
        type = "diffuse"
        reflectance = 0.5
        [[shapes]]
        type = "rectangle"
        material = "grey"
        transform = [{ scale = 20 }, { rotate = [1, 0, 0], angle = -90 }, { translate = [0, -0.6, -10] }]
        [[shapes]]
        type = "uv_sphere"
        material = "grey"
        transform = [{ scale = 0.6 }]
        "#,
        Path::new("bench-view.toml"),
        &SceneOverrides::default(),
    )?;
    let synthesis = Synthesis {
        tiling: Tiling::Hexagonal,
        tile_size: 0.036_084_39,
        seed: 1,
        deformation: Some(deformation),
        cuts: None,
        blend: Blend::Linear,
        inset: false,
    };
    let texture = TilingBlending::new(Arc::new(synthesis), exemplar).map_err(|e| Error::param("bench", e))?;
    let view = GpuView::new(device, &scene, &scene.camera, &texture, None).map_err(|e| Error::param("gpu", e.0))?;
    for derivatives in [Derivatives::Dpdx, Derivatives::Ray] {
        let probe = median(view.time(derivatives, 1, 1).map_err(|e| Error::param("gpu", e.0))?);
        let frames = ((0.2 / probe) as usize).clamp(1, 200);
        let seconds = view.time(derivatives, frames, runs).map_err(|e| Error::param("gpu", e.0))?;
        println!(
            "           view, {:<18} {:9.1} frames/s at 1920 x 1080 ({frames} per submission)",
            format!("{} derivatives", derivatives.name()),
            1.0 / median(seconds)
        );
    }
    let cpu_texture = Texture::TilingBlending(texture);
    let camera = scene.camera.with_resolution(480, 270)?;
    let cpu_fps = median(
        (0..runs)
            .map(|_| {
                let start = Instant::now();
                pool.install(|| primary_view(&scene, &camera, &cpu_texture));
                // A 480 x 270 view is a 16th of the pixels.
                1.0 / (16.0 * start.elapsed().as_secs_f64())
            })
            .collect(),
    );
    println!("           view on the CPU   {cpu_fps:9.3} frames/s at 1920 x 1080 (from 480 x 270, ray differentials)");
    Ok(())
}

/// Without the `gpu` feature: say how to build with it.
#[cfg(not(feature = "gpu"))]
fn gpu(_runs: usize, _pool: &rayon::ThreadPool) -> Result<()> {
    Err(Error::param(
        "--only gpu",
        "this tessera was built without the `gpu` feature: cargo build --release --features gpu",
    ))
}
