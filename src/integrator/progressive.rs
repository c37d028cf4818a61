//! A render in passes (`tessera render --time-limit / --checkpoint`, Ctrl-C): samples 0..spp of
//! every pixel split into consecutive ranges, each rendered by [`render_samples_into`] onto the
//! previous pass's film, so that the image after any pass is the image of that many samples per
//! pixel, bit for bit, and the final one that of an uninterrupted render. Passes double in
//! length from one sample per pixel, bounded by the time left and a longest pass, so that a
//! time limit is kept and an interruption loses little; a remainder shorter than a pass joins
//! it (64 samples per pixel: passes of 1, 2, 4, 8, 16 and 33). A pass after the first lasts at
//! least [`SHORTEST_PASS`] at the rate so far, where samples remain: each costs a sweep over
//! every tile, and a short render's passes of a few samples cost it several percent (scene A's
//! 64 samples per pixel on two cores: passes of 1 and 63).

use super::{Crop, render_samples_into};
use crate::image::Film;
use crate::scene::Scene;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// When to stop early and how long a pass may take.
#[derive(Clone, Copy, Debug)]
pub struct PassLimits {
    /// Stop before a pass that would end after this long (None: render every sample).
    pub time_limit: Option<Duration>,
    /// Longest pass, estimated from the passes so far (checkpoints are written between passes).
    pub longest_pass: Duration,
}

/// The shortest pass after the first (where samples remain), at the rate so far: long enough
/// that what a pass costs beyond its samples (a sweep over every tile and a copy of the film,
/// some 20-40 ms for 512 x 512 pixels on two cores) is about 1% of it, short enough that an
/// interruption loses little more than the half of the work that doubling passes may lose.
/// The rate after the first pass is pessimistic (a pass of one sample per pixel takes up to
/// twice a sample's share), so this is some two seconds of samples.
pub const SHORTEST_PASS: Duration = Duration::from_secs(3);

/// Why a render in passes ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// Every sample of the scene was rendered.
    Complete,
    /// The time limit left no room for another pass.
    TimeLimit,
    /// `stop` was set: the pass under way was dropped.
    Stopped,
}

/// Render `crop` of `scene` in passes, continuing `start` (a film of the crop holding whole
/// samples per pixel: empty, or a [`super::Checkpoint`]'s); `after_pass(film, spp)` sees the
/// film after each pass (for checkpoints) and may fail the render; `progress(done, total)`
/// counts samples over the whole render. Returns the film of the last whole pass, its samples
/// per pixel, and why it ended.
pub fn render_in_passes(
    scene: &Scene,
    crop: Crop,
    start_film: Film,
    limits: PassLimits,
    stop: &AtomicBool,
    progress: &(dyn Fn(u64, u64) + Sync),
    mut after_pass: impl FnMut(&Film, u32) -> crate::Result<()>,
) -> crate::Result<(Film, u32, Ending)> {
    let spp = scene.settings.spp;
    let (w, h) = crop.size();
    debug_assert_eq!(start_film.resolution(), (w as usize, h as usize));
    let per_pass_sample = w as u64 * h as u64;
    let resumed = start_film.samples_per_pixel().unwrap_or(0);
    let total = per_pass_sample * spp.saturating_sub(resumed) as u64;
    let start = Instant::now();
    let (mut film, mut spare) = (start_film, None);
    let (mut done, mut pass) = (resumed, 1u32);
    while done < spp {
        // The time so far, and the seconds a sample per pixel has taken after the first pass.
        let elapsed = start.elapsed();
        let per_spp = (done > resumed).then(|| elapsed.as_secs_f64() / (done - resumed) as f64);
        pass = pass_length(pass, done, spp, per_spp);
        if let Some(limit) = limits.time_limit {
            // Keep within the limit: no more samples than the time left allows at the rate so far.
            match per_spp {
                Some(per_spp) => {
                    let room = ((limit.saturating_sub(elapsed)).as_secs_f64() / per_spp).floor();
                    if room < 1.0 {
                        return Ok((film, done, Ending::TimeLimit));
                    }
                    pass = pass.min(room as u32);
                }
                None if elapsed >= limit => return Ok((film, done, Ending::TimeLimit)),
                None => {}
            }
        }
        if let Some(per_spp) = per_spp {
            pass = pass.min(((limits.longest_pass.as_secs_f64() / per_spp).floor() as u32).max(1));
        }
        let range = done..(done + pass).min(spp);
        let base = per_pass_sample * (done - resumed) as u64;
        // The film two passes old is rewritten whole by the next pass (a copy of the film
        // for each pass cost as much as 1% of a short render in page faults).
        let into = spare.take().unwrap_or_else(|| film.clone());
        let next =
            render_samples_into(scene, crop, &film, into, range.clone(), &|d, _| progress(base + d, total), stop);
        let Ok(next) = next else { return Ok((film, done, Ending::Stopped)) };
        spare = Some(std::mem::replace(&mut film, next));
        done = range.end;
        after_pass(&film, done)?;
        pass = pass.saturating_mul(2);
    }
    Ok((film, done, Ending::Complete))
}

