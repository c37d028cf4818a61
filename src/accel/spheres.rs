//! Ray queries against a scene's exact spheres: obvhs's binary BVH over their boxes, traversed
//! with obvhs's own loop and the closed-form test of [`Sphere::intersect`]. The same for every
//! triangle backend, so spheres are hit alike whichever one a build uses.

use crate::geometry::{Ray, Sphere};
use glam::Vec3A;
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::Bvh2, ray::RayHit};

/// The spheres of a scene with a BVH over them.
pub(super) struct SphereSet {
    /// The spheres in the BVH's leaf order.
    spheres: Vec<Sphere>,
    /// For each entry of `spheres`, its index in the slice the set was built from.
    ids: Vec<u32>,
    bvh: Bvh2,
}

impl SphereSet {
    /// The set over `spheres`; None when there are none.
    pub(super) fn build(spheres: &[Sphere]) -> Option<Self> {
        if spheres.is_empty() {
            return None;
        }
        let boxes: Vec<Aabb> = spheres
            .iter()
            .map(|s| {
                // Widened by a few ulps of the box, so that rounding in the slab test cannot
                // cut off a grazing hit that the sphere's own test finds.
                let b = s.bounds();
                let pad = Vec3A::splat(1e-6 * (b.max.abs().max(b.min.abs()).max_element()));
                Aabb { min: Vec3A::from(b.min) - pad, max: Vec3A::from(b.max) + pad }
            })
            .collect();
        let params = BvhBuildParams { max_prims_per_leaf: 2, ..BvhBuildParams::medium_build() };
        let bvh = obvhs::bvh2::builder::build_bvh2(&boxes, params, &mut std::time::Duration::default());
        let ids = bvh.primitive_indices.clone();
        let spheres = ids.iter().map(|&i| spheres[i as usize].clone()).collect();
        Some(SphereSet { spheres, ids, bvh })
    }

    fn obvhs_ray(ray: &Ray) -> obvhs::ray::Ray {
        obvhs::ray::Ray::new(ray.o.into(), ray.d.into(), 0.0, ray.t_max)
    }

    /// The closest sphere along `ray` before its `t_max`: the ray parameter and the sphere's
    /// index.
    #[inline]
    pub(super) fn intersect(&self, ray: &Ray) -> Option<(f32, u32)> {
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(Self::obvhs_ray(ray), &mut hit, |r, i| {
            self.spheres[i].intersect(&Ray { t_max: r.tmax, ..*ray }).unwrap_or(f32::INFINITY)
        });
        found.then(|| (hit.t, self.ids[hit.primitive_id as usize]))
    }

    /// Whether any sphere lies on `ray` before its `t_max`.
    #[inline]
    pub(super) fn occluded(&self, ray: &Ray) -> bool {
        !self
            .bvh
            .ray_traverse_miss(Self::obvhs_ray(ray), |_, i| self.spheres[i].intersect(ray).unwrap_or(f32::INFINITY))
    }

    /// Number of spheres.
    pub(super) fn len(&self) -> usize {
        self.spheres.len()
    }
}
