//! The anisotropic GGX (Trowbridge-Reitz) microfacet distribution (Walter et al. 2007,
//! "Microfacet Models for Refraction through Rough Surfaces"), with visible-normal sampling
//! (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4)).
//!
//! Shadowing-masking is Smith's *separable* form G = G1(wo) G1(wi), as Mitsuba 3 uses, so that
//! tessera and its independent check render the same model (pbrt-v4 uses the height-correlated
//! form; the two differ by a few percent at grazing angles).

use crate::simd::{Real, V3};
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
        self.d_of(m.into())
    }

    /// [`Ggx::d`] in one lane or eight.
    #[inline(always)]
    pub fn d_of<T: Real>(&self, m: V3<T>) -> T {
        let (x, y) = (m.x / T::splat(self.alpha_u), m.y / T::splat(self.alpha_v));
        let e = x * x + y * y + m.z * m.z;
        let d = T::splat(1.0) / (T::splat(PI * self.alpha_u * self.alpha_v) * e * e);
        // Mitsuba's guard: tiny values only produce numerical trouble downstream.
        T::select(T::splat(1e-20).lt(d * m.z), d, T::splat(0.0))
    }

    /// Smith's masking function G1(v, m) = 2 / (1 + sqrt(1 + alpha(v)^2 tan^2 theta_v)), zero
    /// when v sees the back of the microfacet m or lies on the other side of the macrosurface.
    #[inline]
    pub fn g1(&self, v: Vec3, m: Vec3) -> f32 {
        self.g1_of(v.into(), m.into())
    }

    /// [`Ggx::g1`] in one lane or eight.
    #[inline(always)]
    pub fn g1_of<T: Real>(&self, v: V3<T>, m: V3<T>) -> T {
        let (one, zero) = (T::splat(1.0), T::splat(0.0));
        let (x, y) = (T::splat(self.alpha_u) * v.x, T::splat(self.alpha_v) * v.y);
        let xy = x * x + y * y;
        let tan2_alpha2 = xy / (v.z * v.z);
        let g1 = T::splat(2.0) / (one + (one + tan2_alpha2).sqrt());
        // Normal incidence (xy = 0) is 1 exactly, where tan2_alpha2 may be 0 / 0.
        T::select((v.dot(m) * v.z).le(zero), zero, T::select(xy.eq(zero), one, g1))
    }

    /// Separable shadowing-masking G1(wo, m) G1(wi, m).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Sample a microfacet normal from the distribution of normals visible from `w`
    /// (`w.z > 0`): D_w(m) = G1(w, m) max(0, w.m) D(m) / w.z.
    pub fn sample_visible(&self, w: Vec3, u: Vec2) -> Vec3 {
        self.sample_visible_of(w.into(), [u.x, u.y]).into()
    }

    /// [`Ggx::sample_visible`] in one lane or eight (Heitz 2018, listing 1).
    #[inline(always)]
    pub fn sample_visible_of<T: Real>(&self, w: V3<T>, u: [T; 2]) -> V3<T> {
        let (one, zero) = (T::splat(1.0), T::splat(0.0));
        let (alpha_u, alpha_v) = (T::splat(self.alpha_u), T::splat(self.alpha_v));
        // Stretch to the hemisphere configuration of alpha = 1.
        let vh = V3::new(alpha_u * w.x, alpha_v * w.y, w.z).normalize();
        // Orthonormal basis around vh (t1 horizontal; x where vh is the pole).
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = V3::select(zero.lt(len2), V3::new(-vh.y, vh.x, zero) / len2.sqrt(), V3::new(one, zero, zero));
        let t2 = vh.cross(t1);
        // Uniform point on the disk, warped onto the visible half of the projected hemisphere.
        let r = u[0].sqrt();
        let (s_phi, c_phi) = (T::splat(2.0 * PI) * u[1]).sin_cos();
        let p1 = r * c_phi;
        let s = T::splat(0.5) * (one + vh.z);
        let p2 = (one - s) * (one - p1 * p1).max(zero).sqrt() + s * r * s_phi;
        // Reproject onto the hemisphere, then unstretch.
        let nh = t1 * p1 + t2 * p2 + vh * (one - p1 * p1 - p2 * p2).max(zero).sqrt();
        V3::new(alpha_u * nh.x, alpha_v * nh.y, nh.z.max(zero)).normalize()
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
    use crate::simd::F32x8;
    use crate::simd::testing::{direction, gather, isas, lane, numbers, on_every_isa, upper_direction};

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

    #[test]
    fn lanes_give_d_and_g1_bit_for_bit_with_either_instruction_set() {
        let g = Ggx::new(0.05, 0.3);
        for isa in isas() {
            for chunk in 0..2000 {
                let (v, m) = (|i| direction(chunk * 16 + i), |i| direction(chunk * 16 + 8 + i));
                let (d, g1) = isa.run(|| (g.d_of(gather(m)), g.g1_of(gather(v), gather(m))));
                for i in 0..8 {
                    assert_eq!(d.0[i].to_bits(), g.d(m(i)).to_bits(), "{isa:?} D({})", m(i));
                    assert_eq!(g1.0[i].to_bits(), g.g1(v(i), m(i)).to_bits(), "{isa:?} G1({}, {})", v(i), m(i));
                }
            }
        }
    }

    #[test]
    fn lane_samples_match_one_at_a_time_and_agree_across_instruction_sets() {
        let g = Ggx::new(0.05, 0.3);
        let mut worst = 0.0f32;
        on_every_isa(|isa| {
            let mut samples = Vec::new();
            for chunk in 0..4000 {
                let w = |i: usize| upper_direction(chunk * 8 + i);
                let u = |i: usize| Vec2::from(numbers(chunk, i));
                let m = isa
                    .run(|| g.sample_visible_of(gather(w), [F32x8::from_fn(|i| u(i).x), F32x8::from_fn(|i| u(i).y)]));
                for i in 0..8 {
                    let got = lane(m, i);
                    worst = worst.max((got - g.sample_visible(w(i), u(i))).abs().max_element());
                    samples.push(got.to_array().map(f32::to_bits));
                }
            }
            samples
        });
        // Lanes differ from one value at a time only by their sine and cosine (within 2e-7),
        // which the warp onto the hemisphere amplifies where sqrt(1 - p1^2) is steep.
        assert!(worst < 1e-4, "largest difference from the f32 samples {worst:e}");
    }
}
