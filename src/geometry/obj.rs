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
    let mut mesh = TriangleMesh { normals: Some(Vec::new()), uvs: Some(Vec::new()), ..Default::default() };
    let (mut with_normals, mut with_uvs) = (0usize, 0usize);
    for model in &models {
        let m = &model.mesh;
        let base = mesh.positions.len() as u32;
        let count = m.positions.len() / 3;
        mesh.positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        if m.normals.len() == m.positions.len() {
            with_normals += count;
            let normals = m.normals.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2]));
            mesh.normals.as_mut().map(|ns| ns.extend(normals));
        }
        if m.texcoords.len() / 2 == count && !m.texcoords.is_empty() {
            with_uvs += count;
            let uvs = m.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1]));
            if let Some(out) = mesh.uvs.as_mut() {
                out.extend(uvs);
            }
        }
        if m.indices.len() % 3 != 0 {
            return Err(Error::mesh(path, format!("object '{}' has an incomplete triangle", model.name)));
        }
        mesh.indices.extend(m.indices.chunks_exact(3).map(|c| [base + c[0], base + c[1], base + c[2]]));
    }
    let n = mesh.positions.len();
    for (have, what) in [(with_normals, "normals"), (with_uvs, "texture coordinates")] {
        if have != 0 && have != n {
            return Err(Error::mesh(path, format!("only {have} of {n} vertices have {what}")));
        }
    }
    if with_normals == 0 {
        mesh.normals = None;
    }
    if with_uvs == 0 {
        mesh.uvs = None;
    }
    Ok(mesh)
}
