//! How a mesh's UV triangles cover the UV square, which an F map spans. Overlapping UV islands:
//! the part of the square that more than one triangle covers. An F map has one value per texel,
//! so where two parts of the surface share texels (mirrored or stacked islands) one of them gets
//! the other's deformation; `tessera deform` warns with this fraction. UV area outside the
//! square: the map holds no field there (UDIM tiles, islands moved by whole periods), and
//! `deform` warns or refuses ([`uv_area_outside_square`]).
//!
//! Coverage is counted at texel centres of an `n` x `n` grid over the UV square. Each triangle
//! adds, on every row it crosses, one to the texels between its left and right edges, through a
//! difference array: the cost is one span per triangle and row, not per texel, so a hostile
//! mesh of huge UV triangles costs at most triangles x rows. Spans are half-open ([left,
//! right) on a row, rows [bottom, top)) and shared edges are intersected with their endpoints in
//! one order, so triangles that only share an edge never count a texel twice.

use glam::Vec2;

/// Coverage of the UV square by a mesh's UV triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvOverlap {
    /// Texel centres inside at least one triangle.
    pub covered: usize,
    /// Texel centres inside two triangles or more.
    pub overlapped: usize,
}

impl UvOverlap {
    /// The counts of a coverage grid ([`uv_coverage`]).
    pub fn of_coverage(coverage: &[u8]) -> Self {
        UvOverlap {
            covered: coverage.iter().filter(|c| **c >= 1).count(),
            overlapped: coverage.iter().filter(|c| **c >= 2).count(),
        }
    }

    /// The fraction of the covered texels that are covered more than once (0 when none is
    /// covered).
    pub fn fraction(&self) -> f64 {
        if self.covered == 0 { 0.0 } else { self.overlapped as f64 / self.covered as f64 }
    }
}

/// Count, on an `n` x `n` grid of texel centres over the UV square, how many are covered once
/// or more and twice or more by `triangles` (in UV). Parts of triangles outside the square are
/// not counted; degenerate triangles cover nothing.
pub fn uv_overlap(triangles: &[[Vec2; 3]], n: usize) -> UvOverlap {
    UvOverlap::of_coverage(&uv_coverage(triangles, n))
}

/// How many of `triangles` cover each texel centre of an `n` x `n` grid over the UV square
/// (row-major, row 0 at v = 0), saturated at 255.
pub fn uv_coverage(triangles: &[[Vec2; 3]], n: usize) -> Vec<u8> {
    // Per row, +1 where a span starts and -1 just after it ends.
    let mut starts = vec![0i32; n * (n + 1)];
    for t in triangles {
        let area = (t[1] - t[0]).perp_dot(t[2] - t[0]);
        if !(area.abs() > 0.0) || !t.iter().all(|p| p.is_finite()) {
            continue;
        }
        let (low, high) = t.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), p| (l.min(p.y), h.max(p.y)));
        // Rows whose centre (j + 0.5) / n lies in [low, high).
        let first = ((low * n as f32 - 0.5).ceil().max(0.0)) as usize;
        let end = ((high * n as f32 - 0.5).ceil().clamp(0.0, n as f32)) as usize;
        for j in first..end {
            let y = (j as f32 + 0.5) / n as f32;
            let Some((left, right)) = span(t, y) else { continue };
            let i0 = ((left * n as f32 - 0.5).ceil().clamp(0.0, n as f32)) as usize;
            let i1 = ((right * n as f32 - 0.5).ceil().clamp(0.0, n as f32)) as usize;
            if i0 < i1 {
                starts[j * (n + 1) + i0] += 1;
                starts[j * (n + 1) + i1] -= 1;
            }
        }
    }
    let mut counts = Vec::with_capacity(n * n);
    for row in starts.chunks_exact(n + 1) {
        let mut count = 0;
        for delta in &row[..n] {
            count += delta;
            counts.push(count.clamp(0, 255) as u8);
        }
    }
    counts
}

/// The fraction of the UV area of `triangles` that lies outside the unit square [0, 1]^2 (0 when
/// their area is 0 or not finite): each triangle clipped to the square by its four sides
/// (Sutherland-Hodgman), in f64.
pub fn uv_area_outside_square(triangles: &[[Vec2; 3]]) -> f64 {
    let (mut total, mut inside) = (0.0f64, 0.0f64);
    for t in triangles {
        let polygon: Vec<[f64; 2]> = t.iter().map(|p| [p.x as f64, p.y as f64]).collect();
        let area = polygon_area(&polygon);
        if !area.is_finite() {
            continue;
        }
        total += area;
        if t.iter().all(|p| (0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y)) {
            inside += area;
            continue;
        }
        // The half-planes x >= 0, x <= 1, y >= 0, y <= 1 as (axis, side).
        let clipped = [(0, 0.0), (0, 1.0), (1, 0.0), (1, 1.0)]
            .iter()
            .fold(polygon, |polygon, &(axis, side)| clip(&polygon, axis, side));
        inside += polygon_area(&clipped);
    }
    if total > 0.0 { ((total - inside) / total).clamp(0.0, 1.0) } else { 0.0 }
}

