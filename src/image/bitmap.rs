//! A float image with 1 to 4 channels.

use glam::{Vec2, Vec4};

/// How the integer values of an image file encode colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ColorSpace {
    /// sRGB-encoded: 8- and 16-bit colour channels are decoded to linear on load.
    Srgb,
    /// Values are used as stored (data textures: normals, roughness, F maps).
    Linear,
}

/// A row-major float image, row 0 at the top, `channels` interleaved values per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Values per pixel: 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA).
    pub channels: usize,
    /// `width * height * channels` values.
    pub data: Vec<f32>,
}

impl Bitmap {
    /// An image filled with zeros.
    pub fn new(width: usize, height: usize, channels: usize) -> Self {
        assert!((1..=4).contains(&channels));
        Bitmap { width, height, channels, data: vec![0.0; width * height * channels] }
    }

    /// Width and height as floats, for texel addressing. Converted through u32, which x86-64
    /// turns into a float in one instruction where usize takes a branch: no image comes near
    /// 2^32 texels a side (`limits::MAX_IMAGE_SIDE`; a side of 2^32 would be 16 GB a row).
    #[inline(always)]
    pub fn size_f32(&self) -> Vec2 {
        debug_assert!(self.width <= u32::MAX as usize && self.height <= u32::MAX as usize);
        Vec2::new(self.width as u32 as f32, self.height as u32 as f32)
    }

    /// The pixel at column `x`, row `y` as RGBA: grey is replicated, missing alpha is 1.
    #[inline(always)]
    pub fn pixel(&self, x: usize, y: usize) -> Vec4 {
        match self.channels {
            1 => self.pixel_of::<1>(x, y),
            2 => self.pixel_of::<2>(x, y),
            3 => self.pixel_of::<3>(x, y),
            _ => self.pixel_of::<4>(x, y),
        }
    }

    /// [`Bitmap::pixel`] of a bitmap whose channel count is `C` (4: at least 4), for loops over
    /// many pixels of one bitmap that match the count once rather than at every pixel.
    #[inline(always)]
    pub fn pixel_of<const C: usize>(&self, x: usize, y: usize) -> Vec4 {
        debug_assert!(self.channels == C || (C == 4 && self.channels > 4));
        let i = (y * self.width + x) * self.channels;
        let d = &self.data[i..i + C];
        match C {
            1 => Vec4::new(d[0], d[0], d[0], 1.0),
            2 => Vec4::new(d[0], d[0], d[0], d[1]),
            3 => Vec4::new(d[0], d[1], d[2], 1.0),
            _ => Vec4::new(d[0], d[1], d[2], d[3]),
        }
    }

    /// The values of pixel (x, y).
    #[inline]
    pub fn values(&self, x: usize, y: usize) -> &[f32] {
        let i = (y * self.width + x) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// Mutable values of pixel (x, y).
    #[inline]
    pub fn values_mut(&mut self, x: usize, y: usize) -> &mut [f32] {
        let i = (y * self.width + x) * self.channels;
        &mut self.data[i..i + self.channels]
    }

    /// Set negative values (lossy EXR compression) and non-finite ones to 0: what colours and
    /// radiance read from a file become ([`super::read_bitmap`]).
    pub fn zero_negative_and_non_finite(&mut self) {
        for v in &mut self.data {
            if !(v.is_finite() && *v >= 0.0) {
                *v = 0.0;
            }
        }
    }

    /// The RGB channels of an RGBA image (other images as they are).
    pub fn without_alpha(&self) -> Bitmap {
        if self.channels != 4 {
            return self.clone();
        }
        let data = self.data.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        Bitmap { width: self.width, height: self.height, channels: 3, data }
    }

    /// Number of NaN or infinite values.
    pub fn non_finite_count(&self) -> usize {
        self.data.iter().filter(|v| !v.is_finite()).count()
    }

    /// Mean of each channel.
    pub fn channel_means(&self) -> Vec<f64> {
        let mut sums = vec![0.0f64; self.channels];
        for px in self.data.chunks_exact(self.channels) {
            for (s, v) in sums.iter_mut().zip(px) {
                *s += *v as f64;
            }
        }
        let n = (self.width * self.height).max(1) as f64;
        sums.iter().map(|s| s / n).collect()
    }
}
