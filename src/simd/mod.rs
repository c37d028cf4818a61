//! Arithmetic written once for one value or for eight SIMD lanes (issue 19; Mitsuba 3 writes its
//! plugins once over `Float` the same way, for its scalar and its LLVM variants).
//!
//! A function generic over [`Real`] runs on `f32`, as the path tracer calls it today, or on
//! [`F32x8`], eight paths' values at once. Branches become [`Real::select`]s: both sides are
//! computed and one is kept, so that the `f32` instantiation returns what the branching code
//! returned, bit for bit. Eight lanes compile to AVX2 where the CPU has it and to SSE2 (two
//! halves) where not ([`Isa`]); both run the same IEEE operations in the same order, so they
//! agree bit for bit. Lanes differ from `f32` only in [`Real::sin_cos`]: libm's for `f32`, a
//! polynomial in lanes ([`trig`]). An RGB colour is a [`Real`] too, its channels being lanes.
//!
//! Kernels whose lanes LLVM would split and spill (the ray packets' traversal) are written over
//! [`Lanes8`] instead, whose operations are named AVX2 instructions or their portable twins
//! (`wide.rs`).

mod dispatch;
mod lanes;
pub mod trig;
mod wide;

pub use dispatch::Isa;
pub use lanes::{F32x8, M32x8};
#[cfg(target_arch = "x86_64")]
pub use wide::Avx2Lanes;
pub use wide::{LaneKernel, Lanes8, PortableLanes};

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Which lanes of a comparison held: `bool` for one value, [`M32x8`] for eight lanes.
pub trait Mask: Copy + BitAnd<Output = Self> + BitOr<Output = Self> + Not<Output = Self> {}

impl Mask for bool {}

/// A real number in one lane (`f32`) or eight ([`F32x8`]), or a colour's three channels as
/// lanes (glam's `Vec3A`), with IEEE single-precision arithmetic in every lane.
pub trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Neg<Output = Self>
{
    /// Lanes of a comparison.
    type Mask: Mask;
    /// `x` in every lane.
    fn splat(x: f32) -> Self;
    /// Square root (IEEE, correctly rounded).
    fn sqrt(self) -> Self;
    /// Absolute value (the sign bit cleared).
    fn abs(self) -> Self;
    /// The larger of the two in every lane; `other` where `self` is NaN (callers pass a
    /// number as `other`).
    fn max(self, other: Self) -> Self;
    /// `self < other`, per lane (false for NaN).
    fn lt(self, other: Self) -> Self::Mask;
    /// `self <= other`, per lane (false for NaN).
    fn le(self, other: Self) -> Self::Mask;
    /// `self == other`, per lane (false for NaN).
    fn eq(self, other: Self) -> Self::Mask;
    /// `a` where `mask` holds, else `b`, per lane.
    fn select(mask: Self::Mask, a: Self, b: Self) -> Self;
    /// (sin x, cos x): libm's for `f32`, [`trig::sin_cos`] in lanes.
    fn sin_cos(self) -> (Self, Self);
    /// The magnitude of `self` with the sign bit of `sign`, per lane.
    fn copysign(self, sign: Self) -> Self;
    /// Neither infinite nor NaN, per lane.
    fn is_finite(self) -> Self::Mask;
}

