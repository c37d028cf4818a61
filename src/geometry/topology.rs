//! Edge adjacency of a polygon mesh whose faces all have the same number of corners
//! (triangles for the UV cuts of paper 000, quads for the tiles of paper 001).
//!
//! Half-edge `h = N f + k` runs along face `f` from its corner `k` to corner `k + 1` (mod N).
//! An edge is the set of half-edges joining the same two vertices, in either direction: one
//! half-edge on a boundary, two on a manifold edge, more on a non-manifold one. Edges are
//! numbered in the order of their first half-edge, so the numbering follows the faces' order.

/// The edges of a mesh and the half-edges along each.
#[derive(Clone, Debug)]
pub struct Topology {
    /// Corners per face.
    face_size: usize,
    /// Start vertex of each half-edge.
    origins: Vec<u32>,
    /// Edge of each half-edge.
    edge_of_half: Vec<u32>,
    /// Half-edges of edge `e`: `edge_halves[edge_start[e]..edge_start[e + 1]]`, in increasing order.
    edge_start: Vec<u32>,
    edge_halves: Vec<u32>,
}

impl Topology {
    /// The edges of `faces` (vertex ids, corners in order around each face). A face that
    /// repeats a vertex gives a half-edge from a vertex to itself: [`Topology::degenerate`]
    /// finds them.
    ///
    /// Half-edges are grouped by their lower vertex (a counting sort), then matched by their
    /// upper one within each group: linear time, no hashing, a few bytes per half-edge.
    pub fn new<const N: usize>(faces: &[[u32; N]]) -> Self {
        assert!(N >= 3, "faces have at least three corners");
        let halves = faces.len() * N;
        assert!(halves < u32::MAX as usize, "at most 2^32 - 1 half-edges");
        let origins: Vec<u32> = faces.iter().flatten().copied().collect();
        let target = |h: usize| faces[h / N][(h % N + 1) % N];
        let vertex_count = origins.iter().map(|&v| v as usize + 1).max().unwrap_or(0);
        // Counting sort of the half-edges by their lower endpoint.
        let mut group_start = vec![0u32; vertex_count + 1];
        for h in 0..halves {
            group_start[origins[h].min(target(h)) as usize + 1] += 1;
        }
        for v in 0..vertex_count {
            group_start[v + 1] += group_start[v];
        }
        let mut fill = group_start.clone();
        let mut grouped = vec![0u32; halves];
        for h in 0..halves {
            let slot = &mut fill[origins[h].min(target(h)) as usize];
            grouped[*slot as usize] = h as u32;
            *slot += 1;
        }
        // Within a group, half-edges with the same upper endpoint form an edge; its first
        // (lowest) half-edge represents it.
        let mut representative = vec![0u32; halves];
        for v in 0..vertex_count {
            let group = &grouped[group_start[v] as usize..group_start[v + 1] as usize];
            for (i, &h) in group.iter().enumerate() {
                let upper = origins[h as usize].max(target(h as usize));
                let first = group[..i]
                    .iter()
                    .copied()
                    .find(|&g| origins[g as usize].max(target(g as usize)) == upper)
                    .map_or(h, |g| representative[g as usize]);
                representative[h as usize] = first;
            }
        }
        // Number the edges in the order of their representatives; list each edge's half-edges.
        let mut edge_of_half = vec![u32::MAX; halves];
        let mut counts: Vec<u32> = Vec::new();
        for h in 0..halves {
            let r = representative[h] as usize;
            let e = if r == h {
                counts.push(0);
                (counts.len() - 1) as u32
            } else {
                edge_of_half[r]
            };
            edge_of_half[h] = e;
            counts[e as usize] += 1;
        }
        let mut edge_start = vec![0u32; counts.len() + 1];
        for (e, c) in counts.iter().enumerate() {
            edge_start[e + 1] = edge_start[e] + c;
        }
        let mut fill = edge_start.clone();
        let mut edge_halves = vec![0u32; halves];
        for (h, &e) in edge_of_half.iter().enumerate() {
            edge_halves[fill[e as usize] as usize] = h as u32;
            fill[e as usize] += 1;
        }
        Topology { face_size: N, origins, edge_of_half, edge_start, edge_halves }
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        self.edge_start.len() - 1
    }

    /// Number of half-edges (faces times corners).
    pub fn half_edge_count(&self) -> usize {
        self.origins.len()
    }

    /// The half-edges of `edge`, in increasing order (so in the order of their faces).
    #[inline]
    pub fn halves(&self, edge: usize) -> &[u32] {
        &self.edge_halves[self.edge_start[edge] as usize..self.edge_start[edge + 1] as usize]
    }

    /// The edge a half-edge lies on.
    #[inline]
    pub fn edge_of(&self, half: usize) -> usize {
        self.edge_of_half[half] as usize
    }

    /// The face of a half-edge.
    #[inline]
    pub fn face_of(&self, half: usize) -> usize {
        half / self.face_size
    }

