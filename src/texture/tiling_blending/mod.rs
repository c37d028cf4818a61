//! Deformed tiling and blending (paper 000 Sec. 3, Eq. 1-3 and Sec. 6.1; DESIGN.md section 4):
//! a texture synthesised at every lookup by blending k pseudo-randomly shifted copies (tiles)
//! of an exemplar, each read at E(F(u) (u - c_i) + h_i) with the footprint multiplied by F(u).
//!
//! A [`Synthesis`] is the paving, the shifts, the deformation field and the blending weights;
//! a [`TilingBlending`] texture is one exemplar read through a synthesis. The layers of a
//! material (albedo, roughness, normal, ...) share one `Arc<Synthesis>` so that they all see the
//! same tiles, shifts and weights and stay registered (paper 000 Sec. 6.2).

mod cuts;
mod deformation;
mod histogram;
mod lattice;
mod tiling;

pub use cuts::{BANDS_PER_POINT, BandLookup, CutBands, CutCurve, CutPoint, cuts_from_json, cuts_to_json};
pub use deformation::{Deformation, DeformationField};
pub use histogram::GaussianizedExemplar;
pub use lattice::{lattice_frequencies, lattice_visibility, synthesis_lattice_visibility};
pub use tiling::{MAX_TILES, Tile, Tiling, cut_shift, shift};

use super::{ImageTexture, TexCtx, Texture};
use crate::color::{Rgb, luminance};
use crate::math::largest_singular_value;
use glam::{Mat2, Vec2, Vec3, Vec4};
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
/// footprint.
#[derive(Clone, Debug)]
pub struct PriorityMap {
    /// Channels: s, s^2 (read back as RGB = s, A = s^2).
    map: ImageTexture,
}

impl PriorityMap {
    /// The priority map of an image (its RGB mean).
    pub fn new(image: &ImageTexture) -> Self {
        let base = image.mipmap.level(0);
        let mut moments = crate::image::Bitmap::new(base.width, base.height, 2);
        for y in 0..base.height {
            for x in 0..base.width {
                let s = super::Channel::Mean.select(base.pixel(x, y));
                moments.values_mut(x, y).copy_from_slice(&[s, s * s]);
            }
        }
        let map = ImageTexture {
            mipmap: Arc::new(super::MipMap::new(moments)),
            filter: image.filter,
            scale: image.scale,
            offset: image.offset,
        };
        PriorityMap { map }
    }

    /// Mean and variance of the priority over the lookup's footprint.
    #[inline]
    fn mean_and_variance(&self, ctx: &TexCtx) -> (f32, f32) {
        let v = self.map.eval(ctx);
        (v.x, (v.w - v.x * v.x).max(0.0))
    }

    fn memory_bytes(&self) -> usize {
        self.map.mipmap.memory_bytes()
    }
}

/// The tiles, shifts, deformation and weights of a tiling-and-blending texture.
#[derive(Clone, Debug)]
pub struct Synthesis {
    /// The paving.
    pub tiling: Tiling,
    /// Lattice spacing in UV units.
    pub tile_size: f32,
    /// Seed of the tiles' shifts.
    pub seed: u64,
    /// The deformation field F; None is classical tiling and blending (Eq. 2).
    pub deformation: Option<DeformationField>,
    /// The cut bands: near a UV cut, rows of tiles along the cut that both of its sides read
    /// alike ([`CutBands`]). None leaves cuts alone. They need an F map among the deformation's
    /// factors (their lengths are in its units).
    pub cuts: Option<CutBands>,
    /// The blending operator.
    pub blend: Blend,
    /// Keep each tile inside the exemplar's unit square where it fits (for exemplars that do
    /// not tile): the shift of tile i is drawn, per axis, in [r_i, 1 - r_i], r_i the tile's
    /// reach in the exemplar (its support's extent through F at its centre). Otherwise shifts
    /// are uniform over the square and lookups wrap around it.
    pub inset: bool,
}

