//! The figures `tessera analyze` prints for a UV-mapped mesh and its deformation maps (paper
//! 000; DESIGN.md sections 5 and 6), computed here so that the tests share them:
//!
//! - **seams**, normalised: at corresponding points of the two sides of every cut, the mean of
//!   |T_left - T_right| divided by the mean of |T(p) - T(q)| over independent point pairs of the
//!   same synthesis (the cut points paired with those half the list away). 0 is a continuous
//!   texture, about 1 a cut that shows as much as two unrelated points do; unlike a division by
//!   the exemplar's spread, this does not depend on the blending's variance or the scale of F.
//!   Ordinary cuts and UV singularities (pole fans, darts) are reported apart.
//! - **orientation error**: the angle between the texture's x axis on the surface, J F^-1 e1
//!   (DESIGN.md section 3), and the orientation field, area-weighted mean and 95th percentile.
//! - **frame jumps**: the angle between the texture's x axis on the two faces of each edge
//!   (unfolded about it), apart for cut edges and for edges inside charts: what a brushed
//!   highlight shows as a kink.
//! - **fold-over**: where the lookup u -> F(u)(u - c) of a tile centred at c stops being
//!   injective (its Jacobian F + dF (u - c) changes the sign of det F) or stretches by more than
//!   2:1, for tile centres in every direction at a tile's distance (the paper's open "cracks").
//!   Measured on the F map's texels inside UV triangles.
//! - **distortion**: [`super::distortion`], classical and deformed.
//! - **continuity bound**: [`super::continuity_bound`], what no F continuous in UV can beat on
//!   the mesh's UV map, for the orientation error and the anisotropy.

use super::bound::{ContinuityBound, continuity_bound};
use super::edges::manifold_edges;
use super::fold::{DIRECTIONS, LookupFold, centred_fold, lookup_fold};
use super::gradient::texture_axis;
use super::{Cuts, DeformationMaps, Distortion, Orientation, SeamPoint, deformation_gradient, distortion};
use crate::geometry::TriangleMesh;
use crate::image::Bitmap;
use crate::limits;
use crate::texture::tiling_blending::{
    Blend, Charts, CutBands, Deformation, DeformationField, FieldAt, Synthesis, Tiling, synthesis_lattice_visibility,
};
use crate::texture::{MipMap, TexCtx, Texture, TilingBlending};
use glam::{Mat2, Vec2, Vec3};
use std::sync::Arc;

/// Seam figures of one synthesis.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Seams {
    /// mean |T_left - T_right| / mean |T(p) - T(q)| over independent pairs.
    pub normalised: f64,
    /// mean |T_left - T_right| averaged over RGB (the numerator).
    pub mean_difference: f64,
}

/// The seams of one synthesis, apart for ordinary cuts and for UV singularities (pole fans,
/// darts: [`super::CutEdge::is_singular`]), whose texture the paper's Sec. 5 does not address.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SeamFigures {
    /// Over the ordinary cut edges; None if there are none.
    pub ordinary: Option<Seams>,
    /// Over the singular cut edges; None if there are none.
    pub singular: Option<Seams>,
}

/// Measure the seams of `texture` over `cuts` with `samples` point lookups per cut edge (no
/// footprint).
pub fn seams(cuts: &Cuts, texture: &TilingBlending, samples: usize) -> SeamFigures {
    let at = |uv: Vec2| texture.eval(&TexCtx { uv, ..Default::default() }).truncate();
    let points = cuts.seam_points(samples);
    let of = |singular: bool| {
        let points: Vec<&SeamPoint> = points.iter().filter(|p| p.singular == singular).collect();
        seams_at(&points, at)
    };
    SeamFigures { ordinary: of(false), singular: of(true) }
}

