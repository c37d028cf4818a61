//! Metals: smooth mirrors and rough anisotropic GGX conductors (Mitsuba's `conductor` and
//! `roughconductor` with `distribution = "ggx"`, `sample_visible = true`).

use super::fresnel::{fresnel_conductor, fresnel_schlick, reflect_of};
use super::{BsdfSample, Ggx};
use crate::color::Rgb;
use crate::simd::{Real, V3};
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
        let terms = Conductor::eval_terms(&ggx, wo.into(), wi.into());
        if !terms.valid {
            return (Rgb::ZERO, 0.0);
        }
        (self.fresnel.eval(terms.cos_m) * self.specular_reflectance * terms.factor, terms.pdf)
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
        let terms = Conductor::sample_terms(&ggx, wo.into(), [u.x, u.y]);
        if !terms.valid {
            return None;
        }
        let weight = self.fresnel.eval(terms.cos_m) * self.specular_reflectance * terms.factor;
        Some(BsdfSample { wi: terms.wi.into(), weight, pdf: terms.pdf, delta: false, eta: 1.0 })
    }

    /// The colourless terms of [`Conductor::sample`] on a rough conductor (`wo.z > 0`), in one
    /// lane or eight: wi reflected about a visible normal m, its density D G1(wo, m) / (4 wo.z),
    /// and the weight's factor G1(wi, m) on F(wo . m) times the specular reflectance.
    #[inline(always)]
    pub fn sample_terms<T: Real>(ggx: &Ggx, wo: V3<T>, u: [T; 2]) -> ReflectionTerms<T> {
        let zero = T::splat(0.0);
        let m = ggx.sample_visible_of(wo, u);
        let wi = reflect_of(wo, m);
        let pdf = ggx.d_of(m) * ggx.g1_of(wo, m) / (T::splat(4.0) * wo.z);
        let valid = !wi.z.le(zero) & zero.lt(pdf);
        ReflectionTerms { wi, cos_m: wo.dot(m), factor: ggx.g1_of(wi, m), pdf, valid }
    }

    /// The colourless terms of [`Conductor::eval_pdf`] on a rough conductor, in one lane or
    /// eight: the factor D G / (4 wo.z) on F(wo . m) times the specular reflectance, and the
    /// density D G1(wo, m) / (4 wo.z), with m the half vector; invalid (f and the density 0) below
    /// either horizon or where D vanishes.
    #[inline(always)]
    pub fn eval_terms<T: Real>(ggx: &Ggx, wo: V3<T>, wi: V3<T>) -> ReflectionTerms<T> {
        let zero = T::splat(0.0);
        let m = (wo + wi).normalize();
        let d = ggx.d_of(m);
        let g1_o = ggx.g1_of(wo, m);
        let g = g1_o * ggx.g1_of(wi, m);
        let four_wo_z = T::splat(4.0) * wo.z;
        let valid = !wo.z.le(zero) & !wi.z.le(zero) & !d.eq(zero);
        ReflectionTerms { wi, cos_m: wo.dot(m), factor: d * g / four_wo_z, pdf: d * g1_o / four_wo_z, valid }
    }
}

/// What a rough conductor's sampling or evaluation computes before its colour
/// ([`Conductor::sample_terms`], [`Conductor::eval_terms`]).
#[derive(Clone, Copy, Debug)]
pub struct ReflectionTerms<T: Real> {
    /// The direction towards the light (sampled, or the one evaluated).
    pub wi: V3<T>,
    /// wo . m, the Fresnel term's cosine.
    pub cos_m: T,
    /// The factor on F(wo . m) times the specular reflectance.
    pub factor: T,
    /// Solid-angle density of wi.
    pub pdf: T,
    /// Where the terms hold; elsewhere the sample fails, or f and the density are 0.
    pub valid: T::Mask,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::fresnel::fresnel_conductor_of;
    use crate::simd::F32x8;
    use crate::simd::testing::{direction, gather, isas, lane, numbers, on_every_isa, upper_direction};

