//! The pavings of tiling and blending (paper 000 Sec. 3.1; DESIGN.md section 4): which tiles
//! cover a point, their centres c_i and their weights w_i (a partition of unity).
//! `shaders/tiling_blending/tiling.wgsl` is the GPU port of this file.

use crate::math::{floor, floor2};
use glam::{IVec2, Vec2};

/// Most tiles that cover one point (the square grid's four).
pub const MAX_TILES: usize = 4;

/// A paving of the UV plane by overlapping tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Tiling {
    /// k = 3: the triangle lattice of Heitz and Neyret 2018. A tile is the hexagon around a
    /// lattice vertex; its weight is that vertex's barycentric coordinate in the lattice
    /// triangle holding the point. The tile size is the lattice spacing.
    Hexagonal,
    /// k = 4: a square lattice. A tile is the square of side twice the spacing around a lattice
    /// vertex; its weight is the bilinear weight of the vertex with each coordinate passed
    /// through smoothstep 3t^2 - 2t^3, so that weights are C1 across cell edges.
    Square,
}

/// One tile covering a point: its lattice vertex, centre and weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    /// Lattice coordinates of the tile's vertex (what its shift is hashed from).
    pub vertex: IVec2,
    /// The tile's centre c_i in UV (its lattice vertex, which is also its barycentre).
    pub centre: Vec2,
    /// The paving's weight w_i(u) in [0, 1]; the weights of a point sum to 1.
    pub weight: f32,
}

/// sqrt(3) / 2: the height of the hexagonal lattice's rows in units of its spacing.
const ROW_HEIGHT: f32 = 0.866_025_4;

impl Tiling {
    /// Number of tiles covering each point (k).
    pub fn tiles_per_point(self) -> usize {
        match self {
            Tiling::Hexagonal => 3,
            Tiling::Square => 4,
        }
    }

    /// The corners of a tile's support (it is their convex hull) relative to its centre, for a
    /// unit lattice spacing: the hexagon of the six neighbouring vertices, or the square of
    /// half-side 1.
    pub fn support_corners(self) -> &'static [Vec2] {
        const HEXAGON: [Vec2; 6] = [
            Vec2::new(1.0, 0.0),
            Vec2::new(0.5, ROW_HEIGHT),
            Vec2::new(-0.5, ROW_HEIGHT),
            Vec2::new(-1.0, 0.0),
            Vec2::new(-0.5, -ROW_HEIGHT),
            Vec2::new(0.5, -ROW_HEIGHT),
        ];
        const SQUARE: [Vec2; 4] =
            [Vec2::new(1.0, 1.0), Vec2::new(-1.0, 1.0), Vec2::new(-1.0, -1.0), Vec2::new(1.0, -1.0)];
        match self {
            Tiling::Hexagonal => &HEXAGON,
            Tiling::Square => &SQUARE,
        }
    }

    /// The tiles covering `uv` for lattice spacing `size`; the first
    /// [`Tiling::tiles_per_point`] entries are valid.
    #[inline]
    pub fn tiles(self, uv: Vec2, size: f32) -> [Tile; MAX_TILES] {
        match self {
            Tiling::Hexagonal => hexagonal(uv, size),
            Tiling::Square => square(uv, size),
        }
    }
}

/// Position in UV of the hexagonal lattice vertex (i, j): i a1 + j a2 with a1 = (1, 0),
/// a2 = (1/2, sqrt 3 / 2), times the spacing.
#[inline]
fn hex_vertex(v: IVec2, size: f32) -> Vec2 {
    Vec2::new(v.x as f32 + 0.5 * v.y as f32, v.y as f32 * ROW_HEIGHT) * size
}

fn hexagonal(uv: Vec2, size: f32) -> [Tile; MAX_TILES] {
    // Lattice ("skewed") coordinates: uv / size = x a1 + y a2.
    let y = uv.y / (size * ROW_HEIGHT);
    let x = uv.x / size - 0.5 * y;
    let base = Vec2::new(floor(x), floor(y));
    let (fx, fy) = (x - base.x, y - base.y);
    let base = base.as_ivec2();
    let tile = |offset: IVec2, weight: f32| {
        let vertex = base + offset;
        Tile { vertex, centre: hex_vertex(vertex, size), weight }
    };
    let fz = 1.0 - fx - fy;
    let tiles = if fz > 0.0 {
        // Lower triangle (0,0), (1,0), (0,1).
        [tile(IVec2::ZERO, fz), tile(IVec2::X, fx), tile(IVec2::Y, fy)]
    } else {
        // Upper triangle (1,1), (0,1), (1,0).
        [tile(IVec2::ONE, -fz), tile(IVec2::Y, 1.0 - fx), tile(IVec2::X, 1.0 - fy)]
    };
    [tiles[0], tiles[1], tiles[2], Tile { vertex: IVec2::ZERO, centre: Vec2::ZERO, weight: 0.0 }]
}