/// The seam figures over `points`; None without points or for a texture equal at every pair.
fn seams_at(points: &[&SeamPoint], at: impl Fn(Vec2) -> Vec3) -> Option<Seams> {
    let n = points.len();
    let difference = |a: Vec3, b: Vec3| ((a - b).abs().element_sum() / 3.0) as f64;
    let values: Vec<(Vec3, Vec3)> = points.iter().map(|p| (at(p.left), at(p.right))).collect();
    let (mut across, mut independent, mut total) = (0.0, 0.0, 0.0);
    for (i, (p, (left, right))) in points.iter().zip(&values).enumerate() {
        let w = p.weight as f64;
        across += w * difference(*left, *right);
        independent += w * difference(*left, values[(i + n / 2) % n].1);
        total += w;
    }
    (n > 0 && independent > 0.0).then(|| Seams { normalised: across / independent, mean_difference: across / total })
}

/// Area-weighted statistics of an angle, in degrees.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct AngleError {
    /// Mean.
    pub mean: f64,
    /// 95th percentile.
    pub p95: f64,
}

impl AngleError {
    /// The statistics of `(angle in degrees, weight)` pairs; None without weight.
    pub(super) fn of(mut angles: Vec<(f64, f64)>) -> Option<Self> {
        let total: f64 = angles.iter().map(|a| a.1).sum();
        if !(total > 0.0) {
            return None;
        }
        let mean = angles.iter().map(|(a, w)| a * w).sum::<f64>() / total;
        angles.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut below = 0.0;
        let p95 = angles
            .iter()
            .find(|(_, w)| {
                below += w;
                below >= 0.95 * total
            })
            .map_or(0.0, |a| a.0);
        Some(AngleError { mean, p95 })
    }
}

/// Whether a triangle's UVs are mirrored (clockwise).
fn uv_mirrored(u: [Vec2; 3]) -> bool {
    (u[1] - u[0]).perp_dot(u[2] - u[0]) < 0.0
}

/// The angle between the texture's x axis on the surface, J F^-1 e1 with F from `f_at` at each
/// triangle's UV centroid (given whether the triangle's UVs are mirrored, as the renderer
/// knows at a hit), and the orientation field's direction on each triangle. None for
/// [`Orientation::Uv`] or where no triangle has both.
pub fn orientation_error(
    mesh: &TriangleMesh,
    orientation: &Orientation,
    f_at: impl Fn(Vec2, bool) -> Mat2,
) -> Option<AngleError> {
    let uvs = mesh.uvs.as_ref()?;
    let mut angles: Vec<(f64, f64)> = Vec::new();
    for (idx, direction) in mesh.indices.iter().zip(orientation.per_triangle(mesh)) {
        let Some(o) = direction else { continue };
        let x = idx.map(|i| mesh.positions[i as usize]);
        let u = idx.map(|i| uvs[i as usize]);
        let Some(axis) =
            deformation_gradient(x, u).and_then(|j| texture_axis(j, f_at((u[0] + u[1] + u[2]) / 3.0, uv_mirrored(u))))
        else {
            continue;
        };
        let normal = (x[1] - x[0]).cross(x[2] - x[0]);
        let Some(along) = (o - normal * o.dot(normal) / normal.length_squared()).try_normalize() else { continue };
        let angle = axis.dot(along).clamp(-1.0, 1.0).acos().to_degrees() as f64;
        angles.push((angle, normal.length() as f64 / 2.0));
    }
    AngleError::of(angles)
}

/// How far the texture's x axis turns across the mesh's edges, apart for UV cuts and for
/// edges inside charts.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FrameJumps {
    /// Over the ordinary cut edges (not UV singularities); None without any.
    pub cuts: Option<AngleError>,
    /// Over the edges inside charts; None without any.
    pub interior: Option<AngleError>,
}

