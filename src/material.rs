//! Materials: turn texture lookups at a hit into a [`Bsdf`] (pbrt-v4's material / BxDF split:
//! BSDFs never see textures).

use crate::bsdf::{Bsdf, Conductor, ConductorFresnel, Dielectric, Diffuse, Ggx, Pbr, Plastic, PlasticTables};
use crate::color::Rgb;
use crate::geometry::Frame;
use crate::texture::{Channel, TexCtx, Texture};
use glam::Vec3;
use std::sync::Arc;

/// Index of a texture in the scene's texture list.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureId(pub u32);

/// A colour parameter: a constant or a texture's RGB times a factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorParam {
    /// The same colour everywhere.
    Value(Rgb),
    /// A texture's RGB.
    Texture {
        /// The texture.
        id: TextureId,
        /// Factor on its value (glTF's `baseColorFactor`, for instance).
        scale: Rgb,
    },
}

/// A scalar parameter: a constant or one channel of a texture times a factor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FloatParam {
    /// The same value everywhere.
    Value(f32),
    /// A texture's channel.
    Texture {
        /// The texture.
        id: TextureId,
        /// The channel read.
        channel: Channel,
        /// Factor on the value.
        scale: f32,
    },
}

impl ColorParam {
    /// The colour at the lookup.
    #[inline]
    pub fn eval(&self, textures: &[Texture], ctx: &TexCtx) -> Rgb {
        match *self {
            ColorParam::Value(c) => c,
            ColorParam::Texture { id, scale } => textures[id.0 as usize].eval(ctx).truncate() * scale,
        }
    }
}

impl FloatParam {
    /// The value at the lookup.
    #[inline]
    pub fn eval(&self, textures: &[Texture], ctx: &TexCtx) -> f32 {
        match *self {
            FloatParam::Value(v) => v,
            FloatParam::Texture { id, channel, scale } => channel.select(textures[id.0 as usize].eval(ctx)) * scale,
        }
    }
}

/// Roughness of a microfacet material: None for a smooth (delta) surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Roughness {
    /// GGX alpha along the tangent s.
    pub alpha_u: FloatParam,
    /// GGX alpha along t.
    pub alpha_v: FloatParam,
}

impl Roughness {
    fn eval(&self, textures: &[Texture], ctx: &TexCtx) -> Ggx {
        Ggx::new(self.alpha_u.eval(textures, ctx), self.alpha_v.eval(textures, ctx))
    }
}

/// The scattering model of a material and its parameters.
#[derive(Clone, Debug)]
pub enum MaterialKind {
    /// Lambertian.
    Diffuse {
        /// Albedo.
        reflectance: ColorParam,
    },
    /// Metal.
    Conductor {
        /// None for a mirror.
        roughness: Option<Roughness>,
        /// Real part of the IOR (per channel).
        eta: Rgb,
        /// Imaginary part of the IOR.
        k: Rgb,
        /// Factor on the reflectance.
        specular_reflectance: ColorParam,
    },
    /// Glass.
    Dielectric {
        /// None for a smooth interface.
        roughness: Option<Roughness>,
        /// Interior over exterior IOR.
        eta: f32,
        /// Factor on reflection.
        specular_reflectance: ColorParam,
        /// Factor on transmission.
        specular_transmittance: ColorParam,
    },
    /// Rough plastic (roughness and IOR constant, as in Mitsuba: the tables depend on them).
    Plastic {
        /// Albedo of the diffuse base.
        diffuse_reflectance: ColorParam,
        /// Factor on the coating's reflection.
        specular_reflectance: ColorParam,
        /// GGX alpha of the coating.
        alpha: f32,
        /// Interface albedos at `alpha`.
        tables: Arc<PlasticTables>,
    },
    /// glTF metallic-roughness.
    Pbr {
        /// Base colour.
        base_color: ColorParam,
        /// Metalness.
        metallic: FloatParam,
        /// glTF roughness; GGX alpha = roughness^2.
        roughness: FloatParam,
        /// Interface albedos of IOR 1.5 over [`PlasticTables::alpha_grid`].
        tables: Arc<PlasticTables>,
    },
}

/// A material: a scattering model, an optional tangent-space normal map, and sidedness.
#[derive(Clone, Debug)]
pub struct Material {
    /// Model and parameters.
    pub kind: MaterialKind,
    /// Tangent-space normal map (RGB in [0, 1] encodes n = 2 rgb - 1 in the shading frame).
    pub normal_map: Option<TextureId>,
    /// Scatter on both sides (Mitsuba's `twosided` adapter): the back behaves as the front.
    pub two_sided: bool,
}

impl ColorParam {
    fn texture(&self) -> Option<TextureId> {
        match *self {
            ColorParam::Value(_) => None,
            ColorParam::Texture { id, .. } => Some(id),
        }
    }
}

impl FloatParam {
    fn texture(&self) -> Option<TextureId> {
        match *self {
            FloatParam::Value(_) => None,
            FloatParam::Texture { id, .. } => Some(id),
        }
    }
}

impl Material {
    /// The default material of a shape without one, as Mitsuba 3 (`Shape::Shape`) makes it:
    /// diffuse with reflectance 0.5, or 0 (black) if the shape is an emitter.
    pub fn default_diffuse(emitter: bool) -> Self {
        let reflectance = ColorParam::Value(Rgb::splat(if emitter { 0.0 } else { 0.5 }));
        Material { kind: MaterialKind::Diffuse { reflectance }, normal_map: None, two_sided: false }
    }