/// The length of the pass after `done` of `spp` samples per pixel, doubled to `doubled`, before
/// the time limit and the longest pass bound it: at least what fills [`SHORTEST_PASS`] at
/// `per_spp` seconds a sample per pixel (where that is known), and all that is left when the
/// remainder after it would be shorter than it. A pass of a few samples per pixel costs more
/// than its share (a sweep over every tile, camera packets of few rays).
fn pass_length(doubled: u32, done: u32, spp: u32, per_spp: Option<f64>) -> u32 {
    // Saturating float-to-integer conversion: a rate of 0 or NaN gives u32::MAX or 0.
    let filling = per_spp.map_or(0, |per_spp| (SHORTEST_PASS.as_secs_f64() / per_spp).floor() as u32);
    let pass = doubled.max(filling);
    let left = spp - done;
    if left < pass.saturating_mul(2) { left } else { pass }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pass lengths of a render of `spp` samples per pixel without limits, a sample per
    /// pixel taking `per_spp` seconds.
    fn schedule(spp: u32, per_spp: f64) -> Vec<u32> {
        let (mut done, mut pass, mut lengths) = (0, 1u32, Vec::new());
        while done < spp {
            pass = pass_length(pass, done, spp, (done > 0).then_some(per_spp));
            lengths.push(pass);
            done += pass;
            pass = pass.saturating_mul(2);
        }
        lengths
    }

    #[test]
    fn passes_double_and_a_short_remainder_joins_the_last() {
        // Slow samples (a minute a sample per pixel): doubling alone.
        assert_eq!(schedule(1, 60.0), [1]);
        assert_eq!(schedule(6, 60.0), [1, 2, 3]);
        assert_eq!(schedule(64, 60.0), [1, 2, 4, 8, 16, 33]);
        assert_eq!(schedule(100, 60.0), [1, 2, 4, 8, 16, 32, 37]);
        assert_eq!(schedule(127, 60.0), [1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(schedule(u32::MAX, 60.0).iter().map(|&p| p as u64).sum::<u64>(), u32::MAX as u64);
    }

    #[test]
    fn passes_after_the_first_fill_the_shortest_pass() {
        // Scene A's rate on two cores (about 40 ms a sample per pixel): three seconds of
        // samples, which the rest joins; the first pass stays one sample per pixel.
        assert_eq!(schedule(64, 0.04), [1, 63]);
        assert_eq!(schedule(1024, 0.04), [1, 75, 150, 300, 498]);
        assert_eq!(schedule(1024, 0.5), [1, 6, 12, 24, 48, 96, 192, 645]);
        // Samples so fast that a second holds them all; a rate of zero or NaN does not panic.
        assert_eq!(schedule(1_000_000, 1e-9), [1, 999_999]);
        assert_eq!(schedule(64, 0.0), [1, 63]);
        assert_eq!(schedule(64, f64::NAN), [1, 2, 4, 8, 16, 33]);
    }
}
