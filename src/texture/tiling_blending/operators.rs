//! The blending operators of tiling and blending (paper 000 Eq. 1 and DESIGN.md section 4): how
//! the k tiles' exemplar values at a point are combined into one, linear, variance-preserving,
//! histogram-preserving, sharpened (Mikkelsen 2022) or Mix-Max (Fournier and Sauvage 2024).
//! `shaders/tiling_blending/operators.wgsl` is the GPU port of this file.

use super::TileLookup;
use super::synthesis::MAX_LOOKUPS;
use crate::color::{Rgb, luminance};
use crate::texture::{Channel, Filter, ImageTexture, MipMap, TexCtx, Texture};
use glam::Vec4;
use std::sync::Arc;

/// How the tiles covering a point are combined (DESIGN.md section 4).
#[derive(Clone, Debug)]
pub enum Blend {
    /// T = sum w_i E_i (Eq. 1) with the paving's weights.
    Linear,
    /// T = m + sum w_i (E_i - m) / sqrt(sum w_i^2), m the exemplar's mean (Heitz-Neyret 2018):
    /// keeps the variance of a Gaussian exemplar where linear blending lowers it.
    VariancePreserving,
    /// Variance-preserving blending of the Gaussianized exemplar, then its inverse histogram
    /// transformation, prefiltered per MIP level (Heitz-Neyret 2018, Deliot-Heitz 2019): keeps
    /// the exemplar's histogram.
    HistogramPreserving,
    /// Mikkelsen 2022 ("Practical Real-Time Hex-Tiling", JCGT 11(3)): weights
    /// w_i' = lerp(1, L_i, luminance_contrast) w_i^exponent, normalised, L_i the luminance of
    /// `source` (the exemplar of the synthesis' first layer) read by tile i.
    Sharpened {
        /// Power on the paving's weights (Mikkelsen's default 7).
        exponent: f32,
        /// How much the tiles' luminance weighs (Mikkelsen's default 0.6).
        luminance_contrast: f32,
        /// The texture whose luminance weights the tiles.
        source: Arc<Texture>,
    },
    /// Mix-Max (Fournier and Sauvage 2024): each tile has the priority c s_i + ln w_i, s_i its
    /// priority map's mean over the footprint and c the priority contrast; with the footprint's
    /// variance of c s_i, sigma_i^2, and the micro-priority spread lambda, tile i beats tile j with probability
    /// Phi(((s_i + ln w_i) - (s_j + ln w_j)) / sqrt(sigma_i^2 + sigma_j^2 + 2 lambda^2)), and its
    /// weight is the product of those over the other tiles, normalised (exact for two tiles; a
    /// hard maximum when the variances and lambda are 0). The ln w_i term makes a tile lose
    /// before its weight reaches 0, so that the result is continuous at tile borders.
    MixMax {
        /// The priority map.
        priority: PriorityMap,
        /// Factor c on the priorities against the paving's ln w_i: larger values let the
        /// exemplar's content, rather than the tile shapes, decide where tiles cut.
        contrast: f32,
        /// Spread of the sub-footprint priorities: 0 cuts sharply, larger values blend.
        lambda: f32,
    },
}

/// A scalar priority map (the mean of its RGB) stored with its square in one two-channel MIP
/// pyramid, so that one filtered lookup gives both the priority's mean and its variance over a
/// footprint. The map is stored less its mean over the image: Mix-Max reads only differences
/// of priorities and their variances, which a constant does not change, and the variance
/// E[s^2] - E[s]^2 then cancels less (at a contrast of 32 its rounding weighs on the weights).
#[derive(Clone, Debug)]
pub struct PriorityMap {
    /// Channels: s - mean, (s - mean)^2 (read back as RGB = s - mean, A = its square).
    map: ImageTexture,
}

impl PriorityMap {
    /// The priority map of an image (its RGB mean).
    pub fn new(image: &ImageTexture) -> Self {
        let base = image.mipmap.level(0);
        let mut moments = crate::image::Bitmap::new(base.width, base.height, 2);
        let count = (base.width * base.height) as f64;
        let mut total = 0.0f64;
        for y in 0..base.height {
            for x in 0..base.width {
                total += Channel::Mean.select(base.pixel(x, y)) as f64;
            }
        }
        let mean = (total / count) as f32;
        for y in 0..base.height {
            for x in 0..base.width {
                let s = Channel::Mean.select(base.pixel(x, y)) - mean;
                moments.values_mut(x, y).copy_from_slice(&[s, s * s]);
            }
        }
        let map = ImageTexture {
            mipmap: Arc::new(MipMap::new(moments)),
            filter: image.filter,
            scale: image.scale,
            offset: image.offset,
        };
        PriorityMap { map }
    }

