//! Histogram-preserving blending (Heitz and Neyret 2018, "High-Performance By-Example Noise
//! using a Histogram-Preserving Blending Operator"; filtering as Deliot and Heitz 2019).
//!
//! Each channel of the exemplar is sent through its own histogram transformation T to a
//! Gaussian of mean 1/2 and standard deviation 1/6 (G = T(E), ranks to normal quantiles). Tiles
//! of G blended by the variance-preserving operator stay Gaussian with those statistics, and
//! T^-1 brings the result back to the exemplar's histogram.
//!
//! Filtering: a filtered lookup of G at MIP level L is the mean of a footprint whose values
//! spread around it with variance sigma_L^2 = Var(G_0) - Var(G_L) (the variance the box filter
//! removed, by the law of total variance). The lookup table of level L is therefore the
//! expectation of T^-1 over that spread, LUT_L(g) = E[T^-1(g + sigma_L Z)], Z standard normal,
//! so that a footprint averages exemplar values, not Gaussian ones. That the blended field's
//! spread inside a footprint equals the exemplar's is the approximation this makes.

use crate::image::Bitmap;
use crate::math::{floor, normal_cdf, normal_quantile};
use crate::texture::{ImageTexture, MipMap, TexCtx};
use glam::Vec4;

/// Mean of the Gaussianized exemplar.
pub const GAUSSIAN_MEAN: f32 = 0.5;
/// Standard deviation of the Gaussianized exemplar.
const GAUSSIAN_STD: f64 = 1.0 / 6.0;
/// Entries of each inverse lookup table, over g in [0, 1].
const LUT_SIZE: usize = 256;
/// Quadrature nodes of the expectation over the footprint's spread (equal-probability
/// midpoints of the normal distribution).
const SPREAD_NODES: usize = 64;

/// An exemplar in Gaussian space and the inverse transformation of each MIP level.
#[derive(Clone, Debug)]
pub struct GaussianizedExemplar {
    /// G = T(E): the exemplar's RGBA with each channel Gaussianized, with its MIP pyramid and
    /// the exemplar's filter, scale and offset.
    pub gaussian: ImageTexture,
    /// Per MIP level, per channel (RGBA): LUT_L over g in [0, 1].
    luts: Vec<[Vec<f32>; 4]>,
}

impl GaussianizedExemplar {
    /// Gaussianize an image exemplar.
    pub fn new(exemplar: &ImageTexture) -> Self {
        let base = exemplar.mipmap.level(0);
        let n = base.width * base.height;
        let mut gaussian = Bitmap::new(base.width, base.height, 4);
        let mut sorted: [Vec<f32>; 4] = Default::default();
        for (c, sorted) in sorted.iter_mut().enumerate() {
            let values: Vec<f32> = (0..n).map(|i| base.pixel(i % base.width, i / base.width)[c]).collect();
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by(|&a, &b| values[a].total_cmp(&values[b]).then(a.cmp(&b)));
            for (rank, &i) in order.iter().enumerate() {
                let g = GAUSSIAN_MEAN as f64 + GAUSSIAN_STD * normal_quantile((rank as f64 + 0.5) / n as f64);
                gaussian.data[i * 4 + c] = g as f32;
            }
            *sorted = order.iter().map(|&i| values[i]).collect();
        }
        let mipmap = MipMap::new(gaussian);
        let variance = |level: &Bitmap, c: usize| {
            let count = (level.width * level.height) as f64;
            let mean: f64 = level.data.iter().skip(c).step_by(4).map(|&v| v as f64).sum::<f64>() / count;
            level.data.iter().skip(c).step_by(4).map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / count
        };
        let base_variance: [f64; 4] = std::array::from_fn(|c| variance(mipmap.level(0), c));
        let spread: Vec<f64> =
            (0..SPREAD_NODES).map(|q| normal_quantile((q as f64 + 0.5) / SPREAD_NODES as f64)).collect();
        let luts = (0..mipmap.level_count())
            .map(|l| {
                std::array::from_fn(|c| {
                    let sigma = (base_variance[c] - variance(mipmap.level(l), c)).max(0.0).sqrt();
                    (0..LUT_SIZE)
                        .map(|i| {
                            let g = i as f64 / (LUT_SIZE - 1) as f64;
                            let sum: f64 = spread.iter().map(|z| inverse_transform(&sorted[c], g + sigma * z)).sum();
                            (sum / SPREAD_NODES as f64) as f32
                        })
                        .collect()
                })
            })
            .collect();
        GaussianizedExemplar {
            gaussian: ImageTexture {
                mipmap: std::sync::Arc::new(mipmap),
                filter: exemplar.filter,
                scale: exemplar.scale,
                offset: exemplar.offset,
            },
            luts,
        }
    }

