//! A counter-based sampler: every random number is a pure function of
//! (seed, pixel, sample index, dimension), so images do not depend on thread scheduling.

use glam::Vec2;

/// Independent uniform samples for one camera path.
///
/// The stream is keyed by (seed, pixel, sample index); each draw ([`Sampler::next_1d`], or
/// [`Sampler::next_2d`] for a pair) hashes the key with the next dimension number. There is no
/// state besides that counter, so the same path always sees the same numbers, whichever thread
/// traces it.
#[derive(Clone, Debug)]
pub struct Sampler {
    key: u64,
    dimension: u32,
}

/// The part of the samplers' key that one pixel's samples share: (seed, pixel), hashed once.
#[derive(Clone, Copy, Debug)]
pub struct PixelKey(u64);

impl PixelKey {
    /// The key of pixel `pixel` (a linear pixel index) under `seed`.
    pub fn new(seed: u64, pixel: u64) -> Self {
        let key = mix64(seed ^ 0x9e37_79b9_7f4a_7c15);
        PixelKey(mix64(key ^ pixel.wrapping_mul(0xd1b5_4a32_d192_ed03)))
    }

    /// The sampler of sample `sample` of this pixel: the same as [`Sampler::new`].
    #[inline]
    pub fn sampler(self, sample: u32) -> Sampler {
        Sampler { key: mix64(self.0 ^ (sample as u64).wrapping_mul(0x8cb9_2ba7_2f3d_8dd7)), dimension: 0 }
    }
}

/// A 64-bit finaliser with full avalanche (Stafford's "Mix13" variant of the MurmurHash3
/// finaliser, as used by SplitMix64).
#[inline(always)]
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler {
    /// The sampler of sample `sample` of pixel `pixel` (a linear pixel index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u32) -> Self {
        PixelKey::new(seed, pixel).sampler(sample)
    }

    /// The next draw's 64 hashed bits.
    #[inline]
    fn next_bits(&mut self) -> u64 {
        let bits = mix64(self.key ^ (self.dimension as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        self.dimension += 1;
        bits
    }

    /// The next uniform number in [0, 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        // The top 24 bits make every float in [0, 1) with spacing 2^-24 equally likely.
        unit_from_24_bits(self.next_bits() >> 40)
    }

    /// The next two uniform numbers, from the top and the next 24 bits of one hash: the
    /// finaliser mixes every output bit with every input bit, so the two are independent.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let bits = self.next_bits();
        Vec2::new(unit_from_24_bits(bits >> 40), unit_from_24_bits((bits >> 16) & 0xff_ffff))
    }
}

/// A 24-bit integer as a float in [0, 1) (exact: floats hold 24-bit integers).
#[inline(always)]
fn unit_from_24_bits(bits: u64) -> f32 {
    bits as f32 * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampler_is_a_pure_function_of_its_key() {
        let a: Vec<f32> = {
            let mut s = Sampler::new(3, 17, 5);
            (0..8).map(|_| s.next_1d()).collect()
        };
        let b: Vec<f32> = {
            let mut s = Sampler::new(3, 17, 5);
            (0..8).map(|_| s.next_1d()).collect()
        };
        assert_eq!(a, b);
        let c: Vec<f32> = {
            let mut s = Sampler::new(3, 17, 6);
            (0..8).map(|_| s.next_1d()).collect()
        };
        assert_ne!(a, c);
    }

    #[test]
    fn sampler_moments_are_uniform() {
        // Mean 1/2, variance 1/12 and lag-1 correlation 0, over many keys and dimensions.
        let n = 200_000;
        let (mut sum, mut sum2, mut cross) = (0.0f64, 0.0f64, 0.0f64);
        let mut prev = 0.5f64;
        for i in 0..n {
            let mut s = Sampler::new(1, i / 4, (i % 4) as u32);
            let x = s.next_1d() as f64;
            assert!((0.0..1.0).contains(&x));
            sum += x;
            sum2 += x * x;
            cross += (x - 0.5) * (prev - 0.5);
            prev = x;
        }
        let n = n as f64;
        let mean = sum / n;
        let var = sum2 / n - mean * mean;
        // Standard errors: 0.29/sqrt(n) = 6.5e-4 for the mean; use about 5 sigma.
        assert!((mean - 0.5).abs() < 3e-3, "mean {mean}");
        assert!((var - 1.0 / 12.0).abs() < 2e-3, "variance {var}");
        assert!((cross / n).abs() < 1e-3, "lag-1 covariance {}", cross / n);
    }

    #[test]
    fn sampler_2d_draws_are_uniform_on_the_square() {
        // Chi-square of 2D draws over a 16 x 16 grid (255 degrees of freedom): a correlation
        // between the two halves of a hash would crowd some cells.
        let (n, cells) = (256_000usize, 16usize);
        let mut counts = vec![0u32; cells * cells];
        for i in 0..n {
            let mut s = Sampler::new(2, i as u64 / 4, (i % 4) as u32);
            s.next_1d();
            let u = s.next_2d();
            assert!((0.0..1.0).contains(&u.x) && (0.0..1.0).contains(&u.y));
            counts[(u.y * cells as f32) as usize * cells + (u.x * cells as f32) as usize] += 1;
        }
        let expected = (n / (cells * cells)) as f64;
        let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
        // The 0.999 quantile of chi-square with 255 degrees of freedom is about 330.
        assert!(chi2 < 330.0, "chi-square {chi2}");
    }
}
