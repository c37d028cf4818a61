//! glTF 2.0 import (.gltf and .glb): triangle meshes with their node transforms, cameras, and
//! metallic-roughness materials with their textures. Texture coordinates are converted from
//! glTF's top-left origin to tessera's bottom-left one (v -> 1 - v, DESIGN.md section 3).

use crate::bsdf::PlasticTables;
use crate::color::Rgb;
use crate::error::{Error, Result};
use crate::geometry::TriangleMesh;
use crate::image::{Bitmap, ColorSpace, srgb_decode_colors};
use crate::material::{ColorParam, FloatParam, Material, MaterialKind, TextureId};
use crate::texture::{Channel, Filter, ImageTexture, MipMap, Texture};
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// The meshes of a glTF file in world space, each with its material (an index into the scene's
/// materials) if the primitive has one, and what was ignored.
pub(super) struct GltfImport {
    pub meshes: Vec<(TriangleMesh, Option<u32>)>,
    pub warnings: Vec<String>,
}

fn open(path: &Path) -> Result<gltf::Gltf> {
    match gltf::Gltf::open(path) {
        Ok(g) => Ok(g),
        Err(gltf::Error::Io(e)) => Err(Error::io(path, e)),
        Err(e) => Err(Error::mesh(path, format!("malformed glTF: {e}"))),
    }
}

fn import(path: &Path) -> Result<(gltf::Document, Vec<gltf::buffer::Data>, Vec<gltf::image::Data>)> {
    // Parse first so that a missing file is reported as such.
    open(path)?;
    gltf::import(path).map_err(|e| match e {
        gltf::Error::Io(e) => Error::mesh(path, format!("cannot read a file it refers to: {e}")),
        other => Error::mesh(path, format!("malformed glTF: {other}")),
    })
}

/// Visit every node of the default (or first) scene with its world transform.
fn walk_nodes(doc: &gltf::Document, mut f: impl FnMut(&gltf::Node, Mat4)) {
    fn visit(node: gltf::Node, parent: Mat4, f: &mut impl FnMut(&gltf::Node, Mat4)) {
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        f(&node, m);
        for child in node.children() {
            visit(child, m, f);
        }
    }
    if let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) {
        for node in scene.nodes() {
            visit(node, Mat4::IDENTITY, &mut f);
        }
    }
}

/// The camera-to-world matrix and vertical field of view (degrees) of the `index`-th camera node.
pub(super) fn import_camera(path: &Path, index: usize) -> Result<(Mat4, f32)> {
    let doc = open(path)?.document;
    // Per camera node: its world matrix and vertical field of view (None if orthographic).
    let mut cameras: Vec<(Mat4, Option<f32>)> = Vec::new();
    walk_nodes(&doc, |node, m| {
        if let Some(cam) = node.camera() {
            let yfov = match cam.projection() {
                gltf::camera::Projection::Perspective(p) => Some(p.yfov().to_degrees()),
                gltf::camera::Projection::Orthographic(_) => None,
            };
            cameras.push((m, yfov));
        }
    });
    let count = cameras.len();
    let (m, yfov) = cameras
        .into_iter()
        .nth(index)
        .ok_or_else(|| Error::mesh(path, format!("camera {index} requested, but the file has {count} camera nodes")))?;
    let yfov = yfov.ok_or_else(|| Error::mesh(path, "orthographic cameras are not supported"))?;
    Ok((m, yfov))
}

/// A primitive's vertex tangents (glTF TANGENT's xyz), in world space.
type Tangents = Option<Vec<Vec3>>;

