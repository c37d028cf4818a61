//! The nearest-primitive fill of a square grid (paper 000 Sec. 6.1: "samples outside of these
//! triangles ... take the value of the closest UV triangle"; here the F map's texels):
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