    /// The map: RGB = s, A = s^2.
    pub fn image(&self) -> &ImageTexture {
        &self.map
    }

    /// Mean and variance of the priority over the lookup's footprint.
    #[inline]
    pub(super) fn mean_and_variance(&self, ctx: &TexCtx) -> (f32, f32) {
        let v = self.map.eval(ctx);
        Self::moments(v.x, v.w)
    }

    /// Mean and variance from the map's two channels filtered over a footprint: the mean of
    /// s and the mean of s^2.
    #[inline]
    pub(super) fn moments(mean: f32, mean_square: f32) -> (f32, f32) {
        (mean, (mean_square - mean * mean).max(0.0))
    }

    /// Whether every lookup of `image` reads this map at the same texels with the same filter
    /// weights, so that the exemplar's [`ImageTexture::taps`] read both.
    pub(super) fn reads_like(&self, image: &ImageTexture) -> bool {
        let m = &self.map;
        (m.filter, m.scale, m.offset) == (image.filter, image.scale, image.offset)
            && image.mipmap.same_layout(&m.mipmap)
    }

    fn memory_bytes(&self) -> usize {
        self.map.mipmap.memory_bytes()
    }
}

impl Blend {
    /// The blending weights of the tiles: the paving's for the linear and variance-preserving
    /// operators, reweighted and normalised for the others. `values` are the tiles' exemplar
    /// values and `exemplar` their texture (reused when it is the weights' source).
    pub(super) fn weights(
        &self,
        lookups: &[TileLookup],
        values: &[Vec4],
        exemplar: Option<&Arc<Texture>>,
    ) -> [f32; MAX_LOOKUPS] {
        let k = lookups.len();
        let mut w = [0.0; MAX_LOOKUPS];
        match self {
            Blend::Linear | Blend::VariancePreserving | Blend::HistogramPreserving => {
                for i in 0..k {
                    w[i] = lookups[i].weight;
                }
                return w;
            }
            Blend::Sharpened { exponent, luminance_contrast, source } => {
                let same = exemplar.is_some_and(|e| Arc::ptr_eq(e, source));
                for i in 0..k {
                    let v = if same { values[i] } else { source.eval(&lookups[i].ctx) };
                    let lum = luminance(Rgb::new(v.x, v.y, v.z));
                    let factor = 1.0 + (lum - 1.0) * luminance_contrast;
                    w[i] = factor.max(0.0) * lookups[i].weight.powf(*exponent);
                }
            }
            Blend::MixMax { priority, contrast, lambda } => {
                let mut moments = [(0.0, 0.0); MAX_LOOKUPS];
                for i in (0..k).filter(|&i| lookups[i].weight > 0.0) {
                    moments[i] = priority.mean_and_variance(&lookups[i].ctx);
                }
                return mix_max_weights(lookups, &moments, *contrast, *lambda);
            }
        }
        normalised(w, lookups)
    }

    /// Bytes held by the operator's maps.
    pub fn memory_bytes(&self) -> usize {
        match self {
            Blend::MixMax { priority, .. } => priority.memory_bytes(),
            _ => 0,
        }
    }

    /// True when the weights read a filtered texture.
    pub fn uses_footprint(&self) -> bool {
        match self {
            Blend::Sharpened { source, .. } => source.uses_footprint(),
            Blend::MixMax { priority, .. } => priority.map.filter != Filter::None,
            _ => false,
        }
    }
}

/// P(X > 0) for X normal with mean `difference` and variance `variance`; a step (1/2 at 0) when
/// the variance is 0. Beyond [`DECIDED_SQUARED_SIGMAS`] it is the step without computing Phi,
/// whose value there rounds to exactly 0 or 1.
#[inline]
fn win_probability(difference: f32, variance: f32) -> f32 {
    if difference * difference > DECIDED_SQUARED_SIGMAS * variance || !(variance > 0.0) {
        // 1, 0 or 1/2 (a tie, or NaN) without a branch: which tile wins is a coin toss to the
        // branch predictor.
        0.5 + 0.5 * ((difference > 0.0) as i32 - (difference < 0.0) as i32) as f32
    } else {
        crate::math::normal_cdf_f32(difference / variance.sqrt())
    }
}

/// The squared number of standard deviations x^2 beyond which the f32 Phi(x) of
/// [`crate::math::normal_cdf_f32`] is exactly 0 or 1: there erfc(|x| / sqrt 2), A&S 7.1.26's
/// poly(t) e^(-x^2 / 2), is below 0.13 e^-20 < 3e-10, far under half an ulp below 1 (2^-25),
/// so that 1 - erfc rounds to 1. Most duels of a sharp Mix-Max are decided by far.
const DECIDED_SQUARED_SIGMAS: f32 = 40.0;

