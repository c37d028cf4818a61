//! Small numerical tools: a fast floor, quadrature, the standard normal distribution, and the
//! polar decomposition of 3x3 matrices.

mod polar;

pub use polar::{polar_decomposition, symmetric_eigen};

/// Nodes and weights of the n-point Gauss-Legendre rule on [-1, 1], by Newton iteration on the
/// Legendre polynomial P_n (Golub-Welsch would do as well; n is small here).
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    assert!(n >= 1);
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        // Initial guess (Tricomi): the i-th root from the right.
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // p1 = P_n(x), p0 = P_{n-1}(x) (also for n = 1).
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / derivative;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * derivative * derivative);
    }
    (nodes, weights)
}

/// floor(x), without the library call that x86-64's baseline instruction set (no SSE4.1
/// `roundps`) makes of `f32::floor`: identical for every input (floats of magnitude 2^23 and
/// above are integers; NaN and infinities pass through), except that -0.0 gives 0.0.
#[inline(always)]
pub fn floor(x: f32) -> f32 {
    if x.abs() < 8_388_608.0 {
        let t = x as i32 as f32;
        if t > x { t - 1.0 } else { t }
    } else {
        x
    }
}

/// floor(x) as an integer, and the fraction x - floor(x): a texel's index and weight, for
/// |x| < 2^23 (beyond, the integer saturates at i32's range). One conversion to an integer,
/// none back: [`floor`] then a cast converts twice. The fraction is bit for bit x - floor(x);
/// NaN gives index 0 and a NaN fraction, as `floor(x) as i64` and x - floor(x) do.
#[inline(always)]
pub fn floor_index(x: f32) -> (i64, f32) {
    let t = x as i32;
    let i = if t as f32 > x { t - 1 } else { t };
    (i as i64, x - i as f32)
}

/// ceil(x) as [`floor`] computes floor(x), without a library call: -floor(-x), identical to
/// `f32::ceil` except for the sign of a zero result.
#[inline(always)]
pub fn ceil(x: f32) -> f32 {
    -floor(-x)
}

/// [`floor`] of each component.
#[inline(always)]
pub fn floor2(v: glam::Vec2) -> glam::Vec2 {
    glam::Vec2::new(floor(v.x), floor(v.y))
}

/// Phi(x) in single precision for hot loops: erf by Abramowitz and Stegun 7.1.26 (absolute
/// error below 1.5e-7), so Phi is within 1e-7 of [`normal_cdf`].
#[inline]
pub fn normal_cdf_f32(x: f32) -> f32 {
    let z = x.abs() * std::f32::consts::FRAC_1_SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * z);
    let poly = t * (0.254_829_6 + t * (-0.284_496_74 + t * (1.421_413_7 + t * (-1.453_152_1 + t * 1.061_405_4))));
    let erf = 1.0 - poly * (-z * z).exp();
    if x >= 0.0 { 0.5 + 0.5 * erf } else { 0.5 - 0.5 * erf }
}

/// [`floor`] of each of four lanes (glam's `Vec4`: SSE2 on x86-64), bit for bit. In float
/// arithmetic alone: x86-64's baseline has no vector conversion to integers that saturates as
/// Rust's casts do, so LLVM would convert lane by lane. Below 2^23, x + 2^23 (with x's sign)
/// less 2^23 is x rounded to an integer, and one less where that exceeds x.
#[inline(always)]
pub fn floor_x4(x: glam::Vec4) -> glam::Vec4 {
    let big = glam::Vec4::splat(8_388_608.0);
    let magic = big.copysign(x);
    let rounded = (x + magic) - magic;
    let floor = glam::Vec4::select(rounded.cmpgt(x), rounded - glam::Vec4::ONE, rounded);
    glam::Vec4::select(x.abs().cmplt(big), floor, x)
}

/// The integers (|i| < 2^22) in four lanes as i32 lanes, by the bits of i + 1.5 2^23.
#[inline(always)]
pub fn int_x4(i: glam::Vec4) -> glam::IVec4 {
    const MAGIC: f32 = 12_582_912.0;
    let bits = (i + glam::Vec4::splat(MAGIC)).to_array().map(|v| v.to_bits() as i32);
    glam::IVec4::from_array(bits) - glam::IVec4::splat(MAGIC.to_bits() as i32)
}

