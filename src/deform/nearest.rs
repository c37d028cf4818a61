//! The nearest-primitive fill of a square grid (paper 000 Sec. 6.1: "samples outside of these
//! triangles ... take the value of the closest UV triangle"; the cut map's nearest cut edge):
//! candidates propagate from neighbours in forward and backward raster sweeps, each point
//! keeping the one nearest to it (the classic two-pass distance transform, run twice, with exact
//! distances to the primitives).

/// No primitive yet.
pub const NONE: u32 = u32::MAX;

/// Fill the `n` x `n` grid (row-major, `i` along a row): `owner` holds seeds (primitive ids,
/// [`NONE`] elsewhere) and `best` their squared distances; `distance2(i, j, id)` is the squared
/// distance from point (i, j) to primitive `id`. On return every point reachable from a seed
/// holds its nearest primitive among those its neighbours offered.
pub fn propagate_nearest(n: usize, owner: &mut [u32], best: &mut [f32], distance2: impl Fn(usize, usize, u32) -> f32) {
    for pass in 0..4 {
        let forward = pass % 2 == 0;
        for step in 0..n * n {
            let k = if forward { step } else { n * n - 1 - step };
            if best[k] == 0.0 {
                continue;
            }
            let (i, j) = ((k % n) as i64, (k / n) as i64);
            let d = if forward { -1 } else { 1 };
            for (di, dj) in [(d, 0), (0, d), (d, d), (-d, d)] {
                let (ni, nj) = (i + di, j + dj);
                if ni < 0 || nj < 0 || ni >= n as i64 || nj >= n as i64 {
                    continue;
                }
                let candidate = owner[nj as usize * n + ni as usize];
                if candidate == NONE || candidate == owner[k] {
                    continue;
                }
                let dist = distance2(i as usize, j as usize, candidate);
                if dist < best[k] {
                    best[k] = dist;
                    owner[k] = candidate;
                }
            }
        }
    }
}

/// Squared distance from `p` to the segment `a` `b` (a point when they coincide).
pub fn distance2_to_segment(p: glam::Vec2, a: glam::Vec2, b: glam::Vec2) -> f32 {
    let ab = b - a;
    let s = ((p - a).dot(ab) / ab.length_squared().max(1e-30)).clamp(0.0, 1.0);
    (a + ab * s).distance_squared(p)
}
/// The segment a-b clamped to the unit square, as at most five straight pieces: clamping is
/// linear between the points where the segment crosses the lines u = 0, u = 1, v = 0, v = 1.
/// Pieces of a non-finite segment are not finite either; callers skip such points.
pub(super) fn clamped_pieces(a: glam::Vec2, b: glam::Vec2) -> Vec<[glam::Vec2; 2]> {
    let d = b - a;
    let mut ts = vec![0.0f32, 1.0];
    for axis in 0..2 {
        if d[axis] != 0.0 {
            ts.extend([0.0, 1.0].map(|edge| (edge - a[axis]) / d[axis]).into_iter().filter(|t| *t > 0.0 && *t < 1.0));
        }
    }
    ts.sort_by(f32::total_cmp);
    let clamp = |t: f32| (a + d * t).clamp(glam::Vec2::ZERO, glam::Vec2::ONE);
    ts.windows(2).map(|w| [clamp(w[0]), clamp(w[1])]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn clamped_pieces_follow_the_clamped_segment_and_stay_short() {
        // Far outside the square: the pieces trace the clamp of the segment, whose length is
        // bounded by the square's, whatever the segment's.
        let (a, b) = (Vec2::new(-1e4, -3e4), Vec2::new(2e4, 1e4));
        let pieces = clamped_pieces(a, b);
        assert!(pieces.len() <= 5);
        let length: f32 = pieces.iter().map(|[p, q]| p.distance(*q)).sum();
        assert!(length <= 4.0, "{length}");
        for [p, q] in &pieces {
            for t in [0.0, 0.3, 1.0] {
                let x = p.lerp(*q, t);
                assert!(x.cmpge(Vec2::ZERO).all() && x.cmple(Vec2::ONE).all(), "{x}");
            }
        }
        // Consecutive pieces join, and the ends are the clamped end points.
        assert!(pieces.windows(2).all(|w| w[0][1].distance(w[1][0]) < 1e-6));
        assert_eq!(pieces[0][0], a.clamp(Vec2::ZERO, Vec2::ONE));
        assert_eq!(pieces[pieces.len() - 1][1], b.clamp(Vec2::ZERO, Vec2::ONE));
        // Inside the square a segment is one piece, itself.
        let inside = clamped_pieces(Vec2::new(0.1, 0.2), Vec2::new(0.7, 0.9));
        assert_eq!(inside, vec![[Vec2::new(0.1, 0.2), Vec2::new(0.7, 0.9)]]);
    }
}
