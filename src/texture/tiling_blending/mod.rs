//! Deformed tiling and blending (paper 000 Sec. 3, Eq. 1-3 and Sec. 6.1; DESIGN.md section 4):
//! a texture synthesised at every lookup by blending k pseudo-randomly shifted copies (tiles)
//! of an exemplar, each read at E(F(u) (u - c_i) + h_i) with the footprint multiplied by F(u).
//!
//! A [`Synthesis`] is the paving, the shifts, the deformation field and the blending weights;
//! a [`TilingBlending`] texture is one exemplar read through a synthesis. The layers of a
//! material (albedo, roughness, normal, ...) share one `Arc<Synthesis>` so that they all see the
//! same tiles, shifts and weights and stay registered (paper 000 Sec. 6.2).

mod charts;
mod cuts;
mod deformation;
mod histogram;
mod lattice;
mod operators;
pub mod params;
mod shift;
mod synthesis;
mod tiling;

pub use charts::Charts;
pub use cuts::{BANDS_PER_POINT, BandLookup, CutBands, CutCurve, CutPoint, cuts_from_json, cuts_to_json};
pub use deformation::{Deformation, DeformationField, FieldAt, MAX_DEFORMATION};
pub use histogram::GaussianizedExemplar;
pub use lattice::{lattice_frequencies, lattice_visibility, synthesis_lattice_visibility};
pub use operators::{Blend, PriorityMap};
// Constants the shaders repeat, which `src/shader.rs`'s tests compare.
#[cfg(test)]
pub(crate) use cuts::SEARCH as CUT_SEARCH;
#[cfg(test)]
pub(crate) use shift::CUT_SALT;
pub use shift::{cut_shift, fold_seed, shift};
pub use synthesis::{MAX_LOOKUPS, Synthesis, TileLookup};
pub use tiling::{MAX_TILES, Tile, Tiling};

use super::{PreparedFootprint, Taps, TexCtx, Texture};
use glam::{Vec2, Vec3, Vec4};
use std::sync::Arc;

/// The exemplar of a tiling-and-blending texture, as its blending operator needs it.
#[derive(Clone, Debug)]
enum Exemplar {
    /// Read directly; `mean` for the variance-preserving operator. `paired_priority`: the
    /// exemplar is an image whose Mix-Max priority map reads like it (same layout, filter and
    /// mapping), so that one addressing reads both ([`ImageTexture::taps`]).
    Plain { texture: Arc<Texture>, mean: Vec4, paired_priority: bool },
    /// Read in Gaussian space (histogram-preserving operator).
    Gaussianized(Box<GaussianizedExemplar>),
}

/// A tiling-and-blending texture: an exemplar read through a [`Synthesis`].
#[derive(Clone, Debug)]
pub struct TilingBlending {
    /// The tiles, shifts, deformation and weights (shared by the layers of a material).
    pub synthesis: Arc<Synthesis>,
    exemplar: Exemplar,
}

impl TilingBlending {
    /// The texture that reads `exemplar` through `synthesis`. The histogram-preserving operator
    /// needs an image exemplar.
    pub fn new(synthesis: Arc<Synthesis>, exemplar: Arc<Texture>) -> Result<Self, String> {
        let exemplar = match (&synthesis.blend, exemplar.as_ref()) {
            (Blend::HistogramPreserving, Texture::Image(image)) => {
                Exemplar::Gaussianized(Box::new(GaussianizedExemplar::new(image)))
            }
            (Blend::HistogramPreserving, _) => {
                return Err("the histogram_preserving operator needs an image exemplar".into());
            }
            _ => Exemplar::Plain {
                mean: texture_mean(&exemplar),
                paired_priority: match (&synthesis.blend, exemplar.as_ref()) {
                    (Blend::MixMax { priority, .. }, Texture::Image(image)) => priority.reads_like(image),
                    _ => false,
                },
                texture: exemplar,
            },
        };
        Ok(TilingBlending { synthesis, exemplar })
    }

