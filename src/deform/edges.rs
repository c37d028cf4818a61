//! The manifold edges of a UV-mapped mesh as the edge figures of `tessera analyze` see them:
//! each edge's two faces, whether the UV map cuts it, and the unfolding of the second face into
//! the first one's plane about the edge (the isometry that makes the two faces one flat strip).

use crate::geometry::{Topology, TriangleMesh};
use glam::{Vec2, Vec3};

/// One face of an edge: its corners' positions and UVs, its index, and the UVs it gives the
/// edge's two endpoints.
pub(super) struct EdgeFace {
    /// The face's index in the mesh.
    pub index: usize,
    /// Corner positions.
    pub x: [Vec3; 3],
    /// Corner UVs.
    pub u: [Vec2; 3],
    /// The UVs of the edge's endpoints on this face (lower welded vertex first).
    pub ends: [Vec2; 2],
}

/// A manifold edge with both faces valid in 3D.
pub(super) struct ManifoldEdge {
    /// The two faces, in the order of their half-edges.
    pub faces: [EdgeFace; 2],
    /// The faces give the endpoints different UVs (a UV cut).
    pub cut: bool,
    /// A cut where one endpoint keeps its UV (a pole fan or a dart: a UV singularity).
    pub singular: bool,
    /// Edge length.
    pub length: f32,
    /// Unit direction of the edge.
    pub tangent: Vec3,
    /// Unit in-plane directions across the edge, n x t, on the first and the second face.
    pub across: [Vec3; 2],
}

impl ManifoldEdge {
    /// Coordinates in the first face's plane (along the edge, across it) of a vector lying in
    /// face `side`'s plane, the second face unfolded into the first's.
    pub fn flat(&self, side: usize, w: Vec3) -> Vec2 {
        Vec2::new(w.dot(self.tangent), w.dot(self.across[side]))
    }
}

/// Every manifold edge of `mesh` (welded by position) whose faces have UVs for both endpoints
/// and non-degenerate normals. None without UVs.
pub(super) fn manifold_edges(mesh: &TriangleMesh) -> Option<Vec<ManifoldEdge>> {
    let uvs = mesh.uvs.as_ref()?;
    let (welded, points) = mesh.welded_vertices();
    let triangles: Vec<[u32; 3]> = mesh.indices.iter().map(|t| t.map(|i| welded[i as usize])).collect();
    let topology = Topology::new(&triangles);
    let face = |h: u32, [a, b]: [u32; 2]| {
        let index = topology.face_of(h as usize);
        let t = mesh.indices[index];
        let (x, u) = (t.map(|i| mesh.positions[i as usize]), t.map(|i| uvs[i as usize]));
        let at = |v: u32| (0..3).find(|&k| welded[t[k] as usize] == v).map(|k| u[k]);
        let ends = [at(a)?, at(b)?];
        Some(EdgeFace { index, x, u, ends })
    };
    let edges = (0..topology.edge_count()).filter_map(|e| {
        let &[h0, h1] = topology.halves(e) else { return None };
        let ends = topology.edge_vertices(e);
        let faces = [face(h0, ends)?, face(h1, ends)?];
        let (pa, pb) = (points[ends[0] as usize], points[ends[1] as usize]);
        let tangent = (pb - pa).try_normalize()?;
        let normal = |x: [Vec3; 3]| (x[1] - x[0]).cross(x[2] - x[0]).try_normalize();
        let across = [normal(faces[0].x)?.cross(tangent), normal(faces[1].x)?.cross(tangent)];
        let moved = [0, 1].map(|k| faces[0].ends[k].distance_squared(faces[1].ends[k]) > 1e-12);
        Some(ManifoldEdge {
            cut: moved[0] || moved[1],
            singular: moved[0] != moved[1],
            length: pa.distance(pb),
            tangent,
            across,
            faces,
        })
    });
    Some(edges.collect())
}
