//! Random numbers and the warps that turn them into directions and points.

mod distribution;
mod rng;
pub mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub(crate) use rng::SamplerLanes;
pub(crate) use rng::mix64;
pub use rng::{PixelKey, Sampler};

use crate::simd::Real;

/// The power heuristic with exponent 2 for multiple importance sampling (Veach 1997, Eq. 9.13):
/// the weight of a sample drawn with density `pdf_a` when `pdf_b` could also have drawn it.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    power_heuristic_of(pdf_a, pdf_b)
}

/// [`power_heuristic`] in one lane or eight: 0 where `pdf_a` is 0, 1 where its square is
/// infinite or NaN.
#[inline(always)]
pub fn power_heuristic_of<T: Real>(pdf_a: T, pdf_b: T) -> T {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    let (zero, one) = (T::splat(0.0), T::splat(1.0));
    let finite = a.abs().lt(T::splat(f32::INFINITY));
    T::select(a.eq(zero), zero, T::select(finite, a / (a + b), one))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_heuristic_weights_sum_to_one() {
        for (a, b) in [(1.0, 1.0), (0.3, 7.0), (5.0, 0.0)] {
            assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-6);
        }
        assert_eq!(power_heuristic(0.0, 1.0), 0.0);
    }

    #[test]
    fn lanes_weigh_bit_for_bit_as_one_sample_does() {
        use crate::simd::F32x8;
        use crate::simd::testing::isas;
        let special = [0.0, -0.0, 1e-30, 1e30, 3e38, f32::INFINITY, f32::NAN, -2.0];
        let value = |k: usize| if k.is_multiple_of(5) { special[k / 5 % 8] } else { (k as f32 * 0.37).fract() * 10.0 };
        for isa in isas() {
            for chunk in 0..500 {
                let (a, b) = (|i| value(chunk * 8 + i), |i| value(chunk * 8 + i + 3));
                let w = isa.run(|| power_heuristic_of(F32x8::from_fn(a), F32x8::from_fn(b)));
                for i in 0..8 {
                    assert_eq!(w.0[i].to_bits(), power_heuristic(a(i), b(i)).to_bits(), "{isa:?} {} {}", a(i), b(i));
                }
            }
        }
    }
}
