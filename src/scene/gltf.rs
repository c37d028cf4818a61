//! glTF 2.0 import (.gltf and .glb): triangle meshes with their node transforms, cameras, and
//! metallic-roughness materials with their textures. Texture coordinates are converted from
//! glTF's top-left origin to tessera's bottom-left one (v -> 1 - v, DESIGN.md section 3).

use crate::bsdf::PlasticTables;
use crate::camera::{FovAxis, Projection};
use crate::color::Rgb;
use crate::error::{Error, Result, guard_parser};
use crate::files::read_bounded;
use crate::geometry::TriangleMesh;
use crate::image::{Bitmap, ColorSpace, decode_image as decode_image_bytes};
use crate::light::{DistantLight, Lights, PointLight, SpotCone, SpotFalloff};
use crate::limits;
use crate::material::{ColorParam, FloatParam, Material, MaterialKind, TextureId};
use crate::texture::{Channel, Filter, ImageTexture, MipMap, Texture};
use glam::{Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The meshes of a glTF file in world space, each with its material (an index into the scene's
/// materials) if the primitive has one, its punctual lights, and what was ignored.
pub(super) struct GltfImport {
    pub meshes: Vec<(TriangleMesh, Option<u32>)>,
    pub lights: Lights,
    pub warnings: Vec<String>,
}

/// A glTF file read and checked: its document and the bytes of its buffers. Everything that the
/// `gltf` crate's readers assume without checking (accessor and view ranges, component types,
/// image sources) is checked here or before each read, so that malformed files are errors, not
/// panics; [`guard_parser`] is the last line of defence around the crate.
struct GltfFile {
    doc: gltf::Document,
    buffers: Vec<Vec<u8>>,
    /// The folder that relative URIs start from.
    base: PathBuf,
}

/// Read, parse and check a .gltf or .glb file and the buffers it refers to.
fn read_gltf(path: &Path) -> Result<GltfFile> {
    let bytes = read_bounded(path, limits::MAX_MESH_FILE_BYTES, "a glTF file")?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    guard_parser(path, || {
        let malformed = |e: gltf::Error| Error::mesh(path, format!("malformed glTF: {e}"));
        // gltf-json's own validation indexes the accessors by each POSITION attribute before it
        // checks the index: check those first, then validate.
        let gltf::Gltf { document, mut blob } = gltf::Gltf::from_slice_without_validation(&bytes).map_err(malformed)?;
        check_position_accessors(document.as_json()).map_err(|msg| Error::mesh(path, msg))?;
        let doc = gltf::Document::from_json(document.into_json()).map_err(malformed)?;
        check_node_tree(&doc).map_err(|msg| Error::mesh(path, msg))?;
        let mut buffers = Vec::new();
        for buffer in doc.buffers() {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                    Error::mesh(path, format!("buffer {} refers to a GLB binary chunk the file lacks", buffer.index()))
                })?,
                gltf::buffer::Source::Uri(uri) => {
                    read_uri(path, &base, uri, limits::MAX_MESH_FILE_BYTES, "a glTF buffer")?
                }
            };
            if data.len() < buffer.length() {
                return Err(Error::mesh(
                    path,
                    format!("buffer {} holds {} bytes, but declares {}", buffer.index(), data.len(), buffer.length()),
                ));
            }
            buffers.push(data);
        }
        Ok(GltfFile { doc, buffers, base: base.clone() })
    })
}

/// The bytes a URI of the glTF file `path` names: a base64 data URI, or a file relative to
/// `base` (percent-encoded), read within `max_bytes`.
fn read_uri(path: &Path, base: &Path, uri: &str, max_bytes: u64, what: &str) -> Result<Vec<u8>> {
    if uri.starts_with("data:") {
        let source = gltf::buffer::Source::Uri(uri);
        return gltf::buffer::Data::from_source_and_blob(source, None, &mut None)
            .map(|d| d.0)
            .map_err(|e| Error::mesh(path, format!("a data URI cannot be decoded: {e}")));
    }
    let file = percent_decode(uri)
        .filter(|f| !f.contains("://"))
        .ok_or_else(|| Error::mesh(path, format!("URI '{uri}' is neither a data URI nor a relative file path")))?;
    read_bounded(&base.join(file), max_bytes, what)
}