    #[test]
    fn lanes_evaluate_and_fresnel_bit_for_bit_as_one_path_does() {
        let ggx = Ggx::new(0.05, 0.3);
        let (eta, k) = (Rgb::new(1.657_5, 0.880_3, 0.521_2), Rgb::new(9.223_8, 6.269_5, 4.837));
        for isa in isas() {
            for chunk in 0..2000 {
                let (wo, wi) = (|i| direction(chunk * 16 + i), |i| direction(chunk * 16 + 8 + i));
                let cos = F32x8::from_fn(|i| (chunk * 8 + i) as f32 / 16_000.0);
                let (terms, fresnel) = isa.run(|| {
                    let terms = Conductor::eval_terms(&ggx, gather(wo), gather(wi));
                    let channel = |c: usize| fresnel_conductor_of(cos, F32x8::splat(eta[c]), F32x8::splat(k[c]));
                    (terms, [channel(0), channel(1), channel(2)])
                });
                for i in 0..8 {
                    let one = Conductor::eval_terms(&ggx, wo(i).into(), wi(i).into());
                    let got = (terms.valid.test(i), terms.cos_m.0[i], terms.factor.0[i], terms.pdf.0[i]);
                    assert_eq!(
                        (got.0, got.1.to_bits(), got.2.to_bits(), got.3.to_bits()),
                        (one.valid, one.cos_m.to_bits(), one.factor.to_bits(), one.pdf.to_bits()),
                        "{isa:?} wo {} wi {}",
                        wo(i),
                        wi(i)
                    );
                    let f = fresnel_conductor(cos.0[i], eta, k);
                    for c in 0..3 {
                        assert_eq!(fresnel[c].0[i].to_bits(), f[c].to_bits(), "{isa:?} channel {c}");
                    }
                }
            }
        }
    }

    #[test]
    fn lane_samples_match_one_path_and_agree_across_instruction_sets() {
        let ggx = Ggx::new(0.05, 0.3);
        let mut worst = 0.0f32;
        on_every_isa(|isa| {
            let mut bits = Vec::new();
            for chunk in 0..4000 {
                let wo = |i: usize| upper_direction(chunk * 8 + i);
                let u = |i: usize| numbers(chunk, i);
                let terms = isa.run(|| {
                    Conductor::sample_terms(
                        &ggx,
                        gather(wo),
                        [F32x8::from_fn(|i| u(i)[0]), F32x8::from_fn(|i| u(i)[1])],
                    )
                });
                for i in 0..8 {
                    let one = Conductor::sample_terms(&ggx, wo(i).into(), u(i));
                    let wi = lane(terms.wi, i);
                    // Away from the horizon, where the sine's last bits cannot decide validity.
                    if one.wi.z.abs() > 1e-3 {
                        assert_eq!(terms.valid.test(i), one.valid, "{isa:?} wo {} u {:?}", wo(i), u(i));
                    }
                    if one.valid && terms.valid.test(i) {
                        let rel = |a: f32, b: f32| (a - b).abs() / b.abs().max(1.0);
                        worst = worst
                            .max((wi - Vec3::from(one.wi)).abs().max_element())
                            .max(rel(terms.cos_m.0[i], one.cos_m))
                            .max(rel(terms.factor.0[i], one.factor))
                            .max((terms.pdf.0[i] / one.pdf - 1.0).abs());
                    }
                    bits.push(
                        [terms.wi.x.0[i], terms.wi.y.0[i], terms.wi.z.0[i], terms.pdf.0[i], terms.factor.0[i]]
                            .map(f32::to_bits),
                    );
                }
            }
            bits
        });
        // Directions absolutely, the cosine, factor and density relatively: the lanes' sine and
        // cosine differ from libm's in the last bits (3e-5 measured).
        assert!(worst < 2e-4, "largest difference from one path's terms {worst:e}");
    }
}