/// Most lookups at a point: the paving's tiles and two tiles per cut band.
pub const MAX_LOOKUPS: usize = MAX_TILES + 2 * BANDS_PER_POINT;

/// One tile's lookup into the exemplar and its paving weight.
#[derive(Clone, Copy, Debug, Default)]
pub struct TileLookup {
    /// Where the exemplar is read: F(u) (u - c_i) + h_i, footprint F(u) du/dx, F(u) du/dy.
    pub ctx: TexCtx,
    /// The paving's weight w_i(u).
    pub weight: f32,
}

impl Synthesis {
    /// Number of tiles blended at each point.
    pub fn tiles_per_point(&self) -> usize {
        self.tiling.tiles_per_point()
    }

    /// F at `uv` (the identity without a deformation field).
    #[inline]
    pub fn deformation_at(&self, uv: Vec2) -> Mat2 {
        self.deformation.as_ref().map_or(Mat2::IDENTITY, |d| d.at(uv))
    }

    /// The tiles' exemplar lookups at `ctx` (Eq. 3; Sec. 6.1 for the footprint) and how many
    /// there are. Without a deformation field the lookup is u - c_i + h_i: Eq. 2 with the shift
    /// h_i - c_i, so that F = identity reproduces it exactly. Within a cut band of weight psi
    /// the paving's weights are scaled by 1 - psi and the band's row of tiles along the cut
    /// takes the rest ([`CutBands`]); where two bands overlap, band b weighs
    /// psi_b (1 - psi_other), normalised, so that on a cut only its own row is read.
    #[inline]
    pub fn lookups(&self, ctx: &TexCtx) -> ([TileLookup; MAX_LOOKUPS], usize) {
        let k = self.tiles_per_point();
        let tiles = self.tiling.tiles(ctx.uv, self.tile_size);
        let f = self.deformation.as_ref().map(|d| d.at_surface(ctx.uv, ctx.uv_mirrored));
        let mut out = [TileLookup::default(); MAX_LOOKUPS];
        for i in 0..k {
            let tile = &tiles[i];
            let h = shift(tile.vertex, self.seed);
            let h = if self.inset { inset_shift(h, self.tile_reach(tile.centre)) } else { h };
            let offset = ctx.uv - tile.centre;
            out[i].weight = tile.weight;
            out[i].ctx = match f {
                None => TexCtx { uv: offset + h, uv_mirrored: None, ..*ctx },
                Some(f) => {
                    TexCtx { uv: f * offset + h, duv_dx: f * ctx.duv_dx, duv_dy: f * ctx.duv_dy, uv_mirrored: None }
                }
            };
        }
        let count = k + self.band_lookups(ctx, f.unwrap_or(Mat2::IDENTITY), &mut out);
        (out, count)
    }

