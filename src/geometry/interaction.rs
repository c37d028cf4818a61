//! The surface interaction: everything shading needs to know about a ray hit.

use super::{Frame, FrameOf, Ray, RayDifferential};
use crate::simd::{Real, V3};
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
        let surface = triangle_surface_of(
            tri.p.map(V3::from),
            tri.n.unwrap_or([Vec3::ZERO; 3]).map(V3::from),
            tri.uv.unwrap_or(DEFAULT_UVS).map(|uv| [uv.x, uv.y]),
            b1,
            b2,
        );
        Self::new(surface.into(), ray, t, triangle)
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
        let (o, d) = shadow_ray_to_of(self.p.into(), self.ng.into(), target.into());
        Ray { o: o.into(), d: d.into(), t_max: SHADOW_RAY_T_MAX }
    }
}

/// Where a shadow ray towards a point ends ([`shadow_ray_to_of`]): just short of the point,
/// since Mitsuba 3's `ShadowEpsilon` is ten `RayEpsilon`s.
pub const SHADOW_RAY_T_MAX: f32 = 1.0 - 10.0 * 1500.0 / 16_777_216.0;

/// The origin and direction of the shadow ray from `p` (geometric normal `ng`) to `target`, in
/// one lane or eight: the origin offset off the surface towards the target
/// ([`super::offset_ray_origin`]), the direction `target - origin`, so that the ray reaches the
/// target at t = 1 and ends at [`SHADOW_RAY_T_MAX`].
#[inline(always)]
pub fn shadow_ray_to_of<T: Real>(p: V3<T>, ng: V3<T>, target: V3<T>) -> (V3<T>, V3<T>) {
    let o = super::offset_ray_origin_of(p, ng, target - p);
    (o, target - o)
}

/// The texture coordinates of a mesh without them: uv = (b1, b2).
pub const DEFAULT_UVS: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];

/// A triangle's surface at a point, in one lane or eight ([`triangle_surface_of`]).
#[derive(Clone, Copy, Debug)]
pub struct TriangleSurface<T: Real> {
    /// Position.
    pub p: V3<T>,
    /// Geometric normal (the counter-clockwise winding's), unit length.
    pub ng: V3<T>,
    /// Interpolated shading normal, unit length; `ng` where the vertex normals sum to zero.
    pub shading_normal: V3<T>,
    /// Texture coordinates.
    pub uv: [T; 2],
    /// dp/du.
    pub dpdu: V3<T>,
    /// dp/dv.
    pub dpdv: V3<T>,
}

/// The surface of triangles `p` (vertex normals `n`, zero where a mesh has none; texture
/// coordinates `uv`) at barycentric coordinates `(b1, b2)`, in one lane or eight. dp/du and
/// dp/dv solve `p_i - p_0 = dpdu (u_i - u_0) + dpdv (v_i - v_0)` (pbrt-v4
/// `Triangle::InteractionFromIntersection`); where the UVs are degenerate they are the tangents
/// of [`FrameOf::from_normal`] about the geometric normal.
#[inline(always)]
pub fn triangle_surface_of<T: Real>(
    [p0, p1, p2]: [V3<T>; 3],
    [n0, n1, n2]: [V3<T>; 3],
    uvs: [[T; 2]; 3],
    b1: T,
    b2: T,
) -> TriangleSurface<T> {
    let zero = T::splat(0.0);
    let b0 = T::splat(1.0) - b1 - b2;
    let p = p0 * b0 + p1 * b1 + p2 * b2;
    let ng = (p1 - p0).cross(p2 - p0).normalize();
    let uv = [uvs[0][0] * b0 + uvs[1][0] * b1 + uvs[2][0] * b2, uvs[0][1] * b0 + uvs[1][1] * b1 + uvs[2][1] * b2];

    let duv02 = [uvs[0][0] - uvs[2][0], uvs[0][1] - uvs[2][1]];
    let duv12 = [uvs[1][0] - uvs[2][0], uvs[1][1] - uvs[2][1]];
    let dp02 = p0 - p2;
    let dp12 = p1 - p2;
    let det = duv02[0] * duv12[1] - duv02[1] * duv12[0];
    let inv = T::splat(1.0) / det;
    let solvable = !det.abs().lt(T::splat(1e-12));
    let dpdu = V3::select(solvable, (dp02 * duv12[1] - dp12 * duv02[1]) * inv, V3::splat(0.0));
    let dpdv = V3::select(solvable, (dp12 * duv02[0] - dp02 * duv12[0]) * inv, V3::splat(0.0));
    let cross = dpdu.cross(dpdv);
    let degenerate = !(dpdu.is_finite() & dpdv.is_finite()) | cross.dot(cross).eq(zero);
    let fallback = FrameOf::from_normal(ng);

    // glam's normalize_or_zero, then the geometric normal in place of zero.
    let ns = n0 * b0 + n1 * b1 + n2 * b2;
    let rcp = T::splat(1.0) / ns.dot(ns).sqrt();
    let ns = ns * rcp;
    let usable = rcp.is_finite() & zero.lt(rcp) & !ns.is_zero();
    TriangleSurface {
        p,
        ng,
        shading_normal: V3::select(usable, ns, ng),
        uv,
        dpdu: V3::select(degenerate, fallback.s, dpdu),
        dpdv: V3::select(degenerate, fallback.t, dpdv),
    }
}

