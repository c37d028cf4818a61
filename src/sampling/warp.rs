//! Warps from the unit square to directions and points, with their densities.

use crate::simd::{Real, V3};
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Shirley-Chiu concentric map of the unit square to the unit disk (area-preserving).
#[inline]
pub fn square_to_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let (x, y) = square_to_uniform_disk_concentric_of([u.x, u.y]);
    Vec2::new(x, y)
}

/// [`square_to_uniform_disk_concentric`] in one lane or eight.
#[inline(always)]
pub fn square_to_uniform_disk_concentric_of<T: Real>(u: [T; 2]) -> (T, T) {
    let (one, zero) = (T::splat(1.0), T::splat(0.0));
    let p = (T::splat(2.0) * u[0] - one, T::splat(2.0) * u[1] - one);
    let wide = p.1.abs().lt(p.0.abs());
    let r = T::select(wide, p.0, p.1);
    let theta =
        T::select(wide, T::splat(FRAC_PI_4) * (p.1 / p.0), T::splat(FRAC_PI_2) - T::splat(FRAC_PI_4) * (p.0 / p.1));
    let (s, c) = theta.sin_cos();
    // The centre maps to itself (where theta is 0 / 0).
    let centre = p.0.eq(zero) & p.1.eq(zero);
    (T::select(centre, zero, r * c), T::select(centre, zero, r * s))
}

/// Cosine-weighted hemisphere around +z (Malley's method on the concentric disk).
#[inline]
pub fn square_to_cosine_hemisphere(u: Vec2) -> Vec3 {
    square_to_cosine_hemisphere_of([u.x, u.y]).into()
}

/// [`square_to_cosine_hemisphere`] in one lane or eight.
#[inline(always)]
pub fn square_to_cosine_hemisphere_of<T: Real>(u: [T; 2]) -> V3<T> {
    let (x, y) = square_to_uniform_disk_concentric_of(u);
    let z = (T::splat(1.0) - (x * x + y * y)).max(T::splat(0.0)).sqrt();
    V3::new(x, y, z)
}

/// Density of [`square_to_cosine_hemisphere`] (per steradian).
#[inline]
pub fn cosine_hemisphere_pdf(w: Vec3) -> f32 {
    cosine_hemisphere_pdf_of(w.z)
}

/// [`cosine_hemisphere_pdf`] in one lane or eight, of a direction's z.
#[inline(always)]
pub fn cosine_hemisphere_pdf_of<T: Real>(z: T) -> T {
    T::select(T::splat(0.0).lt(z), z * T::splat(FRAC_1_PI), T::splat(0.0))
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn square_to_uniform_sphere(u: Vec2) -> Vec3 {
    square_to_uniform_sphere_of([u.x, u.y]).into()
}

/// [`square_to_uniform_sphere`] in one lane or eight.
#[inline(always)]
pub fn square_to_uniform_sphere_of<T: Real>(u: [T; 2]) -> V3<T> {
    let one = T::splat(1.0);
    let z = one - T::splat(2.0) * u[1];
    let r = (one - z * z).max(T::splat(0.0)).sqrt();
    let (s, c) = (T::splat(2.0 * PI) * u[0]).sin_cos();
    V3::new(r * c, r * s, z)
}

/// Density of [`square_to_uniform_sphere`].
pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone of directions within angle theta_max of +z, given
/// 1 - cos theta_max (which a small cone, such as the sun's, needs exactly: 1 - cos in f32
/// would lose half its digits at a quarter of a degree).
#[inline]
pub fn square_to_uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    let one_minus_z = u.y * one_minus_cos_max;
    let r = (one_minus_z * (2.0 - one_minus_z)).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.x).sin_cos();
    Vec3::new(r * c, r * s, 1.0 - one_minus_z)
}

/// Density of [`square_to_uniform_cone`] inside the cone: one over its solid angle,
/// 2 pi (1 - cos theta_max).
#[inline]
pub fn uniform_cone_pdf(one_minus_cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * one_minus_cos_max)
}

/// Uniform point on a triangle, as barycentric weights (b1, b2) of its second and third
/// vertices (the square-root parameterisation).
#[inline]
pub fn square_to_uniform_triangle(u: Vec2) -> Vec2 {
    let (b1, b2) = square_to_uniform_triangle_of([u.x, u.y]);
    Vec2::new(b1, b2)
}

/// [`square_to_uniform_triangle`] in one lane or eight.
#[inline(always)]
pub fn square_to_uniform_triangle_of<T: Real>(u: [T; 2]) -> (T, T) {
    let t = (T::splat(1.0) - u[0]).max(T::splat(0.0)).sqrt();
    (T::splat(1.0) - t, t * u[1])
}

