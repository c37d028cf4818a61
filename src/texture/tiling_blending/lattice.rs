//! How visible the paving's lattice is in a synthesis (issue 20): the power of a bake's spectrum
//! at the lattice's frequencies (its first two rings of reciprocal vectors), relative to the
//! power the exemplar's own spectrum has there once scaled as the synthesis reads it. About 1:
//! the lattice adds nothing a viewer could see; well above 1: the tiles' layout shows (an
//! exemplar with dark corners or a gradient turns into a regular grid of bands).
//!
//! Both spectra are windowed (Hann) direct Fourier sums at the exact frequencies, each
//! normalised by its image's variance and sample spacing, so that a bake that is the exemplar
//! itself, rescaled, gives 1 whatever the resolutions. The exemplar's power is averaged over
//! the 3 x 3 frequency bins around each frequency (its spectrum is smooth at that scale); the
//! bake's is taken at the exact frequency, where a lattice puts its peak.

use super::{Synthesis, Tiling, TilingBlending};
use crate::image::Bitmap;
use crate::texture::{BakeFootprint, Texture, bake};
use glam::Vec2;
use std::sync::Arc;

/// The lattice's frequencies (cycles per UV unit) whose powers are compared: the first two
/// rings of its reciprocal lattice, one of each pair +-k (a real image's power is even).
pub fn lattice_frequencies(tiling: Tiling, tile_size: f32) -> Vec<Vec2> {
    let ring = match tiling {
        // Reciprocal of a1 = (1, 0), a2 = (1/2, sqrt 3 / 2): b1 = (1, -1/sqrt 3),
        // b2 = (0, 2/sqrt 3); the first ring b1, b2, b1 + b2, the second 2 b1 + b2, b1 + 2 b2,
        // b1 - b2.
        Tiling::Hexagonal => {
            let s = 1.0 / 3f32.sqrt();
            vec![
                Vec2::new(1.0, -s),
                Vec2::new(0.0, 2.0 * s),
                Vec2::new(1.0, s),
                Vec2::new(2.0, 0.0),
                Vec2::new(1.0, 3.0 * s),
                Vec2::new(1.0, -3.0 * s),
            ]
        }
        Tiling::Square => vec![Vec2::X, Vec2::Y, Vec2::ONE, Vec2::new(1.0, -1.0)],
    };
    ring.into_iter().map(|k| k / tile_size).collect()
}

/// The lattice visibility of `bakes` (square luminance-or-colour images of the synthesis over
/// the UV square [0, `extent`]^2, e.g. one per seed) for the paving `tiling` of spacing
/// `tile_size`, against `exemplar` read at `scale` exemplar units per UV unit. None when an
/// image is constant or too small.
pub fn lattice_visibility(
    bakes: &[Bitmap],
    tiling: Tiling,
    tile_size: f32,
    extent: f32,
    exemplar: &Bitmap,
    scale: f32,
) -> Option<f64> {
    let frequencies = lattice_frequencies(tiling, tile_size);
    let mut bake_power = 0.0;
    let mut bake_spacing = 0.0;
    for bake in bakes {
        let spectrum = Spectrum::new(bake)?;
        bake_power += frequencies.iter().map(|k| spectrum.power(*k * extent)).sum::<f64>() / bakes.len() as f64;
        bake_spacing = (extent * scale) as f64 / bake.width as f64;
    }
    let spectrum = Spectrum::new(exemplar)?;
    let exemplar_power: f64 = frequencies
        .iter()
        .map(|k| {
            let nu = *k / scale;
            let mut sum = 0.0;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    sum += spectrum.power(nu + Vec2::new(dx as f32, dy as f32));
                }
            }
            sum / 9.0
        })
        .sum();
    // Per-sample powers scale as the area of a sample in exemplar units.
    let exemplar_spacing = 1.0 / exemplar.width as f64;
    let expected = exemplar_power * (exemplar_spacing / bake_spacing).powi(2);
    (expected > 0.0 && !bakes.is_empty()).then(|| bake_power / expected)
}

/// The lattice visibility of `texture` with its synthesis' seed replaced by each of `seeds`:
/// bakes of the UV square at `res` x `res` (point lookups), against its exemplar image read at
/// the mean of sqrt |det F| over the bake (exact for a constant F). None without an image
/// exemplar.
pub fn synthesis_lattice_visibility(texture: &TilingBlending, res: usize, seeds: &[u64]) -> Option<f64> {
    let exemplar = texture.exemplar_image()?;
    let synthesis = &texture.synthesis;
    let mut scale = 0.0f64;
    let n = 16;
    for j in 0..n {
        for i in 0..n {
            let uv = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
            scale += synthesis.deformation_at(uv).determinant().abs().sqrt() as f64 / (n * n) as f64;
        }
    }
    let bakes: Vec<Bitmap> = seeds
        .iter()
        .map(|&seed| {
            let reseeded = Synthesis { seed, ..synthesis.as_ref().clone() };
            let texture = texture.with_synthesis(Arc::new(reseeded));
            bake(&Texture::TilingBlending(texture), res, BakeFootprint::Point)
        })
        .collect();
    lattice_visibility(&bakes, synthesis.tiling, synthesis.tile_size, 1.0, exemplar, scale as f32)
}

