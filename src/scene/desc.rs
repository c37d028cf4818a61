//! The scene file format (TOML), as serde types. `docs/scene-format.md` is the user's
//! reference; every struct rejects unknown fields so that a typo is an error, not a default.

use crate::camera::FovAxis;
use crate::image::ColorSpace;
use crate::texture::{Channel, Filter};
use serde::Deserialize;
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use std::collections::BTreeMap;
use std::fmt;

/// A whole scene file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    /// Image and integrator settings.
    #[serde(default)]
    pub render: RenderDesc,
    /// The camera.
    pub camera: CameraDesc,
    /// Light from infinitely far away.
    pub environment: Option<EnvironmentDesc>,
    /// Point, spot, directional lights and suns.
    #[serde(default)]
    pub lights: Vec<LightDesc>,
    /// Named textures.
    #[serde(default)]
    pub textures: BTreeMap<String, TextureDesc>,
    /// Named materials.
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialDesc>,
    /// Geometry.
    #[serde(default)]
    pub shapes: Vec<ShapeDesc>,
}

/// `[render]`: image size, sampling and path length.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderDesc {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path in segments, as Mitsuba counts (1: emitters only, 2: direct light); -1 for
    /// no limit (Russian roulette ends paths).
    pub max_depth: i64,
    /// Path depth from which Russian roulette applies.
    pub rr_depth: u32,
    /// Seed of the sampler.
    pub seed: u64,
    /// The pixel reconstruction filter (default `box`).
    pub filter: PixelFilterDesc,
}

impl Default for RenderDesc {
    fn default() -> Self {
        RenderDesc {
            width: 512,
            height: 512,
            spp: 16,
            max_depth: -1,
            rr_depth: 5,
            seed: 0,
            filter: PixelFilterDesc::Box,
        }
    }
}

/// `[render.filter]`: Mitsuba's reconstruction filters.
#[derive(Clone, Copy, Debug, Default, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum PixelFilterDesc {
    /// Each pixel the mean over its square.
    #[default]
    Box,
    /// Mitsuba's `gaussian` (its default filter).
    Gaussian {
        /// Standard deviation in pixels (default 0.5, Mitsuba's); the radius is 4 stddev.
        stddev: Option<f32>,
    },
    /// Mitsuba's `tent`.
    Tent {
        /// Radius in pixels (default 1).
        radius: Option<f32>,
    },
}

/// `[camera]`: a perspective or orthographic camera, placed by eye/target/up, a matrix, or a
/// glTF file's camera.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// `perspective` (default, or the glTF camera's) or `orthographic`.
    pub projection: Option<ProjectionKind>,
    /// Perspective: field of view in degrees along `fov_axis`.
    pub fov: Option<f32>,
    /// Orthographic: the image's size along `fov_axis` in world units.
    pub extent: Option<f32>,
    /// Which axis `fov` or `extent` spans (default y).
    pub fov_axis: Option<FovAxis>,
    /// Thin lens: radius of the aperture (with `focus_distance`; default none, a pinhole).
    pub aperture_radius: Option<f32>,
    /// Thin lens: distance of the plane in focus along the view axis.
    pub focus_distance: Option<f32>,
    /// Distance along the view axis where rays start (default 0, or a glTF camera's znear).
    pub near_clip: Option<f32>,
    /// Camera position.
    pub eye: Option<[f32; 3]>,
    /// Point the camera looks at.
    pub target: Option<[f32; 3]>,
    /// Up direction (default +y).
    pub up: Option<[f32; 3]>,
    /// Camera-to-world matrix, row-major (camera looks down its local -z).
    pub matrix: Option<[f32; 16]>,
    /// Take the camera from this glTF file.
    pub gltf: Option<String>,
    /// Which of the glTF file's camera nodes (default the first).
    pub index: Option<usize>,
}

/// Camera projections.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProjectionKind {
    /// Rays from one point (or a thin lens).
    Perspective,
    /// Parallel rays.
    Orthographic,
}