/// Unsigned area of a polygon (shoelace).
fn polygon_area(polygon: &[[f64; 2]]) -> f64 {
    let n = polygon.len();
    let twice: f64 = (0..n)
        .map(|i| {
            let (p, q) = (polygon[i], polygon[(i + 1) % n]);
            p[0] * q[1] - q[0] * p[1]
        })
        .sum();
    0.5 * twice.abs()
}

/// The part of `polygon` (convex) on the square's side of the line `p[axis] = side`: where
/// p[axis] >= 0 for side 0, p[axis] <= 1 for side 1.
fn clip(polygon: &[[f64; 2]], axis: usize, side: f64) -> Vec<[f64; 2]> {
    let inside = |p: &[f64; 2]| if side == 0.0 { p[axis] >= 0.0 } else { p[axis] <= 1.0 };
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (i, p) in polygon.iter().enumerate() {
        let q = &polygon[(i + 1) % polygon.len()];
        if inside(p) {
            out.push(*p);
        }
        if inside(p) != inside(q) {
            let t = (side - p[axis]) / (q[axis] - p[axis]);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    out
}

/// The interval [left, right) of the horizontal line at height `y` inside triangle `t`, from
/// the edges that straddle it (each edge's crossing computed from its endpoints in a fixed
/// order, so that two triangles sharing the edge agree on it exactly).
fn span(t: &[Vec2; 3], y: f32) -> Option<(f32, f32)> {
    let mut xs = [0.0f32; 2];
    let mut count = 0;
    for k in 0..3 {
        let (mut p, mut q) = (t[k], t[(k + 1) % 3]);
        if (p.y, p.x) > (q.y, q.x) {
            std::mem::swap(&mut p, &mut q);
        }
        // Half-open in y, so that a vertex exactly on the line counts for one edge of each pair.
        if p.y <= y && y < q.y && count < 2 {
            xs[count] = p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x);
            count += 1;
        }
    }
    (count == 2).then(|| (xs[0].min(xs[1]), xs[0].max(xs[1])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(origin: Vec2, size: f32) -> [[Vec2; 3]; 2] {
        let [a, b, c, d] = [origin, origin + Vec2::X * size, origin + Vec2::splat(size), origin + Vec2::Y * size];
        [[a, b, c], [a, c, d]]
    }

    #[test]
    fn uv_overlap_of_a_tiled_square_is_zero() {
        // A 5 x 5 grid of squares, each two triangles: edges shared in every direction.
        let triangles: Vec<[Vec2; 3]> =
            (0..25).flat_map(|k| square(Vec2::new((k % 5) as f32, (k / 5) as f32) * 0.2, 0.2)).collect();
        let o = uv_overlap(&triangles, 64);
        assert_eq!(o, UvOverlap { covered: 64 * 64, overlapped: 0 });
    }

    #[test]
    fn uv_overlap_counts_stacked_islands() {
        // Two islands: one over the left half, a copy of a quarter of the square over its top.
        let mut triangles = square(Vec2::ZERO, 0.5).to_vec();
        triangles.extend(square(Vec2::new(0.0, 0.0), 0.25));
        let o = uv_overlap(&triangles, 64);
        assert_eq!(o.covered, 32 * 32);
        assert_eq!(o.overlapped, 16 * 16);
        assert!((o.fraction() - 0.25).abs() < 1e-12);
        // Huge and degenerate triangles cost rows, not texels, and count only inside.
        let huge = [[Vec2::splat(-1e6), Vec2::new(1e6, -1e6), Vec2::new(0.0, 1e6)]];
        assert_eq!(uv_overlap(&huge, 16), UvOverlap { covered: 256, overlapped: 0 });
        assert_eq!(uv_overlap(&[[Vec2::ZERO, Vec2::ONE, Vec2::ONE]], 16).covered, 0);
    }

    #[test]
    fn uv_area_outside_the_square_is_measured_exactly() {
        let inside = square(Vec2::splat(0.25), 0.5);
        assert_eq!(uv_area_outside_square(&inside), 0.0);
        // A square of side 0.5 straddling the right edge by 0.1: a fifth of it outside.
        let straddling = square(Vec2::new(0.6, 0.2), 0.5);
        assert!((uv_area_outside_square(&straddling) - 0.2).abs() < 1e-6);
        // Moved by a whole period (a UDIM tile): all of it outside; a square over the unit
        // square's corner, half outside along each axis: three quarters.
        assert_eq!(uv_area_outside_square(&square(Vec2::new(1.25, 0.25), 0.5)), 1.0);
        let corner = square(Vec2::splat(-0.5), 1.0);
        assert!((uv_area_outside_square(&corner) - 0.75).abs() < 1e-6);
        // Both together weigh by area; degenerate and non-finite triangles weigh nothing.
        let mut both = inside.to_vec();
        both.extend(square(Vec2::new(1.25, 0.25), 0.5));
        both.push([Vec2::ZERO, Vec2::ONE, Vec2::ONE]);
        both.push([Vec2::ZERO, Vec2::X, Vec2::splat(f32::NAN)]);
        assert!((uv_area_outside_square(&both) - 0.5).abs() < 1e-12);
        assert_eq!(uv_area_outside_square(&[]), 0.0);
    }
}
