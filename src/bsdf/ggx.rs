//! The anisotropic GGX (Trowbridge-Reitz) microfacet distribution (Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces"), with visible-normal sampling
//! (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)).
//!
//! Shadowing-masking is Smith's *separable* form G = G1(wo) G1(wi), as Mitsuba 3 uses, so that
//! tessera and its independent check render the same model (pbrt-v4 uses the height-correlated
//! form; the two differ by a few percent at grazing angles).

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Smallest roughness: Mitsuba clamps alpha to 1e-4, below which D overflows in f32.
pub const MIN_ALPHA: f32 = 1e-4;

/// An anisotropic GGX distribution in the local shading frame; `alpha_u` is the roughness along
/// the tangent s (local x), `alpha_v` along t (local y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    /// Roughness along local x.
    pub alpha_u: f32,
    /// Roughness along local y.
    pub alpha_v: f32,
}

impl Ggx {
    /// A distribution with the given roughness, clamped to [`MIN_ALPHA`].
    pub fn new(alpha_u: f32, alpha_v: f32) -> Self {
        Ggx { alpha_u: alpha_u.max(MIN_ALPHA), alpha_v: alpha_v.max(MIN_ALPHA) }
    }

    /// Normal distribution D(m) = 1 / (pi au av (mx^2/au^2 + my^2/av^2 + mz^2)^2), zero below
    /// the macrosurface.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        let (x, y) = (m.x / self.alpha_u, m.y / self.alpha_v);
        let e = x * x + y * y + m.z * m.z;
        let d = 1.0 / (PI * self.alpha_u * self.alpha_v * e * e);
        // Mitsuba's guard: tiny values only produce numerical trouble downstream.
        if d * m.z > 1e-20 { d } else { 0.0 }
    }

    /// Smith's masking function G1(v, m) = 2 / (1 + sqrt(1 + alpha(v)^2 tan^2 theta_v)), zero
    /// when v sees the back of the microfacet m or lies on the other side of the macrosurface.
    #[inline]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        let xy = (self.alpha_u * v.x).powi(2) + (self.alpha_v * v.y).powi(2);
        if xy == 0.0 {
            return 1.0;
        }
        let tan2_alpha2 = xy / (v.z * v.z);
        2.0 / (1.0 + (1.0 + tan2_alpha2).sqrt())
    }

    /// Separable shadowing-masking G1(wo, m) G1(wi, m).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Sample a microfacet normal from the distribution of normals visible from `w`
    /// (`w.z > 0`): D_w(m) = G1(w, m) max(0, w.m) D(m) / w.z.
    pub fn sample_visible(&self, w: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the hemisphere configuration of alpha = 1.
        let vh = Vec3::new(self.alpha_u * w.x, self.alpha_v * w.y, w.z).normalize();
        // Orthonormal basis around vh (t1 horizontal).
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        // Uniform point on the disk, warped onto the visible half of the projected hemisphere.
        let r = u.x.sqrt();
        let (s_phi, c_phi) = (2.0 * PI * u.y).sin_cos();
        let p1 = r * c_phi;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * s_phi;
        // Reproject onto the hemisphere, then unstretch.
        let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        Vec3::new(self.alpha_u * nh.x, self.alpha_v * nh.y, nh.z.max(0.0)).normalize()
    }

    /// Density of [`Ggx::sample_visible`] over microfacet normals (per steradian of m).
    #[inline]
    pub fn pdf_visible(&self, w: Vec3, m: Vec3) -> f32 {
        if w.z == 0.0 {
            return 0.0;
        }
        self.d(m) * self.g1(w, m) * w.dot(m).abs() / w.z.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integrate f over the sphere with a midpoint rule in (cos theta, phi).
    fn integrate_sphere(f: impl Fn(Vec3) -> f64, n: usize) -> f64 {
        let mut sum = 0.0;
        for i in 0..n {
            let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            for j in 0..2 * n {
                let phi = std::f64::consts::PI * (j as f64 + 0.5) / n as f64;
                let w = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                sum += f(w);
            }
        }
        sum * (4.0 * std::f64::consts::PI) / (2 * n * n) as f64
    }

    #[test]
    fn ggx_projected_area_is_one() {
        // int D(m) m.z dm = 1 (the microsurface projects onto the unit macrosurface).
        for (au, av) in [(0.5, 0.5), (0.3, 0.8), (0.9, 0.2)] {
            let g = Ggx::new(au, av);
            let i = integrate_sphere(|m| (g.d(m) * m.z.max(0.0)) as f64, 600);
            assert!((i - 1.0).abs() < 2e-3, "alpha ({au}, {av}): {i}");
        }
    }

    #[test]
    fn ggx_visible_normals_are_normalised() {
        // int G1(w, m) max(0, w.m) D(m) dm = w.z (Heitz 2014, Eq. 2).
        let g = Ggx::new(0.4, 0.7);
        for w in [Vec3::new(0.3, 0.1, 0.9).normalize(), Vec3::new(-0.8, 0.5, 0.2).normalize()] {
            let i = integrate_sphere(|m| (g.pdf_visible(w, m)) as f64, 600);
            assert!((i - 1.0).abs() < 3e-3, "w {w}: {i}");
        }
    }
}
