//! Rendering an image: tiles in parallel (rayon), each pixel's samples in a fixed order, so the
//! image is bit-identical whatever the number of threads.

mod checkpoint;
mod lanes;
mod path;
pub mod primary;
mod progressive;

pub use checkpoint::{Checkpoint, fingerprint};
pub use path::{FirstHit, Path, PathTracer, WaveBuffers};
pub use progressive::{Ending, PassLimits, render_in_passes};

use crate::color::Rgb;
use crate::image::{Aov, Film};
use crate::scene::Scene;
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Side of the square tiles work is split into.
const TILE: u32 = 16;

/// About this many paths are traced as one wavefront ([`PathTracer::trace_wave`]): whole
/// pixels' samples, at least one pixel's. Waves of 1,024 fill the lanes' groups of eight better
/// than waves of 256 at every bounce (scene A 0.7% fewer instructions, the Cornell box 1.6%).
const WAVE: usize = 1024;

/// A rectangle of pixels `[x0, x1) x [y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Crop {
    /// The whole image.
    pub fn full(width: u32, height: u32) -> Self {
        Crop { x0: 0, y0: 0, x1: width, y1: height }
    }

    /// Size in pixels.
    pub fn size(&self) -> (u32, u32) {
        (self.x1 - self.x0, self.y1 - self.y0)
    }
}

fn aov_values(aovs: &[Aov], hit: &Option<path::FirstHit>, out: &mut [f32]) {
    let mut i = 0;
    let Some(h) = hit else {
        out.iter_mut().for_each(|v| *v = 0.0);
        return;
    };
    for a in aovs {
        let values: &[f32] = match a {
            Aov::Albedo => &h.albedo.to_array(),
            Aov::Normal => &h.normal.to_array(),
            Aov::Uv => &h.uv.to_array(),
            Aov::Footprint => &[h.footprint],
            Aov::Position => &h.position.to_array(),
            Aov::Depth => &[h.depth],
        };
        out[i..i + values.len()].copy_from_slice(values);
        i += values.len();
    }
}

/// Render the pixels of `crop` (default: the whole image) with the scene's settings, recording
/// `aovs`. `progress(done, total)` is called as samples complete (from worker threads).
/// Runs on the current rayon thread pool.
pub fn render(scene: &Scene, crop: Option<Crop>, aovs: &[Aov], progress: &(dyn Fn(u64, u64) + Sync)) -> Film {
    let crop = crop.unwrap_or(Crop::full(scene.settings.width, scene.settings.height));
    let (w, h) = crop.size();
    let empty = Film::new(w as usize, h as usize, aovs);
    render_samples(scene, crop, &empty, 0..scene.settings.spp, progress, &AtomicBool::new(false))
        .expect("never stopped")
}

/// Continue `film` (the pixels of `crop`, each holding its samples 0..`samples.start`) with the
/// samples `samples` of every pixel, returning the film that holds 0..`samples.end`. Each
/// pixel's samples are added to its running sums in order, so any split of 0..spp into ranges
/// gives the image of one uninterrupted render bit for bit (progressive output, time limits,
/// resuming). None if `stop` is set before the last tile is done (the pass is then lost, not
/// half kept: `film` is left as it was).
pub fn render_samples(
    scene: &Scene,
    crop: Crop,
    film: &Film,
    samples: std::ops::Range<u32>,
    progress: &(dyn Fn(u64, u64) + Sync),
    stop: &AtomicBool,
) -> Option<Film> {
    render_samples_into(scene, crop, film, film.clone(), samples, progress, stop).ok()
}

/// [`render_samples`], writing every pixel of the new film into `into` (a film of `film`'s
/// size and AOVs, whatever it holds: a spare one is reused rather than a copy of 20 MB made at
/// each pass); `into` back, its pixels partly written, where `stop` ends the pass.
pub fn render_samples_into(
    scene: &Scene,
    crop: Crop,
    film: &Film,
    into: Film,
    samples: std::ops::Range<u32>,
    progress: &(dyn Fn(u64, u64) + Sync),
    stop: &AtomicBool,
) -> Result<Film, Film> {
    let (w, h) = crop.size();
    let stride = film.aov_stride();
    let aovs = film.aovs();
    assert!(into.resolution() == film.resolution() && into.aovs() == aovs, "a spare film of another size or AOVs");
    let next = Mutex::new(into);
    let tracer = PathTracer::new(scene, !aovs.is_empty(), aovs.contains(&Aov::Footprint));
    let spp = samples.len() as u64;
    let total = w as u64 * h as u64 * spp;
    let done = AtomicU64::new(0);
    let tiles: Vec<(u32, u32)> =
        (0..h.div_ceil(TILE)).flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty))).collect();
    // Each worker's buffers are kept from tile to tile (grown once, not for every tile).
    let worker_buffers = || (Vec::new(), vec![0.0f32; stride], Vec::new(), WaveBuffers::default(), Vec::new());
    tiles.par_iter().for_each_init(worker_buffers, |(pixels, aov_buf, paths, buffers, tile_pixels), &(tx, ty)| {
        if stop.load(Ordering::Relaxed) {
            return;
        }
        pixels.clear();
        tile_pixels.clear();
        tile_pixels.extend(
            (ty * TILE..((ty + 1) * TILE).min(h))
                .flat_map(|fy| (tx * TILE..((tx + 1) * TILE).min(w)).map(move |fx| (fx, fy))),
        );
        // Whole pixels at a time, about WAVE paths, are traced as one wavefront; then each
        // pixel's samples are added to its sums in order.
        let pixels_per_wave = (WAVE / samples.len().max(1)).max(1);
        for wave in tile_pixels.chunks(pixels_per_wave) {
            let wave_pixels = wave.iter().map(|&(fx, fy)| (crop.x0 + fx, crop.y0 + fy));
            tracer.start_wave(wave_pixels, samples.clone(), buffers, paths);
            tracer.trace_wave(paths, buffers);
            for (&(fx, fy), pixel_paths) in wave.iter().zip(paths.chunks(samples.len().max(1))) {
                let mut sum = film.pixel(fx as usize, fy as usize).clone();
                for path in pixel_paths {
                    let l = path.radiance;
                    aov_values(aovs, &path.first_hit, aov_buf);
                    sum.add(if l.is_finite() { l } else { Rgb::ZERO }, !l.is_finite(), aov_buf);
                }
                pixels.push((fx as usize, fy as usize, sum));
            }
        }
        let taken = pixels.len() as u64 * spp;
        {
            let mut next = next.lock().expect("no panics while holding the film");
            for (x, y, sum) in pixels.drain(..) {
                next.set_pixel(x, y, sum);
            }
        }
        progress(done.fetch_add(taken, Ordering::Relaxed) + taken, total);
    });
    let next = next.into_inner().expect("no panics while holding the film");
    if done.load(Ordering::Relaxed) == total { Ok(next) } else { Err(next) }
}
