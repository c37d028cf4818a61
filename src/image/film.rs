//! The film: per-pixel sample accumulation with a box reconstruction filter (each pixel is the
//! mean of its own samples, as Mitsuba's `box` rfilter), plus auxiliary (AOV) channels.

use super::Bitmap;
use crate::color::Rgb;

/// Auxiliary outputs recorded at the first surface a camera ray hits, averaged over the samples
/// of a pixel (zero where the ray escapes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Aov {
    /// The BSDF's reflectance colour.
    Albedo,
    /// Shading normal (world space, components in [-1, 1]).
    Normal,
    /// Texture coordinates (u, v).
    Uv,
    /// Texture footprint: max(|duv/dx|, |duv/dy|) in uv units.
    Footprint,
    /// World position of the hit (x, y, z).
    Position,
    /// Distance from the camera to the hit along the camera ray (Mitsuba's `depth` AOV).
    Depth,
}

impl Aov {
    /// Number of channels of this AOV.
    pub fn channels(self) -> usize {
        match self {
            Aov::Albedo | Aov::Normal | Aov::Position => 3,
            Aov::Uv => 2,
            Aov::Footprint | Aov::Depth => 1,
        }
    }

    /// EXR channel names.
    pub fn channel_names(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo => &["albedo.R", "albedo.G", "albedo.B"],
            Aov::Normal => &["normal.X", "normal.Y", "normal.Z"],
            Aov::Uv => &["uv.U", "uv.V"],
            Aov::Footprint => &["footprint.Y"],
            Aov::Position => &["position.X", "position.Y", "position.Z"],
            Aov::Depth => &["depth.Z"],
        }
    }
}

/// The samples of one pixel, accumulated in a fixed order by the thread that renders it.
#[derive(Clone, Debug)]
pub struct PixelSum {
    sum: [f64; 3],
    sum_sq: [f64; 3],
    count: u32,
    invalid: u32,
    aov: Vec<f64>,
}

impl PixelSum {
    /// An empty accumulator for `aov_stride` AOV values per sample.
    pub fn new(aov_stride: usize) -> Self {
        PixelSum { sum: [0.0; 3], sum_sq: [0.0; 3], count: 0, invalid: 0, aov: vec![0.0; aov_stride] }
    }

    /// Add a sample. `invalid` marks a sample whose radiance was not finite (replaced by zero
    /// by the caller): it is counted so that the renderer can report it.
    pub fn add(&mut self, radiance: Rgb, invalid: bool, aov_values: &[f32]) {
        for c in 0..3 {
            let v = radiance[c] as f64;
            self.sum[c] += v;
            self.sum_sq[c] += v * v;
        }
        self.count += 1;
        self.invalid += u32::from(invalid);
        // AOVs come from textures and geometry, which extreme input can drive to NaN; like
        // radiance, a non-finite value counts as zero rather than poisoning the pixel.
        for (s, v) in self.aov.iter_mut().zip(aov_values) {
            *s += if v.is_finite() { *v as f64 } else { 0.0 };
        }
    }
}

/// Accumulated radiance (and its per-sample variance) and AOVs of an image.
#[derive(Clone, Debug)]
pub struct Film {
    width: usize,
    height: usize,
    aovs: Vec<Aov>,
    aov_stride: usize,
    pixels: Vec<PixelSum>,
}

impl Film {
    /// An empty film recording the given AOVs.
    pub fn new(width: usize, height: usize, aovs: &[Aov]) -> Self {
        let aov_stride = aovs.iter().map(|a| a.channels()).sum();
        Film { width, height, aovs: aovs.to_vec(), aov_stride, pixels: vec![PixelSum::new(aov_stride); width * height] }
    }

    /// Image size.
    pub fn resolution(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The AOVs recorded.
    pub fn aovs(&self) -> &[Aov] {
        &self.aovs
    }

    /// Values per pixel of all AOVs together.
    pub fn aov_stride(&self) -> usize {
        self.aov_stride
    }

    /// Store the accumulated samples of pixel (x, y).
    pub fn set_pixel(&mut self, x: usize, y: usize, sum: PixelSum) {
        debug_assert_eq!(sum.aov.len(), self.aov_stride);
        self.pixels[y * self.width + x] = sum;
    }

    /// The accumulated samples of pixel (x, y).
    pub fn pixel(&self, x: usize, y: usize) -> &PixelSum {
        &self.pixels[y * self.width + x]
    }

    /// Samples per pixel, where every pixel has the same number (None otherwise, or empty).
    pub fn samples_per_pixel(&self) -> Option<u32> {
        let first = self.pixels.first()?.count;
        self.pixels.iter().all(|p| p.count == first).then_some(first)
    }

    /// The running sums of every pixel as bytes, for a render to be resumed ([`Film::from_state`]):
    /// per pixel, little-endian, sum and sum of squares of R, G, B (f64), the sample and invalid
    /// counts (u32), then the AOV sums (f64).
    pub fn state(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixels.len() * self.state_bytes_per_pixel());
        for p in &self.pixels {
            p.sum.iter().chain(&p.sum_sq).for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
            out.extend_from_slice(&p.count.to_le_bytes());
            out.extend_from_slice(&p.invalid.to_le_bytes());
            p.aov.iter().for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        }
        out
    }

