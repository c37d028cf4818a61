//! Eight f32 lanes whose every operation is one named AVX2 instruction where the CPU has it
//! (through the `pulp` crate's safe wrappers), and a portable twin that computes the same bits:
//! for kernels, such as the ray packets' traversal, whose values LLVM splits into 128-bit pieces
//! and spills when they are written over [`super::F32x8`]'s arrays.
//!
//! A kernel is written once, generic over [`Lanes8`], and run by [`super::Isa::run_lanes`]. The
//! two sets run the same IEEE operations lane by lane; `min` and `max` are x86's (the second
//! operand where either is NaN), so the portable set gives the AVX2 bits.
#![allow(clippy::needless_range_loop)]

/// A set of eight-lane operations (a zero-sized token: [`Avx2Lanes`] exists only where the CPU
/// runs AVX2). Masks hold a lane's comparison as all bits set or none.
pub trait Lanes8: Copy {
    /// Eight f32 lanes.
    type F: Copy;
    /// Eight lanes of a comparison.
    type M: Copy;
    /// `x` in every lane.
    fn splat(self, x: f32) -> Self::F;
    /// Lanes from an array.
    fn load(self, x: [f32; 8]) -> Self::F;
    /// The lanes as an array.
    fn store(self, x: Self::F) -> [f32; 8];
    /// `a + b`.
    fn add(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a - b`.
    fn sub(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a * b`.
    fn mul(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a / b`.
    fn div(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a` where `a < b`, else `b` (x86's `minps`).
    fn min(self, a: Self::F, b: Self::F) -> Self::F;
    /// `a` where `a > b`, else `b` (x86's `maxps`).
    fn max(self, a: Self::F, b: Self::F) -> Self::F;
    /// `|a|`.
    fn abs(self, a: Self::F) -> Self::F;
    /// The magnitude of `a` with the sign of `sign`.
    fn copysign(self, a: Self::F, sign: Self::F) -> Self::F;
    /// `a < b` (false for NaN).
    fn lt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a <= b` (false for NaN).
    fn le(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a > b` (false for NaN).
    fn gt(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a >= b` (false for NaN).
    fn ge(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a == b` (false for NaN).
    fn eq(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a != b` (true for NaN).
    fn ne(self, a: Self::F, b: Self::F) -> Self::M;
    /// `a & b`.
    fn and(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a | b`.
    fn or(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a & !b`.
    fn and_not(self, a: Self::M, b: Self::M) -> Self::M;
    /// `a` where `mask` holds, else `b`.
    fn select(self, mask: Self::M, a: Self::F, b: Self::F) -> Self::F;
    /// Bit i set where lane i of `mask` holds.
    fn bits(self, mask: Self::M) -> u32;
    /// The mask holding in lane i where bit i of `bits` is set.
    fn mask(self, bits: u32) -> Self::M;
}

/// A kernel written once over [`Lanes8`] ([`super::Isa::run_lanes`]).
pub trait LaneKernel {
    /// What the kernel returns.
    type Output;
    /// The kernel with the operations of `lanes`.
    fn run<L: Lanes8>(self, lanes: L) -> Self::Output;
}

/// The portable operations: a loop over the lanes each.
#[derive(Clone, Copy, Debug)]
pub struct PortableLanes;

impl PortableLanes {
    #[inline(always)]
    fn zip(a: [f32; 8], b: [f32; 8], f: impl Fn(f32, f32) -> f32) -> [f32; 8] {
        let mut out = [0.0; 8];
        for i in 0..8 {
            out[i] = f(a[i], b[i]);
        }
        out
    }

    #[inline(always)]
    fn compare(a: [f32; 8], b: [f32; 8], f: impl Fn(f32, f32) -> bool) -> [bool; 8] {
        let mut out = [false; 8];
        for i in 0..8 {
            out[i] = f(a[i], b[i]);
        }
        out
    }

    #[inline(always)]
    fn logic(a: [bool; 8], b: [bool; 8], f: impl Fn(bool, bool) -> bool) -> [bool; 8] {
        let mut out = [false; 8];
        for i in 0..8 {
            out[i] = f(a[i], b[i]);
        }
        out
    }
}

impl Lanes8 for PortableLanes {
    type F = [f32; 8];
    type M = [bool; 8];
    #[inline(always)]
    fn splat(self, x: f32) -> [f32; 8] {
        [x; 8]
    }
    #[inline(always)]
    fn load(self, x: [f32; 8]) -> [f32; 8] {
        x
    }
    #[inline(always)]
    fn store(self, x: [f32; 8]) -> [f32; 8] {
        x
    }
    #[inline(always)]
    fn add(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| a + b)
    }
    #[inline(always)]
    fn sub(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| a - b)
    }
    #[inline(always)]
    fn mul(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| a * b)
    }
    #[inline(always)]
    fn div(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| a / b)
    }
    #[inline(always)]
    fn min(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn max(self, a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        Self::zip(a, b, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn abs(self, a: [f32; 8]) -> [f32; 8] {
        Self::zip(a, a, |a, _| a.abs())
    }
    #[inline(always)]
    fn copysign(self, a: [f32; 8], sign: [f32; 8]) -> [f32; 8] {
        Self::zip(a, sign, f32::copysign)
    }
    #[inline(always)]
    fn lt(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a <= b)
    }
    #[inline(always)]
    fn gt(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a > b)
    }
    #[inline(always)]
    fn ge(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a >= b)
    }
    #[inline(always)]
    fn eq(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a == b)
    }
    #[inline(always)]
    fn ne(self, a: [f32; 8], b: [f32; 8]) -> [bool; 8] {
        Self::compare(a, b, |a, b| a != b)
    }
    #[inline(always)]
    fn and(self, a: [bool; 8], b: [bool; 8]) -> [bool; 8] {
        Self::logic(a, b, |a, b| a & b)
    }
    #[inline(always)]
    fn or(self, a: [bool; 8], b: [bool; 8]) -> [bool; 8] {
        Self::logic(a, b, |a, b| a | b)
    }
    #[inline(always)]
    fn and_not(self, a: [bool; 8], b: [bool; 8]) -> [bool; 8] {
        Self::logic(a, b, |a, b| a & !b)
    }
    #[inline(always)]
    fn select(self, mask: [bool; 8], a: [f32; 8], b: [f32; 8]) -> [f32; 8] {
        let mut out = [0.0; 8];
        for i in 0..8 {
            out[i] = if mask[i] { a[i] } else { b[i] };
        }
        out
    }
    #[inline(always)]
    fn bits(self, mask: [bool; 8]) -> u32 {
        let mut bits = 0;
        for i in 0..8 {
            bits |= (mask[i] as u32) << i;
        }
        bits
    }
    #[inline(always)]
    fn mask(self, bits: u32) -> [bool; 8] {
        let mut mask = [false; 8];
        for i in 0..8 {
            mask[i] = bits & (1 << i) != 0;
        }
        mask
    }
}

/// AVX2's operations, one instruction each (`pulp`'s safe wrappers of `std::arch`): a token that
/// [`Avx2Lanes::new`] returns only where the CPU runs them. They are inlined, as one instruction,
/// only into code compiled with these features: [`super::Isa::run_lanes`] compiles the kernel so.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub struct Avx2Lanes(pub(super) pulp::x86::V3);

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Avx2Lanes, Lanes8};
    use pulp::{f32x8, m32x8};

    impl Avx2Lanes {
        /// The token, where the CPU runs AVX2 and the features `pulp` asks with it (FMA, BMI,
        /// LZCNT: every AVX2 CPU has them). No multiply-add is formed from them: Rust lets LLVM
        /// contract none.
        pub fn new() -> Option<Self> {
            pulp::x86::V3::try_new().map(Avx2Lanes)
        }
    }

    impl Lanes8 for Avx2Lanes {
        type F = f32x8;
        type M = m32x8;
        #[inline(always)]
        fn splat(self, x: f32) -> f32x8 {
            self.0.splat_f32x8(x)
        }
        #[inline(always)]
        fn load(self, x: [f32; 8]) -> f32x8 {
            bytemuck::cast(x)
        }
        #[inline(always)]
        fn store(self, x: f32x8) -> [f32; 8] {
            bytemuck::cast(x)
        }
        #[inline(always)]
        fn add(self, a: f32x8, b: f32x8) -> f32x8 {
            self.0.add_f32x8(a, b)
        }
        #[inline(always)]
        fn sub(self, a: f32x8, b: f32x8) -> f32x8 {
            self.0.sub_f32x8(a, b)
        }
        #[inline(always)]
        fn mul(self, a: f32x8, b: f32x8) -> f32x8 {
            self.0.mul_f32x8(a, b)
        }
        #[inline(always)]
        fn div(self, a: f32x8, b: f32x8) -> f32x8 {
            self.0.div_f32x8(a, b)
        }
        #[inline(always)]
        fn min(self, a: f32x8, b: f32x8) -> f32x8 {
            bytemuck::cast(self.0.avx._mm256_min_ps(bytemuck::cast(a), bytemuck::cast(b)))
        }
        #[inline(always)]
        fn max(self, a: f32x8, b: f32x8) -> f32x8 {
            bytemuck::cast(self.0.avx._mm256_max_ps(bytemuck::cast(a), bytemuck::cast(b)))
        }
        #[inline(always)]
        fn abs(self, a: f32x8) -> f32x8 {
            self.0.abs_f32x8(a)
        }
        #[inline(always)]
        fn copysign(self, a: f32x8, sign: f32x8) -> f32x8 {
            let sign_bit = self.0.splat_f32x8(-0.0);
            self.0.or_f32x8(self.0.and_f32x8(sign, sign_bit), self.0.abs_f32x8(a))
        }
        #[inline(always)]
        fn lt(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_lt_f32x8(a, b)
        }
        #[inline(always)]
        fn le(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_le_f32x8(a, b)
        }
        #[inline(always)]
        fn gt(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_gt_f32x8(a, b)
        }
        #[inline(always)]
        fn ge(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_ge_f32x8(a, b)
        }
        #[inline(always)]
        fn eq(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_eq_f32x8(a, b)
        }
        #[inline(always)]
        fn ne(self, a: f32x8, b: f32x8) -> m32x8 {
            self.0.cmp_not_eq_f32x8(a, b)
        }
        #[inline(always)]
        fn and(self, a: m32x8, b: m32x8) -> m32x8 {
            self.0.and_m32x8(a, b)
        }
        #[inline(always)]
        fn or(self, a: m32x8, b: m32x8) -> m32x8 {
            self.0.or_m32x8(a, b)
        }
        #[inline(always)]
        fn and_not(self, a: m32x8, b: m32x8) -> m32x8 {
            self.0.and_m32x8(a, self.0.not_m32x8(b))
        }
        #[inline(always)]
        fn select(self, mask: m32x8, a: f32x8, b: f32x8) -> f32x8 {
            self.0.select_f32x8(mask, a, b)
        }
        #[inline(always)]
        fn bits(self, mask: m32x8) -> u32 {
            self.0.avx._mm256_movemask_ps(bytemuck::cast(mask)) as u32
        }
        #[inline(always)]
        fn mask(self, bits: u32) -> m32x8 {
            let lane_bits = pulp::u32x8(1, 2, 4, 8, 16, 32, 64, 128);
            let set = self.0.and_u32x8(self.0.splat_u32x8(bits), lane_bits);
            self.0.cmp_eq_u32x8(set, lane_bits)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every operation on values that tell x86's semantics apart (NaN, signed zeros,
    /// infinities), through a kernel, as both sets compute it.
    struct EveryOperation([f32; 8], [f32; 8]);

    impl LaneKernel for EveryOperation {
        type Output = Vec<[u32; 8]>;
        fn run<L: Lanes8>(self, l: L) -> Vec<[u32; 8]> {
            let (a, b) = (l.load(self.0), l.load(self.1));
            let f = |x: L::F| l.store(x).map(f32::to_bits);
            let m = |x: L::M| {
                let bits = l.bits(x);
                std::array::from_fn(|i| (bits >> i) & 1)
            };
            vec![
                f(l.splat(-0.0)),
                f(l.add(a, b)),
                f(l.sub(a, b)),
                f(l.mul(a, b)),
                f(l.div(a, b)),
                f(l.min(a, b)),
                f(l.max(a, b)),
                f(l.abs(a)),
                f(l.copysign(a, b)),
                m(l.lt(a, b)),
                m(l.le(a, b)),
                m(l.gt(a, b)),
                m(l.ge(a, b)),
                m(l.eq(a, b)),
                m(l.ne(a, b)),
                m(l.and(l.lt(a, b), l.ne(a, b))),
                m(l.or(l.lt(a, b), l.eq(a, b))),
                m(l.and_not(l.le(a, b), l.eq(a, b))),
                f(l.select(l.lt(a, b), a, b)),
                m(l.mask(0b1011_0010)),
                f(l.select(l.mask(0b0110_1001), a, b)),
            ]
        }
    }

    #[test]
    fn avx2_and_portable_lanes_compute_the_same_bits() {
        let nan = f32::NAN;
        let cases = [
            ([1.0, -0.0, 0.0, nan, 2.0, f32::INFINITY, -3.5, nan], [2.0, 0.0, -0.0, 1.0, nan, 1.0, -3.5, nan]),
            (
                [1e-30, -1e30, 7.0, -7.0, 0.1, 0.2, 3.0, -0.0],
                [3.0, 1e-30, -0.0, 0.0, 0.3, 0.2, f32::NEG_INFINITY, -1.0],
            ),
        ];
        // min(NaN, 1) is the second operand, as minps gives it.
        assert_eq!(EveryOperation(cases[0].0, cases[0].1).run(PortableLanes)[5][3], 1.0f32.to_bits());
        for (a, b) in cases {
            let portable = EveryOperation(a, b).run(PortableLanes);
            // The portable set against scalar arithmetic, where it is unambiguous.
            assert_eq!(portable[1], std::array::from_fn(|i| (a[i] + b[i]).to_bits()));
            let expected_min = |i: usize| if a[i] < b[i] { a[i] } else { b[i] };
            assert_eq!(portable[5], std::array::from_fn(|i| expected_min(i).to_bits()));
            #[cfg(target_arch = "x86_64")]
            if Avx2Lanes::new().is_some() {
                let avx2 = crate::simd::Isa::Avx2.run_lanes(EveryOperation(a, b));
                assert_eq!(avx2, portable);
            }
        }
    }
}