/// The angle between the texture's x axis J F^-1 e1 on the two faces of each manifold edge, at
/// the edge's middle (F from `f_at` at each face's UV of that point, given whether the face's
/// UVs are mirrored), the second face's axis unfolded into the first face's plane about the
/// edge: what a brushed highlight shows as a kink. Inside a chart F is continuous and the
/// angle is the jump of the piecewise-linear UV map's Jacobian J between the faces; across a
/// cut it adds the mismatch of the two charts' fields there. Weighted by edge length.
pub fn frame_jumps(mesh: &TriangleMesh, f_at: impl Fn(Vec2, bool) -> Mat2) -> Option<FrameJumps> {
    let (mut cuts, mut interior) = (Vec::new(), Vec::new());
    for edge in manifold_edges(mesh)?.iter().filter(|e| !(e.cut && e.singular)) {
        let axis = |side: usize| {
            let face = &edge.faces[side];
            let f = f_at((face.ends[0] + face.ends[1]) / 2.0, uv_mirrored(face.u));
            let axis = texture_axis(deformation_gradient(face.x, face.u)?, f)?;
            Some(edge.flat(side, axis))
        };
        let (Some(axis0), Some(axis1)) = (axis(0), axis(1)) else { continue };
        let angle = axis0.dot(axis1).clamp(-1.0, 1.0).acos().to_degrees() as f64;
        if edge.cut { &mut cuts } else { &mut interior }.push((angle, edge.length as f64));
    }
    Some(FrameJumps { cuts: AngleError::of(cuts), interior: AngleError::of(interior) })
}

/// Where tiles' lookups fold over or stretch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FoldOver {
    /// Fraction of the measured texels where a tile's lookup folds (its Jacobian's determinant
    /// has the opposite sign to det F, or is 0).
    pub folded: f64,
    /// Fraction where it stretches by more than 2:1 against F (a singular value of
    /// (F + dF d) F^-1 above 2 or below 1/2) without folding.
    pub stretched: f64,
    /// Texels measured (inside a UV triangle).
    pub texels: usize,
}

/// The fold-over of the F map `f_map` (4 channels, row 0 at v = 1) for tiles whose centres
/// lie `reach` UV units away (the tile's support radius) in [`super::fold::DIRECTIONS`]
/// directions, their lookups reading F as `field_at` says, on the texels that `covered` marks
/// (row-major from the bottom row, as [`super::uv_coverage`] and [`DeformationMaps::coverage`]
/// give them). Read at the point, dF comes from central differences of neighbouring texels of
/// the same chart (`chart`, row-major from the bottom row; one-sided at a chart's or the map's
/// border), since a tile never reads across charts. Read at tile centres, F(c) is the texel at
/// the centre where it lies in the texel's chart, and the point's criterion applies where some
/// centre does not (the renderer reads F(u) there), and on every texel of a map with more
/// charts than [`Charts`] relates (the renderer refuses such a map for tile centres).
pub fn fold_over(f_map: &Bitmap, covered: &[u8], chart: &[u32], reach: f32, field_at: FieldAt) -> FoldOver {
    let res = f_map.width;
    let f = |i: usize, j: usize| {
        // j counts rows from the bottom (v up).
        let t = f_map.values(i, res - 1 - j);
        Mat2::from_cols(Vec2::new(t[0], t[2]), Vec2::new(t[1], t[3]))
    };
    let derivative = |i: usize, j: usize, along_u: bool| {
        let same = |(a, b): (usize, usize)| chart[b * res + a] == chart[j * res + i];
        let (mut lo, mut hi) = if along_u {
            ((i.saturating_sub(1), j), ((i + 1).min(res - 1), j))
        } else {
            ((i, j.saturating_sub(1)), (i, (j + 1).min(res - 1)))
        };
        if !same(lo) {
            lo = (i, j);
        }
        if !same(hi) {
            hi = (i, j);
        }
        let span = if along_u { hi.0 - lo.0 } else { hi.1 - lo.1 };
        if span == 0 { Mat2::ZERO } else { (f(hi.0, hi.1) - f(lo.0, lo.1)) * (res as f32 / span as f32) }
    };
    // Read at tile centres: where each centre around (i, j) reads F, as the renderer does
    // (Charts); the worst over the centres, None if one has no point of the chart in reach.
    let charts = (field_at == FieldAt::TileCentre).then(|| Charts::new(&super::chart_map_of(res, chart), reach).ok());
    let texel_at = |uv: Vec2| {
        let p = (uv - crate::math::floor2(uv)) * res as f32;
        ((p.x as usize).min(res - 1), (p.y as usize).min(res - 1))
    };
    let centred = |i: usize, j: usize| {
        let charts = charts.as_ref()?.as_ref()?;
        let u = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / res as f32;
        let mut worst = LookupFold::Fine;
        for k in 0..DIRECTIONS {
            let d = Vec2::from_angle(k as f32 * std::f32::consts::TAU / DIRECTIONS as f32) * reach;
            let (ci, cj) = texel_at(charts.field_point(u - d, chart[j * res + i])?);
            worst = worst.max(centred_fold(f(i, j), f(ci, cj))?);
        }
        Some(worst)
    };
    let (mut folded, mut stretched, mut texels) = (0usize, 0usize, 0usize);
    for j in 0..res {
        for i in 0..res {
            if covered[j * res + i] == 0 {
                continue;
            }
            let outcome = match centred(i, j) {
                Some(outcome) => outcome,
                None => {
                    let (du, dv) = (derivative(i, j, true), derivative(i, j, false));
                    let Some(outcome) = lookup_fold(f(i, j), du, dv, reach) else { continue };
                    outcome
                }
            };
            texels += 1;
            folded += usize::from(outcome == LookupFold::Folded);
            stretched += usize::from(outcome == LookupFold::Stretched);
        }
    }
    let fraction = |n: usize| if texels == 0 { 0.0 } else { n as f64 / texels as f64 };
    FoldOver { folded: fraction(folded), stretched: fraction(stretched), texels }
}

