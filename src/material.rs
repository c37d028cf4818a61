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

/// Complex IORs (name, eta, k) of Mitsuba 3's named conductors in RGB, as its `*_rgb` variants
/// use them (read back from Mitsuba 3.9.1's `scalar_rgb` with `mi.traverse`, 6 digits; its
/// out-of-gamut negative channels are clamped to 0 there, and so here). `none` is a perfect
/// mirror. `AlSb` is left out: a channel of its RGB eta and k are both 0, where the conductor
/// Fresnel term is 0/0 at normal incidence.
const NAMED_CONDUCTORS: &[(&str, [f32; 3], [f32; 3])] = &[
    ("a-C", [2.94405, 2.22714, 1.96816], [0.887465, 0.799299, 0.81529]),
    ("Ag", [0.155276, 0.116728, 0.138388], [4.82835, 3.12222, 2.1469]),
    ("Al", [1.6575, 0.880405, 0.521244], [9.22381, 6.2695, 4.837]),
    ("AlAs", [3.6053, 3.23294, 2.21632], [0.000679437, 0.0, 0.00751271]),
    ("Au", [0.143036, 0.375307, 1.44205], [3.983, 2.38556, 1.60336]),
    ("Be", [4.18501, 3.18503, 2.78406], [3.83547, 3.01012, 2.86899]),
    ("Cr", [4.36967, 2.91651, 1.6549], [5.20655, 4.23131, 3.7547]),
    ("CsI", [2.1449, 1.70232, 1.66243], [0.0, 0.0, 0.0]),
    ("Cu", [0.201005, 0.92375, 1.10222], [3.91326, 2.45305, 2.14209]),
    ("Cu2O", [3.55177, 2.94987, 2.75188], [0.114207, 0.193897, 0.606134]),
    ("CuO", [3.24754, 2.44781, 2.21022], [0.52109, 0.570031, 0.722179]),
    ("d-C", [2.70872, 2.31883, 2.2289], [0.0, 0.0, 0.0]),
    ("Hg", [2.39894, 1.44003, 0.90957], [6.32759, 4.37192, 3.42176]),
    ("HgTe", [4.77904, 3.2312, 2.6599], [1.63161, 1.58081, 1.72929]),
    ("Ir", [3.0863, 2.08219, 1.61791], [5.59215, 4.06709, 3.26731]),
    ("K", [0.0640432, 0.0464098, 0.0381849], [2.1042, 1.34894, 0.913126]),
    ("Li", [0.265791, 0.195618, 0.220949], [3.54015, 2.31112, 1.66861]),
    ("MgO", [2.08958, 1.65072, 1.59488], [4.3327e-12, 0.0, 2.49865e-11]),
    ("Mo", [4.48397, 3.52513, 2.77631], [4.11144, 3.42083, 3.15061]),
    ("Na_palik", [0.0602694, 0.0561409, 0.0619884], [3.17927, 2.11249, 1.57904]),
    ("Nb", [3.42007, 2.79009, 2.39563], [3.44139, 2.73767, 2.57975]),
    ("Ni_palik", [2.3673, 1.66337, 1.46708], [4.49881, 3.05015, 2.34544]),
    ("Rh", [2.58579, 1.86022, 1.55426], [6.78226, 4.70299, 3.97607]),
    ("Se", [4.05831, 2.84294, 2.82085], [0.75405, 0.638444, 0.521808]),
    ("SiC", [3.17234, 2.52597, 2.47937], [7.53766e-07, 0.0, 1.01925e-05]),
    ("SnTe", [4.52425, 1.98164, 1.28159], [0.0, 0.0, 0.0]),
    ("Ta", [2.06272, 2.39294, 2.62793], [2.40836, 1.74149, 1.94703]),
    ("Te", [7.39023, 4.4821, 2.63711], [3.25602, 3.52706, 3.29205]),
    ("ThF4", [1.83071, 1.44223, 1.38765], [0.0, 0.0, 0.0]),
    ("TiC", [3.70053, 2.83742, 2.58229], [3.26564, 2.35159, 2.17279]),
    ("TiN", [1.64845, 1.15052, 1.37982], [3.36833, 1.9435, 1.10207]),
    ("TiO2", [3.45661, 2.80174, 2.90517], [0.000105265, 0.0, 0.000652887]),
    ("VC", [3.65757, 2.75274, 2.53267], [3.0683, 2.19869, 1.96319]),
    ("V_palik", [4.27758, 3.51295, 2.76107], [3.4913, 2.88945, 3.11152]),
    ("VN", [2.8656, 2.11919, 1.94009], [3.03224, 2.05612, 1.61631]),
    ("W", [4.37082, 3.30025, 2.99841], [3.50064, 2.60487, 2.27323]),
    ("none", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
];

/// The complex IOR (eta, k) of a conductor of [`NAMED_CONDUCTORS`] by its Mitsuba name.
pub fn named_conductor(name: &str) -> Option<(Rgb, Rgb)> {
    NAMED_CONDUCTORS.iter().find(|c| c.0 == name).map(|&(_, eta, k)| (Rgb::from(eta), Rgb::from(k)))
}

/// The names [`named_conductor`] knows, comma separated, for messages.
pub fn conductor_names() -> String {
    NAMED_CONDUCTORS.iter().map(|c| c.0).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_named_conductor_reflects_a_finite_fraction_at_every_angle() {
        for &(name, _, _) in NAMED_CONDUCTORS {
            let (eta, k) = named_conductor(name).unwrap();
            for cos in [1.0, 0.999, 0.7, 0.3, 0.01, 0.0] {
                let f = crate::bsdf::fresnel::fresnel_conductor(cos, eta, k);
                assert!(
                    f.is_finite() && f.min_element() >= 0.0 && f.max_element() <= 1.0 + 1e-6,
                    "{name} at {cos}: {f}"
                );
            }
        }
        assert!(conductor_names().contains("Au, Be"));
    }

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
