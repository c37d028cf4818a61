//! The pseudo-random shifts h_i of tiling and blending (paper 000 Eq. 1): a 32-bit hash of a
//! tile's integer key (its lattice vertex, or its place in a cut band's row) and the seed, so
//! that a WGSL shader computes the same shifts bit for bit (WGSL has no 64-bit integers).
//! `shaders/tiling_blending/shift.wgsl` is the GPU port of this file.

use glam::{IVec2, UVec3, Vec2};

/// The pcg3d hash of Jarzynski and Olano ("Hash Functions for GPU Rendering", JCGT 9(3), 2020):
/// three 32-bit words to three, an LCG step and two rounds of cross-multiplication.
#[inline]
pub fn pcg3d(v: UVec3) -> UVec3 {
    let mut v = v.wrapping_mul(UVec3::splat(1_664_525)).wrapping_add(UVec3::splat(1_013_904_223));
    let mix = |v: &mut UVec3| {
        v.x = v.x.wrapping_add(v.y.wrapping_mul(v.z));
        v.y = v.y.wrapping_add(v.z.wrapping_mul(v.x));
        v.z = v.z.wrapping_add(v.x.wrapping_mul(v.y));
    };
    mix(&mut v);
    v ^= v >> 16;
    mix(&mut v);
    v
}

/// A scene's 64-bit seed as the 32-bit word the hash takes: its two halves XORed (seeds below
/// 2^32 are themselves).
#[inline]
pub fn fold_seed(seed: u64) -> u32 {
    (seed ^ (seed >> 32)) as u32
}

/// Salt of the cut bands' key space, so that a band's tiles never share a lattice vertex's
/// shift.
pub(crate) const CUT_SALT: u32 = 0x9e37_79b9;

/// The pseudo-random shift h of a lattice vertex under `seed`: uniform over the exemplar's unit
/// square (the exemplar repeats with period 1), 24 bits per axis.
#[inline]
pub fn shift(vertex: IVec2, seed: u64) -> Vec2 {
    shift_of_key(UVec3::new(vertex.x as u32, vertex.y as u32, fold_seed(seed)))
}

/// The shift of tile `m` of the row along cut `curve` under `seed` ([`super::CutBands`]),
/// drawn like a lattice vertex's from a separate key space. Rows longer than 2^32 tiles wrap.
#[inline]
pub fn cut_shift(curve: u32, m: i64, seed: u64) -> Vec2 {
    shift_of_key(UVec3::new(m as u32, curve, fold_seed(seed) ^ CUT_SALT))
}

/// The top 24 bits of the first two hash words, as a point of [0, 1)^2.
#[inline]
fn shift_of_key(key: UVec3) -> Vec2 {
    let bits = pcg3d(key);
    Vec2::new((bits.x >> 8) as f32, (bits.y >> 8) as f32) * (1.0 / 16_777_216.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_are_uniform_and_differ_between_vertices() {
        let n = 64;
        let mut sum = Vec2::ZERO;
        let mut seen = std::collections::HashSet::new();
        for i in -n / 2..n / 2 {
            for j in -n / 2..n / 2 {
                let h = shift(IVec2::new(i, j), 7);
                assert!(h.cmpge(Vec2::ZERO).all() && h.cmplt(Vec2::ONE).all());
                sum += h;
                seen.insert((h.x.to_bits(), h.y.to_bits()));
            }
        }
        let mean = sum / (n * n) as f32;
        // Mean of 4096 uniforms: standard error 0.0045.
        assert!((mean - Vec2::splat(0.5)).abs().max_element() < 0.02, "{mean}");
        assert_eq!(seen.len(), (n * n) as usize);
        assert_ne!(shift(IVec2::new(1, 2), 7), shift(IVec2::new(1, 2), 8));
    }

    #[test]
    fn cut_shifts_differ_from_lattice_shifts() {
        for m in -50..50 {
            assert_ne!(cut_shift(3, m, 7), shift(IVec2::new(m as i32, 3), 7));
        }
        assert_eq!(fold_seed(7), 7);
        assert_eq!(fold_seed(1 << 32), 1);
    }
}
