//! Sine and cosine in lanes, where libm cannot run: Cody and Waite's reduction by pi/2 (pi/2
//! split in three parts, so that q pi/2 is subtracted without rounding for |q| < 2^13) and the
//! minimax polynomials of Cephes' `sinf` and `cosf` on [-pi/4, pi/4] (Moshier 1989). Within 2e-7
//! of the true values for |x| <= 8192 (tested); the path tracer calls it on [0, 2 pi). Its loops
//! index the lanes, as `lanes.rs` explains.
#![allow(clippy::needless_range_loop)]

use super::Real;
use super::lanes::{F32x8, M32x8};

/// pi/2 in three parts: the first two have few enough bits that q times them is exact.
const PI_2_PARTS: [f32; 3] = [1.570_312_5, 4.837_513e-4, 7.549_79e-8];

/// (sin x, cos x) in each lane, for |x| <= 8192; NaN for NaN and infinite lanes.
#[inline(always)]
pub fn sin_cos(x: F32x8) -> (F32x8, F32x8) {
    let q = (x * F32x8::splat(std::f32::consts::FRAC_2_PI)).round_small();
    let r = x - q * F32x8::splat(PI_2_PARTS[0]) - q * F32x8::splat(PI_2_PARTS[1]) - q * F32x8::splat(PI_2_PARTS[2]);
    let r2 = r * r;
    let sin_r = r + r
        * r2
        * ((F32x8::splat(-1.951_529_6e-4) * r2 + F32x8::splat(8.332_161e-3)) * r2 + F32x8::splat(-1.666_665_5e-1));
    let cos_r = F32x8::splat(1.0) - r2 * F32x8::splat(0.5)
        + r2 * r2
            * ((F32x8::splat(2.443_315_7e-5) * r2 + F32x8::splat(-1.388_731_6e-3)) * r2 + F32x8::splat(4.166_664_6e-2));
    // x = q pi/2 + r: odd quadrants swap sine and cosine; quadrants 2 and 3 negate the sine,
    // quadrants 1 and 2 the cosine (by the sign bit).
    let q = q.to_i32();
    let (mut swap, mut sin_sign, mut cos_sign) = ([0u32; 8], [0u32; 8], [0u32; 8]);
    for i in 0..8 {
        swap[i] = 0u32.wrapping_sub((q[i] & 1) as u32);
        sin_sign[i] = ((q[i] & 2) as u32) << 30;
        cos_sign[i] = ((q[i].wrapping_add(1) & 2) as u32) << 30;
    }
    let (sin, cos) =
        (F32x8::select(M32x8(swap), cos_r, sin_r).to_bits(), F32x8::select(M32x8(swap), sin_r, cos_r).to_bits());
    let (mut sin_out, mut cos_out) = ([0u32; 8], [0u32; 8]);
    for i in 0..8 {
        sin_out[i] = sin[i] ^ sin_sign[i];
        cos_out[i] = cos[i] ^ cos_sign[i];
    }
    (F32x8::from_bits(sin_out), F32x8::from_bits(cos_out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_is_within_2e_7_of_the_truth() {
        let mut worst = 0.0f64;
        let n = 400_000;
        for chunk in 0..n / 8 {
            // [-8192, 8192] coarsely, and [0, 2 pi] densely.
            let x = F32x8::from_fn(|i| {
                let k = (chunk * 8 + i) as f32 / n as f32;
                if chunk % 2 == 0 { -8192.0 + 16384.0 * k } else { std::f32::consts::TAU * k }
            });
            let (s, c) = sin_cos(x);
            for i in 0..8 {
                let xi = x.0[i] as f64;
                worst = worst.max((s.0[i] as f64 - xi.sin()).abs()).max((c.0[i] as f64 - xi.cos()).abs());
            }
        }
        assert!(worst < 2e-7, "largest error {worst:e}");
    }

    #[test]
    fn sin_cos_of_nan_and_infinity_is_nan() {
        let (s, c) = sin_cos(F32x8([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0]));
        for i in 0..3 {
            assert!(s.0[i].is_nan() && c.0[i].is_nan(), "lane {i}: {} {}", s.0[i], c.0[i]);
        }
        assert_eq!((s.0[3], c.0[3]), (0.0, 1.0));
    }
}
