//! Scene loading: the TOML description to a renderable [`Scene`]. Paths are relative to the
//! scene file; every error names the scene file and the item, and the file at fault.

use super::desc::{
    BlendKind, CameraDesc, ColorValue, DeformationDesc, EnvironmentDesc, FloatValue, IorValue, MaterialDesc,
    PixelFilterDesc, ProjectionKind, RenderDesc, RgbValue, ScaleValue, SceneDesc, ShapeDesc, ShapeKind, TextureDesc,
    TilingBlendingDesc, TransformStep,
};
use super::{Geometry, RenderSettings, Scene};
use crate::accel::Accel;
use crate::bsdf::PlasticTables;
use crate::camera::{Camera, CameraModel, FovAxis, Projection, ThinLens};
use crate::color::Rgb;
use crate::error::{Error, Result};
use crate::files::read_text_bounded;
use crate::geometry::{Sphere, TriangleMesh, obj, ply, serialized, shapes};
use crate::image::{ColorSpace, PixelFilter, read_bitmap, read_bitmap_raw};
use crate::light::{AreaLight, Environment, EnvironmentMap, Lights};
use crate::limits;
use crate::material::{
    ColorParam, FloatParam, Material, MaterialKind, Roughness, TextureId, named_conductor, named_ior,
};
use crate::pups::{PresetParams, PupsTexture, read_points};
use crate::texture::tiling_blending::{
    Blend, Charts, CutBands, Deformation, DeformationField, PriorityMap, Synthesis, Tiling, cuts_from_json,
};
use crate::texture::{Checkerboard, ImageTexture, MipMap, PupsLookup, QuadTilesTexture, Texture, TilingBlending};
use glam::{Mat2, Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// Largest absolute index of refraction accepted: above every transparent material's (diamond
/// 2.42, germanium 4 in the infrared).
const MAX_IOR: f32 = 10.0;
/// Largest radiance of an emitter or environment: far above the sun's (1.6e9 W m^-2 sr^-1),
/// and small enough that the film's per-pixel variance stays finite in 32-bit floats.
const MAX_RADIANCE: f32 = 1e15;

/// Settings given on the command line that replace the scene file's.
#[derive(Clone, Debug, Default)]
pub struct SceneOverrides {
    /// Samples per pixel.
    pub spp: Option<u32>,
    /// Sampler seed.
    pub seed: Option<u64>,
    /// Image width.
    pub width: Option<u32>,
    /// Image height.
    pub height: Option<u32>,
    /// Path length (-1 unlimited).
    pub max_depth: Option<i64>,
    /// Any scene values, replaced before the scene is read: (key path, TOML value), as
    /// [`super::set::set_value`] takes them (`--set camera.fov=40`).
    pub set: Vec<(String, String)>,
}

/// Load a scene file.
pub fn load_scene(path: &Path, overrides: &SceneOverrides) -> Result<Scene> {
    let text = read_scene_file(path)?;
    load_scene_str(&text, path, overrides)
}

/// Load a scene from its text; `path` names it in messages and anchors its relative paths.
pub fn load_scene_str(text: &str, path: &Path, overrides: &SceneOverrides) -> Result<Scene> {
    let desc = parse_scene(text, path, &overrides.set)?;
    Loader::new(path, &desc).load(&desc, overrides)
}

/// The text of a scene file, within [`limits::MAX_SCENE_FILE_BYTES`].
fn read_scene_file(path: &Path) -> Result<String> {
    read_text_bounded(path, limits::MAX_SCENE_FILE_BYTES, "a scene file")
}

/// Parse a scene file's text with the values `set` replaced; errors give the line, or the key
/// of a number that is not finite.
fn parse_scene(text: &str, path: &Path, set: &[(String, String)]) -> Result<SceneDesc> {
    let syntax_error = |e: toml::de::Error| {
        let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
        Error::Scene { path: path.to_path_buf(), line, msg: e.message().to_string() }
    };
    let mut table: toml::Table = toml::from_str(text).map_err(syntax_error)?;
    for (key, value) in set {
        super::set::set_value(&mut table, key, value).map_err(|msg| Error::param(format!("--set {key}"), msg))?;
    }
    let table = toml::Value::Table(table);
    check_numbers(&table, "").map_err(|msg| Error::scene(path, msg))?;
    if set.is_empty() {
        return toml::from_str(text).map_err(syntax_error);
    }
    let keys: Vec<&str> = set.iter().map(|(k, _)| k.as_str()).collect();
    table.try_into().map_err(|e: toml::de::Error| {
        Error::scene(path, format!("{} (with --set {})", e.message(), keys.join(", --set ")))
    })
}

/// An error naming the first number under `value` (at key path `key`) that is not a finite
/// 32-bit float: TOML allows `nan` and `inf`, and 1e300 becomes infinite in an f32. Every
/// parameter tessera reads is such a float or an integer.
fn check_numbers(value: &toml::Value, key: &str) -> Result<(), String> {
    match value {
        toml::Value::Float(x) if !(x.abs() <= f32::MAX as f64) => {
            Err(format!("{key}: {x} is not a finite number tessera can represent (32-bit float)"))
        }
        toml::Value::Array(items) => {
            items.iter().enumerate().try_for_each(|(i, v)| check_numbers(v, &format!("{key}[{i}]")))
        }
        toml::Value::Table(table) => table
            .iter()
            .try_for_each(|(k, v)| check_numbers(v, &if key.is_empty() { k.clone() } else { format!("{key}.{k}") })),
        _ => Ok(()),
    }
}

/// Load the texture `name` of a scene file alone, as a colour (8-bit images sRGB-decoded) or
/// as data (`color` false), for `tessera bake`.
pub fn load_texture(path: &Path, name: &str, color: bool) -> Result<Texture> {
    let text = read_scene_file(path)?;
    let desc = parse_scene(&text, path, &[])?;
    let role = if color { Role::Color } else { Role::Data };
    Ok(Loader::new(path, &desc).build_texture(name, role, "--texture")?.0)
}

/// The IOR-1.5 tables shared by every `pbr` material (computed once per process).
fn pbr_tables() -> Arc<PlasticTables> {
    static TABLES: OnceLock<Arc<PlasticTables>> = OnceLock::new();
    TABLES.get_or_init(|| Arc::new(PlasticTables::new(1.5, &PlasticTables::alpha_grid()))).clone()
}

/// How a texture is used, which decides its default colour space.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Color,
    Data,
}

struct Loader<'a> {
    path: &'a Path,
    base: PathBuf,
    texture_descs: &'a std::collections::BTreeMap<String, TextureDesc>,
    textures: Vec<Texture>,
    /// What the scene calls each of `textures`.
    texture_names: Vec<String>,
    loaded_textures: HashMap<(String, ColorSpace), TextureId>,
    built_textures: HashMap<(String, ColorSpace), Texture>,
    textures_in_progress: Vec<String>,
    syntheses: HashMap<String, Arc<Synthesis>>,
    plastic_tables: HashMap<(u32, u32), Arc<PlasticTables>>,
    warnings: Vec<String>,
}

