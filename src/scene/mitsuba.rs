//! Export a scene as Mitsuba 3 XML (`tessera export-mitsuba`), so that Mitsuba renders the same
//! image: the independent check of tessera (DESIGN.md section 10).
//!
//! What is written, and why each choice keeps the two renderers' lookups identical:
//! - every shape as a world-space OBJ file (`meshes/`). tessera's uv convention is OBJ's `vt`, and
//!   Mitsuba's OBJ loader flips v while its bitmaps start at the top-left row, so texture
//!   lookups agree (DESIGN.md section 3);
//! - every texture use baked to a linear float EXR (`textures/`) exactly as tessera reads it:
//!   colour decoded, factor applied, the channel of a scalar parameter selected. Mitsuba then
//!   interpolates the same values bilinearly. A texture's uv scale and offset become Mitsuba's
//!   `to_uv` transform, adjusted for Mitsuba's flipped v;
//! - materials as the Mitsuba plugins they mirror (`diffuse`, `conductor` / `roughconductor`,
//!   `dielectric` / `roughdielectric`, `roughplastic`, all GGX with visible-normal sampling),
//!   wrapped in `normalmap` and `twosided` where needed;
//! - the camera as a `perspective`, `thinlens` or `orthographic` sensor with tessera's
//!   camera-to-world matrix turned into Mitsuba's camera frame (x left, z forward), a box
//!   reconstruction filter, the `path` integrator with the same `max_depth` and `rr_depth`;
//! - lights as `area`, `point`, `spot`, `directional`, `constant` and `envmap` emitters.
//!
//! Exported as the nearest Mitsuba equivalent, with a warning naming the item: the `pbr`
//! material (no Mitsuba plugin has its Schlick-Fresnel metal blend; see [`Exporter::pbr`]),
//! glTF's spot falloff and range window, and the sun's disc. Filtered textures (`trilinear`, `ewa`) are exported bilinear,
//! with a warning: Mitsuba 3.9 has no MIP-mapping. Procedural textures (tiling and blending)
//! are baked over the UV square at the export's resolution, with a warning; a shading frame
//! turned by a deformation field has no Mitsuba equivalent and is exported unturned, with a
//! warning.

use super::Scene;
use crate::camera::{FovAxis, Projection};
use crate::color::Rgb;
use crate::error::{Error, Result};
use crate::files::StagedFolder;
use crate::geometry::obj::obj_text;
use crate::geometry::{Frame, Sphere, TriangleMesh};
use crate::image::{PixelFilter, write_exr};
use crate::light::{Environment, SpotFalloff};
use crate::limits;
use crate::material::{ColorParam, FloatParam, Material, MaterialKind, Roughness, TextureId};
use crate::texture::{BakeFootprint, Channel, Checkerboard, Filter, Texture, bake};
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

/// What an export wrote and what it could not carry over exactly.
#[derive(Debug, Default)]
pub struct MitsubaExport {
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
    /// Differences between the exported scene and tessera's.
    pub warnings: Vec<String>,
}

/// Escape a string for an XML attribute value.
fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;").replace('\'', "&apos;")
}

fn rgb_value(c: Rgb) -> String {
    format!("{}, {}, {}", c.x, c.y, c.z)
}

/// The `to_uv` element of tessera's texture-coordinate scale `s` and offset `o`: tessera reads
/// uv' = uv s + o with v up; Mitsuba's v runs down (v_m = 1 - v), so the same lookup is
/// v_m' = v_m s_y + (1 - s_y - o_y).
fn to_uv_element(s: Vec2, o: Vec2) -> String {
    format!(
        "<transform name=\"to_uv\"><scale x=\"{}\" y=\"{}\"/><translate x=\"{}\" y=\"{}\"/></transform>",
        s.x,
        s.y,
        o.x,
        1.0 - s.y - o.y
    )
}

/// A checkerboard as Mitsuba's own `checkerboard`, its colours as a parameter reads them (a
/// colour times its factor, or a channel times its factor); None for a normal map (baked).
fn checkerboard(board: &Checkerboard, kind: BakeKind, name: &str) -> Option<String> {
    let value = |c: glam::Vec4| match kind {
        BakeKind::Color(scale) => Some(Rgb::from_vec4(c) * Rgb::from(scale.map(f32::from_bits))),
        BakeKind::Scalar(channel, scale) => {
            let channel = CHANNELS[channel as usize];
            Some(Rgb::splat(channel.select(c) * f32::from_bits(scale)))
        }
        BakeKind::Normal => None,
    };
    Some(format!(
        "<texture type=\"checkerboard\" name=\"{name}\"><rgb name=\"color0\" value=\"{}\"/>\
         <rgb name=\"color1\" value=\"{}\"/>{}</texture>",
        rgb_value(value(board.color0)?),
        rgb_value(value(board.color1)?),
        to_uv_element(board.scale, board.offset)
    ))
}

