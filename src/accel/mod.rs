//! Ray-scene intersection: closest hit and occlusion over all triangles and spheres of a scene.
//!
//! obvhs builds a binary BVH (PLOC with reinsertion, SAH-sized leaves), which `bvh4.rs` collapses
//! into a four-wide BVH with four-triangle leaf packets for SIMD traversal on the CPU; it
//! measured faster than obvhs's own CWBVH and BVH2 traversals for the incoherent rays of path
//! tracing (DESIGN.md section 2). Triangles are tested with the watertight algorithm of Woop,
//! Benthin and Wald (2013), so that no ray slips between two triangles that share an edge.
//! With the feature `embree`, Embree 3 is available too, and is the default backend. Exact
//! spheres are intersected by tessera whatever the backend (`spheres.rs`).

mod bvh4;
#[cfg(feature = "embree")]
mod embree;
mod leaf_plane;
mod spheres;
mod watertight;

use crate::geometry::{Ray, Sphere};
use crate::simd::{Isa, LaneKernel, Lanes8};
use bvh4::Bvh4;
use glam::Vec3;
use obvhs::{BvhBuildParams, triangle::Triangle};
use spheres::SphereSet;

/// A closest hit: the primitive, the ray parameter and, on a triangle, the barycentric
/// coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Index of the primitive: a triangle's in the slice the accelerator was built from, or the
    /// number of triangles plus a sphere's index in its slice.
    pub primitive: u32,
    /// Barycentric weight of the triangle's second vertex (0 on a sphere).
    pub b1: f32,
    /// Barycentric weight of the triangle's third vertex (0 on a sphere).
    pub b2: f32,
}

/// The ray-query implementations an [`Accel`] can be built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AccelKind {
    /// tessera's four-wide BVH over obvhs's build (`bvh4.rs`).
    Bvh4,
    /// Embree 3 (feature `embree`).
    #[cfg(feature = "embree")]
    Embree,
}

impl AccelKind {
    /// Every kind this build has.
    pub const ALL: &[AccelKind] = &[
        AccelKind::Bvh4,
        #[cfg(feature = "embree")]
        AccelKind::Embree,
    ];
    /// The kind [`Accel::build`] uses: Embree where compiled in.
    pub const DEFAULT: AccelKind = *Self::ALL.last().expect("one kind at least");
}

enum Backend {
    /// No triangles.
    Empty,
    Bvh4(Bvh4),
    #[cfg(feature = "embree")]
    Embree(embree::EmbreeScene),
}

/// Bounding volume hierarchies over a fixed set of triangles and spheres.
pub struct Accel {
    backend: Backend,
    triangle_count: usize,
    spheres: Option<SphereSet>,
}

impl Accel {
    /// Build the default kind over `triangles` (`emitting` as for [`Accel::build_kind`]) and
    /// `spheres`. Triangles of zero area are allowed: they are never hit.
    pub fn build(triangles: &[[Vec3; 3]], emitting: &[bool], spheres: &[Sphere]) -> Self {
        Self::build_kind(triangles, emitting, spheres, AccelKind::DEFAULT)
    }

