//! Display of a linear render as an 8-bit PNG (`tessera render --exposure --tonemap`): an
//! exposure in stops, then a tone curve, before the sRGB encoding of [`super::write_png`]. EXR
//! output is never tone-mapped: it keeps the linear radiance.

/// The tone curve applied to each linear channel after the exposure.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ToneMap {
    /// Values above 1 clip (what a PNG of the linear image shows).
    #[default]
    Clamp,
    /// Narkowicz's fit of the ACES reference rendering transform's filmic curve,
    /// x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), per channel: highlights roll off instead
    /// of clipping (a display choice, not ACES colour management).
    Aces,
}

impl ToneMap {
    /// The display value of linear value `v` (before sRGB encoding), in [0, 1].
    pub fn map(self, v: f32) -> f32 {
        let v = v.max(0.0);
        match self {
            ToneMap::Clamp => v.min(1.0),
            ToneMap::Aces => (v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14)).clamp(0.0, 1.0),
        }
    }

    /// `image` (linear RGB) exposed by 2^`stops` and mapped by this curve.
    pub fn apply(self, image: &super::Bitmap, stops: f32) -> super::Bitmap {
        let gain = stops.exp2();
        let mut out = image.clone();
        out.data.iter_mut().for_each(|v| *v = self.map(*v * gain));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_curves_keep_black_clip_or_roll_off_and_rise() {
        assert_eq!((ToneMap::Clamp.map(0.0), ToneMap::Clamp.map(0.5), ToneMap::Clamp.map(7.0)), (0.0, 0.5, 1.0));
        assert_eq!(ToneMap::Aces.map(0.0), 0.0);
        // The ACES fit: mid grey 0.18 maps near 0.27, 1 to 0.80, and large values approach 1.
        assert!((ToneMap::Aces.map(0.18) - 0.2669).abs() < 1e-3, "{}", ToneMap::Aces.map(0.18));
        assert!((ToneMap::Aces.map(1.0) - 0.8038).abs() < 1e-3, "{}", ToneMap::Aces.map(1.0));
        assert!(ToneMap::Aces.map(100.0) > 0.99 && ToneMap::Aces.map(100.0) <= 1.0);
        // It rises, strictly where f32 can still tell (below 4), and never falls.
        let mut last = 0.0;
        for k in 1..2000 {
            let v = ToneMap::Aces.map(k as f32 * 0.01);
            assert!(v > last || (k >= 400 && v == last), "rises at {}", k as f32 * 0.01);
            last = v;
        }
        let image = crate::image::Bitmap { width: 1, height: 1, channels: 3, data: vec![0.25, 0.5, 2.0] };
        assert_eq!(ToneMap::Clamp.apply(&image, 1.0).data, vec![0.5, 1.0, 1.0]);
    }
}
