//! A four-wide BVH for CPU traversal, collapsed from obvhs's binary BVH.
//!
//! obvhs builds the hierarchy (PLOC with reinsertion, leaves of up to four triangles chosen by
//! the SAH); this module lays it out for a CPU's 4-wide SIMD, as Embree's BVH4 does (Wald et al.
//! 2008, "Getting Rid of Packets"; Dammertz et al. 2008, "Shallow Bounding Volume Hierarchies"):
//! each node holds its four children's boxes in structure-of-arrays form, so that one ray is
//! tested against all four at once, and each leaf holds packets of four triangles tested at once
//! (`watertight.rs`). Collapsing opens, while a node has fewer than four children, the child of
//! largest surface area; subtrees of at most four triangles become one packet, which is the
//! leaf: its index sits in the parent's child entry, so that a ray reaches the triangles with
//! no load between.
//!
//! Coherent rays (a pixel's camera rays) can be traced together: one traversal for the packet,
//! whose box test bounds all its rays by interval arithmetic, with the rays' own box and
//! triangle tests at the leaves, eight rays at a time in SIMD lanes (`intersect_many`).
//!
//! The wavefront's bounce and shadow rays are sorted by direction and traced eight at a time,
//! one per lane, through every node's boxes and every leaf's triangles (`packets.rs`); a ray
//! that alone enters a node or leaf goes on from there with its own traversal.
//!
//! Leaves whose triangles all emit and lie in one plane (a quad light) keep that plane, and shadow
//! rays that stay clear of it skip their triangle tests (`leaf_plane.rs`).
//!
//! The queries are written to inline, their leaf closures with them, into the batches of
//! `Queries` (`super::Queries::intersect_many`), which run compiled for the lanes' instruction
//! set: a closure or iterator left out of line would run without it.
//!
//! Box tests are conservative as in Ize 2013 ("Robust BVH Ray Traversal", JCGT 2(2)): the far
//! distance is enlarged by 2 gamma(3), so that rounding never culls a box the ray touches (a
//! single ray's through a reciprocal enlarged once per ray, as Ize does), and a ray that runs
//! in the plane of a box's face enters the box (`SlabRay`).

mod packets;

pub(super) use packets::{Batch, Closest, Occluded};

use super::leaf_plane::LeafPlane;
use super::watertight::{PacketHit, RayShear, TrianglePacket};
use super::{Hit, TraversalStack};
use crate::geometry::Ray;
use crate::simd::Lanes8;
use glam::{Vec3, Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

/// Children of a node that are leaves: `LEAF | leaf index`, with [`PLANE`] set where the leaf
/// keeps its plane. A leaf is one packet: its index is that of `Bvh4::packets` and of
/// `Bvh4::leaves`, so that a ray reaches its triangles without a load on the way.
const LEAF: u32 = 1 << 31;
/// Set in a leaf's child entry where the leaf keeps its plane ([`Leaf::plane`]): shadow rays
/// read the leaf's entry only then.
const PLANE: u32 = 1 << 30;
/// The leaf index in a leaf's child entry.
const LEAF_INDEX: u32 = PLANE - 1;
/// The root node's index.
const ROOT: u32 = 0;
/// 1 + 2 gamma(3) with gamma(n) = n eps / (1 - n eps), eps = 2^-24 (Ize 2013).
const ROBUST_FAR: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Four child boxes and the children.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
struct Node {
    /// `[min x, max x, min y, max y, min z, max z]`, lane i for child i; an unused slot has the
    /// empty box (min +inf, max -inf), which no ray enters.
    bounds: [Vec4; 6],
    /// A node index, or a leaf's entry ([`LEAF`]).
    children: [u32; 4],
}

/// What a leaf's packet of triangles does not hold: their bounding box (for the rays' own test
/// in [`Bvh4::intersect_coherent`], whose traversal bounds the packet, not the ray), and, where
/// they all emit and are flat, their plane (an index into `Bvh4::planes`), which shadow rays
/// towards them clear ([`LeafPlane`]).
#[derive(Clone, Copy, Debug)]
struct Leaf {
    plane: Option<u32>,
    /// `[min x, max x, min y, max y, min z, max z]`, as a node's boxes.
    bounds: [f32; 6],
}

/// Four triangles of a leaf, for its tests, and the index of each lane's triangle (short packets
/// repeat their first), kept together so that a hit reads its index beside the triangles.
#[derive(Clone, Copy, Debug)]
struct Packet {
    triangles: TrianglePacket,
    ids: [u32; 4],
}

impl Packet {
    /// How many triangles the packet holds (short packets repeat their first).
    #[inline(always)]
    fn len(&self) -> usize {
        let ids = self.ids;
        1 + (ids[1] != ids[0]) as usize + (ids[2] != ids[0]) as usize + (ids[3] != ids[0]) as usize
    }
}

/// The four-wide BVH; node 0 is the root. Leaf i is `packets[i]` and `leaves[i]`.
pub(super) struct Bvh4 {
    nodes: Vec<Node>,
    packets: Vec<Packet>,
    leaves: Vec<Leaf>,
    planes: Vec<LeafPlane>,
}

/// Per-ray constants of the box test ([`SlabRay`]).
struct RayBoxes {
    /// Per axis, 1 when the near plane is the max plane (a negative direction), else 0.
    near_is_max: [usize; 3],
    origin: [Vec4; 3],
    origin_far: [Vec4; 3],
    inv_d: [Vec4; 3],
    /// `inv_d` enlarged by [`ROBUST_FAR`], for the far planes (Ize 2013).
    inv_d_far: [Vec4; 3],
}

/// A test of the four child boxes of a node: bit i of the mask set when the ray (or some ray of
/// a packet) may meet child i's box within (0, t_max), and the entry distances (lower bounds,
/// for a packet).
trait BoxTest {
    fn test(&self, node: &Node, t_max: f32) -> (u32, Vec4);
}

/// A ray's constants for the slab tests of boxes: the reciprocal of its direction, whose zero
/// components are made tiny ones of the same sign, so that it stays finite and no 0 * inf makes
/// a NaN; its origin, from which the near planes are measured; and the origin from which the
/// far planes are. Along an axis where the direction is (made) tiny, the ray stays in the slab
/// it starts in, on its faces too; but a face through the origin would be at 0 * (1 / tiny) =
/// 0, a far bound that culls the box. On such an axis the far planes are measured from the
/// origin moved back (against the direction) by a millionth of its size and at least a
/// millionth, so that a face through the origin lies at least 1e24 ahead; elsewhere from the
/// origin itself.
#[derive(Clone, Copy)]
struct SlabRay {
    inv_d: Vec3A,
    o: Vec3A,
    o_far: Vec3A,
}

impl SlabRay {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let (d, o) = (Vec3A::from(ray.d), Vec3A::from(ray.o));
        let tiny = Vec3A::splat(1e-30);
        let along_face = d.abs().cmplt(tiny);
        let shift = (o.abs() + Vec3A::ONE) * 2f32.powi(-20);
        SlabRay {
            inv_d: Vec3A::select(along_face, tiny.copysign(d), d).recip(),
            o,
            o_far: Vec3A::select(along_face, o - shift.copysign(d), o),
        }
    }
}