impl<'a> Loader<'a> {
    fn new(path: &'a Path, desc: &'a SceneDesc) -> Self {
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Loader {
            path,
            base,
            texture_descs: &desc.textures,
            textures: Vec::new(),
            texture_names: Vec::new(),
            loaded_textures: HashMap::new(),
            built_textures: HashMap::new(),
            textures_in_progress: Vec::new(),
            syntheses: HashMap::new(),
            plastic_tables: HashMap::new(),
            warnings: Vec::new(),
        }
    }

    fn error(&self, msg: impl Into<String>) -> Error {
        Error::scene(self.path, msg)
    }

    fn resolve_path(&self, file: &str) -> PathBuf {
        self.base.join(file)
    }

    fn load(mut self, desc: &SceneDesc, overrides: &SceneOverrides) -> Result<Scene> {
        let settings = self.settings(&desc.render, overrides)?;

        let mut materials = Vec::new();
        let mut material_ids = HashMap::new();
        for (name, m) in &desc.materials {
            let material = self.material(m, &format!("materials.{name}"))?;
            material_ids.insert(name.clone(), materials.len() as u32);
            materials.push(material);
        }
        // The default materials, made when first needed: for plain shapes and for emitters.
        let mut default_material = [None, None];
        let mut geometry = Geometry::default();
        let mut lights = Lights::default();
        for (i, shape) in desc.shapes.iter().enumerate() {
            let item = match &shape.filename {
                Some(f) => format!("shapes[{i}] ({f})"),
                None => format!("shapes[{i}]"),
            };
            let assigned = match &shape.material {
                Some(name) => Some(*material_ids.get(name).ok_or_else(|| {
                    self.error(format!(
                        "{item}: unknown material '{name}' (defined: {})",
                        desc.materials.keys().cloned().collect::<Vec<_>>().join(", ")
                    ))
                })?),
                None => None,
            };
            let transform = self.transform(&shape.transform, &item)?;
            let emission = match shape.emission {
                Some(RgbValue(e)) if e.iter().any(|v| !(0.0..=MAX_RADIANCE).contains(v)) => {
                    return Err(self.error(format!("{item}.emission: {e:?} is outside [0, {MAX_RADIANCE:e}]")));
                }
                Some(RgbValue(e)) if e.iter().any(|v| *v > 0.0) => Some(Rgb::from(e)),
                _ => None,
            };
            self.check_shape_keys(shape, &item)?;
            if shape.kind == ShapeKind::Sphere {
                let centre = Vec3::from(shape.center.unwrap_or([0.0; 3]));
                let radius = shape.radius.unwrap_or(1.0);
                if !(radius > 0.0) {
                    return Err(self.error(format!("{item}.radius: {radius} is not positive")));
                }
                let to_world = transform * Mat4::from_translation(centre) * Mat4::from_scale(Vec3::splat(radius));
                let sphere =
                    Sphere::new(to_world, shape.flip_normals).map_err(|msg| self.error(format!("{item}: {msg}")))?;
                let material = material_or_default(&mut default_material, &mut materials, assigned, emission.is_some());
                let light = emission.map(|radiance| {
                    lights.area.push(AreaLight::sphere(sphere.clone(), radiance));
                    lights.area.len() as u32 - 1
                });
                geometry.add_sphere(sphere, item.clone(), material, light);
                continue;
            }
            let mut file_lights = Lights::default();
            for (mesh, material) in self.shape_meshes(shape, &item, &mut materials, &mut file_lights)? {
                let mut mesh = mesh;
                mesh.transform(&transform);
                if shape.flip_normals {
                    mesh.flip_normals();
                }
                let cleanup = mesh.validate().map_err(|msg| self.error(format!("{item}: {msg}")))?;
                let triangles = (geometry.triangles.len() + mesh.indices.len()) as u64;
                if triangles > limits::MAX_TRIANGLES {
                    let msg = limits::exceeded("the scene's triangle count", triangles, limits::MAX_TRIANGLES);
                    return Err(self.error(format!("{item}: {msg}")));
                }
                if cleanup.degenerate_triangles > 0 {
                    self.warnings.push(format!(
                        "{}: {item}: dropped {} zero-area triangles",
                        self.path.display(),
                        cleanup.degenerate_triangles
                    ));
                }
                let material = material_or_default(
                    &mut default_material,
                    &mut materials,
                    assigned.or(material),
                    emission.is_some(),
                );
                let light = emission.map(|radiance| {
                    let tris = (0..mesh.triangle_count()).map(|t| mesh.triangle(t)).collect();
                    lights.area.push(AreaLight::new(tris, radiance));
                    lights.area.len() as u32 - 1
                });
                geometry.add(mesh, item.clone(), material, light);
            }
            lights.points.extend(file_lights.points.iter().map(|l| l.transformed(&transform)));
            for l in &file_lights.distant {
                lights.distant.push(l.transformed(&transform).map_err(|msg| self.error(format!("{item}: {msg}")))?);
            }
        }

        lights.environment = match &desc.environment {
            Some(env) => Some(self.environment(env)?),
            None => None,
        };
        for (i, light) in desc.lights.iter().enumerate() {
            super::lights::add_light(&mut lights, light, MAX_RADIANCE)
                .map_err(|msg| self.error(format!("lights[{i}]: {msg}")))?;
        }
        if geometry.shapes.is_empty() {
            self.warnings
                .push(format!("{}: the scene has no shapes: only the environment is seen", self.path.display()));
        }
        if !lights.any_emit() {
            self.warnings.push(format!(
                "{}: the scene has no light (no emission, no lights, no environment): the image will be black",
                self.path.display()
            ));
        }
        let camera = self.camera(&desc.camera, &settings)?;
        let accel = Accel::build(&geometry.all_triangle_positions(), &geometry.emitting_triangles(), &geometry.spheres);
        Ok(Scene {
            path: self.path.to_path_buf(),
            settings,
            camera,
            geometry,
            accel,
            materials,
            textures: self.textures,
            texture_names: self.texture_names,
            lights,
            warnings: self.warnings,
        })
    }

    fn settings(&self, r: &RenderDesc, o: &SceneOverrides) -> Result<RenderSettings> {
        let width = o.width.unwrap_or(r.width);
        let height = o.height.unwrap_or(r.height);
        let spp = o.spp.unwrap_or(r.spp);
        let max_depth = o.max_depth.unwrap_or(r.max_depth);
        let (side, pixels) = (limits::MAX_RENDER_SIDE, limits::MAX_RENDER_PIXELS);
        if width == 0 || height == 0 || width > side || height > side || width as u64 * height as u64 > pixels {
            return Err(Error::param(
                "render.width/height",
                format!("{width}x{height} is outside 1..={side} per side and {pixels} pixels (docs/limits.md)"),
            )
            .in_scene(self.path, "render"));
        }
        if spp == 0 || spp > limits::MAX_SPP {
            let msg = format!("{spp} is outside 1..={} (docs/limits.md)", limits::MAX_SPP);
            return Err(Error::param("render.spp", msg).in_scene(self.path, "render"));
        }
        let max_depth = match max_depth {
            -1 => None,
            d if (1..=i64::from(u32::MAX)).contains(&d) => Some(d as u32),
            d => {
                return Err(Error::param("render.max_depth", format!("{d}: use -1 (unlimited) or at least 1"))
                    .in_scene(self.path, "render"));
            }
        };
        let pixel_filter = match r.filter {
            PixelFilterDesc::Box => Ok(PixelFilter::Box),
            PixelFilterDesc::Gaussian { stddev } => PixelFilter::gaussian(stddev.unwrap_or(0.5)),
            PixelFilterDesc::Tent { radius } => PixelFilter::tent(radius.unwrap_or(1.0)),
        }
        .map_err(|msg| Error::param("render.filter", msg).in_scene(self.path, "render"))?;
        let seed = o.seed.unwrap_or(r.seed);
        Ok(RenderSettings { width, height, spp, max_depth, rr_depth: r.rr_depth, seed, pixel_filter })
    }

