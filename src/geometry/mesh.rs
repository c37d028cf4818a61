//! Indexed triangle meshes, as loaded from OBJ/glTF or built procedurally.

use glam::{Mat3, Mat4, Vec2, Vec3};

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// Smallest corner.
    pub min: Vec3,
    /// Largest corner.
    pub max: Vec3,
}

impl Bounds {
    /// The empty box (min = +inf, max = -inf), the identity of [`Bounds::union`].
    pub const EMPTY: Bounds = Bounds { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// Grow to contain `p`.
    pub fn include(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    /// The smallest box containing both.
    pub fn union(self, other: Bounds) -> Bounds {
        Bounds { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// True when nothing was included.
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }

    /// Centre and radius of the bounding sphere through the box corners.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        if self.is_empty() {
            return (Vec3::ZERO, 0.0);
        }
        let c = (self.min + self.max) * 0.5;
        (c, (self.max - c).length())
    }
}

/// A triangle mesh with optional per-vertex normals and texture coordinates.
///
/// Texture coordinates follow DESIGN.md section 3: origin at the bottom-left, v up (OBJ `vt`);
/// loaders convert other conventions (glTF's top-left origin) on load.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    /// Vertex positions (world space once the scene is loaded).
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals, if the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, if the file has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Vertex indices, three per triangle, counter-clockwise seen from the front.
    pub indices: Vec<[u32; 3]>,
}

/// Positions joined where they are bit for bit equal: for each position the id of its distinct
/// position, and the distinct positions in order of first appearance.
pub fn weld_positions(positions: &[Vec3]) -> (Vec<u32>, Vec<Vec3>) {
    let mut ids: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::new();
    let mut points = Vec::new();
    let welded = positions
        .iter()
        .map(|p| {
            *ids.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
                points.push(*p);
                (points.len() - 1) as u32
            })
        })
        .collect();
    (welded, points)
}

/// What [`TriangleMesh::validate`] removed or found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MeshCleanup {
    /// Triangles of zero area (or with a repeated vertex) that were dropped.
    pub degenerate_triangles: usize,
}

impl TriangleMesh {
    /// Vertices welded by exact position: for each vertex the id of its position, and the
    /// distinct positions. Loaders split vertices at UV seams and normal creases; welding joins
    /// the surface back (geodesic distances, UV cuts).
    pub fn welded_vertices(&self) -> (Vec<u32>, Vec<Vec3>) {
        weld_positions(&self.positions)
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The three vertex positions of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let [a, b, c] = self.indices[i];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// Area of triangle `i`.
    pub fn triangle_area(&self, i: usize) -> f32 {
        let [a, b, c] = self.triangle(i);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Bounding box of all vertices.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for &p in &self.positions {
            b.include(p);
        }
        b
    }

    /// Apply an affine transform: positions by `m`, normals by its inverse transpose.
    pub fn transform(&mut self, m: &Mat4) {
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        if let Some(normals) = &mut self.normals {
            let nm = Mat3::from_mat4(*m).inverse().transpose();
            for n in normals {
                *n = (nm * *n).normalize_or_zero();
            }
        }
        // A mirroring transform turns the winding around; restore counter-clockwise fronts.
        if m.determinant() < 0.0 {
            for t in &mut self.indices {
                t.swap(1, 2);
            }
        }
    }

    /// Turn the mesh inside out: reverse the winding and negate the normals (Mitsuba's
    /// `flip_normals`), so that the front faces the other way.
    pub fn flip_normals(&mut self) {
        for t in &mut self.indices {
            t.swap(1, 2);
        }
        if let Some(normals) = &mut self.normals {
            normals.iter_mut().for_each(|n| *n = -*n);
        }
    }

    /// Check the mesh for data no consumer can use, as every loader does before handing a
    /// mesh on. Errors (returned as a message for the caller to attach the file name to):
    /// non-finite positions, normals or texture coordinates, indices out of range, attribute
    /// arrays whose length differs from the vertex count, more triangles than
    /// [`crate::limits::MAX_TRIANGLES`].
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        if self.indices.len() as u64 > crate::limits::MAX_TRIANGLES {
            let limit = crate::limits::MAX_TRIANGLES;
            return Err(crate::limits::exceeded("the triangle count", self.indices.len(), limit));
        }
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {i} has a non-finite position {}", self.positions[i]));
        }
        if let Some(normals) = &self.normals {
            if normals.len() != n {
                return Err(format!("{} normals for {n} vertices", normals.len()));
            }
            if let Some(i) = normals.iter().position(|v| !v.is_finite()) {
                return Err(format!("vertex {i} has a non-finite normal {}", normals[i]));
            }
        }
        if let Some(uvs) = &self.uvs {
            if uvs.len() != n {
                return Err(format!("{} texture coordinates for {n} vertices", uvs.len()));
            }
            if let Some(i) = uvs.iter().position(|v| !v.is_finite()) {
                return Err(format!("vertex {i} has non-finite texture coordinates {}", uvs[i]));
            }
        }
        for (i, tri) in self.indices.iter().enumerate() {
            if let Some(&bad) = tri.iter().find(|&&v| v as usize >= n) {
                return Err(format!("triangle {i} refers to vertex {bad}, but there are only {n} vertices"));
            }
        }
        Ok(())
    }

    /// [`TriangleMesh::check`] the mesh and drop its degenerate triangles, for rendering: an
    /// error also for a mesh with no triangle left. Zero-area triangles are removed and
    /// counted: they cannot be hit and have no normal.
    pub fn validate(&mut self) -> Result<MeshCleanup, String> {
        self.check()?;
        let before = self.indices.len();
        let positions = &self.positions;
        self.indices.retain(|&[a, b, c]| {
            let (a, b, c) = (positions[a as usize], positions[b as usize], positions[c as usize]);
            let area2 = (b - a).cross(c - a).length_squared();
            area2 > 0.0 && area2.is_finite()
        });
        let cleanup = MeshCleanup { degenerate_triangles: before - self.indices.len() };
        if self.indices.is_empty() {
            return Err(if before == 0 {
                "the mesh has no triangles".to_string()
            } else {
                format!("all {before} triangles have zero area (or one beyond the range of 32-bit floats)")
            });
        }
        Ok(cleanup)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> TriangleMesh {
        TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            normals: None,
            uvs: None,
            indices: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn mesh_validate_drops_zero_area_triangles() {
        let mut m = quad();
        m.indices.push([0, 0, 1]);
        m.indices.push([0, 1, 1]);
        assert_eq!(m.validate().unwrap().degenerate_triangles, 2);
        assert_eq!(m.triangle_count(), 2);
    }

    #[test]
    fn mesh_validate_rejects_bad_data() {
        let mut m = quad();
        m.positions[2].y = f32::NAN;
        assert!(m.validate().unwrap_err().contains("non-finite position"));
        let mut m = quad();
        m.indices.push([0, 1, 7]);
        assert!(m.validate().unwrap_err().contains("vertex 7"));
        let mut m = quad();
        m.indices = vec![[0, 1, 1]];
        assert!(m.validate().unwrap_err().contains("zero area"));
        let mut m = quad();
        m.indices.clear();
        assert!(m.validate().unwrap_err().contains("no triangles"));
    }

    #[test]
    fn mesh_mirror_transform_keeps_front_faces() {
        let mut m = quad();
        m.normals = Some(vec![Vec3::Z; 4]);
        m.transform(&Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        let [a, b, c] = m.triangle(0);
        assert!((b - a).cross(c - a).z > 0.0);
        assert_eq!(m.normals.unwrap()[0], Vec3::Z);
    }
}
