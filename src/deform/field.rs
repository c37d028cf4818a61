//! The smoothing of the deformation field (paper 000 Sec. 4.4), done on the surface chart by
//! chart: one orientation and one stretch per UV vertex (a welded position with one UV), the
//! area-weighted mean of its triangles', optionally averaged further over the 1-ring, and
//! interpolated barycentrically inside each triangle. The paper lists these per-vertex values
//! as the alternative to its UV grid (Eq. 7); on a packed atlas the grid mixes the fields of
//! neighbouring charts and interpolates between mirrored and unmirrored ones (DESIGN.md section
//! 5), while the vertices of a chart only ever see that chart, except that the UV vertices of
//! one position on a cut may share their direction on the surface
//! ([`ChartField::share_directions_across_cuts`]; stretches stay per chart). Angles are
//! interpolated as unit vectors (cos, sin), so that wrapping through +-pi never blends the long
//! way round; the mirror of a triangle with mirrored UVs is applied per triangle, never
//! interpolated.

use super::nearest::{NONE, distance2_to_segment, propagate_nearest};
use crate::geometry::TriangleMesh;
use glam::{Mat2, Mat3, Vec2, Vec3};
use std::collections::HashMap;

/// The orientation and stretch of the field at a point or a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldSample {
    /// (cos theta, sin theta).
    pub direction: Vec2,
    /// The stretch S (symmetric positive definite, Sec. 4.2).
    pub stretch: Mat2,
}

impl FieldSample {
    /// F = R(theta) S, or R(theta) M S with M = diag(1, -1) where the UVs are `mirrored`:
    /// J F^-1 = R M R(-theta) is then a rotation of the exemplar's frame onto the surface and
    /// the texture never shows mirrored (det F < 0 there; DESIGN.md section 5).
    pub fn deformation(&self, mirrored: bool) -> Mat2 {
        let d = self.direction.normalize_or(Vec2::X);
        let m = if mirrored { crate::math::MIRROR } else { Mat2::IDENTITY };
        Mat2::from_cols(d, d.perp()) * m * self.stretch
    }
}

/// What one triangle gives the field: its sample and whether its UVs are mirrored; None for a
/// degenerate triangle.
pub type TriangleSample = Option<(FieldSample, bool)>;

/// The field smoothed per chart: samples at the UV vertices, interpolated in each triangle.
#[derive(Clone, Debug)]
pub struct ChartField {
    /// The chart (UV island: triangles joined through shared UV vertices) of each triangle.
    pub chart_of_triangle: Vec<u32>,
    /// How many charts the mesh has.
    pub charts: usize,
    /// The UV vertex at each corner of each triangle.
    corners: Vec<[u32; 3]>,
    /// The smoothed sample at each UV vertex.
    vertex_samples: Vec<FieldSample>,
    /// Whether each triangle's UVs are mirrored.
    mirrored: Vec<bool>,
}

