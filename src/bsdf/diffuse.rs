//! Lambertian reflection (Mitsuba's `diffuse`).

use crate::color::Rgb;
use crate::sampling::warp;
use crate::simd::{Real, V3};
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
        let (factor, pdf, valid) = Diffuse::eval_terms(wo.into(), wi.into());
        if !valid {
            return (Rgb::ZERO, 0.0);
        }
        (self.reflectance * factor, pdf)
    }

    /// Cosine-weighted sampling; the weight is the albedo.
    pub fn sample(&self, wo: Vec3, u: Vec2) -> Option<BsdfSample> {
        let (wi, pdf, valid) = Diffuse::sample_terms(wo.into(), [u.x, u.y]);
        valid.then_some(BsdfSample { wi: wi.into(), weight: self.reflectance, pdf, delta: false, eta: 1.0 })
    }

    /// The colourless terms of [`Diffuse::eval_pdf`], in one lane or eight: the factor
    /// max(0, wi.z) / pi on the albedo, the density, and where they hold (`wo` above the surface;
    /// elsewhere f and the density are 0).
    #[inline(always)]
    pub fn eval_terms<T: Real>(wo: V3<T>, wi: V3<T>) -> (T, T, T::Mask) {
        let zero = T::splat(0.0);
        let factor = T::select(wi.z.le(zero), zero, wi.z * T::splat(FRAC_1_PI));
        (factor, warp::cosine_hemisphere_pdf_of(wi.z), !wo.z.le(zero))
    }

    /// The colourless terms of [`Diffuse::sample`], in one lane or eight: a cosine-weighted wi,
    /// its density, and where the sample holds.
    #[inline(always)]
    pub fn sample_terms<T: Real>(wo: V3<T>, u: [T; 2]) -> (V3<T>, T, T::Mask) {
        let zero = T::splat(0.0);
        let wi = warp::square_to_cosine_hemisphere_of(u);
        let pdf = warp::cosine_hemisphere_pdf_of(wi.z);
        (wi, pdf, !wo.z.le(zero) & zero.lt(pdf))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::F32x8;
    use crate::simd::testing::{direction, gather, isas, lane, numbers, on_every_isa};

    #[test]
    fn lanes_evaluate_bit_for_bit_as_one_path_does() {
        for isa in isas() {
            for chunk in 0..2000 {
                let (wo, wi) = (|i| direction(chunk * 16 + i), |i| direction(chunk * 16 + 8 + i));
                let (factor, pdf, valid) = isa.run(|| Diffuse::eval_terms(gather(wo), gather(wi)));
                for i in 0..8 {
                    let (one_factor, one_pdf, one_valid) = Diffuse::eval_terms(wo(i).into(), wi(i).into());
                    assert_eq!(
                        (factor.0[i].to_bits(), pdf.0[i].to_bits(), valid.test(i)),
                        (one_factor.to_bits(), one_pdf.to_bits(), one_valid),
                        "{isa:?} wo {} wi {}",
                        wo(i),
                        wi(i)
                    );
                }
            }
        }
    }

    #[test]
    fn lane_samples_match_one_path_and_agree_across_instruction_sets() {
        let (mut worst_disk, mut worst_z) = (0.0f32, 0.0f32);
        on_every_isa(|isa| {
            let mut bits = Vec::new();
            for chunk in 0..4000 {
                let wo = |i| direction(chunk * 8 + i);
                // The square's centre and edges too, where the concentric map branches.
                let u = |i: usize| match (chunk + i) % 50 {
                    0 => [0.5, 0.5],
                    1 => [0.0, 0.3],
                    2 => [0.7, 1.0],
                    _ => numbers(chunk, i),
                };
                let (wi, pdf, valid) = isa.run(|| {
                    Diffuse::sample_terms(gather(wo), [F32x8::from_fn(|i| u(i)[0]), F32x8::from_fn(|i| u(i)[1])])
                });
                for i in 0..8 {
                    let (one_wi, one_pdf, one_valid) = Diffuse::sample_terms(wo(i).into(), u(i));
                    if one_wi.z.abs() > 1e-3 {
                        assert_eq!(valid.test(i), one_valid, "{isa:?} wo {} u {:?}", wo(i), u(i));
                    }
                    let difference = (lane(wi, i) - Vec3::from(one_wi)).abs();
                    worst_disk = worst_disk.max(difference.x).max(difference.y);
                    worst_z = worst_z.max(difference.z).max((pdf.0[i] - one_pdf).abs() * std::f32::consts::PI);
                    bits.push([wi.x.0[i], wi.y.0[i], wi.z.0[i], pdf.0[i]].map(f32::to_bits));
                }
            }
            bits
        });
        // The lanes' sine and cosine differ from libm's in the last bits: so do the points on
        // the disk (6e-8 measured), and at the rim z = sqrt(1 - x^2 - y^2) by the square root
        // of those bits' effect on x^2 + y^2 near 1 (2.4e-4 measured, one unit in the last
        // place: 2^-12; two units would give 3.5e-4).
        assert!(worst_disk < 1e-6, "largest difference on the disk {worst_disk:e}");
        assert!(worst_z < 4e-4, "largest difference in z and the density {worst_z:e}");
    }
}
