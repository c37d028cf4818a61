//! Lambertian reflection (Mitsuba's `diffuse`).

use crate::color::Rgb;
use crate::sampling::warp;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

use super::BsdfSample;

/// Ideal diffuse reflection with albedo `reflectance`: f = reflectance / pi.
#[derive(Clone, Copy, Debug)]
pub struct Diffuse {
    /// Albedo in [0, 1] per channel.
    pub reflectance: Rgb,
}

impl Diffuse {
    /// f |cos theta_i| = reflectance cos theta_i / pi on the front side, 0 elsewhere, and the
    /// cosine-weighted hemisphere density.
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let f = if wi.z <= 0.0 { Rgb::ZERO } else { self.reflectance * (wi.z * FRAC_1_PI) };
        (f, warp::cosine_hemisphere_pdf(wi))
    }

    /// Cosine-weighted sampling; the weight is the albedo.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = warp::square_to_cosine_hemisphere(u);
        let pdf = warp::cosine_hemisphere_pdf(wi);
        (pdf > 0.0).then_some(BsdfSample { wi, weight: self.reflectance, pdf, delta: false, eta: 1.0 })
    }
}
