//! Cut bands: continuity of deformed tiling and blending across UV cuts (DESIGN.md section 6;
//! tessera's answer to paper 000 Sec. 5, whose Eq. 8 shares the tiles' content across a cut
//! but not the paving's weights, and matches F(u)(u - b) to F'(u')(u' - b') only to first
//! order, so that it leaves seams open on real meshes).
//!
//! A cut is a curve on the surface that the UV map embeds twice, on side 0 and on side 1. Along
//! it tessera lays a 1D row of tiles, indexed by the arc length s that both sides share, with a
//! developed exemplar coordinate g(s) shared too (`tessera deform` integrates the field along
//! the cut: g' = F t, the mean of the two sides). Near the cut a point u of either side reads
//! tile m at g(s) - g(s_m) + F(u)(u - p) + h_m, with p the nearest point of its side's copy of
//! the cut and s its arc length: on the cut both sides read exactly the same values. Those
//! tiles are blended by a 1D partition of unity over s (hats one tile spacing wide), weighted
//! against the ordinary paving by psi(d), 1 on the cut and 0 at one tile spacing away
//! (d = |F(u)(u - p)|, measured in map units): a band one tile wide on each side.

use crate::image::Bitmap;
use crate::math::{floor, largest_singular_value};
use glam::{Mat2, Vec2};

/// A point of a cut: its UV on both sides, its arc length and its developed coordinate (both in
/// the F map's units, the surface's where F is exact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutPoint {
    /// UV on side 0 and on side 1.
    pub uv: [Vec2; 2],
    /// Arc length from the cut's start.
    pub s: f32,
    /// The developed exemplar coordinate g(s).
    pub g: Vec2,
}

/// One cut: a polyline seen from its two sides.
#[derive(Clone, Debug, PartialEq)]
pub struct CutCurve {
    points: Vec<CutPoint>,
    /// Map units per UV unit along the cut (the mean over both sides): the row's tile spacing is
    /// the synthesis' tile size times this, so that cut tiles are as large as the ordinary ones.
    scale: f32,
}

impl CutCurve {
    /// A cut through `points` (at least two, arc length non-decreasing, everything finite), with
    /// `scale` map units per UV unit along it (positive).
    pub fn new(points: Vec<CutPoint>, scale: f32) -> Result<Self, String> {
        if points.len() < 2 {
            return Err(format!("a cut needs at least two points, not {}", points.len()));
        }
        if !(scale > 0.0 && scale.is_finite()) {
            return Err(format!("a cut's scale must be a positive number, not {scale}"));
        }
        for (k, p) in points.iter().enumerate() {
            let finite = p.uv[0].is_finite() && p.uv[1].is_finite() && p.s.is_finite() && p.g.is_finite();
            let bounded = p.uv.iter().all(|u| u.abs().max_element() <= 1e4) && p.s.abs() <= 1e9;
            if !(finite && bounded) {
                return Err(format!("cut point {k} is not finite or out of range (UVs within 1e4)"));
            }
            if k > 0 && !(p.s >= points[k - 1].s) {
                return Err(format!("cut point {k}: the arc length decreases ({} after {})", p.s, points[k - 1].s));
            }
        }
        Ok(CutCurve { points, scale })
    }

    /// The points.
    pub fn points(&self) -> &[CutPoint] {
        &self.points
    }

    /// Map units per UV unit along the cut.
    pub fn scale(&self) -> f32 {
        self.scale
    }

    /// g at arc length `s`, clamped to the cut's ends.
    fn g_at(&self, s: f32) -> Vec2 {
        let k = self.points.partition_point(|p| p.s <= s);
        if k == 0 {
            return self.points[0].g;
        }
        if k == self.points.len() {
            return self.points[k - 1].g;
        }
        let (a, b) = (&self.points[k - 1], &self.points[k]);
        let t = if b.s > a.s { (s - a.s) / (b.s - a.s) } else { 0.0 };
        a.g.lerp(b.g, t)
    }
}

