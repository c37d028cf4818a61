//! Mitsuba's `serialized` meshes (format versions 3 and 4, which Mitsuba 0.5 through 3.9 read
//! and write): after a 4-byte header (magic 0x041C, version), a zlib stream holding a flag word,
//! the shape's name (version 4), the vertex and triangle counts, per-vertex positions, normals,
//! texture coordinates and colours in single or double precision, and u32 triangle indices. A
//! file may hold several meshes, one after another, indexed by a dictionary of offsets at its
//! end; `shape_index` picks one, as Mitsuba's parameter of that name does.
//!
//! Texture coordinates are stored as Mitsuba holds them, v running down the image (measured:
//! Mitsuba 3.9.1 keeps a serialized mesh's uv as stored and flips an OBJ's), so tessera takes
//! 1 - v, as for PLY files.

use super::TriangleMesh;
use crate::error::{Error, Result};
use crate::files::read_bounded;
use crate::limits;
use glam::{Vec2, Vec3};
use std::io::Read;
use std::path::Path;

/// The format's magic number.
const MAGIC: u16 = 0x041C;
/// Flag bits of the legacy (version 3 and 4) encoding.
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const DOUBLE_PRECISION: u32 = 0x2000;
/// Most elements reserved before they are read: the counts come from the file, and a short
/// file claiming millions must not allocate for them.
const RESERVE_AHEAD: usize = 1 << 20;
/// Longest shape name read (version 4 names end with a zero byte).
const MAX_NAME_BYTES: usize = 1 << 16;

/// Read mesh `shape_index` of a `.serialized` file. A mesh flagged for face normals loses its
/// vertex normals (Mitsuba renders it faceted).
pub fn load_serialized(path: &Path, shape_index: u32) -> Result<TriangleMesh> {
    let bytes = read_bounded(path, limits::MAX_MESH_FILE_BYTES, "mesh")?;
    parse(&bytes, shape_index).map_err(|msg| Error::mesh(path, msg))
}

fn parse(bytes: &[u8], shape_index: u32) -> std::result::Result<TriangleMesh, String> {
    let u16_at = |at: usize| bytes.get(at..at + 2).map(|b| u16::from_le_bytes([b[0], b[1]]));
    if u16_at(0) != Some(MAGIC) {
        return Err("not a Mitsuba serialized mesh (no 0x041C magic number)".to_string());
    }
    let version = u16_at(2).expect("four bytes read");
    if !(version == 3 || version == 4) {
        return Err(format!(
            "serialized format version {version} is not read (versions 3 and 4 are, as Mitsuba 3.9 writes them)"
        ));
    }
    let start = if shape_index == 0 { 0 } else { mesh_offset(bytes, version, shape_index)? };
    if u16_at(start) != Some(MAGIC) {
        return Err(format!("mesh {shape_index} does not start with the format's header at byte {start}"));
    }
    let mut stream = flate2::read::ZlibDecoder::new(&bytes[start + 4..]);
    read_mesh(&mut stream, version).map_err(|msg| format!("mesh {shape_index}: {msg}"))
}

/// The byte offset of mesh `index` from the dictionary at the file's end: u64 offsets (u32 in
/// version 3), then a u32 count.
fn mesh_offset(bytes: &[u8], version: u16, index: u32) -> std::result::Result<usize, String> {
    let tail = |from_end: usize, width: usize| -> Option<u64> {
        let at = bytes.len().checked_sub(from_end)?;
        let b = bytes.get(at..at + width)?;
        Some(if width == 4 {
            u32::from_le_bytes(b.try_into().ok()?) as u64
        } else {
            u64::from_le_bytes(b.try_into().ok()?)
        })
    };
    let count = tail(4, 4).ok_or("the file is too short for its dictionary of meshes")? as u32;
    if index >= count {
        return Err(format!("shape_index {index} is out of range: the file holds {count} meshes"));
    }
    let width = if version == 4 { 8 } else { 4 };
    let offset = tail(4 + width * (count - index) as usize, width).ok_or("the dictionary of meshes is truncated")?;
    usize::try_from(offset)
        .ok()
        .filter(|&o| o + 4 <= bytes.len())
        .ok_or_else(|| format!("mesh {index}'s offset {offset} lies beyond the file's {} bytes", bytes.len()))
}

/// Read one mesh's decompressed stream.
fn read_mesh(stream: &mut impl Read, version: u16) -> std::result::Result<TriangleMesh, String> {
    let mut reader = Reader(stream);
    let flags = reader.u32()?;
    if version == 4 {
        reader.name()?;
    }
    let (vertices, triangles) = (reader.u64()?, reader.u64()?);
    if triangles > limits::MAX_TRIANGLES || vertices > 3 * limits::MAX_TRIANGLES || vertices > u32::MAX as u64 {
        return Err(limits::exceeded("its vertex or triangle count", vertices.max(triangles), limits::MAX_TRIANGLES));
    }
    let (n, double) = (vertices as usize, flags & DOUBLE_PRECISION != 0);
    let positions = reader.vectors(n, 3, double)?.chunks_exact(3).map(Vec3::from_slice).collect();
    let normals = if flags & HAS_NORMALS != 0 {
        Some(reader.vectors(n, 3, double)?.chunks_exact(3).map(Vec3::from_slice).collect())
    } else {
        None
    };
    let uvs = if flags & HAS_TEXCOORDS != 0 {
        Some(reader.vectors(n, 2, double)?.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect())
    } else {
        None
    };
    if flags & HAS_COLORS != 0 {
        reader.vectors(n, 3, double)?;
    }
    let mut indices = Vec::with_capacity((triangles as usize).min(RESERVE_AHEAD));
    for _ in 0..triangles {
        indices.push([reader.u32()?, reader.u32()?, reader.u32()?]);
    }
    let normals = normals.filter(|_| flags & FACE_NORMALS == 0);
    Ok(TriangleMesh { positions, normals, uvs, indices })
}

/// Little-endian reads from the decompressed stream; running out is an error.
struct Reader<'a, R: Read>(&'a mut R);

impl<R: Read> Reader<'_, R> {
    fn bytes<const N: usize>(&mut self) -> std::result::Result<[u8; N], String> {
        let mut b = [0u8; N];
        self.0.read_exact(&mut b).map_err(|e| format!("truncated or corrupt compressed data ({e})"))?;
        Ok(b)
    }

    fn u32(&mut self) -> std::result::Result<u32, String> {
        Ok(u32::from_le_bytes(self.bytes()?))
    }

    fn u64(&mut self) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(self.bytes()?))
    }

    /// A zero-terminated name, skipped.
    fn name(&mut self) -> std::result::Result<(), String> {
        for _ in 0..MAX_NAME_BYTES {
            if self.bytes::<1>()?[0] == 0 {
                return Ok(());
            }
        }
        Err(format!("the shape's name is longer than {MAX_NAME_BYTES} bytes"))
    }

    /// `count` vectors of `dim` floats (f64 converted to f32).
    fn vectors(&mut self, count: usize, dim: usize, double: bool) -> std::result::Result<Vec<f32>, String> {
        let mut values = Vec::with_capacity((count * dim).min(RESERVE_AHEAD));
        for _ in 0..count * dim {
            let v = if double { f64::from_le_bytes(self.bytes()?) as f32 } else { f32::from_le_bytes(self.bytes()?) };
            values.push(v);
        }
        Ok(values)
    }
}