/// `i` modulo `n` in [0, n): texel indices of images that repeat. Lookups fall at most one
/// period outside, where this avoids the division.
#[inline(always)]
pub fn wrap_index(i: i64, n: usize) -> usize {
    let n = n as i64;
    if (0..n).contains(&i) {
        i as usize
    } else if (-n..0).contains(&i) {
        (i + n) as usize
    } else if (n..2 * n).contains(&i) {
        (i - n) as usize
    } else {
        i.rem_euclid(n) as usize
    }
}

/// The standard normal cumulative distribution function Phi(x).
#[inline]
pub fn normal_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}

/// The standard normal quantile Phi^-1(p) for p in (0, 1): Acklam's rational approximation
/// (relative error 1.2e-9) refined by one Halley step on [`normal_cdf`]. Returns -inf / +inf at
/// 0 / 1 and NaN outside [0, 1].
pub fn normal_quantile(p: f64) -> f64 {
    if !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] =
        [-5.447609879822406e1, 1.615858368580409e2, -1.556989798598866e2, 6.680131188771972e1, -1.328068155288572e1];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [7.784695709041462e-3, 3.224671290700398e-1, 2.445134137142996, 3.754408661907416];
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let x = if p < 0.02425 {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - 0.02425 {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    };
    // Halley's step: e = Phi(x) - p, u = e sqrt(2 pi) exp(x^2 / 2).
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (x * x / 2.0).exp();
    x - u / (1.0 + x * u / 2.0)
}

/// M = diag(1, -1): the mirror of the texture's y axis that F = R(theta) M S puts in front of
/// the stretch where a triangle's UVs are mirrored (DESIGN.md section 5).
pub const MIRROR: glam::Mat2 = glam::Mat2::from_cols_array(&[1.0, 0.0, 0.0, -1.0]);