impl ChartField {
    /// Per-vertex samples from the triangles' (`samples[t]` for triangle t, None where it is
    /// degenerate), each vertex taking the mean of its triangles weighted by their surface area,
    /// then `smoothing` rounds of averaging over each vertex's triangles. None when every
    /// triangle is degenerate.
    pub fn new(mesh: &TriangleMesh, samples: &[TriangleSample], smoothing: usize) -> Option<Self> {
        let uvs = mesh.uvs.as_ref()?;
        let fallback = samples.iter().flatten().next()?.0;
        let (corners, vertices) = uv_vertices(mesh, uvs);
        let (chart_of_triangle, charts) = charts(&corners, vertices);
        let areas: Vec<f32> = mesh
            .indices
            .iter()
            .map(|idx| {
                let x = idx.map(|i| mesh.positions[i as usize]);
                (x[1] - x[0]).cross(x[2] - x[0]).length() / 2.0
            })
            .collect();
        // Area-weighted sums into the vertices; a triangle contributes `value(t)` to its
        // corners.
        let gather = |value: &dyn Fn(usize) -> Option<FieldSample>| {
            let mut sum = vec![(Vec2::ZERO, Mat2::ZERO, 0.0f32); vertices];
            for (t, c) in corners.iter().enumerate() {
                let Some(s) = value(t) else { continue };
                for &v in c {
                    let e = &mut sum[v as usize];
                    *e = (e.0 + s.direction * areas[t], e.1 + s.stretch * areas[t], e.2 + areas[t]);
                }
            }
            sum
        };
        let average = |sums: Vec<(Vec2, Mat2, f32)>| -> Vec<Option<FieldSample>> {
            sums.into_iter()
                .map(|(d, s, w)| (w > 0.0).then(|| FieldSample { direction: d / w, stretch: s / w }))
                .collect()
        };
        // The mean of a triangle's corners (over those that have a value).
        let corner_mean = |vertex_samples: &[Option<FieldSample>], t: usize| {
            samples[t]?;
            let known: Vec<FieldSample> = corners[t].iter().filter_map(|&v| vertex_samples[v as usize]).collect();
            let n = known.len() as f32;
            (n > 0.0).then(|| FieldSample {
                direction: known.iter().map(|s| s.direction).sum::<Vec2>() / n,
                stretch: known.iter().fold(Mat2::ZERO, |m, s| m + s.stretch) / n,
            })
        };
        let mut vertex_samples = average(gather(&|t| samples[t].map(|s| s.0)));
        for _ in 0..smoothing {
            vertex_samples = average(gather(&|t| corner_mean(&vertex_samples, t)));
        }
        // A vertex whose triangles are all degenerate takes its chart's mean.
        let mut chart_sums = vec![(Vec2::ZERO, Mat2::ZERO, 0.0f32); charts];
        for (t, s) in samples.iter().enumerate() {
            if let Some((s, _)) = s {
                let e = &mut chart_sums[chart_of_triangle[t] as usize];
                *e = (e.0 + s.direction * areas[t], e.1 + s.stretch * areas[t], e.2 + areas[t]);
            }
        }
        let chart_means = average(chart_sums);
        let mut chart_of_vertex = vec![0u32; vertices];
        for (t, c) in corners.iter().enumerate() {
            c.iter().for_each(|&v| chart_of_vertex[v as usize] = chart_of_triangle[t]);
        }
        let vertex_samples = vertex_samples
            .into_iter()
            .zip(&chart_of_vertex)
            .map(|(s, &c)| s.or(chart_means[c as usize]).unwrap_or(fallback))
            .collect();
        let mirrored = samples.iter().map(|s| s.is_some_and(|s| s.1)).collect();
        Some(ChartField { chart_of_triangle, charts, corners, vertex_samples, mirrored })
    }