/// A URI's percent-encoded path decoded (`%20` to a space); None if malformed or not UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let mut bytes = Vec::with_capacity(uri.len());
    let mut rest = uri.as_bytes();
    while let [first, tail @ ..] = rest {
        if *first == b'%' {
            let hex = std::str::from_utf8(tail.get(..2)?).ok()?;
            bytes.push(u8::from_str_radix(hex, 16).ok()?);
            rest = &tail[2..];
        } else {
            bytes.push(*first);
            rest = tail;
        }
    }
    String::from_utf8(bytes).ok()
}

/// An error if a primitive's POSITION names an accessor the document lacks.
fn check_position_accessors(json: &gltf::json::Root) -> Result<(), String> {
    let accessors = json.accessors.len();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(index) = primitive.attributes.get(&position).filter(|i| i.value() >= accessors) {
                return Err(format!(
                    "mesh {m} primitive {p}: POSITION is accessor {}, but there are {accessors} accessors",
                    index.value()
                ));
            }
        }
    }
    Ok(())
}

/// An error unless the nodes form a forest, as glTF requires: no node is the child of two
/// nodes, and no node is its own ancestor. Walking a cycle would never end.
fn check_node_tree(doc: &gltf::Document) -> Result<(), String> {
    let count = doc.nodes().len();
    let mut parent = vec![None; count];
    for node in doc.nodes() {
        for child in node.children() {
            if let Some(other) = parent[child.index()].replace(node.index()) {
                return Err(format!(
                    "node {} is a child of both node {other} and node {}: glTF nodes form trees",
                    child.index(),
                    node.index()
                ));
            }
        }
    }
    // With one parent at most, a node is in or under a cycle exactly when no root reaches it.
    let mut reached = vec![false; count];
    let mut stack: Vec<usize> = (0..count).filter(|&n| parent[n].is_none()).collect();
    while let Some(n) = stack.pop() {
        reached[n] = true;
        stack.extend(doc.nodes().nth(n).into_iter().flat_map(|node| node.children().map(|c| c.index())));
    }
    match reached.iter().position(|r| !r) {
        Some(n) => Err(format!("node {n} is its own ancestor: the node hierarchy has a cycle")),
        None => Ok(()),
    }
}

/// Visit every node of the default (or first) scene with its world transform, each once.
fn walk_nodes(path: &Path, doc: &gltf::Document, mut f: impl FnMut(&gltf::Node, Mat4) -> Result<()>) -> Result<()> {
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else { return Ok(()) };
    let mut visited = vec![false; doc.nodes().len()];
    // Depth first, in the file's order: roots and children are pushed last first.
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(Error::mesh(
                path,
                format!(
                    "node {} is reached twice from scene {}: glTF scenes list root nodes",
                    node.index(),
                    scene.index()
                ),
            ));
        }
        let m = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        f(&node, m)?;
        stack.extend(node.children().map(|child| (child, m)).collect::<Vec<_>>().into_iter().rev());
    }
    Ok(())
}

/// The camera-to-world matrix, projection (vertical: `yfov`, or twice `ymag`) and `znear` of the
/// `index`-th camera node.
pub(super) fn import_camera(path: &Path, index: usize) -> Result<(Mat4, Projection, f32)> {
    let file = read_gltf(path)?;
    let mut cameras: Vec<(Mat4, Projection, f32)> = Vec::new();
    guard_parser(path, || {
        walk_nodes(path, &file.doc, |node, m| {
            if let Some(cam) = node.camera() {
                let axis = FovAxis::Y;
                cameras.push(match cam.projection() {
                    gltf::camera::Projection::Perspective(p) => {
                        (m, Projection::Perspective { fov: p.yfov().to_degrees(), axis }, p.znear())
                    }
                    gltf::camera::Projection::Orthographic(o) => {
                        (m, Projection::Orthographic { extent: 2.0 * o.ymag(), axis }, o.znear())
                    }
                });
            }
            Ok(())
        })
    })?;
    let count = cameras.len();
    cameras
        .into_iter()
        .nth(index)
        .ok_or_else(|| Error::mesh(path, format!("camera {index} requested, but the file has {count} camera nodes")))
}

