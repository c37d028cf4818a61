//! Bidirectional scattering distribution functions, in the local shading frame.
//!
//! Contract shared by every model (Mitsuba 3's, with pbrt-v4's names for the directions):
//! - `wo` points towards the viewer (the previous path vertex), `wi` towards the light (the next
//!   one), both unit vectors in the local frame where the shading normal is +z;
//! - `eval(wo, wi)` returns f(wo, wi) |cos theta_i|: the cosine is included;
//! - `pdf(wo, wi)` is the solid-angle density with which `sample(wo, ..)` returns `wi`;
//!   each model computes the two together (`eval_pdf`), as next-event estimation needs both;
//! - `sample` returns the direction and its weight f |cos| / pdf. Delta lobes (smooth mirrors
//!   and glass) have `eval = pdf = 0` and are only reached through `sample`.
//!
//! Parameter names follow Mitsuba 3's plugins (`reflectance`, `alpha_u`, `alpha_v`, `eta`, `k`,
//! `specular_reflectance`, `int_ior`, `ext_ior`, `diffuse_reflectance`) so that scenes translate
//! one to one. Reflective models are one-sided, as in Mitsuba: their back is black unless the
//! material is `two_sided`.

mod conductor;
mod dielectric;
mod diffuse;
pub mod fresnel;
pub mod ggx;
mod pbr;
mod plastic;

pub use conductor::{Conductor, ConductorFresnel};
pub use dielectric::Dielectric;
pub use diffuse::Diffuse;
pub use ggx::Ggx;
pub use pbr::Pbr;
pub use plastic::{Plastic, PlasticTables};

use crate::color::Rgb;
use glam::{Vec2, Vec3};

/// A direction sampled from a BSDF.
#[derive(Clone, Copy, Debug)]
pub struct BsdfSample {
    /// The sampled direction towards the light (local frame).
    pub wi: Vec3,
    /// f |cos theta_i| / pdf: the factor the path throughput is multiplied by.
    pub weight: Rgb,
    /// Solid-angle density of `wi`; for a delta lobe, the probability of having chosen it.
    pub pdf: f32,
    /// True when `wi` comes from a delta lobe (no density, no MIS with light sampling).
    pub delta: bool,
    /// Relative index of refraction crossed (1 for reflection), for Russian roulette.
    pub eta: f32,
}

/// The BSDF at a surface point, with its texture lookups already done.
#[derive(Clone, Copy, Debug)]
pub enum Bsdf<'a> {
    /// Lambertian reflection.
    Diffuse(Diffuse),
    /// Smooth or rough (anisotropic GGX) metal.
    Conductor(Conductor),
    /// Smooth or rough glass.
    Dielectric(Dielectric),
    /// Rough dielectric coating over a diffuse base.
    Plastic(Plastic<'a>),
    /// glTF metallic-roughness: a blend of a Schlick conductor and a plastic.
    Pbr(Pbr<'a>),
}

impl Bsdf<'_> {
    /// f(wo, wi) |cos theta_i| and the solid-angle density of sampling `wi` given `wo`,
    /// computed together: they share most of their terms (the half vector, D, G1, Fresnel).
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        match self {
            Bsdf::Diffuse(b) => b.eval_pdf(wo, wi),
            Bsdf::Conductor(b) => b.eval_pdf(wo, wi),
            Bsdf::Dielectric(b) => b.eval_pdf(wo, wi),
            Bsdf::Plastic(b) => b.eval_pdf(wo, wi),
            Bsdf::Pbr(b) => b.eval_pdf(wo, wi),
        }
    }

    /// f(wo, wi) |cos theta_i| ([`Bsdf::eval_pdf`]'s first half).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval_pdf(wo, wi).0
    }

    /// Solid-angle density of sampling `wi` given `wo` ([`Bsdf::eval_pdf`]'s second half).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).1
    }

    /// Sample `wi` given `wo`, with a uniform number `u1` to choose a lobe and `u2` for the
    /// direction. None when the sample carries no energy (below the horizon, absorbed).
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        match self {
            Bsdf::Diffuse(b) => b.sample(wo, u2),
            Bsdf::Conductor(b) => b.sample(wo, u2),
            Bsdf::Dielectric(b) => b.sample(wo, u1, u2),
            Bsdf::Plastic(b) => b.sample(wo, u1, u2),
            Bsdf::Pbr(b) => b.sample(wo, u1, u2),
        }
    }

    /// True when every lobe is a delta: light sampling cannot contribute.
    pub fn is_delta(&self) -> bool {
        match self {
            Bsdf::Conductor(b) => b.ggx.is_none(),
            Bsdf::Dielectric(b) => b.ggx.is_none(),
            Bsdf::Diffuse(_) | Bsdf::Plastic(_) | Bsdf::Pbr(_) => false,
        }
    }

    /// True for models that scatter from both sides (glass); the others are one-sided.
    pub fn is_two_sided_by_nature(&self) -> bool {
        matches!(self, Bsdf::Dielectric(_))
    }

    /// A colour summarising the surface, for the albedo AOV: the reflectance parameter that
    /// tints the model.
    pub fn albedo(&self) -> Rgb {
        match self {
            Bsdf::Diffuse(b) => b.reflectance,
            Bsdf::Conductor(b) => b.specular_reflectance * b.fresnel.normal_incidence(),
            Bsdf::Dielectric(b) => b.specular_transmittance,
            Bsdf::Plastic(b) => b.diffuse_reflectance,
            Bsdf::Pbr(b) => b.base_color,
        }
    }
}