/// The seam figures of the three syntheses `tessera analyze` compares.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SeamReport {
    /// Classical tiling and blending (F = I).
    pub classical: SeamFigures,
    /// Deformed by the F map, cuts left alone.
    pub deformed: SeamFigures,
    /// Deformed, with cut bands ([`CutBands`]).
    pub deformed_bands: SeamFigures,
}

/// Everything `tessera analyze` reports about a mesh and its maps.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Analysis {
    /// Triangles of the mesh.
    pub triangles: usize,
    /// Cut edges.
    pub cut_edges: usize,
    /// Cuts (chains of cut edges).
    pub cuts: usize,
    /// Distortion of the classical texture (F = I).
    pub distortion_classical: Option<Distortion>,
    /// Distortion of the deformed texture (the F map).
    pub distortion_deformed: Option<Distortion>,
    /// Seams, with the point pairs per cut edge used.
    pub seams: Option<SeamReport>,
    /// Point pairs per cut edge of the seam figures.
    pub seam_samples: usize,
    /// Angle between the deformed texture's x axis and the orientation field.
    pub orientation_error: Option<AngleError>,
    /// The same for the classical texture (F = I), whose x axis follows the UV map's u: what
    /// the deformation corrects.
    pub orientation_error_classical: Option<AngleError>,
    /// How far the deformed texture's x axis turns across cuts and across edges inside charts.
    pub frame_jumps: Option<FrameJumps>,
    /// What no F continuous in UV can do better than at the edges inside charts.
    pub continuity_bound: Option<ContinuityBound>,
    /// Fold-over of the tiles' lookups through the F map, read at the point (Eq. 3).
    pub fold_over: FoldOver,
    /// The same, the tiles reading F at their centres ([`FieldAt::TileCentre`]).
    pub fold_over_at_centres: FoldOver,
    /// Fraction of the UV area covered more than once.
    pub uv_overlap: f64,
    /// How visible the paving's lattice is in the classical synthesis of the exemplar (F = I;
    /// [`synthesis_lattice_visibility`], four seeds): about 1 where the exemplar is stationary.
    pub lattice_visibility: Option<f64>,
}