    /// A `width` x `height` film recording `aovs` from [`Film::state`] bytes; None unless
    /// `bytes` is exactly such a film's state.
    pub fn from_state(width: usize, height: usize, aovs: &[Aov], bytes: &[u8]) -> Option<Film> {
        let mut film = Film::new(width, height, aovs);
        let per_pixel = film.state_bytes_per_pixel();
        if bytes.len() != per_pixel.checked_mul(width.checked_mul(height)?)? {
            return None;
        }
        let f64_at = |b: &[u8], k: usize| f64::from_le_bytes(b[8 * k..8 * k + 8].try_into().expect("8 bytes"));
        for (p, b) in film.pixels.iter_mut().zip(bytes.chunks_exact(per_pixel)) {
            p.sum = std::array::from_fn(|c| f64_at(b, c));
            p.sum_sq = std::array::from_fn(|c| f64_at(b, 3 + c));
            p.count = u32::from_le_bytes(b[48..52].try_into().expect("4 bytes"));
            p.invalid = u32::from_le_bytes(b[52..56].try_into().expect("4 bytes"));
            p.aov.iter_mut().enumerate().for_each(|(k, v)| *v = f64_at(&b[56..], k));
        }
        Some(film)
    }

    /// Bytes per pixel of [`Film::state`].
    fn state_bytes_per_pixel(&self) -> usize {
        6 * 8 + 2 * 4 + 8 * self.aov_stride
    }

    /// Total number of samples taken.
    pub fn sample_count(&self) -> u64 {
        self.pixels.iter().map(|p| p.count as u64).sum()
    }

    /// Number of samples whose radiance was NaN or infinite (counted as zero).
    pub fn invalid_sample_count(&self) -> u64 {
        self.pixels.iter().map(|p| p.invalid as u64).sum()
    }

    /// Mean radiance per pixel (RGB).
    pub fn radiance(&self) -> Bitmap {
        let mut out = Bitmap::new(self.width, self.height, 3);
        for (px, p) in out.data.chunks_exact_mut(3).zip(&self.pixels) {
            let n = p.count.max(1) as f64;
            for (v, sum) in px.iter_mut().zip(p.sum) {
                *v = (sum / n) as f32;
            }
        }
        out
    }

    /// Per-pixel variance of one sample (unbiased, N - 1 in the denominator; 0 with one sample;
    /// at most `f32::MAX`).
    pub fn variance(&self) -> Bitmap {
        let mut out = Bitmap::new(self.width, self.height, 3);
        for (px, p) in out.data.chunks_exact_mut(3).zip(&self.pixels) {
            let n = p.count as f64;
            if n < 2.0 {
                continue;
            }
            for ((v, sum), sum_sq) in px.iter_mut().zip(p.sum).zip(p.sum_sq) {
                let mean = sum / n;
                // Squares of finite f32 samples can exceed f32's range: saturate, never inf.
                *v = ((sum_sq / n - mean * mean).max(0.0) * n / (n - 1.0)).min(f32::MAX as f64) as f32;
            }
        }
        out
    }

    /// Mean of AOV `aov` per pixel, or None if it was not recorded.
    pub fn aov(&self, aov: Aov) -> Option<Bitmap> {
        let index = self.aovs.iter().position(|a| *a == aov)?;
        let offset: usize = self.aovs[..index].iter().map(|a| a.channels()).sum();
        let ch = aov.channels();
        let mut out = Bitmap::new(self.width, self.height, ch);
        for (px, p) in out.data.chunks_exact_mut(ch).zip(&self.pixels) {
            let n = p.count.max(1) as f64;
            for (v, sum) in px.iter_mut().zip(&p.aov[offset..offset + ch]) {
                *v = (sum / n) as f32;
            }
        }
        Some(out)
    }
}