/// `[environment]`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum EnvironmentDesc {
    /// The same radiance from every direction.
    Constant {
        /// Radiance (a number or [r, g, b]).
        radiance: RgbValue,
    },
    /// An equirectangular map (EXR or HDR).
    Envmap {
        /// Image file.
        filename: String,
        /// Radiance multiplier (default 1).
        #[serde(default = "one")]
        scale: f32,
    },
}

fn one() -> f32 {
    1.0
}

/// `[[lights]]`: lights that are not shapes. Parameter names follow Mitsuba 3's emitters.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LightDesc {
    /// Light leaving one point equally in all directions (`point`).
    Point {
        /// Where it is.
        position: [f32; 3],
        /// Radiant intensity, W/sr (a number or [r, g, b]).
        intensity: RgbValue,
    },
    /// A point light limited to a cone (`spot`).
    Spot {
        /// Where it is.
        position: [f32; 3],
        /// The cone's axis (or give `target`).
        direction: Option<[f32; 3]>,
        /// A point on the cone's axis (or give `direction`).
        target: Option<[f32; 3]>,
        /// Radiant intensity on the axis, W/sr.
        intensity: RgbValue,
        /// Half-angle in degrees beyond which no light leaves (default 20).
        cutoff_angle: Option<f32>,
        /// Half-angle in degrees within which the intensity is full (default 3/4 of the cutoff).
        beam_width: Option<f32>,
        /// `mitsuba` (linear in the angle between beam and cutoff; default) or `gltf` (glTF's
        /// squared ramp in the cosine).
        falloff: Option<SpotFalloffDesc>,
    },
    /// Parallel light from infinitely far away (`directional`).
    Directional {
        /// The direction the light travels.
        direction: [f32; 3],
        /// Irradiance on a surface facing the light, W/m^2.
        irradiance: RgbValue,
    },
    /// A disc of constant radiance infinitely far away, casting soft shadows.
    Sun {
        /// The direction the light travels (from the sun towards the scene).
        direction: [f32; 3],
        /// Irradiance on a surface facing the sun, W/m^2.
        irradiance: RgbValue,
        /// Angular diameter of the disc in degrees (default 0.533, the sun's as seen from Earth).
        angular_diameter: Option<f32>,
    },
}

/// Spot falloff profiles by the renderer that defines them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpotFalloffDesc {
    /// Mitsuba 3's `spot`.
    Mitsuba,
    /// glTF's `KHR_lights_punctual`.
    Gltf,
}

fn unit_scale() -> [f32; 2] {
    [1.0, 1.0]
}

