//! The deformation field of a UV-mapped mesh (paper 000 Sec. 4; DESIGN.md section 5): per
//! triangle the deformation gradient and its polar decomposition, an orientation angle from a
//! tangent field, its smoothing per chart (Sec. 4.4), and the F map that a tiling-and-blending texture
//! reads (`deformation = [{ type = "map", ... }]`).

pub mod analysis;
mod bound;
mod cuts;
mod distortion;
mod edges;
mod field;
mod fold;
mod geodesic;
mod gradient;
mod nearest;
mod overlap;
mod repack;

pub use analysis::{Analysis, AnalysisInput, analyze};
pub use bound::{ContinuityBound, continuity_bound};
pub use cuts::{CutEdge, Cuts, SeamPoint};
pub use distortion::{Distortion, distortion};
pub use field::{ChartField, FieldSample, TriangleRaster, uv_charts};

pub use gradient::{TriangleDeformation, deformation_gradient};
pub use overlap::{UvOverlap, uv_area_outside_square, uv_coverage, uv_overlap};
pub use repack::{Repacked, pack_charts};

use crate::geometry::TriangleMesh;
use crate::image::Bitmap;
use crate::limits;
use crate::texture::tiling_blending::CutBands;
use glam::{Vec2, Vec3};

/// The tangent field o that orients the texture (Sec. 4.3).
#[derive(Clone, Debug, PartialEq)]
pub enum Orientation {
    /// None: F = S (Sec. 4.2), the texture oriented by the UV iso-lines.
    Uv,
    /// A fixed direction projected on each triangle's plane.
    Fixed(Vec3),
    /// Along the parallels around an axis through the origin: o = axis x p.
    Parallels(Vec3),
    /// Along the gradient of the distance over the surface from the vertices nearest to these
    /// points (Sec. 6.3): the texture runs away from them.
    Geodesic(Vec<Vec3>),
    /// Given per vertex (as the mesh's positions are), e.g. a glTF file's TANGENT: each
    /// triangle takes the sum of its corners' tangents.
    PerVertex(Vec<Vec3>),
}

impl Orientation {
    /// The direction o on each triangle of `mesh` (not yet projected on its plane); None where
    /// there is none ([`Orientation::Uv`], a vanishing gradient).
    pub(crate) fn per_triangle(&self, mesh: &TriangleMesh) -> Vec<Option<Vec3>> {
        let corners = |idx: &[u32; 3]| idx.map(|i| mesh.positions[i as usize]);
        match self {
            Orientation::Uv => vec![None; mesh.indices.len()],
            Orientation::Fixed(d) => vec![Some(*d); mesh.indices.len()],
            Orientation::Parallels(axis) => mesh
                .indices
                .iter()
                .map(|idx| {
                    let x = corners(idx);
                    Some(axis.cross((x[0] + x[1] + x[2]) / 3.0))
                })
                .collect(),
            Orientation::PerVertex(tangents) => mesh
                .indices
                .iter()
                .map(|idx| Some(idx.iter().map(|&i| tangents.get(i as usize).copied().unwrap_or(Vec3::ZERO)).sum()))
                .collect(),
            Orientation::Geodesic(sources) => {
                let d = geodesic::surface_distances(mesh, sources);
                mesh.indices
                    .iter()
                    .map(|idx| geodesic::triangle_gradient(corners(idx), idx.map(|i| d[i as usize])))
                    .collect()
            }
        }
    }
}

/// How the field is smoothed before it is written to the F map (Sec. 4.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Smoothing {
    /// Not at all: each texel takes its triangle's own F, which jumps at every edge (paper
    /// 000 Fig. 4 c: the tiles' lookups F(u)(u - c) tear there).
    Triangles,
    /// Per chart on the surface: the UV vertices' means, then this many rounds of averaging
    /// ([`ChartField`]).
    Vertices(usize),
}

/// What `tessera deform` computes from a mesh.
#[derive(Clone, Debug)]
pub struct DeformationMaps {
    /// The field smoothed per chart (theta and S at the UV vertices).
    pub field: ChartField,
    /// The triangle each texel of the maps takes F from ([`TriangleRaster`]).
    pub raster: TriangleRaster,
    /// The F map: `res` x `res`, 4 channels (F00, F01, F10, F11), row 0 at the top (v = 1), as
    /// image textures are laid out: the field at each texel centre, in the triangle covering
    /// it or (outside every triangle) extrapolated from the nearest one, so that the map's
    /// bilinear lookups near a chart's border read that chart's field.
    pub f_map: Bitmap,
    /// The UV cuts, chained.
    pub cuts: Cuts,
    /// The cut bands of the cuts' curves for the F map and the tile size ([`CutBands`]).
    pub bands: CutBands,
    /// Triangles skipped because they are degenerate in 3D or in UV.
    pub degenerate: usize,
    /// Triangles whose UVs are mirrored (R is a reflection there).
    pub mirrored: usize,
    /// How many UV triangles cover each texel centre of the maps ([`uv_coverage`]; row 0 at
    /// v = 0).
    pub coverage: Vec<u8>,
    /// The fraction of the UV area outside the unit square, where the maps hold no field
    /// ([`uv_area_outside_square`]; at most [`MAX_OUTSIDE_SQUARE`]).
    pub outside_square: f64,
}