/// Luminous efficacy at which photometric glTF intensities become radiometric ones: 683 lm/W,
/// that of light at 555 nm, as Blender's glTF importer converts them.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The `KHR_lights_punctual` lights of the file's default scene, in world space, with
/// intensities (candela for points and spots, lux for directional lights) multiplied by
/// `scale`. Spots keep glTF's falloff, and lights with a range glTF's window.
fn read_lights(path: &Path, file: &GltfFile, scale: f32) -> Result<Lights> {
    use gltf::khr_lights_punctual::Kind;
    let mut lights = Lights::default();
    walk_nodes(path, &file.doc, |node, m| {
        let Some(light) = node.light() else { return Ok(()) };
        let bad = |msg: String| Error::mesh(path, format!("light {} (node {}): {msg}", light.index(), node.index()));
        let intensity = light.intensity() * scale;
        if !(intensity >= 0.0 && intensity.is_finite()) || light.color().iter().any(|c| !(*c >= 0.0 && c.is_finite())) {
            let (i, c) = (light.intensity(), light.color());
            return Err(bad(format!("intensity {i} and colour {c:?} must be finite and >= 0")));
        }
        let power = Rgb::from(light.color()) * intensity;
        let range = match light.range() {
            Some(r) if !(r > 0.0 && r.is_finite()) => return Err(bad(format!("range {r} must be > 0"))),
            r => r,
        };
        let position = m.transform_point3(Vec3::ZERO);
        let axis = m.transform_vector3(Vec3::NEG_Z);
        match light.kind() {
            Kind::Directional => lights.distant.push(DistantLight::new(axis, power, 0.0).map_err(bad)?),
            Kind::Point => lights.points.push(PointLight { position, intensity: power, spot: None, range }),
            Kind::Spot { inner_cone_angle, outer_cone_angle } => {
                if !(outer_cone_angle > 0.0 && outer_cone_angle <= std::f32::consts::FRAC_PI_2) {
                    return Err(bad(format!("outerConeAngle {outer_cone_angle} is outside (0, pi/2]")));
                }
                let cone = SpotCone::new(axis, inner_cone_angle, outer_cone_angle, SpotFalloff::SquaredInCosine)
                    .map_err(bad)?;
                lights.points.push(PointLight { position, intensity: power, spot: Some(cone), range });
            }
        }
        Ok(())
    })?;
    Ok(lights)
}

/// A primitive's vertex tangents (glTF TANGENT's xyz), in world space.
type Tangents = Option<Vec<Vec3>>;

/// The accessor types glTF 2.0 allows for a vertex attribute or the indices (section 3.7.2.1).
fn allowed_types(semantic: Option<&gltf::Semantic>) -> &'static [(DataType, Dimensions)] {
    use gltf::Semantic;
    match semantic {
        Some(Semantic::Positions | Semantic::Normals) => &[(DataType::F32, Dimensions::Vec3)],
        Some(Semantic::Tangents) => &[(DataType::F32, Dimensions::Vec4)],
        Some(Semantic::TexCoords(_)) => {
            &[(DataType::F32, Dimensions::Vec2), (DataType::U8, Dimensions::Vec2), (DataType::U16, Dimensions::Vec2)]
        }
        None => &[
            (DataType::U8, Dimensions::Scalar),
            (DataType::U16, Dimensions::Scalar),
            (DataType::U32, Dimensions::Scalar),
        ],
        Some(_) => &[],
    }
}