/// Read every triangle primitive of the default scene in world space, with its material index
/// and its tangents if it has them. An error for a primitive without positions or with a bad
/// index count, or a scene without triangles.
fn read_primitives(
    path: &Path,
    doc: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    warnings: &mut Vec<String>,
    mut f: impl FnMut(TriangleMesh, Option<usize>, Tangents),
) -> Result<()> {
    let mut error = None;
    let mut count = 0;
    walk_nodes(doc, |node, m| {
        let Some(mesh) = node.mesh() else { return };
        for prim in mesh.primitives() {
            if prim.mode() != gltf::mesh::Mode::Triangles {
                warnings.push(format!("mesh {}: primitive of mode {:?} skipped", mesh.index(), prim.mode()));
                continue;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(positions) = reader.read_positions() else {
                error.get_or_insert_with(|| {
                    Error::mesh(path, format!("mesh {}: a primitive has no POSITION", mesh.index()))
                });
                continue;
            };
            let positions: Vec<Vec3> = positions.map(Vec3::from).collect();
            let n = positions.len();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if indices.len() % 3 != 0 {
                error.get_or_insert_with(|| {
                    Error::mesh(path, format!("mesh {}: index count not a multiple of 3", mesh.index()))
                });
                continue;
            }
            let tangents = reader
                .read_tangents()
                .map(|t| t.map(|[x, y, z, _]| m.transform_vector3(Vec3::new(x, y, z))).collect::<Vec<_>>());
            if tangents.as_ref().is_some_and(|t| t.len() != n) {
                error.get_or_insert_with(|| {
                    Error::mesh(path, format!("mesh {}: TANGENT and POSITION counts differ", mesh.index()))
                });
                continue;
            }
            let mut tri = TriangleMesh {
                positions,
                normals: reader.read_normals().map(|it| it.map(Vec3::from).collect()),
                uvs: reader.read_tex_coords(0).map(|t| t.into_f32().map(|[u, v]| Vec2::new(u, 1.0 - v)).collect()),
                indices: indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            };
            tri.transform(&m);
            count += 1;
            f(tri, prim.material().index(), tangents);
        }
    });
    if let Some(e) = error {
        return Err(e);
    }
    if count == 0 {
        return Err(Error::mesh(path, "the file's scene has no triangle meshes"));
    }
    Ok(())
}

/// The surface of a glTF file for `tessera deform`: all its triangle primitives in world space
/// as one mesh, with their per-vertex tangents (glTF TANGENT) where every primitive has them.
pub(super) fn import_surface(path: &Path) -> Result<(TriangleMesh, Option<Vec<Vec3>>)> {
    let (doc, buffers, _) = import(path)?;
    let mut surface = TriangleMesh { uvs: Some(Vec::new()), ..TriangleMesh::default() };
    let mut tangents = Some(Vec::new());
    read_primitives(path, &doc, &buffers, &mut Vec::new(), |mesh, _, t| {
        let base = surface.positions.len() as u32;
        match (&mut surface.uvs, mesh.uvs) {
            (Some(all), Some(uvs)) => all.extend(uvs),
            (uvs, _) => *uvs = None,
        }
        match (&mut tangents, t) {
            (Some(all), Some(t)) => all.extend(t),
            (t, _) => *t = None,
        }
        surface.positions.extend(mesh.positions);
        surface.indices.extend(mesh.indices.iter().map(|i| i.map(|v| v + base)));
    })?;
    Ok((surface, tangents))
}

/// Convert a decoded glTF image to a bitmap in the given colour space.
fn bitmap(data: &gltf::image::Data, space: ColorSpace) -> Bitmap {
    use gltf::image::Format;
    let (w, h) = (data.width as usize, data.height as usize);
    let bytes = &data.pixels;
    let (channels, mut values, integer): (usize, Vec<f32>, bool) = match data.format {
        Format::R8 | Format::R8G8 | Format::R8G8B8 | Format::R8G8B8A8 => {
            let ch = bytes.len() / (w * h).max(1);
            (ch, bytes.iter().map(|&b| b as f32 / 255.0).collect(), true)
        }
        Format::R16 | Format::R16G16 | Format::R16G16B16 | Format::R16G16B16A16 => {
            let ch = bytes.len() / 2 / (w * h).max(1);
            (ch, bytes.chunks_exact(2).map(|b| u16::from_le_bytes([b[0], b[1]]) as f32 / 65535.0).collect(), true)
        }
        Format::R32G32B32FLOAT | Format::R32G32B32A32FLOAT => {
            let ch = bytes.len() / 4 / (w * h).max(1);
            (ch, bytes.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect(), false)
        }
    };
    if integer && space == ColorSpace::Srgb {
        srgb_decode_colors(&mut values, channels);
    }
    Bitmap { width: w, height: h, channels, data: values }
}

struct TextureCache<'a> {
    images: &'a [gltf::image::Data],
    textures: &'a mut Vec<Texture>,
    loaded: HashMap<(usize, ColorSpace), TextureId>,
}