/// The cuts file `tessera deform` writes (`cuts.json`): per cut, its scale and its points as
/// [u0, v0, u1, v1, s, gx, gy].
#[derive(serde::Serialize, serde::Deserialize)]
struct CutsFile {
    curves: Vec<CurveRecord>,
}

#[derive(serde::Serialize, serde::Deserialize)]
struct CurveRecord {
    scale: f32,
    points: Vec<[f32; 7]>,
}

/// Parse a cuts file's text.
pub fn cuts_from_json(text: &str) -> Result<Vec<CutCurve>, String> {
    let file: CutsFile = serde_json::from_str(text).map_err(|e| format!("not a cuts file: {e}"))?;
    file.curves
        .into_iter()
        .enumerate()
        .map(|(c, r)| {
            let points = r
                .points
                .iter()
                .map(|p| CutPoint {
                    uv: [Vec2::new(p[0], p[1]), Vec2::new(p[2], p[3])],
                    s: p[4],
                    g: Vec2::new(p[5], p[6]),
                })
                .collect();
            CutCurve::new(points, r.scale).map_err(|e| format!("cut {c}: {e}"))
        })
        .collect()
}

/// The text of a cuts file.
pub fn cuts_to_json(curves: &[CutCurve]) -> String {
    let file = CutsFile {
        curves: curves
            .iter()
            .map(|c| CurveRecord {
                scale: c.scale,
                points: c
                    .points
                    .iter()
                    .map(|p| [p.uv[0].x, p.uv[0].y, p.uv[1].x, p.uv[1].y, p.s, p.g.x, p.g.y])
                    .collect(),
            })
            .collect(),
    };
    serde_json::to_string(&file).expect("plain numbers serialise")
}

/// Cut bands a texel can be in at once (the two nearest; more meet only at isolated points).
pub const BANDS_PER_POINT: usize = 2;

/// Segments either side of a texel's nearest one searched for a point's nearest (a point within
/// a texel of the texel's centre has its nearest point of the cut a texel from the centre's)
/// and for the arc length the row's weights use.
pub(crate) const SEARCH: usize = 4;

/// Most texel visits of the bands' rasterisation (a few seconds).
const MAX_BAND_WORK: u64 = 1 << 28;

/// Most tiles laid along all the cuts together (their anchors g(s_m) are precomputed).
const MAX_CUT_TILES: usize = 1 << 24;

/// A texel's reference to a side of a cut: (curve, side, segment), or none.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BandRef {
    curve: u32,
    /// Segment index times 2, plus the side.
    segment_side: u32,
}

const NO_BAND: BandRef = BandRef { curve: u32::MAX, segment_side: 0 };

/// A point's place in one cut's band: the weight of the band against the paving, and the two
/// tiles of the cut's row covering it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandLookup {
    /// psi(d): 1 on the cut, 0 at the band's edge.
    pub weight: f32,
    /// The cut.
    pub curve: u32,
    /// The two tiles: their index m along the row, their 1D weight (a partition of unity over
    /// s) and the offset g(s) - g(s_m) + F(u)(u - p), in map units.
    pub tiles: [(i64, f32, Vec2); 2],
    /// How far any of this row's lookups reach from their tile's origin, in map units.
    pub reach: f32,
}

/// The cuts of a mesh, ready for lookups: the curves, their tiles' anchors, and per texel of
/// the UV square (the F map's raster) the nearest sides of cuts within a band.
#[derive(Clone, Debug)]
pub struct CutBands {
    curves: Vec<CutCurve>,
    /// Tile spacing of each curve's row, in map units.
    spacing: Vec<f32>,
    /// g(s_m) for each curve's tiles, m from 0: s_m = s_0 + m spacing.
    anchors: Vec<Vec<Vec2>>,
    res: usize,
    /// Row-major from the top row (v = 1), as image textures are laid out.
    texels: Vec<[BandRef; BANDS_PER_POINT]>,
}