    fn texture(&mut self, name: &str, role: Role, item: &str) -> Result<TextureId> {
        let (texture, key) = self.build_texture(name, role, item)?;
        if let Some(id) = self.loaded_textures.get(&key) {
            return Ok(*id);
        }
        let id = self.add_texture(texture, format!("textures.{name}"));
        self.loaded_textures.insert(key, id);
        Ok(id)
    }

    /// The texture `name` as `role` uses it (built once per colour space), and its cache key.
    fn build_texture(&mut self, name: &str, role: Role, item: &str) -> Result<(Texture, (String, ColorSpace))> {
        let Some(desc) = self.texture_descs.get(name) else {
            return Err(self.error(format!(
                "{item}: unknown texture '{name}' (defined: {})",
                self.texture_descs.keys().cloned().collect::<Vec<_>>().join(", ")
            )));
        };
        let role_space = if role == Role::Color { ColorSpace::Srgb } else { ColorSpace::Linear };
        let space = match desc {
            TextureDesc::Image { colorspace, .. } | TextureDesc::QuadTiles { colorspace, .. } => {
                colorspace.unwrap_or(role_space)
            }
            TextureDesc::TilingBlending(_) | TextureDesc::Pups { .. } => role_space,
            TextureDesc::Checkerboard { .. } => ColorSpace::Linear,
        };
        let key = (name.to_string(), space);
        if let Some(t) = self.built_textures.get(&key) {
            return Ok((t.clone(), key));
        }
        if self.textures_in_progress.iter().any(|n| n == name) {
            return Err(self.error(format!(
                "textures.{name}: refers to itself (through {})",
                self.textures_in_progress.join(" -> ")
            )));
        }
        self.textures_in_progress.push(name.to_string());
        let is_synthesis = |n: &String| matches!(self.texture_descs.get(n), Some(TextureDesc::TilingBlending(_)));
        let nesting = self.textures_in_progress.iter().filter(|n| is_synthesis(n)).count();
        if nesting > limits::MAX_TILING_BLENDING_NESTING {
            let chain = self.textures_in_progress.join(" -> ");
            let limit = limits::MAX_TILING_BLENDING_NESTING;
            return Err(self.error(format!(
                "textures.{name}: tiling_blending textures nest {nesting} deep ({chain}), over tessera's limit of {limit} \
                 (docs/limits.md): each level triples the cost of a lookup"
            )));
        }
        let texture = match desc {
            TextureDesc::Image { filename, filter, scale, offset, .. } => {
                let file = self.resolve_path(filename);
                let bitmap =
                    read_bitmap(&file, space).map_err(|e| e.in_scene(self.path, format!("textures.{name}")))?;
                if !(scale.iter().chain(offset).all(|v| v.is_finite())) {
                    return Err(self.error(format!("textures.{name}: scale and offset must be finite")));
                }
                Texture::Image(ImageTexture {
                    mipmap: Arc::new(MipMap::new(bitmap)),
                    filter: *filter,
                    scale: Vec2::from(*scale),
                    offset: Vec2::from(*offset),
                })
            }
            TextureDesc::TilingBlending(d) => self.tiling_blending(name, d, role)?,
            TextureDesc::Pups {
                preset,
                points_file,
                labels,
                points,
                seed,
                tileable,
                epsilon,
                axis_scale,
                reference,
                density,
                scale,
                filter,
            } => {
                let defaults = PresetParams::default();
                let grey_image = |file: &Option<String>, key: &str| match file {
                    Some(file) => read_bitmap(&self.resolve_path(file), ColorSpace::Linear)
                        .map(Some)
                        .map_err(|e| e.in_scene(self.path, format!("textures.{name}.{key}"))),
                    None => Ok(None),
                };
                let reference = grey_image(reference, "reference")?;
                let density = grey_image(density, "density")?;
                let params = PresetParams {
                    points: points.unwrap_or(defaults.points),
                    seed: seed.unwrap_or(defaults.seed),
                    tileable: tileable.unwrap_or(defaults.tileable),
                    epsilon: epsilon.unwrap_or(defaults.epsilon),
                    axis_scale: axis_scale.unwrap_or(defaults.axis_scale),
                    reference,
                    density,
                };
                if !scale.iter().all(|v| v.is_finite()) {
                    return Err(self.error(format!("textures.{name}: scale must be finite")));
                }
                let texture = match (preset, points_file) {
                    (Some(_), None) if labels.is_some() => Err("labels applies to a points_file".into()),
                    (Some(preset), None) => PupsTexture::preset(*preset, &params),
                    (None, Some(_))
                        if points.is_some()
                            || seed.is_some()
                            || params.reference.is_some()
                            || params.density.is_some() =>
                    {
                        Err("points, seed, reference and density apply to presets, not to a points_file".into())
                    }
                    (None, Some(file)) => {
                        let file = self.resolve_path(file);
                        let control =
                            read_points(&file).map_err(|e| e.in_scene(self.path, format!("textures.{name}")))?;
                        PupsTexture::from_points(
                            control,
                            params.tileable,
                            params.axis_scale,
                            params.epsilon,
                            labels.unwrap_or(false),
                        )
                        .map_err(|msg| format!("{}: {msg}", file.display()))
                    }
                    _ => Err("give either a preset or a points_file".into()),
                }
                .map_err(|msg| self.error(format!("textures.{name}: {msg}")))?;
                Texture::Pups(PupsLookup { texture: Arc::new(texture), scale: Vec2::from(*scale), filter: *filter })
            }
            TextureDesc::Checkerboard { color0, color1, scale, offset } => {
                let color =
                    |c: &Option<RgbValue>, default: f32| Vec3::from(c.map_or([default; 3], |c| c.0)).extend(1.0);
                Texture::Checkerboard(Checkerboard {
                    color0: color(color0, 0.4),
                    color1: color(color1, 0.2),
                    scale: Vec2::from(*scale),
                    offset: Vec2::from(*offset),
                })
            }
            TextureDesc::QuadTiles { filename, conditions, filter, .. } => {
                let file = self.resolve_path(filename);
                let bitmap =
                    read_bitmap(&file, space).map_err(|e| e.in_scene(self.path, format!("textures.{name}")))?;
                let tiles = QuadTilesTexture::new(&bitmap, *conditions, *filter)
                    .map_err(|msg| self.error(format!("textures.{name}: {}: {msg}", file.display())))?;
                Texture::QuadTiles(tiles)
            }
        };
        self.textures_in_progress.pop();
        self.built_textures.insert(key.clone(), texture.clone());
        Ok((texture, key))
    }

