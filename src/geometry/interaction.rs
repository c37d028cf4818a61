//! The surface interaction: everything shading needs to know about a ray hit.

use super::{Frame, Ray, RayDifferential};
use glam::{Vec2, Vec3};

/// A ray hit on a surface, with its shading frame, texture coordinates and texture footprint.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// Hit point.
    pub p: Vec3,
    /// Geometric normal on the front side (a triangle's counter-clockwise winding), unit length.
    pub ng: Vec3,
    /// Shading frame: interpolated normal, tangent along dp/du (DESIGN.md section 3).
    pub frame: Frame,
    /// Texture coordinates (bottom-left origin, v up).
    pub uv: Vec2,
    /// Partial derivative of the position along u (a triangle's from its UV Jacobian).
    pub dpdu: Vec3,
    /// Partial derivative of the position along v.
    pub dpdv: Vec3,
    /// Texture footprint: change of uv for a one-pixel step in x on the image.
    pub duv_dx: Vec2,
    /// Texture footprint: change of uv for a one-pixel step in y on the image.
    pub duv_dy: Vec2,
    /// Direction towards where the ray came from (world, unit length).
    pub wo: Vec3,
    /// Distance along the ray (in units of the ray direction's length).
    pub t: f32,
    /// Index of the primitive in the scene: its triangles first, then its spheres
    /// ([`crate::accel::Hit::primitive`]).
    pub primitive: u32,
}

/// A point of a surface with its normals, texture coordinates and their derivatives: what a
/// shape computes at a hit, for [`SurfaceInteraction::new`].
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// Position.
    pub p: Vec3,
    /// Geometric normal on the front side, unit length.
    pub ng: Vec3,
    /// Shading normal, unit length.
    pub shading_normal: Vec3,
    /// Texture coordinates (bottom-left origin, v up).
    pub uv: Vec2,
    /// dp/du.
    pub dpdu: Vec3,
    /// dp/dv.
    pub dpdv: Vec3,
}

/// The vertex data of one triangle, as the mesh stores it.
#[derive(Clone, Copy, Debug)]
pub struct TriangleVertices {
    /// Positions.
    pub p: [Vec3; 3],
    /// Shading normals, if the mesh has them.
    pub n: Option<[Vec3; 3]>,
    /// Texture coordinates, if the mesh has them.
    pub uv: Option<[Vec2; 3]>,
}