    /// Append the cut bands' lookups at `ctx` after the paving's (`f` is F there), reweighting
    /// both; returns how many were appended.
    #[inline]
    fn band_lookups(&self, ctx: &TexCtx, f: Mat2, out: &mut [TileLookup; MAX_LOOKUPS]) -> usize {
        let (Some(cuts), Some(field)) = (&self.cuts, &self.deformation) else { return 0 };
        if !cuts.near(ctx.uv) {
            return 0;
        }
        let Some(f_map) = field.map_at(ctx.uv, ctx.uv_mirrored) else { return 0 };
        let bands = cuts.at(ctx.uv, f_map);
        if bands.iter().all(Option::is_none) || !(f_map.determinant().abs() > 1e-20) {
            return 0;
        }
        // The factors other than the map, which carry map units to the exemplar's.
        let other = f * f_map.inverse();
        let psi = bands.map(|b| b.map_or(0.0, |b| b.weight));
        let mut band_weight = [0.0f32; BANDS_PER_POINT];
        for b in 0..BANDS_PER_POINT {
            band_weight[b] = psi[b] * (0..BANDS_PER_POINT).filter(|&o| o != b).map(|o| 1.0 - psi[o]).product::<f32>();
        }
        let mut paving: f32 = psi.iter().map(|p| 1.0 - p).product();
        let mut total = paving + band_weight.iter().sum::<f32>();
        if !(total > 1e-6) {
            // On two cuts at once (where they meet): the nearest alone.
            (band_weight, paving, total) = ([1.0, 0.0], 0.0, 1.0);
        }
        let k = self.tiles_per_point();
        for lookup in &mut out[..k] {
            lookup.weight *= paving / total;
        }
        let stretch = largest_singular_value(other);
        let mut n = 0;
        for (band, w) in bands.iter().zip(band_weight) {
            let Some(band) = band else { continue };
            if w <= 0.0 {
                continue;
            }
            for (m, tile_weight, offset) in band.tiles {
                let h = cut_shift(band.curve, m, self.seed);
                let h = if self.inset { inset_shift(h, Vec2::splat(band.reach * stretch)) } else { h };
                out[k + n] = TileLookup {
                    ctx: TexCtx {
                        uv: other * offset + h,
                        duv_dx: f * ctx.duv_dx,
                        duv_dy: f * ctx.duv_dy,
                        uv_mirrored: None,
                    },
                    weight: tile_weight * w / total,
                };
                n += 1;
            }
        }
        n
    }

    /// How far, per axis, a tile centred at `centre` reaches into the exemplar: its support's
    /// corners through F at its centre.
    fn tile_reach(&self, centre: Vec2) -> Vec2 {
        let f = self.deformation_at(centre);
        self.tiling.support_corners().iter().fold(Vec2::ZERO, |r, corner| r.max((f * (*corner * self.tile_size)).abs()))
    }

    /// The blending weights of the tiles: the paving's for the linear and variance-preserving
    /// operators, reweighted and normalised for the others. `values` are the tiles' exemplar
    /// values and `exemplar` their texture (reused when it is the weights' source).
    fn weights(&self, lookups: &[TileLookup], values: &[Vec4], exemplar: Option<&Arc<Texture>>) -> [f32; MAX_LOOKUPS] {
        let k = lookups.len();
        let mut w = [0.0; MAX_LOOKUPS];
        match &self.blend {
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
                let mut score = [f32::NEG_INFINITY; MAX_LOOKUPS];
                let mut variance = [0.0; MAX_LOOKUPS];
                // Tiles of weight 0 (outside a cut band's reach) take no part.
                let live = |i: usize| lookups[i].weight > 0.0;
                for i in (0..k).filter(|&i| live(i)) {
                    let (s, var) = priority.mean_and_variance(&lookups[i].ctx);
                    score[i] = contrast * s + lookups[i].weight.ln();
                    variance[i] = contrast * contrast * var;
                }
                for i in (0..k).filter(|&i| live(i)) {
                    w[i] = (0..k)
                        .filter(|&j| j != i && live(j))
                        .map(|j| {
                            win_probability(score[i] - score[j], variance[i] + variance[j] + 2.0 * lambda * lambda)
                        })
                        .product();
                }
            }
        }
        let sum: f32 = w[..k].iter().sum();
        if sum > 0.0 {
            w.iter_mut().for_each(|x| *x /= sum);
        } else {
            // Every tile lost every duel (ties at zero spread): fall back to the paving.
            for i in 0..k {
                w[i] = lookups[i].weight;
            }
        }
        w
    }

    /// Approximate memory held by the deformation field and weight maps, in bytes.
    pub fn memory_bytes(&self) -> usize {
        let maps = match &self.blend {
            Blend::MixMax { priority, .. } => priority.memory_bytes(),
            _ => 0,
        };
        maps + self.deformation.as_ref().map_or(0, |d| d.memory_bytes())
            + self.cuts.as_ref().map_or(0, |c| c.memory_bytes())
    }

    /// True when the weights read a filtered texture.
    fn uses_footprint(&self) -> bool {
        match &self.blend {
            Blend::Sharpened { source, .. } => source.uses_footprint(),
            Blend::MixMax { priority, .. } => priority.map.filter != super::Filter::None,
            _ => false,
        }
    }
}