    /// A tiling-and-blending texture: its synthesis (shared with `layer_of`) and its exemplar.
    fn tiling_blending(&mut self, name: &str, d: &TilingBlendingDesc, role: Role) -> Result<Texture> {
        let item = format!("textures.{name}");
        let synthesis = self.synthesis(name, d)?;
        // The sharpened operator weighs by the first layer's exemplar: share it when this is it.
        let exemplar = match &synthesis.blend {
            Blend::Sharpened { source, .. } if d.layer_of.is_none() && role == Role::Color => source.clone(),
            _ => Arc::new(self.build_texture(&d.exemplar, role, &format!("{item}.exemplar"))?.0),
        };
        let texture = TilingBlending::new(synthesis, exemplar).map_err(|msg| self.error(format!("{item}: {msg}")))?;
        Ok(Texture::TilingBlending(texture))
    }

    /// The synthesis of tiling-and-blending texture `name`, or of the texture it is a layer of.
    fn synthesis(&mut self, name: &str, d: &TilingBlendingDesc) -> Result<Arc<Synthesis>> {
        let item = format!("textures.{name}");
        if let Some(master) = &d.layer_of {
            let own = [
                ("tiling", d.tiling.is_some()),
                ("tile_size", d.tile_size.is_some()),
                ("seed", d.seed.is_some()),
                ("tileable", d.tileable.is_some()),
                ("blend", d.blend.is_some()),
                ("exponent", d.exponent.is_some()),
                ("luminance_contrast", d.luminance_contrast.is_some()),
                ("priority", d.priority.is_some()),
                ("lambda", d.lambda.is_some()),
                ("contrast", d.contrast.is_some()),
                ("deformation", d.deformation.is_some()),
                ("cuts", d.cuts.is_some()),
                ("field_at", d.field_at.is_some()),
            ];
            if let Some((key, _)) = own.iter().find(|(_, set)| *set) {
                return Err(
                    self.error(format!("{item}: a layer takes its {key} from '{master}' (layer_of); leave it out"))
                );
            }
            return match self.texture_descs.get(master.as_str()) {
                Some(TextureDesc::TilingBlending(m)) if m.layer_of.is_none() => self.synthesis(master, m),
                Some(TextureDesc::TilingBlending(_)) => {
                    Err(self.error(format!("{item}.layer_of: '{master}' is itself a layer; name its first layer")))
                }
                _ => Err(self.error(format!("{item}.layer_of: '{master}' is not a tiling_blending texture"))),
            };
        }
        if let Some(s) = self.syntheses.get(name) {
            return Ok(s.clone());
        }
        let tile_size = d.tile_size.unwrap_or(0.25);
        if !(tile_size > 1e-6 && tile_size <= 1e4) {
            return Err(self.error(format!("{item}.tile_size: {tile_size} is not in (1e-6, 1e4] UV units")));
        }
        let kind = d.blend.unwrap_or(BlendKind::Linear);
        let misplaced = [
            ("exponent", d.exponent.is_some(), BlendKind::Sharpened),
            ("luminance_contrast", d.luminance_contrast.is_some(), BlendKind::Sharpened),
            ("priority", d.priority.is_some(), BlendKind::MixMax),
            ("lambda", d.lambda.is_some(), BlendKind::MixMax),
            ("contrast", d.contrast.is_some(), BlendKind::MixMax),
        ];
        if let Some((key, _, needs)) = misplaced.iter().find(|(_, set, needs)| *set && *needs != kind) {
            return Err(self.error(format!("{item}.{key}: only used with blend = \"{}\"", blend_name(*needs))));
        }
        let blend = match kind {
            BlendKind::Linear => Blend::Linear,
            BlendKind::VariancePreserving => Blend::VariancePreserving,
            BlendKind::HistogramPreserving => Blend::HistogramPreserving,
            BlendKind::Sharpened => {
                let exponent = d.exponent.unwrap_or(7.0);
                let luminance_contrast = d.luminance_contrast.unwrap_or(0.6);
                if !(exponent > 0.0 && exponent <= 64.0) {
                    return Err(self.error(format!("{item}.exponent: {exponent} is not in (0, 64]")));
                }
                if !(0.0..=1.0).contains(&luminance_contrast) {
                    return Err(self.error(format!("{item}.luminance_contrast: {luminance_contrast} is not in [0, 1]")));
                }
                let source = Arc::new(self.build_texture(&d.exemplar, Role::Color, &format!("{item}.exemplar"))?.0);
                Blend::Sharpened { exponent, luminance_contrast, source }
            }
            BlendKind::MixMax => {
                let Some(priority) = &d.priority else {
                    return Err(
                        self.error(format!("{item}: blend = \"mix_max\" needs a priority map (priority = NAME)"))
                    );
                };
                let lambda = d.lambda.unwrap_or(0.05);
                if !(0.0..=1e3).contains(&lambda) {
                    return Err(self.error(format!("{item}.lambda: {lambda} is not in [0, 1000]")));
                }
                let Texture::Image(image) = self.build_texture(priority, Role::Data, &format!("{item}.priority"))?.0
                else {
                    return Err(self.error(format!("{item}.priority: '{priority}' must be an image texture")));
                };
                let contrast = d.contrast.unwrap_or(4.0);
                if !(contrast > 0.0 && contrast <= 1e3) {
                    return Err(self.error(format!("{item}.contrast: {contrast} is not in (0, 1000]")));
                }
                Blend::MixMax { priority: PriorityMap::new(&image), contrast, lambda }
            }
        };
        let deformation = match &d.deformation {
            None if d.field_at.is_some() => {
                return Err(self.error(format!("{item}.field_at: there is no deformation field to read")));
            }
            None => None,
            Some(factors) => {
                let factors = factors
                    .iter()
                    .enumerate()
                    .map(|(i, f)| self.deformation(f, &format!("{item}.deformation[{i}]")))
                    .collect::<Result<Vec<_>>>()?;
                let charts = self.chart_map(factors.as_slice(), &d.deformation, &item)?;
                let reach = d
                    .tiling
                    .unwrap_or(Tiling::Hexagonal)
                    .support_corners()
                    .iter()
                    .map(|c| c.length())
                    .fold(0.0, f32::max)
                    * tile_size;
                let charts = charts
                    .map(|map| Charts::new(&map, reach))
                    .transpose()
                    .map_err(|msg| self.error(format!("{item}.deformation: {msg}")))?;
                Some(DeformationField::new(factors).read_at(d.field_at.unwrap_or_default(), charts))
            }
        };
        let cuts = match &d.cuts {
            None => None,
            Some(filename) => {
                let file = self.resolve_path(filename);
                let item = format!("{item}.cuts");
                let f_map = deformation.as_ref().and_then(|d| d.map_texels()).ok_or_else(|| {
                    self.error(format!(
                        "{item}: cut bands need a deformation with a map factor (their lengths are in its units)"
                    ))
                })?;
                let text = crate::files::read_text_bounded(&file, limits::MAX_CUTS_FILE_BYTES, "a cuts file")
                    .map_err(|e| e.in_scene(self.path, &item))?;
                let bands = cuts_from_json(&text).and_then(|curves| CutBands::new(curves, f_map, tile_size));
                Some(bands.map_err(|msg| Error::mesh(&file, msg).in_scene(self.path, &item))?)
            }
        };
        let synthesis = Arc::new(Synthesis {
            tiling: d.tiling.unwrap_or(Tiling::Hexagonal),
            tile_size,
            seed: d.seed.unwrap_or(0),
            deformation,
            cuts,
            blend,
            inset: !d.tileable.unwrap_or(true),
        });
        self.syntheses.insert(name.to_string(), synthesis.clone());
        Ok(synthesis)
    }

