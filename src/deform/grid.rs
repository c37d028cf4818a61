//! The smoothing operator L of paper 000 Eq. 7 (Sec. 4.4, 6.1): theta and S sampled on a
//! regular grid over the UV square and interpolated bilinearly in between. A grid vertex inside
//! a UV triangle takes that triangle's values; one outside every triangle takes the values of
//! the nearest UV triangle. Angles are interpolated as unit vectors (cos, sin), so that
//! wrapping through +-pi never blends the long way round (DESIGN.md section 5).

use super::nearest::{NONE, distance2_to_segment, propagate_nearest};
use glam::{Mat2, Vec2};

/// The values a triangle gives the grid: its orientation angle and its stretch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldSample {
    /// (cos theta, sin theta).
    pub direction: Vec2,
    /// The stretch S (symmetric 2x2), with the mirror diag(1, -1) in front where the UVs are
    /// mirrored ([`super::TriangleDeformation::signed_stretch`]).
    pub stretch: Mat2,
}

impl FieldSample {
    /// F = R(theta) S.
    pub fn deformation(&self) -> Mat2 {
        let d = self.direction.normalize_or(Vec2::X);
        Mat2::from_cols(d, d.perp()) * self.stretch
    }
}

/// An n x n grid of field samples at the UV points ((i + 1/2) / n, (j + 1/2) / n), j = 0 at
/// v = 0.
#[derive(Clone, Debug)]
pub struct FieldGrid {
    /// Samples per side.
    pub n: usize,
    /// Row-major samples, row 0 at v = 0.
    pub samples: Vec<FieldSample>,
    /// The triangle each sample came from (nearest, for samples outside every triangle).
    pub owner: Vec<u32>,
    /// Samples that no triangle covered (filled from the nearest one).
    pub filled: usize,
}

/// Squared distance from `p` to the triangle `t` (in the plane).
fn distance2_to_triangle(p: Vec2, t: [Vec2; 3]) -> f32 {
    if let Some(b) = barycentric(p, t) {
        if b.min_element() >= 0.0 {
            return 0.0;
        }
    }
    (0..3).map(|k| distance2_to_segment(p, t[k], t[(k + 1) % 3])).fold(f32::INFINITY, f32::min)
}

/// Barycentric coordinates of `p` in `t`, None for a degenerate triangle.
fn barycentric(p: Vec2, t: [Vec2; 3]) -> Option<glam::Vec3> {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], p - t[0]);
    let det = e1.perp_dot(e2);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let b1 = d.perp_dot(e2) / det;
    let b2 = e1.perp_dot(d) / det;
    Some(glam::Vec3::new(1.0 - b1 - b2, b1, b2))
}

impl FieldGrid {
    /// Sample the triangles' values (`values[i]` for triangle `i`, None for a degenerate one)
    /// on an n x n grid. None when no triangle has a value.
    pub fn new(n: usize, uv_triangles: &[[Vec2; 3]], values: &[Option<FieldSample>]) -> Option<Self> {
        let mut owner = vec![NONE; n * n];
        let point = |i: usize, j: usize| Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / n as f32;
        for (t, tri) in uv_triangles.iter().enumerate() {
            if values[t].is_none() {
                continue;
            }
            let lo = tri.iter().fold(Vec2::INFINITY, |m, p| m.min(*p));
            let hi = tri.iter().fold(Vec2::NEG_INFINITY, |m, p| m.max(*p));
            let range = |a: f32, b: f32| {
                let first = ((a * n as f32 - 0.5).ceil().max(0.0)) as usize;
                let last = ((b * n as f32 - 0.5).floor().min(n as f32 - 1.0)).max(-1.0) as i64;
                first..(last + 1).max(0) as usize
            };
            for j in range(lo.y, hi.y) {
                for i in range(lo.x, hi.x) {
                    if barycentric(point(i, j), *tri).is_some_and(|b| b.min_element() >= -1e-6) {
                        owner[j * n + i] = t as u32;
                    }
                }
            }
        }
        let covered = owner.iter().filter(|&&o| o != NONE).count();
        if covered == 0 {
            // Nothing landed on a grid point: seed with any valid triangle's nearest point.
            let t = values.iter().position(Option::is_some)?;
            let centre = (uv_triangles[t][0] + uv_triangles[t][1] + uv_triangles[t][2]) / 3.0;
            let (i, j) = ((centre * n as f32).floor().clamp(Vec2::ZERO, Vec2::splat(n as f32 - 1.0))).as_uvec2().into();
            owner[j as usize * n + i as usize] = t as u32;
        }
        // Nearest triangle for the others.
        let mut best: Vec<f32> = owner.iter().map(|&o| if o == NONE { f32::INFINITY } else { 0.0 }).collect();
        propagate_nearest(n, &mut owner, &mut best, |i, j, t| {
            distance2_to_triangle(point(i, j), uv_triangles[t as usize])
        });
        let samples = owner.iter().map(|&o| values[o as usize].expect("owners have values")).collect();
        Some(FieldGrid { n, samples, owner, filled: n * n - covered })
    }

    /// L(theta), L(S) at `uv` (bilinear between grid points, clamped at the square's border),
    /// as F = R(L(theta)) L(S) (Eq. 7).
    pub fn at(&self, uv: Vec2) -> Mat2 {
        let n = self.n;
        let p = (uv * n as f32 - Vec2::splat(0.5)).clamp(Vec2::ZERO, Vec2::splat((n - 1) as f32));
        let base = p.floor();
        let f = p - base;
        let (i0, j0) = (base.x as usize, base.y as usize);
        let (i1, j1) = ((i0 + 1).min(n - 1), (j0 + 1).min(n - 1));
        let s = |i: usize, j: usize| &self.samples[j * n + i];
        let weights = [(1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y];
        let corners = [s(i0, j0), s(i1, j0), s(i0, j1), s(i1, j1)];
        let mut direction = Vec2::ZERO;
        let mut stretch = Mat2::ZERO;
        for (w, c) in weights.iter().zip(corners) {
            direction += c.direction * *w;
            stretch += c.stretch * *w;
        }
        // Opposite directions can cancel: keep the nearest corner's then.
        if direction.length_squared() < 1e-12 {
            direction =
                corners[weights.iter().enumerate().fold(0, |b, (k, w)| if *w > weights[b] { k } else { b })].direction;
        }
        FieldSample { direction, stretch }.deformation()
    }
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

    #[test]
    fn angles_interpolate_the_short_way_round() {
        // Two triangles covering the left and right halves with angles just either side of pi.
        let tris = [
            [Vec2::new(0.0, 0.0), Vec2::new(0.5, 0.0), Vec2::new(0.0, 1.0)],
            [Vec2::new(0.5, 0.0), Vec2::new(0.5, 1.0), Vec2::new(0.0, 1.0)],
            [Vec2::new(0.5, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.5, 1.0)],
            [Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.5, 1.0)],
        ];
        let sample = |a: f32| Some(FieldSample { direction: Vec2::from_angle(a), stretch: Mat2::IDENTITY });
        let (a, b) = (std::f32::consts::PI - 0.1, -std::f32::consts::PI + 0.1);
        let grid = FieldGrid::new(2, &tris, &[sample(a), sample(a), sample(b), sample(b)]).unwrap();
        let mid = grid.at(Vec2::new(0.5, 0.5));
        // Halfway: angle pi (F = -I), not 0.
        assert!((mid * Vec2::X + Vec2::X).length() < 1e-4, "{mid}");
    }
}
