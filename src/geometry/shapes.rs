//! Procedural meshes that scenes can use without a mesh file. `rectangle` and `uv_sphere` match
//! Mitsuba 3's `rectangle` and the sphere asset of `../shared/tools/mitsuba` vertex for vertex,
//! so that exported scenes are identical.

use super::TriangleMesh;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Mitsuba's `rectangle`: the square [-1, 1]^2 in the plane z = 0, front face towards +z.
///
/// Mitsuba gives it uv = ((x + 1) / 2, (y + 1) / 2) in *its* convention, where uv (0, 0) is a
/// bitmap's top-left texel (only its OBJ loader flips v). In tessera's convention (origin at the
/// bottom-left, DESIGN.md section 3) the same lookups are uv = ((x + 1) / 2, (1 - y) / 2): the
/// image's top-left corner lies at (-1, -1), as in Mitsuba.
pub fn rectangle() -> TriangleMesh {
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    TriangleMesh {
        positions: corners.iter().map(|&(x, y)| Vec3::new(x, y, 0.0)).collect(),
        normals: Some(vec![Vec3::Z; 4]),
        uvs: Some(corners.iter().map(|&(x, y)| Vec2::new((x + 1.0) / 2.0, (1.0 - y) / 2.0)).collect()),
        indices: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// The cube [-1, 1]^3 (the extent of Mitsuba's `cube`) with outward faces, 4 vertices per face
/// (flat normals), and each face's uv covering [0, 1]^2.
pub fn cube() -> TriangleMesh {
    let (mut positions, mut normals, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            // Tangents chosen so that (u_dir x v_dir) = n: counter-clockwise seen from outside.
            let u_dir = Vec3::AXES[(axis + 1) % 3] * sign;
            let v_dir = n.cross(u_dir);
            let base = positions.len() as u32;
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                positions.push(n + u_dir * (2.0 * u - 1.0) + v_dir * (2.0 * v - 1.0));
                normals.push(n);
                uvs.push(Vec2::new(u, v));
            }
            indices.push([base, base + 1, base + 2]);
            indices.push([base, base + 2, base + 3]);
        }
    }
    TriangleMesh { positions, normals: Some(normals), uvs: Some(uvs), indices }
}

/// The UV sphere of `../shared/tools/mitsuba/gen_assets.py`: radius 1, poles on the y axis,
/// `segments` x `rings` quads, a seam at phi = 0 (duplicated column u = 0 / u = 1), one pole
/// vertex per segment (u = (i + 0.5) / segments), no degenerate triangles.
///
/// Position `(sin th cos ph, cos th, -sin th sin ph)`, uv `(ph / 2 pi, 1 - th / pi)`, normal =
/// position. dP/du points east (+phi), dP/dv north.
pub fn uv_sphere(segments: u32, rings: u32) -> TriangleMesh {
    assert!(segments >= 3 && rings >= 2, "uv_sphere needs at least 3 segments and 2 rings");
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    // Index of vertex (ring j, column i); pole rings have `segments` columns, others `segments + 1`.
    let row_start = |j: u32| -> u32 { if j == 0 { 0 } else { segments + (j - 1) * (segments + 1) } };
    for j in 0..=rings {
        let theta = PI * j as f32 / rings as f32;
        let pole = j == 0 || j == rings;
        let columns = if pole { segments } else { segments + 1 };
        for i in 0..columns {
            let u = if pole { (i as f32 + 0.5) / segments as f32 } else { i as f32 / segments as f32 };
            let phi = 2.0 * PI * u;
            let p = if j == 0 {
                Vec3::Y
            } else if j == rings {
                -Vec3::Y
            } else {
                let (st, ct) = theta.sin_cos();
                Vec3::new(st * phi.cos(), ct, -st * phi.sin())
            };
            positions.push(p);
            uvs.push(Vec2::new(u, 1.0 - j as f32 / rings as f32));
        }
    }
    let mut indices = Vec::new();
    for j in 0..rings {
        for i in 0..segments {
            let a = row_start(j) + i; // north-west
            let b = row_start(j + 1) + i; // south-west
            let c = row_start(j + 1) + i + 1; // south-east (not on the south pole row)
            let d = row_start(j) + i + 1; // north-east (not on the north pole row)
            if j == rings - 1 {
                indices.push([a, b, d]);
            } else {
                indices.push([a, b, c]);
                if j != 0 {
                    indices.push([a, c, d]);
                }
            }
        }
    }
    TriangleMesh { normals: Some(positions.clone()), positions, uvs: Some(uvs), indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn total_area(m: &TriangleMesh) -> f32 {
        (0..m.triangle_count()).map(|i| m.triangle_area(i)).sum()
    }

    fn assert_outward(m: &TriangleMesh) {
        for i in 0..m.triangle_count() {
            let [a, b, c] = m.triangle(i);
            let ng = (b - a).cross(c - a);
            let centre = (a + b + c) / 3.0;
            assert!(ng.dot(centre) > 0.0, "triangle {i} faces inwards");
        }
    }

    #[test]
    fn uv_sphere_matches_mitsuba_asset() {
        // gen_assets.py: 2143 vertices, 3968 triangles; Mitsuba's area 12.5412.
        let m = uv_sphere(64, 32);
        assert_eq!(m.positions.len(), 2143);
        assert_eq!(m.triangle_count(), 3968);
        assert!((total_area(&m) - 12.5412).abs() < 1e-3, "{}", total_area(&m));
        assert_outward(&m);
        let mut m = m;
        assert_eq!(m.validate().unwrap().degenerate_triangles, 0);
    }

    #[test]
    fn cube_faces_outward_with_area_24() {
        let m = cube();
        assert_outward(&m);
        assert!((total_area(&m) - 24.0).abs() < 1e-4);
    }

    #[test]
    fn rectangle_lookups_match_mitsuba() {
        // Mitsuba's uv (u_m, v_m) = ((x + 1) / 2, (y + 1) / 2) reads the image row v_m H from the
        // top; tessera's (u, v) reads row (1 - v) H from the top. The rows must agree.
        let m = rectangle();
        for (p, uv) in m.positions.iter().zip(m.uvs.as_ref().unwrap()) {
            let mitsuba_row_from_top = (p.y + 1.0) / 2.0;
            assert_eq!(uv.x, (p.x + 1.0) / 2.0);
            assert_eq!(1.0 - uv.y, mitsuba_row_from_top);
        }
        let [a, b, c] = m.triangle(0);
        assert!((b - a).cross(c - a).z > 0.0);
    }
}
