//! Distances along a mesh from source points, for the geodesic orientation field of paper 000
//! Sec. 6.3 ("the gradient of the geodesic distance from certain vertices").
//!
//! The distance is computed by fast marching on the triangles (Kimmel and Sethian 1998, without
//! their splitting of obtuse triangles): vertices are settled in order of distance as in
//! Dijkstra's algorithm, and a vertex is reached not only along edges but across each triangle
//! from two settled corners, by unfolding the triangle and a virtual source into the plane. Edge
//! paths alone would bias the gradient's direction by tens of degrees on a regular grid. Vertices
//! are welded by position first (loaders split them at UV seams, which must not cut the surface).

use crate::geometry::TriangleMesh;
use glam::Vec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A heap entry ordered by smallest distance first.
#[derive(PartialEq)]
struct Entry(f32, u32);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Distance over the surface of every vertex of `mesh` from the vertices nearest to `sources`
/// (infinite where unreachable).
pub fn surface_distances(mesh: &TriangleMesh, sources: &[Vec3]) -> Vec<f32> {
    let (welded, points) = mesh.welded_vertices();
    let triangles: Vec<[u32; 3]> = mesh.indices.iter().map(|t| t.map(|i| welded[i as usize])).collect();
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); points.len()];
    for (k, t) in triangles.iter().enumerate() {
        for &v in t {
            incident[v as usize].push(k as u32);
        }
    }
    let mut distance = vec![f32::INFINITY; points.len()];
    let mut settled = vec![false; points.len()];
    let mut heap = BinaryHeap::new();
    for s in sources {
        let nearest = (0..points.len())
            .min_by(|&a, &b| points[a].distance_squared(*s).total_cmp(&points[b].distance_squared(*s)));
        if let Some(v) = nearest {
            distance[v] = 0.0;
            heap.push(Entry(0.0, v as u32));
        }
    }
    while let Some(Entry(d, v)) = heap.pop() {
        if settled[v as usize] || d > distance[v as usize] {
            continue;
        }
        settled[v as usize] = true;
        for &t in &incident[v as usize] {
            let t = triangles[t as usize];
            for &c in &t {
                if settled[c as usize] {
                    continue;
                }
                let pc = points[c as usize];
                let mut best = d + points[v as usize].distance(pc);
                // Across the triangle from v and its third corner w, if w is settled too.
                if let Some(&w) = t.iter().find(|&&w| w != v && w != c)
                    && settled[w as usize]
                {
                    let (pv, pw) = (points[v as usize], points[w as usize]);
                    if let Some(across) = planar_update(pv, pw, pc, d, distance[w as usize]) {
                        best = best.min(across);
                    }
                }
                if best < distance[c as usize] {
                    distance[c as usize] = best;
                    heap.push(Entry(best, c));
                }
            }
        }
    }
    welded.iter().map(|&w| distance[w as usize]).collect()
}

/// The distance at `c` of a front that reaches `a` at `da` and `b` at `db`, from a virtual point
/// source unfolded into the triangle's plane on the far side of ab; None when the front would
/// not cross the edge ab on its way to `c` (edge paths then decide).
fn planar_update(a: Vec3, b: Vec3, c: Vec3, da: f32, db: f32) -> Option<f32> {
    let ab = b - a;
    let len = ab.length();
    if !(len > 0.0) {
        return None;
    }
    let x_axis = ab / len;
    let ac = c - a;
    let (cx, cy) = (ac.dot(x_axis), (ac - x_axis * ac.dot(x_axis)).length());
    // The virtual source S: |S| = da, |S - (len, 0)| = db, below the x axis.
    let sx = (da * da - db * db + len * len) / (2.0 * len);
    let sy2 = da * da - sx * sx;
    if !(sy2 >= 0.0) || !(cy > 0.0) {
        return None;
    }
    let sy = -sy2.sqrt();
    // Where the path from S to C crosses the x axis: it must be on the edge.
    let t = -sy / (cy - sy);
    let x = sx + t * (cx - sx);
    (0.0..=len).contains(&x).then(|| ((cx - sx).powi(2) + (cy - sy).powi(2)).sqrt())
}

/// The gradient over a triangle of the linear interpolant of `d` at its corners `x`.
pub fn triangle_gradient(x: [Vec3; 3], d: [f32; 3]) -> Option<Vec3> {
    let n = (x[1] - x[0]).cross(x[2] - x[0]);
    let area2 = n.length_squared();
    if !(area2 > 0.0) || !d.iter().all(|v| v.is_finite()) {
        return None;
    }
    // grad phi_i = n x (x_{i+2} - x_{i+1}) / |n|^2 for the hat function of corner i.
    let g = (0..3).fold(Vec3::ZERO, |g, i| g + n.cross(x[(i + 2) % 3] - x[(i + 1) % 3]) * d[i]) / area2;
    g.is_finite().then_some(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_of_a_linear_function_is_exact() {
        let x = [Vec3::new(0.1, 0.0, 0.2), Vec3::new(1.0, 0.3, 0.0), Vec3::new(0.2, 1.0, 0.5)];
        let a = Vec3::new(0.3, -0.7, 0.2);
        let n = (x[1] - x[0]).cross(x[2] - x[0]).normalize();
        let g = triangle_gradient(x, x.map(|p| a.dot(p) + 4.0)).unwrap();
        // The gradient of a linear function restricted to the plane: a without its normal part.
        assert!(g.distance(a - n * n.dot(a)) < 1e-5, "{g}");
    }

    #[test]
    fn fast_marching_distances_on_a_plane_are_euclidean() {
        // A 20 x 20 grid of right triangles on the plane: distances from a corner must be close
        // to Euclidean (edge paths alone overestimate the diagonal by up to 8% here).
        let n = 20;
        let mut mesh = TriangleMesh::default();
        for j in 0..=n {
            for i in 0..=n {
                mesh.positions.push(Vec3::new(i as f32, j as f32, 0.0) / n as f32);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = (j * (n + 1) + i) as u32;
                let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32 + 2);
                mesh.indices.push([a, b, d]);
                mesh.indices.push([a, d, c]);
            }
        }
        let source = Vec3::new(0.0, 0.5, 0.0);
        let d = surface_distances(&mesh, &[source]);
        for (p, dist) in mesh.positions.iter().zip(&d) {
            let exact = p.distance(source);
            assert!((dist - exact).abs() < 0.02 + 0.02 * exact, "at {p}: {dist} vs {exact}");
        }
    }

    #[test]
    fn distances_cross_uv_seams() {
        // Two triangles sharing an edge whose vertices are duplicated (as at a UV seam).
        let mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)],
            normals: None,
            uvs: None,
            indices: vec![[0, 1, 2], [3, 5, 4]],
        };
        let d = surface_distances(&mesh, &[Vec3::ZERO]);
        assert_eq!(d[0], 0.0);
        // Across the flat unit square, through the seam: the diagonal.
        assert!((d[5] - std::f32::consts::SQRT_2).abs() < 1e-6, "{d:?}");
    }
}
