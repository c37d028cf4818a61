//! Catmull-Clark subdivision of a quad mesh (Catmull and Clark 1978), with per-corner texture
//! coordinates interpolated bilinearly over each quad, as Maya does for paper 001's figures
//! (its footnote 1): a subdivided quad's corners read the parent quad's tile at its corner, its
//! edge midpoints and its centre, so the children of one quad still show one tile.
//!
//! Each quad splits into four, corner k's child being (vertex k, midpoint of edge k, face
//! centre, midpoint of edge k - 1), counter-clockwise as the parent. Positions: face points are
//! the corners' mean; edge points the mean of the edge's ends and its two face points (the
//! edge's midpoint on a boundary); vertex points (Q + 2R + (n - 3) P) / n inside (Q the mean
//! of the adjacent face points, R of the incident edges' midpoints, n the valence) and
//! (P_prev + 6 P + P_next) / 8 along a boundary (a cubic B-spline crease).

use super::{QuadMesh, Topology};
use glam::Vec3;

/// One round of Catmull-Clark subdivision of `mesh`, whose `topology` is given (manifold, as
/// [`QuadMesh::topology`] checks). New vertices: the old vertices' points, then one per edge,
/// then one per face.
pub fn catmull_clark(mesh: &QuadMesh, topology: &Topology) -> QuadMesh {
    let (nv, ne, nf) = (mesh.positions.len(), topology.edge_count(), mesh.quads.len());
    let face_points: Vec<Vec3> =
        mesh.quads.iter().map(|q| q.iter().map(|&v| mesh.positions[v as usize]).sum::<Vec3>() * 0.25).collect();
    let edge_points: Vec<Vec3> = (0..ne)
        .map(|e| {
            let [a, b] = topology.edge_vertices(e).map(|v| mesh.positions[v as usize]);
            match topology.halves(e) {
                &[h0, h1] => {
                    let (f0, f1) = (topology.face_of(h0 as usize), topology.face_of(h1 as usize));
                    (a + b + face_points[f0] + face_points[f1]) * 0.25
                }
                _ => (a + b) * 0.5,
            }
        })
        .collect();
    // Per vertex: the sums of adjacent face points and of incident edge midpoints, the valence,
    // and the boundary neighbours.
    let mut face_sum = vec![Vec3::ZERO; nv];
    let mut face_count = vec![0u32; nv];
    for (f, q) in mesh.quads.iter().enumerate() {
        for &v in q {
            face_sum[v as usize] += face_points[f];
            face_count[v as usize] += 1;
        }
    }
    let mut midpoint_sum = vec![Vec3::ZERO; nv];
    let mut valence = vec![0u32; nv];
    let mut boundary_sum = vec![Vec3::ZERO; nv];
    let mut boundary_count = vec![0u32; nv];
    for e in 0..ne {
        let [a, b] = topology.edge_vertices(e).map(|v| v as usize);
        let (pa, pb) = (mesh.positions[a], mesh.positions[b]);
        midpoint_sum[a] += (pa + pb) * 0.5;
        midpoint_sum[b] += (pa + pb) * 0.5;
        valence[a] += 1;
        valence[b] += 1;
        if topology.halves(e).len() == 1 {
            boundary_sum[a] += pb;
            boundary_sum[b] += pa;
            boundary_count[a] += 1;
            boundary_count[b] += 1;
        }
    }
    let vertex_points = (0..nv).map(|v| {
        let p = mesh.positions[v];
        match boundary_count[v] {
            0 if valence[v] >= 3 => {
                let n = valence[v] as f32;
                let q = face_sum[v] / face_count[v] as f32;
                let r = midpoint_sum[v] / n;
                (q + 2.0 * r + (n - 3.0) * p) / n
            }
            2 if valence[v] > 2 => (boundary_sum[v] + 6.0 * p) * 0.125,
            // Corners of the boundary (valence 2), unused vertices, and vertices where several
            // boundaries meet stay where they are.
            _ => p,
        }
    });
    let mut positions: Vec<Vec3> = Vec::with_capacity(nv + ne + nf);
    positions.extend(vertex_points);
    positions.extend(edge_points);
    positions.extend(face_points);

    let mut quads = Vec::with_capacity(4 * nf);
    let mut uvs = mesh.uvs.as_ref().map(|_| Vec::with_capacity(4 * nf));
    for (f, q) in mesh.quads.iter().enumerate() {
        let edge_vertex = |k: usize| (nv + topology.edge_of(4 * f + k % 4)) as u32;
        let face_vertex = (nv + ne + f) as u32;
        for (k, &corner) in q.iter().enumerate() {
            quads.push([corner, edge_vertex(k), face_vertex, edge_vertex(k + 3)]);
        }
        if let (Some(out), Some(parent)) = (&mut uvs, &mesh.uvs) {
            let c = parent[f];
            let centre = (c[0] + c[1] + c[2] + c[3]) * 0.25;
            let mid = |k: usize| (c[k % 4] + c[(k + 1) % 4]) * 0.5;
            for (k, &corner) in c.iter().enumerate() {
                out.push([corner, mid(k), centre, mid(k + 3)]);
            }
        }
    }
    QuadMesh { positions, quads, uvs, lines: Vec::new() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// The cube, valence 3 everywhere, outward-facing quads.
    pub(crate) fn cube() -> QuadMesh {
        let positions =
            (0..8).map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32) * 2.0 - 1.0);
        let quads = vec![[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        QuadMesh::new(positions.collect(), quads).unwrap()
    }

    /// Subdividing the cube: 24 quads, still closed and consistently oriented, with the
    /// textbook vertex and edge points worked by hand.
    #[test]
    fn a_cube_subdivides_into_a_closed_mesh_with_the_textbook_vertex_points() {
        let cube = cube();
        let (topology, report) = cube.topology().unwrap();
        assert_eq!(report.boundary_edges, 0);
        let once = catmull_clark(&cube, &topology);
        assert_eq!(once.quads.len(), 24);
        assert_eq!(once.positions.len(), 8 + 12 + 6);
        let (_, report) = once.topology().unwrap();
        assert_eq!((report.boundary_edges, report.interior_edges), (0, 48));
        // Corner (1, 1, 1): Q = mean of the face centres (1,0,0), (0,1,0), (0,0,1) = 1/3 on each
        // axis; R = mean of the midpoints (0,1,1), (1,0,1), (1,1,0) = 2/3; n = 3:
        // (Q + 2R + 0 P) / 3 = (1/3 + 4/3) / 3 = 5/9.
        assert!(once.positions[7].abs_diff_eq(Vec3::splat(5.0 / 9.0), 1e-6));
        // Edge (1,1,-1)-(1,1,1): the mean of its ends and of the centres (1,0,0) and (0,1,0).
        let e = topology.edge_of(
            (0..24)
                .find(|&h| {
                    let [a, b] = topology.endpoints(h);
                    a.min(b) == 3 && a.max(b) == 7
                })
                .unwrap(),
        );
        assert!(once.positions[8 + e].abs_diff_eq(Vec3::new(0.75, 0.75, 0.0), 1e-6));
    }

    #[test]
    fn corner_values_are_carried_bilinearly() {
        let mut cube = cube();
        let corners = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
        cube.uvs = Some(vec![corners; 6]);
        let (topology, _) = cube.topology().unwrap();
        let once = catmull_clark(&cube, &topology);
        let uvs = once.uvs.unwrap();
        // The first child of the first quad: its corner, the edge midpoint, the centre, the
        // previous edge's midpoint.
        assert_eq!(uvs[0], [Vec2::ZERO, Vec2::new(0.5, 0.0), Vec2::splat(0.5), Vec2::new(0.0, 0.5)]);
        assert_eq!(uvs[2][0], Vec2::ONE);
    }

    #[test]
    fn open_borders_follow_the_boundary_rule() {
        // A 2 x 1 strip: the middle boundary vertices move by (P_prev + 6 P + P_next) / 8.
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.5, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        let strip = QuadMesh::new(positions, vec![[0, 1, 4, 3], [1, 2, 5, 4]]).unwrap();
        let (topology, _) = strip.topology().unwrap();
        let once = catmull_clark(&strip, &topology);
        assert!(once.positions[1].abs_diff_eq(Vec3::new(1.0, 0.0625, 0.0), 1e-6));
        // Corners (two boundary edges, valence 2) are kept.
        assert_eq!(once.positions[0], Vec3::ZERO);
    }
}
