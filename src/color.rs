//! Linear Rec.709 RGB, the colour space of everything inside tessera (DESIGN.md section 3).
//!
//! 8-bit colour textures are sRGB-decoded once on load ([`srgb_to_linear`]); PNG output is
//! sRGB-encoded ([`linear_to_srgb`]). Nothing else converts colours.

use glam::Vec3A;

/// Linear Rec.709 RGB radiance, reflectance or weight; a SIMD vector (glam's `Vec3A`), so that
/// colour arithmetic works on the three channels at once.
pub type Rgb = Vec3A;

/// Relative luminance of a linear Rec.709 colour (ITU-R BT.709 weights).
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.212_671 * c.x + 0.715_160 * c.y + 0.072_169 * c.z
}

/// The sRGB electro-optical transfer function: an encoded value in [0, 1] to linear.
#[inline]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// The inverse of [`srgb_to_linear`]: a linear value to sRGB encoding (not clamped).
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 { v * 12.92 } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

/// Lookup table of [`srgb_to_linear`] for the 256 values of an 8-bit channel.
pub fn srgb_u8_table() -> [f32; 256] {
    std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_is_identity() {
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            let back = srgb_to_linear(linear_to_srgb(v));
            assert!((back - v).abs() < 1e-5, "{v} -> {back}");
        }
    }

    #[test]
    fn srgb_decode_matches_mitsuba_values() {
        // Values checked in Mitsuba 3.9.1 (../shared/tools/mitsuba/README.md).
        assert!((srgb_to_linear(200.0 / 255.0) - 0.577_581).abs() < 1e-5);
        assert!((srgb_to_linear(40.0 / 255.0) - 0.021_219).abs() < 1e-5);
    }
}