    /// The same exemplar read through another synthesis (which must use the same blending
    /// operator).
    pub fn with_synthesis(&self, synthesis: Arc<Synthesis>) -> Self {
        TilingBlending { synthesis, exemplar: self.exemplar.clone() }
    }

    /// The exemplar's image (its Gaussianized image for the histogram-preserving operator);
    /// None for a procedural exemplar.
    pub fn exemplar_image(&self) -> Option<&crate::image::Bitmap> {
        match &self.exemplar {
            Exemplar::Plain { texture, .. } => match texture.as_ref() {
                Texture::Image(image) => Some(image.mipmap.level(0)),
                _ => None,
            },
            Exemplar::Gaussianized(g) => Some(g.gaussian.mipmap.level(0)),
        }
    }

    /// The synthesised value at the lookup (Eq. 1 with the blending operator).
    pub fn eval(&self, ctx: &TexCtx) -> Vec4 {
        let s = &*self.synthesis;
        let mut lookups = [TileLookup::default(); MAX_LOOKUPS];
        let k = s.lookups_into(ctx, &mut lookups);
        let lookups = &lookups[..k];
        let mut values = [Vec4::ZERO; MAX_LOOKUPS];
        match &self.exemplar {
            Exemplar::Plain { texture, mean, paired_priority } => {
                let (values, w) = self.values_and_weights(texture, *paired_priority, lookups);
                match s.blend {
                    Blend::VariancePreserving => operators::variance_preserving(&w[..k], &values[..k], *mean),
                    _ => (0..k).map(|i| values[i] * w[i]).sum(),
                }
            }
            Exemplar::Gaussianized(g) => {
                for i in 0..k {
                    values[i] = g.eval(&lookups[i].ctx);
                }
                let w = s.blend.weights(lookups, &values, None);
                let blended =
                    operators::variance_preserving(&w[..k], &values[..k], Vec4::splat(histogram::GAUSSIAN_MEAN));
                // All tiles' footprints are F times the same one: they read the same level.
                g.invert(blended, &lookups[0].ctx)
            }
        }
    }

    /// The exemplar `texture`'s values at the tiles' `lookups` and the operator's weights;
    /// `paired_priority` as in [`Exemplar::Plain`]. The value of a tile of weight 0 may be left
    /// unread (0).
    fn values_and_weights(
        &self,
        texture: &Arc<Texture>,
        paired_priority: bool,
        lookups: &[TileLookup],
    ) -> ([Vec4; MAX_LOOKUPS], [f32; MAX_LOOKUPS]) {
        let mut values = [Vec4::ZERO; MAX_LOOKUPS];
        let Texture::Image(image) = texture.as_ref() else {
            for (value, lookup) in values.iter_mut().zip(lookups) {
                *value = texture.eval(&lookup.ctx);
            }
            return (values, self.synthesis.blend.weights(lookups, &values, Some(texture)));
        };
        // The tiles' footprints are F times the same one, and equal where F is read at the
        // point: each footprint is prepared once for the tiles in a row that share it.
        let mut prepared: Option<(Vec2, Vec2, PreparedFootprint)> = None;
        let mut footprint = |ctx: &TexCtx| match prepared {
            Some((dx, dy, footprint)) if (dx, dy) == (ctx.duv_dx, ctx.duv_dy) => footprint,
            _ => {
                let footprint = image.prepare(ctx.duv_dx, ctx.duv_dy);
                prepared = Some((ctx.duv_dx, ctx.duv_dy, footprint));
                footprint
            }
        };
        if let (true, Blend::MixMax { priority, contrast, lambda }) = (paired_priority, &self.synthesis.blend) {
            // Each tile's texels are found once: its priorities are read there, then its value
            // only if the duels left it a weight (often not: a tile that loses every duel by
            // far weighs exactly 0), which gives the same sum as reading every value. An EWA
            // ellipse's texels would be searched again: there both are read in one pass.
            let map = &priority.image().mipmap;
            // The tiles with one footprint (F read at the point), up to four, are addressed and
            // their priorities filtered in SSE lanes, a tile per lane.
            let shared =
                |l: &TileLookup| (l.ctx.duv_dx, l.ctx.duv_dy) == (lookups[0].ctx.duv_dx, lookups[0].ctx.duv_dy);
            if (1..=4).contains(&lookups.len()) && lookups.iter().all(shared) {
                let uv = std::array::from_fn(|i| lookups.get(i).map_or(Vec2::ZERO, |l| l.ctx.uv));
                if let Some(taps) = image.taps_x4(uv, &footprint(&lookups[0].ctx)) {
                    let [s, s2] = map.gather_two_channels_x4(&taps);
                    let moments: [(f32, f32); 4] = std::array::from_fn(|i| PriorityMap::moments(s[i], s2[i]));
                    let w = operators::mix_max_weights(lookups, &moments[..lookups.len()], *contrast, *lambda);
                    for i in (0..lookups.len()).filter(|&i| w[i] != 0.0) {
                        values[i] = image.mipmap.gather(&taps.lane(i));
                    }
                    return (values, w);
                }
            }
            let mut unread: [Option<Taps>; MAX_LOOKUPS] = [None; MAX_LOOKUPS];
            let mut moments = [(0.0, 0.0); MAX_LOOKUPS];
            for (i, lookup) in lookups.iter().enumerate() {
                let taps = image.taps(lookup.ctx.uv, &footprint(&lookup.ctx));
                let p = if taps.is_ellipse() {
                    let (value, p) = image.mipmap.gather_pair(map, &taps);
                    values[i] = value;
                    p
                } else {
                    unread[i] = Some(taps);
                    map.gather(&taps)
                };
                moments[i] = PriorityMap::moments(p.x, p.w);
            }
            let w = operators::mix_max_weights(lookups, &moments[..lookups.len()], *contrast, *lambda);
            for (i, taps) in unread.iter().enumerate() {
                if let Some(taps) = taps
                    && w[i] != 0.0
                {
                    values[i] = image.mipmap.gather(taps);
                }
            }
            return (values, w);
        }
        for (value, lookup) in values.iter_mut().zip(lookups) {
            *value = image.eval_prepared(lookup.ctx.uv, &footprint(&lookup.ctx));
        }
        (values, self.synthesis.blend.weights(lookups, &values, Some(texture)))
    }