impl CutBands {
    /// Bands of the `curves` for tiles of lattice spacing `tile_size` (UV units), found on the
    /// raster of the square F map `f_map` (4 channels, row 0 at v = 1) that measures distances.
    pub fn new(curves: Vec<CutCurve>, f_map: &Bitmap, tile_size: f32) -> Result<Self, String> {
        if f_map.channels != 4 || f_map.width != f_map.height || f_map.width == 0 {
            return Err("cut bands need a square four-channel F map".into());
        }
        let res = f_map.width;
        let spacing: Vec<f32> = curves.iter().map(|c| tile_size * c.scale).collect();
        let mut anchors = Vec::with_capacity(curves.len());
        let mut total = 0usize;
        for (c, h) in curves.iter().zip(&spacing) {
            if !(h.is_finite() && *h > 0.0) {
                return Err(format!("the tile size {tile_size} gives a cut of scale {} no tile spacing", c.scale));
            }
            let (s0, s1) = (c.points[0].s, c.points[c.points.len() - 1].s);
            // A float cast saturates: an enormous ratio becomes usize::MAX, refused below.
            let count = (((s1 - s0) / h).ceil() as usize).saturating_add(2);
            total = total.saturating_add(count);
            if total > MAX_CUT_TILES {
                return Err(format!(
                    "the tile size {tile_size} lays more than {MAX_CUT_TILES} tiles along the cuts: too small for them"
                ));
            }
            anchors.push((0..count).map(|m| c.g_at(s0 + m as f32 * h)).collect());
        }
        let f_at = |uv: Vec2| {
            let i = ((uv.x * res as f32) as usize).min(res - 1);
            let j = ((crate::texture::image_coordinates(uv).y * res as f32) as usize).min(res - 1);
            let t = f_map.values(i, j);
            Mat2::from_cols(Vec2::new(t[0], t[2]), Vec2::new(t[1], t[3]))
        };
        // Nearest candidates per texel, with their distances in tile spacings.
        let mut best = vec![[(NO_BAND, f32::INFINITY); BANDS_PER_POINT]; res * res];
        // The texels each side's segments are searched over: around the segment, a band's
        // extent in UV (a tile spacing through the smallest stretch of F at its ends, with
        // room to spare), clamped to the square; counted first, so that cuts whose bands would
        // cover the map many times over are refused rather than left to run for hours.
        let mut boxes = Vec::new();
        let mut work = 0u64;
        for (c, curve) in curves.iter().enumerate() {
            for side in 0..2 {
                for (k, pair) in curve.points.windows(2).enumerate() {
                    let (a, b) = (pair[0].uv[side], pair[1].uv[side]);
                    let sigma_min = [a, b]
                        .map(|p| {
                            let f = f_at(p.clamp(Vec2::ZERO, Vec2::ONE));
                            f.determinant().abs() / largest_singular_value(f).max(1e-30)
                        })
                        .into_iter()
                        .fold(f32::INFINITY, f32::min);
                    let extent = (2.0 * spacing[c] / sigma_min.max(1e-12)).min(0.5);
                    let lo = ((a.min(b) - Vec2::splat(extent)) * res as f32).floor().max(Vec2::ZERO);
                    let hi = ((a.max(b) + Vec2::splat(extent)) * res as f32).ceil().min(Vec2::splat(res as f32));
                    if lo.x < hi.x && lo.y < hi.y {
                        work += ((hi.x - lo.x) * (hi.y - lo.y)) as u64;
                        boxes.push((c, side, k, a, b, lo, hi));
                    }
                }
            }
        }
        if work > MAX_BAND_WORK {
            return Err(format!(
                "the cut bands of tiles of {tile_size} would search {work} texels of the {res} x {res} map (at most \
                 {MAX_BAND_WORK}): the tiles are too large for these cuts"
            ));
        }
        for (c, side, k, a, b, lo, hi) in boxes {
            // Points anywhere in a texel within the band: the texel's centre within the band
            // widened by half a texel's diagonal.
            let margin =
                |f: Mat2| largest_singular_value(f) * std::f32::consts::FRAC_1_SQRT_2 / (res as f32 * spacing[c]);
            for j in lo.y as usize..hi.y as usize {
                for i in lo.x as usize..hi.x as usize {
                    let uv = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / res as f32;
                    let (_, p) = nearest_on_segment(uv, a, b);
                    let f = f_at(uv);
                    let d = (f * (uv - p)).length() / spacing[c];
                    if d >= 1.0 + margin(f) {
                        continue;
                    }
                    let candidate = (BandRef { curve: c as u32, segment_side: (k * 2 + side) as u32 }, d);
                    insert_nearest(&mut best[(res - 1 - j) * res + i], candidate);
                }
            }
        }
        let texels = best.into_iter().map(|b| b.map(|(r, _)| r)).collect();
        Ok(CutBands { curves, spacing, anchors, res, texels })
    }

