//! Quad meshes (paper 001): four corners per face, counter-clockwise seen from outside, and
//! optional per-corner texture coordinates. Read from OBJ with their faces kept as quads,
//! checked for what the tile mapping needs (manifold, consistently oriented edges), and written
//! back to OBJ with a material library naming the tile image.

use super::Topology;
use crate::error::{Error, Result, guard_parser};
use crate::files::{read_bounded, write_atomically};
use crate::limits;
use glam::{Vec2, Vec3};
use std::fmt::Write as _;
use std::path::Path;

/// A mesh of quads.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct QuadMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Corners of each quad, counter-clockwise.
    pub quads: Vec<[u32; 4]>,
    /// Texture coordinates of each quad's corners, when mapped.
    pub uvs: Option<Vec<[Vec2; 4]>>,
    /// The OBJ line of each quad (1-based), to name it in errors; empty for generated meshes.
    pub lines: Vec<u32>,
}

/// What [`QuadMesh::topology`] found that the mapping tolerates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QuadMeshReport {
    /// Edges with one quad.
    pub boundary_edges: usize,
    /// Edges with two quads.
    pub interior_edges: usize,
}

impl QuadMesh {
    /// A quad mesh from positions and corner indices: every index within range, every
    /// position finite.
    pub fn new(positions: Vec<Vec3>, quads: Vec<[u32; 4]>) -> std::result::Result<Self, String> {
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {} has a non-finite position", i + 1));
        }
        if let Some(f) = quads.iter().position(|q| q.iter().any(|&v| v as usize >= positions.len())) {
            return Err(format!("quad {} names a vertex past the {} there are", f + 1, positions.len()));
        }
        Ok(QuadMesh { positions, quads, uvs: None, lines: Vec::new() })
    }

    /// Where quad `f` came from, for messages: its OBJ line when known.
    pub fn describe_quad(&self, f: usize) -> String {
        match self.lines.get(f) {
            Some(line) => format!("face {} (line {line})", f + 1),
            None => format!("quad {}", f + 1),
        }
    }

    /// The edge adjacency, or an error naming the first edge the tile mapping cannot handle:
    /// a quad repeating a vertex, an edge with more than two quads, two quads that run along
    /// their shared edge in the same direction (inconsistent orientation).
    pub fn topology(&self) -> std::result::Result<(Topology, QuadMeshReport), String> {
        let topology = Topology::new(&self.quads);
        if let Some(h) = topology.degenerate().next() {
            return Err(format!("{} repeats a vertex", self.describe_quad(topology.face_of(h))));
        }
        let quads_of = |e: usize| {
            topology.halves(e).iter().map(|&h| self.describe_quad(topology.face_of(h as usize))).collect::<Vec<_>>()
        };
        let vertices = |e: usize| topology.edge_vertices(e).map(|v| v + 1);
        if let Some(e) = topology.non_manifold_edges().next() {
            let [a, b] = vertices(e);
            return Err(format!(
                "the edge between vertices {a} and {b} is non-manifold: {} quads share it ({}); each edge may have at most two",
                topology.halves(e).len(),
                quads_of(e).join(", ")
            ));
        }
        if let Some(e) = topology.misoriented_edges().next() {
            let [a, b] = vertices(e);
            return Err(format!(
                "{} run along their shared edge (vertices {a} and {b}) in the same direction: the quads are not \
                 consistently oriented",
                quads_of(e).join(" and ")
            ));
        }
        let boundary_edges = topology.boundary_edges().count();
        let report = QuadMeshReport { boundary_edges, interior_edges: topology.edge_count() - boundary_edges };
        Ok((topology, report))
    }

    /// Smooth vertex normals: the sum of the adjacent quads' normals, each the cross product of
    /// its diagonals (twice its projected area), normalised.
    pub fn vertex_normals(&self) -> Vec<Vec3> {
        let mut normals = vec![Vec3::ZERO; self.positions.len()];
        for q in &self.quads {
            let p = q.map(|v| self.positions[v as usize]);
            let n = (p[2] - p[0]).cross(p[3] - p[1]);
            for &v in q {
                normals[v as usize] += n;
            }
        }
        normals.into_iter().map(|n| n.try_normalize().unwrap_or(Vec3::Z)).collect()
    }

    /// Write the mesh as OBJ with its texture coordinates (shared where equal), `normals` per
    /// vertex when given, and a material library `path` with extension `.mtl` whose material
    /// reads `texture` as its diffuse map.
    pub fn write_obj(&self, path: &Path, texture: &str, normals: Option<&[Vec3]>) -> Result<()> {
        let mtl_path = path.with_extension("mtl");
        let mtl_name = mtl_path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let mut obj = String::with_capacity(self.positions.len() * 40 + self.quads.len() * 40);
        let _ = writeln!(obj, "# tessera tiles map: {} quads, one tile per quad (paper 001)", self.quads.len());
        let _ = writeln!(obj, "mtllib {mtl_name}");
        for p in &self.positions {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        for n in normals.unwrap_or_default() {
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
        }
        // A corner: its vertex, texture coordinates and normal ids (1-based).
        let corner = |v: u32, t: Option<usize>| match (t, normals.is_some()) {
            (Some(t), true) => format!("{}/{}/{}", v + 1, t + 1, v + 1),
            (Some(t), false) => format!("{}/{}", v + 1, t + 1),
            (None, true) => format!("{}//{}", v + 1, v + 1),
            (None, false) => format!("{}", v + 1),
        };
        // Distinct texture coordinates (a tile image has few corners).
        let mut uv_ids: std::collections::HashMap<[u32; 2], usize> = Default::default();
        let corner_uv_ids: Vec<[usize; 4]> = match &self.uvs {
            Some(uvs) => uvs
                .iter()
                .map(|corners| {
                    corners.map(|uv| {
                        let next = uv_ids.len();
                        *uv_ids.entry(uv.to_array().map(f32::to_bits)).or_insert_with(|| {
                            let _ = writeln!(obj, "vt {} {}", uv.x, uv.y);
                            next
                        })
                    })
                })
                .collect(),
            None => Vec::new(),
        };
        let _ = writeln!(obj, "usemtl tiles");
        for (f, q) in self.quads.iter().enumerate() {
            let t = corner_uv_ids.get(f);
            let corners: Vec<String> = (0..4).map(|k| corner(q[k], t.map(|t| t[k]))).collect();
            let _ = writeln!(obj, "f {}", corners.join(" "));
        }
        let mtl = format!("newmtl tiles\nKd 1 1 1\nmap_Kd {texture}\n");
        write_atomically(&mtl_path, |tmp| std::fs::write(tmp, mtl.as_bytes()).map_err(|e| Error::io(&mtl_path, e)))?;
        write_atomically(path, |tmp| std::fs::write(tmp, obj.as_bytes()).map_err(|e| Error::io(path, e)))
    }
}