    /// Give the UV vertices of one position on a cut one direction on the surface, for an
    /// orientation field given on the surface (not F = S, whose direction is the UV map's own).
    /// Each chart's vertex averages only its own chart's triangles, so where the field or the
    /// UV map varies across the cut, the two sides' texture axes J F^-1 e1 meet at an angle
    /// there (a kink in a brushed highlight). Here each UV vertex's axis on the surface (J F^-1
    /// e1 over its triangles, area-weighted) is averaged over all the UV vertices of its
    /// position, and each takes the direction that its own triangles give that mean (Eq. 6
    /// with the mean for the field's direction and each triangle's own stretch from `samples`,
    /// which must be those of [`ChartField::new`], averaged as unit vectors like the vertex's
    /// own samples); stretches stay per chart. Positions whose sides' axes differ by more than
    /// 30 degrees keep their own directions: there the field turns fast (near its singular
    /// points, or by 180 degrees on a mirrored half) and one mean would pull each side off its
    /// neighbours.
    pub fn share_directions_across_cuts(&mut self, mesh: &TriangleMesh, samples: &[TriangleSample]) {
        let Some(uvs) = mesh.uvs.as_ref() else { return };
        let vertices = self.vertex_samples.len();
        let (welded, _) = mesh.welded_vertices();
        let mut position_of_vertex = vec![0u32; vertices];
        for (idx, c) in mesh.indices.iter().zip(&self.corners) {
            (0..3).for_each(|k| position_of_vertex[c[k] as usize] = welded[idx[k] as usize]);
        }
        let mut at_position: HashMap<u32, Vec<u32>> = HashMap::new();
        for v in 0..vertices as u32 {
            at_position.entry(position_of_vertex[v as usize]).or_default().push(v);
        }
        at_position.retain(|_, vs| vs.len() > 1);
        // Each triangle's Jacobian (d position / d uv, the unit normal as third column) and
        // area, listed at its UV vertices with its own sample.
        let mut triangles_of: Vec<Vec<(f32, Mat3, FieldSample, bool)>> = vec![Vec::new(); vertices];
        for ((idx, c), sample) in mesh.indices.iter().zip(&self.corners).zip(samples) {
            let x = idx.map(|i| mesh.positions[i as usize]);
            let u = idx.map(|i| uvs[i as usize]);
            if let (Some(j), Some((sample, mirrored))) = (super::deformation_gradient(x, u), sample) {
                let area = (x[1] - x[0]).cross(x[2] - x[0]).length() / 2.0;
                c.iter().for_each(|&v| triangles_of[v as usize].push((area, j, *sample, *mirrored)));
            }
        }
        // The area-weighted sum of a UV vertex's texture axis over its triangles.
        let axis_sum = |v: u32| -> Vec3 {
            let s = self.vertex_samples[v as usize];
            triangles_of[v as usize].iter().fold(Vec3::ZERO, |sum, &(area, j, _, mirrored)| {
                sum + super::gradient::texture_axis(j, s.deformation(mirrored)).unwrap_or(Vec3::ZERO) * area
            })
        };
        let mut shared: Vec<(u32, Vec3)> = Vec::new();
        for vs in at_position.values() {
            let sums: Vec<Vec3> = vs.iter().map(|&v| axis_sum(v)).collect();
            let agree =
                sums.iter().all(|a| sums.iter().all(|b| a.dot(*b) > AGREEING_AXES_COS * a.length() * b.length()));
            let mean = sums.iter().sum::<Vec3>();
            if agree && mean.length_squared() > 0.0 {
                shared.extend(vs.iter().map(|&v| (v, mean)));
            }
        }
        for (v, mean) in shared {
            // (cos theta, sin theta) with theta = -angle of [M] S J^+ d from e1 (Eq. 6): the
            // vector [M] S J^+ d reflected in the u axis.
            let direction = triangles_of[v as usize].iter().fold(Vec2::ZERO, |sum, &(area, j, sample, mirrored)| {
                let mut local = sample.stretch * (j.inverse() * mean).truncate();
                if mirrored {
                    local.y = -local.y;
                }
                sum + Vec2::new(local.x, -local.y).normalize_or_zero() * area
            });
            if let Some(direction) = direction.try_normalize() {
                self.vertex_samples[v as usize].direction = direction;
            }
        }
    }

    /// F at the point of triangle `t` with barycentric coordinates `b` (clamped to the triangle).
    pub fn at(&self, t: usize, b: Vec3) -> Mat2 {
        let b = b.max(Vec3::ZERO);
        let b = b / b.element_sum().max(1e-30);
        let s = self.corners[t].map(|v| self.vertex_samples[v as usize]);
        let mut direction = s[0].direction * b.x + s[1].direction * b.y + s[2].direction * b.z;
        // Opposite directions can cancel: keep the nearest corner's then.
        if direction.length_squared() < 1e-12 {
            let k = if b.x >= b.y && b.x >= b.z {
                0
            } else if b.y >= b.z {
                1
            } else {
                2
            };
            direction = s[k].direction;
        }
        let stretch = s[0].stretch * b.x + s[1].stretch * b.y + s[2].stretch * b.z;
        FieldSample { direction, stretch }.deformation(self.mirrored[t])
    }
}

/// [`ChartField::share_directions_across_cuts`] leaves a position alone where its sides'
/// texture axes differ by more than this angle's cosine (30 degrees).
const AGREEING_AXES_COS: f32 = 0.866_025_4;

/// The UV vertex (a welded position with one UV) at each corner of each triangle of `mesh`,
/// whose UVs are `uvs`, numbered from 0; and how many there are.
fn uv_vertices(mesh: &TriangleMesh, uvs: &[Vec2]) -> (Vec<[u32; 3]>, usize) {
    let (welded, _) = mesh.welded_vertices();
    let mut ids: HashMap<(u32, [u32; 2]), u32> = HashMap::new();
    let corners = mesh
        .indices
        .iter()
        .map(|idx| {
            idx.map(|i| {
                let key = (welded[i as usize], uvs[i as usize].to_array().map(f32::to_bits));
                let next = ids.len() as u32;
                *ids.entry(key).or_insert(next)
            })
        })
        .collect();
    (corners, ids.len())
}