    /// A tangent-space normal map read through the synthesis: the tiles' normals (RGB in [0, 1]
    /// encoding 2 rgb - 1) are blended as slopes (x / z, y / z) with the operator's weights,
    /// never as raw RGB, and returned as a unit normal in the exemplar's frame (DESIGN.md
    /// section 4). [`TilingBlending::tangent_direction`] says where that frame's x axis lies.
    pub fn eval_normal(&self, ctx: &TexCtx) -> Option<Vec3> {
        let Exemplar::Plain { texture, paired_priority, .. } = &self.exemplar else { return None };
        let mut lookups = [TileLookup::default(); MAX_LOOKUPS];
        let k = self.synthesis.lookups_into(ctx, &mut lookups);
        let (values, w) = self.values_and_weights(texture, *paired_priority, &lookups[..k]);
        let total: f32 = w[..k].iter().sum();
        let mut slope = Vec2::ZERO;
        for i in 0..k {
            let n = values[i].truncate() * 2.0 - Vec3::ONE;
            slope += Vec2::new(n.x, n.y) / n.z.max(1e-3) * (w[i] / total);
        }
        Vec3::new(slope.x, slope.y, 1.0).try_normalize()
    }

    /// The direction in UV of the exemplar's x axis at `uv` on a surface whose UV map is
    /// `uv_mirrored` or not: F(u)^-1 e1 (DESIGN.md section 3; F as
    /// [`DeformationField::at_surface`] gives it), and whether F reverses orientation. None
    /// without a deformation field or where F is singular.
    pub fn tangent_direction(&self, uv: Vec2, uv_mirrored: Option<bool>) -> Option<(Vec2, bool)> {
        let f = self.synthesis.deformation.as_ref()?.at_surface(uv, uv_mirrored);
        let det = f.determinant();
        if !(det.abs() > 1e-12) {
            return None;
        }
        // F^-1 e1 = (f11, -f10) / det.
        Some((Vec2::new(f.y_axis.y, -f.x_axis.y) / det, det < 0.0))
    }