/// `[textures.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TextureDesc {
    /// An image file (PNG, JPEG, HDR, EXR).
    Image {
        /// Image file.
        filename: String,
        /// Lookup filter (default `none`: bilinear at the point).
        #[serde(default)]
        filter: Filter,
        /// How integer values encode colour; by default sRGB where the texture feeds a colour
        /// and linear where it feeds a scalar or a normal map.
        colorspace: Option<ColorSpace>,
        /// Multiplier of the texture coordinates (default [1, 1]).
        #[serde(default = "unit_scale")]
        scale: [f32; 2],
        /// Offset added to the scaled texture coordinates (default [0, 0]).
        #[serde(default)]
        offset: [f32; 2],
    },
    /// Tiling and blending of an exemplar, optionally deformed (paper 000 Sec. 3).
    TilingBlending(Box<TilingBlendingDesc>),
    /// A partition-of-unity parametric texture (paper 002): a named preset of Sec. 3, or
    /// control points from a file, evaluated at every lookup.
    Pups {
        /// The preset (`noise`, `octaves`, `turbulence`, `cells`, `clustered-cells`,
        /// `multiscale-cells`, `cow`, `space-giraffe`, `reference-labels`, `iterative`,
        /// `progressive-cow`, `progressive-giraffe`, `label-ramp`); or `points_file`.
        preset: Option<crate::pups::Preset>,
        /// Control points from a CSV or JSON file instead of a preset.
        points_file: Option<String>,
        /// With `points_file`: show each label's colour where its points weigh most (cells)
        /// instead of blending the values (default false).
        labels: Option<bool>,
        /// About how many control points its base layer has over the unit square (default 700).
        points: Option<u32>,
        /// Seed of the points and their attributes (default 0).
        seed: Option<u64>,
        /// Whether the texture tiles (a periodic domain; default false).
        tileable: Option<bool>,
        /// Orientation strength of Eq. 4 (default 0.5).
        epsilon: Option<f32>,
        /// Axis length scale of Fig. 4 (default 1).
        axis_scale: Option<f32>,
        /// A grey reference image for `reference-labels` and `iterative`.
        reference: Option<String>,
        /// A grey density image: the points' spacing from twice the base (black) to half
        /// (white), for presets without their own density ramp.
        density: Option<String>,
        /// Multiplier of the texture coordinates (default [1, 1]; a tileable texture repeats).
        #[serde(default = "unit_scale")]
        scale: [f32; 2],
        /// `none` (the value at the point, default) or `supersample` (the mean over the
        /// lookup's footprint).
        #[serde(default)]
        filter: crate::pups::PupsFilter,
    },
    /// Mitsuba's checkerboard: `color0` and `color1` alternating over cells of side 1/2.
    Checkerboard {
        /// Colour of the cells where both half-period tests agree (linear RGB; default 0.4).
        color0: Option<RgbValue>,
        /// Colour of the others (default 0.2).
        color1: Option<RgbValue>,
        /// Multiplier of the texture coordinates (default [1, 1]).
        #[serde(default = "unit_scale")]
        scale: [f32; 2],
        /// Offset added to the scaled texture coordinates (default [0, 0]).
        #[serde(default)]
        offset: [f32; 2],
    },
    /// A tile image written by `tessera tiles synth` (paper 001), for a quad mesh whose
    /// texture coordinates `tessera tiles map` assigned: each lookup filters one tile only.
    QuadTiles {
        /// The tile image.
        filename: String,
        /// Its number of boundary conditions (default 1: 16 tiles).
        #[serde(default = "one_condition")]
        conditions: u32,
        /// Lookup filter (default `none`: bilinear at the point).
        #[serde(default)]
        filter: Filter,
        /// How integer values encode colour (as for `image`).
        colorspace: Option<ColorSpace>,
    },
}

fn one_condition() -> u32 {
    1
}

/// `type = "tiling_blending"`: an exemplar read through tiles, shifts, a deformation field and
/// a blending operator. A layer (`layer_of`) takes all of those from another such texture.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TilingBlendingDesc {
    /// The exemplar: the name of another texture (usually an image).
    pub exemplar: String,
    /// Name of a tiling_blending texture whose tiles, shifts, deformation and weights this one
    /// shares (the layers of a PBR material); the synthesis keys below must then be left out.
    pub layer_of: Option<String>,
    /// `hexagonal` (k = 3, default) or `square` (k = 4).
    pub tiling: Option<crate::texture::tiling_blending::Tiling>,
    /// Lattice spacing in UV units (default 0.25).
    pub tile_size: Option<f32>,
    /// Seed of the tiles' shifts (default 0).
    pub seed: Option<u64>,
    /// Whether the exemplar tiles (default true): if false, each tile's shift keeps it inside
    /// the exemplar where it fits, so that its borders never show.
    pub tileable: Option<bool>,
    /// Blending operator (default `linear`).
    pub blend: Option<BlendKind>,
    /// `sharpened`: power on the paving's weights (default 7).
    pub exponent: Option<f32>,
    /// `sharpened`: weight of the tiles' luminance in [0, 1] (default 0.6).
    pub luminance_contrast: Option<f32>,
    /// `mix_max`: the priority map (an image texture's name).
    pub priority: Option<String>,
    /// `mix_max`: spread of sub-footprint priorities (default 0.05; 0 cuts sharply).
    pub lambda: Option<f32>,
    /// `mix_max`: factor on the priorities against the tiles' weights (default 4).
    pub contrast: Option<f32>,
    /// The deformation field F as a product of factors, F = F_1 F_2 ... (default: none, which
    /// is classical tiling and blending).
    pub deformation: Option<Vec<DeformationDesc>>,
    /// A cuts file written by `tessera deform` (`cuts.json`): near each UV cut a row of tiles
    /// laid along it, read alike from both sides, so that the texture continues across the cut
    /// (DESIGN.md section 6). Needs a `map` factor in `deformation`.
    pub cuts: Option<String>,
    /// Where each tile reads the deformation field: `point` (F(u), the paper's Eq. 3; default)
    /// or `tile_centre` (F(c_i): each tile affine, never folding).
    pub field_at: Option<crate::texture::tiling_blending::FieldAt>,
}