    /// The textures this material reads.
    pub fn textures(&self) -> Vec<TextureId> {
        let roughness = |r: &Option<Roughness>| r.map_or([None, None], |r| [r.alpha_u.texture(), r.alpha_v.texture()]);
        let ids: Vec<Option<TextureId>> = match &self.kind {
            MaterialKind::Diffuse { reflectance } => vec![reflectance.texture()],
            MaterialKind::Conductor { roughness: r, specular_reflectance, .. } => {
                [roughness(r).as_slice(), &[specular_reflectance.texture()]].concat()
            }
            MaterialKind::Dielectric { roughness: r, specular_reflectance, specular_transmittance, .. } => {
                [roughness(r).as_slice(), &[specular_reflectance.texture(), specular_transmittance.texture()]].concat()
            }
            MaterialKind::Plastic { diffuse_reflectance, specular_reflectance, .. } => {
                vec![diffuse_reflectance.texture(), specular_reflectance.texture()]
            }
            MaterialKind::Pbr { base_color, metallic, roughness, .. } => {
                vec![base_color.texture(), metallic.texture(), roughness.texture()]
            }
        };
        ids.into_iter().chain([self.normal_map]).flatten().collect()
    }

    /// The BSDF at a lookup.
    pub fn bsdf<'a>(&'a self, textures: &[Texture], ctx: &TexCtx) -> Bsdf<'a> {
        match &self.kind {
            MaterialKind::Diffuse { reflectance } => {
                Bsdf::Diffuse(Diffuse { reflectance: reflectance.eval(textures, ctx) })
            }
            MaterialKind::Conductor { roughness, eta, k, specular_reflectance } => Bsdf::Conductor(Conductor {
                ggx: roughness.map(|r| r.eval(textures, ctx)),
                fresnel: ConductorFresnel::Complex { eta: *eta, k: *k },
                specular_reflectance: specular_reflectance.eval(textures, ctx),
            }),
            MaterialKind::Dielectric { roughness, eta, specular_reflectance, specular_transmittance } => {
                Bsdf::Dielectric(Dielectric {
                    eta: *eta,
                    ggx: roughness.map(|r| r.eval(textures, ctx)),
                    specular_reflectance: specular_reflectance.eval(textures, ctx),
                    specular_transmittance: specular_transmittance.eval(textures, ctx),
                })
            }
            MaterialKind::Plastic { diffuse_reflectance, specular_reflectance, alpha, tables } => {
                Bsdf::Plastic(Plastic {
                    diffuse_reflectance: diffuse_reflectance.eval(textures, ctx),
                    specular_reflectance: specular_reflectance.eval(textures, ctx),
                    alpha: *alpha,
                    tables,
                })
            }
            MaterialKind::Pbr { base_color, metallic, roughness, tables } => {
                let r = roughness.eval(textures, ctx).clamp(0.0, 1.0);
                Bsdf::Pbr(Pbr {
                    base_color: base_color.eval(textures, ctx),
                    metallic: metallic.eval(textures, ctx).clamp(0.0, 1.0),
                    alpha: r * r,
                    tables,
                })
            }
        }
    }

    /// The shading frame after normal mapping: the map's normal, read in `frame`, with the
    /// tangent s re-projected onto its plane (as Mitsuba's `normalmap`).
    pub fn shading_frame(&self, textures: &[Texture], ctx: &TexCtx, frame: Frame) -> Frame {
        let Some(id) = self.normal_map else {
            return frame;
        };
        let rgb = textures[id.0 as usize].eval(ctx).truncate();
        let local = rgb * 2.0 - Vec3::ONE;
        let Some(local) = local.try_normalize() else {
            return frame;
        };
        Frame::from_normal_tangent(frame.to_world(local), frame.s)
    }
}

/// Indices of refraction by name (Mitsuba 3's table).
pub fn named_ior(name: &str) -> Option<f32> {
    Some(match name.to_ascii_lowercase().as_str() {
        "vacuum" => 1.0,
        "helium" => 1.000036,
        "hydrogen" => 1.000132,
        "air" => 1.000277,
        "carbon dioxide" => 1.00045,
        "water" => 1.3330,
        "acetone" => 1.36,
        "ethanol" => 1.361,
        "carbon tetrachloride" => 1.461,
        "glycerol" => 1.4729,
        "benzene" => 1.501,
        "silicone oil" => 1.52045,
        "bromine" => 1.661,
        "water ice" => 1.31,
        "fused quartz" => 1.458,
        "pyrex" => 1.470,
        "acrylic glass" => 1.49,
        "polypropylene" => 1.49,
        "bk7" => 1.5046,
        "sodium chloride" => 1.544,
        "amber" => 1.55,
        "pet" => 1.5750,
        "diamond" => 2.419,
        _ => return None,
    })
}

/// Complex IORs (eta, k) of named conductors in RGB, as Mitsuba 3's `*_rgb` variants use them
/// (values read back from Mitsuba 3.9.1 with `mi.traverse`). `none` is a perfect mirror.
pub fn named_conductor(name: &str) -> Option<(Rgb, Rgb)> {
    match name {
        "Al" => Some((Rgb::new(1.6575, 0.880405, 0.521244), Rgb::new(9.22381, 6.2695, 4.837))),
        "none" => Some((Rgb::ZERO, Rgb::ONE)),
        _ => None,
    }
}
