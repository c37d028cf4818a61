//! The synthesis of deformed tiling and blending (paper 000 Eq. 1-3 and Sec. 6.1): at a point u,
//! the k tiles of the paving that cover it, each read at E(F(u) (u - c_i) + h_i) with the
//! footprint F(u) du/dx, F(u) du/dy (or with F(c_i) in place of F(u): [`super::FieldAt`]), and
//! the cut bands' rows of tiles near a UV cut (Eq. 8,
//! [`CutBands`]). `shaders/tiling_blending/synthesis.wgsl` is the GPU port of this file.

use super::shift::{cut_shift, shift};
use super::{BANDS_PER_POINT, Blend, CutBands, DeformationField, MAX_TILES, Tiling};
use crate::math::largest_singular_value;
use crate::texture::TexCtx;
use glam::{Mat2, Vec2};

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
    pub fn lookups(&self, ctx: &TexCtx) -> ([TileLookup; MAX_LOOKUPS], usize) {
        let mut out = [TileLookup::default(); MAX_LOOKUPS];
        let count = self.lookups_into(ctx, &mut out);
        (out, count)
    }

    /// [`Synthesis::lookups`] written to the first entries of `out`, the caller's array; returns
    /// how many. Texture lookups use this: an array returned by value was copied, 256 bytes read
    /// in wide loads from the narrower stores just made, which the store buffer cannot forward,
    /// and the lookup waited for them (a tenth of a deformed Mix-Max lookup's time).
    #[inline]
    pub fn lookups_into(&self, ctx: &TexCtx, out: &mut [TileLookup; MAX_LOOKUPS]) -> usize {
        let k = self.tiles_per_point();
        let tiles = self.tiling.tiles(ctx.uv, self.tile_size);
        let f = self.deformation.as_ref().map(|d| d.at_surface(ctx.uv, ctx.uv_mirrored));
        let chart = self.deformation.as_ref().and_then(|d| d.chart_at(ctx.uv));
        for i in 0..k {
            let tile = &tiles[i];
            let h = shift(tile.vertex, self.seed);
            let h = if self.inset { inset_shift(h, self.tile_reach(tile.centre)) } else { h };
            let offset = ctx.uv - tile.centre;
            out[i].weight = tile.weight;
            out[i].ctx = match (f, &self.deformation) {
                (Some(f), Some(field)) => {
                    let f = field.for_tile(tile.centre, chart, ctx.uv_mirrored, f);
                    TexCtx { uv: f * offset + h, duv_dx: f * ctx.duv_dx, duv_dy: f * ctx.duv_dy, uv_mirrored: None }
                }
                _ => TexCtx { uv: offset + h, uv_mirrored: None, ..*ctx },
            };
        }
        k + self.band_lookups(ctx, f.unwrap_or(Mat2::IDENTITY), out)
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

    /// Approximate memory held by the deformation field and weight maps, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.blend.memory_bytes()
            + self.deformation.as_ref().map_or(0, |d| d.memory_bytes())
            + self.cuts.as_ref().map_or(0, |c| c.memory_bytes())
    }
}

/// A shift `h` uniform over the exemplar's square narrowed, along each axis where the tile fits,
/// to the positions that keep the tile (reaching `reach` from its centre) inside the square.
#[inline]
fn inset_shift(h: Vec2, reach: Vec2) -> Vec2 {
    let narrowed = reach + h * (Vec2::ONE - 2.0 * reach);
    Vec2::select(reach.cmplt(Vec2::splat(0.5)), narrowed, h)
}