/// A scale: one number for both axes, or [along u, along v].
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(untagged, expecting = "a number or [along u, along v]")]
pub enum ScaleValue {
    /// The same on both axes.
    Uniform(f32),
    /// Per axis.
    PerAxis([f32; 2]),
}

/// Blending operators of tiling and blending.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BlendKind {
    /// Weighted sum with the paving's weights.
    Linear,
    /// Heitz-Neyret's variance-preserving operator.
    VariancePreserving,
    /// Variance-preserving on the Gaussianized exemplar, then its inverse histogram transform.
    HistogramPreserving,
    /// Mikkelsen's sharpened, luminance-weighted weights.
    Sharpened,
    /// Fournier-Sauvage's Mix-Max with a priority map.
    MixMax,
}

/// One factor of a deformation field F (maps UV offsets to exemplar offsets; F = s I shows the
/// pattern 1/s as large).
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum DeformationDesc {
    /// A constant matrix, row-major [F00, F01, F10, F11].
    Matrix {
        /// The matrix.
        matrix: [f32; 4],
    },
    /// A rotation by angle + gradient . uv degrees.
    Rotation {
        /// Angle at uv = (0, 0), degrees (default 0).
        #[serde(default)]
        angle: f32,
        /// Degrees per UV unit along u and v (default [0, 0]).
        #[serde(default)]
        gradient: [f32; 2],
    },
    /// A scaling diag(scale) 2^(gradient . uv).
    Scale {
        /// Scale at uv = (0, 0): a number or [along u, along v] (default 1).
        scale: Option<ScaleValue>,
        /// Change of log2(scale) per UV unit along u and v (default [0, 0]).
        #[serde(default)]
        gradient: [f32; 2],
    },
    /// A shear [[1, k], [0, 1]], k = shear + gradient . uv.
    Shear {
        /// Shear at uv = (0, 0) (default 0).
        #[serde(default)]
        shear: f32,
        /// Change of the shear per UV unit along u and v (default [0, 0]).
        #[serde(default)]
        gradient: [f32; 2],
    },
    /// An F map: a 4-channel EXR (F00, F01, F10, F11), bilinear.
    Map {
        /// The EXR file.
        filename: String,
        /// Its UV charts, a one-channel image of chart numbers of the same size (`charts.exr`
        /// from `tessera deform`): where tiles read F at their centres, a centre in another chart
        /// than the point reads F at the point instead.
        charts: Option<String>,
    },
}

