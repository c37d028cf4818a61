//! Pixel reconstruction filters (Mitsuba's `rfilter`): `box`, `gaussian` and `tent`.
//!
//! Mitsuba splats each sample into the pixels within the filter's radius, weighted by f(dx)
//! f(dy), and divides each pixel by its weights' sum: a pixel converges to
//! int f(x - c) L(x) dx / int f. tessera gets the same value without splatting: each pixel draws
//! its own samples at c + d with the offset d distributed as f (pbrt-v4's filter importance
//! sampling; f is separable and non-negative, so each axis is sampled exactly by inverting its
//! CDF and every sample weighs the same). Pixels stay independent: no sample crosses into
//! another pixel's sums, whatever the threads or the crop.

use glam::Vec2;

/// A separable reconstruction filter, in pixel units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFilter {
    /// Each pixel the mean of the radiance over its own square (Mitsuba's `box`, radius 1/2).
    Box,
    /// Mitsuba's `gaussian`: exp(-x^2 / (2 stddev^2)) less its value at the radius 4 stddev,
    /// where it reaches 0 (Mitsuba's default filter, with stddev 1/2).
    Gaussian {
        /// Standard deviation in pixels.
        stddev: f32,
    },
    /// Mitsuba's `tent`: 1 - |x| / radius.
    Tent {
        /// Radius in pixels.
        radius: f32,
    },
}

/// The widest filter radius accepted, in pixels.
pub const MAX_FILTER_RADIUS: f32 = 16.0;

impl PixelFilter {
    /// A Gaussian of standard deviation `stddev` pixels (its radius, 4 stddev, at most
    /// [`MAX_FILTER_RADIUS`]).
    pub fn gaussian(stddev: f32) -> Result<Self, String> {
        if !(stddev > 0.0 && 4.0 * stddev <= MAX_FILTER_RADIUS) {
            return Err(format!(
                "a Gaussian filter's stddev must lie in (0, {}] pixels, not {stddev}",
                MAX_FILTER_RADIUS / 4.0
            ));
        }
        Ok(PixelFilter::Gaussian { stddev })
    }

    /// A tent of radius `radius` pixels (at most [`MAX_FILTER_RADIUS`]).
    pub fn tent(radius: f32) -> Result<Self, String> {
        if !(radius > 0.0 && radius <= MAX_FILTER_RADIUS) {
            return Err(format!("a tent filter's radius must lie in (0, {MAX_FILTER_RADIUS}] pixels, not {radius}"));
        }
        Ok(PixelFilter::Tent { radius })
    }

    /// The position on the film of a sample of pixel (`x`, `y`) drawn with `u`: uniform over
    /// the pixel's square for the box (its corner plus `u`, bit for bit as before filters),
    /// else the pixel's centre plus an offset distributed as the filter.
    #[inline]
    pub fn film_position(&self, x: u32, y: u32, u: Vec2) -> Vec2 {
        let corner = Vec2::new(x as f32, y as f32);
        match *self {
            PixelFilter::Box => corner + u,
            _ => corner + Vec2::splat(0.5) + Vec2::new(self.offset(u.x), self.offset(u.y)),
        }
    }

    /// A 1D offset distributed as the filter, from `u` in [0, 1): its sign from which half `u`
    /// falls in, its size by inverting the CDF of the filter on [0, radius].
    fn offset(&self, u: f32) -> f32 {
        let (sign, v) = if u < 0.5 { (-1.0, 1.0 - 2.0 * u) } else { (1.0, 2.0 * u - 1.0) };
        let size = match *self {
            PixelFilter::Box => v * 0.5,
            // The tent's CDF on [0, r] is 1 - (1 - x/r)^2.
            PixelFilter::Tent { radius } => radius * (1.0 - (1.0 - v).max(0.0).sqrt()),
            PixelFilter::Gaussian { stddev } => gaussian_inverse_cdf(f64::from(stddev), f64::from(v)) as f32,
        };
        sign * size
    }
}

/// The x in [0, 4 stddev] where the CDF of the truncated, shifted Gaussian on that interval is
/// `v`. The filter is the unit one (stddev 1, radius 4) scaled by stddev, so x = stddev x_1(v),
/// with x_1 read from a table and refined by Newton's method ([`unit_gaussian_inverse_cdf`]).
fn gaussian_inverse_cdf(stddev: f64, v: f64) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=INVERSE_CDF_STEPS).map(|i| unit_gaussian_inverse_cdf(i as f64 / INVERSE_CDF_STEPS as f64, None)).collect()
    });
    let at = v.clamp(0.0, 1.0) * INVERSE_CDF_STEPS as f64;
    let i = (at as usize).min(INVERSE_CDF_STEPS - 1);
    let guess = table[i] + (table[i + 1] - table[i]) * (at - i as f64);
    stddev * unit_gaussian_inverse_cdf(v, Some(guess))
}

