//! Rays and ray differentials.

use glam::Vec3;

/// A ray `o + t d` for `t` in `(0, t_max)`. `d` need not be unit length: shadow rays use
/// `d = target - o` with `t_max` just below 1.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
    /// Largest parameter that counts as a hit.
    pub t_max: f32,
}

impl Ray {
    /// A ray from `o` along `d`, unbounded.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        debug_assert!(o.is_finite() && d.is_finite(), "ray {o} {d}");
        Ray { o, d, t_max: f32::INFINITY }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// The rays through the neighbouring pixels, one pixel to the right (x) and one down (y),
/// used to estimate a hit's texture footprint (Igehy 1999; pbrt-v4 `RayDifferential`), kept as
/// changes of the main ray: the ray to the right starts at `o + dx_o` and points along
/// `d + dx_d`, where `d` is the main ray's direction at the scale the changes are given in (its
/// length does not change where a ray meets a plane). Keeping the changes rather than the
/// neighbouring rays spares [`crate::geometry::SurfaceInteraction::footprint_from_differential`]
/// the cancellation of subtracting two nearby hit points: in f32 that cost a relative error of
/// about 1e-4 in the footprint, enough to move a GPU's view off tessera's (docs/gpu.md).
#[derive(Clone, Copy, Debug)]
pub struct RayDifferential {
    /// The main ray's direction, at the scale of `dx_d` and `dy_d`.
    pub d: Vec3,
    /// Change of the origin for the ray one pixel to the right.
    pub dx_o: Vec3,
    /// Change of the direction for the ray one pixel to the right.
    pub dx_d: Vec3,
    /// Change of the origin for the ray one pixel down.
    pub dy_o: Vec3,
    /// Change of the direction for the ray one pixel down.
    pub dy_d: Vec3,
}

impl RayDifferential {
    /// Scale the changes to neighbours that are `scale` pixels away instead of one (pbrt-v4
    /// `ScaleDifferentials`).
    pub fn scaled(&self, scale: f32) -> Self {
        RayDifferential {
            d: self.d,
            dx_o: self.dx_o * scale,
            dx_d: self.dx_d * scale,
            dy_o: self.dy_o * scale,
            dy_d: self.dy_d * scale,
        }
    }

    /// Where the neighbouring rays meet the plane through `p` with normal `n`, less where the
    /// main ray from `o` meets it (at `p`, up to p's rounding, which the steps do not inherit);
    /// None for a neighbour parallel to the plane. With t the main ray's parameter at p along `d`, a neighbour (o + do, d + dd)
    /// meets the plane at t' = t - k, k = (n . do + t n . dd) / (n . (d + dd)), so its hit less
    /// p is do + dd (t - k) - d k: small terms only, no difference of nearby points.
    pub fn steps_on_plane(&self, o: Vec3, p: Vec3, n: Vec3) -> Option<(Vec3, Vec3)> {
        let t = (p - o).dot(self.d) / self.d.length_squared();
        let step = |d_o: Vec3, d_d: Vec3| {
            let k = (n.dot(d_o) + t * n.dot(d_d)) / n.dot(self.d + d_d);
            let s = d_o + d_d * (t - k) - self.d * k;
            s.is_finite().then_some(s)
        };
        Some((step(self.dx_o, self.dx_d)?, step(self.dy_o, self.dy_d)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_on_a_plane_are_where_the_neighbouring_rays_meet_it() {
        // A plane through p, tilted; rays from o. The steps are the neighbours' hits less the
        // main ray's, computed here the direct way in f64. (p, rounded to f32, lies off the
        // main ray by about 1e-7 of its distance: the steps do not inherit that.)
        let (o, p, n) = (Vec3::new(0.1, 0.2, 3.0), Vec3::new(0.3, -0.1, 0.2), Vec3::new(0.2, 0.5, 0.8).normalize());
        let diff = RayDifferential {
            d: (p - o) * 0.7,
            dx_o: Vec3::new(0.01, 0.0, 0.002),
            dx_d: Vec3::new(0.003, 0.001, 0.0),
            dy_o: Vec3::ZERO,
            dy_d: Vec3::new(0.0, -0.002, 0.0005),
        };
        let (sx, sy) = diff.steps_on_plane(o, p, n).unwrap();
        let hit = |o: glam::DVec3, d: glam::DVec3| {
            let (p, n) = (p.as_dvec3(), n.as_dvec3());
            o + d * (n.dot(p - o) / n.dot(d))
        };
        let direct = |d_o: Vec3, d_d: Vec3| {
            let (o, d) = (o.as_dvec3(), diff.d.as_dvec3());
            (hit(o + d_o.as_dvec3(), d + d_d.as_dvec3()) - hit(o, d)).as_vec3()
        };
        let (ex, ey) = (direct(diff.dx_o, diff.dx_d), direct(diff.dy_o, diff.dy_d));
        assert!(sx.distance(ex) < 1e-6 * sx.length(), "{sx} against {ex}");
        assert!(sy.distance(ey) < 1e-6 * sy.length(), "{sy} against {ey}");
        // A neighbour parallel to the plane meets it nowhere.
        let parallel = RayDifferential { dx_d: Vec3::new(0.1, 0.0, -diff.d.z), ..diff };
        assert!(parallel.steps_on_plane(o, p, Vec3::Z).is_none());
    }
}