/// The largest fraction of a mesh's UV area outside the unit square that [`deformation_maps`]
/// accepts (with a warning from `tessera deform`): beyond it, lookups on most of the surface
/// would wrap into the square and read the field of another part of it.
pub const MAX_OUTSIDE_SQUARE: f64 = 0.5;

impl DeformationMaps {
    /// The chart of the triangle each texel of the maps takes F from (row-major from the
    /// bottom row).
    pub fn chart_of_texels(&self) -> Vec<u32> {
        self.raster.owner.iter().map(|&t| self.field.chart_of_triangle[t as usize]).collect()
    }

    /// How much of the UV square more than one triangle covers, at the maps' resolution.
    pub fn overlap(&self) -> UvOverlap {
        UvOverlap::of_coverage(&self.coverage)
    }
}

/// The chart map of `charts` (a `res` x `res` raster's chart per texel, row-major from the bottom
/// row, as [`DeformationMaps::chart_of_texels`] gives it): one channel, row 0 at the top (v = 1)
/// as the F map; the scene's `charts` for tiles that read F at their centres.
pub fn chart_map_of(res: usize, charts: &[u32]) -> Bitmap {
    let mut map = Bitmap::new(res, res, 1);
    for (k, c) in charts.iter().enumerate() {
        map.values_mut(k % res, res - 1 - k / res)[0] = *c as f32;
    }
    map
}

/// Derive the deformation field of `mesh` (which must have UVs): F = R(theta) S per triangle,
/// smoothed as `smoothing` says, written as a `res` x `res` F map; and the cut bands of its cuts for tiles of lattice spacing
/// `tile_size`.
pub fn deformation_maps(
    mesh: &TriangleMesh,
    orientation: &Orientation,
    smoothing: Smoothing,
    res: usize,
    tile_size: f32,
) -> Result<DeformationMaps, String> {
    mesh.check()?;
    let uvs = mesh.uvs.as_ref().ok_or("the mesh has no texture coordinates")?;
    if res == 0 {
        return Err("the maps need at least one texel per side".into());
    }
    let rounds = match smoothing {
        Smoothing::Triangles => 0,
        Smoothing::Vertices(rounds) => rounds,
    };
    if rounds > limits::MAX_DEFORM_SMOOTHING as usize || res > limits::MAX_DEFORM_RES as usize {
        let (max_smoothing, max_res) = (limits::MAX_DEFORM_SMOOTHING, limits::MAX_DEFORM_RES);
        return Err(format!(
            "{rounds} smoothing rounds or maps {res} over tessera's limits of {max_smoothing} rounds and {max_res} per side"
        ));
    }
    if let Orientation::PerVertex(tangents) = orientation
        && (tangents.len() != mesh.positions.len() || !tangents.iter().all(|t| t.is_finite()))
    {
        return Err(format!(
            "{} tangents for {} vertices, or some not finite: one finite tangent per vertex is needed",
            tangents.len(),
            mesh.positions.len()
        ));
    }
    if !(tile_size > 0.0 && tile_size.is_finite()) {
        return Err(format!("the tile size must be a positive UV length, not {tile_size}"));
    }
    let mut degenerate = 0;
    let mut mirrored = 0;
    let mut uv_triangles = Vec::with_capacity(mesh.indices.len());
    let directions = orientation.per_triangle(mesh);
    let samples: Vec<field::TriangleSample> = mesh
        .indices
        .iter()
        .zip(&directions)
        .map(|(idx, direction)| {
            let x = idx.map(|i| mesh.positions[i as usize]);
            let u = idx.map(|i| uvs[i as usize]);
            uv_triangles.push(u);
            let Some(d) = TriangleDeformation::new(x, u) else {
                degenerate += 1;
                return None;
            };
            if d.mirrored() {
                mirrored += 1;
            }
            let theta = direction.map_or(0.0, |o| d.orientation_angle(o));
            Some((FieldSample { direction: Vec2::from_angle(theta), stretch: d.stretch }, d.mirrored()))
        })
        .collect();
    let outside_square = uv_area_outside_square(&uv_triangles);
    if outside_square > MAX_OUTSIDE_SQUARE {
        return Err(format!(
            "{:.1}% of the UV area lies outside the unit square [0, 1]^2, which the F map spans: move the UV \
             islands into it (UDIM tiles and islands moved by whole periods are not followed)",
            100.0 * outside_square
        ));
    }
    let mut field = ChartField::new(mesh, &samples, rounds).ok_or("every triangle is degenerate")?;
    // The shared directions smooth the field across cuts: not for F = S, whose direction is
    // the UV map's, nor for each triangle's own F.
    if !matches!(orientation, Orientation::Uv) && smoothing != Smoothing::Triangles {
        field.share_directions_across_cuts(mesh, &samples);
    }
    // Overlapping islands: the unmirrored one's field is kept; the renderer mirrors it for the
    // other (DeformationField::at_surface).
    let unmirrored = |t: usize| samples[t].is_some_and(|s| !s.1);
    let raster = TriangleRaster::new(res, &uv_triangles, |t| samples[t].is_none(), unmirrored)
        .ok_or("every triangle is degenerate")?;
    let mut f_map = Bitmap::new(res, res, 4);
    for (k, &t) in raster.owner.iter().enumerate() {
        let f = match (smoothing, samples[t as usize]) {
            (Smoothing::Triangles, Some((sample, mirrored))) => sample.deformation(mirrored),
            _ => {
                field.at(t as usize, field::barycentric(raster.point(k), uv_triangles[t as usize]).unwrap_or(Vec3::ONE))
            }
        };
        f_map.values_mut(k % res, res - 1 - k / res).copy_from_slice(&[f.x_axis.x, f.y_axis.x, f.x_axis.y, f.y_axis.y]);
    }
    let coverage = uv_coverage(&uv_triangles, res);
    let cuts = Cuts::new(mesh);
    let bands = CutBands::new(cuts.curves(&field, &uv_triangles), &f_map, tile_size)?;
    Ok(DeformationMaps { field, raster, f_map, cuts, bands, degenerate, mirrored, coverage, outside_square })
}

