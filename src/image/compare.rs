//! Image comparison: the error metrics of `tessera diff` and of the render tests.
//!
//! - relMSE = mean((t - r)^2 / (r^2 + 0.01)) over all values, and MAE = mean |t - r|;
//! - mean FLIP: NVIDIA's FLIP (Andersson et al. 2020, via the `nv-flip` crate) between the two
//!   images tone-mapped to 8-bit sRGB (exposure 1, clamped: LDR-FLIP) at 67 pixels per degree;
//! - the per-pixel Z-test of Mitsuba 3's `src/render/tests/test_renders.py`: with the
//!   reference's per-sample variance v (floored at 1e-4) and the test image's sample count n,
//!   z = |t - r| sqrt(n / v), p = 2 (1 - Phi(z)); a value is accepted when p exceeds the Sidak
//!   correction of 0.01 over the pixel count, and the image passes when accepted values / 3 are at
//!   least 99.75% of the pixels. The image mean is checked too: a bias too small for any one pixel
//!   shows there (its z is computed from the same variances).

use super::Bitmap;
use crate::color::linear_to_srgb;
use crate::error::{Error, Result};
use glam::Vec4;

/// Sample variance below which the Z-test does not trust the reference (Mitsuba's floor).
pub const MIN_VARIANCE: f64 = 1e-4;
/// Overall significance level of the per-pixel Z-test (Mitsuba's).
pub const SIGNIFICANCE: f64 = 0.01;
/// Fraction of pixels that must pass for the image to pass (Mitsuba's).
pub const PASS_FRACTION: f64 = 0.9975;

/// Differences between a test image and a reference.
#[derive(Clone, Debug)]
pub struct ImageMetrics {
    /// mean((t - r)^2 / (r^2 + 0.01)).
    pub relmse: f64,
    /// mean |t - r|.
    pub mae: f64,
    /// Mean LDR-FLIP error in [0, 1].
    pub mean_flip: f64,
    /// Mean of each channel of the test image.
    pub mean_test: [f64; 3],
    /// Mean of each channel of the reference.
    pub mean_reference: [f64; 3],
}

/// Outcome of the per-pixel Z-test.
#[derive(Clone, Debug)]
pub struct ZTest {
    /// Per-value significance after the Sidak correction.
    pub alpha: f64,
    /// Fraction of pixels accepted (accepted values / 3 / pixels).
    pub accepted_fraction: f64,
    /// Smallest p-value.
    pub min_p: f64,
    /// z of each channel's image mean against the reference's.
    pub mean_z: [f64; 3],
    /// Per-pixel p-values (RGB).
    pub p_values: Bitmap,
}

impl ZTest {
    /// Mitsuba's criterion: at least 99.75% of the pixels accepted.
    pub fn pixels_pass(&self) -> bool {
        self.accepted_fraction >= PASS_FRACTION
    }

    /// True when every channel's image mean lies within `sigmas` standard errors.
    pub fn mean_passes(&self, sigmas: f64) -> bool {
        self.mean_z.iter().all(|z| z.abs() <= sigmas)
    }

    /// Per pixel, the smallest p-value of its three channels (one channel).
    pub fn min_p_image(&self) -> Bitmap {
        let p = &self.p_values;
        let mut out = Bitmap::new(p.width, p.height, 1);
        for (i, v) in out.data.iter_mut().enumerate() {
            *v = p.data[3 * i..3 * i + 3].iter().copied().fold(1.0, f32::min);
        }
        out
    }
}

/// Largest |z| of a channel's image mean that passes: a bias too small for any one pixel shows
/// there.
pub const MEAN_SIGMAS: f64 = 5.0;

/// What a test image must satisfy against its reference (`tessera diff`, the golden test).
#[derive(Clone, Copy, Debug, Default)]
pub struct Criteria<'a> {
    /// Mitsuba's per-pixel Z-test and the image-mean test: the reference's per-sample variance,
    /// and the test image's samples per pixel.
    pub z_test: Option<(&'a Bitmap, u32)>,
    /// Largest relMSE.
    pub max_relmse: Option<f64>,
    /// Largest mean FLIP.
    pub max_flip: Option<f64>,
}