    /// The chart map of a deformation's first F map factor (`charts`), checked against it: one
    /// channel, its size, whole numbers.
    fn chart_map(
        &self,
        factors: &[Deformation],
        descs: &Option<Vec<DeformationDesc>>,
        item: &str,
    ) -> Result<Option<crate::image::Bitmap>> {
        let Some(descs) = descs else { return Ok(None) };
        let Some((i, filename, f_map)) =
            descs.iter().zip(factors).enumerate().find_map(|(i, (desc, f))| match (desc, f) {
                (DeformationDesc::Map { charts: Some(file), .. }, Deformation::Map(map)) => {
                    Some((i, file, map.level(0)))
                }
                _ => None,
            })
        else {
            return Ok(None);
        };
        let item = format!("{item}.deformation[{i}].charts");
        let file = self.resolve_path(filename);
        let charts = read_bitmap_raw(&file, ColorSpace::Linear).map_err(|e| e.in_scene(self.path, &item))?;
        if charts.channels != 1 || (charts.width, charts.height) != (f_map.width, f_map.height) {
            let msg = format!(
                "a chart map needs one channel and the F map's size, {}x{}: found {}x{} with {} channels",
                f_map.width, f_map.height, charts.width, charts.height, charts.channels
            );
            return Err(Error::image(&file, msg).in_scene(self.path, &item));
        }
        if !charts.data.iter().all(|c| c.is_finite() && *c >= 0.0 && c.fract() == 0.0) {
            return Err(Error::image(&file, "chart numbers must be whole numbers >= 0").in_scene(self.path, &item));
        }
        Ok(Some(charts))
    }

    /// One factor of a deformation field.
    fn deformation(&self, f: &DeformationDesc, item: &str) -> Result<Deformation> {
        let finite = |values: &[f32]| values.iter().all(|v| v.is_finite());
        let bad = || self.error(format!("{item}: values must be finite numbers"));
        Ok(match f {
            DeformationDesc::Matrix { matrix: m } => {
                if !finite(m) {
                    return Err(bad());
                }
                Deformation::Constant(Mat2::from_cols(Vec2::new(m[0], m[2]), Vec2::new(m[1], m[3])))
            }
            DeformationDesc::Rotation { angle, gradient } => {
                if !finite(&[*angle, gradient[0], gradient[1]]) {
                    return Err(bad());
                }
                Deformation::Rotation { angle: angle.to_radians(), gradient: Vec2::from(*gradient) * (PI / 180.0) }
            }
            DeformationDesc::Scale { scale, gradient } => {
                let scale = match scale {
                    None => Vec2::ONE,
                    Some(ScaleValue::Uniform(s)) => Vec2::splat(*s),
                    Some(ScaleValue::PerAxis(s)) => Vec2::from(*s),
                };
                if !finite(&[scale.x, scale.y, gradient[0], gradient[1]]) || scale.x == 0.0 || scale.y == 0.0 {
                    return Err(self.error(format!("{item}: the scale must be finite and non-zero")));
                }
                Deformation::Scale { scale, gradient: Vec2::from(*gradient) }
            }
            DeformationDesc::Shear { shear, gradient } => {
                if !finite(&[*shear, gradient[0], gradient[1]]) {
                    return Err(bad());
                }
                Deformation::Shear { shear: *shear, gradient: Vec2::from(*gradient) }
            }
            DeformationDesc::Map { filename, .. } => {
                let file = self.resolve_path(filename);
                // Signed data: F maps have negative entries.
                let bitmap = read_bitmap_raw(&file, ColorSpace::Linear).map_err(|e| e.in_scene(self.path, item))?;
                if bitmap.channels != 4 {
                    return Err(Error::image(
                        &file,
                        format!("an F map needs 4 channels (F00, F01, F10, F11), found {}", bitmap.channels),
                    )
                    .in_scene(self.path, item));
                }
                if !finite(&bitmap.data) {
                    return Err(Error::image(&file, "the F map holds NaN or infinite values").in_scene(self.path, item));
                }
                Deformation::Map(MipMap::new(bitmap))
            }
        })
    }

    fn add_texture(&mut self, texture: Texture, name: String) -> TextureId {
        self.textures.push(texture);
        self.texture_names.push(name);
        TextureId(self.textures.len() as u32 - 1)
    }

    /// A reflectance or transmittance: a constant in [0, 1] (more would create energy), or a
    /// texture with a non-negative scale.
    fn color(&mut self, v: Option<&ColorValue>, default: f32, item: &str) -> Result<ColorParam> {
        Ok(match v {
            None => ColorParam::Value(Rgb::splat(default)),
            Some(ColorValue::Value(c)) if c.iter().any(|x| !(0.0..=1.0).contains(x)) => {
                return Err(self.error(format!("{item}: {c:?} is not a reflectance in [0, 1]")));
            }
            Some(ColorValue::Texture { scale, .. }) if scale.iter().any(|x| *x < 0.0) => {
                return Err(self.error(format!("{item}: the scale {scale:?} is negative")));
            }
            Some(ColorValue::Value(c)) => ColorParam::Value(Rgb::from(*c)),
            Some(ColorValue::Texture { name, scale }) => {
                ColorParam::Texture { id: self.texture(name, Role::Color, item)?, scale: Rgb::from(*scale) }
            }
        })
    }

    fn float(&mut self, v: &FloatValue, item: &str, valid: impl Fn(f32) -> bool, expected: &str) -> Result<FloatParam> {
        Ok(match v {
            FloatValue::Value(x) if !valid(*x) => {
                return Err(self.error(format!("{item}: {x} is not {expected}")));
            }
            FloatValue::Value(x) => FloatParam::Value(*x),
            FloatValue::Texture { name, channel, scale } => {
                FloatParam::Texture { id: self.texture(name, Role::Data, item)?, channel: *channel, scale: *scale }
            }
        })
    }

