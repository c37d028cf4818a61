//! Materials: turn texture lookups at a hit into a [`Bsdf`] (pbrt-v4's material / BxDF split:
//! BSDFs never see textures).

use crate::bsdf::{Bsdf, Conductor, ConductorFresnel, Dielectric, Diffuse, Ggx, Pbr, Plastic, PlasticTables};
use crate::color::Rgb;
use crate::geometry::Frame;
use crate::texture::{Channel, TexCtx, Texture};
use glam::{Vec3, Vec4};
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
            ColorParam::Texture { id, scale } => Rgb::from_vec4(textures[id.0 as usize].eval(ctx)) * scale,
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
        /// Factor on the diffuse base (ambient occlusion), in [0, 1].
        occlusion: FloatParam,
        /// Anisotropy strength in [0, 1] (KHR_materials_anisotropy): the metal lobe's alpha
        /// along the anisotropy direction becomes mix(alpha, 1, strength^2).
        anisotropy: FloatParam,
        /// Tangent-space direction of the anisotropy: RG in [0, 1] encode (x, y) = 2 rg - 1 in
        /// the shading frame (s, t); None is along s.
        anisotropy_direction: Option<TextureId>,
        /// Interface albedos of IOR 1.5 over [`PlasticTables::alpha_grid`].
        tables: Arc<PlasticTables>,
    },
}

/// A material: a scattering model, an optional tangent-space normal map, and sidedness.
#[derive(Clone, Debug)]
pub struct Material {
    /// What the scene calls it, for messages: `materials.NAME`, a glTF file's material, or
    /// the default.
    pub name: String,
    /// Model and parameters.
    pub kind: MaterialKind,
    /// Tangent-space normal map (RGB in [0, 1] encodes n = 2 rgb - 1 in the shading frame).
    pub normal_map: Option<TextureId>,
    /// Scatter on both sides (Mitsuba's `twosided` adapter): the back behaves as the front.
    pub two_sided: bool,
    /// A deformed tiling-and-blending texture whose deformation field orients the shading
    /// frame: s follows the texture's own x axis, J F^-1 e1 (DESIGN.md section 3), so that
    /// anisotropic roughness and normal maps follow the synthesised texture, not the UVs.
    pub texture_frame: Option<TextureId>,
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
        let name = if emitter { "the default emitter material (black)" } else { "the default material (diffuse 0.5)" };
        Material {
            name: name.to_string(),
            kind: MaterialKind::Diffuse { reflectance },
            normal_map: None,
            two_sided: false,
            texture_frame: None,
        }
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
            MaterialKind::Pbr {
                base_color, metallic, roughness, occlusion, anisotropy, anisotropy_direction, ..
            } => vec![
                base_color.texture(),
                metallic.texture(),
                roughness.texture(),
                occlusion.texture(),
                anisotropy.texture(),
                *anisotropy_direction,
            ],
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
            MaterialKind::Pbr { base_color, metallic, roughness, occlusion, anisotropy, tables, .. } => {
                let r = roughness.eval(textures, ctx).clamp(0.0, 1.0);
                let alpha = r * r;
                let strength = anisotropy.eval(textures, ctx).clamp(0.0, 1.0);
                Bsdf::Pbr(Pbr {
                    base_color: base_color.eval(textures, ctx),
                    metallic: metallic.eval(textures, ctx).clamp(0.0, 1.0),
                    alpha_u: alpha + (1.0 - alpha) * strength * strength,
                    alpha_v: alpha,
                    occlusion: occlusion.eval(textures, ctx).clamp(0.0, 1.0),
                    tables,
                })
            }
        }
    }

    /// The frame the BSDF is evaluated in at a lookup, from the unperturbed shading frame `base`
    /// (mirrored already for a two-sided material seen from the back) and the position's
    /// derivatives `dpdu`, `dpdv`.
    ///
    /// With a texture frame, s is first turned in the tangent plane to the texture's x axis,
    /// then to a `pbr` material's anisotropy direction. With a normal map, the map's normal is read in that frame and the tangent s re-projected
    /// onto its plane (Mitsuba's `normalmap`).
    pub fn shading(&self, textures: &[Texture], ctx: &TexCtx, base: Frame, dpdu: Vec3, dpdv: Vec3) -> Shading {
        let base = match self
            .texture_frame
            .and_then(|id| textures[id.0 as usize].tangent_direction(ctx.uv, ctx.uv_mirrored))
        {
            Some((direction, f_reversed)) => {
                // The exemplar's frame reaches the surface through J F^-1: mirrored when exactly
                // one of F and the UV map (as seen from this side) reverses orientation.
                let uv_mirrored = dpdu.cross(dpdv).dot(base.n) < 0.0;
                base.turned_towards(dpdu * direction.x + dpdv * direction.y, f_reversed != uv_mirrored)
            }
            None => base,
        };
        let base = match &self.kind {
            MaterialKind::Pbr { anisotropy_direction: Some(id), .. } => {
                let d = textures[id.0 as usize].eval(ctx) * 2.0 - Vec4::ONE;
                base.turned_towards(base.s * d.x + base.t * d.y, false)
            }
            _ => base,
        };
        let plain = Shading { frame: base, base, bump_alpha2: None };
        let Some(id) = self.normal_map else { return plain };
        let Some(local) = textures[id.0 as usize].eval_normal(ctx) else { return plain };
        // Roughness of the bump-terminator shadowing: alpha^2 = tan^2(theta_d) / 8, theta_d the
        // tilt of the map's normal (Conty Estevez et al. 2019).
        let cos_d = local.z.clamp(1e-6, 1.0);
        let alpha2 = ((1.0 - cos_d * cos_d) / (cos_d * cos_d) / 8.0).min(1.0);
        Shading { frame: Frame::from_normal_tangent(base.to_world(local), base.s), base, bump_alpha2: Some(alpha2) }
    }
}