/// An image's luminance (mean of its colour channels), less its mean, Hann-windowed, with the
/// normalisation of its power.
struct Spectrum {
    size: usize,
    values: Vec<f64>,
    /// Variance times the sum of the squared window.
    norm: f64,
}

impl Spectrum {
    fn new(image: &Bitmap) -> Option<Self> {
        let size = image.width.min(image.height);
        if size < 8 {
            return None;
        }
        let colours = image.channels.min(3);
        let luminance: Vec<f64> = (0..size * size)
            .map(|k| {
                let v = image.values(k % size, k / size);
                v[..colours].iter().map(|&c| c as f64).sum::<f64>() / colours as f64
            })
            .collect();
        let mean = luminance.iter().sum::<f64>() / luminance.len() as f64;
        let variance = luminance.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / luminance.len() as f64;
        if !(variance > 0.0) {
            return None;
        }
        let hann = |i: usize| 0.5 - 0.5 * (std::f64::consts::TAU * (i as f64 + 0.5) / size as f64).cos();
        let mut window2 = 0.0;
        let values = luminance
            .iter()
            .enumerate()
            .map(|(k, v)| {
                let w = hann(k % size) * hann(k / size);
                window2 += w * w;
                (v - mean) * w
            })
            .collect();
        Some(Spectrum { size, values, norm: variance * window2 })
    }

    /// |sum_x v(x) e^(-2 pi i k.x)|^2 / norm, x the sample positions in units of the image's
    /// side and k in cycles per side.
    fn power(&self, k: Vec2) -> f64 {
        let n = self.size;
        let step = |f: f32| {
            let a = -std::f64::consts::TAU * f as f64 / n as f64;
            (a.cos(), a.sin())
        };
        let ((cx, sx), (cy, sy)) = (step(k.x), step(k.y));
        let (mut re, mut im) = (0.0, 0.0);
        // Rows are image rows (y down); the sign of k.y does not change the power of a real
        // image's pair +-k, but the rows' direction does for the pair's members: use v up.
        let (mut ry, mut iy) = (1.0, 0.0);
        for row in (0..n).rev() {
            let (mut rx, mut ix) = (ry, iy);
            for &v in &self.values[row * n..(row + 1) * n] {
                re += v * rx;
                im += v * ix;
                (rx, ix) = (rx * cx - ix * sx, rx * sx + ix * cx);
            }
            (ry, iy) = (ry * cy - iy * sy, ry * sy + iy * cy);
        }
        (re * re + im * im) / self.norm
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `size` x `size` image of seeded white noise plus `bump` times a grid of cosines along
    /// the lattice `frequencies` (cycles per side).
    fn image(size: usize, seed: u64, bump: f32, frequencies: &[Vec2]) -> Bitmap {
        let mut b = Bitmap::new(size, size, 1);
        for (k, v) in b.data.iter_mut().enumerate() {
            let noise = (crate::sampling::mix64(seed ^ k as u64) >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
            let (x, y) = ((k % size) as f32 / size as f32, 1.0 - (k / size) as f32 / size as f32);
            let wave: f32 = frequencies.iter().map(|f| (std::f32::consts::TAU * (f.x * x + f.y * y)).cos()).sum();
            *v = noise + bump * wave;
        }
        b
    }

    #[test]
    fn white_noise_shows_no_lattice_and_a_periodic_pattern_does() {
        let (tile, size) = (0.1, 256);
        let frequencies = lattice_frequencies(Tiling::Hexagonal, tile);
        // The exemplar: white noise (flat spectrum), read at scale 1 over the unit square.
        let exemplar = image(size, 1, 0.0, &[]);
        let plain: Vec<Bitmap> = (0..4).map(|s| image(size, 10 + s, 0.0, &[])).collect();
        let v = lattice_visibility(&plain, Tiling::Hexagonal, tile, 1.0, &exemplar, 1.0).unwrap();
        assert!((0.6..1.6).contains(&v), "{v}");
        // A lattice of cosines at the paving's first ring: many times the noise's power.
        let first_ring = &frequencies[..3];
        let gridded: Vec<Bitmap> = (0..4).map(|s| image(size, 10 + s, 0.05, first_ring)).collect();
        let v = lattice_visibility(&gridded, Tiling::Hexagonal, tile, 1.0, &exemplar, 1.0).unwrap();
        assert!(v > 10.0, "{v}");
        // Over half the UV square the lattice has half as many cycles per side: found there,
        // and not where a bake of the full square would have it.
        let halved: Vec<Vec2> = first_ring.iter().map(|k| *k * 0.5).collect();
        let half: Vec<Bitmap> = (0..4).map(|s| image(size, 20 + s, 0.05, &halved)).collect();
        let v = lattice_visibility(&half, Tiling::Hexagonal, tile, 0.5, &exemplar, 2.0).unwrap();
        assert!(v > 10.0, "{v}");
        let v = lattice_visibility(&half, Tiling::Hexagonal, tile, 1.0, &exemplar, 1.0).unwrap();
        assert!(v < 3.0, "{v}");
    }
}