/// Mix-Max's weights (see [`Blend::MixMax`]) of the tiles `lookups`, whose priority maps read
/// `moments` (mean and variance over each tile's footprint): each pair of live tiles duels once,
/// the winner's probability p multiplying one weight and 1 - p the other; normalised.
pub(super) fn mix_max_weights(
    lookups: &[TileLookup],
    moments: &[(f32, f32)],
    contrast: f32,
    lambda: f32,
) -> [f32; MAX_LOOKUPS] {
    // The pavings' three and four tiles in loops of a constant length, unrolled: loops of a
    // varying length mispredict among the duels' own branches.
    let w = match lookups.len() {
        3 => duels::<3>(lookups, moments, contrast, lambda),
        4 => duels::<4>(lookups, moments, contrast, lambda),
        _ => duels::<MAX_LOOKUPS>(lookups, moments, contrast, lambda),
    };
    normalised(w, lookups)
}

/// The unnormalised weights of [`mix_max_weights`] of `lookups`, of which there are at most
/// `K`: loops over the constant `K` tiles and their pairs, which LLVM unrolls, tiles beyond
/// `lookups` left out like dead ones.
#[inline(always)]
fn duels<const K: usize>(
    lookups: &[TileLookup],
    moments: &[(f32, f32)],
    contrast: f32,
    lambda: f32,
) -> [f32; MAX_LOOKUPS] {
    let mut score = [f32::NEG_INFINITY; MAX_LOOKUPS];
    let mut variance = [0.0; MAX_LOOKUPS];
    let mut w = [0.0; MAX_LOOKUPS];
    // Tiles of weight 0 (outside a cut band's reach) take no part.
    let live = |i: usize| lookups.get(i).is_some_and(|l| l.weight > 0.0);
    for i in 0..K {
        if live(i) {
            let (s, var) = moments[i];
            score[i] = contrast * s + lookups[i].weight.ln();
            variance[i] = contrast * contrast * var;
            w[i] = 1.0;
        }
    }
    for i in 0..K {
        for j in i + 1..K {
            if live(i) && live(j) {
                let p = win_probability(score[i] - score[j], variance[i] + variance[j] + 2.0 * lambda * lambda);
                w[i] *= p;
                w[j] *= 1.0 - p;
            }
        }
    }
    w
}

/// Weights `w` of `lookups` divided by their sum; the paving's weights where every tile lost
/// every duel (ties at zero spread).
fn normalised(mut w: [f32; MAX_LOOKUPS], lookups: &[TileLookup]) -> [f32; MAX_LOOKUPS] {
    let k = lookups.len();
    let sum: f32 = w[..k].iter().sum();
    if sum > 0.0 {
        w.iter_mut().for_each(|x| *x /= sum);
    } else {
        for i in 0..k {
            w[i] = lookups[i].weight;
        }
    }
    w
}

/// m + sum w_i (v_i - m) / sqrt(sum w_i^2).
#[inline]
pub(super) fn variance_preserving(w: &[f32], values: &[Vec4], mean: Vec4) -> Vec4 {
    let norm = w.iter().map(|w| w * w).sum::<f32>().sqrt();
    let deviation: Vec4 = w.iter().zip(values).map(|(w, v)| (*v - mean) * *w).sum();
    mean + deviation / norm
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::normal_cdf_f32;

    #[test]
    fn a_duel_decided_by_far_is_the_step_that_phi_rounds_to() {
        let mut decided = 0;
        for e in -60..=60 {
            let variance = 10f32.powf(e as f32 * 0.5);
            let sigma = variance.sqrt();
            // From well inside the threshold (6.3 sigmas) to far beyond it, on both sides.
            for i in 0..400 {
                let difference = sigma * (5.0 + i as f32 * 0.01) * if i % 2 == 0 { 1.0 } else { -1.0 };
                let exact = normal_cdf_f32(difference / sigma);
                assert_eq!(win_probability(difference, variance).to_bits(), exact.to_bits(), "{difference} {variance}");
                decided += (difference * difference > DECIDED_SQUARED_SIGMAS * variance) as usize;
            }
        }
        assert!(decided > 10_000, "the shortcut was taken {decided} times");
        // Without spread: a step, 1/2 on a tie.
        assert_eq!(
            [win_probability(1e-30, 0.0), win_probability(-1e-30, 0.0), win_probability(0.0, 0.0)],
            [1.0, 0.0, 0.5]
        );
    }
}
