//! Stanford PLY meshes (ASCII, binary little- and big-endian), as Mitsuba 3's `ply` shape reads
//! them: vertex positions, normals (`nx ny nz`) and texture coordinates (`u v`, `s t` or
//! `texture_u texture_v`), and polygon faces (`vertex_indices` or `vertex_index`), fanned into
//! triangles. Other elements and properties are read past.
//!
//! Texture coordinates: Mitsuba's PLY loader keeps v as stored and its bitmaps start at the top
//! row, so a PLY's v runs down the image (measured by rendering one quad in Mitsuba 3.9.1 as PLY
//! and as OBJ: the images are each other's mirror). tessera's v runs up (DESIGN.md section 3),
//! so v becomes 1 - v here, and tessera's lookups stay Mitsuba's.

use super::TriangleMesh;
use crate::error::{Error, Result, guard_parser};
use crate::files::read_bounded;
use crate::limits;
use glam::{Vec2, Vec3};
use std::path::Path;

/// How the body is stored.
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// A scalar type of the format, by its size in bytes and whether it is an integer (signed?) or
/// a float.
#[derive(Clone, Copy)]
enum Scalar {
    Int { bytes: usize, signed: bool },
    Float { bytes: usize },
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Scalar::Int { bytes: 1, signed: true },
            "uchar" | "uint8" => Scalar::Int { bytes: 1, signed: false },
            "short" | "int16" => Scalar::Int { bytes: 2, signed: true },
            "ushort" | "uint16" => Scalar::Int { bytes: 2, signed: false },
            "int" | "int32" => Scalar::Int { bytes: 4, signed: true },
            "uint" | "uint32" => Scalar::Int { bytes: 4, signed: false },
            "float" | "float32" => Scalar::Float { bytes: 4 },
            "double" | "float64" => Scalar::Float { bytes: 8 },
            _ => return None,
        })
    }
}

/// A property: a scalar, or a list with its count's type.
struct Property {
    name: String,
    count: Option<Scalar>,
    value: Scalar,
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Reads the body's numbers one at a time, in either encoding.
struct Body<'a> {
    bytes: &'a [u8],
    at: usize,
    encoding: Encoding,
}

impl Body<'_> {
    fn next(&mut self, scalar: Scalar) -> std::result::Result<f64, String> {
        if self.encoding == Encoding::Ascii {
            while self.at < self.bytes.len() && self.bytes[self.at].is_ascii_whitespace() {
                self.at += 1;
            }
            let start = self.at;
            while self.at < self.bytes.len() && !self.bytes[self.at].is_ascii_whitespace() {
                self.at += 1;
            }
            let word = std::str::from_utf8(&self.bytes[start..self.at]).unwrap_or("");
            return match word {
                "" => Err("the file ends before its elements do".into()),
                w => w.parse::<f64>().map_err(|_| format!("'{w}' is not a number")),
            };
        }
        let size = match scalar {
            Scalar::Int { bytes, .. } | Scalar::Float { bytes } => bytes,
        };
        let Some(raw) = self.bytes.get(self.at..self.at + size) else {
            return Err("the file ends before its elements do".into());
        };
        self.at += size;
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(raw);
        if self.encoding == Encoding::BigEndian {
            b[..size].reverse();
        }
        Ok(match scalar {
            Scalar::Int { bytes: 1, signed } => {
                if signed {
                    f64::from(b[0] as i8)
                } else {
                    f64::from(b[0])
                }
            }
            Scalar::Int { bytes: 2, signed } => {
                let v = u16::from_le_bytes([b[0], b[1]]);
                if signed { f64::from(v as i16) } else { f64::from(v) }
            }
            Scalar::Int { signed, .. } => {
                let v = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if signed { f64::from(v as i32) } else { f64::from(v) }
            }
            Scalar::Float { bytes: 4 } => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::Float { .. } => f64::from_le_bytes(b),
        })
    }
}