    /// The cuts.
    pub fn curves(&self) -> &[CutCurve] {
        &self.curves
    }

    /// The bands `uv` lies in, with `f` the F map's value there (the field whose units g and s
    /// are in).
    #[inline]
    pub fn at(&self, uv: Vec2, f: Mat2) -> [Option<BandLookup>; BANDS_PER_POINT] {
        self.texel(uv).map(|r| if r.curve == u32::MAX { None } else { self.band(r, uv, f) })
    }

    /// Whether `uv`'s texel is near a cut at all (before anything is evaluated there).
    #[inline]
    pub fn near(&self, uv: Vec2) -> bool {
        self.texel(uv)[0].curve != u32::MAX
    }

    /// The cut sides recorded for the texel holding `uv` (clamped to the square).
    #[inline]
    fn texel(&self, uv: Vec2) -> [BandRef; BANDS_PER_POINT] {
        let i = ((uv.x * self.res as f32).max(0.0) as usize).min(self.res - 1);
        let j = ((crate::texture::image_coordinates(uv).y * self.res as f32).max(0.0) as usize).min(self.res - 1);
        self.texels[j * self.res + i]
    }

    fn band(&self, r: BandRef, uv: Vec2, f: Mat2) -> Option<BandLookup> {
        let c = r.curve as usize;
        let curve = &self.curves[c];
        let side = (r.segment_side % 2) as usize;
        let segment = (r.segment_side / 2) as usize;
        let last = curve.points.len() - 2;
        // The nearest point of this side's copy among the segments around the texel's: p, and
        // its g for the lookups.
        let first = segment.saturating_sub(SEARCH);
        let count = (segment + SEARCH).min(last) + 1 - first;
        // (distance, s, g, point) per segment of the window, on the stack: this runs per lookup.
        let mut nearest = [(f32::INFINITY, 0.0f32, Vec2::ZERO, Vec2::ZERO); 2 * SEARCH + 1];
        for (slot, k) in nearest.iter_mut().zip(first..first + count) {
            let (a, b) = (&curve.points[k], &curve.points[k + 1]);
            let (t, q) = nearest_on_segment(uv, a.uv[side], b.uv[side]);
            *slot = (q.distance(uv), a.s + (b.s - a.s) * t, a.g.lerp(b.g, t), q);
        }
        let nearest = &nearest[..count];
        let &(closest, _, g, p) = nearest.iter().min_by(|a, b| a.0.total_cmp(&b.0)).expect("a segment");
        // The arc length for the row's weights: the nearest points' s, averaged over the
        // segments nearly as near as the nearest (weights falling to 0 at half again its
        // distance). Where two segments are equally near (on the bisector of a concave corner,
        // where the nearest point jumps) they weigh alike, so that the weights do not jump; the
        // lookups do not either, being the same affine map g(s_p) + F (u - p) from both.
        let spread = 0.5 * closest + 1e-9;
        let (mut s_sum, mut w_sum) = (0.0f32, 0.0f32);
        for &(d, s_k, _, _) in nearest {
            let w = (1.0 - (d - closest) / spread).max(0.0).powi(2);
            s_sum += w * s_k;
            w_sum += w;
        }
        let s = s_sum / w_sum;
        let h = self.spacing[c];
        let offset = f * (uv - p);
        let d = offset.length() / h;
        if !(d < 1.0) {
            return None;
        }
        // psi(d) = 1 - smoothstep(d): flat at the cut and at the band's edge.
        let weight = 1.0 - d * d * (3.0 - 2.0 * d);
        let sigma = (s - curve.points[0].s) / h;
        let m = (floor(sigma) as i64).clamp(0, self.anchors[c].len() as i64 - 2);
        let t = (sigma - m as f32).clamp(0.0, 1.0);
        let tile = |m: i64, w: f32| (m, w, g - self.anchors[c][m as usize] + offset);
        Some(BandLookup { weight, curve: r.curve, tiles: [tile(m, 1.0 - t), tile(m + 1, t)], reach: 2.0 * h })
    }