    fn roughness(
        &mut self,
        alpha: &Option<FloatValue>,
        alpha_u: &Option<FloatValue>,
        alpha_v: &Option<FloatValue>,
        item: &str,
    ) -> Result<Option<Roughness>> {
        let valid = |a: f32| (0.0..=10.0).contains(&a);
        let expected = "a roughness in [0, 10]";
        let (u, v) = match (alpha, alpha_u, alpha_v) {
            (None, None, None) => return Ok(None),
            (Some(a), None, None) => (a, a),
            (None, Some(u), Some(v)) => (u, v),
            (Some(_), _, _) => {
                return Err(self.error(format!("{item}: give either alpha or alpha_u and alpha_v")));
            }
            _ => return Err(self.error(format!("{item}: alpha_u and alpha_v must both be given"))),
        };
        Ok(Some(Roughness {
            alpha_u: self.float(u, &format!("{item}.alpha_u"), valid, expected)?,
            alpha_v: self.float(v, &format!("{item}.alpha_v"), valid, expected)?,
        }))
    }

    fn ior(&self, v: &Option<IorValue>, default: &str, item: &str) -> Result<f32> {
        let ior = match v {
            None => named_ior(default).expect("default IOR names are in the table"),
            Some(IorValue::Value(x)) => *x,
            Some(IorValue::Named(name)) => {
                named_ior(name).ok_or_else(|| self.error(format!("{item}: unknown IOR name '{name}'")))?
            }
        };
        if !(1.0..=MAX_IOR).contains(&ior) {
            return Err(
                self.error(format!("{item}: {ior} is not an index of refraction of a real material (1 to {MAX_IOR})"))
            );
        }
        Ok(ior)
    }

    fn relative_ior(
        &self,
        int: &Option<IorValue>,
        ext: &Option<IorValue>,
        int_default: &str,
        item: &str,
    ) -> Result<f32> {
        let int = self.ior(int, int_default, &format!("{item}.int_ior"))?;
        let ext = self.ior(ext, "air", &format!("{item}.ext_ior"))?;
        if int == ext {
            return Err(self.error(format!("{item}: int_ior and ext_ior must differ")));
        }
        Ok(int / ext)
    }

    fn normal_map(&mut self, name: &Option<String>, item: &str) -> Result<Option<TextureId>> {
        name.as_ref().map(|n| self.texture(n, Role::Data, &format!("{item}.normal_map"))).transpose()
    }

    fn material(&mut self, m: &MaterialDesc, item: &str) -> Result<Material> {
        let (kind, normal_map, two_sided) = match m {
            MaterialDesc::Diffuse { reflectance, two_sided, normal_map } => (
                MaterialKind::Diffuse {
                    reflectance: self.color(reflectance.as_ref(), 0.5, &format!("{item}.reflectance"))?,
                },
                normal_map,
                *two_sided,
            ),
            MaterialDesc::Conductor {
                alpha,
                alpha_u,
                alpha_v,
                material,
                eta,
                k,
                specular_reflectance,
                two_sided,
                normal_map,
            } => {
                let (eta, k) = match (material, eta, k) {
                    (Some(name), None, None) => named_conductor(name).ok_or_else(|| {
                        self.error(format!(
                            "{item}.material: unknown conductor '{name}' (known: {}; or give eta and k)",
                            crate::material::conductor_names()
                        ))
                    })?,
                    (None, Some(RgbValue(e)), Some(RgbValue(k))) => {
                        if !e.iter().all(|x| *x > 0.0 && *x <= MAX_IOR) || !k.iter().all(|x| (0.0..=100.0).contains(x))
                        {
                            return Err(self.error(format!(
                                "{item}: eta {e:?} and k {k:?} are not a conductor's (eta in (0, {MAX_IOR}], k in [0, 100])"
                            )));
                        }
                        (Rgb::from(*e), Rgb::from(*k))
                    }
                    (None, None, None) => named_conductor("none").expect("in the table"),
                    _ => return Err(self.error(format!("{item}: give either material or both eta and k"))),
                };
                let roughness = self.roughness(alpha, alpha_u, alpha_v, item)?;
                let specular_reflectance =
                    self.color(specular_reflectance.as_ref(), 1.0, &format!("{item}.specular_reflectance"))?;
                (MaterialKind::Conductor { roughness, eta, k, specular_reflectance }, normal_map, *two_sided)
            }
            MaterialDesc::Dielectric {
                alpha,
                alpha_u,
                alpha_v,
                int_ior,
                ext_ior,
                specular_reflectance,
                specular_transmittance,
                normal_map,
            } => {
                let eta = self.relative_ior(int_ior, ext_ior, "bk7", item)?;
                let roughness = self.roughness(alpha, alpha_u, alpha_v, item)?;
                let specular_reflectance =
                    self.color(specular_reflectance.as_ref(), 1.0, &format!("{item}.specular_reflectance"))?;
                let specular_transmittance =
                    self.color(specular_transmittance.as_ref(), 1.0, &format!("{item}.specular_transmittance"))?;
                (
                    MaterialKind::Dielectric { roughness, eta, specular_reflectance, specular_transmittance },
                    normal_map,
                    false,
                )
            }
            MaterialDesc::Plastic {
                diffuse_reflectance,
                specular_reflectance,
                alpha,
                int_ior,
                ext_ior,
                two_sided,
                normal_map,
            } => {
                let eta = self.relative_ior(int_ior, ext_ior, "polypropylene", item)?;
                let alpha = alpha.unwrap_or(0.1);
                if !(alpha > 0.0 && alpha <= 10.0) {
                    return Err(self.error(format!("{item}.alpha: {alpha} is not in (0, 10]")));
                }
                let tables = self
                    .plastic_tables
                    .entry((eta.to_bits(), alpha.to_bits()))
                    .or_insert_with(|| Arc::new(PlasticTables::new(eta, &[alpha])))
                    .clone();
                let diffuse_reflectance =
                    self.color(diffuse_reflectance.as_ref(), 0.5, &format!("{item}.diffuse_reflectance"))?;
                let specular_reflectance =
                    self.color(specular_reflectance.as_ref(), 1.0, &format!("{item}.specular_reflectance"))?;
                (
                    MaterialKind::Plastic { diffuse_reflectance, specular_reflectance, alpha, tables },
                    normal_map,
                    *two_sided,
                )
            }
            MaterialDesc::Pbr {
                base_color,
                metallic,
                roughness,
                occlusion,
                anisotropy,
                anisotropy_direction,
                two_sided,
                normal_map,
            } => {
                let base_color = self.color(base_color.as_ref(), 1.0, &format!("{item}.base_color"))?;
                // The scalar parameters of pbr all lie in [0, 1].
                let mut unit = |value: &Option<FloatValue>, default: f32, key: &str| {
                    let fallback = FloatValue::Value(default);
                    let value = value.as_ref().unwrap_or(&fallback);
                    self.float(value, &format!("{item}.{key}"), |x| (0.0..=1.0).contains(&x), "in [0, 1]")
                };
                let metallic = unit(metallic, 1.0, "metallic")?;
                let roughness = unit(roughness, 1.0, "roughness")?;
                let occlusion = unit(occlusion, 1.0, "occlusion")?;
                let anisotropy = unit(anisotropy, 0.0, "anisotropy")?;
                let anisotropy_direction = anisotropy_direction
                    .as_ref()
                    .map(|n| self.texture(n, Role::Data, &format!("{item}.anisotropy_direction")))
                    .transpose()?;
                let kind = MaterialKind::Pbr {
                    base_color,
                    metallic,
                    roughness,
                    occlusion,
                    anisotropy,
                    anisotropy_direction,
                    tables: pbr_tables(),
                };
                (kind, normal_map, *two_sided)
            }
        };
        let normal_map = self.normal_map(normal_map, item)?;
        let mut material = Material { name: item.to_string(), kind, normal_map, two_sided, texture_frame: None };
        material.texture_frame = self.texture_frame(&material, item)?;
        Ok(material)
    }