/// Entries of the table of [`gaussian_inverse_cdf`], less one.
const INVERSE_CDF_STEPS: usize = 256;

/// The x in [0, 4] where G(x) = sqrt(pi/2) erf(x / sqrt 2) - b x, the CDF of the unit filter
/// (b = exp(-8), its value at the radius), is `v` G(4): Newton's method from `guess` (or v 4),
/// kept inside a shrinking bracket (G is increasing; its slope, the filter, falls to 0 at the
/// radius), to 1e-12.
fn unit_gaussian_inverse_cdf(v: f64, guess: Option<f64>) -> f64 {
    const RADIUS: f64 = 4.0;
    let bias = (-RADIUS * RADIUS / 2.0).exp();
    let k = (std::f64::consts::PI / 2.0).sqrt();
    let cdf = |x: f64| k * libm::erf(x / std::f64::consts::SQRT_2) - bias * x;
    let target = v * cdf(RADIUS);
    let (mut lo, mut hi, mut x) = (0.0, RADIUS, guess.unwrap_or(v * RADIUS).clamp(0.0, RADIUS));
    for _ in 0..64 {
        let g = cdf(x) - target;
        if g.abs() < 1e-12 {
            break;
        }
        if g > 0.0 {
            hi = x
        } else {
            lo = x
        }
        let slope = (-x * x / 2.0).exp() - bias;
        let newton = x - g / slope;
        x = if slope > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo < 1e-12 {
            break;
        }
    }
    x.clamp(0.0, RADIUS)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter's own value at offset x (for the tests: Mitsuba's definitions).
    fn eval(filter: PixelFilter, x: f64) -> f64 {
        match filter {
            PixelFilter::Box => f64::from(x.abs() <= 0.5),
            PixelFilter::Tent { radius } => (1.0 - x.abs() / f64::from(radius)).max(0.0),
            PixelFilter::Gaussian { stddev } => {
                let s = f64::from(stddev);
                ((-x * x / (2.0 * s * s)).exp() - (-8.0f64).exp()).max(0.0)
            }
        }
    }

    #[test]
    fn pixel_filter_offsets_are_distributed_as_the_filter() {
        // A histogram of offsets from stratified u against the filter's integral over each bin.
        for filter in [
            PixelFilter::Box,
            PixelFilter::gaussian(0.5).unwrap(),
            PixelFilter::tent(1.25).unwrap(),
            PixelFilter::gaussian(1.3).unwrap(),
        ] {
            let radius = match filter {
                PixelFilter::Box => 0.5,
                PixelFilter::Tent { radius } => f64::from(radius),
                PixelFilter::Gaussian { stddev } => 4.0 * f64::from(stddev),
            };
            let (n, bins) = (200_000, 40);
            let mut counts = vec![0.0f64; bins];
            for i in 0..n {
                let x = f64::from(filter.offset((i as f32 + 0.5) / n as f32));
                assert!(x.abs() <= radius + 1e-6, "{filter:?}: {x}");
                let bin = (((x + radius) / (2.0 * radius)) * bins as f64).floor().clamp(0.0, bins as f64 - 1.0);
                counts[bin as usize] += 1.0 / n as f64;
            }
            let integral = |a: f64, b: f64| {
                (0..1000).map(|k| eval(filter, a + (b - a) * (k as f64 + 0.5) / 1000.0)).sum::<f64>() * (b - a) / 1000.0
            };
            let total = integral(-radius, radius);
            for (b, count) in counts.iter().enumerate() {
                let (a, c) = (
                    -radius + 2.0 * radius * b as f64 / bins as f64,
                    -radius + 2.0 * radius * (b + 1) as f64 / bins as f64,
                );
                let expected = integral(a, c) / total;
                assert!((count - expected).abs() < 2e-4, "{filter:?}: bin {b}: {count} against {expected}");
            }
        }
    }

    #[test]
    fn box_filter_keeps_the_pixel_corner_plus_u() {
        let u = Vec2::new(0.3, 0.9);
        assert_eq!(PixelFilter::Box.film_position(7, 2, u), Vec2::new(7.0, 2.0) + u);
        let g = PixelFilter::gaussian(0.5).unwrap().film_position(7, 2, Vec2::splat(0.5));
        assert!(g.distance(Vec2::new(7.5, 2.5)) < 1e-6);
        assert!(
            PixelFilter::gaussian(0.0).is_err()
                && PixelFilter::tent(f32::NAN).is_err()
                && PixelFilter::tent(17.0).is_err()
        );
    }
}