/// Parse the header: the encoding, the elements, and where the body starts.
fn header(bytes: &[u8]) -> std::result::Result<(Encoding, Vec<Element>, usize), String> {
    const END: &[u8] = b"end_header";
    let end = bytes.windows(END.len()).position(|w| w == END).ok_or("no end_header line")?;
    let body = bytes[end..].iter().position(|&b| b == b'\n').map(|n| end + n + 1).ok_or("no body")?;
    let text = std::str::from_utf8(&bytes[..end]).map_err(|_| "the header is not text")?;
    let mut lines = text.lines().map(str::trim);
    if lines.next() != Some("ply") {
        return Err("not a PLY file (it does not start with 'ply')".into());
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", kind, _version] => {
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::LittleEndian,
                    "binary_big_endian" => Encoding::BigEndian,
                    other => return Err(format!("unknown format '{other}'")),
                })
            }
            ["element", name, count] => {
                let count: usize = count.parse().map_err(|_| format!("element {name}: count '{count}'"))?;
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", "list", count, value, name] => {
                let (Some(count), Some(value)) = (Scalar::parse(count), Scalar::parse(value)) else {
                    return Err(format!("property {name}: unknown type in '{line}'"));
                };
                let element = elements.last_mut().ok_or("a property before any element")?;
                element.properties.push(Property { name: name.to_string(), count: Some(count), value });
            }
            ["property", ty, name] => {
                let value = Scalar::parse(ty).ok_or_else(|| format!("property {name}: unknown type '{ty}'"))?;
                let element = elements.last_mut().ok_or("a property before any element")?;
                element.properties.push(Property { name: name.to_string(), count: None, value });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            _ => return Err(format!("header line '{line}' is not PLY")),
        }
    }
    Ok((encoding.ok_or("no format line")?, elements, body))
}

/// Read a PLY mesh.
pub fn load_ply(path: &Path) -> Result<TriangleMesh> {
    let bytes = read_bounded(path, limits::MAX_MESH_FILE_BYTES, "a mesh file")?;
    guard_parser(path, || parse(&bytes).map_err(|msg| Error::mesh(path, msg)))
}

