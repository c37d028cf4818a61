//! Random numbers and the warps that turn them into directions and points.

mod distribution;
mod rng;
pub mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub(crate) use rng::mix64;
pub use rng::{PixelKey, Sampler};

/// The power heuristic with exponent 2 for multiple importance sampling (Veach 1997, Eq. 9.13):
/// the weight of a sample drawn with density `pdf_a` when `pdf_b` could also have drawn it.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a == 0.0 {
        return 0.0;
    }
    if !a.is_finite() {
        return 1.0;
    }
    a / (a + b)
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
}
