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
        let bits = draw_bits(self.key, self.dimension);
        self.dimension += 1;
        bits
    }

    /// The next uniform number in [0, 1).
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        first_unit(self.next_bits())
    }

    /// The next two uniform numbers, from the top and the next 24 bits of one hash: the
    /// finaliser mixes every output bit with every input bit, so the two are independent.
    #[inline]
    pub fn next_2d(&mut self) -> Vec2 {
        let bits = self.next_bits();
        Vec2::new(first_unit(bits), second_unit(bits))
    }

    /// The stream's key and next dimension, for `draws` draws taken in lanes
    /// ([`SamplerLanes`]); the sampler moves past them, as if it had drawn them.
    #[inline]
    pub(crate) fn reserve(&mut self, draws: u32) -> (u64, u32) {
        let start = (self.key, self.dimension);
        self.dimension += draws;
        start
    }
}

/// The draws of eight samplers in lanes, bit for bit what [`Sampler::next_1d`] and
/// [`Sampler::next_2d`] give: the hashes are computed eight at a time, in 64-bit lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SamplerLanes {
    /// Per lane, the sampler's key ([`Sampler::reserve`]).
    pub(crate) keys: [u64; 8],
    /// Per lane, the dimension of the sampler's first reserved draw.
    pub(crate) dimensions: [u32; 8],
}

impl SamplerLanes {
    /// The hashed bits of each lane's reserved draw `offset` (0 for the first).
    #[inline(always)]
    fn bits(&self, offset: u32) -> [u64; 8] {
        let mut bits = [0; 8];
        for (lane, out) in bits.iter_mut().enumerate() {
            *out = draw_bits(self.keys[lane], self.dimensions[lane] + offset);
        }
        bits
    }

    /// Each lane's reserved draw `offset` as [`Sampler::next_1d`] gives it.
    #[inline(always)]
    pub(crate) fn draw_1d(&self, offset: u32) -> [f32; 8] {
        self.bits(offset).map(first_unit)
    }

    /// Each lane's reserved draw `offset` as [`Sampler::next_2d`] gives it: the first numbers,
    /// then the second.
    #[inline(always)]
    pub(crate) fn draw_2d(&self, offset: u32) -> [[f32; 8]; 2] {
        let bits = self.bits(offset);
        [bits.map(first_unit), bits.map(second_unit)]
    }
}

/// The 64 hashed bits of the draw of dimension `dimension` (0 for the first) of stream `key`.
#[inline(always)]
fn draw_bits(key: u64, dimension: u32) -> u64 {
    mix64(key ^ (dimension as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// A draw's first number in [0, 1): its top 24 bits, which make every float in [0, 1) with
/// spacing 2^-24 equally likely.
#[inline(always)]
fn first_unit(bits: u64) -> f32 {
    unit_from_24_bits(bits >> 40)
}

/// A draw's second number in [0, 1) (for [`Sampler::next_2d`]): its next 24 bits.
#[inline(always)]
fn second_unit(bits: u64) -> f32 {
    unit_from_24_bits((bits >> 16) & 0xff_ffff)
}

/// A 24-bit integer as a float in [0, 1) (exact: floats hold 24-bit integers; converted from
/// i32, which lanes convert in one instruction).
#[inline(always)]
fn unit_from_24_bits(bits: u64) -> f32 {
    bits as i32 as f32 * (1.0 / 16_777_216.0)
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
    fn draws_in_lanes_are_the_samplers_draws_bit_for_bit() {
        use crate::simd::Isa;
        for isa in [Isa::Avx2, Isa::Portable].into_iter().filter(|isa| isa.available()) {
            for trial in 0..300u64 {
                // Eight streams at different dimensions.
                let samplers: [Sampler; 8] = std::array::from_fn(|lane| {
                    let mut s = Sampler::new(trial, lane as u64 * 7919 + trial * 3, (lane as u32 * 13) ^ trial as u32);
                    (0..(lane + trial as usize) % 6).for_each(|_| _ = s.next_1d());
                    s
                });
                let mut lanes = SamplerLanes { keys: [0; 8], dimensions: [0; 8] };
                for (lane, sampler) in samplers.iter().enumerate() {
                    let mut reserving = sampler.clone();
                    (lanes.keys[lane], lanes.dimensions[lane]) = reserving.reserve(3);
                    // Past the reserved draws, the stream goes on where three draws leave it.
                    let mut drawing = sampler.clone();
                    (0..3).for_each(|_| _ = drawing.next_1d());
                    assert_eq!(reserving.next_1d().to_bits(), drawing.next_1d().to_bits());
                }
                let (first, second, third) = isa.run(|| (lanes.draw_1d(0), lanes.draw_2d(1), lanes.draw_1d(2)));
                for (lane, sampler) in samplers.iter().enumerate() {
                    let mut s = sampler.clone();
                    assert_eq!(s.next_1d().to_bits(), first[lane].to_bits(), "{isa:?}, lane {lane}");
                    let pair = s.next_2d();
                    assert_eq!(
                        [pair.x.to_bits(), pair.y.to_bits()],
                        [second[0][lane].to_bits(), second[1][lane].to_bits()]
                    );
                    assert_eq!(s.next_1d().to_bits(), third[lane].to_bits(), "{isa:?}, lane {lane}");
                }
            }
        }
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