impl Real for f32 {
    type Mask = bool;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        f32::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self < other
    }
    #[inline(always)]
    fn le(self, other: Self) -> bool {
        self <= other
    }
    #[inline(always)]
    fn eq(self, other: Self) -> bool {
        self == other
    }
    #[inline(always)]
    fn select(mask: bool, a: Self, b: Self) -> Self {
        if mask { a } else { b }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        f32::sin_cos(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        f32::copysign(self, sign)
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

/// An RGB colour's three channels as three lanes (one SSE register: glam's `Vec3A`, which
/// [`crate::color::Rgb`] is), so that a colour's arithmetic, such as a Fresnel term, is written
/// once over [`Real`] for one path's colour and, channel by channel, for eight paths'.
impl Real for glam::Vec3A {
    type Mask = glam::BVec3A;
    #[inline(always)]
    fn splat(x: f32) -> Self {
        glam::Vec3A::splat(x)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        glam::Vec3A::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        glam::Vec3A::abs(self)
    }
    #[inline(always)]
    fn max(self, other: Self) -> Self {
        glam::Vec3A::max(self, other)
    }
    #[inline(always)]
    fn lt(self, other: Self) -> glam::BVec3A {
        self.cmplt(other)
    }
    #[inline(always)]
    fn le(self, other: Self) -> glam::BVec3A {
        self.cmple(other)
    }
    #[inline(always)]
    fn eq(self, other: Self) -> glam::BVec3A {
        self.cmpeq(other)
    }
    #[inline(always)]
    fn select(mask: glam::BVec3A, a: Self, b: Self) -> Self {
        glam::Vec3A::select(mask, a, b)
    }
    #[inline(always)]
    fn sin_cos(self) -> (Self, Self) {
        let ((sx, cx), (sy, cy), (sz, cz)) = (self.x.sin_cos(), self.y.sin_cos(), self.z.sin_cos());
        (glam::Vec3A::new(sx, sy, sz), glam::Vec3A::new(cx, cy, cz))
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        glam::Vec3A::copysign(self, sign)
    }
    #[inline(always)]
    fn is_finite(self) -> glam::BVec3A {
        self.is_finite_mask()
    }
}

impl Mask for glam::BVec3A {}

/// A 3-vector of [`Real`]s, with glam's `Vec3` operations in glam's order of operations, so
/// that `V3<f32>` computes what `Vec3` computes bit for bit.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct V3<T> {
    /// x.
    pub x: T,
    /// y.
    pub y: T,
    /// z.
    pub z: T,
}

impl<T: Real> V3<T> {
    /// The vector (x, y, z).
    #[inline(always)]
    pub fn new(x: T, y: T, z: T) -> Self {
        V3 { x, y, z }
    }

    /// x x' + y y' + z z'.
    #[inline(always)]
    pub fn dot(self, o: Self) -> T {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The cross product.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        V3::new(self.y * o.z - o.y * self.z, self.z * o.x - o.z * self.x, self.x * o.y - o.x * self.y)
    }

    /// self / |self|, as glam computes it: self * (1 / sqrt(self . self)).
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self * (T::splat(1.0) / self.dot(self).sqrt())
    }

    /// `a` where `mask` holds, else `b`, per lane.
    #[inline(always)]
    pub fn select(mask: T::Mask, a: Self, b: Self) -> Self {
        V3::new(T::select(mask, a.x, b.x), T::select(mask, a.y, b.y), T::select(mask, a.z, b.z))
    }

    /// `x` in every component.
    #[inline(always)]
    pub fn splat(x: f32) -> Self {
        V3::new(T::splat(x), T::splat(x), T::splat(x))
    }

    /// Whether every component is finite, per lane.
    #[inline(always)]
    pub fn is_finite(self) -> T::Mask {
        self.x.is_finite() & self.y.is_finite() & self.z.is_finite()
    }

    /// Whether every component is zero, per lane.
    #[inline(always)]
    pub fn is_zero(self) -> T::Mask {
        let zero = T::splat(0.0);
        self.x.eq(zero) & self.y.eq(zero) & self.z.eq(zero)
    }
}

impl<T: Real> Add for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        V3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<T: Real> Sub for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        V3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<T: Real> Neg for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        V3::new(-self.x, -self.y, -self.z)
    }
}

impl<T: Real> Mul<T> for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, s: T) -> Self {
        V3::new(self.x * s, self.y * s, self.z * s)
    }
}

impl<T: Real> Div<T> for V3<T> {
    type Output = Self;
    #[inline(always)]
    fn div(self, s: T) -> Self {
        V3::new(self.x / s, self.y / s, self.z / s)
    }
}