/// `[materials.NAME]`. Parameter names and defaults follow Mitsuba 3's plugins.
#[derive(Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum MaterialDesc {
    /// Lambertian (`diffuse`).
    Diffuse {
        /// Albedo (default 0.5).
        reflectance: Option<ColorValue>,
        /// Scatter from the back side as from the front.
        #[serde(default)]
        two_sided: bool,
        /// Tangent-space normal map texture.
        normal_map: Option<String>,
    },
    /// Metal (`conductor` when no roughness is given, else `roughconductor`).
    Conductor {
        /// Isotropic GGX roughness.
        alpha: Option<FloatValue>,
        /// GGX roughness along the tangent (dp/du).
        alpha_u: Option<FloatValue>,
        /// GGX roughness along the bitangent.
        alpha_v: Option<FloatValue>,
        /// Named conductor (`Al`, or `none` for a perfect mirror); default `none` unless eta/k.
        material: Option<String>,
        /// Real part of the IOR.
        eta: Option<RgbValue>,
        /// Imaginary part of the IOR.
        k: Option<RgbValue>,
        /// Factor on the reflectance (default 1).
        specular_reflectance: Option<ColorValue>,
        /// Scatter from the back side as from the front.
        #[serde(default)]
        two_sided: bool,
        /// Tangent-space normal map texture.
        normal_map: Option<String>,
    },
    /// Glass (`dielectric`, or `roughdielectric` with a roughness).
    Dielectric {
        /// Isotropic GGX roughness.
        alpha: Option<FloatValue>,
        /// GGX roughness along the tangent.
        alpha_u: Option<FloatValue>,
        /// GGX roughness along the bitangent.
        alpha_v: Option<FloatValue>,
        /// Interior IOR (number or name; default `bk7`).
        int_ior: Option<IorValue>,
        /// Exterior IOR (default `air`).
        ext_ior: Option<IorValue>,
        /// Factor on reflection (default 1).
        specular_reflectance: Option<ColorValue>,
        /// Factor on transmission (default 1).
        specular_transmittance: Option<ColorValue>,
        /// Tangent-space normal map texture.
        normal_map: Option<String>,
    },
    /// Rough plastic (`roughplastic`).
    Plastic {
        /// Albedo of the base (default 0.5).
        diffuse_reflectance: Option<ColorValue>,
        /// Factor on the coating (default 1).
        specular_reflectance: Option<ColorValue>,
        /// GGX roughness of the coating (default 0.1).
        alpha: Option<f32>,
        /// Interior IOR (default `polypropylene`).
        int_ior: Option<IorValue>,
        /// Exterior IOR (default `air`).
        ext_ior: Option<IorValue>,
        /// Scatter from the back side as from the front.
        #[serde(default)]
        two_sided: bool,
        /// Tangent-space normal map texture.
        normal_map: Option<String>,
    },
    /// glTF 2.0 metallic-roughness.
    Pbr {
        /// Base colour (default 1).
        base_color: Option<ColorValue>,
        /// Metalness (default 1, as glTF).
        metallic: Option<FloatValue>,
        /// glTF roughness (default 1); alpha = roughness^2.
        roughness: Option<FloatValue>,
        /// Factor on the diffuse base, an ambient-occlusion map (default 1).
        occlusion: Option<FloatValue>,
        /// Anisotropy strength in [0, 1] (default 0): alpha along the anisotropy direction is
        /// mix(alpha, 1, strength^2).
        anisotropy: Option<FloatValue>,
        /// Texture whose RG encode the anisotropy direction (2 rg - 1) in the shading frame.
        anisotropy_direction: Option<String>,
        /// Scatter from the back side as from the front.
        #[serde(default)]
        two_sided: bool,
        /// Tangent-space normal map texture.
        normal_map: Option<String>,
    },
}

/// `[[shapes]]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeDesc {
    /// `obj`, `ply`, `serialized`, `gltf`, `rectangle`, `cube`, `sphere` or `uv_sphere`.
    #[serde(rename = "type")]
    pub kind: ShapeKind,
    /// Mesh file (obj, ply, serialized, gltf).
    pub filename: Option<String>,
    /// Which mesh of a serialized file (default 0).
    pub shape_index: Option<u32>,
    /// Segments around the axis (uv_sphere, default 64).
    pub segments: Option<u32>,
    /// Rings from pole to pole (uv_sphere, default 32).
    pub rings: Option<u32>,
    /// Centre before the transform (sphere, default [0, 0, 0]).
    pub center: Option<[f32; 3]>,
    /// Radius before the transform (sphere, default 1).
    pub radius: Option<f32>,
    /// Material name (default: diffuse 0.5; glTF files bring their own).
    pub material: Option<String>,
    /// Radiance emitted from the front side: makes the shape an area light.
    pub emission: Option<RgbValue>,
    /// Transform steps, applied in order.
    #[serde(default)]
    pub transform: Vec<TransformStep>,
    /// Turn the shape inside out (its front, and the side an emitter lights, become the back).
    #[serde(default)]
    pub flip_normals: bool,
    /// gltf: whether the file's `KHR_lights_punctual` lights are added to the scene (default
    /// true).
    pub lights: Option<bool>,
    /// gltf: factor from the file's light intensities (candela, lux) to tessera's (W/sr,
    /// W/m^2); default 1/683, photometric to radiometric at 683 lm/W.
    pub light_scale: Option<f32>,
}