/// Check that the gltf crate can read `accessor` (as `semantic`, or as indices when None)
/// without panicking: a type glTF allows there, a buffer view, no sparse storage, a stride at
/// least the element size, and every element inside the view and the view inside its buffer.
fn check_accessor(file: &GltfFile, accessor: &gltf::Accessor, semantic: Option<&gltf::Semantic>) -> Result<(), String> {
    let what = match semantic {
        Some(s) => format!("accessor {} ({s:?})", accessor.index()),
        None => format!("accessor {} (indices)", accessor.index()),
    };
    let found = (accessor.data_type(), accessor.dimensions());
    let allowed = allowed_types(semantic);
    if !allowed.contains(&found) {
        return Err(format!("{what} is {:?} of {:?}; glTF allows {allowed:?} here", found.1, found.0));
    }
    if accessor.sparse().is_some() {
        return Err(format!("{what} is sparse, which tessera does not read"));
    }
    let view = accessor.view().ok_or_else(|| format!("{what} has no bufferView"))?;
    if accessor.count() == 0 {
        return Err(format!("{what} is empty"));
    }
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!("{what}: byteStride {stride} is less than its element size {size}"));
    }
    let end = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|e| e.checked_add(size))
        .and_then(|e| e.checked_add(accessor.offset()));
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!("{what} reaches past the end of buffer view {} ({} bytes)", view.index(), view.length()));
    }
    let buffer_length = file.buffers[view.buffer().index()].len();
    if view.offset().checked_add(view.length()).is_none_or(|end| end > buffer_length) {
        return Err(format!("buffer view {} reaches past the end of buffer {}", view.index(), view.buffer().index()));
    }
    Ok(())
}

/// Read every triangle primitive of the default scene in world space, with its material index
/// and its tangents if it has them; returns how many it read. An error for a primitive without
/// positions, with a bad accessor or index count, or more triangles than the limit.
fn read_primitives(
    path: &Path,
    file: &GltfFile,
    warnings: &mut Vec<String>,
    mut f: impl FnMut(TriangleMesh, Option<usize>, Tangents),
) -> Result<usize> {
    let mut count = 0;
    let mut triangles = 0u64;
    let error = |msg: String| Error::mesh(path, msg);
    walk_nodes(path, &file.doc, |node, m| {
        let Some(mesh) = node.mesh() else { return Ok(()) };
        for prim in mesh.primitives() {
            let here = format!("mesh {} primitive {}", mesh.index(), prim.index());
            if prim.mode() != gltf::mesh::Mode::Triangles {
                warnings.push(format!("{here}: primitive of mode {:?} skipped", prim.mode()));
                continue;
            }
            use gltf::Semantic;
            let Some(positions) = prim.get(&Semantic::Positions) else {
                return Err(error(format!("{here}: no POSITION")));
            };
            let vertex_count = positions.count();
            let mut accessors = vec![(Some(Semantic::Positions), positions)];
            for semantic in [Semantic::Normals, Semantic::TexCoords(0), Semantic::Tangents] {
                if let Some(accessor) = prim.get(&semantic) {
                    if accessor.count() != vertex_count {
                        return Err(error(format!(
                            "{here}: {semantic:?} has {} values for {vertex_count} positions",
                            accessor.count()
                        )));
                    }
                    accessors.push((Some(semantic), accessor));
                }
            }
            accessors.extend(prim.indices().map(|a| (None, a)));
            for (semantic, accessor) in &accessors {
                check_accessor(file, accessor, semantic.as_ref()).map_err(|msg| error(format!("{here}: {msg}")))?;
            }
            let index_count = prim.indices().map_or(vertex_count, |a| a.count());
            if index_count % 3 != 0 {
                return Err(error(format!("{here}: index count {index_count} is not a multiple of 3")));
            }
            triangles += index_count as u64 / 3;
            if triangles > limits::MAX_TRIANGLES {
                return Err(error(limits::exceeded(
                    "the scene's triangle count (meshes instanced by nodes included)",
                    format!("at least {triangles}"),
                    limits::MAX_TRIANGLES,
                )));
            }
            let reader = prim.reader(|b| file.buffers.get(b.index()).map(|d| &d[..]));
            let unreadable = || error(format!("{here}: an accessor cannot be read"));
            let positions: Vec<Vec3> = reader.read_positions().ok_or_else(unreadable)?.map(Vec3::from).collect();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..vertex_count as u32).collect(),
            };
            let tangents = reader
                .read_tangents()
                .map(|t| t.map(|[x, y, z, _]| m.transform_vector3(Vec3::new(x, y, z))).collect::<Vec<_>>());
            let mut tri = TriangleMesh {
                positions,
                normals: reader.read_normals().map(|it| it.map(Vec3::from).collect()),
                uvs: reader.read_tex_coords(0).map(|t| t.into_f32().map(|[u, v]| flip_v(Vec2::new(u, v))).collect()),
                indices: indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            };
            tri.check().map_err(|msg| error(format!("{here}: {msg}")))?;
            tri.transform(&m);
            count += 1;
            f(tri, prim.material().index(), tangents);
        }
        Ok(())
    })?;
    Ok(count)
}