/// Read an OBJ file whose faces are all quads, keeping them as quads. Vertices at the same
/// position are joined (OBJ objects and groups are read separately). A face of another size is
/// an error naming it and its line.
pub fn load_quad_obj(path: &Path) -> Result<QuadMesh> {
    let bytes = read_bounded(path, limits::MAX_MESH_FILE_BYTES, "a mesh file")?;
    let options =
        tobj::LoadOptions { single_index: false, triangulate: false, ignore_points: true, ignore_lines: true };
    let (models, _materials) = guard_parser(path, || {
        tobj::load_obj_buf(&mut &bytes[..], &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| Error::mesh(path, format!("malformed OBJ: {e}")))
    })?;
    let lines = face_lines(&bytes);
    let mut positions = Vec::new();
    let mut quads: Vec<[u32; 4]> = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        positions.extend(m.positions.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])));
        // tobj leaves the arities empty when every face is a triangle.
        let arities: Vec<u32> =
            if m.face_arities.is_empty() { vec![3; m.indices.len() / 3] } else { m.face_arities.clone() };
        let mut next = 0usize;
        for arity in arities {
            let corners = &m.indices[next..next + arity as usize];
            next += arity as usize;
            if arity != 4 {
                let f = quads.len();
                let at = lines.get(f).map_or(String::new(), |l| format!(" (line {l})"));
                return Err(Error::mesh(
                    path,
                    format!("face {}{at} has {arity} corners: tessera tiles needs a mesh of quads only", f + 1),
                ));
            }
            if corners.iter().any(|&c| c as usize >= m.positions.len() / 3) {
                return Err(Error::mesh(path, format!("face {} names a vertex that does not exist", quads.len() + 1)));
            }
            quads.push(std::array::from_fn(|k| base + corners[k]));
            if quads.len() as u64 > limits::MAX_TRIANGLES {
                return Err(Error::mesh(path, format!("more than {} quads", limits::MAX_TRIANGLES)));
            }
        }
    }
    if quads.is_empty() {
        return Err(Error::mesh(path, "no faces"));
    }
    let (welded, positions) = super::mesh::weld_positions(&positions);
    for q in &mut quads {
        *q = q.map(|v| welded[v as usize]);
    }
    let mut mesh = QuadMesh::new(positions, quads).map_err(|msg| Error::mesh(path, msg))?;
    if lines.len() == mesh.quads.len() {
        mesh.lines = lines;
    }
    Ok(mesh)
}