/// Sample x in [0, 1] with density proportional to the linear function from `a` (at 0) to `b`
/// (at 1), both non-negative and not both zero: invert the quadratic CDF in its stable form.
#[inline]
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + (a * a + u * (b * b - a * a)).max(0.0).sqrt());
    x.min(1.0 - f32::EPSILON)
}

/// Sample a point of [0, 1]^2 with density proportional to the bilinear interpolation of corner
/// weights `w` = [w(0,0), w(1,0), w(0,1), w(1,1)]: y from the marginal, then x given y.
#[inline]
pub fn square_to_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(u.x, w[0] + (w[2] - w[0]) * y, w[1] + (w[3] - w[1]) * y);
    Vec2::new(x, y)
}

/// Density of [`square_to_bilinear`] at `p` (uniform when all weights are zero).
#[inline]
pub fn bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum == 0.0 {
        return 1.0;
    }
    let value =
        (1.0 - p.x) * (1.0 - p.y) * w[0] + p.x * (1.0 - p.y) * w[1] + (1.0 - p.x) * p.y * w[2] + p.x * p.y * w[3];
    4.0 * value / sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concentric_disk_stays_in_disk_and_preserves_area() {
        // Equal-area: the fraction of a uniform grid landing within radius r is r^2.
        let n = 200;
        let mut inside_half = 0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let d = square_to_uniform_disk_concentric(u);
                assert!(d.length() <= 1.0 + 1e-6);
                if d.length() < 0.5 {
                    inside_half += 1;
                }
            }
        }
        let frac = inside_half as f32 / (n * n) as f32;
        assert!((frac - 0.25).abs() < 0.01, "{frac}");
    }

    #[test]
    fn cosine_hemisphere_mean_cosine_is_two_thirds() {
        // E[cos] under p = cos/pi is (1/pi) * int cos^2 dw = 2/3.
        let n = 300;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let w = square_to_cosine_hemisphere(u);
                assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
                sum += w.z;
            }
        }
        let mean = sum / (n * n) as f32;
        assert!((mean - 2.0 / 3.0).abs() < 1e-3, "{mean}");
    }

    #[test]
    fn bilinear_warp_inverts_its_cdf() {
        // The fraction of samples below (x0, y0) equals the integral of the density there.
        let w = [0.2, 3.0, 1.0, 0.0];
        let n = 300;
        let (x0, y0) = (0.4f32, 0.7f32);
        let mut below = 0;
        for i in 0..n {
            for j in 0..n {
                let p = square_to_bilinear(Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32), w);
                assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
                below += usize::from(p.x < x0 && p.y < y0);
            }
        }
        // Integral of the density over [0, x0] x [0, y0], by a fine midpoint rule.
        let m = 400;
        let mut integral = 0.0;
        for a in 0..m {
            for b in 0..m {
                let p = Vec2::new((a as f32 + 0.5) / m as f32 * x0, (b as f32 + 0.5) / m as f32 * y0);
                integral += bilinear_pdf(p, w) * x0 * y0 / (m * m) as f32;
            }
        }
        let fraction = below as f32 / (n * n) as f32;
        assert!((fraction - integral).abs() < 3e-3, "{fraction} vs {integral}");
    }

    #[test]
    fn uniform_triangle_barycentrics_are_uniform() {
        // The mean of uniform barycentrics is (1/3, 1/3).
        let n = 300;
        let mut sum = Vec2::ZERO;
        for i in 0..n {
            for j in 0..n {
                let b = square_to_uniform_triangle(Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32));
                assert!(b.x >= 0.0 && b.y >= 0.0 && b.x + b.y <= 1.0 + 1e-6);
                sum += b;
            }
        }
        let mean = sum / (n * n) as f32;
        assert!(mean.distance(Vec2::splat(1.0 / 3.0)) < 2e-3, "{mean}");
    }

    #[test]
    fn uniform_sphere_lanes_match_one_direction_and_agree_across_instruction_sets() {
        use crate::simd::F32x8;
        use crate::simd::testing::{lane, numbers, on_every_isa};
        let mut worst = 0.0f32;
        on_every_isa(|isa| {
            let mut bits = Vec::new();
            for chunk in 0..4000 {
                let u = |i: usize| numbers(chunk, i);
                let w =
                    isa.run(|| square_to_uniform_sphere_of([F32x8::from_fn(|i| u(i)[0]), F32x8::from_fn(|i| u(i)[1])]));
                for i in 0..8 {
                    worst = worst.max((lane(w, i) - square_to_uniform_sphere(Vec2::from(u(i)))).abs().max_element());
                    bits.push(lane(w, i).to_array().map(f32::to_bits));
                }
            }
            bits
        });
        // z is exact; x and y carry the lanes' sine and cosine, within 2e-7.
        assert!(worst < 2e-7, "largest difference from one direction {worst:e}");
    }
}