    /// The texture whose deformation field orients the material's frame: its deformed
    /// tiling-and-blending textures must share one synthesis (be layers of one texture).
    fn texture_frame(&self, material: &Material, item: &str) -> Result<Option<TextureId>> {
        let deformed: Vec<(TextureId, &Arc<Synthesis>)> = material
            .textures()
            .into_iter()
            .filter_map(|id| match &self.textures[id.0 as usize] {
                Texture::TilingBlending(t) if t.synthesis.deformation.is_some() => Some((id, &t.synthesis)),
                _ => None,
            })
            .collect();
        if deformed.windows(2).any(|w| !Arc::ptr_eq(w[0].1, w[1].1)) {
            return Err(self.error(format!(
                "{item}: its textures have different deformation fields, but the material's frame follows one: \
                 make them layers of one tiling_blending texture (layer_of)"
            )));
        }
        Ok(deformed.first().map(|d| d.0))
    }

    fn transform(&self, steps: &[TransformStep], item: &str) -> Result<Mat4> {
        let mut m = Mat4::IDENTITY;
        for (i, s) in steps.iter().enumerate() {
            let here = format!("{item}.transform[{i}]");
            let given =
                [s.translate.is_some(), s.scale.is_some(), s.rotate.is_some(), s.lookat.is_some(), s.matrix.is_some()];
            if given.iter().filter(|g| **g).count() != 1 || (s.angle.is_some() != s.rotate.is_some()) {
                return Err(self.error(format!(
                    "{here}: give exactly one of translate, scale, rotate (with angle), lookat or matrix"
                )));
            }
            let step = if let Some(t) = s.translate {
                Mat4::from_translation(Vec3::from(t))
            } else if let Some(RgbValue(sc)) = s.scale {
                Mat4::from_scale(Vec3::from(sc))
            } else if let (Some(axis), Some(angle)) = (s.rotate, s.angle) {
                let axis = Vec3::from(axis)
                    .try_normalize()
                    .ok_or_else(|| self.error(format!("{here}: zero rotation axis")))?;
                Mat4::from_axis_angle(axis, angle.to_radians())
            } else if let Some(l) = &s.lookat {
                mitsuba_look_at(Vec3::from(l.origin), Vec3::from(l.target), Vec3::from(l.up.unwrap_or([0.0, 1.0, 0.0])))
                    .ok_or_else(|| self.error(format!("{here}: origin, target and up do not define a frame")))?
            } else {
                Mat4::from_cols_array(&s.matrix.expect("checked above")).transpose()
            };
            m = step * m;
        }
        if !m.is_finite() || m.determinant().abs() < 1e-20 {
            return Err(self.error(format!("{item}.transform: the transform is singular or not finite")));
        }
        Ok(m)
    }

    /// Refuse keys that `shape`'s kind does not take, and a missing filename.
    fn check_shape_keys(&self, shape: &ShapeDesc, item: &str) -> Result<()> {
        let needs_file =
            matches!(shape.kind, ShapeKind::Obj | ShapeKind::Ply | ShapeKind::Serialized | ShapeKind::Gltf);
        if needs_file != shape.filename.is_some() {
            return Err(self.error(if needs_file {
                format!("{item}: a {:?} shape needs a filename", shape.kind).to_lowercase()
            } else {
                format!("{item}: only obj, ply, serialized and gltf shapes take a filename")
            }));
        }
        if shape.kind != ShapeKind::Serialized && shape.shape_index.is_some() {
            return Err(self.error(format!("{item}: shape_index applies to serialized only")));
        }
        if shape.kind != ShapeKind::UvSphere && (shape.segments.is_some() || shape.rings.is_some()) {
            return Err(self.error(format!("{item}: segments and rings apply to uv_sphere only")));
        }
        if shape.kind != ShapeKind::Sphere && (shape.center.is_some() || shape.radius.is_some()) {
            return Err(self.error(format!("{item}: center and radius apply to sphere only")));
        }
        if shape.kind != ShapeKind::Gltf && (shape.lights.is_some() || shape.light_scale.is_some()) {
            return Err(self.error(format!("{item}: lights and light_scale apply to gltf shapes only")));
        }
        Ok(())
    }

    /// The meshes of a shape, each with the material it brings (glTF) if any; a glTF file's
    /// punctual lights are added to `file_lights`, in the file's space.
    fn shape_meshes(
        &mut self,
        shape: &ShapeDesc,
        item: &str,
        materials: &mut Vec<Material>,
        file_lights: &mut Lights,
    ) -> Result<Vec<(TriangleMesh, Option<u32>)>> {
        Ok(match shape.kind {
            ShapeKind::Obj => {
                let file = self.resolve_path(shape.filename.as_deref().expect("checked"));
                vec![(obj::load_obj(&file).map_err(|e| e.in_scene(self.path, item))?, None)]
            }
            ShapeKind::Ply => {
                let file = self.resolve_path(shape.filename.as_deref().expect("checked"));
                vec![(ply::load_ply(&file).map_err(|e| e.in_scene(self.path, item))?, None)]
            }
            ShapeKind::Serialized => {
                let file = self.resolve_path(shape.filename.as_deref().expect("checked"));
                let mesh = serialized::load_serialized(&file, shape.shape_index.unwrap_or(0));
                vec![(mesh.map_err(|e| e.in_scene(self.path, item))?, None)]
            }
            ShapeKind::Gltf => {
                let file = self.resolve_path(shape.filename.as_deref().expect("checked"));
                let scale = shape.light_scale.unwrap_or(1.0 / super::gltf::LUMENS_PER_WATT);
                if !(0.0..=MAX_RADIANCE).contains(&scale) {
                    return Err(self.error(format!("{item}.light_scale: {scale} is outside [0, {MAX_RADIANCE:e}]")));
                }
                let light_scale = shape.lights.unwrap_or(true).then_some(scale);
                let import = super::gltf::import_meshes(
                    &file,
                    (&mut self.textures, &mut self.texture_names),
                    materials,
                    pbr_tables,
                    light_scale,
                )
                .map_err(|e| e.in_scene(self.path, item))?;
                *file_lights = import.lights;
                self.warnings
                    .extend(import.warnings.into_iter().map(|w| format!("{}: {item}: {w}", self.path.display())));
                import.meshes
            }
            ShapeKind::Sphere => unreachable!("spheres are not meshes"),
            ShapeKind::Rectangle => vec![(shapes::rectangle(), None)],
            ShapeKind::Cube => vec![(shapes::cube(), None)],
            ShapeKind::UvSphere => {
                let (segments, rings) = (shape.segments.unwrap_or(64), shape.rings.unwrap_or(32));
                let most = limits::MAX_SPHERE_SEGMENTS;
                if !(3..=most).contains(&segments) || !(2..=most).contains(&rings) {
                    return Err(
                        self.error(format!("{item}: a uv_sphere needs 3..={most} segments and 2..={most} rings"))
                    );
                }
                let triangles = 2 * segments as u64 * rings as u64;
                if triangles > limits::MAX_TRIANGLES {
                    let msg =
                        limits::exceeded("its triangle count (2 segments rings)", triangles, limits::MAX_TRIANGLES);
                    return Err(self.error(format!("{item}: {msg}")));
                }
                vec![(shapes::uv_sphere(segments, rings), None)]
            }
        })
    }