/// Kinds of shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ShapeKind {
    /// Wavefront OBJ file.
    Obj,
    /// Stanford PLY file (ASCII or binary), read as Mitsuba 3 reads it.
    Ply,
    /// Mitsuba's serialized mesh file (format versions 3 and 4).
    Serialized,
    /// glTF 2.0 file (.gltf or .glb): meshes, node transforms and materials.
    Gltf,
    /// [-1, 1]^2 in z = 0, facing +z.
    Rectangle,
    /// [-1, 1]^3.
    Cube,
    /// The exact sphere (Mitsuba's `sphere`): `center`, `radius`, placed by the transform.
    Sphere,
    /// The UV sphere mesh of the Mitsuba test scenes.
    UvSphere,
}

/// One step of a transform; exactly one of the operations.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransformStep {
    /// Translation.
    pub translate: Option<[f32; 3]>,
    /// Uniform (number) or per-axis ([x, y, z]) scale.
    pub scale: Option<RgbValue>,
    /// Rotation axis (with `angle`).
    pub rotate: Option<[f32; 3]>,
    /// Rotation angle in degrees, counter-clockwise about `rotate` (right-hand rule).
    pub angle: Option<f32>,
    /// Mitsuba's `lookat`: local +z turned towards `target`.
    pub lookat: Option<LookAt>,
    /// A 4x4 matrix, row-major.
    pub matrix: Option<[f32; 16]>,
}

/// Mitsuba's `lookat` transform.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LookAt {
    /// New origin.
    pub origin: [f32; 3],
    /// Point local +z turns towards.
    pub target: [f32; 3],
    /// Up direction (default +y).
    pub up: Option<[f32; 3]>,
}

/// A colour, written as a number (grey) or [r, g, b].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbValue(pub [f32; 3]);

/// A colour parameter: a number, [r, g, b], a texture name, or `{ texture = NAME, scale = .. }`.
#[derive(Clone, Debug, PartialEq)]
pub enum ColorValue {
    /// A constant.
    Value([f32; 3]),
    /// A texture, optionally scaled.
    Texture {
        /// Texture name.
        name: String,
        /// Factor on the texture's value.
        scale: [f32; 3],
    },
}

/// A scalar parameter: a number, a texture name, or `{ texture = NAME, channel = .., scale = .. }`.
#[derive(Clone, Debug, PartialEq)]
pub enum FloatValue {
    /// A constant.
    Value(f32),
    /// A texture's channel, optionally scaled.
    Texture {
        /// Texture name.
        name: String,
        /// Channel read (default the mean of RGB).
        channel: Channel,
        /// Factor on the value.
        scale: f32,
    },
}

/// An index of refraction: a number or a name (`bk7`, `air`, `water`, ...).
#[derive(Clone, Debug, PartialEq)]
pub enum IorValue {
    /// A number.
    Value(f32),
    /// A named material.
    Named(String),
}

fn finite(v: f64) -> Result<f32, String> {
    let f = v as f32;
    if f.is_finite() { Ok(f) } else { Err(format!("{v} is not a finite number")) }
}

fn read_triple<'de, A: SeqAccess<'de>>(mut seq: A) -> Result<[f32; 3], A::Error> {
    let mut out = [0.0f32; 3];
    for (i, slot) in out.iter_mut().enumerate() {
        let v: f64 = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &"three numbers"))?;
        *slot = finite(v).map_err(de::Error::custom)?;
    }
    if seq.next_element::<f64>()?.is_some() {
        return Err(de::Error::invalid_length(4, &"three numbers"));
    }
    Ok(out)
}

/// Keys of an inline texture reference.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TextureRef {
    texture: String,
    channel: Option<Channel>,
    scale: Option<RgbValue>,
}

