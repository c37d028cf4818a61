//! Orthonormal shading frames: world <-> local, with the normal along local +z.

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
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let s = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { s, t, n }
    }

    /// The shading frame of DESIGN.md section 3: `s = normalize(dpdu - n (n . dpdu))`,
    /// `t = n x s`. Falls back to [`Frame::from_normal`] when `dpdu` is (nearly) parallel to
    /// `n` or zero (a degenerate UV mapping).
    pub fn from_normal_tangent(n: Vec3, dpdu: Vec3) -> Self {
        let s = dpdu - n * n.dot(dpdu);
        let len2 = s.length_squared();
        if !(len2 > 1e-20 * dpdu.length_squared().max(1e-30)) || !len2.is_finite() {
            return Self::from_normal(n);
        }
        let s = s / len2.sqrt();
        Frame { s, t: n.cross(s), n }
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
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    /// Local direction to world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.s * v.x + self.t * v.y + self.n * v.z
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