/// The UV chart (island: triangles joined through shared UV vertices) of each triangle of
/// `mesh`, numbered from 0 in the order of their first triangles, as [`ChartField`] finds them;
/// and how many there are. None without UVs.
pub fn uv_charts(mesh: &TriangleMesh) -> Option<(Vec<u32>, usize)> {
    let (corners, vertices) = uv_vertices(mesh, mesh.uvs.as_ref()?);
    Some(charts(&corners, vertices))
}

/// The connected components of triangles sharing a vertex: the chart of each triangle (numbered
/// from 0 in order of first appearance) and their number.
fn charts(corners: &[[u32; 3]], vertices: usize) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..vertices as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    for c in corners {
        let r = root(&mut parent, c[0]);
        for &v in &c[1..] {
            let other = root(&mut parent, v);
            parent[other as usize] = r;
        }
    }
    let mut number: HashMap<u32, u32> = HashMap::new();
    let chart_of_triangle = corners
        .iter()
        .map(|c| {
            let r = root(&mut parent, c[0]);
            let next = number.len() as u32;
            *number.entry(r).or_insert(next)
        })
        .collect();
    (chart_of_triangle, number.len())
}

/// A raster of the UV square: for each of its `res` x `res` texel centres
/// ((i + 1/2) / res, (j + 1/2) / res), row-major from the bottom row, the triangle that covers
/// it (the last one where UV triangles overlap) or else the nearest triangle, with the texel's
/// barycentric coordinates in it.
#[derive(Clone, Debug)]
pub struct TriangleRaster {
    /// Texels per side.
    pub res: usize,
    /// The triangle of each texel.
    pub owner: Vec<u32>,
    /// Texels no triangle covers (they take the nearest one's).
    pub filled: usize,
}

impl TriangleRaster {
    /// Rasterise `uv_triangles`, leaving out those with `skip[t]` (degenerate ones). Where
    /// triangles overlap in UV, one with `preferred[t]` keeps a texel from later ones without
    /// (so that overlapping mirrored islands leave one island's field, not a patchwork of both).
    /// None when every triangle is skipped.
    pub fn new(
        res: usize,
        uv_triangles: &[[Vec2; 3]],
        skip: impl Fn(usize) -> bool,
        preferred: impl Fn(usize) -> bool,
    ) -> Option<Self> {
        let mut owner = vec![NONE; res * res];
        let point = |i: usize, j: usize| Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / res as f32;
        for (t, tri) in uv_triangles.iter().enumerate() {
            if skip(t) {
                continue;
            }
            let lo = tri.iter().fold(Vec2::INFINITY, |m, p| m.min(*p));
            let hi = tri.iter().fold(Vec2::NEG_INFINITY, |m, p| m.max(*p));
            let range = |a: f32, b: f32| {
                let first = ((a * res as f32 - 0.5).ceil().max(0.0)) as usize;
                let last = ((b * res as f32 - 0.5).floor().min(res as f32 - 1.0)).max(-1.0) as i64;
                first..(last + 1).max(0) as usize
            };
            for j in range(lo.y, hi.y) {
                for i in range(lo.x, hi.x) {
                    let inside = barycentric(point(i, j), *tri).is_some_and(|b| b.min_element() >= -1e-6);
                    let kept = owner[j * res + i] != NONE && preferred(owner[j * res + i] as usize) && !preferred(t);
                    if inside && !kept {
                        owner[j * res + i] = t as u32;
                    }
                }
            }
        }
        let covered = owner.iter().filter(|&&o| o != NONE).count();
        if covered == 0 {
            // Nothing landed on a texel centre: seed with any kept triangle's nearest texel.
            let t = (0..uv_triangles.len()).find(|&t| !skip(t))?;
            let centre = (uv_triangles[t][0] + uv_triangles[t][1] + uv_triangles[t][2]) / 3.0;
            let (i, j) =
                ((centre * res as f32).floor().clamp(Vec2::ZERO, Vec2::splat(res as f32 - 1.0))).as_uvec2().into();
            owner[j as usize * res + i as usize] = t as u32;
        }
        let mut best: Vec<f32> = owner.iter().map(|&o| if o == NONE { f32::INFINITY } else { 0.0 }).collect();
        propagate_nearest(res, &mut owner, &mut best, |i, j, t| {
            distance2_to_triangle(point(i, j), uv_triangles[t as usize])
        });
        Some(TriangleRaster { res, owner, filled: res * res - covered })
    }