impl From<glam::Vec3> for V3<f32> {
    #[inline(always)]
    fn from(v: glam::Vec3) -> Self {
        V3::new(v.x, v.y, v.z)
    }
}

impl From<V3<f32>> for glam::Vec3 {
    #[inline(always)]
    fn from(v: V3<f32>) -> Self {
        glam::Vec3::new(v.x, v.y, v.z)
    }
}

impl From<[glam::Vec3; 8]> for V3<F32x8> {
    /// Eight vectors into lanes (a gather, outside the lane kernels).
    #[inline(always)]
    fn from(v: [glam::Vec3; 8]) -> Self {
        V3::new(F32x8::from_fn(|i| v[i].x), F32x8::from_fn(|i| v[i].y), F32x8::from_fn(|i| v[i].z))
    }
}

impl V3<F32x8> {
    /// Lane `i` (read in place: taken by value with a run-time index, the three vectors were
    /// copied to the stack first, at every call).
    #[inline(always)]
    pub fn lane(&self, i: usize) -> glam::Vec3 {
        glam::Vec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    /// Set lane `i` to `v` (a gather written in place, outside the lane kernels).
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: glam::Vec3) {
        (self.x.0[i], self.y.0[i], self.z.0[i]) = (v.x, v.y, v.z);
    }
}

/// The indices of the bits set in `mask`, lowest first: the lanes a bit mask selects, or the
/// children a node's box test lets through.
#[inline(always)]
pub fn set_bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        let i = (mask != 0).then_some(mask.trailing_zeros() as usize)?;
        mask &= mask - 1;
        Some(i)
    })
}

/// What the lane tests of the BSDFs share.
#[cfg(test)]
pub(crate) mod testing {
    use super::{F32x8, Isa, V3};
    use glam::{Vec2, Vec3};

    /// Eight lanes from `f(i)`, i the lane.
    pub fn gather(f: impl Fn(usize) -> Vec3) -> V3<F32x8> {
        V3::from(std::array::from_fn::<Vec3, 8, _>(f))
    }

    /// Lane `i` of `v`.
    pub fn lane(v: V3<F32x8>, i: usize) -> Vec3 {
        v.lane(i)
    }

    /// Directions over the sphere, and the poles, the horizon and a direction a hair off the
    /// pole, where the formulas branch.
    pub fn direction(k: usize) -> Vec3 {
        match k % 97 {
            0 => Vec3::Z,
            1 => Vec3::X,
            2 => -Vec3::Z,
            3 => Vec3::new(0.0, 1e-20, 1.0),
            _ => {
                let u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 * 0.414_213_57).fract());
                crate::sampling::warp::square_to_uniform_sphere(u)
            }
        }
    }

    /// [`direction`] moved into the upper hemisphere (z at least 1e-3).
    pub fn upper_direction(k: usize) -> Vec3 {
        let w = direction(k);
        Vec3::new(w.x, w.y, w.z.abs().max(1e-3)).normalize()
    }

    /// Sample numbers in [0, 1)^2 for lane `i` of chunk `chunk`.
    pub fn numbers(chunk: usize, i: usize) -> [f32; 2] {
        [((chunk * 8 + i) as f32 * 0.754_877_7).fract(), (i as f32 + 0.5) / 8.0]
    }

    /// The instruction sets this CPU runs.
    pub fn isas() -> impl Iterator<Item = Isa> {
        [Isa::Portable, Isa::Avx2].into_iter().filter(|isa| isa.available())
    }

    /// `run(isa)` for each instruction set this CPU runs, asserting that all give the same
    /// result (the lanes' bits).
    pub fn on_every_isa<T: PartialEq>(run: impl FnMut(Isa) -> T) {
        let results: Vec<T> = isas().map(run).collect();
        assert!(results.windows(2).all(|w| w[0] == w[1]), "AVX2 and portable lanes differ");
    }
}
