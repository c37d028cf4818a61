//! Eight f32 lanes as a plain array. Every operation is a loop over the lanes without branches,
//! which LLVM turns into one 256-bit instruction inside an AVX2 function ([`super::Isa`]) and
//! two 128-bit ones elsewhere; nothing here names an instruction set. The loops index the
//! lanes rather than call `array::map` or `array::from_fn`: a call that LLVM leaves out of line
//! is compiled without AVX2, and where a kernel is large it did (the conductor's lanes ran 27%
//! slower with AVX2 than without).
#![allow(clippy::needless_range_loop)]

use super::{Mask, Real, trig};
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight f32 lanes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F32x8(pub [f32; 8]);

/// Which of eight lanes a comparison held in: all bits set, or none.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
pub struct M32x8(pub [u32; 8]);

impl F32x8 {
    /// Lane i from `f(i)`: for gathering values into lanes, outside the lane kernels.
    #[inline(always)]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        F32x8(std::array::from_fn(f))
    }

    /// `f` of each lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Self {
        let mut out = [0.0; 8];
        for i in 0..8 {
            out[i] = f(self.0[i]);
        }
        F32x8(out)
    }

    /// `f` of each pair of lanes.
    #[inline(always)]
    fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        let mut out = [0.0; 8];
        for i in 0..8 {
            out[i] = f(self.0[i], o.0[i]);
        }
        F32x8(out)
    }

    /// The comparison `f` of each pair of lanes, as a mask.
    #[inline(always)]
    fn compare(self, o: Self, f: impl Fn(f32, f32) -> bool) -> M32x8 {
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = if f(self.0[i], o.0[i]) { u32::MAX } else { 0 };
        }
        M32x8(out)
    }

    /// The lanes' bits.
    #[inline(always)]
    pub fn to_bits(self) -> [u32; 8] {
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = self.0[i].to_bits();
        }
        out
    }

    /// Lanes from their bits.
    #[inline(always)]
    pub fn from_bits(bits: [u32; 8]) -> Self {
        let mut out = [0.0; 8];
        for i in 0..8 {
            out[i] = f32::from_bits(bits[i]);
        }
        F32x8(out)
    }

    /// Each lane rounded to the nearest integer (ties to even), for |x| < 2^22: by adding and
    /// subtracting 1.5 2^23, which SSE2 can do in lanes where it has no rounding instruction.
    #[inline(always)]
    pub fn round_small(self) -> Self {
        const MAGIC: f32 = 12_582_912.0;
        (self + F32x8::splat(MAGIC)) - F32x8::splat(MAGIC)
    }

    /// Each lane (a whole number) as an i32.
    #[inline(always)]
    pub fn to_i32(self) -> [i32; 8] {
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = self.0[i] as i32;
        }
        out
    }
}

macro_rules! lane_op {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for F32x8 {
            type Output = F32x8;
            #[inline(always)]
            fn $f(self, o: F32x8) -> F32x8 {
                self.zip(o, |a, b| a $op b)
            }
        }
    };
}
lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl Neg for F32x8 {
    type Output = F32x8;
    #[inline(always)]
    fn neg(self) -> F32x8 {
        self.map(|a| -a)
    }
}

macro_rules! mask_op {
    ($trait:ident, $f:ident, $op:tt) => {
        impl $trait for M32x8 {
            type Output = M32x8;
            #[inline(always)]
            fn $f(self, o: M32x8) -> M32x8 {
                let mut out = [0; 8];
                for i in 0..8 {
                    out[i] = self.0[i] $op o.0[i];
                }
                M32x8(out)
            }
        }
    };
}
mask_op!(BitAnd, bitand, &);
mask_op!(BitOr, bitor, |);

impl Not for M32x8 {
    type Output = M32x8;
    #[inline(always)]
    fn not(self) -> M32x8 {
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = !self.0[i];
        }
        M32x8(out)
    }
}

impl Mask for M32x8 {}

impl M32x8 {
    /// The mask that holds in lane i where `set[i]`.
    #[inline(always)]
    pub fn from_bools(set: [bool; 8]) -> Self {
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = if set[i] { u32::MAX } else { 0 };
        }
        M32x8(out)
    }

    /// Whether lane `i` is set.
    #[inline(always)]
    pub fn test(&self, i: usize) -> bool {
        self.0[i] != 0
    }
}

impl Real for F32x8 {
    type Mask = M32x8;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        F32x8([x; 8])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        self.map(f32::abs)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.zip(other, f32::max)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> M32x8 {
        self.compare(other, |a, b| a < b)
    }
    #[inline(always)]
    fn le(self, other: Self) -> M32x8 {
        self.compare(other, |a, b| a <= b)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> M32x8 {
        self.compare(other, |a, b| a == b)
    }
    #[inline(always)]
    fn select(mask: M32x8, a: Self, b: Self) -> Self {
        let (a, b) = (a.to_bits(), b.to_bits());
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = (a[i] & mask.0[i]) | (b[i] & !mask.0[i]);
        }
        F32x8::from_bits(out)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        trig::sin_cos(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        const SIGN: u32 = 0x8000_0000;
        let (a, b) = (self.to_bits(), sign.to_bits());
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = (a[i] & !SIGN) | (b[i] & SIGN);
        }
        F32x8::from_bits(out)
    }
    #[inline(always)]
    fn is_finite(self) -> M32x8 {
        const EXPONENT: u32 = 0x7f80_0000;
        let bits = self.to_bits();
        let mut out = [0; 8];
        for i in 0..8 {
            out[i] = if bits[i] & EXPONENT != EXPONENT { u32::MAX } else { 0 };
        }
        M32x8(out)
    }
}