    /// Build `kind` over `triangles` (the spheres have their own BVH, the same for every kind).
    /// `emitting` tells which triangles emit (one per triangle, or empty where none do): the
    /// four-wide BVH lets shadow rays that clear a flat emitting leaf's plane skip its triangles
    /// (`leaf_plane.rs`), with the same answers. Where Embree fails to build (an unsupported
    /// CPU), this says so and builds the four-wide BVH instead.
    pub fn build_kind(triangles: &[[Vec3; 3]], emitting: &[bool], spheres: &[Sphere], kind: AccelKind) -> Self {
        assert!(emitting.is_empty() || emitting.len() == triangles.len(), "one emitting flag per triangle");
        let backend = if triangles.is_empty() {
            Backend::Empty
        } else {
            match kind {
                AccelKind::Bvh4 => Backend::Bvh4(build_bvh4(triangles, emitting)),
                #[cfg(feature = "embree")]
                AccelKind::Embree => match embree::EmbreeScene::build(triangles) {
                    Ok(scene) => Backend::Embree(scene),
                    Err(e) => {
                        eprintln!("warning: {e}; using tessera's own BVH");
                        Backend::Bvh4(build_bvh4(triangles, emitting))
                    }
                },
            }
        };
        Accel { backend, triangle_count: triangles.len(), spheres: SphereSet::build(spheres) }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// Number of spheres.
    pub fn sphere_count(&self) -> usize {
        self.spheres.as_ref().map_or(0, SphereSet::len)
    }

    /// Approximate memory held, in bytes (Embree's own is not counted).
    pub fn memory_bytes(&self) -> usize {
        match &self.backend {
            Backend::Bvh4(bvh) => bvh.memory_bytes(),
            _ => 0,
        }
    }

    /// Run `f` with ray queries that share this thread's traversal stack: a batch of queries
    /// (a stage of the wavefront) takes it once, rather than once per ray.
    #[inline]
    pub fn queries<R>(&self, f: impl FnOnce(&mut Queries<'_>) -> R) -> R {
        TRAVERSAL_STACK.with(|cell| match cell.try_borrow_mut() {
            Ok(mut stack) => f(&mut Queries { accel: self, stack: &mut stack }),
            // Queries started inside `f` (none of tessera's do) get a stack of their own.
            Err(_) => f(&mut Queries { accel: self, stack: &mut Default::default() }),
        })
    }

    /// The closest hit with `0 < t < ray.t_max`, if any.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.queries(|q| q.intersect(ray))
    }

    /// The closest hit of each of `rays` into `hits` (of the same length), as [`Accel::intersect`]
    /// gives it but for ties in distance. Rays of nearly one direction (a pixel's camera rays)
    /// are traced together as a packet, for less than each alone.
    pub fn intersect_many(&self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        self.queries(|q| q.intersect_many(rays, hits))
    }

    /// True when any triangle or sphere lies on the ray with `0 < t < ray.t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.queries(|q| q.occluded(ray))
    }

    /// `hit` (a triangle's, or none), or the closest sphere before it.
    #[inline(always)]
    fn closer_sphere(&self, ray: &Ray, hit: Option<Hit>) -> Option<Hit> {
        match &self.spheres {
            None => hit,
            Some(spheres) => self.closer_sphere_of(spheres, ray, hit),
        }
    }

    /// [`Accel::closer_sphere`] where the scene has spheres (kept out of line: most scenes have
    /// none, and every query asks).
    #[inline(never)]
    fn closer_sphere_of(&self, spheres: &SphereSet, ray: &Ray, hit: Option<Hit>) -> Option<Hit> {
        let before = Ray { t_max: hit.map_or(ray.t_max, |h| h.t), ..*ray };
        match spheres.intersect(&before) {
            Some((t, i)) => Some(Hit { t, primitive: self.triangle_count as u32 + i, b1: 0.0, b2: 0.0 }),
            None => hit,
        }
    }
}

/// Ray queries into an [`Accel`] that share the traversal stack of a thread ([`Accel::queries`]).
pub struct Queries<'a> {
    accel: &'a Accel,
    stack: &'a mut TraversalStack,
}