impl From<TriangleSurface<f32>> for SurfacePoint {
    #[inline(always)]
    fn from(s: TriangleSurface<f32>) -> Self {
        SurfacePoint {
            p: s.p.into(),
            ng: s.ng.into(),
            shading_normal: s.shading_normal.into(),
            uv: Vec2::from_array(s.uv),
            dpdu: s.dpdu.into(),
            dpdv: s.dpdv.into(),
        }
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
    fn lanes_reconstruct_hits_bit_for_bit_as_one_hit_does() {
        use crate::simd::F32x8;
        use crate::simd::testing::{direction, isas, numbers};
        // Triangles of every size and orientation, without vertex normals, with them, with
        // normals that cancel at the hit point, without UVs, with degenerate and with ordinary
        // ones.
        let triangle = |k: usize| {
            let scale = [1e-3, 1.0, 40.0][k % 3];
            let p = [0, 1, 2].map(|c| direction(k * 3 + c) * scale + Vec3::splat(0.1 * k as f32));
            let n = match k % 4 {
                0 => None,
                1 => Some([-Vec3::Z, -Vec3::Z, -Vec3::Z]),
                2 => Some([Vec3::Y, -Vec3::Y, Vec3::X]),
                _ => Some([0, 1, 2].map(|c| direction(k * 5 + c))),
            };
            let uv = match k % 5 {
                0 => None,
                1 => Some([Vec2::splat(0.5); 3]),
                _ => Some([0, 1, 2].map(|c| Vec2::new((k * 7 + c) as f32 * 0.37, (k + c * c) as f32 * 0.11).fract())),
            };
            TriangleVertices { p, n, uv }
        };
        let ray = Ray::new(Vec3::new(0.3, 2.0, 5.0), Vec3::new(0.1, -0.3, -1.0));
        for isa in isas() {
            for chunk in 0..1000 {
                let tris: [TriangleVertices; 8] = std::array::from_fn(|i| triangle(chunk * 8 + i));
                let b = |i: usize| {
                    let [b1, b2] = numbers(chunk, i);
                    if b1 + b2 > 1.0 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) }
                };
                let corners = |f: &dyn Fn(&TriangleVertices) -> [Vec3; 3]| {
                    [0, 1, 2].map(|c| V3::from(std::array::from_fn::<Vec3, 8, _>(|i| f(&tris[i])[c])))
                };
                let uvs =
                    [0, 1, 2].map(|c| [0, 1].map(|k| F32x8::from_fn(|i| tris[i].uv.unwrap_or(DEFAULT_UVS)[c][k])));
                let (b1, b2) = (F32x8::from_fn(|i| b(i).0), F32x8::from_fn(|i| b(i).1));
                let (s, frame) = isa.run(|| {
                    let s = triangle_surface_of(
                        corners(&|t| t.p),
                        corners(&|t| t.n.unwrap_or([Vec3::ZERO; 3])),
                        uvs,
                        b1,
                        b2,
                    );
                    (s, FrameOf::from_normal_tangent(s.shading_normal, s.dpdu))
                });
                for (i, tri) in tris.iter().enumerate() {
                    let one = SurfaceInteraction::from_triangle(tri, b(i).0, b(i).1, 1.0, &ray, 0);
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    let lanes = [s.p, s.ng, s.dpdu, s.dpdv, frame.s, frame.t, frame.n].map(|v| bits(v.lane(i)));
                    let alone = [one.p, one.ng, one.dpdu, one.dpdv, one.frame.s, one.frame.t, one.frame.n].map(bits);
                    assert_eq!(lanes, alone, "{isa:?} {tri:?} at {:?}", b(i));
                    assert_eq!([s.uv[0].0[i], s.uv[1].0[i]].map(f32::to_bits), one.uv.to_array().map(f32::to_bits));
                }
            }
        }
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
