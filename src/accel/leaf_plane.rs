//! The plane of a flat emitting leaf, which shadow rays towards it need not test (issue 19).
//!
//! A shadow ray towards an area light ends short of the light's sampled point, which is itself
//! offset off the light's surface towards the ray's origin
//! ([`crate::geometry::offset_ray_origin`]). Where the light is flat, the whole segment stays on
//! one side of its plane, and cannot meet its triangles: their distance to the plane is linear
//! along the segment. A small quad light is a leaf of its own, which every shadow ray aimed at
//! it enters, so [`LeafPlane::clears`] lets such rays skip the leaf's triangle tests. It is
//! kept only for leaves whose triangles all emit: other flat leaves (floors, walls) hold the
//! origins of shadow rays rather than their ends, and would pay the check for nothing.

use crate::geometry::Ray;
use glam::{Vec3, Vec3A};

/// Relative precision of [`LeafPlane`] distances: a leaf is flat where its vertices lie within
/// `FLAT (1 + their largest coordinate)` of its plane, and a segment must clear the plane by
/// `slack` plus `FLAT` times its own largest coordinate. Far above f32 rounding (2^-24), so that
/// distances computed in f32 decide as exact ones would, and a segment that clears the plane
/// clears every triangle the watertight test could report within rounding; far below a shadow
/// ray's offset off its light (1500 2^-24), so that a shadow ray ends clear of it.
const FLAT: f32 = 1.0 / 65536.0;

/// The plane n . x = `offset` (n a unit normal) that every vertex of a flat leaf lies within
/// `slack` of.
#[derive(Clone, Copy, Debug)]
pub(super) struct LeafPlane {
    normal: Vec3A,
    offset: f32,
    slack: f32,
}

impl LeafPlane {
    /// The plane of the largest of `triangles`, where all of them lie in it within [`FLAT`];
    /// None where they do not, or have no area.
    pub(super) fn of(triangles: &[[Vec3; 3]]) -> Option<Self> {
        let cross = |[a, b, c]: &[Vec3; 3]| (b.as_dvec3() - a.as_dvec3()).cross(c.as_dvec3() - a.as_dvec3());
        let largest = triangles.iter().max_by(|x, y| cross(x).length_squared().total_cmp(&cross(y).length_squared()));
        let largest = largest.filter(|t| cross(t).length_squared() > 0.0 && cross(t).is_finite())?;
        let normal = cross(largest).normalize();
        let offset = normal.dot(largest[0].as_dvec3());
        let vertices = || triangles.iter().flatten();
        let deviation = vertices().map(|v| (normal.dot(v.as_dvec3()) - offset).abs()).fold(0.0, f64::max);
        let magnitude = 1.0 + vertices().map(|v| v.abs().max_element()).fold(0.0, f32::max) as f64;
        (deviation <= FLAT as f64 * magnitude).then(|| LeafPlane {
            normal: normal.as_vec3().into(),
            offset: offset as f32,
            slack: (deviation + FLAT as f64 * magnitude) as f32,
        })
    }

    /// Whether the segment (0, `t_max`) of `ray` stays clear of the plane: its two ends lie on
    /// one side, farther than `slack` and the segment's own rounding allow. False where
    /// `t_max` is infinite. (Out of line: inlined, LLVM computed its per-ray terms before every
    /// traversal, for the few rays that reach an emitting leaf.)
    #[inline(never)]
    pub(super) fn clears(&self, ray: &Ray, t_max: f32) -> bool {
        let (o, d) = (Vec3A::from(ray.o), Vec3A::from(ray.d) * t_max);
        let start = self.normal.dot(o) - self.offset;
        let end = start + self.normal.dot(d);
        let margin = self.slack + FLAT * (o.abs().max_element() + d.abs().max_element());
        // An infinite or NaN margin or end fails the comparisons.
        start.abs() > margin && end.abs() > margin && (start > 0.0) == (end > 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_leaf_is_cleared_only_by_segments_that_stay_off_its_plane() {
        // A tilted unit quad away from the origin, as a quad light is.
        let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.7, -0.4, 0.2);
        let corner = |x: f32, y: f32| Vec3::new(30.0, -12.0, 5.0) + rotation * Vec3::new(x, y, 0.0);
        let quad = [
            [corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0)],
            [corner(0.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)],
        ];
        let plane = LeafPlane::of(&quad).expect("a quad is flat");
        let normal = rotation * Vec3::Z;
        let mut rng = crate::accel::tests::Lcg(0x2545f491);
        let mut next = || rng.next();
        for i in 0..2000 {
            let q = corner(next(), next());
            let side = if i % 2 == 0 { 1.0 } else { -1.0 };
            // Origins from overhead down to a grazing 0.6 degrees off the plane.
            let slope = [1.0, 0.1, 0.01][i % 3];
            let along = rotation * Vec3::new(next() - 0.5, next() - 0.5, 0.0).normalize();
            let o = q + (along + normal * side * slope).normalize() * (0.5 + 20.0 * next());
            // The shadow ray towards q, which ends offset off the quad towards o: clear.
            let end = crate::geometry::offset_ray_origin(q, normal, o - q);
            let shadow = Ray { o, d: end - o, t_max: crate::geometry::SHADOW_RAY_T_MAX };
            assert!(plane.clears(&shadow, shadow.t_max), "shadow ray {shadow:?}");
            // A segment that reaches q exactly, or passes through the quad: not clear.
            let through = Ray { o, d: q - o, t_max: 1.0 + next() };
            assert!(!plane.clears(&through, through.t_max), "segment {through:?}");
            // An unbounded ray: never clear, whichever way it goes.
            assert!(!plane.clears(&Ray::new(o, o - q), f32::INFINITY));
        }
        // A quad bent by a hundredth of its size is not flat, nor is a triangle without area.
        let bent = [quad[0], [corner(0.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0) + normal * 0.01]];
        assert!(LeafPlane::of(&bent).is_none());
        assert!(LeafPlane::of(&[[Vec3::ONE; 3]]).is_none());
    }
}