    /// True when lookups use the footprint.
    pub fn uses_footprint(&self) -> bool {
        let exemplar = match &self.exemplar {
            Exemplar::Plain { texture, .. } => texture.uses_footprint(),
            Exemplar::Gaussianized(g) => g.gaussian.filter != super::Filter::None,
        };
        exemplar || self.synthesis.blend.uses_footprint()
    }

    /// Approximate memory held, in bytes (a shared synthesis is counted by every layer).
    pub fn memory_bytes(&self) -> usize {
        let exemplar = match &self.exemplar {
            Exemplar::Plain { texture, .. } => texture.memory_bytes(),
            Exemplar::Gaussianized(g) => g.memory_bytes(),
        };
        exemplar + self.synthesis.memory_bytes()
    }
}

/// The mean of a texture over the unit square: exact for an image (its 1x1 MIP level, which
/// box filtering makes the mean), else the average of a 256 x 256 grid of point lookups.
fn texture_mean(texture: &Texture) -> Vec4 {
    if let Texture::Image(image) = texture {
        let top = image.mipmap.level(image.mipmap.level_count() - 1);
        return top.pixel(0, 0);
    }
    let n = 256;
    let mut sum = Vec4::ZERO;
    for j in 0..n {
        for i in 0..n {
            let uv = (Vec2::new(i as f32, j as f32) + 0.5) / n as f32;
            sum += texture.eval(&TexCtx { uv, ..Default::default() });
        }
    }
    sum / (n * n) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::Bitmap;
    use crate::texture::{Filter, ImageTexture, MipMap};
    use glam::Mat2;

    /// Mix-Max of a trilinear exemplar takes the lanes' path ([`MipMap::taps_x4`]); its blend is
    /// the scalar definition's: the operator's weights from the priority map's own lookups,
    /// times the exemplar's own lookups, bit for bit.
    #[test]
    fn mix_max_in_lanes_is_the_scalar_blend_bit_for_bit() {
        let mut bitmap = Bitmap::new(37, 29, 3);
        for (i, v) in bitmap.data.iter_mut().enumerate() {
            *v = ((i * 2_654_435_761) % 1000) as f32 / 1000.0;
        }
        let image = ImageTexture {
            mipmap: Arc::new(MipMap::new(bitmap)),
            filter: Filter::Trilinear,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        };
        let blend = Blend::MixMax { priority: PriorityMap::new(&image), contrast: 4.0, lambda: 0.05 };
        let exemplar = Arc::new(Texture::Image(image));
        let rotation = Deformation::Constant(Mat2::from_angle(0.7) * 1.3);
        for deformation in [None, Some(DeformationField::new(vec![rotation]))] {
            let synthesis = Synthesis {
                tiling: Tiling::Hexagonal,
                tile_size: 0.25,
                seed: 3,
                deformation,
                cuts: None,
                blend: blend.clone(),
                inset: false,
            };
            let texture = TilingBlending::new(Arc::new(synthesis), exemplar.clone()).expect("an image exemplar");
            let s = &texture.synthesis;
            for i in 0..4000 {
                let uv = Vec2::new(i as f32 * 0.013_7 - 20.0, (i * i % 997) as f32 * 0.007_1);
                let dx = Vec2::from_angle(i as f32) * (0.2 / (1 + i % 60) as f32);
                let ctx = TexCtx { uv, duv_dx: dx, duv_dy: dx.perp() * 0.5, uv_mirrored: None };
                let (lookups, k) = s.lookups(&ctx);
                let w = s.blend.weights(&lookups[..k], &[Vec4::ZERO; MAX_LOOKUPS][..k], None);
                let expected: Vec4 =
                    (0..k).map(|t| if w[t] != 0.0 { exemplar.eval(&lookups[t].ctx) * w[t] } else { Vec4::ZERO }).sum();
                let bits = |v: Vec4| v.to_array().map(f32::to_bits);
                assert_eq!(bits(texture.eval(&ctx)), bits(expected), "{uv}");
            }
        }
    }
}
