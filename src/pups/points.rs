//! Control points of a PUPs texture (paper 002 Sec. 3): Poisson disk distributions (Bridson's
//! algorithm), uniform or with a spacing that varies over the plane, on the unit square or on
//! the torus (periodic, for tileable textures).

use crate::sampling::Sampler;
use glam::Vec2;

/// Most control points a texture may have (copies of a periodic domain included).
pub const MAX_POINTS: usize = 1 << 20;

/// Candidates Bridson's algorithm tries around an active point before retiring it.
const CANDIDATES: usize = 30;

/// Where points are drawn: the unit square, either with a margin of points around it (so that
/// the square's border sees a full neighbourhood) or periodic (a torus).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// [0, 1]^2 grown by `margin` on each side.
    Square {
        /// Width of the band of extra points around the unit square.
        margin: f32,
    },
    /// The unit square with opposite sides identified.
    Periodic,
}

impl Domain {
    /// Lower corner and size of the region points are drawn in.
    fn extent(self) -> (Vec2, f32) {
        match self {
            Domain::Square { margin } => (Vec2::splat(-margin), 1.0 + 2.0 * margin),
            Domain::Periodic => (Vec2::ZERO, 1.0),
        }
    }

    /// The offset from `a` to `b`: straight, or the shortest one on the torus.
    pub fn offset(self, a: Vec2, b: Vec2) -> Vec2 {
        let d = b - a;
        match self {
            Domain::Square { .. } => d,
            Domain::Periodic => d - d.round(),
        }
    }
}

/// An upper bound on the points of a Poisson disk distribution with spacing at least
/// `min_spacing` over `domain`: disks of radius min_spacing / 2 do not overlap, and the densest
/// packing of disks covers pi / sqrt(12) of the plane.
pub fn max_point_count(domain: Domain, min_spacing: f32) -> f64 {
    let (_, size) = domain.extent();
    let r = (min_spacing as f64 * 0.5).max(1e-12);
    let grown = size as f64 + min_spacing as f64;
    (grown * grown) * (std::f64::consts::PI / 12f64.sqrt()) / (std::f64::consts::PI * r * r)
}