impl Queries<'_> {
    /// The closest hit with `0 < t < ray.t_max`, if any.
    #[inline(always)]
    pub fn intersect(&mut self, ray: &Ray) -> Option<Hit> {
        let accel = self.accel;
        let triangle = match &accel.backend {
            Backend::Empty => None,
            Backend::Bvh4(bvh) => bvh.intersect(ray, self.stack),
            #[cfg(feature = "embree")]
            Backend::Embree(scene) => scene.intersect(ray),
        };
        accel.closer_sphere(ray, triangle)
    }

    /// [`Accel::intersect_many`]. Batches of queries (this, [`Queries::intersect_each`],
    /// [`Queries::occluded_each`]) run with the lanes' instruction set ([`Isa::selected`],
    /// [`Isa::run_lanes`]): under AVX2, eight rays' box and triangle tests in 256-bit lanes, and
    /// the single-ray traversal's SSE operations in VEX form. The operations are the same
    /// either way (LLVM contracts no multiply-add), so are the answers.
    pub fn intersect_many(&mut self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit per ray");
        Isa::selected().run_lanes(CoherentBatch { queries: self, rays, hits })
    }

    /// The closest hit of each of `rays` into `hits` (of the same length), as
    /// [`Queries::intersect`] gives it (but for which of two triangles at exactly the same
    /// distance it reports); both backends trace them eight at a time, as packets, the four-wide
    /// BVH after sorting them by direction.
    pub fn intersect_each(&mut self, rays: &[Ray], hits: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), hits.len(), "one hit per ray");
        let accel = self.accel;
        match &accel.backend {
            Backend::Empty => hits.fill(None),
            Backend::Bvh4(bvh) => Isa::selected().run_lanes(bvh4::Batch::<bvh4::Closest> { bvh, rays, answers: hits }),
            #[cfg(feature = "embree")]
            Backend::Embree(scene) => {
                for (rays, hits) in rays.chunks(embree::PACKET).zip(hits.chunks_mut(embree::PACKET)) {
                    scene.intersect8(rays, hits);
                }
            }
        }
        if accel.spheres.is_some() {
            rays.iter().zip(hits.iter_mut()).for_each(|(r, h)| *h = accel.closer_sphere(r, *h));
        }
    }

    /// Whether each of `rays` is blocked ([`Queries::occluded`]), into `blocked` (of the same
    /// length); both backends test them eight at a time, as packets, the four-wide BVH after
    /// sorting them by direction.
    pub fn occluded_each(&mut self, rays: &[Ray], blocked: &mut [bool]) {
        assert_eq!(rays.len(), blocked.len(), "one answer per ray");
        let accel = self.accel;
        match &accel.backend {
            Backend::Empty => blocked.fill(false),
            Backend::Bvh4(bvh) => {
                Isa::selected().run_lanes(bvh4::Batch::<bvh4::Occluded> { bvh, rays, answers: blocked })
            }
            #[cfg(feature = "embree")]
            Backend::Embree(scene) => {
                for (rays, blocked) in rays.chunks(embree::PACKET).zip(blocked.chunks_mut(embree::PACKET)) {
                    scene.occluded8(rays, blocked);
                }
            }
        }
        if let Some(spheres) = &accel.spheres {
            rays.iter().zip(blocked.iter_mut()).for_each(|(r, b)| *b = *b || spheres.occluded(r));
        }
    }

    /// True when any triangle or sphere lies on the ray with `0 < t < ray.t_max`.
    #[inline(always)]
    pub fn occluded(&mut self, ray: &Ray) -> bool {
        let accel = self.accel;
        let triangle = match &accel.backend {
            Backend::Empty => false,
            Backend::Bvh4(bvh) => bvh.occluded(ray, self.stack),
            #[cfg(feature = "embree")]
            Backend::Embree(scene) => scene.occluded(ray),
        };
        triangle || accel.spheres.as_ref().is_some_and(|s| s.occluded(ray))
    }
}

/// [`Queries::intersect_many`], compiled for the lanes' instruction set.
struct CoherentBatch<'q, 'a, 'b> {
    queries: &'q mut Queries<'a>,
    rays: &'b [Ray],
    hits: &'b mut [Option<Hit>],
}

impl LaneKernel for CoherentBatch<'_, '_, '_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lanes8>(self, l: L) {
        let CoherentBatch { queries, rays, hits } = self;
        let accel = queries.accel;
        for (rays, hits) in rays.chunks(32).zip(hits.chunks_mut(32)) {
            match &accel.backend {
                Backend::Bvh4(bvh) => {
                    bvh.intersect_many(l, rays, hits, queries.stack);
                    for (r, h) in rays.iter().zip(hits) {
                        *h = accel.closer_sphere(r, *h);
                    }
                }
                _ => {
                    for (r, h) in rays.iter().zip(hits) {
                        *h = queries.intersect(r);
                    }
                }
            }
        }
    }
}

/// A traversal stack of (child, entry distance) pairs ([`bvh4`]).
type TraversalStack = Vec<(u32, f32)>;

thread_local! {
    /// Each thread's traversal stack, reused by every batch of queries so that none allocates
    /// one.
    static TRAVERSAL_STACK: std::cell::RefCell<TraversalStack> = const { std::cell::RefCell::new(Vec::new()) };
}

/// obvhs's binary BVH (leaves of up to four triangles: one packet), collapsed four-wide; the
/// flat leaves of `emitting` triangles keep their planes.
fn build_bvh4(triangles: &[[Vec3; 3]], emitting: &[bool]) -> Bvh4 {
    let prims: Vec<Triangle> =
        triangles.iter().map(|t| Triangle { v0: t[0].into(), v1: t[1].into(), v2: t[2].into() }).collect();
    let params = BvhBuildParams { max_prims_per_leaf: 4, pre_split: false, ..BvhBuildParams::slow_build() };
    let bvh2 = obvhs::bvh2::builder::build_bvh2_from_tris(&prims, params, &mut std::time::Duration::default());
    Bvh4::from_bvh2(&bvh2, triangles, emitting)
}