/// A `to_world` transform element of matrix `m`.
fn to_world_element(m: Mat4) -> String {
    let rows = m.transpose().to_cols_array().map(|v| v.to_string()).join(" ");
    format!("<transform name=\"to_world\"><matrix value=\"{rows}\"/></transform>")
}

/// The channels a scalar bake can read, by their index in [`BakeKind::Scalar`].
const CHANNELS: [Channel; 5] = [Channel::Mean, Channel::R, Channel::G, Channel::B, Channel::A];

/// How a texture is baked: as a colour (RGB times a factor) or a scalar (a channel times a factor).
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum BakeKind {
    Color([u32; 3]),
    Normal,
    Scalar(u8, u32),
}

struct Exporter<'a> {
    scene: &'a Scene,
    dir: &'a Path,
    baked: HashMap<(TextureId, BakeKind), String>,
    bake_res: usize,
    out: MitsubaExport,
}

impl Exporter<'_> {
    fn io(&self, file: &str) -> impl Fn(std::io::Error) -> Error + '_ {
        let path = self.dir.join(file);
        move |e| Error::io(&path, e)
    }

    fn write_text(&mut self, file: &str, text: &str) -> Result<()> {
        std::fs::write(self.dir.join(file), text).map_err(self.io(file))?;
        self.out.files.push(file.to_string());
        Ok(())
    }

    /// Bake texture `id` as tessera reads it and return its `<texture>` element for `name`.
    /// Images are written at their resolution; procedural textures are evaluated over the UV
    /// square at the export's bake resolution (point lookups).
    fn texture(&mut self, id: TextureId, kind: BakeKind, name: &str) -> Result<String> {
        let texture = &self.scene.textures[id.0 as usize];
        if let Texture::Checkerboard(board) = texture
            && let Some(element) = checkerboard(board, kind, name)
        {
            return Ok(element);
        }
        let (scale, offset) = match texture {
            Texture::Image(tex) => {
                if tex.filter != Filter::None {
                    self.out.warnings.push(format!(
                        "{} uses the {:?} filter; Mitsuba 3.9 has no MIP-mapping, so it is exported bilinear",
                        self.scene.texture_names[id.0 as usize], tex.filter
                    ));
                }
                (tex.scale, tex.offset)
            }
            Texture::TilingBlending(_) | Texture::QuadTiles(_) | Texture::Pups(_) | Texture::Checkerboard(_) => {
                self.out.warnings.push(format!(
                    "{} is procedural: baked over the UV square at {res}x{res} (lookups outside [0, 1] repeat the bake)",
                    self.scene.texture_names[id.0 as usize],
                    res = self.bake_res
                ));
                (Vec2::ONE, Vec2::ZERO)
            }
        };
        let file = match self.baked.get(&(id, kind)) {
            Some(f) => f.clone(),
            None => {
                let image = match texture {
                    Texture::Image(tex) => std::borrow::Cow::Borrowed(tex.mipmap.level(0)),
                    procedural => std::borrow::Cow::Owned(bake(procedural, self.bake_res, BakeFootprint::Point)),
                };
                let (w, h) = (image.width, image.height);
                let pixels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y)));
                let (file, channels) = match kind {
                    BakeKind::Color(scale) => {
                        let scale =
                            Rgb::new(f32::from_bits(scale[0]), f32::from_bits(scale[1]), f32::from_bits(scale[2]));
                        let values: Vec<Rgb> = pixels.map(|(x, y)| Rgb::from_vec4(image.pixel(x, y)) * scale).collect();
                        let plane = |c: usize| values.iter().map(|v| v[c]).collect::<Vec<f32>>();
                        let file = format!("textures/texture{}_rgb{}.exr", id.0, self.baked.len());
                        (file, vec![("R".into(), plane(0)), ("G".into(), plane(1)), ("B".into(), plane(2))])
                    }
                    BakeKind::Normal => {
                        // The normal tessera shades with, encoded as Mitsuba's normalmap reads it.
                        let values: Vec<Vec3> = pixels
                            .map(|(x, y)| {
                                let uv =
                                    Vec2::new(x as f32 + 0.5, (h - 1 - y) as f32 + 0.5) / Vec2::new(w as f32, h as f32);
                                let n = match texture {
                                    Texture::Image(_) => image.pixel(x, y).truncate() * 2.0 - Vec3::ONE,
                                    procedural => procedural
                                        .eval_normal(&crate::texture::TexCtx { uv, ..Default::default() })
                                        .unwrap_or(Vec3::Z),
                                };
                                (n + Vec3::ONE) * 0.5
                            })
                            .collect();
                        let plane = |c: usize| values.iter().map(|v| v[c]).collect::<Vec<f32>>();
                        let file = format!("textures/texture{}_normal{}.exr", id.0, self.baked.len());
                        (file, vec![("R".into(), plane(0)), ("G".into(), plane(1)), ("B".into(), plane(2))])
                    }
                    BakeKind::Scalar(channel, scale) => {
                        let channel = CHANNELS[channel as usize];
                        let scale = f32::from_bits(scale);
                        let values = pixels.map(|(x, y)| channel.select(image.pixel(x, y)) * scale).collect();
                        let file = format!("textures/texture{}_y{}.exr", id.0, self.baked.len());
                        (file, vec![("Y".into(), values)])
                    }
                };
                write_exr(&self.dir.join(&file), w, h, channels)?;
                self.out.files.push(file.clone());
                self.baked.insert((id, kind), file.clone());
                file
            }
        };
        Ok(format!(
            "<texture type=\"bitmap\" name=\"{name}\">\
             <string name=\"filename\" value=\"{}\"/>\
             <string name=\"filter_type\" value=\"bilinear\"/>\
             <string name=\"wrap_mode\" value=\"repeat\"/>\
             <boolean name=\"raw\" value=\"true\"/>{}</texture>",
            xml_escape(&file),
            to_uv_element(scale, offset)
        ))
    }

    fn color(&mut self, p: &ColorParam, name: &str) -> Result<String> {
        match *p {
            ColorParam::Value(c) => Ok(format!("<rgb name=\"{name}\" value=\"{}\"/>", rgb_value(c))),
            ColorParam::Texture { id, scale } => {
                self.texture(id, BakeKind::Color(scale.to_array().map(f32::to_bits)), name)
            }
        }
    }

    fn float(&mut self, p: &FloatParam, name: &str) -> Result<String> {
        match *p {
            FloatParam::Value(v) => Ok(format!("<float name=\"{name}\" value=\"{v}\"/>")),
            FloatParam::Texture { id, channel, scale } => {
                let index = CHANNELS.iter().position(|c| *c == channel);
                self.texture(id, BakeKind::Scalar(index.expect("all channels listed") as u8, scale.to_bits()), name)
            }
        }
    }

    /// The factor parameters Mitsuba leaves out by default (value 1).
    fn optional_color(&mut self, p: &ColorParam, name: &str) -> Result<String> {
        if *p == ColorParam::Value(Rgb::ONE) { Ok(String::new()) } else { self.color(p, name) }
    }

    fn roughness(&mut self, r: &Roughness) -> Result<String> {
        Ok(format!(
            "<string name=\"distribution\" value=\"ggx\"/><boolean name=\"sample_visible\" value=\"true\"/>{}{}",
            self.float(&r.alpha_u, "alpha_u")?,
            self.float(&r.alpha_v, "alpha_v")?
        ))
    }

    /// The glTF metallic-roughness material `name` as the nearest Mitsuba 3 BSDF, with a warning:
    /// a `blendbsdf` by `metallic` of a `roughplastic` (the dielectric lobe, exact: the same
    /// model) and a `roughconductor` whose Fresnel has the base colour as F0 (k = 0 and
    /// eta = (1 + sqrt F0) / (1 - sqrt F0), instead of Schlick's curve, which no Mitsuba plugin
    /// has; a textured base colour becomes the conductor's `specular_reflectance` over a
    /// perfect mirror). A textured roughness is exported as its factor.
    fn pbr(
        &mut self,
        name: &str,
        base_color: &ColorParam,
        metallic: &FloatParam,
        roughness: &FloatParam,
        ior: f32,
    ) -> Result<String> {
        self.out.warnings.push(format!(
            "{name}: glTF's metallic-roughness has no exact Mitsuba 3 equivalent: exported as a blendbsdf of \
             roughplastic and roughconductor, the metal's Schlick Fresnel replaced by a conductor's of the same F0"
        ));
        let r = match *roughness {
            FloatParam::Value(r) => r,
            FloatParam::Texture { scale, .. } => {
                self.out.warnings.push(format!("{name}: its roughness texture is exported as its factor {scale}"));
                scale
            }
        };
        let alpha = r * r;
        let plastic = format!(
            "<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"ggx\"/>\
             <boolean name=\"sample_visible\" value=\"true\"/><float name=\"alpha\" value=\"{alpha}\"/>\
             <float name=\"int_ior\" value=\"{ior}\"/><float name=\"ext_ior\" value=\"1\"/>\
             <boolean name=\"nonlinear\" value=\"false\"/>{}</bsdf>",
            self.color(base_color, "diffuse_reflectance")?
        );
        let fresnel = match *base_color {
            ColorParam::Value(f0) => {
                let root = f0.max(Rgb::ZERO).powf(0.5).min(Rgb::splat(0.999));
                let eta = (Rgb::ONE + root) / (Rgb::ONE - root);
                format!("<rgb name=\"eta\" value=\"{}\"/><rgb name=\"k\" value=\"0, 0, 0\"/>", rgb_value(eta))
            }
            ColorParam::Texture { .. } => {
                format!("<string name=\"material\" value=\"none\"/>{}", self.color(base_color, "specular_reflectance")?)
            }
        };
        let metal = format!(
            "<bsdf type=\"roughconductor\"><string name=\"distribution\" value=\"ggx\"/>\
             <boolean name=\"sample_visible\" value=\"true\"/><float name=\"alpha\" value=\"{alpha}\"/>{fresnel}</bsdf>"
        );
        Ok(format!("<bsdf type=\"blendbsdf\">{}{plastic}{metal}</bsdf>", self.float(metallic, "weight")?))
    }

    /// The `<bsdf>` element of material `index`, with its id.
    fn material(&mut self, index: usize, m: &Material) -> Result<String> {
        if m.texture_frame.is_some() {
            self.out.warnings.push(format!(
                "{}: its shading frame follows a deformation field; Mitsuba's follows dp/du, so \
                 anisotropic roughness and normal maps are exported unturned",
                m.name
            ));
        }
        let inner = match &m.kind {
            MaterialKind::Diffuse { reflectance } => {
                format!("<bsdf type=\"diffuse\">{}</bsdf>", self.color(reflectance, "reflectance")?)
            }
            MaterialKind::Conductor { roughness, eta, k, specular_reflectance } => {
                let ior = if *eta == Rgb::ZERO && *k == Rgb::ONE {
                    "<string name=\"material\" value=\"none\"/>".to_string()
                } else {
                    format!(
                        "<rgb name=\"eta\" value=\"{}\"/><rgb name=\"k\" value=\"{}\"/>",
                        rgb_value(*eta),
                        rgb_value(*k)
                    )
                };
                let spec = self.optional_color(specular_reflectance, "specular_reflectance")?;
                match roughness {
                    None => format!("<bsdf type=\"conductor\">{ior}{spec}</bsdf>"),
                    Some(r) => format!("<bsdf type=\"roughconductor\">{}{ior}{spec}</bsdf>", self.roughness(r)?),
                }
            }
            MaterialKind::Dielectric { roughness, eta, specular_reflectance, specular_transmittance } => {
                let ior = format!("<float name=\"int_ior\" value=\"{eta}\"/><float name=\"ext_ior\" value=\"1\"/>");
                let factors = self.optional_color(specular_reflectance, "specular_reflectance")?
                    + &self.optional_color(specular_transmittance, "specular_transmittance")?;
                match roughness {
                    None => format!("<bsdf type=\"dielectric\">{ior}{factors}</bsdf>"),
                    Some(r) => format!("<bsdf type=\"roughdielectric\">{}{ior}{factors}</bsdf>", self.roughness(r)?),
                }
            }
            MaterialKind::Plastic { diffuse_reflectance, specular_reflectance, alpha, tables } => format!(
                "<bsdf type=\"roughplastic\"><string name=\"distribution\" value=\"ggx\"/>\
                 <boolean name=\"sample_visible\" value=\"true\"/><float name=\"alpha\" value=\"{alpha}\"/>\
                 <float name=\"int_ior\" value=\"{}\"/><float name=\"ext_ior\" value=\"1\"/>\
                 <boolean name=\"nonlinear\" value=\"false\"/>{}{}</bsdf>",
                tables.eta(),
                self.color(diffuse_reflectance, "diffuse_reflectance")?,
                self.optional_color(specular_reflectance, "specular_reflectance")?
            ),
            MaterialKind::Pbr {
                base_color,
                metallic,
                roughness,
                occlusion,
                anisotropy,
                anisotropy_direction,
                tables,
            } => {
                if *occlusion != FloatParam::Value(1.0) {
                    self.out.warnings.push(format!("{}: its occlusion map is not exported", m.name));
                }
                if *anisotropy != FloatParam::Value(0.0) || anisotropy_direction.is_some() {
                    self.out.warnings.push(format!("{}: its anisotropy is not exported (isotropic)", m.name));
                }
                self.pbr(&m.name, base_color, metallic, roughness, tables.eta())?
            }
        };
        let mut bsdf = inner;
        if let Some(map) = m.normal_map {
            let texture = self.texture(map, BakeKind::Normal, "normalmap")?;
            bsdf = format!("<bsdf type=\"normalmap\">{texture}{bsdf}</bsdf>");
        }
        if m.two_sided {
            bsdf = format!("<bsdf type=\"twosided\">{bsdf}</bsdf>");
        }
        // Give the outermost element the id.
        Ok(bsdf.replacen("<bsdf ", &format!("<bsdf id=\"material{index}\" "), 1))
    }

    /// Write shape `index` as a world-space OBJ; return its file name.
    fn mesh(&mut self, index: usize) -> Result<String> {
        let g = &self.scene.geometry;
        let shape = &g.shapes[index];
        let first = shape.first_vertex as usize;
        let end = g.shapes.get(index + 1).map_or(g.positions.len(), |s| s.first_vertex as usize);
        let mesh = TriangleMesh {
            positions: g.positions[first..end].to_vec(),
            normals: shape.has_normals.then(|| g.normals[first..end].to_vec()),
            uvs: shape.has_uvs.then(|| g.uvs[first..end].to_vec()),
            indices: (g.triangles.iter().zip(&g.triangle_shape))
                .filter(|(_, s)| **s as usize == index)
                .map(|(tri, _)| tri.map(|i| i - first as u32))
                .collect(),
        };
        let comment = format!("shape {index} of {}, exported by tessera (world space)", self.scene.path.display());
        let obj = obj_text(&mesh, &comment);
        let file = format!("meshes/shape{index}.obj");
        self.write_text(&file, &obj)?;
        Ok(file)
    }

    /// The opening of a Mitsuba `sphere` shape: the unit sphere under the sphere's transform.
    fn sphere(&mut self, sphere: &Sphere, name: &str) -> String {
        let m = sphere.to_world();
        if m.determinant() < 0.0 {
            self.out.warnings.push(format!(
                "{name}: the sphere's transform mirrors it; Mitsuba may turn a mirrored sphere inside out"
            ));
        }
        let flip = if sphere.flip_normals() { "<boolean name=\"flip_normals\" value=\"true\"/>" } else { "" };
        format!("<shape type=\"sphere\">{}{flip}", to_world_element(m))
    }

    /// The camera as Mitsuba's `perspective`, `thinlens` or `orthographic` sensor.
    fn sensor(&self) -> String {
        let s = &self.scene.settings;
        let camera = &self.scene.camera;
        let model = camera.model();
        // tessera's camera looks down -z with x right; Mitsuba's looks down +z with x left.
        let mut m = camera.to_world() * Mat4::from_scale(Vec3::new(-1.0, 1.0, -1.0));
        let axis_name = |axis: FovAxis| if axis == FovAxis::X { "x" } else { "y" };
        // Mitsuba needs a near clip > 0; tessera's default 0 becomes a millimetre.
        let near_clip = if model.near_clip > 0.0 { model.near_clip } else { 0.001 };
        let (kind, params) = match (model.projection, model.lens) {
            (Projection::Perspective { fov, axis }, lens) => {
                let mut params = format!(
                    "<float name=\"fov\" value=\"{fov}\"/><string name=\"fov_axis\" value=\"{}\"/>",
                    axis_name(axis)
                );
                let kind = match lens {
                    None => "perspective",
                    Some(lens) => {
                        let _ = write!(
                            params,
                            "<float name=\"aperture_radius\" value=\"{}\"/><float name=\"focus_distance\" value=\"{}\"/>",
                            lens.aperture_radius, lens.focus_distance
                        );
                        "thinlens"
                    }
                };
                (kind, params)
            }
            (Projection::Orthographic { extent, axis }, _) => {
                // Mitsuba's film spans x in [-1, 1] (y by the aspect ratio) before to_world.
                let (w, h) = (s.width as f32, s.height as f32);
                let half_x = if axis == FovAxis::X { 0.5 * extent } else { 0.5 * extent * w / h };
                m *= Mat4::from_scale(Vec3::new(half_x, half_x, 1.0));
                ("orthographic", String::new())
            }
        };
        let to_world = to_world_element(m);
        let rfilter = match s.pixel_filter {
            PixelFilter::Box => "<rfilter type=\"box\"/>".to_string(),
            PixelFilter::Gaussian { stddev } => {
                format!("<rfilter type=\"gaussian\"><float name=\"stddev\" value=\"{stddev}\"/></rfilter>")
            }
            PixelFilter::Tent { radius } => {
                format!("<rfilter type=\"tent\"><float name=\"radius\" value=\"{radius}\"/></rfilter>")
            }
        };
        format!(
            "<sensor type=\"{kind}\">{params}\
             <float name=\"near_clip\" value=\"{near_clip}\"/><float name=\"far_clip\" value=\"10000000\"/>\
             {to_world}\
             <sampler type=\"independent\"><integer name=\"sample_count\" value=\"{}\"/><integer name=\"seed\" value=\"{}\"/></sampler>\
             <film type=\"hdrfilm\"><integer name=\"width\" value=\"{}\"/><integer name=\"height\" value=\"{}\"/>\
             <string name=\"pixel_format\" value=\"rgb\"/><string name=\"component_format\" value=\"float32\"/>\
             {rfilter}</film></sensor>",
            s.spp, s.seed, s.width, s.height
        )
    }

    /// Point, spot, directional lights and suns as Mitsuba's `point`, `spot` and `directional`
    /// emitters; what Mitsuba lacks (glTF's spot falloff and range window, the sun's disc) is
    /// exported as the nearest emitter, with a warning.
    fn punctual_emitters(&mut self) -> String {
        let lights = &self.scene.lights;
        let mut xml = String::new();
        for (i, light) in lights.points.iter().enumerate() {
            let p = light.position;
            let intensity = rgb_value(light.intensity);
            if light.range.is_some() {
                self.out.warnings.push(format!(
                    "point light {i}: glTF's range window has no Mitsuba equivalent: exported without it"
                ));
            }
            let Some(cone) = &light.spot else {
                let _ = write!(
                    xml,
                    "<emitter type=\"point\"><point name=\"position\" value=\"{}, {}, {}\"/>\
                     <rgb name=\"intensity\" value=\"{intensity}\"/></emitter>",
                    p.x, p.y, p.z
                );
                continue;
            };
            if cone.falloff() != SpotFalloff::LinearInAngle {
                self.out.warnings.push(format!(
                    "point light {i}: glTF's spot falloff (squared in the cosine) exported as Mitsuba's (linear in the angle)"
                ));
            }
            let (beam, cutoff) = cone.angles();
            let target = p + cone.axis();
            let up = Frame::from_normal(cone.axis()).s;
            let _ = write!(
                xml,
                "<emitter type=\"spot\"><transform name=\"to_world\"><lookat origin=\"{}, {}, {}\" \
                 target=\"{}, {}, {}\" up=\"{}, {}, {}\"/></transform><rgb name=\"intensity\" value=\"{intensity}\"/>\
                 <float name=\"cutoff_angle\" value=\"{}\"/><float name=\"beam_width\" value=\"{}\"/></emitter>",
                p.x,
                p.y,
                p.z,
                target.x,
                target.y,
                target.z,
                up.x,
                up.y,
                up.z,
                cutoff.to_degrees(),
                beam.to_degrees()
            );
        }
        for (i, light) in lights.distant.iter().enumerate() {
            if !light.is_delta() {
                self.out.warnings.push(format!(
                    "distant light {i}: Mitsuba has no sun disc: exported as a directional light with the same \
                     irradiance (hard shadows instead of a {:.3}-degree penumbra)",
                    light.angular_diameter().to_degrees()
                ));
            }
            let d = light.direction();
            let _ = write!(
                xml,
                "<emitter type=\"directional\"><vector name=\"direction\" value=\"{}, {}, {}\"/>\
                 <rgb name=\"irradiance\" value=\"{}\"/></emitter>",
                d.x,
                d.y,
                d.z,
                rgb_value(light.irradiance())
            );
        }
        xml
    }

    fn environment(&mut self) -> Result<String> {
        Ok(match &self.scene.lights.environment {
            None => String::new(),
            Some(Environment::Constant(c)) => {
                format!("<emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>", rgb_value(*c))
            }
            Some(Environment::Map(map)) => {
                let (image, scale) = map.image();
                let plane = |c: usize| {
                    (0..image.width * image.height).map(|i| image.pixel(i % image.width, i / image.width)[c]).collect()
                };
                let file = "textures/environment.exr".to_string();
                let channels = vec![("R".into(), plane(0)), ("G".into(), plane(1)), ("B".into(), plane(2))];
                write_exr(&self.dir.join(&file), image.width, image.height, channels)?;
                self.out.files.push(file.clone());
                format!(
                    "<emitter type=\"envmap\"><string name=\"filename\" value=\"{file}\"/><float name=\"scale\" value=\"{scale}\"/></emitter>"
                )
            }
        })
    }
}