/// A shift `h` uniform over the exemplar's square narrowed, along each axis where the tile fits,
/// to the positions that keep the tile (reaching `reach` from its centre) inside the square.
#[inline]
fn inset_shift(h: Vec2, reach: Vec2) -> Vec2 {
    let narrowed = reach + h * (Vec2::ONE - 2.0 * reach);
    Vec2::select(reach.cmplt(Vec2::splat(0.5)), narrowed, h)
}

/// P(X > 0) for X normal with mean `difference` and variance `variance`; a step (1/2 at 0) when
/// the variance is 0.
#[inline]
fn win_probability(difference: f32, variance: f32) -> f32 {
    if variance > 0.0 {
        crate::math::normal_cdf_f32(difference / variance.sqrt())
    } else if difference > 0.0 {
        1.0
    } else if difference < 0.0 {
        0.0
    } else {
        0.5
    }
}

/// The exemplar of a tiling-and-blending texture, as its blending operator needs it.
#[derive(Clone, Debug)]
enum Exemplar {
    /// Read directly; `mean` for the variance-preserving operator.
    Plain { texture: Arc<Texture>, mean: Vec4 },
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
            _ => Exemplar::Plain { mean: texture_mean(&exemplar), texture: exemplar },
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
        let (lookups, k) = s.lookups(ctx);
        let lookups = &lookups[..k];
        let mut values = [Vec4::ZERO; MAX_LOOKUPS];
        match &self.exemplar {
            Exemplar::Plain { texture, mean } => {
                for i in 0..k {
                    values[i] = texture.eval(&lookups[i].ctx);
                }
                let w = s.weights(lookups, &values, Some(texture));
                match s.blend {
                    Blend::VariancePreserving => variance_preserving(&w[..k], &values[..k], *mean),
                    _ => (0..k).map(|i| values[i] * w[i]).sum(),
                }
            }
            Exemplar::Gaussianized(g) => {
                for i in 0..k {
                    values[i] = g.eval(&lookups[i].ctx);
                }
                let w = s.weights(lookups, &values, None);
                let blended = variance_preserving(&w[..k], &values[..k], Vec4::splat(histogram::GAUSSIAN_MEAN));
                // All tiles' footprints are F times the same one: they read the same level.
                g.invert(blended, &lookups[0].ctx)
            }
        }
    }

    /// A tangent-space normal map read through the synthesis: the tiles' normals (RGB in [0, 1]
    /// encoding 2 rgb - 1) are blended as slopes (x / z, y / z) with the operator's weights,
    /// never as raw RGB, and returned as a unit normal in the exemplar's frame (DESIGN.md
    /// section 4). [`TilingBlending::tangent_direction`] says where that frame's x axis lies.
    pub fn eval_normal(&self, ctx: &TexCtx) -> Option<Vec3> {
        let Exemplar::Plain { texture, .. } = &self.exemplar else { return None };
        let s = &*self.synthesis;
        let (lookups, k) = s.lookups(ctx);
        let lookups = &lookups[..k];
        let mut values = [Vec4::ZERO; MAX_LOOKUPS];
        for i in 0..k {
            values[i] = texture.eval(&lookups[i].ctx);
        }
        let w = s.weights(lookups, &values, Some(texture));
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
        exemplar || self.synthesis.uses_footprint()
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

/// m + sum w_i (v_i - m) / sqrt(sum w_i^2).
#[inline]
fn variance_preserving(w: &[f32], values: &[Vec4], mean: Vec4) -> Vec4 {
    let norm = w.iter().map(|w| w * w).sum::<f32>().sqrt();
    let deviation: Vec4 = w.iter().zip(values).map(|(w, v)| (*v - mean) * *w).sum();
    mean + deviation / norm
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