    /// The UV point at the centre of texel `k`.
    pub fn point(&self, k: usize) -> Vec2 {
        Vec2::new((k % self.res) as f32 + 0.5, (k / self.res) as f32 + 0.5) / self.res as f32
    }
}

/// Squared distance from `p` to the triangle `t` (in the plane).
fn distance2_to_triangle(p: Vec2, t: [Vec2; 3]) -> f32 {
    if let Some(b) = barycentric(p, t)
        && b.min_element() >= 0.0
    {
        return 0.0;
    }
    (0..3).map(|k| distance2_to_segment(p, t[k], t[(k + 1) % 3])).fold(f32::INFINITY, f32::min)
}

/// Barycentric coordinates of `p` in `t`, None for a degenerate triangle.
pub fn barycentric(p: Vec2, t: [Vec2; 3]) -> Option<Vec3> {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let det = e1.perp_dot(e2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let b1 = d.perp_dot(e2) / det;
    let b2 = e1.perp_dot(d) / det;
    Some(Vec3::new(1.0 - b1 - b2, b1, b2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_triangle() {
        let t = [Vec2::ZERO, Vec2::X, Vec2::Y];
        assert_eq!(distance2_to_triangle(Vec2::new(0.2, 0.2), t), 0.0);
        assert!((distance2_to_triangle(Vec2::new(0.5, -0.5), t) - 0.25).abs() < 1e-6);
        assert!((distance2_to_triangle(Vec2::new(2.0, 0.0), t) - 1.0).abs() < 1e-6);
    }

    /// Two charts side by side in UV, each a square of two triangles; positions apart.
    fn two_charts() -> TriangleMesh {
        let square = |x: f32, u: f32| {
            let p = [
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 1.0, 0.0, 0.0),
                Vec3::new(x + 1.0, 1.0, 0.0),
                Vec3::new(x, 1.0, 0.0),
            ];
            let t = [Vec2::new(u, 0.0), Vec2::new(u + 0.5, 0.0), Vec2::new(u + 0.5, 1.0), Vec2::new(u, 1.0)];
            (p, t)
        };
        let (p0, t0) = square(0.0, 0.0);
        let (p1, t1) = square(5.0, 0.5);
        TriangleMesh {
            positions: [p0, p1].concat(),
            normals: None,
            uvs: Some([t0, t1].concat()),
            indices: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]],
        }
    }

    #[test]
    fn charts_never_mix_and_angles_interpolate_the_short_way_round() {
        let mesh = two_charts();
        let sample = |a: f32| Some((FieldSample { direction: Vec2::from_angle(a), stretch: Mat2::IDENTITY }, false));
        let (a, b) = (std::f32::consts::PI - 0.1, -std::f32::consts::PI + 0.1);
        // Chart 0 has a on one triangle and b on the other; chart 1 has 0.
        let field = ChartField::new(&mesh, &[sample(a), sample(b), sample(0.0), sample(0.0)], 0).unwrap();
        assert_eq!(field.charts, 2);
        assert_eq!(field.chart_of_triangle, vec![0, 0, 1, 1]);
        // On the shared diagonal of chart 0 the angle is pi (F = -I), not 0.
        let f = field.at(0, Vec3::new(0.5, 0.0, 0.5));
        assert!((f * Vec2::X + Vec2::X).length() < 1e-4, "{f}");
        // Chart 1's corner next to chart 0 in UV keeps chart 1's identity exactly.
        assert!((field.at(2, Vec3::X) - Mat2::IDENTITY).abs_diff_eq(Mat2::ZERO, 1e-6));
    }

    #[test]
    fn the_mirror_stays_with_its_triangle() {
        let mesh = two_charts();
        let s = FieldSample { direction: Vec2::X, stretch: Mat2::from_diagonal(Vec2::new(2.0, 3.0)) };
        let field =
            ChartField::new(&mesh, &[Some((s, true)), Some((s, false)), Some((s, true)), Some((s, true))], 2).unwrap();
        // det F never passes through 0: mirrored triangles have det -6, the other +6.
        for (t, sign) in [(0, -1.0), (1, 1.0), (2, -1.0)] {
            for b in [Vec3::X, Vec3::new(0.3, 0.3, 0.4), Vec3::Z] {
                assert!((field.at(t, b).determinant() - 6.0 * sign).abs() < 1e-4);
            }
        }
    }
}