    fn environment(&mut self, env: &EnvironmentDesc) -> Result<Environment> {
        Ok(match env {
            EnvironmentDesc::Constant { radiance: RgbValue(c) } => {
                if c.iter().any(|v| !(0.0..=MAX_RADIANCE).contains(v)) {
                    return Err(self.error(format!("environment.radiance: {c:?} is outside [0, {MAX_RADIANCE:e}]")));
                }
                Environment::Constant(Rgb::from(*c))
            }
            EnvironmentDesc::Envmap { filename, scale } => {
                if !(0.0..=MAX_RADIANCE).contains(scale) {
                    return Err(self.error(format!("environment.scale: {scale} is outside [0, {MAX_RADIANCE:e}]")));
                }
                let file = self.resolve_path(filename);
                let image = read_bitmap(&file, ColorSpace::Linear).map_err(|e| e.in_scene(self.path, "environment"))?;
                Environment::Map(EnvironmentMap::new(image, *scale))
            }
        })
    }

    fn camera(&self, c: &CameraDesc, s: &RenderSettings) -> Result<Camera> {
        let placed_by = [c.eye.is_some() || c.target.is_some(), c.matrix.is_some(), c.gltf.is_some()];
        if placed_by.iter().filter(|p| **p).count() != 1 {
            return Err(self.error("camera: place it with exactly one of eye/target, matrix or gltf"));
        }
        if c.index.is_some() && c.gltf.is_none() {
            return Err(self.error("camera.index applies to a gltf camera only"));
        }
        let (to_world, from_file) = if let Some(file) = &c.gltf {
            let path = self.resolve_path(file);
            let (m, projection, znear) =
                super::gltf::import_camera(&path, c.index.unwrap_or(0)).map_err(|e| e.in_scene(self.path, "camera"))?;
            (m, Some((projection, znear)))
        } else if let Some(m) = c.matrix {
            (Mat4::from_cols_array(&m).transpose(), None)
        } else {
            let (Some(eye), Some(target)) = (c.eye, c.target) else {
                return Err(self.error("camera: eye and target must both be given"));
            };
            let up = Vec3::from(c.up.unwrap_or([0.0, 1.0, 0.0]));
            (
                Camera::look_at(Vec3::from(eye), Vec3::from(target), up)
                    .map_err(|e| e.in_scene(self.path, "camera"))?,
                None,
            )
        };
        let file_projection = from_file.map(|(p, _)| p);
        let kind = c.projection.unwrap_or(match file_projection {
            Some(Projection::Orthographic { .. }) => ProjectionKind::Orthographic,
            _ => ProjectionKind::Perspective,
        });
        let axis = c.fov_axis.unwrap_or(FovAxis::Y);
        let projection = match kind {
            ProjectionKind::Perspective => {
                if c.extent.is_some() {
                    return Err(self.error("camera.extent applies to an orthographic camera (use fov)"));
                }
                match (c.fov, file_projection) {
                    (Some(fov), _) => Projection::Perspective { fov, axis },
                    (None, Some(p @ Projection::Perspective { .. })) => p,
                    _ => return Err(self.error("camera.fov is required (degrees)")),
                }
            }
            ProjectionKind::Orthographic => {
                if c.fov.is_some() {
                    return Err(self.error("camera.fov applies to a perspective camera (use extent)"));
                }
                match (c.extent, file_projection) {
                    (Some(extent), _) => Projection::Orthographic { extent, axis },
                    (None, Some(p @ Projection::Orthographic { .. })) => p,
                    _ => {
                        return Err(self.error(
                            "camera.extent is required for an orthographic camera (the image's size in world units along fov_axis)",
                        ));
                    }
                }
            }
        };
        let lens = match (c.aperture_radius, c.focus_distance) {
            (Some(aperture_radius), Some(focus_distance)) => Some(ThinLens { aperture_radius, focus_distance }),
            (None, None) => None,
            _ => return Err(self.error("camera: a thin lens needs both aperture_radius and focus_distance")),
        };
        let near_clip = c.near_clip.or(from_file.map(|(_, znear)| znear)).unwrap_or(0.0);
        let model = CameraModel { projection, lens, near_clip };
        Camera::new(to_world, model, s.width, s.height, s.spp).map_err(|e| e.in_scene(self.path, "camera"))
    }
}

/// Mitsuba's `lookat` transform: local +z towards `target`, local x = normalize(up x z).
pub(super) fn mitsuba_look_at(origin: Vec3, target: Vec3, up: Vec3) -> Option<Mat4> {
    let dir = (target - origin).try_normalize()?;
    let left = up.cross(dir).try_normalize()?;
    let new_up = dir.cross(left);
    Some(Mat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0)))
}

/// The scene-file name of a blending operator.
/// The material a shape renders with: its own (`chosen`), or the scene's default for plain
/// shapes or for emitters, made the first time one is needed (`defaults` holds them).
fn material_or_default(
    defaults: &mut [Option<u32>; 2],
    materials: &mut Vec<Material>,
    chosen: Option<u32>,
    emits: bool,
) -> u32 {
    chosen.unwrap_or_else(|| {
        *defaults[usize::from(emits)].get_or_insert_with(|| {
            materials.push(Material::default_diffuse(emits));
            materials.len() as u32 - 1
        })
    })
}

fn blend_name(kind: BlendKind) -> &'static str {
    match kind {
        BlendKind::Linear => "linear",
        BlendKind::VariancePreserving => "variance_preserving",
        BlendKind::HistogramPreserving => "histogram_preserving",
        BlendKind::Sharpened => "sharpened",
        BlendKind::MixMax => "mix_max",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{ColorParam, MaterialKind};

    #[test]
    fn default_materials_follow_mitsuba() {
        // A shape without a material is diffuse 0.5; an emitter without one is black (Mitsuba 3's
        // `Shape::Shape`), so that it adds no reflected light.
        let scene = load_scene_str(
            "[camera]\nfov = 30\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n\
             [[shapes]]\ntype = \"cube\"\n[[shapes]]\ntype = \"rectangle\"\nemission = 1\n",
            Path::new("inline.toml"),
            &SceneOverrides::default(),
        )
        .unwrap();
        let reflectance = |shape: usize| match scene.materials[scene.geometry.shapes[shape].material as usize].kind {
            MaterialKind::Diffuse { reflectance: ColorParam::Value(c) } => c,
            ref other => panic!("{other:?}"),
        };
        assert_eq!(reflectance(0), Rgb::splat(0.5));
        assert_eq!(reflectance(1), Rgb::ZERO);
    }
}