/// The largest singular value of a 2x2 matrix (its spectral norm): for M = [a b; c d],
/// (|(a + d, c - b)| + |(a - d, c + b)|) / 2, the lengths of M's conformal and anticonformal
/// parts. Only sums of squares go under the roots, so it is accurate to a few ulps also where
/// the two singular values are close; the textbook sqrt((|M|^2 + sqrt(|M|^4 - 4 det^2)) / 2)
/// cancels there and keeps only half the digits (a relative error of about 3e-4 in f32, which
/// moved the GPU's inset cut-band shifts off the CPU's).
pub fn largest_singular_value(m: glam::Mat2) -> f32 {
    let (a, c, b, d) = (m.x_axis.x, m.x_axis.y, m.y_axis.x, m.y_axis.y);
    0.5 * (glam::Vec2::new(a + d, c - b).length() + glam::Vec2::new(a - d, c + b).length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        // An n-point rule is exact for degree 2n - 1.
        for n in [1, 2, 5, 32, 64] {
            let (x, w) = gauss_legendre(n);
            let total: f64 = w.iter().sum();
            assert!((total - 2.0).abs() < 1e-12, "n {n}");
            let deg = 2 * n - 1;
            let integral: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(deg as i32 - 1)).sum();
            // int_{-1}^{1} x^(2n-2) dx = 2 / (2n - 1)
            assert!((integral - 2.0 / deg as f64).abs() < 1e-10, "n {n}: {integral}");
        }
    }

    #[test]
    fn normal_quantile_inverts_the_cdf() {
        for p in [1e-9, 1e-4, 0.01, 0.02425, 0.2, 0.5, 0.7, 0.975, 0.999_999] {
            let x = normal_quantile(p);
            assert!((normal_cdf(x) - p).abs() < 1e-12 * p.max(1e-3), "{p}: {x}");
        }
        // Known values.
        assert!((normal_quantile(0.975) - 1.959963984540054).abs() < 1e-12);
        assert_eq!(normal_quantile(0.5), 0.0);
        assert!(normal_quantile(1.5).is_nan());
    }

    #[test]
    fn fast_floor_matches_floor() {
        for x in
            [0.0f32, 0.5, -0.5, -1.0, 1.0, 2.999_999, -2.000_001, 1e7 + 0.5, -8_388_607.5, 3e9, -3e9, f32::INFINITY]
        {
            assert_eq!(floor(x), x.floor(), "{x}");
        }
        assert!(floor(f32::NAN).is_nan());
        assert!(ceil(f32::NAN).is_nan());
        let mut x = -1000.0f32;
        while x < 1000.0 {
            assert_eq!(floor(x), x.floor(), "{x}");
            // Equal as numbers: -0.0 == 0.0, the one difference.
            assert_eq!(ceil(x), x.ceil(), "{x}");
            x += 0.123_456_7;
        }
        for x in [0.0f32, -0.5, 0.5, 1e7 + 0.5, -1e7 - 0.5, 3e9, -3e9, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(ceil(x), x.ceil(), "{x}");
        }
    }

    #[test]
    fn floor_index_is_the_floor_and_its_fraction() {
        let mut x = -5000.0f32;
        while x < 5000.0 {
            let (i, fraction) = floor_index(x);
            assert_eq!(i, x.floor() as i64, "{x}");
            assert_eq!(fraction.to_bits(), (x - x.floor()).to_bits(), "{x}");
            x += 0.013_7;
        }
        for x in [-0.0f32, -1e-30, 1e-30, 8_388_607.5, -8_388_607.5, 4_194_303.5] {
            let (i, fraction) = floor_index(x);
            assert_eq!((i, fraction), (x.floor() as i64, x - x.floor()), "{x}");
        }
        let (i, fraction) = floor_index(f32::NAN);
        assert_eq!(i, 0);
        assert!(fraction.is_nan());
    }

    #[test]
    fn lane_floors_are_the_scalar_floors_bit_for_bit() {
        let mut xs = vec![
            0.0f32,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.499_999_97,
            -0.499_999_97,
            -1.0,
            1e-30,
            -1e-30,
            2.999_999,
            -2.000_001,
            4_194_303.5,
            -4_194_303.5,
            8_388_607.5,
            -8_388_607.5,
            1e7 + 0.5,
            3e9,
            -3e9,
            1e38,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        xs.extend((0..4000).map(|i| (i as f32 - 2000.0) * 0.731_3));
        for x in xs.chunks(4) {
            let v = glam::Vec4::from_slice(&[x, &[0.0; 4]].concat()[..4]);
            let (floors, ints) = (floor_x4(v).to_array(), int_x4(floor_x4(v)).to_array());
            for l in 0..x.len() {
                assert_eq!(floors[l].to_bits(), floor(x[l]).to_bits(), "{}", x[l]);
                // Lanes' integers hold below 2^22.
                if x[l].abs() < 4_194_304.0 {
                    assert_eq!(ints[l] as i64, floor_index(x[l]).0, "{}", x[l]);
                }
            }
        }
    }

    #[test]
    fn fast_normal_cdf_is_close() {
        for i in -80..=80 {
            let x = i as f32 * 0.1;
            assert!((normal_cdf_f32(x) as f64 - normal_cdf(x as f64)).abs() < 2e-7, "{x}");
        }
    }

    #[test]
    fn largest_singular_value_of_known_matrices() {
        use glam::{Mat2, Vec2};
        assert!((largest_singular_value(Mat2::from_diagonal(Vec2::new(3.0, -5.0))) - 5.0).abs() < 1e-5);
        // A rotation times diag(2, 0.5): 2; a shear [[1, 1], [0, 1]]: the golden ratio.
        assert!(
            (largest_singular_value(Mat2::from_angle(0.7) * Mat2::from_diagonal(Vec2::new(2.0, 0.5))) - 2.0).abs()
                < 1e-5
        );
        let shear = Mat2::from_cols(Vec2::X, Vec2::ONE);
        assert!((largest_singular_value(shear) - 1.618_034).abs() < 1e-5);
        // Nearly a similarity (singular values 1.3 and 1.3 (1 - 1e-5)): to a few ulps, where
        // the textbook formula's inner root cancels (a relative error near 3e-4).
        let m = Mat2::from_angle(0.4) * Mat2::from_diagonal(Vec2::new(1.3, 1.3 * (1.0 - 1e-5)));
        let m64 = m.as_dmat2();
        let (f2, det) = (m64.x_axis.length_squared() + m64.y_axis.length_squared(), m64.determinant());
        let exact = ((f2 + (f2 * f2 - 4.0 * det * det).max(0.0).sqrt()) * 0.5).sqrt();
        assert!((largest_singular_value(m) as f64 - exact).abs() < 4.0 * f32::EPSILON as f64 * exact);
    }
}
