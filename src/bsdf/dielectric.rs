//! Glass: a smooth or rough (isotropic or anisotropic GGX) dielectric interface (Mitsuba's
//! `dielectric` and `roughdielectric`; Walter et al. 2007).

use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::{BsdfSample, Ggx};
use crate::color::Rgb;
use glam::{Vec2, Vec3};

/// A dielectric interface with relative IOR `eta` = interior / exterior. Radiance crossing it
/// is scaled by 1 / eta_it^2 (solid-angle compression), as Mitsuba does for camera paths.
#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// Interior IOR over exterior IOR.
    pub eta: f32,
    /// Microfacet distribution; None for a smooth interface.
    pub ggx: Option<Ggx>,
    /// Factor on reflection (default 1).
    pub specular_reflectance: Rgb,
    /// Factor on transmission (default 1).
    pub specular_transmittance: Rgb,
}

/// The generalised half vector of a reflected or refracted pair (Walter et al., Eq. 13 and 16),
/// oriented to the macrosurface's front, and the relative IOR `eta` of the side `wi` lies in.
struct HalfVector {
    m: Vec3,
    reflect: bool,
    eta: f32,
}

impl Dielectric {
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<HalfVector> {
        if wo.z == 0.0 {
            return None;
        }
        let reflect = wo.z * wi.z > 0.0;
        let eta = if wo.z > 0.0 { self.eta } else { 1.0 / self.eta };
        let m = (wo + wi * if reflect { 1.0 } else { eta }).normalize();
        if !m.is_finite() {
            return None;
        }
        let m = if m.z < 0.0 { -m } else { m };
        // Both directions must see the microfacet from the side they are on.
        (wo.dot(m) * wo.z > 0.0 && wi.dot(m) * wi.z > 0.0).then_some(HalfVector { m, reflect, eta })
    }

    /// f |cos theta_i|: the reflection lobe F D G / (4 |cos_o|), the transmission lobe
    /// (1 - F) D G |wo.m| |wi.m| / (|cos_o| (wo.m + eta wi.m)^2) (Walter et al., Eq. 21, with
    /// the 1/eta^2 radiance scaling); and the density of [`Dielectric::sample`]: visible-normal
    /// density times the lobe probability (F or 1 - F) times the Jacobian of the half-vector
    /// map. Both 0 for a smooth interface (delta).
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(ggx) = self.ggx else {
            return (Rgb::ZERO, 0.0);
        };
        let Some(h) = self.half_vector(wo, wi) else {
            return (Rgb::ZERO, 0.0);
        };
        let d = ggx.d(h.m);
        let (om, im) = (wo.dot(h.m), wi.dot(h.m));
        let f = fresnel_dielectric(om, self.eta).r;
        let g = ggx.g(wo, wi, h.m);
        let value = if h.reflect {
            self.specular_reflectance * (f * d * g / (4.0 * wo.z.abs()))
        } else {
            let denom = om + h.eta * im;
            self.specular_transmittance * ((1.0 - f) * d * g * om * im / (wo.z * denom * denom)).abs()
        };
        let dm_dwi = if h.reflect { 1.0 / (4.0 * im) } else { h.eta * h.eta * im / (om + h.eta * im).powi(2) };
        let lobe = if h.reflect { f } else { 1.0 - f };
        let wo_front = if wo.z < 0.0 { -wo } else { wo };
        (value, (ggx.pdf_visible(wo_front, h.m) * lobe * dm_dwi).abs())
    }

    /// Choose reflection with probability F, else refraction, about the macro normal (smooth)
    /// or a visible microfacet normal (rough).
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let Some(ggx) = self.ggx else {
            let f = fresnel_dielectric(wo.z, self.eta);
            return Some(if u1 <= f.r {
                BsdfSample {
                    wi: Vec3::new(-wo.x, -wo.y, wo.z),
                    weight: self.specular_reflectance,
                    pdf: f.r,
                    delta: true,
                    eta: 1.0,
                }
            } else {
                BsdfSample {
                    wi: refract(wo, Vec3::Z, f.cos_theta_t, f.eta_ti),
                    weight: self.specular_transmittance * (f.eta_ti * f.eta_ti),
                    pdf: 1.0 - f.r,
                    delta: true,
                    eta: f.eta_it,
                }
            });
        };
        let wo_front = if wo.z < 0.0 { -wo } else { wo };
        let m = ggx.sample_visible(wo_front, u2);
        let pdf_m = ggx.pdf_visible(wo_front, m);
        let om = wo.dot(m);
        let f = fresnel_dielectric(om, self.eta);
        let (wi, mut weight, pdf, eta) = if u1 <= f.r {
            let wi = reflect(wo, m);
            (wi, self.specular_reflectance, pdf_m * f.r / (4.0 * wi.dot(m)), 1.0)
        } else {
            let wi = refract(wo, m, f.cos_theta_t, f.eta_ti);
            let im = wi.dot(m);
            let jacobian = f.eta_it * f.eta_it * im / (om + f.eta_it * im).powi(2);
            (wi, self.specular_transmittance * (f.eta_ti * f.eta_ti), pdf_m * (1.0 - f.r) * jacobian, f.eta_it)
        };
        let reflected = wi.z * wo.z > 0.0;
        if reflected != (eta == 1.0) {
            // Reflected below the horizon or refracted back to the same side: no energy.
            return None;
        }
        weight *= ggx.g1(wi, m);
        let pdf = pdf.abs();
        (pdf > 0.0 && pdf.is_finite() && weight.max_element() > 0.0).then_some(BsdfSample {
            wi,
            weight,
            pdf,
            delta: false,
            eta,
        })
    }
}