/// The shading frame of a hit: the one the BSDF is evaluated in, and the unperturbed one it
/// came from (they differ under a normal map).
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    /// The frame the BSDF is evaluated in (right-handed).
    pub frame: Frame,
    /// The unperturbed shading frame (the interpolated normal; mirrored for a two-sided back).
    pub base: Frame,
    /// With a normal map: the GGX alpha^2 of its terminator shadowing.
    bump_alpha2: Option<f32>,
}

impl Shading {
    /// Factor on the BSDF for light arriving from (or sampled towards) the world direction `w`.
    ///
    /// 1 without a normal map. With one, as Mitsuba 3.9.1's `normalmap` does (measured on its
    /// plugin, see docs/design-decisions.md): 0 when `w` lies on different sides of the perturbed
    /// and the unperturbed normals, so that light never arrives through the surface; else the
    /// bump-terminator shadowing of Conty Estevez, Lecocq and Stein 2019 ("A Microfacet-Based
    /// Shadowing Function to Solve the Bump Terminator Problem", Ray Tracing Gems ch. 12):
    /// G1 = 2 / (1 + sqrt(1 + alpha^2 tan^2 theta)), theta the angle of `w` to the unperturbed
    /// normal. Densities do not include it: sample weights do.
    #[inline]
    pub fn light_factor(&self, w: Vec3) -> f32 {
        let Some(alpha2) = self.bump_alpha2 else { return 1.0 };
        let cos_base = self.base.n.dot(w);
        if cos_base * self.frame.n.dot(w) <= 0.0 {
            return 0.0;
        }
        let cos2 = cos_base * cos_base;
        let tan2 = (1.0 - cos2).max(0.0) / cos2;
        2.0 / (1.0 + (1.0 + alpha2 * tan2).sqrt())
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_map_light_factor_matches_mitsuba() {
        // Values read off Mitsuba 3.9.1's `normalmap` around a Lambertian BSDF (ratio of its
        // eval to cos/pi in the perturbed frame), for a map normal tilted 45 degrees towards +s.
        let base = Frame { s: Vec3::X, t: Vec3::Y, n: Vec3::Z };
        let local = Vec3::new(1.0, 0.0, 1.0).normalize();
        let alpha2 = 1.0 / 8.0;
        let shading = Shading { frame: Frame::from_normal_tangent(local, Vec3::X), base, bump_alpha2: Some(alpha2) };
        for (w, expected) in [
            (Vec3::new(0.9, 0.1, 0.4), 0.8769),
            (Vec3::new(0.98, 0.0, 0.2), 0.6666),
            (Vec3::new(0.6, -0.5, 0.6), 0.9520),
            (Vec3::new(0.3, 0.1, 0.9), 0.9962),
            (Vec3::Z, 1.0),
        ] {
            let f = shading.light_factor(w.normalize());
            assert!((f - expected).abs() < 2e-4, "{w}: {f} vs {expected}");
        }
        // Below the unperturbed surface (though above the perturbed one): nothing.
        assert_eq!(shading.light_factor(Vec3::new(0.9, 0.0, -0.1).normalize()), 0.0);
        // Without a normal map the factor is 1 everywhere, even below.
        let plain = Shading { frame: base, base, bump_alpha2: None };
        assert_eq!(plain.light_factor(-Vec3::Z), 1.0);
    }
}
