//! Geometry: rays with differentials, shading frames, triangle meshes, spheres and the surface
//! interaction at a ray hit. Conventions (DESIGN.md section 3): right-handed world, y up;
//! texture coordinates with the origin at the bottom-left, v up.

mod frame;
mod interaction;
mod mesh;
pub mod obj;
pub mod ply;
mod quad_mesh;
mod ray;
pub mod serialized;
pub mod shapes;
mod sphere;
mod subdivision;
mod topology;

pub use frame::{Frame, FrameOf};
pub use interaction::{
    DEFAULT_UVS, SHADOW_RAY_T_MAX, SurfaceInteraction, SurfacePoint, TriangleSurface, TriangleVertices,
    shadow_ray_to_of, triangle_surface_of,
};
pub use mesh::{Bounds, TriangleMesh};
pub use quad_mesh::{QuadMesh, QuadMeshReport, load_quad_obj};
pub use ray::{Ray, RayDifferential};
pub use sphere::{Sphere, SphereSample};
pub use subdivision::catmull_clark;
pub use topology::Topology;

use crate::simd::{Real, V3};
use glam::Vec3;

/// Offset a point along the geometric normal `ng`, to the side of direction `w`, far enough
/// that a ray leaving it does not hit its own surface again.
///
/// The distance scales with the point's magnitude, as Mitsuba 3's `offset_p` does: float
/// positions carry a relative error of a few ulps, so a fixed epsilon fails far from the origin.
#[inline]
pub fn offset_ray_origin(p: Vec3, ng: Vec3, w: Vec3) -> Vec3 {
    offset_ray_origin_of(p.into(), ng.into(), w.into()).into()
}

/// [`offset_ray_origin`] in one lane or eight.
#[inline(always)]
pub fn offset_ray_origin_of<T: Real>(p: V3<T>, ng: V3<T>, w: V3<T>) -> V3<T> {
    /// Relative offset: 2^-24 (half an ulp of 1) times 1500, Mitsuba 3's `RayEpsilon`.
    const RAY_EPSILON: f32 = 1500.0 / 16_777_216.0;
    // glam's max_element: max(max(x, y), z), each max keeping its second operand unless the
    // first is larger.
    let larger = |a: T, b: T| T::select(b.lt(a), a, b);
    let largest = larger(larger(p.x.abs(), p.y.abs()), p.z.abs());
    let magnitude = (T::splat(1.0) + largest) * T::splat(RAY_EPSILON);
    let side = T::select(T::splat(0.0).le(ng.dot(w)), magnitude, -magnitude);
    p + ng * side
}