    /// Which side of its face a half-edge is (0 from corner 0 to corner 1, ...).
    #[inline]
    pub fn side_of(&self, half: usize) -> usize {
        half % self.face_size
    }

    /// Start and end vertex of a half-edge.
    #[inline]
    pub fn endpoints(&self, half: usize) -> [u32; 2] {
        let f = half - half % self.face_size;
        let next = f + (half % self.face_size + 1) % self.face_size;
        [self.origins[half], self.origins[next]]
    }

    /// The vertices of `edge`, lower id first.
    pub fn edge_vertices(&self, edge: usize) -> [u32; 2] {
        let [a, b] = self.endpoints(self.halves(edge)[0] as usize);
        [a.min(b), a.max(b)]
    }

    /// The other half-edge of a manifold edge; None on a boundary or a non-manifold edge.
    #[inline]
    pub fn twin(&self, half: usize) -> Option<usize> {
        match self.halves(self.edge_of(half)) {
            [a, b] => Some(if *a as usize == half { *b as usize } else { *a as usize }),
            _ => None,
        }
    }

    /// Edges with one half-edge: the mesh's boundary.
    pub fn boundary_edges(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.edge_count()).filter(|&e| self.halves(e).len() == 1)
    }

    /// Edges with more than two half-edges.
    pub fn non_manifold_edges(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.edge_count()).filter(|&e| self.halves(e).len() > 2)
    }

    /// Manifold edges whose two faces run along them in the same direction: the faces disagree
    /// on the surface's orientation there.
    pub fn misoriented_edges(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.edge_count()).filter(|&e| match self.halves(e) {
            [a, b] => self.endpoints(*a as usize) == self.endpoints(*b as usize),
            _ => false,
        })
    }

    /// Half-edges from a vertex to itself (a face that repeats a vertex).
    pub fn degenerate(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.half_edge_count()).filter(|&h| {
            let [a, b] = self.endpoints(h);
            a == b
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two quads sharing the edge 1-2, and a third hanging on the same edge (non-manifold).
    #[test]
    fn edges_boundaries_twins_and_non_manifold_edges() {
        //  3---2---5
        //  |   |   |
        //  0---1---4
        let quads = [[0u32, 1, 2, 3], [1, 4, 5, 2]];
        let t = Topology::new(&quads);
        assert_eq!(t.edge_count(), 7);
        assert_eq!(t.boundary_edges().count(), 6);
        // Half-edge 1 (face 0, side 1: 1 -> 2) and half-edge 7 (face 1, side 3: 2 -> 1).
        assert_eq!(t.twin(1), Some(7));
        assert_eq!(t.twin(7), Some(1));
        assert_eq!(t.twin(0), None);
        assert_eq!(t.endpoints(7), [2, 1]);
        assert_eq!(t.edge_vertices(t.edge_of(7)), [1, 2]);
        assert_eq!((t.face_of(7), t.side_of(7)), (1, 3));
        // Edges are numbered in the order of their first half-edge.
        assert_eq!((0..8).map(|h| t.edge_of(h)).collect::<Vec<_>>(), [0, 1, 2, 3, 4, 5, 6, 1]);
        assert_eq!(t.misoriented_edges().count(), 0);

        let t = Topology::new(&[[0u32, 1, 2, 3], [1, 4, 5, 2], [2, 6, 7, 1]]);
        assert_eq!(t.non_manifold_edges().collect::<Vec<_>>(), [1]);
        assert_eq!(t.halves(1), [1, 7, 11]);
        assert_eq!(t.twin(1), None);

        // The second quad wound the other way: its edge 1-2 runs 1 -> 2 as the first's does.
        let t = Topology::new(&[[0u32, 1, 2, 3], [2, 5, 4, 1]]);
        assert_eq!(t.misoriented_edges().collect::<Vec<_>>(), [1]);
        let t = Topology::new(&[[0u32, 1, 1, 3]]);
        assert_eq!(t.degenerate().collect::<Vec<_>>(), [1]);
    }

    /// Against a plain hash map of vertex pairs on a random triangle soup.
    #[test]
    fn matches_a_hash_map_of_vertex_pairs() {
        let mut sampler = crate::sampling::Sampler::new(5, 0, 0);
        let triangles: Vec<[u32; 3]> =
            (0..3000).map(|_| std::array::from_fn(|_| (sampler.next_1d() * 400.0) as u32)).collect();
        let t = Topology::new(&triangles);
        let mut pairs: std::collections::HashMap<(u32, u32), Vec<u32>> = Default::default();
        for (f, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                pairs.entry((a.min(b), a.max(b))).or_default().push((3 * f + k) as u32);
            }
        }
        assert_eq!(t.edge_count(), pairs.len());
        for e in 0..t.edge_count() {
            let [a, b] = t.edge_vertices(e);
            assert_eq!(t.halves(e), pairs[&(a, b)].as_slice());
        }
    }
}