fn parse(bytes: &[u8]) -> std::result::Result<TriangleMesh, String> {
    let (encoding, elements, start) = header(bytes)?;
    let mut body = Body { bytes, at: start, encoding };
    let mut mesh = TriangleMesh::default();
    let (mut normals, mut uvs) = (Vec::new(), Vec::new());
    for element in &elements {
        // Every element takes at least a byte (a word in ASCII): a count beyond the file is a lie.
        if element.count > bytes.len() {
            return Err(format!(
                "element {} claims {} items in a {}-byte file",
                element.name,
                element.count,
                bytes.len()
            ));
        }
        let find = |names: &[&str]| element.properties.iter().position(|p| names.contains(&p.name.as_str()));
        let slots = match element.name.as_str() {
            "vertex" => {
                let position = [find(&["x"]), find(&["y"]), find(&["z"])];
                if position.iter().any(Option::is_none) {
                    return Err("the vertices have no x, y and z".into());
                }
                let normal = [find(&["nx"]), find(&["ny"]), find(&["nz"])];
                let uv = [find(&["u", "s", "texture_u", "texture_s"]), find(&["v", "t", "texture_v", "texture_t"])];
                Some((position, normal, uv))
            }
            _ => None,
        };
        let indices = (element.name == "face").then(|| find(&["vertex_indices", "vertex_index"])).flatten();
        if element.name == "face" && indices.is_none() {
            return Err("the faces have no vertex_indices".into());
        }
        let mut values = vec![0.0f64; element.properties.len()];
        let mut list = Vec::new();
        for item in 0..element.count {
            for (k, p) in element.properties.iter().enumerate() {
                match p.count {
                    None => values[k] = body.next(p.value)?,
                    Some(count_type) => {
                        let n = body.next(count_type)?;
                        if !(0.0..=1024.0).contains(&n) {
                            return Err(format!("{} {item}: a list of {n} items", element.name));
                        }
                        list.clear();
                        for _ in 0..n as usize {
                            list.push(body.next(p.value)?);
                        }
                    }
                }
            }
            if let Some((position, normal, uv)) = &slots {
                let at = |i: Option<usize>| i.map(|i| values[i] as f32);
                mesh.positions.push(Vec3::new(
                    at(position[0]).unwrap(),
                    at(position[1]).unwrap(),
                    at(position[2]).unwrap(),
                ));
                if let [Some(x), Some(y), Some(z)] = normal.map(at) {
                    normals.push(Vec3::new(x, y, z));
                }
                if let [Some(u), Some(v)] = uv.map(at) {
                    uvs.push(Vec2::new(u, 1.0 - v));
                }
            }
            if indices.is_some() {
                if list.len() < 3 {
                    continue;
                }
                let bad = list.iter().find(|&&i| !(i >= 0.0 && i < u32::MAX as f64 && i.fract() == 0.0));
                if let Some(i) = bad {
                    return Err(format!("face {item}: vertex index {i}"));
                }
                for k in 1..list.len() - 1 {
                    mesh.indices.push([list[0] as u32, list[k] as u32, list[k + 1] as u32]);
                }
                if mesh.indices.len() as u64 > limits::MAX_TRIANGLES {
                    return Err(limits::exceeded(
                        "its triangle count",
                        mesh.indices.len() as u64,
                        limits::MAX_TRIANGLES,
                    ));
                }
            }
        }
    }
    let n = mesh.positions.len();
    mesh.normals = (n > 0 && normals.len() == n).then_some(normals);
    mesh.uvs = (n > 0 && uvs.len() == n).then_some(uvs);
    mesh.check()?;
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    const QUAD: &str = "ply\nformat ascii 1.0\ncomment a unit quad\nelement vertex 4\nproperty float x\n\
        property float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\
        -1 -1 0 0 0\n1 -1 0 1 0\n1 1 0 1 1\n-1 1 0 0 1\n4 0 1 2 3\n";

    #[test]
    fn ascii_quads_are_fanned_and_v_runs_as_mitsuba_reads_it() {
        let mesh = parse(QUAD.as_bytes()).unwrap();
        assert_eq!(mesh.indices, [[0, 1, 2], [0, 2, 3]]);
        assert_eq!(mesh.uvs.as_ref().unwrap()[0], Vec2::new(0.0, 1.0), "v = 0 is the image's top row");
        assert!(mesh.normals.is_none());
    }

    #[test]
    fn binary_files_in_both_byte_orders_read_alike() {
        let header = |order: &str| {
            format!(
                "ply\nformat binary_{order}_endian 1.0\nelement vertex 3\nproperty double x\nproperty float y\n\
                 property float z\nproperty uchar red\nelement face 1\nproperty list uchar uint vertex_indices\n\
                 element edge 1\nproperty int vertex1\nend_header\n"
            )
        };
        let vertices = [(0.5f64, 0.0f32, 0.0f32), (1.0, 1.0, 0.0), (0.0, 1.0, 0.25)];
        for (order, le) in [("little", true), ("big", false)] {
            let mut bytes = header(order).into_bytes();
            for (x, y, z) in vertices {
                let (x, y, z) = if le {
                    (x.to_le_bytes().to_vec(), y.to_le_bytes(), z.to_le_bytes())
                } else {
                    (x.to_be_bytes().to_vec(), y.to_be_bytes(), z.to_be_bytes())
                };
                bytes.extend(x);
                bytes.extend(y);
                bytes.extend(z);
                bytes.push(255);
            }
            bytes.push(3);
            for i in [0u32, 1, 2] {
                bytes.extend(if le { i.to_le_bytes() } else { i.to_be_bytes() });
            }
            bytes.extend([0u8; 4]);
            let mesh = parse(&bytes).unwrap_or_else(|e| panic!("{order}: {e}"));
            assert_eq!(mesh.positions[2], Vec3::new(0.0, 1.0, 0.25), "{order}");
            assert_eq!(mesh.indices, [[0, 1, 2]]);
        }
    }

    #[test]
    fn malformed_files_are_errors() {
        for (text, needle) in [
            ("obj\n", "no end_header"),
            ("PLY\nend_header\n", "not a PLY file"),
            ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n", "no x, y and z"),
            ("ply\nformat ascii 1.0\nelement vertex 99999999\nproperty float x\nend_header\n", "claims 99999999"),
            (&QUAD.replace("4 0 1 2 3", "4 0 1 2 9"), "refers to vertex 9"),
            (&QUAD.replace("4 0 1 2 3", "4 0 1 2"), "ends before"),
            (&QUAD.replace("property float u", "property quad u"), "unknown type"),
        ] {
            let err = parse(text.as_bytes()).map(|_| ()).unwrap_err();
            assert!(err.contains(needle), "{text:?}: {err}");
        }
    }
}