impl<'de> Deserialize<'de> for RgbValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RgbValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or [r, g, b]")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<RgbValue, E> {
                finite(v).map(|f| RgbValue([f; 3])).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<RgbValue, E> {
                self.visit_f64(v as f64)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<RgbValue, A::Error> {
                read_triple(seq).map(RgbValue)
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for ColorValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = ColorValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, [r, g, b], a texture name or { texture = NAME, scale = .. }")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<ColorValue, E> {
                finite(v).map(|f| ColorValue::Value([f; 3])).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ColorValue, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<ColorValue, E> {
                Ok(ColorValue::Texture { name: v.to_string(), scale: [1.0; 3] })
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<ColorValue, A::Error> {
                read_triple(seq).map(ColorValue::Value)
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<ColorValue, A::Error> {
                let r = TextureRef::deserialize(de::value::MapAccessDeserializer::new(map))?;
                if r.channel.is_some() {
                    return Err(de::Error::custom("`channel` applies to scalar parameters, not colours"));
                }
                Ok(ColorValue::Texture { name: r.texture, scale: r.scale.map_or([1.0; 3], |s| s.0) })
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for FloatValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = FloatValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, a texture name or { texture = NAME, channel = .., scale = .. }")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<FloatValue, E> {
                finite(v).map(FloatValue::Value).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<FloatValue, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<FloatValue, E> {
                Ok(FloatValue::Texture { name: v.to_string(), channel: Channel::Mean, scale: 1.0 })
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<FloatValue, A::Error> {
                let r = TextureRef::deserialize(de::value::MapAccessDeserializer::new(map))?;
                let scale = match r.scale {
                    None => 1.0,
                    Some(RgbValue([a, b, c])) if a == b && b == c => a,
                    Some(_) => {
                        return Err(de::Error::custom("the scale of a scalar parameter is one number"));
                    }
                };
                Ok(FloatValue::Texture { name: r.texture, channel: r.channel.unwrap_or_default(), scale })
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for IorValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = IorValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an index of refraction: a number or a name such as \"bk7\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<IorValue, E> {
                finite(v).map(IorValue::Value).map_err(E::custom)
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<IorValue, E> {
                self.visit_f64(v as f64)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<IorValue, E> {
                Ok(IorValue::Named(v.to_string()))
            }
        }
        d.deserialize_any(V)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_desc_parses_parameter_forms() {
        let src = r#"
            [camera]
            fov = 40
            eye = [0, 1, 2]
            target = [0, 0, 0]
            [materials.a]
            type = "diffuse"
            reflectance = [0.1, 0.2, 0.3]
            [materials.b]
            type = "conductor"
            alpha_u = "rough"
            alpha_v = { texture = "rough", channel = "g", scale = 0.5 }
            material = "Al"
            [materials.c]
            type = "diffuse"
            reflectance = { texture = "tex", scale = [1, 0.5, 0.25] }
        "#;
        let d: SceneDesc = toml::from_str(src).unwrap();
        assert!(matches!(
            &d.materials["a"],
            MaterialDesc::Diffuse { reflectance: Some(ColorValue::Value([0.1, 0.2, 0.3])), .. }
        ));
        let MaterialDesc::Conductor { alpha_u, alpha_v, .. } = &d.materials["b"] else { panic!() };
        assert_eq!(
            alpha_u.as_ref().unwrap(),
            &FloatValue::Texture { name: "rough".into(), channel: Channel::Mean, scale: 1.0 }
        );
        assert_eq!(
            alpha_v.as_ref().unwrap(),
            &FloatValue::Texture { name: "rough".into(), channel: Channel::G, scale: 0.5 }
        );
        assert_eq!(d.render.spp, 16);
    }

    #[test]
    fn scene_desc_rejects_typos_and_bad_values() {
        for (src, needle) in [
            ("[camera]\nfov = 40\nfvo = 3\n", "unknown field `fvo`"),
            ("[camera]\n[materials.a]\ntype = \"difuse\"\n", "unknown variant `difuse`"),
            ("[camera]\n[materials.a]\ntype = \"diffuse\"\nreflectance = [1, 2]\n", "three numbers"),
            ("[camera]\n[materials.a]\ntype = \"diffuse\"\nreflectance = nan\n", "not a finite number"),
            ("[camera]\n[render]\nspp = -3\n", "u32"),
        ] {
            let err = toml::from_str::<SceneDesc>(src).unwrap_err().to_string();
            assert!(err.contains(needle), "{src:?}: {err}");
        }
    }
}