#[cfg(test)]
mod tests {
    use super::*;
    use watertight::{RayShear, TrianglePacket};

    /// Small deterministic generator for test geometry.
    pub(super) struct Lcg(pub(super) u64);
    impl Lcg {
        pub(super) fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn vec(&mut self, scale: f32) -> Vec3 {
            Vec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5) * scale
        }
    }

    fn brute_force(tris: &[[Vec3; 3]], ray: &Ray) -> Option<(f32, u32)> {
        let shear = RayShear::new(ray);
        let mut best: Option<(f32, u32)> = None;
        for (i, t) in tris.iter().enumerate() {
            let t_max = best.map_or(ray.t_max, |b| b.0);
            if let Some(hit) = shear.intersect(&TrianglePacket::new(&[*t]), t_max) {
                best = Some((hit.t, i as u32));
            }
        }
        best
    }

    /// Triangles along a line at exponentially growing distances: a deep, lopsided tree (obvhs's
    /// binary BVH over it is 114 levels deep), whose traversal stack grows past 32 entries.
    pub(super) fn lopsided_scene() -> Vec<[Vec3; 3]> {
        (0..3000)
            .map(|i| {
                let x = 1.01f32.powi(i);
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0 + (i % 7) as f32)]
            })
            .collect()
    }

    fn random_scene(rng: &mut Lcg, n: usize) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|_| {
                let c = rng.vec(10.0);
                [c + rng.vec(1.0), c + rng.vec(1.0), c + rng.vec(1.0)]
            })
            .collect()
    }

    /// Every backend this build has, built over `tris`.
    fn each_kind(tris: &[[Vec3; 3]]) -> impl Iterator<Item = (AccelKind, Accel)> {
        AccelKind::ALL.iter().map(|&kind| (kind, Accel::build_kind(tris, &[], &[], kind)))
    }

    #[test]
    fn accel_closest_hit_matches_brute_force() {
        let mut rng = Lcg(7);
        let tris = random_scene(&mut rng, 2000);
        for (kind, accel) in each_kind(&tris) {
            let mut hits = 0;
            for _ in 0..5000 {
                let o = rng.vec(14.0);
                let d = rng.vec(2.0).normalize();
                let mut ray = Ray::new(o, d);
                if rng.next() < 0.3 {
                    ray.t_max = rng.next() * 10.0;
                }
                let expected = brute_force(&tris, &ray);
                let got = accel.intersect(&ray);
                assert_eq!(expected.map(|e| e.1), got.map(|g| g.primitive), "{kind:?}: ray {ray:?}");
                if let (Some(e), Some(g)) = (expected, got) {
                    if kind == AccelKind::Bvh4 {
                        assert_eq!(e.0, g.t); // the same triangle test
                    } else {
                        assert!((e.0 - g.t).abs() <= 1e-5 * e.0.max(1.0), "{kind:?}: t {} vs {}", g.t, e.0);
                    }
                    let [a, b, c] = tris[g.primitive as usize];
                    let p = a * (1.0 - g.b1 - g.b2) + b * g.b1 + c * g.b2;
                    assert!(p.distance(ray.at(g.t)) < 1e-4, "barycentrics disagree with t");
                    hits += 1;
                }
                assert_eq!(expected.is_some(), accel.occluded(&ray));
            }
            assert!(hits > 500, "the test scene should be hit often, got {hits}");
        }
    }

    #[test]
    fn accel_matches_brute_force_on_a_deep_lopsided_tree() {
        let tris = lopsided_scene();
        for (kind, accel) in each_kind(&tris) {
            let mut rng = Lcg(11);
            for i in 0..2000 {
                // From far along the line, towards a point on a random triangle, or anywhere.
                let o = Vec3::new(3e4 * rng.next(), 3.0 * rng.next() - 1.0, 3.0 * rng.next() - 1.0);
                let [a, b, c] = tris[(rng.next() * tris.len() as f32) as usize % tris.len()];
                let target = if i % 2 == 0 { (a + b + c) / 3.0 } else { rng.vec(2e4) };
                let ray = Ray::new(o, target - o);
                let expected = brute_force(&tris, &ray);
                assert_eq!(expected.map(|e| e.1), accel.intersect(&ray).map(|h| h.primitive), "{kind:?}: ray {ray:?}");
                assert_eq!(expected.is_some(), accel.occluded(&ray));
            }
        }
    }

    #[test]
    fn queries_started_inside_a_batch_get_their_own_stack() {
        // A query inside `Accel::queries` finds the thread's stack taken: it must still answer,
        // and answer alike.
        let mut rng = Lcg(23);
        let tris = random_scene(&mut rng, 500);
        let accel = Accel::build(&tris, &[], &[]);
        let rays: Vec<Ray> = (0..200).map(|_| Ray::new(rng.vec(4.0), rng.vec(1.0))).collect();
        accel.queries(|outer| {
            for ray in &rays {
                let inner = accel.intersect(ray);
                assert_eq!(inner, outer.intersect(ray), "ray {ray:?}");
                assert_eq!(accel.occluded(ray), outer.occluded(ray), "ray {ray:?}");
                assert_eq!(inner.is_some(), accel.occluded(ray), "ray {ray:?}");
            }
        });
    }

    #[test]
    fn emitting_leaves_answer_shadow_rays_as_other_leaves_do() {
        // Random triangles around quad lights of several sizes and tilts (each its own flat
        // leaf, or sharing one), some near the triangles: shadow rays towards points on the
        // lights, as the integrator spawns them, and segments that cross a light, graze it or
        // end on it, answer alike with the emitting flags and without, and as brute force does.
        let mut rng = Lcg(31);
        let mut tris = random_scene(&mut rng, 600);
        let mut quads = Vec::new();
        for (size, centre) in [(1.0, Vec3::new(2.0, 6.0, 1.0)), (0.05, Vec3::new(-3.0, 1.0, 2.0)), (20.0, Vec3::ZERO)] {
            let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, rng.next() * 6.0, rng.next() * 6.0, 0.0);
            let corner = move |x: f32, y: f32| centre + rotation * Vec3::new(x - 0.5, y - 0.5, 0.0) * size;
            let first = tris.len();
            tris.push([corner(0.0, 0.0), corner(1.0, 0.0), corner(1.0, 1.0)]);
            tris.push([corner(0.0, 0.0), corner(1.0, 1.0), corner(0.0, 1.0)]);
            quads.push((first, rotation * Vec3::Z, corner));
        }
        let mut emitting = vec![false; tris.len()];
        for &(first, ..) in &quads {
            emitting[first..first + 2].fill(true);
        }
        let plain = Accel::build_kind(&tris, &[], &[], AccelKind::Bvh4);
        let with_emitters = Accel::build_kind(&tris, &emitting, &[], AccelKind::Bvh4);
        let mut blocked = [0; 2];
        for i in 0..20_000 {
            let (_, normal, corner) = quads[i % quads.len()];
            let q = corner(rng.next(), rng.next());
            let o = match i % 4 {
                0 => rng.vec(14.0),
                // Near the light's plane: grazing rays.
                1 => q + rng.vec(4.0) + normal * (rng.next() - 0.5) * 0.01,
                _ => q + rng.vec(2.0),
            };
            let ray = match i % 6 {
                // Through the light and beyond, or just reaching it.
                0 => Ray { o, d: q - o, t_max: 1.0 + (rng.next() - 0.5) * 1e-3 },
                1 => Ray::new(o, q - o),
                4 => Ray { o, d: q - o, t_max: 1.5 },
                _ => {
                    let end = crate::geometry::offset_ray_origin(q, normal, o - q);
                    Ray { o, d: end - o, t_max: crate::geometry::SHADOW_RAY_T_MAX }
                }
            };
            let expected = brute_force(&tris, &ray).is_some();
            assert_eq!(plain.occluded(&ray), expected, "ray {ray:?}");
            assert_eq!(with_emitters.occluded(&ray), expected, "ray {ray:?}");
            blocked[expected as usize] += 1;
        }
        assert!(blocked.iter().all(|&n| n > 2000), "both answers should be common: {blocked:?}");
    }

    /// Check every batched query of `rays` (the camera rays' `intersect_many`, the wavefront's
    /// `intersect_each` and `occluded_each`, each writing over stale answers) against the
    /// single-ray query; how many rays hit something.
    fn assert_batches_match_single_rays(accel: &Accel, rays: &[Ray], what: &str) -> u32 {
        let stale = Some(Hit { t: 1.0, primitive: 0, b1: 0.0, b2: 0.0 });
        let (mut many, mut each, mut blocked) =
            (vec![stale; rays.len()], vec![stale; rays.len()], vec![true; rays.len()]);
        accel.intersect_many(rays, &mut many);
        accel.queries(|q| {
            q.intersect_each(rays, &mut each);
            q.occluded_each(rays, &mut blocked);
        });
        let mut hits = 0;
        for (i, ray) in rays.iter().enumerate() {
            let single = accel.intersect(ray);
            assert_eq!(many[i], single, "{what}: ray {i}: {ray:?}");
            assert_eq!(each[i], single, "{what}: ray {i} (each): {ray:?}");
            assert_eq!(blocked[i], accel.occluded(ray), "{what}: ray {i} (occluded)");
            hits += single.is_some() as u32;
        }
        hits
    }

    #[test]
    fn batched_queries_match_single_ray_queries() {
        // Batches of up to 32 rays: bundles around a few directions (traced as packets, some
        // from spread origins, some with t_max cut short), and stray rays among them.
        let mut rng = Lcg(19);
        let tris = random_scene(&mut rng, 2000);
        for (kind, accel) in each_kind(&tris) {
            let mut hits_seen = 0;
            for batch in 0..600 {
                let n = 1 + batch % 32;
                let bundles: Vec<(Vec3, Vec3)> = (0..1 + batch % 3).map(|_| (rng.vec(14.0), rng.vec(2.0))).collect();
                let spread = [0.0, 0.001, 0.02][batch % 3];
                let rays: Vec<Ray> = (0..n)
                    .map(|i| {
                        if rng.next() < 0.15 {
                            return Ray::new(rng.vec(14.0), rng.vec(2.0));
                        }
                        let (o, d) = bundles[i % bundles.len()];
                        let mut ray = Ray::new(o + rng.vec(spread), (d - o).normalize() + rng.vec(spread));
                        if rng.next() < 0.3 {
                            ray.t_max = rng.next() * 20.0;
                        }
                        ray
                    })
                    .collect();
                hits_seen += assert_batches_match_single_rays(&accel, &rays, &format!("{kind:?}, batch {batch}"));
            }
            assert!(hits_seen > 2000, "{kind:?}: only {hits_seen} hits");
        }
    }

    #[test]
    fn packets_of_rays_with_signed_zero_components_match_single_ray_queries() {
        // Rays alike but for one component, +0, -0 or tiny of either sign: packets are formed by
        // octant, and a packet's box tests take each axis's near plane from the sign of its
        // rays' reciprocals, which a -0 component makes negative.
        let mut rng = Lcg(29);
        let tris = random_scene(&mut rng, 400);
        let parts = [0.0, -0.0, 1e-7, -1e-7];
        for (kind, accel) in each_kind(&tris) {
            let mut hits_seen = 0;
            for batch in 0..300 {
                let (o, target) = (rng.vec(16.0), rng.vec(6.0));
                let axis = batch % 3;
                let rays: Vec<Ray> = (0..32)
                    .map(|i| {
                        let mut d = (target - o).normalize();
                        d[axis] = parts[(i + batch) % parts.len()];
                        Ray::new(o + rng.vec(0.01), d)
                    })
                    .collect();
                hits_seen += assert_batches_match_single_rays(&accel, &rays, &format!("{kind:?}, batch {batch}"));
            }
            assert!(hits_seen > 1000, "{kind:?}: only {hits_seen} hits");
        }
    }

    #[test]
    fn spheres_among_triangles_are_hit_as_brute_force_finds_them() {
        let mut rng = Lcg(23);
        let tris = random_scene(&mut rng, 500);
        let spheres: Vec<Sphere> = (0..60)
            .map(|_| {
                let to_world =
                    glam::Mat4::from_translation(rng.vec(16.0)) * glam::Mat4::from_scale(Vec3::splat(0.2 + rng.next()));
                Sphere::new(to_world, false).unwrap()
            })
            .collect();
        for kind in AccelKind::ALL {
            let accel = Accel::build_kind(&tris, &[], &spheres, *kind);
            assert_eq!(accel.sphere_count(), 60);
            let mut sphere_hits = 0;
            for _ in 0..4000 {
                let mut ray = Ray::new(rng.vec(16.0), rng.vec(2.0));
                if rng.next() < 0.3 {
                    ray.t_max = rng.next() * 10.0;
                }
                let triangle = brute_force(&tris, &ray);
                let sphere = spheres
                    .iter()
                    .enumerate()
                    .filter_map(|(i, s)| Some((s.intersect(&ray)?, i)))
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                let expected = match (triangle, sphere) {
                    (Some((tt, _)), Some((ts, i))) if ts < tt => Some(tris.len() as u32 + i as u32),
                    (None, Some((_, i))) => Some(tris.len() as u32 + i as u32),
                    (t, _) => t.map(|t| t.1),
                };
                let got = accel.intersect(&ray);
                assert_eq!(expected, got.map(|h| h.primitive), "{kind:?}: ray {ray:?}");
                assert_eq!(expected.is_some(), accel.occluded(&ray), "{kind:?}: ray {ray:?}");
                let mut many = [None];
                accel.intersect_many(&[ray], &mut many);
                assert_eq!(many[0], got, "{kind:?}: batched");
                sphere_hits += expected.is_some_and(|p| p >= tris.len() as u32) as u32;
            }
            assert!(sphere_hits > 300, "{kind:?}: only {sphere_hits} sphere hits");
        }
    }

    #[test]
    fn accel_empty_scene_hits_nothing() {
        let accel = Accel::build(&[], &[], &[]);
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        assert!(accel.intersect(&ray).is_none());
        assert!(!accel.occluded(&ray));
    }

    #[test]
    fn accel_zero_area_triangles_are_never_hit() {
        let p = Vec3::new(0.0, 0.0, -1.0);
        let tris = vec![
            [p, p, p],
            [p, p + Vec3::X, p + 2.0 * Vec3::X],
            [Vec3::new(-1.0, -1.0, -2.0), Vec3::new(1.0, -1.0, -2.0), Vec3::new(0.0, 1.0, -2.0)],
        ];
        for (kind, accel) in each_kind(&tris) {
            let hit = accel.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z)).expect("the real triangle");
            assert_eq!(hit.primitive, 2, "{kind:?}");
            assert!((hit.t - 2.0).abs() < 1e-6, "{kind:?}");
            // A ray along the collapsed triangles hits nothing and produces no NaN.
            assert!(accel.intersect(&Ray::new(p - Vec3::X, Vec3::X)).is_none(), "{kind:?}");
        }
    }

    #[test]
    fn accel_hits_with_negative_zero_direction_components() {
        // Zero direction components of either sign: the slab test must not make NaNs of them.
        let tri = [Vec3::new(-1.0, -1.0, -2.0), Vec3::new(1.0, -1.0, -2.0), Vec3::new(0.0, 1.0, -2.0)];
        for (kind, accel) in each_kind(&[tri]) {
            for d in [Vec3::new(-0.0, -0.0, -1.0), Vec3::new(-0.0, 0.0, -1.0), Vec3::new(0.0, -0.0, -1.0)] {
                let hit = accel.intersect(&Ray::new(Vec3::ZERO, d));
                let t = hit.map(|h| h.t).unwrap_or(f32::NAN);
                assert!((t - 2.0).abs() < 1e-6, "{kind:?}: direction {d:?}, t {t}");
                assert!(accel.occluded(&Ray::new(Vec3::ZERO, d)));
            }
        }
    }

    #[test]
    fn accel_is_watertight_on_shared_edges() {
        // A fan of triangles around the origin; rays aimed exactly at the shared edges and the
        // shared vertex must all hit.
        let n = 16;
        let tris: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let a0 = i as f32 / n as f32 * std::f32::consts::TAU;
                let a1 = (i + 1) as f32 / n as f32 * std::f32::consts::TAU;
                [Vec3::ZERO, Vec3::new(a0.cos(), a0.sin(), 0.0), Vec3::new(a1.cos(), a1.sin(), 0.0)]
            })
            .collect();
        for (kind, accel) in each_kind(&tris) {
            for i in 0..n {
                let a = i as f32 / n as f32 * std::f32::consts::TAU;
                for r in [0.0, 0.1, 0.37, 0.9] {
                    let target = Vec3::new(a.cos() * r, a.sin() * r, 0.0);
                    let o = Vec3::new(0.3, -0.2, 2.0);
                    assert!(accel.intersect(&Ray::new(o, target - o)).is_some(), "{kind:?} missed {target}");
                }
            }
        }
    }
}
