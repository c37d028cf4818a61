//! Orthonormal shading frames: world <-> local, with the normal along local +z.

use crate::simd::{Real, V3};
use glam::Vec3;

/// An orthonormal frame `(s, t, n)`; local coordinates have `n` as +z, `s` as +x, `t` as +y.
///
/// BSDFs work in local coordinates, where `cos_theta(w) = w.z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent (local +x); anisotropic GGX `alpha_u` is along it.
    pub s: Vec3,
    /// Second tangent (local +y), `n x s`.
    pub t: Vec3,
    /// Normal (local +z).
    pub n: Vec3,
}

impl Frame {
    /// A frame around `n` with an arbitrary but continuous tangent (Duff et al. 2017,
    /// "Building an Orthonormal Basis, Revisited"). `n` must be unit length.
    pub fn from_normal(n: Vec3) -> Self {
        FrameOf::from_normal(n.into()).into()
    }

    /// The shading frame of DESIGN.md section 3: `s = normalize(dpdu - n (n . dpdu))`,
    /// `t = n x s`. Falls back to [`Frame::from_normal`] when `dpdu` is (nearly) parallel to
    /// `n` or zero (a degenerate UV mapping).
    pub fn from_normal_tangent(n: Vec3, dpdu: Vec3) -> Self {
        FrameOf::from_normal_tangent(n.into(), dpdu.into()).into()
    }

    /// The frame turned about n so that s points along the tangent-plane part of `direction`
    /// (t turning with it, negated when `reversed`); unchanged when `direction` has none.
    pub fn turned_towards(&self, direction: Vec3, reversed: bool) -> Self {
        let (c, s) = (direction.dot(self.s), direction.dot(self.t));
        let len = (c * c + s * s).sqrt();
        if !(len > 0.0 && len.is_finite()) {
            return *self;
        }
        let (c, s) = (c / len, s / len);
        let t = self.t * c - self.s * s;
        Frame { s: self.s * c + self.t * s, t: if reversed { -t } else { t }, n: self.n }
    }

    /// World direction to local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        FrameOf::from(*self).to_local(v.into()).into()
    }

    /// Local direction to world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        FrameOf::from(*self).to_world(v.into()).into()
    }
}

/// [`Frame`] in one lane or eight: the same constructions written once over [`Real`], so that
/// `FrameOf<f32>` computes what `Frame` does bit for bit.
#[derive(Clone, Copy, Debug)]
pub struct FrameOf<T: Real> {
    /// First tangent (local +x).
    pub s: V3<T>,
    /// Second tangent (local +y).
    pub t: V3<T>,
    /// Normal (local +z).
    pub n: V3<T>,
}

impl<T: Real> FrameOf<T> {
    /// [`Frame::from_normal`] (Duff et al. 2017), in one lane or eight.
    #[inline(always)]
    pub fn from_normal(n: V3<T>) -> Self {
        let one = T::splat(1.0);
        let sign = one.copysign(n.z);
        let a = -one / (sign + n.z);
        let b = n.x * n.y * a;
        let s = V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = V3::new(b, sign + n.y * n.y * a, -n.y);
        FrameOf { s, t, n }
    }

    /// [`Frame::from_normal_tangent`], in one lane or eight: both constructions are computed
    /// and the fallback kept where dp/du has no part in the tangent plane.
    #[inline(always)]
    pub fn from_normal_tangent(n: V3<T>, dpdu: V3<T>) -> Self {
        let s = dpdu - n * n.dot(dpdu);
        let len2 = s.dot(s);
        let degenerate = !(T::splat(1e-20) * dpdu.dot(dpdu).max(T::splat(1e-30))).lt(len2) | !len2.is_finite();
        let s = s / len2.sqrt();
        let fallback = FrameOf::from_normal(n);
        FrameOf { s: V3::select(degenerate, fallback.s, s), t: V3::select(degenerate, fallback.t, n.cross(s)), n }
    }

    /// World direction to local coordinates.
    #[inline(always)]
    pub fn to_local(&self, v: V3<T>) -> V3<T> {
        V3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local direction to world coordinates.
    #[inline(always)]
    pub fn to_world(&self, v: V3<T>) -> V3<T> {
        self.s * v.x + self.t * v.y + self.n * v.z
    }
}

impl From<Frame> for FrameOf<f32> {
    #[inline(always)]
    fn from(f: Frame) -> Self {
        FrameOf { s: f.s.into(), t: f.t.into(), n: f.n.into() }
    }
}

impl From<FrameOf<f32>> for Frame {
    #[inline(always)]
    fn from(f: FrameOf<f32>) -> Self {
        Frame { s: f.s.into(), t: f.t.into(), n: f.n.into() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_orthonormal(f: &Frame) {
        for (a, b) in [(f.s, f.t), (f.t, f.n), (f.n, f.s)] {
            assert!(a.dot(b).abs() < 1e-5, "{f:?}");
        }
        for v in [f.s, f.t, f.n] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{f:?}");
        }
        // Right-handed: s x t = n.
        assert!(f.s.cross(f.t).distance(f.n) < 1e-5, "{f:?}");
    }

    #[test]
    fn frame_from_normal_is_orthonormal_right_handed() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.8, 0.2).normalize()] {
            let f = Frame::from_normal(n);
            assert_orthonormal(&f);
            let v = Vec3::new(0.2, -0.4, 0.7);
            assert!(f.to_world(f.to_local(v)).distance(v) < 1e-5);
        }
    }

    #[test]
    fn frames_in_lanes_are_the_frames_of_one_lane_bit_for_bit() {
        use crate::simd::testing::{direction, isas};
        // Tangents along the normal, zero, tiny, huge and ordinary.
        let tangent = |k: usize, n: Vec3| match k % 6 {
            0 => n * 2.0,
            1 => Vec3::ZERO,
            2 => direction(k + 1) * 1e-30,
            3 => direction(k + 1) * 1e30,
            _ => direction(k + 1) * 3.0,
        };
        for isa in isas() {
            for chunk in 0..2000 {
                let n: [Vec3; 8] = std::array::from_fn(|i| direction(chunk * 8 + i));
                let dpdu: [Vec3; 8] = std::array::from_fn(|i| tangent(chunk * 8 + i, n[i]));
                let frame = isa.run(|| FrameOf::from_normal_tangent(V3::from(n), V3::from(dpdu)));
                for i in 0..8 {
                    let one = Frame::from_normal_tangent(n[i], dpdu[i]);
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(
                        [frame.s, frame.t, frame.n].map(|v| bits(v.lane(i))),
                        [one.s, one.t, one.n].map(bits),
                        "{isa:?} n {} dpdu {}",
                        n[i],
                        dpdu[i]
                    );
                }
            }
        }
    }

    #[test]
    fn frame_tangent_follows_dpdu() {
        // On the front of Mitsuba's test sphere the tangent s is +x and t is +y.
        let f = Frame::from_normal_tangent(Vec3::Z, Vec3::new(6.276, 0.0, 0.240));
        assert_orthonormal(&f);
        assert!(f.s.distance(Vec3::X) < 1e-6);
        assert!(f.t.distance(Vec3::Y) < 1e-6);
        // Degenerate dpdu falls back to some valid frame.
        assert_orthonormal(&Frame::from_normal_tangent(Vec3::Z, Vec3::ZERO));
        assert_orthonormal(&Frame::from_normal_tangent(Vec3::Z, Vec3::Z));
    }
}