/// A test image judged against its reference: the metrics, the Z-test where asked for, and
/// why it fails (empty when it passes).
#[derive(Clone, Debug)]
pub struct Verdict {
    /// relMSE, MAE, mean FLIP, channel means.
    pub metrics: ImageMetrics,
    /// The Z-test, with its per-pixel p-values.
    pub z: Option<ZTest>,
    /// One line per failed criterion.
    pub failures: Vec<String>,
}

impl Verdict {
    /// True when every criterion holds.
    pub fn passes(&self) -> bool {
        self.failures.is_empty()
    }
}

/// Judge `test` against `reference` by `criteria`; `invalid` counts the test image's NaN or
/// infinite values (or samples), each a failure, counted before they were zeroed. Errors when
/// no criterion is given or the images (or the variance) differ in size.
pub fn judge(test: &Bitmap, invalid: usize, reference: &Bitmap, criteria: &Criteria) -> Result<Verdict> {
    if criteria.z_test.is_none() && criteria.max_relmse.is_none() && criteria.max_flip.is_none() {
        return Err(Error::param(
            "criteria",
            "give one at least: a Z-test (variance and spp), a relMSE or a FLIP limit",
        ));
    }
    let metrics = image_metrics(test, reference)?;
    let mut failures = Vec::new();
    if invalid > 0 {
        failures.push(format!("{invalid} values of the test image are NaN or infinite"));
    }
    if let Some(limit) = criteria.max_relmse.filter(|l| !(metrics.relmse <= *l)) {
        failures.push(format!("relMSE {:.4e} > {limit:e}", metrics.relmse));
    }
    if let Some(limit) = criteria.max_flip.filter(|l| !(metrics.mean_flip <= *l)) {
        failures.push(format!("mean FLIP {:.4} > {limit}", metrics.mean_flip));
    }
    let z = match criteria.z_test {
        Some((variance, spp)) => {
            let z = z_test(test, spp, reference, variance)?;
            if !z.pixels_pass() {
                failures.push(format!(
                    "only {:.3}% of pixels pass the Z-test (need {}%)",
                    100.0 * z.accepted_fraction,
                    100.0 * PASS_FRACTION
                ));
            }
            if !z.mean_passes(MEAN_SIGMAS) {
                failures.push(format!(
                    "the image mean is off by {:?} standard errors (at most {MEAN_SIGMAS})",
                    z.mean_z.map(|v| v as f32)
                ));
            }
            Some(z)
        }
        None => None,
    };
    Ok(Verdict { metrics, z, failures })
}

/// A test image read as linear values, and how many of its values were NaN or infinite: those
/// are a failure ([`judge`]), never values to compare (read as 0 they would pass against
/// black), and are zeroed, as negative values are.
pub fn read_test_image(path: &std::path::Path) -> Result<(Bitmap, usize)> {
    let mut image = super::read_bitmap_raw(path, super::ColorSpace::Linear)?;
    let invalid = image.non_finite_count();
    image.zero_negative_and_non_finite();
    Ok((image, invalid))
}

/// A reference image (or its variance) read as linear values; NaN or infinity in it is an error
/// naming the file, negative values are zeroed.
pub fn read_reference(path: &std::path::Path) -> Result<Bitmap> {
    let mut image = super::read_bitmap_raw(path, super::ColorSpace::Linear)?;
    match image.non_finite_count() {
        0 => {
            image.zero_negative_and_non_finite();
            Ok(image)
        }
        n => Err(Error::image(path, format!("{n} values are NaN or infinite: not usable as a reference"))),
    }
}

/// |test - reference| per value, RGB.
pub fn absolute_difference(test: &Bitmap, reference: &Bitmap) -> Result<Bitmap> {
    check_sizes(test, reference, "difference")?;
    let mut out = Bitmap::new(test.width, test.height, 3);
    for (i, e) in out.data.iter_mut().enumerate() {
        let (px, c) = (i / 3, i % 3);
        *e = (test.data[px * test.channels + c] - reference.data[px * reference.channels + c]).abs();
    }
    Ok(out)
}