/// A Poisson disk distribution over `domain` (Bridson 2007): no two points closer than the
/// spacing `spacing(p)` at the newer one, drawn with `seed`. `min_spacing` is the smallest
/// value `spacing` takes (the grid's cell size follows from it). Errors when the spacing is not
/// positive and finite or the points could exceed [`MAX_POINTS`].
pub fn poisson_disk(
    domain: Domain,
    min_spacing: f32,
    max_spacing: f32,
    spacing: &dyn Fn(Vec2) -> f32,
    seed: u64,
) -> Result<Vec<Vec2>, String> {
    if !(min_spacing > 0.0 && min_spacing.is_finite() && max_spacing >= min_spacing && max_spacing.is_finite()) {
        return Err(format!("point spacing {min_spacing} to {max_spacing}: give positive, finite spacings"));
    }
    let bound = max_point_count(domain, min_spacing);
    if bound > MAX_POINTS as f64 {
        return Err(format!(
            "a spacing of {min_spacing} allows up to {bound:.0} points, over tessera's limit of {MAX_POINTS}: give fewer points"
        ));
    }
    let (origin, size) = domain.extent();
    let cell = min_spacing / std::f32::consts::SQRT_2;
    let cells = ((size / cell).ceil() as usize).max(1);
    let periodic = domain == Domain::Periodic;
    let mut grid: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
    let cell_of = |p: Vec2| {
        let c = ((p - origin) / cell).floor();
        ((c.x.max(0.0) as usize).min(cells - 1), (c.y.max(0.0) as usize).min(cells - 1))
    };
    let reach = (max_spacing / cell).ceil() as isize;
    let mut points: Vec<Vec2> = Vec::new();
    let mut active: Vec<u32> = Vec::new();
    let mut sampler = Sampler::new(seed, 0x9075, 0);
    let far_enough = |points: &[Vec2], grid: &[Vec<u32>], p: Vec2| {
        let r = spacing(p);
        let (cx, cy) = cell_of(p);
        for dy in -reach..=reach {
            for dx in -reach..=reach {
                let (mut x, mut y) = (cx as isize + dx, cy as isize + dy);
                if periodic {
                    x = x.rem_euclid(cells as isize);
                    y = y.rem_euclid(cells as isize);
                } else if x < 0 || y < 0 || x >= cells as isize || y >= cells as isize {
                    continue;
                }
                for &q in &grid[y as usize * cells + x as usize] {
                    if domain.offset(points[q as usize], p).length_squared() < r * r {
                        return false;
                    }
                }
            }
        }
        true
    };
    let add = |p: Vec2, points: &mut Vec<Vec2>, grid: &mut Vec<Vec<u32>>, active: &mut Vec<u32>| {
        let (cx, cy) = cell_of(p);
        grid[cy * cells + cx].push(points.len() as u32);
        active.push(points.len() as u32);
        points.push(p);
    };
    let first = origin + sampler.next_2d() * size;
    add(first, &mut points, &mut grid, &mut active);
    while !active.is_empty() {
        let k = ((sampler.next_1d() * active.len() as f32) as usize).min(active.len() - 1);
        let centre = points[active[k] as usize];
        let r = spacing(centre);
        let mut placed = false;
        for _ in 0..CANDIDATES {
            let s = sampler.next_2d();
            let (radius, angle) = (r * (1.0 + s.x), std::f32::consts::TAU * s.y);
            let mut p = centre + Vec2::new(libm::cosf(angle), libm::sinf(angle)) * radius;
            if periodic {
                p -= p.floor();
            } else if p.cmplt(origin).any() || p.cmpge(origin + size).any() {
                continue;
            }
            if far_enough(&points, &grid, p) {
                add(p, &mut points, &mut grid, &mut active);
                placed = true;
                break;
            }
        }
        if !placed {
            active.swap_remove(k);
        }
    }
    Ok(points)
}

/// The spacing that gives about `count` points over the unit square (Bridson's distributions
/// hold about 0.7 / spacing^2 points per unit area).
pub fn spacing_for_count(count: u32) -> f32 {
    (0.7 / count.max(1) as f32).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_keep_their_distance_and_fill_the_domain() {
        for domain in [Domain::Periodic, Domain::Square { margin: 0.1 }] {
            let points = poisson_disk(domain, 0.05, 0.05, &|_| 0.05, 3).unwrap();
            for (i, a) in points.iter().enumerate() {
                for b in &points[i + 1..] {
                    assert!(domain.offset(*a, *b).length() >= 0.05 * 0.9999);
                }
            }
            // Maximal: no gap wider than two spacings (every candidate annulus was tried).
            let (origin, size) = domain.extent();
            let mut sampler = Sampler::new(1, 2, 3);
            for _ in 0..500 {
                let p = origin + sampler.next_2d() * size;
                let nearest = points.iter().map(|q| domain.offset(*q, p).length()).fold(f32::MAX, f32::min);
                assert!(nearest < 0.1, "a gap of {nearest} at {p}");
            }
            let expected = 0.7 / (0.05 * 0.05) * size * size;
            assert!((points.len() as f32 - expected).abs() < 0.15 * expected, "{} points", points.len());
        }
    }

    #[test]
    fn absurd_spacings_are_errors() {
        assert!(poisson_disk(Domain::Periodic, 0.0, 0.1, &|_| 0.1, 0).is_err());
        assert!(poisson_disk(Domain::Periodic, f32::NAN, 0.1, &|_| 0.1, 0).is_err());
        let msg = poisson_disk(Domain::Periodic, spacing_for_count(10_000_000), 0.1, &|_| 0.1, 0).unwrap_err();
        assert!(msg.contains("limit"), "{msg}");
    }
}