/// Pictures of an F map for people to look at: log2 |det F| as grey (0.5 at 1, black at 1/16,
/// white at 16) and the texture's orientation (the angle of F^-1 e1) as a colour wheel.
pub fn f_map_pictures(f_map: &Bitmap) -> (Bitmap, Bitmap) {
    let mut det = Bitmap::new(f_map.width, f_map.height, 3);
    let mut orientation = Bitmap::new(f_map.width, f_map.height, 3);
    for (k, f) in f_map.data.chunks_exact(4).enumerate() {
        let d = f[0] * f[3] - f[1] * f[2];
        let grey = (0.5 + d.abs().max(1e-12).log2() / 8.0).clamp(0.0, 1.0);
        // F^-1 e1 is along (f11, -f10).
        let angle = (-f[2]).atan2(f[3]);
        let colour = [angle, angle - 2.094_395_1, angle + 2.094_395_1].map(|a| 0.5 + 0.5 * a.cos());
        // Stored linear; PNG output applies the sRGB curve.
        det.data[k * 3..k * 3 + 3].copy_from_slice(&[grey * grey; 3]);
        orientation.data[k * 3..k * 3 + 3].copy_from_slice(&colour.map(|c| c * c));
    }
    (det, orientation)
}

/// A picture of cut bands at `res` x `res`: each cut's band in its own colour, the same on both
/// sides, darker away from the cut (its weight psi); black outside the bands.
pub fn bands_picture(bands: &CutBands, f_map: &Bitmap) -> Bitmap {
    let res = f_map.width;
    let mut picture = Bitmap::new(res, res, 3);
    for row in 0..res {
        for col in 0..res {
            let uv = Vec2::new(col as f32 + 0.5, (res - 1 - row) as f32 + 0.5) / res as f32;
            let f = f_map.values(col, row);
            let f = glam::Mat2::from_cols(Vec2::new(f[0], f[2]), Vec2::new(f[1], f[3]));
            if let Some(band) = bands.at(uv, f)[0] {
                let bits = crate::sampling::mix64(band.curve as u64 + 1);
                let colour = [0, 16, 32].map(|s| band.weight * (0.15 + 0.85 * ((bits >> s) & 0xffff) as f32 / 65535.0));
                picture.values_mut(col, row).copy_from_slice(&colour);
            }
        }
    }
    picture
}