fn check_sizes(a: &Bitmap, b: &Bitmap, what: &str) -> Result<()> {
    if (a.width, a.height) != (b.width, b.height) || a.channels < 3 || b.channels < 3 {
        return Err(Error::param(
            what,
            format!(
                "images differ in size or lack RGB: {}x{}x{} vs {}x{}x{}",
                a.width, a.height, a.channels, b.width, b.height, b.channels
            ),
        ));
    }
    Ok(())
}

/// RGB of pixel i as f64.
fn rgb(b: &Bitmap, i: usize) -> [f64; 3] {
    let p = b.pixel(i % b.width, i / b.width);
    [p.x as f64, p.y as f64, p.z as f64]
}

fn to_srgb8(b: &Bitmap) -> Vec<u8> {
    (0..b.width * b.height)
        .flat_map(|i| rgb(b, i).map(|v| (linear_to_srgb((v as f32).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
        .collect()
}

/// The per-pixel LDR-FLIP error map (one channel) of `test` against `reference`.
pub fn flip_map(test: &Bitmap, reference: &Bitmap) -> Result<Bitmap> {
    check_sizes(test, reference, "flip")?;
    let (w, h) = (test.width as u32, test.height as u32);
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &to_srgb8(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &to_srgb8(test));
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    Ok(Bitmap { width: test.width, height: test.height, channels: 1, data: map.to_vec() })
}

/// relMSE, MAE, mean FLIP and channel means of `test` against `reference`.
pub fn image_metrics(test: &Bitmap, reference: &Bitmap) -> Result<ImageMetrics> {
    check_sizes(test, reference, "metrics")?;
    let n = test.width * test.height;
    let (mut relmse, mut mae) = (0.0, 0.0);
    let (mut mean_test, mut mean_reference) = ([0.0; 3], [0.0; 3]);
    for i in 0..n {
        let (t, r) = (rgb(test, i), rgb(reference, i));
        for c in 0..3 {
            relmse += (t[c] - r[c]).powi(2) / (r[c] * r[c] + 0.01);
            mae += (t[c] - r[c]).abs();
            mean_test[c] += t[c];
            mean_reference[c] += r[c];
        }
    }
    let values = (3 * n) as f64;
    let flip = flip_map(test, reference)?;
    let mean_flip = flip.data.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
    Ok(ImageMetrics {
        relmse: relmse / values,
        mae: mae / values,
        mean_flip,
        mean_test: mean_test.map(|m| m / n as f64),
        mean_reference: mean_reference.map(|m| m / n as f64),
    })
}

/// The Z-test of `test` (rendered with `spp` samples per pixel) against `reference` and its
/// per-sample `variance`.
pub fn z_test(test: &Bitmap, spp: u32, reference: &Bitmap, variance: &Bitmap) -> Result<ZTest> {
    check_sizes(test, reference, "z-test")?;
    check_sizes(variance, reference, "variance")?;
    let n = test.width * test.height;
    let alpha = 1.0 - (1.0 - SIGNIFICANCE).powf(1.0 / n as f64);
    let mut p_values = Bitmap::new(test.width, test.height, 3);
    let (mut accepted, mut min_p) = (0usize, 1.0f64);
    let (mut sum_diff, mut sum_var) = ([0.0f64; 3], [0.0f64; 3]);
    for i in 0..n {
        let (t, r, v) = (rgb(test, i), rgb(reference, i), rgb(variance, i));
        for c in 0..3 {
            let var = v[c].max(MIN_VARIANCE);
            let z = (t[c] - r[c]).abs() * (spp as f64 / var).sqrt();
            // 2 (1 - Phi(z)) = erfc(z / sqrt 2).
            let p = libm::erfc(z / std::f64::consts::SQRT_2);
            p_values.data[3 * i + c] = p as f32;
            accepted += usize::from(p > alpha);
            min_p = min_p.min(p);
            sum_diff[c] += t[c] - r[c];
            sum_var[c] += var / spp as f64;
        }
    }
    let mean_z = std::array::from_fn(|c| sum_diff[c] / sum_var[c].sqrt());
    Ok(ZTest { alpha, accepted_fraction: accepted as f64 / 3.0 / n as f64, min_p, mean_z, p_values })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, f: impl Fn(usize) -> f32) -> Bitmap {
        Bitmap { width: w, height: h, channels: 3, data: (0..w * h * 3).map(f).collect() }
    }

    #[test]
    fn identical_images_have_zero_error() {
        let a = image(16, 8, |i| (i % 7) as f32 * 0.1);
        let m = image_metrics(&a, &a).unwrap();
        assert_eq!((m.relmse, m.mae), (0.0, 0.0));
        assert!(m.mean_flip < 1e-6, "{}", m.mean_flip);
    }

    #[test]
    fn relmse_and_mae_match_their_definitions() {
        let r = image(4, 4, |_| 0.5);
        let t = image(4, 4, |_| 0.6);
        let m = image_metrics(&t, &r).unwrap();
        assert!((m.mae - 0.1).abs() < 1e-6);
        assert!((m.relmse - 0.01 / (0.25 + 0.01)).abs() < 1e-6);
        // A visible difference is a visible FLIP error.
        let black = image(32, 32, |_| 0.0);
        let white = image(32, 32, |_| 1.0);
        assert!(image_metrics(&black, &white).unwrap().mean_flip > 0.5);
    }

    #[test]
    fn a_verdict_lists_every_failed_criterion() {
        let r = image(32, 32, |_| 0.5);
        let t = image(32, 32, |_| 0.6);
        let loose = Criteria { max_relmse: Some(0.1), max_flip: Some(0.5), ..Default::default() };
        assert!(judge(&t, 0, &r, &loose).unwrap().passes());
        let tight = Criteria { max_relmse: Some(1e-3), max_flip: Some(1e-4), ..Default::default() };
        let v = judge(&t, 2, &r, &tight).unwrap();
        assert_eq!(v.failures.len(), 3, "{:?}", v.failures);
        assert!(v.failures[0].contains("NaN") && v.failures[1].contains("relMSE") && v.failures[2].contains("FLIP"));
        assert!(judge(&t, 0, &r, &Criteria::default()).is_err(), "no criterion is an error");
        let d = absolute_difference(&t, &r).unwrap();
        assert!(d.data.iter().all(|&e| (e - 0.1).abs() < 1e-6));
    }

    #[test]
    fn z_test_accepts_noise_and_rejects_bias() {
        // Test images drawn around the reference with the variance of a mean of 64 samples.
        let (w, h, spp) = (64, 64, 64u32);
        let reference = image(w, h, |i| 0.2 + 0.001 * (i % 97) as f32);
        let variance = image(w, h, |_| 0.04);
        let sigma = (0.04f64 / spp as f64).sqrt();
        // A deterministic normal-ish deviate from a hash: the sum of 4 uniforms, scaled.
        let noise = |i: usize, salt: u64| {
            let u = |k: u64| {
                let mut s = crate::sampling::Sampler::new(salt, i as u64, k as u32);
                s.next_1d() as f64
            };
            ((u(0) + u(1) + u(2) + u(3)) - 2.0) * (3.0f64).sqrt()
        };
        let noisy = image(w, h, |i| (reference.data[i] as f64 + sigma * noise(i, 1)) as f32);
        let z = z_test(&noisy, spp, &reference, &variance).unwrap();
        assert!(z.pixels_pass() && z.mean_passes(5.0), "{:?} {:?}", z.accepted_fraction, z.mean_z);
        // Shift every pixel by 1% of the value: no single pixel is rejected, the mean is.
        let biased = image(w, h, |i| noisy.data[i] * 1.01);
        let zb = z_test(&biased, spp, &reference, &variance).unwrap();
        assert!(!zb.mean_passes(5.0), "{:?}", zb.mean_z);
        // A hot region fails the per-pixel test.
        let hot = image(w, h, |i| if i < w * h * 3 / 100 { noisy.data[i] + 1.0 } else { noisy.data[i] });
        assert!(!z_test(&hot, spp, &reference, &variance).unwrap().pixels_pass());
    }
}

/// One texel where two images differ most.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelError {
    /// Column.
    pub x: usize,
    /// Row (0 at the top).
    pub y: usize,
    /// Largest absolute difference over the channels.
    pub error: f32,
    /// The test image's value.
    pub test: Vec4,
    /// The reference's value.
    pub reference: Vec4,
}

/// A texel-by-texel comparison of two images of the same size and channels (`tessera
/// gpu-check`): per channel the largest and the mean absolute difference, the worst texels,
/// and the error image max_c |t - r|.
#[derive(Clone, Debug)]
pub struct TexelDifference {
    /// Largest |t - r| per channel.
    pub max_abs: Vec<f32>,
    /// Mean |t - r| per channel.
    pub mean_abs: Vec<f64>,
    /// The texels of largest difference, largest first.
    pub worst: Vec<TexelError>,
    /// max over channels of |t - r|, one channel (NaN where either value is NaN).
    pub error_image: Bitmap,
}

impl TexelDifference {
    /// Compare `test` with `reference`, keeping the `worst` largest differences.
    pub fn new(test: &Bitmap, reference: &Bitmap, worst: usize) -> Result<Self> {
        Self::masked(test, reference, &vec![true; test.width * test.height], worst)
    }

    /// Compare `test` with `reference` at the texels where `mask` is true (row-major, one
    /// entry per texel; the error image is 0 elsewhere and the means are over the masked
    /// texels), keeping the `worst` largest differences.
    pub fn masked(test: &Bitmap, reference: &Bitmap, mask: &[bool], worst: usize) -> Result<Self> {
        if (test.width, test.height, test.channels) != (reference.width, reference.height, reference.channels) {
            return Err(Error::param(
                "images",
                format!(
                    "they differ in size: {}x{}x{} against {}x{}x{}",
                    test.width, test.height, test.channels, reference.width, reference.height, reference.channels
                ),
            ));
        }
        let ch = test.channels;
        let mut max_abs = vec![0.0f32; ch];
        let mut sum = vec![0.0f64; ch];
        if mask.len() != test.width * test.height {
            return Err(Error::param(
                "mask",
                format!("{} entries for {} texels", mask.len(), test.width * test.height),
            ));
        }
        let mut error_image = Bitmap::new(test.width, test.height, 1);
        for (i, (t, r)) in test.data.chunks_exact(ch).zip(reference.data.chunks_exact(ch)).enumerate() {
            if !mask[i] {
                continue;
            }
            let mut texel = 0.0f32;
            for c in 0..ch {
                let d = (t[c] - r[c]).abs();
                // NaN poisons the maximum on purpose: a NaN in either image is a failure.
                max_abs[c] = if d.is_nan() || max_abs[c].is_nan() { f32::NAN } else { max_abs[c].max(d) };
                sum[c] += d as f64;
                texel = if d.is_nan() || texel.is_nan() { f32::NAN } else { texel.max(d) };
            }
            error_image.data[i] = texel;
        }
        let count = mask.iter().filter(|&&m| m).count().max(1) as f64;
        let mut order: Vec<usize> = (0..error_image.data.len()).filter(|&i| mask[i]).collect();
        let key = |i: usize| if error_image.data[i].is_nan() { f32::INFINITY } else { error_image.data[i] };
        order.sort_by(|&a, &b| key(b).total_cmp(&key(a)).then(a.cmp(&b)));
        let worst = order
            .into_iter()
            .take(worst)
            .map(|i| {
                let (x, y) = (i % test.width, i / test.width);
                TexelError {
                    x,
                    y,
                    error: error_image.data[i],
                    test: test.pixel(x, y),
                    reference: reference.pixel(x, y),
                }
            })
            .collect();
        Ok(TexelDifference { max_abs, mean_abs: sum.into_iter().map(|s| s / count).collect(), worst, error_image })
    }

    /// The largest difference over all channels (NaN if any value was NaN).
    pub fn max(&self) -> f32 {
        self.max_abs.iter().fold(0.0f32, |m, &d| if d.is_nan() || m.is_nan() { f32::NAN } else { m.max(d) })
    }

    /// True when every difference is at most `tolerance` (and none is NaN).
    pub fn within(&self, tolerance: f32) -> bool {
        self.max() <= tolerance
    }
}