/// The error for a file whose scene has nothing tessera can use.
fn nothing_to_import(path: &Path, what: &str) -> Error {
    Error::mesh(path, format!("the file's scene has no triangle meshes{what}"))
}

/// glTF's texture coordinates (origin top-left) as tessera's (origin bottom-left), DESIGN.md
/// section 3: the one place the v-flip of glTF is written.
fn flip_v(uv: Vec2) -> Vec2 {
    Vec2::new(uv.x, 1.0 - uv.y)
}

/// The surface of a glTF file for `tessera deform`: all its triangle primitives in world space
/// as one mesh, with their per-vertex tangents (glTF TANGENT) where every primitive has them.
pub(super) fn import_surface(path: &Path) -> Result<(TriangleMesh, Option<Vec<Vec3>>)> {
    let file = read_gltf(path)?;
    let mut surface = TriangleMesh { uvs: Some(Vec::new()), ..TriangleMesh::default() };
    let mut tangents = Some(Vec::new());
    guard_parser(path, || {
        let count = read_primitives(path, &file, &mut Vec::new(), |mesh, _, t| {
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
        if count == 0 {
            return Err(nothing_to_import(path, ""));
        }
        Ok(())
    })?;
    Ok((surface, tangents))
}

/// Decode image `index` of the file in the given colour space, from its URI or buffer view,
/// through tessera's own image reading (its size limits, no panics on missing fields).
fn decode_image(path: &Path, file: &GltfFile, index: usize, space: ColorSpace) -> Result<Bitmap> {
    let image = &file.doc.as_json().images[index];
    let error = |msg: String| Error::mesh(path, format!("image {index}: {msg}"));
    let bytes = match (&image.uri, image.buffer_view) {
        (Some(uri), None) => read_uri(path, &file.base, uri, limits::MAX_IMAGE_FILE_BYTES, "an image")?,
        (None, Some(view)) => {
            let view = file.doc.views().nth(view.value()).ok_or_else(|| error("no such buffer view".into()))?;
            file.buffers[view.buffer().index()]
                .get(view.offset()..view.offset().saturating_add(view.length()))
                .ok_or_else(|| error(format!("buffer view {} reaches past the end of its buffer", view.index())))?
                .to_vec()
        }
        _ => return Err(error("an image needs exactly one of uri and bufferView".into())),
    };
    decode_image_bytes(&bytes, path, space).map_err(|e| error(e.to_string()))
}

/// The file's name without its folder, as messages name a glTF file's materials and images.
fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(|| path.display().to_string(), |f| f.to_string_lossy().into())
}

struct TextureCache<'a> {
    path: &'a Path,
    file: &'a GltfFile,
    textures: &'a mut Vec<Texture>,
    /// What the scene calls each of `textures`.
    names: &'a mut Vec<String>,
    loaded: HashMap<(usize, ColorSpace), TextureId>,
}

impl TextureCache<'_> {
    fn get(&mut self, info_texture: gltf::Texture, space: ColorSpace) -> Result<TextureId> {
        let image = info_texture.source().index();
        if let Some(id) = self.loaded.get(&(image, space)) {
            return Ok(*id);
        }
        let bitmap = decode_image(self.path, self.file, image, space)?;
        self.textures.push(Texture::Image(ImageTexture {
            mipmap: Arc::new(MipMap::new(bitmap)),
            filter: Filter::None,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }));
        let file = file_name(self.path);
        self.names.push(format!("{file} image {image}"));
        let id = TextureId(self.textures.len() as u32 - 1);
        self.loaded.insert((image, space), id);
        Ok(id)
    }
}