    /// The bands as the GPU port reads them (`shaders/tiling_blending/cuts.wgsl`).
    pub fn gpu_cuts(&self) -> super::params::GpuCuts {
        use super::params::{CutCurveParams, CutPointParams, GpuCuts};
        let texels = self.texels.iter().map(|[a, b]| [a.curve, a.segment_side, b.curve, b.segment_side]).collect();
        let (mut points, mut curves, mut anchors) = (Vec::new(), Vec::new(), Vec::new());
        for ((curve, spacing), row) in self.curves.iter().zip(&self.spacing).zip(&self.anchors) {
            curves.push(CutCurveParams {
                first_point: points.len() as u32,
                point_count: curve.points.len() as u32,
                first_anchor: anchors.len() as u32,
                anchor_count: row.len() as u32,
                spacing: *spacing,
                padding: [0; 3],
            });
            points.extend(curve.points.iter().map(|p| CutPointParams {
                uv0: p.uv[0].to_array(),
                uv1: p.uv[1].to_array(),
                g: p.g.to_array(),
                s: p.s,
                padding: 0,
            }));
            anchors.extend(row.iter().map(|g| g.to_array()));
        }
        GpuCuts { res: self.res, texels, points, curves, anchors }
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        self.texels.len() * std::mem::size_of::<[BandRef; BANDS_PER_POINT]>()
            + self.anchors.iter().map(|a| a.len() * 8).sum::<usize>()
            + self.curves.iter().map(|c| c.points.len() * std::mem::size_of::<CutPoint>()).sum::<usize>()
    }
}

/// Keep the nearest candidates of distinct cut sides, nearest first.
fn insert_nearest(slots: &mut [(BandRef, f32); BANDS_PER_POINT], candidate: (BandRef, f32)) {
    let same_side = |a: BandRef, b: BandRef| a.curve == b.curve && a.segment_side % 2 == b.segment_side % 2;
    if let Some(k) = slots.iter().position(|s| same_side(s.0, candidate.0)) {
        if candidate.1 < slots[k].1 {
            slots[k] = candidate;
        }
    } else if candidate.1 < slots[BANDS_PER_POINT - 1].1 {
        slots[BANDS_PER_POINT - 1] = candidate;
    }
    slots.sort_by(|a, b| a.1.total_cmp(&b.1));
}

