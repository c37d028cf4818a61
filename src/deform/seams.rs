//! The seam metric (issue metric for paper 000 Sec. 5): at corresponding points of the two
//! sides of every cut, the texture's values T_left and T_right; the surface-length-weighted mean
//! of |T_left - T_right| (averaged over RGB) divided by the exemplar's standard deviation
//! (averaged over RGB). Independent values would give about 2 / sqrt(pi) = 1.13; a texture
//! continuous across the cuts gives 0.

use super::Cuts;
use crate::image::Bitmap;
use crate::texture::{TexCtx, TilingBlending};
use glam::{Vec2, Vec3};

/// The standard deviation of each of the first three channels of `image`.
pub fn channel_std(image: &Bitmap) -> Vec3 {
    let n = (image.width * image.height) as f64;
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for texel in image.data.chunks_exact(image.channels) {
        for c in 0..3 {
            let v = texel[c.min(image.channels - 1)] as f64;
            sum[c] += v;
            sum2[c] += v * v;
        }
    }
    Vec3::from_array([0, 1, 2].map(|c| ((sum2[c] / n - (sum[c] / n).powi(2)).max(0.0)).sqrt() as f32))
}

/// mean |T_left - T_right| / std(exemplar) over `cuts`, `samples` point lookups per cut edge
/// (no footprint). None without cuts or for a constant exemplar.
pub fn seam_metric(cuts: &Cuts, texture: &TilingBlending, exemplar_std: Vec3, samples: usize) -> Option<f64> {
    let spread = exemplar_std.element_sum() / 3.0;
    if !(spread > 0.0) {
        return None;
    }
    let at = |uv: Vec2| texture.eval(&TexCtx { uv, ..Default::default() }).truncate();
    let mean = cuts.seam_difference(samples, |left, right| (at(left) - at(right)).abs().element_sum() / 3.0)?;
    Some(mean / spread as f64)
}