fn convert_material(
    m: &gltf::Material,
    cache: &mut TextureCache,
    tables: Arc<PlasticTables>,
    warnings: &mut Vec<String>,
) -> Result<Material> {
    let name = m.name().unwrap_or("(unnamed)");
    let pbr = m.pbr_metallic_roughness();
    // The ranges glTF 2.0's schema gives the factors.
    let factors = pbr.base_color_factor().into_iter().chain([pbr.metallic_factor(), pbr.roughness_factor()]);
    if factors.into_iter().any(|f| !(0.0..=1.0).contains(&f)) {
        return Err(Error::mesh(
            cache.path,
            format!("material '{name}': baseColorFactor, metallicFactor and roughnessFactor must lie in [0, 1]"),
        ));
    }
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
            ColorParam::Texture { id: cache.get(info.texture(), ColorSpace::Srgb)?, scale: factor }
        }
        None => ColorParam::Value(factor),
    };
    // Roughness in G, metalness in B (glTF 2.0 section 3.9.2).
    let (metallic, roughness) = match pbr.metallic_roughness_texture() {
        Some(info) => {
            check_info(warnings, "metallicRoughnessTexture", info.tex_coord());
            let id = cache.get(info.texture(), ColorSpace::Linear)?;
            (
                FloatParam::Texture { id, channel: Channel::B, scale: pbr.metallic_factor() },
                FloatParam::Texture { id, channel: Channel::G, scale: pbr.roughness_factor() },
            )
        }
        None => (FloatParam::Value(pbr.metallic_factor()), FloatParam::Value(pbr.roughness_factor())),
    };
    let normal_map = match m.normal_texture() {
        Some(n) => {
            check_info(warnings, "normalTexture", n.tex_coord());
            if n.scale() != 1.0 {
                warnings.push(format!("material '{name}': normalTexture scale {} ignored", n.scale()));
            }
            Some(cache.get(n.texture(), ColorSpace::Linear)?)
        }
        None => None,
    };
    if m.alpha_mode() != gltf::material::AlphaMode::Opaque {
        warnings.push(format!("material '{name}': alpha mode {:?} ignored (rendered opaque)", m.alpha_mode()));
    }
    let file_name = file_name(cache.path);
    Ok(Material {
        name: format!("{file_name} material {} '{name}'", m.index().map_or("default".into(), |i| i.to_string())),
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
    })
}

/// Load all triangle primitives of the file's default scene, in world space (node transforms
/// applied), adding the materials and textures they use to the scene's lists, and its punctual
/// lights with their intensities times `light_scale` (None: leave the lights out).
pub(super) fn import_meshes(
    path: &Path,
    (textures, names): (&mut Vec<Texture>, &mut Vec<String>),
    materials: &mut Vec<Material>,
    pbr_tables: fn() -> Arc<PlasticTables>,
    light_scale: Option<f32>,
) -> Result<GltfImport> {
    let file = read_gltf(path)?;
    guard_parser(path, || {
        let mut warnings = Vec::new();
        let mut cache = TextureCache { path, file: &file, textures, names, loaded: HashMap::new() };
        let first_material = materials.len() as u32;
        for m in file.doc.materials() {
            let material = convert_material(&m, &mut cache, pbr_tables(), &mut warnings)?;
            materials.push(material);
        }
        let mut meshes = Vec::new();
        read_primitives(path, &file, &mut warnings, |mesh, material, _| {
            meshes.push((mesh, material.map(|i| first_material + i as u32)));
        })?;
        let lights = match light_scale {
            Some(scale) => read_lights(path, &file, scale)?,
            None => Lights::default(),
        };
        if meshes.is_empty() && lights.count() == 0 {
            return Err(nothing_to_import(path, " and no punctual lights"));
        }
        Ok(GltfImport { meshes, lights, warnings })
    })
}
