//! Wavefront OBJ loading (tobj): polygons triangulated, one index per vertex, `vt` kept as is
//! (OBJ's bottom-left origin is tessera's convention).

use super::TriangleMesh;
use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use std::path::Path;

/// Load every object of an OBJ file into one mesh. Materials (`.mtl`) are ignored: the scene
/// file assigns them. Attributes present on only some vertices are an error.
pub fn load_obj(path: &Path) -> Result<TriangleMesh> {
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| match e {
        tobj::LoadError::OpenFileFailed => match std::fs::metadata(path) {
            Err(io) => Error::io(path, io),
            Ok(_) => Error::mesh(path, "cannot open the file"),
        },
        other => Error::mesh(path, format!("malformed OBJ: {other}")),
    })?;
    let (mut positions, mut normals, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        let count = m.positions.len() / 3;
        positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        if m.normals.len() == m.positions.len() {
            normals.extend(m.normals.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        }
        if m.texcoords.len() / 2 == count {
            uvs.extend(m.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])));
        }
        if m.indices.len() % 3 != 0 {
            return Err(Error::mesh(path, format!("object '{}' has an incomplete triangle", model.name)));
        }
        indices.extend(m.indices.chunks_exact(3).map(|c| [base + c[0], base + c[1], base + c[2]]));
    }
    let n = positions.len();
    // An attribute counts only if every vertex has it.
    let complete = |have: usize, what: &str| match have {
        0 => Ok(false),
        h if h == n => Ok(true),
        h => Err(Error::mesh(path, format!("only {h} of {n} vertices have {what}"))),
    };
    let has_normals = complete(normals.len(), "normals")?;
    let has_uvs = complete(uvs.len(), "texture coordinates")?;
    let mesh =
        TriangleMesh { positions, normals: has_normals.then_some(normals), uvs: has_uvs.then_some(uvs), indices };
    Ok(mesh)
}