/// Write `scene` as Mitsuba 3 XML to `dir/scene.xml`, with meshes and textures beside it;
/// procedural textures are baked at `bake_res` x `bake_res`.
/// The files are written to a staging folder and moved into `dir` only once all are written,
/// so that a failure leaves `dir` as it was (no mix of old and new files, no empty folders).
pub fn export_mitsuba(scene: &Scene, dir: &Path, bake_res: usize) -> Result<MitsubaExport> {
    if !(1..=limits::MAX_BAKE_RES as usize).contains(&bake_res) {
        return Err(Error::param("bake resolution", format!("{bake_res} is outside 1..={}", limits::MAX_BAKE_RES)));
    }
    let staged = StagedFolder::new(dir)?;
    for sub in ["meshes", "textures"] {
        let folder = staged.path().join(sub);
        std::fs::create_dir(&folder).map_err(|e| Error::io(&folder, e))?;
    }
    let mut ex = Exporter { scene, dir: staged.path(), baked: HashMap::new(), bake_res, out: MitsubaExport::default() };
    let s = &scene.settings;
    let max_depth = s.max_depth.map_or(-1, i64::from);
    let mut xml = format!(
        "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<!-- Exported by tessera from {} -->\n<scene version=\"3.0.0\">\n\
         <integrator type=\"path\"><integer name=\"max_depth\" value=\"{max_depth}\"/>\
         <integer name=\"rr_depth\" value=\"{}\"/><boolean name=\"hide_emitters\" value=\"false\"/></integrator>\n",
        xml_escape(&scene.path.display().to_string()),
        s.rr_depth
    );
    let _ = writeln!(xml, "{}", ex.sensor());
    for (i, m) in scene.materials.iter().enumerate() {
        let bsdf = ex.material(i, m)?;
        let _ = writeln!(xml, "{bsdf}");
    }
    for (i, shape) in scene.geometry.shapes.iter().enumerate() {
        let surface = match shape.sphere {
            Some(s) => ex.sphere(&scene.geometry.spheres[s as usize], &shape.name),
            None => format!("<shape type=\"obj\"><string name=\"filename\" value=\"{}\"/>", ex.mesh(i)?),
        };
        let emitter = shape.light.map_or(String::new(), |l| {
            let radiance = scene.lights.area[l as usize].radiance;
            format!("<emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>", rgb_value(radiance))
        });
        let _ = writeln!(xml, "{surface}<ref id=\"material{}\"/>{emitter}</shape>", shape.material);
    }
    let punctual = ex.punctual_emitters();
    let env = ex.environment()?;
    let _ = writeln!(xml, "{punctual}{env}\n</scene>");
    ex.write_text("scene.xml", &xml)?;
    let mut out = ex.out;
    out.warnings.sort();
    out.warnings.dedup();
    staged.commit()?;
    Ok(out)
}
