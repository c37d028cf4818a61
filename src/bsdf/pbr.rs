//! glTF 2.0 metallic-roughness as a BSDF: a blend, by `metallic`, of a GGX conductor whose
//! Fresnel is Schlick's with F0 = base colour, and a rough plastic (IOR 1.5) whose diffuse base
//! has the base colour. Both lobes share the roughness alpha = roughness^2. Anisotropy (as
//! KHR_materials_anisotropy: alpha along the direction mix(alpha, 1, strength^2), alpha across
//! it) shapes the metal lobe; the dielectric lobe, whose tables are isotropic, takes the
//! geometric mean of the two. An occlusion factor darkens the diffuse base only (a cavity term
//! for detail below the geometry; path tracing computes the rest of the occlusion).

use super::{BsdfSample, Conductor, ConductorFresnel, Ggx, Plastic, PlasticTables};
use crate::color::Rgb;
use glam::{Vec2, Vec3};

/// The glTF metallic-roughness model at a surface point.
#[derive(Clone, Copy, Debug)]
pub struct Pbr<'a> {
    /// Base colour (albedo of the dielectric, F0 of the metal).
    pub base_color: Rgb,
    /// Metalness in [0, 1].
    pub metallic: f32,
    /// GGX alpha of the metal lobe along the shading frame's s (the anisotropy direction).
    pub alpha_u: f32,
    /// GGX alpha of the metal lobe along t.
    pub alpha_v: f32,
    /// Factor on the diffuse base's albedo (ambient occlusion map), in [0, 1].
    pub occlusion: f32,
    /// Interface albedos of the IOR-1.5 coating over the alpha grid.
    pub tables: &'a PlasticTables,
}

impl<'a> Pbr<'a> {
    /// The isotropic model of glTF's core metallic-roughness, without occlusion.
    pub fn isotropic(base_color: Rgb, metallic: f32, alpha: f32, tables: &'a PlasticTables) -> Self {
        Pbr { base_color, metallic, alpha_u: alpha, alpha_v: alpha, occlusion: 1.0, tables }
    }

    fn metal(&self) -> Conductor {
        Conductor {
            ggx: Some(Ggx::new(self.alpha_u, self.alpha_v)),
            fresnel: ConductorFresnel::Schlick { f0: self.base_color },
            specular_reflectance: Rgb::ONE,
        }
    }

    fn dielectric(&self) -> Plastic<'_> {
        Plastic {
            diffuse_reflectance: self.base_color * self.occlusion,
            specular_reflectance: Rgb::ONE,
            alpha: (self.alpha_u * self.alpha_v).sqrt(),
            tables: self.tables,
        }
    }

    /// metallic f_metal + (1 - metallic) f_dielectric, times |cos theta_i|, and the same blend
    /// of the two lobes' densities.
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let m = self.metallic;
        let (mut f, mut p) = (Rgb::ZERO, 0.0);
        if m > 0.0 {
            let (f_metal, p_metal) = self.metal().eval_pdf(wo, wi);
            f += f_metal * m;
            p += p_metal * m;
        }
        if m < 1.0 {
            let (f_dielectric, p_dielectric) = self.dielectric().eval_pdf(wo, wi);
            f += f_dielectric * (1.0 - m);
            p += p_dielectric * (1.0 - m);
        }
        (f, p)
    }

    /// Choose the metal with probability `metallic`, sample it, weight by the whole blend.
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let m = self.metallic;
        let wi = if u1 < m {
            self.metal().sample(wo, u2)?.wi
        } else {
            let u1 = if m > 0.0 { ((u1 - m) / (1.0 - m)).clamp(0.0, 1.0 - f32::EPSILON) } else { u1 };
            self.dielectric().sample(wo, u1, u2)?.wi
        };
        let (f, pdf) = self.eval_pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample { wi, weight: f / pdf, pdf, delta: false, eta: 1.0 })
    }
}