/// The 1-based line of every face statement (`f` with at least three corners) in file order:
/// the order in which tobj lists faces.
fn face_lines(bytes: &[u8]) -> Vec<u32> {
    let text = String::from_utf8_lossy(bytes);
    text.lines()
        .enumerate()
        .filter(|(_, line)| {
            let mut tokens = line.split_whitespace();
            tokens.next() == Some("f") && tokens.count() >= 3
        })
        .map(|(i, _)| (i + 1) as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(text: &str) -> tempfile::NamedTempFile {
        let mut f = tempfile::Builder::new().suffix(".obj").tempfile().unwrap();
        std::io::Write::write_all(&mut f, text.as_bytes()).unwrap();
        f
    }

    const TWO_QUADS: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n";

    #[test]
    fn quads_are_kept_and_groups_joined() {
        let file = write(&format!("{TWO_QUADS}g a\nf 1 2 3 4\ng b\nf 2 5 6 3\n"));
        let mesh = load_quad_obj(file.path()).unwrap();
        assert_eq!(mesh.quads.len(), 2);
        assert_eq!(mesh.positions.len(), 6);
        assert_eq!(mesh.lines, [8, 10]);
        let (topology, report) = mesh.topology().unwrap();
        assert_eq!(report, QuadMeshReport { boundary_edges: 6, interior_edges: 1 });
        assert_eq!(topology.edge_count(), 7);
    }

    #[test]
    fn bad_quad_meshes_are_errors_naming_the_face() {
        let file = write(&format!("{TWO_QUADS}f 1 2 3 4\nf 2 5 6\n"));
        let msg = load_quad_obj(file.path()).unwrap_err().to_string();
        assert!(msg.contains("face 2 (line 8) has 3 corners"), "{msg}");
        let file = write(&format!("{TWO_QUADS}v 3 3 3\nv 4 4 4\nf 1 2 3 4\nf 2 5 6 3\nf 3 7 8 2\n"));
        let msg = load_quad_obj(file.path()).unwrap().topology().unwrap_err();
        assert!(msg.contains("non-manifold") && msg.contains("vertices 2 and 3") && msg.contains("line 11"), "{msg}");
        let file = write(&format!("{TWO_QUADS}f 1 2 3 4\nf 3 6 5 2\n"));
        let msg = load_quad_obj(file.path()).unwrap().topology().unwrap_err();
        assert!(msg.contains("not consistently oriented"), "{msg}");
        let file = write(&format!("{TWO_QUADS}f 1 2 2 4\n"));
        let msg = load_quad_obj(file.path()).unwrap().topology().unwrap_err();
        assert!(msg.contains("repeats a vertex"), "{msg}");
        let file = write("v 0 0 0\n");
        assert!(load_quad_obj(file.path()).unwrap_err().to_string().contains("no faces"));
    }

    #[test]
    fn written_obj_reads_back_with_its_texture_coordinates() {
        let mut mesh =
            QuadMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y], vec![[0, 1, 2, 3]]).unwrap();
        mesh.uvs =
            Some(vec![[Vec2::new(0.125, 0.25), Vec2::new(0.5, 0.25), Vec2::new(0.5, 0.75), Vec2::new(0.125, 0.75)]]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.obj");
        mesh.write_obj(&path, "tiles.png", Some(&mesh.vertex_normals())).unwrap();
        assert!(std::fs::read_to_string(dir.path().join("out.mtl")).unwrap().contains("map_Kd tiles.png"));
        let back = crate::geometry::obj::load_obj(&path).unwrap();
        assert_eq!(back.indices.len(), 2);
        let uvs = back.uvs.unwrap();
        assert!(uvs.contains(&Vec2::new(0.125, 0.25)) && uvs.contains(&Vec2::new(0.5, 0.75)));
        assert!(back.normals.unwrap().iter().all(|n| n.abs_diff_eq(Vec3::Z, 1e-6)));
    }
}