fn square(uv: Vec2, size: f32) -> [Tile; MAX_TILES] {
    let p = uv / size;
    let base = floor2(p);
    let f = p - base;
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (smooth(f.x), smooth(f.y));
    let base = base.as_ivec2();
    let tile = |offset: IVec2, weight: f32| {
        let vertex = base + offset;
        Tile { vertex, centre: vertex.as_vec2() * size, weight }
    };
    [
        tile(IVec2::ZERO, (1.0 - sx) * (1.0 - sy)),
        tile(IVec2::X, sx * (1.0 - sy)),
        tile(IVec2::Y, (1.0 - sx) * sy),
        tile(IVec2::ONE, sx * sy),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> impl Iterator<Item = Vec2> {
        (0..2000).map(|i| {
            let t = i as f32;
            Vec2::new((t * 0.618_034).fract() * 7.0 - 3.0, (t * 0.754_877_7).fract() * 5.0 - 2.0)
        })
    }

    #[test]
    fn weights_are_a_partition_of_unity() {
        for tiling in [Tiling::Hexagonal, Tiling::Square] {
            for uv in points() {
                let tiles = tiling.tiles(uv, 0.3);
                let k = tiling.tiles_per_point();
                let sum: f32 = tiles[..k].iter().map(|t| t.weight).sum();
                assert!((sum - 1.0).abs() < 1e-5, "{tiling:?} at {uv}: {sum}");
                assert!(tiles[..k].iter().all(|t| (0.0..=1.0 + 1e-6).contains(&t.weight)));
                // Distinct tiles.
                for a in 0..k {
                    for b in a + 1..k {
                        assert_ne!(tiles[a].vertex, tiles[b].vertex);
                    }
                }
            }
        }
    }

    #[test]
    fn a_tile_weighs_one_at_its_centre_and_vanishes_at_its_border() {
        for tiling in [Tiling::Hexagonal, Tiling::Square] {
            for uv in points() {
                let size = 0.25;
                for t in tiling.tiles(uv, size).iter().take(tiling.tiles_per_point()) {
                    // Weight at the centre: 1 for this tile.
                    let at_centre = tiling.tiles(t.centre + Vec2::splat(1e-5), size);
                    let w = at_centre.iter().find(|o| o.vertex == t.vertex).map_or(0.0, |o| o.weight);
                    assert!(w > 0.999, "{tiling:?}: {w}");
                    // Every covering tile's centre is within the support radius.
                    let radius = tiling.support_corners().iter().map(|c| c.length()).fold(0.0, f32::max);
                    assert!((uv - t.centre).length() <= radius * size * 1.0001);
                }
            }
        }
    }

    #[test]
    fn weights_are_continuous() {
        // Walking in small steps, each vertex's weight changes little (tiles that appear or
        // disappear do so at weight 0).
        for tiling in [Tiling::Hexagonal, Tiling::Square] {
            let weight_of = |uv: Vec2, v: IVec2| {
                tiling
                    .tiles(uv, 0.2)
                    .iter()
                    .take(tiling.tiles_per_point())
                    .find(|t| t.vertex == v)
                    .map_or(0.0, |t| t.weight)
            };
            let step = Vec2::new(1.3e-4, 0.7e-4);
            let mut uv = Vec2::new(-0.31, 0.17);
            for _ in 0..20_000 {
                let next = uv + step;
                for t in tiling.tiles(uv, 0.2).iter().chain(tiling.tiles(next, 0.2).iter()) {
                    let dw = (weight_of(uv, t.vertex) - weight_of(next, t.vertex)).abs();
                    assert!(dw < 0.01, "{tiling:?} at {uv}: jump {dw}");
                }
                uv = next;
            }
        }
    }
}