impl SurfaceInteraction {
    /// Build the interaction at barycentric coordinates `(b1, b2)` (weights of vertices 1 and 2)
    /// of a triangle hit at parameter `t` by `ray`.
    ///
    /// dp/du and dp/dv solve `p_i - p_0 = dpdu (u_i - u_0) + dpdv (v_i - v_0)` (pbrt-v4
    /// `Triangle::InteractionFromIntersection`). A mesh without texture coordinates gets
    /// uv = (b1, b2). A triangle whose UVs are degenerate gets an arbitrary tangent frame.
    pub fn from_triangle(tri: &TriangleVertices, b1: f32, b2: f32, t: f32, ray: &Ray, triangle: u32) -> Self {
        let b0 = 1.0 - b1 - b2;
        let [p0, p1, p2] = tri.p;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let ng = (p1 - p0).cross(p2 - p0).normalize();
        let uvs = tri.uv.unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y]);
        let uv = uvs[0] * b0 + uvs[1] * b1 + uvs[2] * b2;

        let duv02 = uvs[0] - uvs[2];
        let duv12 = uvs[1] - uvs[2];
        let dp02 = p0 - p2;
        let dp12 = p1 - p2;
        let det = duv02.x * duv12.y - duv02.y * duv12.x;
        let (mut dpdu, mut dpdv) = if det.abs() < 1e-12 {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            let inv = 1.0 / det;
            ((dp02 * duv12.y - dp12 * duv02.y) * inv, (dp12 * duv02.x - dp02 * duv12.x) * inv)
        };
        if !(dpdu.is_finite() && dpdv.is_finite()) || dpdu.cross(dpdv).length_squared() == 0.0 {
            let f = Frame::from_normal(ng);
            dpdu = f.s;
            dpdv = f.t;
        }

        let ns = tri
            .n
            .map(|[n0, n1, n2]| (n0 * b0 + n1 * b1 + n2 * b2).normalize_or_zero())
            .filter(|n| *n != Vec3::ZERO)
            .unwrap_or(ng);
        Self::new(SurfacePoint { p, ng, shading_normal: ns, uv, dpdu, dpdv }, ray, t, triangle)
    }

    /// The interaction at `point`, where `ray` met primitive `primitive` at parameter `t`: the
    /// shading frame of DESIGN.md section 3 (the shading normal, the tangent along dp/du), no
    /// footprint yet.
    pub fn new(point: SurfacePoint, ray: &Ray, t: f32, primitive: u32) -> Self {
        let SurfacePoint { p, ng, shading_normal, uv, dpdu, dpdv } = point;
        SurfaceInteraction {
            p,
            ng,
            frame: Frame::from_normal_tangent(shading_normal, dpdu),
            uv,
            dpdu,
            dpdv,
            duv_dx: Vec2::ZERO,
            duv_dy: Vec2::ZERO,
            wo: -ray.d.normalize(),
            t,
            primitive,
        }
    }

    /// Estimate the texture footprint from the positions `dpdx`, `dpdy` that the neighbouring
    /// pixels' rays reach on the tangent plane: least squares for (du/dx, dv/dx) against dp/du
    /// and dp/dv (pbrt-v4 `SurfaceInteraction::ComputeDifferentials`).
    pub fn set_footprint(&mut self, dpdx: Vec3, dpdy: Vec3) {
        let (a, b) = (self.dpdu, self.dpdv);
        let (ata00, ata01, ata11) = (a.dot(a), a.dot(b), b.dot(b));
        let det = ata00 * ata11 - ata01 * ata01;
        let inv = if det.abs() > 0.0 { 1.0 / det } else { 0.0 };
        let solve = |d: Vec3| {
            let (atb0, atb1) = (a.dot(d), b.dot(d));
            let du = (ata11 * atb0 - ata01 * atb1) * inv;
            let dv = (ata00 * atb1 - ata01 * atb0) * inv;
            // Keep absurd values (grazing angles) from reaching the texture filters.
            let clean = |x: f32| {
                if x.is_finite() { x.clamp(-1e8, 1e8) } else { 0.0 }
            };
            Vec2::new(clean(du), clean(dv))
        };
        self.duv_dx = solve(dpdx);
        self.duv_dy = solve(dpdy);
    }

    /// Footprint from the neighbouring rays of a ray differential of the ray from `o` that
    /// made this hit: where they meet the tangent plane at the hit
    /// ([`RayDifferential::steps_on_plane`]). Returns false (and leaves the footprint alone)
    /// when a neighbouring ray is parallel to the plane.
    pub fn footprint_from_differential(&mut self, o: Vec3, diff: &RayDifferential) -> bool {
        match diff.steps_on_plane(o, self.p, self.ng) {
            Some((dpdx, dpdy)) => {
                self.set_footprint(dpdx, dpdy);
                true
            }
            None => false,
        }
    }

    /// Whether the UV map is mirrored here: dp/du x dp/dv points against the geometric normal.
    #[inline]
    pub fn uv_mirrored(&self) -> bool {
        self.dpdu.cross(self.dpdv).dot(self.ng) < 0.0
    }

    /// Spawn a ray from the hit along `d`, offset off the surface to the side `d` points to.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(super::offset_ray_origin(self.p, self.ng, d), d)
    }

    /// Spawn a shadow ray towards the point `target` (itself already offset off its surface);
    /// it hits nothing when the segment between them is clear.
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let o = super::offset_ray_origin(self.p, self.ng, target - self.p);
        /// Stop just short of the target: Mitsuba 3's `ShadowEpsilon` is ten `RayEpsilon`s.
        const SHADOW_EPSILON: f32 = 10.0 * 1500.0 / 16_777_216.0;
        Ray { o, d: target - o, t_max: 1.0 - SHADOW_EPSILON }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interaction_derivatives_of_affine_uv_map() {
        // p = (2u, 3v, 0) on the plane z = 0.
        let tri = TriangleVertices {
            p: [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 3.0, 0.0)],
            n: None,
            uv: Some([Vec2::ZERO, Vec2::X, Vec2::Y]),
        };
        let ray = Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z);
        let mut si = SurfaceInteraction::from_triangle(&tri, 0.25, 0.5, 1.0, &ray, 0);
        assert!(si.dpdu.distance(Vec3::new(2.0, 0.0, 0.0)) < 1e-6);
        assert!(si.dpdv.distance(Vec3::new(0.0, 3.0, 0.0)) < 1e-6);
        assert!(si.uv.distance(Vec2::new(0.25, 0.5)) < 1e-6);
        assert!(si.frame.s.distance(Vec3::X) < 1e-6 && si.frame.n.distance(Vec3::Z) < 1e-6);
        // A step of (0.1, 0.2) in the plane is du = 0.05, dv = 0.2/3.
        si.set_footprint(Vec3::new(0.1, 0.2, 0.0), Vec3::new(0.0, -0.3, 0.0));
        assert!(si.duv_dx.distance(Vec2::new(0.05, 0.2 / 3.0)) < 1e-6);
        assert!(si.duv_dy.distance(Vec2::new(0.0, -0.1)) < 1e-6);
    }

    #[test]
    fn interaction_degenerate_uv_gets_valid_frame() {
        let tri = TriangleVertices { p: [Vec3::ZERO, Vec3::X, Vec3::Y], n: None, uv: Some([Vec2::ZERO; 3]) };
        let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
        let si = SurfaceInteraction::from_triangle(&tri, 0.2, 0.2, 1.0, &ray, 0);
        assert!(si.frame.s.is_finite() && si.frame.n.distance(Vec3::Z) < 1e-6);
        assert!(si.dpdu.is_finite() && si.dpdv.is_finite());
    }
}