/// Each component of `v` in all four lanes, per axis: the per-ray constants of a box test.
#[inline(always)]
fn splat_axes(v: Vec3A) -> [Vec4; 3] {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

/// Per axis, 1 when the near plane is the max plane (a negative direction), else 0.
#[inline(always)]
fn near_is_max(inv_d: Vec3A) -> [usize; 3] {
    let negative = inv_d.cmplt(Vec3A::ZERO).bitmask() as usize;
    [negative & 1, (negative >> 1) & 1, negative >> 2]
}

impl RayBoxes {
    fn new(ray: &Ray) -> Self {
        let SlabRay { inv_d, o, o_far } = SlabRay::new(ray);
        RayBoxes {
            near_is_max: near_is_max(inv_d),
            origin: splat_axes(o),
            origin_far: splat_axes(o_far),
            inv_d: splat_axes(inv_d),
            inv_d_far: splat_axes(inv_d * ROBUST_FAR),
        }
    }
}

impl BoxTest for RayBoxes {
    #[inline(always)]
    fn test(&self, node: &Node, t_max: f32) -> (u32, Vec4) {
        // Distance to the near (far: `max_side` 1) plane along `axis`, as Ize computes it: the
        // difference, then the product, by the enlarged reciprocal for the far plane, so that
        // the enlargement bounds the rounding and costs nothing per node. `& 1` keeps the index
        // provably in bounds.
        let plane = |axis: usize, max_side: usize| node.bounds[2 * axis + (max_side & 1)];
        let [nx, ny, nz] = self.near_is_max;
        let near = |axis: usize, side: usize| (plane(axis, side) - self.origin[axis]) * self.inv_d[axis];
        let far = |axis: usize, side: usize| (plane(axis, side ^ 1) - self.origin_far[axis]) * self.inv_d_far[axis];
        let t_near = near(0, nx).max(near(1, ny)).max(near(2, nz).max(Vec4::ZERO));
        let t_far = far(0, nx).min(far(1, ny)).min(far(2, nz).min(Vec4::splat(t_max)));
        (t_near.cmple(t_far).bitmask(), t_near)
    }
}

/// The box test of a coherent packet of rays by interval arithmetic (Boulos et al. 2007,
/// "Packet-based Whitted and Distribution Ray Tracing"): with the origins in a box and the
/// reciprocal directions in per-axis intervals of one sign, a lower bound of every ray's entry
/// distance and an upper bound of its exit distance, at about the cost of one ray's test.
struct PacketBoxes {
    near_is_max: [usize; 3],
    inv_lo: [Vec4; 3],
    inv_hi: [Vec4; 3],
    /// Per axis, the end of the origins' interval that gives the smallest entry distance (the
    /// largest origin for a positive direction), and the one that gives the largest exit.
    o_near: [Vec4; 3],
    o_far: [Vec4; 3],
}

impl PacketBoxes {
    /// The bounds of `rays`, whose directions lie in one octant.
    fn new(rays: &[SlabRay]) -> Self {
        let (mut inv_lo, mut inv_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut o_lo, mut o_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let (mut o_far_lo, mut o_far_hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for r in rays {
            (inv_lo, inv_hi) = (inv_lo.min(r.inv_d), inv_hi.max(r.inv_d));
            (o_lo, o_hi) = (o_lo.min(r.o), o_hi.max(r.o));
            (o_far_lo, o_far_hi) = (o_far_lo.min(r.o_far), o_far_hi.max(r.o_far));
        }
        // One octant: a negative lower end means every reciprocal on that axis is negative.
        let negative = inv_lo.cmplt(Vec3A::ZERO);
        let (o_near, o_far) = (Vec3A::select(negative, o_lo, o_hi), Vec3A::select(negative, o_far_hi, o_far_lo));
        PacketBoxes {
            near_is_max: near_is_max(inv_lo),
            inv_lo: splat_axes(inv_lo),
            inv_hi: splat_axes(inv_hi),
            o_near: splat_axes(o_near),
            o_far: splat_axes(o_far),
        }
    }
}

impl BoxTest for PacketBoxes {
    #[inline(always)]
    fn test(&self, node: &Node, t_max: f32) -> (u32, Vec4) {
        // (plane - o) / d over the intervals: its smallest value for the near plane, its largest
        // for the far one. The reciprocals have one sign, so the extremes are at their ends.
        let near = |axis: usize, max_side: usize| {
            let a = node.bounds[2 * axis + (max_side & 1)] - self.o_near[axis];
            (a * self.inv_lo[axis]).min(a * self.inv_hi[axis])
        };
        let far = |axis: usize, max_side: usize| {
            let b = node.bounds[2 * axis + (max_side & 1)] - self.o_far[axis];
            (b * self.inv_lo[axis]).max(b * self.inv_hi[axis])
        };
        let [nx, ny, nz] = self.near_is_max;
        let t_near = near(0, nx).max(near(1, ny)).max(near(2, nz).max(Vec4::ZERO));
        let t_far = far(0, nx ^ 1).min(far(1, ny ^ 1)).min(far(2, nz ^ 1).min(Vec4::splat(t_max)));
        (t_near.cmple(t_far * ROBUST_FAR).bitmask(), t_near)
    }
}

/// Most rays traced as one packet.
const PACKET_SIZE: usize = 32;

/// Rays whose directions are at least this close (cosine of the angle to the group's first ray)
/// are traced as one packet. A pixel's camera rays are within a fraction of a degree; wider
/// packets (bounces, shadow rays) measured slower than their rays traced alone.
const COHERENT_COS: f32 = 0.999;

/// The octant of a ray's direction, by the sign bits of its components: a -0 counts as
/// negative, as it does for the reciprocal that box tests take (`SlabRay`), so that the rays of
/// one octant agree on each axis's near plane.
#[inline(always)]
fn octant(ray: &Ray) -> usize {
    ray.d.is_negative_bitmask() as usize
}

/// The rays of `rays` (at most 32), grouped into packets that [`PacketBoxes`] bounds tightly:
/// one octant, directions within `COHERENT_COS` of the group's first; each group a bit mask.
fn coherent_groups(rays: &[Ray]) -> impl Iterator<Item = u32> {
    debug_assert!(rays.len() <= PACKET_SIZE);
    let mut by_octant = [0u32; 8];
    for (i, r) in rays.iter().enumerate() {
        by_octant[octant(r)] |= 1 << i;
    }
    let mut octant = 0;
    std::iter::from_fn(
        #[inline(always)]
        move || {
            while by_octant[octant] == 0 {
                octant += 1;
                if octant == 8 {
                    return None;
                }
            }
            let remaining = by_octant[octant];
            let first = remaining.trailing_zeros() as usize;
            let d = rays[first].d;
            // d_i . d >= COHERENT_COS |d_i| |d|, squared (in one octant, d_i . d is not negative),
            // tested for every ray without a branch, then kept for those of the octant. (At most
            // PACKET_SIZE rays: a group never exceeds it.)
            let bound = COHERENT_COS * COHERENT_COS * d.length_squared();
            let mut near = 0u32;
            for (i, r) in rays.iter().enumerate() {
                let dot = r.d.dot(d);
                near |= u32::from(dot * dot >= bound * r.d.length_squared()) << i;
            }
            let group = (near & remaining) | (1 << first);
            by_octant[octant] &= !group;
            Some(group)
        },
    )
}

impl Bvh4 {
    /// Collapse `bvh2`, built over `triangles`, into a four-wide BVH; `emitting` tells which
    /// triangles emit (none where it is empty), whose flat leaves keep their planes.
    pub(super) fn from_bvh2(bvh2: &Bvh2, triangles: &[[Vec3; 3]], emitting: &[bool]) -> Self {
        let mut builder = Builder {
            bvh2,
            triangles,
            emitting,
            sizes: subtree_sizes(bvh2),
            out: Bvh4 { nodes: Vec::new(), leaves: Vec::new(), packets: Vec::new(), planes: Vec::new() },
        };
        // Depth first, without recursion: binary nodes still to emit, and where they go.
        let mut pending = Vec::new();
        builder.node(0, &mut pending);
        while let Some((n2, parent, lane)) = pending.pop() {
            let index = builder.node(n2, &mut pending);
            builder.out.nodes[parent as usize].children[lane] = index;
        }
        builder.out
    }

    /// Approximate memory held, in bytes.
    pub(super) fn memory_bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>()
            + self.leaves.len() * size_of::<Leaf>()
            + self.packets.len() * size_of::<Packet>()
            + self.planes.len() * size_of::<LeafPlane>()
    }

    /// The closest hit with `0 < t < ray.t_max`.
    #[inline(always)]
    pub(super) fn intersect(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<Hit> {
        self.intersect_below(ray, ROOT, ray.t_max, stack)
    }

    /// The closest hit with `0 < t < t_max` among the triangles under `start` (a node, or a
    /// leaf's entry).
    #[inline(always)]
    fn intersect_below(&self, ray: &Ray, start: u32, t_max: f32, stack: &mut TraversalStack) -> Option<Hit> {
        let shear = RayShear::new(ray);
        let mut closest: Option<Hit> = None;
        self.traverse::<true>(
            &RayBoxes::new(ray),
            Walk { current: start, t_max },
            stack,
            #[inline(always)]
            |leaf, t_max| {
                self.closest_in_leaf(&shear, leaf, t_max, &mut closest);
                false
            },
        );
        closest
    }

    /// Whether anything lies on the ray with `0 < t < ray.t_max`.
    #[inline(always)]
    pub(super) fn occluded(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        self.occluded_below(ray, ROOT, stack)
    }

    /// Whether a triangle under `start` (a node, or a leaf's entry) lies on the ray with
    /// `0 < t < ray.t_max`.
    #[inline(always)]
    fn occluded_below(&self, ray: &Ray, start: u32, stack: &mut TraversalStack) -> bool {
        let shear = RayShear::new(ray);
        let mut blocked = false;
        self.traverse::<false>(
            &RayBoxes::new(ray),
            Walk { current: start, t_max: ray.t_max },
            stack,
            #[inline(always)]
            |leaf, t_max| {
                blocked = self.blocks_in_leaf(ray, &shear, leaf, *t_max);
                blocked
            },
        );
        blocked
    }

    /// Shorten `t_max` and `closest` to the closest hit of the ray (`shear`) in the leaf of
    /// child entry `leaf` ([`LEAF`]).
    #[inline(always)]
    fn closest_in_leaf(&self, shear: &RayShear, leaf: u32, t_max: &mut f32, closest: &mut Option<Hit>) {
        let packet = &self.packets[(leaf & LEAF_INDEX) as usize];
        if let Some(PacketHit { lane, t, b1, b2 }) = shear.intersect(&packet.triangles, *t_max) {
            *closest = Some(Hit { primitive: packet.ids[lane], t, b1, b2 });
            *t_max = t;
        }
    }

    /// Whether a triangle of the leaf of child entry `leaf` ([`LEAF`]) lies on `ray` (`shear`)
    /// before `t_max`.
    #[inline(always)]
    fn blocks_in_leaf(&self, ray: &Ray, shear: &RayShear, leaf: u32, t_max: f32) -> bool {
        let index = (leaf & LEAF_INDEX) as usize;
        if leaf & PLANE != 0
            && let Some(plane) = self.leaves[index].plane
            && self.planes[plane as usize].clears(ray, t_max)
        {
            return false;
        }
        shear.occludes(&self.packets[index].triangles, t_max)
    }

    /// The closest hit of each ray of `rays` (at most 32), as [`Bvh4::intersect`] gives it but
    /// for ties in distance; coherent rays are traced as packets, their leaves' triangles
    /// tested against eight rays at a time in the lanes of `l`.
    #[inline(always)]
    pub(super) fn intersect_many<L: Lanes8>(
        &self,
        l: L,
        rays: &[Ray],
        hits: &mut [Option<Hit>],
        stack: &mut TraversalStack,
    ) {
        for group in coherent_groups(rays) {
            // Packets in arrays of their size: each slot's ray is set up, used or not.
            match group.count_ones() {
                1 => {
                    let i = group.trailing_zeros() as usize;
                    hits[i] = self.intersect(&rays[i], stack);
                }
                2..=8 => self.intersect_coherent::<L, 8, 1>(l, rays, group, hits, stack),
                9..=16 => self.intersect_coherent::<L, 16, 2>(l, rays, group, hits, stack),
                17..=24 => self.intersect_coherent::<L, 24, 3>(l, rays, group, hits, stack),
                _ => self.intersect_coherent::<L, 32, 4>(l, rays, group, hits, stack),
            }
        }
    }

    /// Visit the leaves under `walk`'s node whose boxes `boxes` lets through, calling `leaf(its
    /// entry, t_max)` ([`LEAF`]), which may shorten `t_max` to a hit and returns true to end the
    /// traversal. With `CLOSEST`, children are visited nearest first and boxes beyond `t_max`
    /// are skipped; without, in any order (a shadow ray needs any hit, not the nearest). `stack`
    /// holds the children still to visit.
    #[inline(always)]
    fn traverse<const CLOSEST: bool>(
        &self,
        boxes: &impl BoxTest,
        mut walk: Walk,
        stack: &mut TraversalStack,
        mut leaf: impl FnMut(u32, &mut f32) -> bool,
    ) {
        stack.clear();
        while self.step::<CLOSEST>(
            boxes,
            &mut walk,
            stack,
            #[inline(always)]
            |visited, t_max| leaf(visited, t_max),
        ) {}
    }

    /// One step of [`Bvh4::traverse`]: visit `walk`'s node or leaf and move it to the next one;
    /// false when the traversal has ended.
    #[inline(always)]
    fn step<const CLOSEST: bool>(
        &self,
        boxes: &impl BoxTest,
        walk: &mut Walk,
        stack: &mut TraversalStack,
        leaf: impl FnOnce(u32, &mut f32) -> bool,
    ) -> bool {
        let current = walk.current;
        if current & LEAF == 0 {
            let node = &self.nodes[current as usize];
            let (mut mask, t_near) = boxes.test(node, walk.t_max);
            if mask != 0 {
                let t_near = t_near.to_array();
                if mask & (mask - 1) == 0 {
                    walk.current = node.children[mask.trailing_zeros() as usize];
                    return true;
                }
                let mut rest = mask & (mask - 1);
                if !CLOSEST {
                    // Any order: visit the first, push the others.
                    walk.current = node.children[mask.trailing_zeros() as usize];
                    while rest != 0 {
                        let i = rest.trailing_zeros() as usize;
                        rest &= rest - 1;
                        stack.push((node.children[i], 0.0));
                    }
                    return true;
                }
                if rest & (rest - 1) == 0 {
                    // Two: visit the nearer, push the other (the order the sort below
                    // would give, ties included).
                    let (i, j) = (mask.trailing_zeros() as usize, rest.trailing_zeros() as usize);
                    let (near, far) = if t_near[i] < t_near[j] { (i, j) } else { (j, i) };
                    stack.push((node.children[far], t_near[far]));
                    walk.current = node.children[near];
                    return true;
                }
                // Three or four: push all but the nearest, farthest first.
                let mut hits = [(0u32, 0.0f32); 4];
                let mut n = 0;
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    hits[n] = (node.children[i], t_near[i]);
                    n += 1;
                }
                // Insertion sort, farthest first; stable, so that ties keep child order.
                for i in 1..n {
                    let mut j = i;
                    while j > 0 && hits[j - 1].1 < hits[j].1 {
                        hits.swap(j - 1, j);
                        j -= 1;
                    }
                }
                stack.extend_from_slice(&hits[..n - 1]);
                walk.current = hits[n - 1].0;
                return true;
            }
        } else if leaf(current, &mut walk.t_max) {
            return false;
        }
        // Next: the nearest entry on the stack that is not beyond the closest hit.
        loop {
            let Some((next, t_near)) = stack.pop() else {
                return false;
            };
            if !CLOSEST || t_near <= walk.t_max {
                walk.current = next;
                return true;
            }
        }
    }
}

/// Where a traversal stands ([`Bvh4::step`]): the node (or `LEAF | leaf`) to visit next, and the
/// distance beyond which nothing is looked for.
struct Walk {
    current: u32,
    t_max: f32,
}

/// Triangles under each node of a binary BVH.
fn subtree_sizes(bvh2: &Bvh2) -> Vec<u32> {
    // Depth-first order lists parents before children; sizes are summed in reverse.
    let mut order = Vec::with_capacity(bvh2.nodes.len());
    let mut pending = vec![0usize];
    while let Some(n) = pending.pop() {
        order.push(n);
        let node = &bvh2.nodes[n];
        if !node.is_leaf() {
            pending.extend([node.first_index as usize, node.first_index as usize + 1]);
        }
    }
    let mut sizes = vec![0u32; bvh2.nodes.len()];
    for &n in order.iter().rev() {
        let node = &bvh2.nodes[n];
        sizes[n] = if node.is_leaf() {
            node.prim_count
        } else {
            sizes[node.first_index as usize] + sizes[node.first_index as usize + 1]
        };
    }
    sizes
}

/// A node's `bounds` over the children's boxes `(min, max)` (at most four): plane 2 axis + 0 / 1
/// is the min / max along the axis; unused lanes get the empty box.
fn node_bounds(boxes: &[(Vec3A, Vec3A)]) -> [Vec4; 6] {
    std::array::from_fn(|plane| {
        Vec4::from_array(std::array::from_fn(|lane| match boxes.get(lane) {
            Some(&(lo, _)) if plane % 2 == 0 => lo[plane / 2],
            Some(&(_, hi)) => hi[plane / 2],
            None if plane % 2 == 0 => f32::INFINITY,
            None => f32::NEG_INFINITY,
        }))
    })
}

struct Builder<'a> {
    bvh2: &'a Bvh2,
    triangles: &'a [[Vec3; 3]],
    emitting: &'a [bool],
    sizes: Vec<u32>,
    out: Bvh4,
}

impl Builder<'_> {
    /// Emit the four-wide node standing for binary node `n2`, with its leaves; its index. The
    /// children that are nodes are left to the caller: `(binary node, this node, lane)` on
    /// `pending`.
    fn node(&mut self, n2: usize, pending: &mut Vec<(usize, u32, usize)>) -> u32 {
        let nodes = &self.bvh2.nodes;
        let opens = |n: usize, sizes: &[u32]| !nodes[n].is_leaf() && sizes[n] > 4;
        // Open the largest child that is worth opening until there are four.
        let mut children = if opens(n2, &self.sizes) {
            vec![nodes[n2].first_index as usize, nodes[n2].first_index as usize + 1]
        } else {
            vec![n2]
        };
        while children.len() < 4 {
            let largest = (0..children.len()).filter(|&i| opens(children[i], &self.sizes)).max_by(|&a, &b| {
                nodes[children[a]].aabb().half_area().total_cmp(&nodes[children[b]].aabb().half_area())
            });
            let Some(i) = largest else { break };
            let first = nodes[children[i]].first_index as usize;
            children[i] = first;
            children.insert(i + 1, first + 1);
        }

        let index = self.out.nodes.len();
        let boxes: Vec<_> = children.iter().map(|&c| (nodes[c].aabb().min, nodes[c].aabb().max)).collect();
        self.out.nodes.push(Node { bounds: node_bounds(&boxes), children: [LEAF; 4] });
        // Reversed, so that the first child is emitted next, beside its parent.
        for (lane, &c) in children.iter().enumerate().rev() {
            if opens(c, &self.sizes) {
                pending.push((c, index as u32, lane));
            } else {
                self.out.nodes[index].children[lane] = self.leaf(c);
            }
        }
        index as u32
    }

    /// Emit the triangles under binary node `n2` as leaves: one, where they are at most four
    /// (as subtrees that are not opened are); else nodes over leaves of four. Its child entry.
    fn leaf(&mut self, n2: usize) -> u32 {
        let nodes = &self.bvh2.nodes;
        let mut ids = Vec::new();
        let mut pending = vec![n2];
        while let Some(n) = pending.pop() {
            let node = &nodes[n];
            if node.is_leaf() {
                let range = node.first_index as usize..(node.first_index + node.prim_count) as usize;
                ids.extend_from_slice(&self.bvh2.primitive_indices[range]);
            } else {
                pending.extend([node.first_index as usize + 1, node.first_index as usize]);
            }
        }
        self.leaves_over(&ids).0
    }

    /// Leaves over the triangles `ids` (not empty): one packet where they are at most four,
    /// else a node over up to four groups of them, each a multiple of four but the last. Its
    /// child entry and the triangles' bounding box.
    fn leaves_over(&mut self, ids: &[u32]) -> (u32, Vec3A, Vec3A) {
        if ids.len() > 4 {
            let group = ids.len().div_ceil(4).next_multiple_of(4);
            let children: Vec<_> = ids.chunks(group).map(|chunk| self.leaves_over(chunk)).collect();
            let boxes: Vec<_> = children.iter().map(|&(_, lo, hi)| (lo, hi)).collect();
            let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
            for &(clo, chi) in &boxes {
                (lo, hi) = (lo.min(clo), hi.max(chi));
            }
            let entries = std::array::from_fn(|lane| children.get(lane).map_or(LEAF, |c| c.0));
            self.out.nodes.push(Node { bounds: node_bounds(&boxes), children: entries });
            return (self.out.nodes.len() as u32 - 1, lo, hi);
        }
        let tris: Vec<[Vec3; 3]> = ids.iter().map(|&i| self.triangles[i as usize]).collect();
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &v in tris.iter().flatten() {
            (lo, hi) = (lo.min(v.into()), hi.max(v.into()));
        }
        let out = &mut self.out;
        out.packets.push(Packet {
            triangles: TrianglePacket::new(&tris),
            ids: std::array::from_fn(|lane| *ids.get(lane).unwrap_or(&ids[0])),
        });
        // Only leaves whose triangles all emit keep their plane (`leaf_plane.rs` says why).
        let emits = !self.emitting.is_empty() && ids.iter().all(|&i| self.emitting[i as usize]);
        let plane = emits.then(|| LeafPlane::of(&tris)).flatten().map(|plane| {
            out.planes.push(plane);
            out.planes.len() as u32 - 1
        });
        out.leaves.push(Leaf { plane, bounds: [lo.x, hi.x, lo.y, hi.y, lo.z, hi.z] });
        let index = out.leaves.len() as u32 - 1;
        debug_assert!(index <= LEAF_INDEX, "more leaves than MAX_TRIANGLES allows");
        (LEAF | if plane.is_some() { PLANE } else { 0 } | index, lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unused_slots_are_entered_by_no_ray_and_the_used_one_by_rays_through_it() {
        // One triangle, whose box is the unit cube: the root holds its leaf in one slot and
        // three unused ones.
        let bvh = crate::accel::build_bvh4(&[[Vec3::ZERO, Vec3::new(1.0, 0.0, 0.5), Vec3::new(0.0, 1.0, 1.0)]], &[]);
        let root = &bvh.nodes[0];
        let used = root.bounds[0].cmplt(Vec4::INFINITY).bitmask();
        assert_eq!(used.count_ones(), 1);
        // Directions of every sign, zeros of both signs among them, from origins all round, with
        // no hit yet (t_max infinite, as camera and bounce rays start).
        let components = [-1.0, -0.3, -0.0, 0.0, 0.4, 1.0];
        for &x in &components {
            for &y in &components {
                for &z in &components {
                    let d = Vec3::new(x, y, z);
                    if d.length_squared() == 0.0 {
                        continue;
                    }
                    for o in [Vec3::splat(-5.0), Vec3::new(3.0, -2.0, 7.0), Vec3::splat(0.25), Vec3::splat(1e6)] {
                        let (mask, _) = RayBoxes::new(&Ray::new(o, d)).test(root, f32::INFINITY);
                        assert_eq!(mask & !used, 0, "an unused slot entered from {o} along {d}");
                        let packet = [SlabRay::new(&Ray::new(o, d)), SlabRay::new(&Ray::new(o + 0.01, d))];
                        let (mask, _) = PacketBoxes::new(&packet).test(root, f32::INFINITY);
                        assert_eq!(mask & !used, 0, "an unused slot entered by a packet from {o} along {d}");
                    }
                    // Aimed through a point inside the box, from outside it.
                    let inside = Vec3::new(0.3, 0.3, 0.4);
                    let (mask, _) = RayBoxes::new(&Ray::new(inside - d * 10.0, d)).test(root, f32::INFINITY);
                    assert_eq!(mask, used, "the box missed along {d}");
                }
            }
        }
    }

    #[test]
    fn rays_through_a_box_corner_enter_it_far_from_the_world_origin() {
        // A ray that only touches a box, at its corner, decides by its last bits whether it
        // enters: Ize's enlargement of the far distance must cover the rounding, also where
        // the box and the origin are far from the world's origin (an error relative to their
        // coordinates, not to the distance, would not be covered). Coordinates on a 1/64 grid
        // and integer directions make `corner - d` exact, so each ray passes exactly through
        // its corner; where a component is zero, the ray lies in the plane of two faces.
        let mut rng = crate::accel::tests::Lcg(11);
        let grid =
            |rng: &mut crate::accel::tests::Lcg, scale: f32| ((rng.next() * 2.0 - 1.0) * scale * 64.0).round() / 64.0;
        let mut tested = 0;
        while tested < 20_000 {
            let lo = Vec3::new(grid(&mut rng, 1e4), grid(&mut rng, 1e4), grid(&mut rng, 1e4));
            let size = Vec3::new(grid(&mut rng, 4.0), grid(&mut rng, 4.0), grid(&mut rng, 4.0));
            let hi = lo + size.abs().max(Vec3::splat(1.0 / 64.0));
            let mut d = Vec3::new(grid(&mut rng, 1.5e4), grid(&mut rng, 1.5e4), grid(&mut rng, 1.5e4)).round();
            // A quarter of the components zero, of either sign: the ray then lies in the plane
            // of the box's faces on that axis.
            for axis in 0..3 {
                if rng.next() < 0.25 {
                    d[axis] = if rng.next() < 0.5 { 0.0 } else { -0.0 };
                }
            }
            if d.length_squared() == 0.0 {
                continue;
            }
            let bvh = crate::accel::build_bvh4(&[[lo, Vec3::new(hi.x, lo.y, hi.z), Vec3::new(lo.x, hi.y, hi.z)]], &[]);
            let root = &bvh.nodes[0];
            let used = root.bounds[0].cmplt(Vec4::INFINITY).bitmask();
            let pick = (rng.next() * 8.0) as usize;
            let corner = Vec3::select(glam::BVec3::new(pick & 1 != 0, pick & 2 != 0, pick & 4 != 0), hi, lo);
            let o = corner - d;
            assert_eq!(o + d, corner, "the ray must pass exactly through the corner");
            let ray = Ray::new(o, d);
            let why = format!("the box [{lo}, {hi}] missed by the ray from {o} along {d} through {corner}");
            assert_eq!(RayBoxes::new(&ray).test(root, f32::INFINITY).0, used, "{why}");
            // A packet's node test, and its rays' leaf test.
            let packet = [SlabRay::new(&ray), SlabRay::new(&ray)];
            assert_eq!(PacketBoxes::new(&packet).test(root, f32::INFINITY).0, used, "packet: {why}");
            for isa in [crate::simd::Isa::Avx2, crate::simd::Isa::Portable] {
                assert!(packets::lanes_enter(isa, &ray, &bvh.leaves[0].bounds), "leaf, {isa:?}: {why}");
            }
            tested += 1;
        }
    }

    /// Walk `bvh`: every triangle of `tris` is reached exactly once, inside every box above it,
    /// and a leaf's plane bit says whether it keeps a plane.
    fn assert_every_triangle_once_inside_its_boxes(bvh: &Bvh4, tris: &[[Vec3; 3]]) {
        let mut seen = vec![0u32; tris.len()];
        let mut pending = vec![(0u32, Vec3::NEG_INFINITY, Vec3::INFINITY)];
        while let Some((child, lo, hi)) = pending.pop() {
            if child & LEAF != 0 {
                let index = (child & LEAF_INDEX) as usize;
                // Short packets repeat their first triangle.
                let mut lanes = bvh.packets[index].ids.to_vec();
                lanes.sort();
                lanes.dedup();
                for t in lanes {
                    seen[t as usize] += 1;
                    assert!(tris[t as usize].iter().all(|v| v.cmpge(lo).all() && v.cmple(hi).all()));
                }
                assert_eq!(child & PLANE != 0, bvh.leaves[index].plane.is_some(), "the plane bit of leaf {index}");
                continue;
            }
            let node = &bvh.nodes[child as usize];
            let b = node.bounds.map(|v| v.to_array());
            for (lane, &grandchild) in node.children.iter().enumerate() {
                let plane = |p: usize| b[p][lane];
                let (clo, chi) = (Vec3::new(plane(0), plane(2), plane(4)), Vec3::new(plane(1), plane(3), plane(5)));
                if clo.x > chi.x {
                    continue; // unused slot
                }
                assert!(clo.cmpge(lo).all() && chi.cmple(hi).all(), "a child's box leaves its parent's");
                pending.push((grandchild, clo, chi));
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "triangles seen other than once");
    }

    #[test]
    fn collapsed_bvh_keeps_every_triangle_once_inside_its_boxes() {
        let tris = crate::accel::tests::lopsided_scene();
        assert_every_triangle_once_inside_its_boxes(&crate::accel::build_bvh4(&tris, &[]), &tris);
    }

    #[test]
    fn a_binary_leaf_of_many_triangles_becomes_nodes_over_leaves_of_one_packet() {
        // obvhs keeps its leaves to four triangles; one of 37 (all the binary BVH holds) must
        // still give leaves of one packet each, under nodes, with the same answers.
        let tris: Vec<[Vec3; 3]> = crate::accel::tests::lopsided_scene().into_iter().take(37).collect();
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &v in tris.iter().flatten() {
            (lo, hi) = (lo.min(v.into()), hi.max(v.into()));
        }
        let bvh2 = Bvh2 {
            nodes: vec![obvhs::bvh2::node::Bvh2Node::new(obvhs::aabb::Aabb::new(lo, hi), 37, 0)],
            primitive_indices: (0..37).collect(),
            ..Default::default()
        };
        let bvh = Bvh4::from_bvh2(&bvh2, &tris, &[]);
        assert!(bvh.nodes.len() > 1, "the leaf was not split");
        assert_every_triangle_once_inside_its_boxes(&bvh, &tris);
        let mut stack = TraversalStack::default();
        for (i, t) in tris.iter().enumerate() {
            // Straight down onto the middle of triangle i (the lopsided scene's triangles stand
            // in planes x = const, so along -x from beyond them all).
            let target = (t[0] + t[1] + t[2]) / 3.0;
            let ray = Ray::new(Vec3::new(hi.x + 1.0, target.y, target.z), Vec3::NEG_X);
            let brute = tris.iter().enumerate().filter_map(|(j, tri)| {
                let shear = RayShear::new(&ray);
                shear.intersect(&TrianglePacket::new(&[*tri]), f32::INFINITY).map(|h| (h.t, j))
            });
            let nearest = brute.min_by(|a, b| a.0.total_cmp(&b.0)).map(|(_, j)| j as u32);
            assert_eq!(bvh.intersect(&ray, &mut stack).map(|h| h.primitive), nearest, "ray onto triangle {i}");
        }
    }
}