/// The parameter t in [0, 1] and the point of the segment a-b nearest to `p`.
#[inline]
fn nearest_on_segment(p: Vec2, a: Vec2, b: Vec2) -> (f32, Vec2) {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-30)).clamp(0.0, 1.0);
    (t, a + ab * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight_cut() -> CutCurve {
        // A vertical cut at u = 0.25 on side 0 and u = 0.75 on side 1, g along x.
        let points = (0..=4)
            .map(|k| {
                let v = k as f32 / 4.0;
                CutPoint { uv: [Vec2::new(0.25, v), Vec2::new(0.75, v)], s: v, g: Vec2::new(v, 0.0) }
            })
            .collect();
        CutCurve::new(points, 1.0).unwrap()
    }

    fn identity_map(res: usize) -> Bitmap {
        let mut map = Bitmap::new(res, res, 4);
        map.data.chunks_exact_mut(4).for_each(|t| t.copy_from_slice(&[1.0, 0.0, 0.0, 1.0]));
        map
    }

    #[test]
    fn both_sides_of_a_cut_read_the_same_tiles_on_it() {
        let bands = CutBands::new(vec![straight_cut()], &identity_map(64), 0.1).unwrap();
        for v in [0.13, 0.5, 0.77] {
            let [Some(a), None] = bands.at(Vec2::new(0.25, v), Mat2::IDENTITY) else { panic!("no band at {v}") };
            let [Some(b), None] = bands.at(Vec2::new(0.75, v), Mat2::IDENTITY) else { panic!("no band at {v}") };
            assert_eq!(a, b);
            assert_eq!(a.weight, 1.0);
            // The 1D weights are a partition of unity.
            assert!((a.tiles[0].1 + a.tiles[1].1 - 1.0).abs() < 1e-6);
        }
        // The band is one tile spacing wide on each side, its weight falling to 0.
        let near = bands.at(Vec2::new(0.3, 0.5), Mat2::IDENTITY)[0].unwrap();
        assert!(near.weight > 0.0 && near.weight < 1.0);
        assert!(bands.at(Vec2::new(0.36, 0.5), Mat2::IDENTITY)[0].is_none());
        // Off the cut the offset is F (u - p): the developed coordinate continues linearly.
        let [(_, _, o0), _] = near.tiles;
        let on = bands.at(Vec2::new(0.25, 0.5), Mat2::IDENTITY)[0].unwrap();
        assert!((o0 - on.tiles[0].2 - Vec2::new(0.05, 0.0)).length() < 1e-5);
    }

    #[test]
    fn bands_that_would_cover_the_map_many_times_over_are_refused() {
        // 400 segments whose bands, for tiles of 10 UV units, each cover most of the square.
        let points = (0..=400)
            .map(|k| {
                let v = k as f32 / 400.0;
                CutPoint { uv: [Vec2::new(0.25, v), Vec2::new(0.75, v)], s: v, g: Vec2::new(v, 0.0) }
            })
            .collect();
        let curve = CutCurve::new(points, 1.0).unwrap();
        let Err(error) = CutBands::new(vec![curve.clone()], &identity_map(1024), 10.0) else { panic!("accepted") };
        assert!(error.contains("too large"), "{error}");
        assert!(CutBands::new(vec![curve], &identity_map(1024), 0.01).is_ok());
    }

    #[test]
    fn absurd_tile_sizes_are_refused_not_overflowed() {
        let mut curve = straight_cut();
        curve.scale = 1e-30;
        let Err(error) = CutBands::new(vec![curve], &identity_map(16), 1e-20) else { panic!("accepted") };
        assert!(error.contains("no tile spacing"), "{error}");
        let Err(error) = CutBands::new(vec![straight_cut()], &identity_map(16), 1e-9) else { panic!("accepted") };
        assert!(error.contains("too small"), "{error}");
    }

    #[test]
    fn cuts_files_round_trip_and_bad_ones_are_refused() {
        let curves = vec![straight_cut()];
        assert_eq!(cuts_from_json(&cuts_to_json(&curves)).unwrap(), curves);
        assert!(cuts_from_json("{\"curves\": [{\"scale\": 1, \"points\": [[0,0,0,0,0,0,0]]}]}").is_err());
        assert!(cuts_from_json("{\"curves\": [{\"scale\": 0, \"points\": []}]}").is_err());
        let decreasing = "{\"curves\": [{\"scale\": 1, \"points\": [[0,0,0,0,1,0,0],[0,1,0,1,0,0,0]]}]}";
        assert!(cuts_from_json(decreasing).unwrap_err().contains("decreases"));
        assert!(cuts_from_json("[1, 2]").unwrap_err().contains("not a cuts file"));
    }
}
