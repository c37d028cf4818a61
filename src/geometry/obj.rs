//! Wavefront OBJ files: loading (tobj; polygons triangulated, one index per vertex, `vt` kept as is
//! (OBJ's bottom-left origin is tessera's convention)) and writing.

use super::TriangleMesh;
use crate::error::{Error, Result, guard_parser};
use crate::files::read_bounded;
use crate::limits;
use glam::{Vec2, Vec3};
use std::path::Path;

/// Load every object of an OBJ file into one mesh. Materials (`.mtl`) are ignored: the scene
/// file assigns them. Attributes present on only some vertices are an error.
pub fn load_obj(path: &Path) -> Result<TriangleMesh> {
    let bytes = read_bounded(path, limits::MAX_MESH_FILE_BYTES, "a mesh file")?;
    let options = tobj::LoadOptions { single_index: true, triangulate: true, ignore_points: true, ignore_lines: true };
    let (models, _materials) = guard_parser(path, || {
        // Materials (`mtllib`) are not read: the scene file assigns them.
        tobj::load_obj_buf(&mut &bytes[..], &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| Error::mesh(path, format!("malformed OBJ: {e}")))
    })?;
    let (mut positions, mut normals, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        let count = m.positions.len() / 3;
        positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        // tobj gives an attribute to no vertex of the object or to every one; anything in
        // between means that some faces lack it (`f 1/1 2/2 3/3` beside `f 1 2 3`).
        let partial = |have: usize, per_vertex: usize, what: &str| {
            (have != 0 && have != per_vertex * count).then(|| {
                Error::mesh(
                    path,
                    format!("object '{}': some faces have {what} and others do not; give all or none", model.name),
                )
            })
        };
        if let Some(e) =
            partial(m.normals.len(), 3, "normals (vn)").or(partial(m.texcoords.len(), 2, "texture coordinates (vt)"))
        {
            return Err(e);
        }
        normals.extend(m.normals.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        uvs.extend(m.texcoords.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])));
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

/// `mesh` as OBJ text after a `comment` line: `v`, then `vt` and `vn` where the mesh has them,
/// one per vertex, and one `f` per triangle (1-based, the same index for all three), which
/// [`load_obj`] reads back to the same mesh.
pub fn obj_text(mesh: &TriangleMesh, comment: &str) -> String {
    use std::fmt::Write;
    let mut obj = String::with_capacity(mesh.positions.len() * 60 + mesh.indices.len() * 30);
    let _ = writeln!(obj, "# {comment}");
    for p in &mesh.positions {
        let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in mesh.uvs.iter().flatten() {
        let _ = writeln!(obj, "vt {} {}", t.x, t.y);
    }
    for n in mesh.normals.iter().flatten() {
        let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
    }
    let corner = |i: u32| {
        let i = i + 1;
        match (mesh.uvs.is_some(), mesh.normals.is_some()) {
            (true, true) => format!("{i}/{i}/{i}"),
            (true, false) => format!("{i}/{i}"),
            (false, true) => format!("{i}//{i}"),
            (false, false) => format!("{i}"),
        }
    };
    for t in &mesh.indices {
        let _ = writeln!(obj, "f {} {} {}", corner(t[0]), corner(t[1]), corner(t[2]));
    }
    obj
}
