//! Mapping tiles to the quads of a mesh (paper 001 Sec. 3, Fig. 6; Sec. 6 for n conditions).
//!
//! AssignBoundaries gives every edge a condition k and a random bit i; its two half-edges get
//! the complementary types 2k + i and 2k + 1 - i (a boundary edge's single half-edge either).
//! A quad's four half-edge types, in its counter-clockwise order, are the name of its tile, and
//! AssignTextureCoordinates puts the quad's corners on that tile's corners
//! ([`TileLayout::corner_uv`]). Two quads sharing an edge walk it in opposite directions and
//! hold complementary types, which the tile image draws as one boundary seen from its two
//! sides: the texture is continuous across every edge, whatever the vertices' valences.

use super::layout::{TileLayout, TileName};
use crate::geometry::Topology;
use crate::sampling::mix64;
use glam::Vec2;

/// AssignBoundaries: the type of every half-edge of `topology` (indexed like its half-edges),
/// drawn per edge from `seed` with `conditions` conditions.
pub fn assign_boundaries(topology: &Topology, conditions: u32, seed: u64) -> Vec<u8> {
    let key = mix64(seed ^ 0x51_7e5a_11ed);
    let mut types = vec![0u8; topology.half_edge_count()];
    for e in 0..topology.edge_count() {
        let bits = mix64(key ^ (e as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let i = (bits & 1) as u8;
        let k = ((bits >> 1) % conditions as u64) as u8;
        for (side, &h) in topology.halves(e).iter().enumerate().take(2) {
            types[h as usize] = 2 * k + if side == 0 { i } else { 1 - i };
        }
    }
    types
}

/// The tile of every face: its half-edges' types in counter-clockwise order.
pub fn assign_tiles(topology: &Topology, types: &[u8]) -> Vec<TileName> {
    let faces = topology.half_edge_count() / 4;
    (0..faces).map(|f| TileName(std::array::from_fn(|k| types[4 * f + k]))).collect()
}

/// AssignTextureCoordinates: the texture coordinates of each quad's corners, counter-clockwise
/// from its first corner.
pub fn texture_coordinates(layout: &TileLayout, tiles: &[TileName]) -> Vec<[Vec2; 4]> {
    tiles.iter().map(|&name| std::array::from_fn(|corner| layout.corner_uv(name, corner))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tiles::layout::complementary;

    /// A torus of 40 x 24 quads: every edge manifold, every vertex of valence 4.
    fn torus_quads(m: u32, n: u32) -> Vec<[u32; 4]> {
        let id = |i: u32, j: u32| (j % n) * m + (i % m);
        (0..n).flat_map(|j| (0..m).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])).collect()
    }

    #[test]
    fn half_edges_of_an_edge_get_complementary_types() {
        for conditions in [1, 2, 3] {
            let quads = torus_quads(40, 24);
            let topology = Topology::new(&quads);
            let types = assign_boundaries(&topology, conditions, 7);
            for e in 0..topology.edge_count() {
                let &[a, b] = topology.halves(e) else { panic!("a torus is closed") };
                assert_eq!(types[a as usize], complementary(types[b as usize]));
                assert!(types[a as usize] < 2 * conditions as u8);
            }
        }
    }

    /// Aperiodicity: every tile is used, about equally (a chi-square test of uniformity over
    /// the 16 tiles), neighbours are not forced to be equal, and another seed gives another
    /// assignment.
    #[test]
    fn every_tile_is_used_and_neighbours_are_free() {
        let quads = torus_quads(80, 50);
        let topology = Topology::new(&quads);
        let tiles = assign_tiles(&topology, &assign_boundaries(&topology, 1, 3));
        let layout = TileLayout::new(1, 16).unwrap();
        let mut counts = [0f64; 16];
        for &t in &tiles {
            counts[layout.index_of(t)] += 1.0;
        }
        let expected = tiles.len() as f64 / 16.0;
        let chi2: f64 = counts.iter().map(|c| (c - expected).powi(2) / expected).sum();
        // 15 degrees of freedom: the 0.999 quantile is 37.7. (The 4 edges of a quad carry
        // independent bits, so the tile is uniform.)
        assert!(chi2 < 37.7, "chi2 {chi2}, counts {counts:?}");
        // Two quads across an edge hold the same tile about as often as two random tiles do
        // (1/16), never always.
        let mut same = 0;
        for e in 0..topology.edge_count() {
            let h = topology.halves(e);
            same += usize::from(tiles[topology.face_of(h[0] as usize)] == tiles[topology.face_of(h[1] as usize)]);
        }
        let fraction = same as f64 / topology.edge_count() as f64;
        assert!(fraction < 0.1, "{fraction} of neighbours share their tile");
        let other = assign_tiles(&topology, &assign_boundaries(&topology, 1, 4));
        let changed = tiles.iter().zip(&other).filter(|(a, b)| a != b).count();
        assert!(changed > tiles.len() / 2);
    }
}
