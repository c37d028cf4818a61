//! Metals: smooth mirrors and rough anisotropic GGX conductors (Mitsuba's `conductor` and
//! `roughconductor` with `distribution = "ggx"`, `sample_visible = true`).

use super::fresnel::{fresnel_conductor, fresnel_schlick, reflect};
use super::{BsdfSample, Ggx};
use crate::color::Rgb;
use glam::{Vec2, Vec3};

/// How a conductor's reflectance varies with the angle.
#[derive(Clone, Copy, Debug)]
pub enum ConductorFresnel {
    /// Exact Fresnel for the complex IOR `eta + i k` (per RGB channel).
    Complex {
        /// Real part of the IOR.
        eta: Rgb,
        /// Imaginary part (extinction coefficient).
        k: Rgb,
    },
    /// Schlick's approximation from the reflectance at normal incidence (glTF metals).
    Schlick {
        /// Reflectance at normal incidence.
        f0: Rgb,
    },
}

impl ConductorFresnel {
    /// Reflectance at incident cosine `cos_theta` in [0, 1].
    #[inline]
    pub fn eval(&self, cos_theta: f32) -> Rgb {
        match *self {
            ConductorFresnel::Complex { eta, k } => fresnel_conductor(cos_theta, eta, k),
            ConductorFresnel::Schlick { f0 } => fresnel_schlick(f0, cos_theta),
        }
    }

    /// Reflectance at normal incidence.
    pub fn normal_incidence(&self) -> Rgb {
        self.eval(1.0)
    }
}

/// A conductor: a perfect mirror when `ggx` is None, else a rough microfacet reflector
/// f = F(wo.m) D(m) G(wo, wi, m) / (4 cos_o cos_i) (Walter et al. 2007, Eq. 20).
#[derive(Clone, Copy, Debug)]
pub struct Conductor {
    /// Microfacet distribution; None for a smooth mirror.
    pub ggx: Option<Ggx>,
    /// Fresnel term.
    pub fresnel: ConductorFresnel,
    /// Factor on the reflectance (Mitsuba's `specular_reflectance`, default 1).
    pub specular_reflectance: Rgb,
}

impl Conductor {
    /// f |cos theta_i| = F D G / (4 cos_o) for a rough conductor, and the visible-normal
    /// density of the reflected direction, D(m) G1(wo, m) / (4 cos_o), which share the half
    /// vector m, D and G1(wo, m); both 0 for a mirror (delta).
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(ggx) = self.ggx else {
            return (Rgb::ZERO, 0.0);
        };
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let m = (wo + wi).normalize();
        let d = ggx.d(m);
        if d == 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let g1_o = ggx.g1(wo, m);
        let g = g1_o * ggx.g1(wi, m);
        let f = self.fresnel.eval(wo.dot(m)) * self.specular_reflectance * (d * g / (4.0 * wo.z));
        (f, d * g1_o / (4.0 * wo.z))
    }

    /// Mirror reflection, or a reflection about a visible microfacet normal; the weight of the
    /// latter is F G1(wi, m) (the other factors cancel with the density).
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let Some(ggx) = self.ggx else {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let weight = self.fresnel.eval(wo.z) * self.specular_reflectance;
            return Some(BsdfSample { wi, weight, pdf: 1.0, delta: true, eta: 1.0 });
        };
        let m = ggx.sample_visible(wo, u);
        let wi = reflect(wo, m);
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = ggx.d(m) * ggx.g1(wo, m) / (4.0 * wo.z);
        if !(pdf > 0.0) {
            return None;
        }
        let weight = self.fresnel.eval(wo.dot(m)) * self.specular_reflectance * ggx.g1(wi, m);
        Some(BsdfSample { wi, weight, pdf, delta: false, eta: 1.0 })
    }
}