    /// The Gaussianized exemplar at a lookup.
    #[inline]
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        self.gaussian.eval(ctx)
    }

    /// T^-1 of a blended Gaussian value `g` for a footprint whose Gaussianized lookup reads
    /// `ctx`'s MIP level.
    pub fn invert(&self, g: Vec4, ctx: &TexCtx) -> Vec4 {
        let lod = self.gaussian.lod(ctx).clamp(0.0, (self.luts.len() - 1) as f32);
        let level = floor(lod) as usize;
        let t = lod - level as f32;
        let at = |l: usize| Vec4::from_array(std::array::from_fn(|c| lut_lookup(&self.luts[l][c], g[c])));
        if t == 0.0 { at(level) } else { at(level) * (1.0 - t) + at(level + 1) * t }
    }

    /// The inverse transformations as one image for a GPU: row L holds level L's tables, texel
    /// i channel c the table of channel c at g = i / (LUT_SIZE - 1).
    pub fn inverse_tables(&self) -> Bitmap {
        let mut image = Bitmap::new(LUT_SIZE, self.luts.len(), 4);
        for (row, tables) in image.data.chunks_exact_mut(LUT_SIZE * 4).zip(&self.luts) {
            for (i, texel) in row.chunks_exact_mut(4).enumerate() {
                for (value, table) in texel.iter_mut().zip(tables) {
                    *value = table[i];
                }
            }
        }
        image
    }

    /// Approximate memory held, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.gaussian.mipmap.memory_bytes() + self.luts.len() * 4 * LUT_SIZE * 4
    }
}

/// T^-1(g): the exemplar value at the quantile Phi((g - 1/2) / std) of the sorted `values`,
/// interpolated between neighbouring ranks.
fn inverse_transform(values: &[f32], g: f64) -> f64 {
    let p = normal_cdf((g - GAUSSIAN_MEAN as f64) / GAUSSIAN_STD);
    let x = (p * values.len() as f64 - 0.5).clamp(0.0, (values.len() - 1) as f64);
    let i = x.floor() as usize;
    let t = x - i as f64;
    let next = values[(i + 1).min(values.len() - 1)] as f64;
    values[i] as f64 * (1.0 - t) + next * t
}

/// Linear interpolation of a table over [0, 1], clamped.
#[inline]
fn lut_lookup(lut: &[f32], g: f32) -> f32 {
    let x = (g.clamp(0.0, 1.0) * (lut.len() - 1) as f32).min((lut.len() - 1) as f32);
    let i = (x as usize).min(lut.len() - 2);
    let t = x - i as f32;
    lut[i] * (1.0 - t) + lut[i + 1] * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::Filter;
    use glam::Vec2;

    fn exemplar() -> ImageTexture {
        // A skewed distribution: squares of a ramp, in scrambled order.
        let n = 64;
        let mut b = Bitmap::new(n, n, 1);
        for i in 0..n * n {
            let j = (i * 2654435761) % (n * n);
            b.data[j] = (i as f32 / (n * n) as f32).powi(2);
        }
        ImageTexture {
            mipmap: std::sync::Arc::new(MipMap::new(b)),
            filter: Filter::Trilinear,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }
    }

    #[test]
    fn gaussianized_values_are_normal_with_the_chosen_moments() {
        let g = GaussianizedExemplar::new(&exemplar());
        let level = g.gaussian.mipmap.level(0);
        let values: Vec<f64> = level.data.iter().step_by(4).map(|&v| v as f64).collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let std = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt();
        assert!((mean - 0.5).abs() < 1e-4, "{mean}");
        assert!((std - 1.0 / 6.0).abs() < 0.003, "{std}");
    }

    #[test]
    fn the_finest_table_inverts_the_transformation() {
        let ex = exemplar();
        let g = GaussianizedExemplar::new(&ex);
        // At level 0, T^-1(T(E)) = E at every texel centre.
        let n = 64;
        for (x, y) in [(3, 5), (17, 40), (63, 0), (31, 31)] {
            let st = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let ctx = TexCtx { uv: crate::texture::image_coordinates(st), ..Default::default() };
            let back = g.invert(g.eval(&ctx), &ctx).x;
            let original = ex.eval(&ctx).x;
            // The table's resolution limits the round trip.
            assert!((back - original).abs() < 0.01, "({x}, {y}): {back} vs {original}");
        }
    }

    #[test]
    fn the_coarsest_table_gives_the_mean() {
        // At the 1x1 level the spread is the whole distribution: LUT(1/2) is the exemplar mean.
        let ex = exemplar();
        let g = GaussianizedExemplar::new(&ex);
        let last = g.luts.last().unwrap();
        let mean = ex.mipmap.level(0).channel_means()[0] as f32;
        assert!((lut_lookup(&last[0], 0.5) - mean).abs() < 0.01 * mean, "{} vs {mean}", lut_lookup(&last[0], 0.5));
    }
}