impl TextureCache<'_> {
    fn get(&mut self, info_texture: gltf::Texture, space: ColorSpace) -> TextureId {
        let image = info_texture.source().index();
        *self.loaded.entry((image, space)).or_insert_with(|| {
            self.textures.push(Texture::Image(ImageTexture {
                mipmap: Arc::new(MipMap::new(bitmap(&self.images[image], space))),
                filter: Filter::None,
                scale: Vec2::ONE,
                offset: Vec2::ZERO,
            }));
            TextureId(self.textures.len() as u32 - 1)
        })
    }
}

fn convert_material(
    m: &gltf::Material,
    cache: &mut TextureCache,
    tables: Arc<PlasticTables>,
    warnings: &mut Vec<String>,
) -> Material {
    let name = m.name().unwrap_or("(unnamed)");
    let pbr = m.pbr_metallic_roughness();
    let check_info = |warnings: &mut Vec<String>, what: &str, coord: u32| {
        if coord != 0 {
            warnings.push(format!("material '{name}': {what} uses TEXCOORD_{coord}; TEXCOORD_0 is used instead"));
        }
    };
    let [r, g, b, _] = pbr.base_color_factor();
    let factor = Rgb::new(r, g, b);
    let base_color = match pbr.base_color_texture() {
        Some(info) => {
            check_info(warnings, "baseColorTexture", info.tex_coord());
            ColorParam::Texture { id: cache.get(info.texture(), ColorSpace::Srgb), scale: factor }
        }
        None => ColorParam::Value(factor),
    };
    // Roughness in G, metalness in B (glTF 2.0 section 3.9.2).
    let (metallic, roughness) = match pbr.metallic_roughness_texture() {
        Some(info) => {
            check_info(warnings, "metallicRoughnessTexture", info.tex_coord());
            let id = cache.get(info.texture(), ColorSpace::Linear);
            (
                FloatParam::Texture { id, channel: Channel::B, scale: pbr.metallic_factor() },
                FloatParam::Texture { id, channel: Channel::G, scale: pbr.roughness_factor() },
            )
        }
        None => (FloatParam::Value(pbr.metallic_factor()), FloatParam::Value(pbr.roughness_factor())),
    };
    let normal_map = m.normal_texture().map(|n| {
        check_info(warnings, "normalTexture", n.tex_coord());
        if n.scale() != 1.0 {
            warnings.push(format!("material '{name}': normalTexture scale {} ignored", n.scale()));
        }
        cache.get(n.texture(), ColorSpace::Linear)
    });
    if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.push(format!("material '{name}': alpha mode {:?} ignored (rendered opaque)", m.alpha_mode()));
    }
    Material {
        kind: MaterialKind::Pbr {
            base_color,
            metallic,
            roughness,
            occlusion: FloatParam::Value(1.0),
            anisotropy: FloatParam::Value(0.0),
            anisotropy_direction: None,
            tables,
        },
        normal_map,
        two_sided: m.double_sided(),
        texture_frame: None,
    }
}

/// Load all triangle primitives of the file's default scene, in world space (node transforms
/// applied), adding the materials and textures they use to the scene's lists.
pub(super) fn import_meshes(
    path: &Path,
    textures: &mut Vec<Texture>,
    materials: &mut Vec<Material>,
    pbr_tables: fn() -> Arc<PlasticTables>,
) -> Result<GltfImport> {
    let (doc, buffers, images) = import(path)?;
    let mut warnings = Vec::new();
    let mut cache = TextureCache { images: &images, textures, loaded: HashMap::new() };
    let first_material = materials.len() as u32;
    for m in doc.materials() {
        let material = convert_material(&m, &mut cache, pbr_tables(), &mut warnings);
        materials.push(material);
    }
    let mut meshes = Vec::new();
    read_primitives(path, &doc, &buffers, &mut warnings, |mesh, material, _| {
        meshes.push((mesh, material.map(|i| first_material + i as u32)));
    })?;
    Ok(GltfImport { meshes, warnings })
}