/// What [`analyze`] measures: a mesh with UVs, the maps `deform` derived from it with its
/// orientation, and the synthesis the seams are measured on (hexagonal tiles of `tile_size`,
/// linear blending of `exemplar`, shifts from `seed`).
pub struct AnalysisInput<'a> {
    /// The mesh, with UVs.
    pub mesh: &'a TriangleMesh,
    /// Its deformation maps.
    pub maps: &'a DeformationMaps,
    /// The orientation field the maps were made with.
    pub orientation: &'a Orientation,
    /// The exemplar the seams are synthesised from.
    pub exemplar: Arc<Texture>,
    /// Lattice spacing of the tiles (UV units).
    pub tile_size: f32,
    /// Seed of the tiles' shifts.
    pub seed: u64,
    /// Point pairs per cut edge (lowered so that cut edges times samples stays within
    /// [`limits::MAX_SEAM_SAMPLES`]).
    pub samples: usize,
}

/// Side of the bakes the lattice visibility is measured on.
pub const LATTICE_BAKE_RES: usize = 512;

/// Measure everything [`Analysis`] holds.
pub fn analyze(input: &AnalysisInput) -> Result<Analysis, String> {
    let (mesh, maps) = (input.mesh, input.maps);
    mesh.uvs.as_ref().ok_or("the mesh has no texture coordinates")?;
    let field = DeformationField::new(vec![Deformation::Map(MipMap::new(maps.f_map.clone()))]);
    let edges = maps.cuts.edges.len();
    let samples = input.samples.min((limits::MAX_SEAM_SAMPLES / edges.max(1)).max(1));
    let classical = Synthesis {
        tiling: Tiling::Hexagonal,
        tile_size: input.tile_size,
        seed: input.seed,
        deformation: None,
        cuts: None,
        blend: Blend::Linear,
        inset: false,
    };
    let classical = TilingBlending::new(Arc::new(classical), input.exemplar.clone())?;
    let seeds: Vec<u64> = (0..4).map(|k| input.seed.wrapping_add(k)).collect();
    let lattice_visibility = synthesis_lattice_visibility(&classical, LATTICE_BAKE_RES, &seeds);
    let seams = (edges > 0)
        .then(|| -> Result<SeamReport, String> {
            let measure = |deformation: Option<DeformationField>, cuts: Option<CutBands>| {
                let synthesis = Synthesis {
                    tiling: Tiling::Hexagonal,
                    tile_size: input.tile_size,
                    seed: input.seed,
                    deformation,
                    cuts,
                    blend: Blend::Linear,
                    inset: false,
                };
                Ok::<_, String>(seams(
                    &maps.cuts,
                    &TilingBlending::new(Arc::new(synthesis), input.exemplar.clone())?,
                    samples,
                ))
            };
            Ok(SeamReport {
                classical: measure(None, None)?,
                deformed: measure(Some(field.clone()), None)?,
                deformed_bands: measure(Some(field.clone()), Some(maps.bands.clone()))?,
            })
        })
        .transpose()?;
    let charts = maps.chart_of_texels();
    Ok(Analysis {
        triangles: mesh.indices.len(),
        cut_edges: edges,
        cuts: maps.cuts.chains.len(),
        distortion_classical: distortion(mesh, |_| Mat2::IDENTITY),
        distortion_deformed: distortion(mesh, |uv| field.at(uv)),
        seams,
        seam_samples: samples,
        orientation_error: orientation_error(mesh, input.orientation, |uv, mirrored| {
            field.at_surface(uv, Some(mirrored))
        }),
        orientation_error_classical: orientation_error(mesh, input.orientation, |_, _| Mat2::IDENTITY),
        frame_jumps: frame_jumps(mesh, |uv, mirrored| field.at_surface(uv, Some(mirrored))),
        continuity_bound: continuity_bound(mesh, input.orientation),
        // A hexagonal tile reaches one lattice spacing from its centre.
        fold_over: fold_over(&maps.f_map, &maps.coverage, &charts, input.tile_size, FieldAt::Point),
        fold_over_at_centres: fold_over(&maps.f_map, &maps.coverage, &charts, input.tile_size, FieldAt::TileCentre),
        uv_overlap: maps.overlap().fraction(),
        lattice_visibility,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An F map of `res` x `res` texels holding F(u) = R(k u) (a rotation turning along u).
    fn turning_map(res: usize, k: f32) -> Bitmap {
        let mut map = Bitmap::new(res, res, 4);
        for (n, px) in map.data.chunks_exact_mut(4).enumerate() {
            let u = ((n % res) as f32 + 0.5) / res as f32;
            let (sin, cos) = (k * u).sin_cos();
            // (F00, F01, F10, F11) of [[cos, -sin], [sin, cos]].
            px.copy_from_slice(&[cos, -sin, sin, cos]);
        }
        map
    }

    #[test]
    fn fold_over_is_found_where_the_field_turns_faster_than_a_tile_can_follow() {
        // The lookup's Jacobian is F + dF/du (u - c) e1^T; relative to F, its determinant is
        // 1 - k d_v: for tile centres a distance r away it folds once k r > 1.
        let (res, r) = (64, 0.1);
        let covered = vec![1u8; res * res];
        let one_chart = vec![0u32; res * res];
        let slow = fold_over(&turning_map(res, 1.0), &covered, &one_chart, r, FieldAt::Point);
        assert_eq!((slow.folded, slow.stretched, slow.texels), (0.0, 0.0, res * res));
        let fast = fold_over(&turning_map(res, 30.0), &covered, &one_chart, r, FieldAt::Point);
        assert!(fast.folded > 0.9, "{fast:?}");
        // Uncovered texels are not measured.
        assert_eq!(fold_over(&turning_map(res, 30.0), &vec![0u8; res * res], &one_chart, r, FieldAt::Point).texels, 0);
        // Every texel its own chart: no neighbour to differentiate with, nothing folds.
        let apart: Vec<u32> = (0..(res * res) as u32).collect();
        assert_eq!(fold_over(&turning_map(res, 30.0), &covered, &apart, r, FieldAt::Point).folded, 0.0);
        // Between: stretched beyond 2:1 (k r = 0.6 gives a relative determinant of 0.4).
        let middle = fold_over(&turning_map(res, 6.0), &covered, &one_chart, r, FieldAt::Point);
        assert!(middle.folded == 0.0 && middle.stretched > 0.9, "{middle:?}");
    }

    #[test]
    fn tiles_that_read_the_field_at_their_centres_never_fold() {
        // F(c)(u - c) is affine in u: with F a rotation everywhere, it never folds, and it
        // stretches only against F(u) (never: F(c) F(u)^-1 is a rotation too), however fast F
        // turns. Centres off the map or in another chart fall back to the point's criterion.
        let (res, r) = (64, 0.1);
        let covered = vec![1u8; res * res];
        let one_chart = vec![0u32; res * res];
        let fast = fold_over(&turning_map(res, 30.0), &covered, &one_chart, r, FieldAt::TileCentre);
        assert_eq!(fast.texels, res * res);
        // Only texels within r of the map's border (some centre off the map) can fold.
        let border = 1.0 - (1.0 - 2.0 * r as f64).powi(2);
        assert!(fast.folded <= border + 0.02, "{fast:?}");
        assert_eq!(fast.stretched, 0.0, "{fast:?}");
        // A field that scales by 3 across a tile stretches beyond 2:1, without folding.
        let mut scaling = Bitmap::new(res, res, 4);
        for (n, px) in scaling.data.chunks_exact_mut(4).enumerate() {
            let s = (3.0f32.ln() / r * ((n % res) as f32 + 0.5) / res as f32).exp();
            px.copy_from_slice(&[s, 0.0, 0.0, s]);
        }
        let scaled = fold_over(&scaling, &covered, &one_chart, r, FieldAt::TileCentre);
        assert!(scaled.stretched > 0.5 && scaled.folded <= border + 0.02, "{scaled:?}");
        // A reflection in the centre's F against a rotation at u folds.
        let mut mirrored = turning_map(res, 0.0);
        for px in mirrored.data.chunks_exact_mut(4).skip(res / 2).step_by(res) {
            px[3] = -1.0;
        }
        let torn = fold_over(&mirrored, &covered, &one_chart, r, FieldAt::TileCentre);
        assert!(torn.folded > 0.0, "{torn:?}");
    }
}
