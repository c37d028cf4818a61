//! Eight rays traced together through the four-wide BVH, one per lane (Wald et al. 2001,
//! "Interactive Rendering with Coherent Ray Tracing"; Embree's `rtcIntersect8`): each node's
//! boxes are tested against the eight rays at once, each triangle of a leaf against the eight
//! rays at once, so that rays sharing a path through the tree share its cost. Where one ray
//! alone enters a node or leaf, it goes on from there by itself, four boxes or triangles at a
//! time, as a single ray is traced (Embree's hybrid traversal).
//!
//! The lanes are [`Lanes8`]'s: AVX2 instructions where the CPU has them, a portable twin with the
//! same bits elsewhere. Each lane runs the operations of the single-ray tests in the same order
//! (the robust box test of [`super::RayBoxes`], the watertight test of
//! [`super::super::watertight::RayShear`]), so a ray's
//! answer is the single-ray query's, but for which of two triangles at exactly the same
//! distance it reports (the packet visits leaves in its own order).

use super::super::watertight::TrianglePacket;
use super::{
    Bvh4, LEAF, LEAF_INDEX, Node, PLANE, Packet, PacketBoxes, ROBUST_FAR, ROOT, SlabRay, TraversalStack, Walk, octant,
};
use crate::accel::Hit;
use crate::geometry::Ray;
use crate::simd::{Lanes8, set_bits};

/// Rays per packet: one per lane.
pub(in crate::accel) const PACKET: usize = 8;

/// A node (or `LEAF | leaf`) still to visit, the lanes that entered its box, and their entry
/// distances.
#[derive(Clone, Copy)]
pub(in crate::accel) struct Pending<F> {
    node: u32,
    lanes: u32,
    t_near: F,
}

/// The scratch of a packet's traversal: the entries still to visit, and the stack of a ray
/// that goes on alone ([`Bvh4::traverse_packet`]).
pub(in crate::accel) struct PacketStacks<F> {
    packet: Vec<Pending<F>>,
    alone: TraversalStack,
}

impl<F> PacketStacks<F> {
    /// Empty stacks, room for a deep tree's entries reserved.
    fn new() -> Self {
        PacketStacks { packet: Vec::with_capacity(64), alone: Vec::with_capacity(64) }
    }
}

/// Each ray's view of the vertices of triangle `j` of `triangles` (RayShear::lane_hits):
/// relative to its origin, permuted and sheared so that the ray runs along +z.
#[inline(always)]
fn sheared<L: Lanes8>(l: L, rays: &RayLanes<L>, triangles: &TrianglePacket, j: usize) -> [(L::F, L::F, L::F); 3] {
    let [kx, ky, kz] = rays.k;
    let mut out = [(rays.shear[0], rays.shear[0], rays.shear[0]); 3];
    for (vertex, out) in out.iter_mut().enumerate() {
        let mut rel = rays.o;
        for (axis, rel) in rel.iter_mut().enumerate() {
            *rel = l.sub(l.splat(triangles.coordinate(vertex, axis, j)), *rel);
        }
        *out = shear(l, rays, pick(l, kx, rel), pick(l, ky, rel), pick(l, kz, rel));
    }
    out
}

/// The shear of a permuted point (x, y, z) relative to the origin.
#[inline(always)]
fn shear<L: Lanes8>(l: L, rays: &RayLanes<L>, x: L::F, y: L::F, z: L::F) -> (L::F, L::F, L::F) {
    let [sx, sy, sz] = rays.shear;
    (l.sub(x, l.mul(sx, z)), l.sub(y, l.mul(sy, z)), l.mul(sz, z))
}

/// A component of each lane's vector `v`, chosen per lane by a one-hot choice of axis (`is[0]`:
/// lanes choosing x, `is[1]`: lanes choosing y, the others z).
#[inline(always)]
fn pick<L: Lanes8>(l: L, is: [L::M; 2], v: [L::F; 3]) -> L::F {
    l.select(is[0], v[0], l.select(is[1], v[1], v[2]))
}

/// `unswapped` where `swap` does not hold, else `swapped`.
#[inline(always)]
fn either<L: Lanes8>(l: L, swap: L::M, unswapped: L::M, swapped: L::M) -> L::M {
    l.or(l.and_not(unswapped, swap), l.and(swapped, swap))
}

/// The rays of a packet, one to eight, and the first again in the lanes beyond them. (The lanes
/// are read from where the rays lie, not from a copy: a copy's narrow stores would hold up the
/// wider loads that read them back.)
struct PacketRays<'a> {
    lanes: [&'a Ray; PACKET],
    count: usize,
}

impl<'a> PacketRays<'a> {
    /// The rays `rays[i]` for `i` in `indices` (one to eight of them).
    #[inline(always)]
    fn new(rays: &'a [Ray], indices: impl IntoIterator<Item = usize>) -> Self {
        let mut indices = indices.into_iter();
        let first = &rays[indices.next().expect("a packet has a ray")];
        let mut packet = PacketRays { lanes: [first; PACKET], count: 1 };
        for i in indices {
            packet.lanes[packet.count] = &rays[i];
            packet.count += 1;
        }
        packet
    }
}

/// Eight rays' constants, lane i for ray i: those of [`super::SlabRay`] and of `RayShear`,
/// computed in lanes by the same operations.
struct RayLanes<L: Lanes8> {
    /// Per axis: the origin, from which near planes are measured.
    o: [L::F; 3],
    /// Per axis: the origin from which far planes are measured.
    o_far: [L::F; 3],
    /// Per axis: the reciprocal direction.
    inv_d: [L::F; 3],
    /// Per axis: the reciprocal enlarged by [`ROBUST_FAR`], for the far planes.
    inv_d_far: [L::F; 3],
    /// Per axis, 1 where the rays' directions are negative (their near plane is the max
    /// plane), else 0: the rays of a packet lie in one octant.
    near_is_max: [usize; 3],
    /// Each lane's permutation, as one-hot choices of axis ([`pick`]).
    k: [[L::M; 2]; 3],
    /// (Sx, Sy, Sz) of the watertight test.
    shear: [L::F; 3],
}

impl<L: Lanes8> RayLanes<L> {
    /// The constants of `rays` (one to eight; missing lanes repeat the first ray).
    #[inline(always)]
    fn new(l: L, rays: &PacketRays) -> Self {
        let mut o = [[0.0; PACKET]; 3];
        let mut d = [[0.0; PACKET]; 3];
        for (i, ray) in rays.lanes.iter().enumerate() {
            for a in 0..3 {
                (o[a][i], d[a][i]) = (ray.o[a], ray.d[a]);
            }
        }
        let (o, d) = ([l.load(o[0]), l.load(o[1]), l.load(o[2])], [l.load(d[0]), l.load(d[1]), l.load(d[2])]);
        // The slab test's constants (SlabRay::new).
        let tiny = l.splat(1e-30);
        let (one, step) = (l.splat(1.0), l.splat(2f32.powi(-20)));
        let mut inv_d = d;
        let mut o_far = o;
        let mut near_is_max = [0; 3];
        for a in 0..3 {
            let along_face = l.lt(l.abs(d[a]), tiny);
            inv_d[a] = l.div(one, l.select(along_face, l.copysign(tiny, d[a]), d[a]));
            let shift = l.mul(l.add(l.abs(o[a]), one), step);
            o_far[a] = l.select(along_face, l.sub(o[a], l.copysign(shift, d[a])), o[a]);
            let negative = l.bits(l.lt(inv_d[a], l.splat(0.0)));
            debug_assert!(negative == 0 || negative == 0xff, "one octant: {negative:b}");
            near_is_max[a] = (negative & 1) as usize;
        }
        let robust = l.splat(ROBUST_FAR);
        let inv_d_far = [l.mul(inv_d[0], robust), l.mul(inv_d[1], robust), l.mul(inv_d[2], robust)];
        // The watertight test's constants (RayShear::new), in lanes: kz the largest component,
        // kx and ky the others in cyclic order, swapped where d[kz] is negative.
        let a = [l.abs(d[0]), l.abs(d[1]), l.abs(d[2])];
        let z_is_x = l.and(l.ge(a[0], a[1]), l.ge(a[0], a[2]));
        let z_is_y = l.and_not(l.ge(a[1], a[2]), z_is_x);
        let every = l.eq(one, one);
        let z_is_z = l.and_not(l.and_not(every, z_is_x), z_is_y);
        let d_kz = pick(l, [z_is_x, z_is_y], d);
        let swap = l.lt(d_kz, l.splat(0.0));
        // kz = x: (kx, ky) = (y, z); kz = y: (z, x); kz = z: (x, y).
        let kx = [either(l, swap, z_is_z, z_is_y), either(l, swap, z_is_x, z_is_z)];
        let ky = [either(l, swap, z_is_y, z_is_z), either(l, swap, z_is_z, z_is_x)];
        let sz = l.div(one, d_kz);
        let shear = [l.mul(pick(l, kx, d), sz), l.mul(pick(l, ky, d), sz), sz];
        let k = [kx, ky, [z_is_x, z_is_y]];
        RayLanes { o, o_far, inv_d, inv_d_far, near_is_max, k, shear }
    }

    /// The box test of [`super::RayBoxes`] against child `c` of `node`: the lanes that may meet
    /// its box within (0, `t_max`) as bits, and their entry distances.
    #[inline(always)]
    fn enter(&self, l: L, node: &Node, c: usize, t_max: L::F) -> (u32, L::F) {
        self.enter_box(
            l,
            #[inline(always)]
            |plane| node.bounds[plane].as_ref()[c],
            t_max,
        )
    }

    /// The box test of [`super::RayBoxes`] against the box whose planes are `plane(i)`, in the
    /// order of [`Node::bounds`]: the lanes that may meet it within (0, `t_max`) as bits, and
    /// their entry distances.
    #[inline(always)]
    fn enter_box(&self, l: L, plane: impl Fn(usize) -> f32, t_max: L::F) -> (u32, L::F) {
        let mut near = [t_max; 3];
        let mut far = [t_max; 3];
        for a in 0..3 {
            // `& 1` keeps the indices provably in bounds.
            let near_plane = l.splat(plane(2 * a + (self.near_is_max[a] & 1)));
            let far_plane = l.splat(plane(2 * a + (!self.near_is_max[a] & 1)));
            near[a] = l.mul(l.sub(near_plane, self.o[a]), self.inv_d[a]);
            far[a] = l.mul(l.sub(far_plane, self.o_far[a]), self.inv_d_far[a]);
        }
        let t_near = l.max(l.max(near[0], near[1]), l.max(near[2], l.splat(0.0)));
        let t_far = l.min(l.min(far[0], far[1]), l.min(far[2], t_max));
        (l.bits(l.le(t_near, t_far)), t_near)
    }
}

/// The watertight test of triangle `j` of a leaf's packet against the eight rays: per lane the
/// distance, the barycentrics scaled by the determinant, the determinant, and the lanes hit
/// within (0, `t_max`) among `lanes` as bits.
#[inline(always)]
fn triangle_lanes<L: Lanes8>(
    l: L,
    rays: &RayLanes<L>,
    triangles: &TrianglePacket,
    j: usize,
    t_max: L::F,
    lanes: u32,
) -> (u32, [L::F; 4]) {
    let zero = l.splat(0.0);
    let [(ax, ay, az), (bx, by, bz), (cx, cy, cz)] = sheared(l, rays, triangles, j);
    let mut u = l.sub(l.mul(cx, by), l.mul(cy, bx));
    let mut v = l.sub(l.mul(ax, cy), l.mul(ay, cx));
    let mut w = l.sub(l.mul(bx, ay), l.mul(by, ax));
    let on_edge = l.bits(l.or(l.or(l.eq(u, zero), l.eq(v, zero)), l.eq(w, zero))) & lanes;
    if on_edge != 0 {
        // On an edge, recompute in double precision so that neighbours agree (as alone).
        let [ax, ay, bx, by, cx, cy] = [ax, ay, bx, by, cx, cy].map(|x| l.store(x).map(f64::from));
        let (mut ua, mut va, mut wa) = (l.store(u), l.store(v), l.store(w));
        for i in set_bits(on_edge) {
            ua[i] = (cx[i] * by[i] - cy[i] * bx[i]) as f32;
            va[i] = (ax[i] * cy[i] - ay[i] * cx[i]) as f32;
            wa[i] = (bx[i] * ay[i] - by[i] * ax[i]) as f32;
        }
        (u, v, w) = (l.load(ua), l.load(va), l.load(wa));
    }
    let negative = l.or(l.or(l.lt(u, zero), l.lt(v, zero)), l.lt(w, zero));
    let positive = l.or(l.or(l.gt(u, zero), l.gt(v, zero)), l.gt(w, zero));
    let det = l.add(l.add(u, v), w);
    let t = l.div(l.add(l.add(l.mul(u, az), l.mul(v, bz)), l.mul(w, cz)), det);
    let valid = l.and(l.and(l.ne(det, zero), l.gt(t, zero)), l.lt(t, t_max));
    let hit = l.bits(valid) & !l.bits(l.and(negative, positive)) & lanes;
    (hit, [t, v, w, det])
}

/// Eight rays' closest hits so far, in lanes: distance (`t_max`, the ray's own where none),
/// triangle (its index's bits), scaled barycentrics and determinant, and which lanes have one.
struct ClosestLanes<L: Lanes8> {
    t_max: L::F,
    id: L::F,
    v: L::F,
    w: L::F,
    det: L::F,
    found: u32,
}

impl<L: Lanes8> ClosestLanes<L> {
    /// No hit yet for `rays` (one to eight); missing lanes end before they start.
    #[inline(always)]
    fn new(l: L, rays: &PacketRays) -> Self {
        let mut t_max = [f32::NEG_INFINITY; PACKET];
        for (t, r) in t_max.iter_mut().zip(&rays.lanes[..rays.count]) {
            *t = r.t_max;
        }
        let zero = l.splat(0.0);
        ClosestLanes { t_max: l.load(t_max), id: zero, v: zero, w: zero, det: zero, found: 0 }
    }

    /// Test the triangles of `packet` against the lanes of `rays` in `entered`, keeping each
    /// lane's closest (the first of equals, as alone).
    #[inline(always)]
    fn test(&mut self, l: L, rays: &RayLanes<L>, packet: &Packet, entered: u32) {
        for j in 0..packet.len() {
            let (hit, [t, v, w, det]) = triangle_lanes(l, rays, &packet.triangles, j, self.t_max, entered);
            if hit != 0 {
                let hit_lanes = l.mask(hit);
                self.t_max = l.select(hit_lanes, t, self.t_max);
                self.id = l.select(hit_lanes, l.splat(f32::from_bits(packet.ids[j])), self.id);
                self.v = l.select(hit_lanes, v, self.v);
                self.w = l.select(hit_lanes, w, self.w);
                self.det = l.select(hit_lanes, det, self.det);
                self.found |= hit;
            }
        }
    }

    /// Make `hit` lane `lane`'s closest (found by the ray alone: its barycentrics unscaled).
    #[inline(always)]
    fn set(&mut self, l: L, lane: usize, hit: Hit) {
        let only = l.mask(1 << lane);
        self.t_max = l.select(only, l.splat(hit.t), self.t_max);
        self.id = l.select(only, l.splat(f32::from_bits(hit.primitive)), self.id);
        self.v = l.select(only, l.splat(hit.b1), self.v);
        self.w = l.select(only, l.splat(hit.b2), self.w);
        self.det = l.select(only, l.splat(1.0), self.det);
        self.found |= 1 << lane;
    }

    /// The hits of the first `n` lanes, as `(lane, hit)`.
    #[inline(always)]
    fn hits(&self, l: L, n: usize) -> impl Iterator<Item = (usize, Option<Hit>)> {
        let (t, id) = (l.store(self.t_max), l.store(self.id));
        let (b1, b2) = (l.store(l.div(self.v, self.det)), l.store(l.div(self.w, self.det)));
        let found = self.found;
        (0..n).map(move |i| {
            (i, (found & (1 << i) != 0).then(|| Hit { primitive: id[i].to_bits(), t: t[i], b1: b1[i], b2: b2[i] }))
        })
    }
}

impl Bvh4 {
    /// The closest hit of each ray `rays[i]` for `i` in `indices` (one to eight) into `hits[i]`,
    /// as [`Bvh4::intersect`] gives it but for ties in distance; `stacks` is scratch.
    #[inline(always)]
    fn intersect_packet<L: Lanes8>(
        &self,
        l: L,
        rays: &[Ray],
        indices: &[u32],
        hits: &mut [Option<Hit>],
        stacks: &mut PacketStacks<L::F>,
    ) {
        let packet = PacketRays::new(rays, indices.iter().map(|&i| i as usize));
        let lanes = RayLanes::new(l, &packet);
        let mut closest = ClosestLanes::new(l, &packet);
        let mut t_max = closest.t_max;
        let PacketStacks { packet: stack, alone } = stacks;
        self.traverse_packet::<L, true>(
            l,
            &lanes,
            (1 << indices.len()) - 1,
            &mut t_max,
            stack,
            #[inline(always)]
            |entry, entered, t_max| {
                if goes_alone(entered) {
                    let lane = entered.trailing_zeros() as usize;
                    let ray_t_max = l.store(closest.t_max)[lane];
                    if let Some(hit) = self.intersect_below(packet.lanes[lane], entry, ray_t_max, alone) {
                        closest.set(l, lane, hit);
                    }
                } else {
                    closest.t_max = *t_max;
                    closest.test(l, &lanes, &self.packets[(entry & LEAF_INDEX) as usize], entered);
                }
                *t_max = closest.t_max;
                false
            },
        );
        for (i, hit) in closest.hits(l, indices.len()) {
            hits[indices[i] as usize] = hit;
        }
    }

    /// The closest hits of the rays of `group` (a bit mask into `rays`, at most `N = 8 G` set;
    /// directions in one octant), traversing once for all: a traversal bounding all the rays
    /// by interval arithmetic ([`PacketBoxes`]), and at each leaf, the box and triangle tests
    /// of the rays, eight at a time in lanes.
    #[inline(always)]
    pub(super) fn intersect_coherent<L: Lanes8, const N: usize, const G: usize>(
        &self,
        l: L,
        rays: &[Ray],
        group: u32,
        hits: &mut [Option<Hit>],
        stack: &mut TraversalStack,
    ) {
        let n = group.count_ones() as usize;
        debug_assert!(N == 8 * G && n > 8 * (G - 1) && n <= N);
        // Unused slots repeat the first ray.
        let mut index = [group.trailing_zeros() as usize; N];
        for (slot, i) in index.iter_mut().zip(set_bits(group)) {
            *slot = i;
        }
        let slabs: [SlabRay; N] = std::array::from_fn(
            #[inline(always)]
            |k| SlabRay::new(&rays[index[k]]),
        );
        // Eight rays a lane group, each with its closest hits so far.
        let mut lanes: [(RayLanes<L>, ClosestLanes<L>); G] = std::array::from_fn(
            #[inline(always)]
            |g| {
                let packet = PacketRays::new(rays, index[8 * g..(8 * g + 8).min(n)].iter().copied());
                (RayLanes::new(l, &packet), ClosestLanes::new(l, &packet))
            },
        );
        let packet_t_max = index[..n].iter().fold(0.0f32, |a, &i| a.max(rays[i].t_max));
        self.traverse::<true>(
            &PacketBoxes::new(&slabs[..n]),
            Walk { current: ROOT, t_max: packet_t_max },
            stack,
            #[inline(always)]
            |leaf, packet_t_max| {
                let index = (leaf & LEAF_INDEX) as usize;
                let bounds = &self.leaves[index].bounds;
                let mut farthest = l.splat(0.0);
                for (rays, closest) in lanes.iter_mut() {
                    let (entered, _) = rays.enter_box(
                        l,
                        #[inline(always)]
                        |plane| bounds[plane],
                        closest.t_max,
                    );
                    if entered != 0 {
                        closest.test(l, rays, &self.packets[index], entered);
                    }
                    farthest = l.max(farthest, closest.t_max);
                }
                *packet_t_max = l.store(farthest).iter().fold(0.0f32, |a, &b| a.max(b));
                false
            },
        );
        for (g, (_, closest)) in lanes.iter().enumerate() {
            for (i, hit) in closest.hits(l, (n - 8 * g).min(PACKET)) {
                hits[index[8 * g + i]] = hit;
            }
        }
    }

    /// Whether each ray `rays[i]` for `i` in `indices` (one to eight) is blocked, into
    /// `blocked[i]`, as [`Bvh4::occluded`] answers; `stacks` is scratch.
    #[inline(always)]
    fn occluded_packet<L: Lanes8>(
        &self,
        l: L,
        rays: &[Ray],
        indices: &[u32],
        blocked: &mut [bool],
        stacks: &mut PacketStacks<L::F>,
    ) {
        let n = indices.len();
        let packet = PacketRays::new(rays, indices.iter().map(|&i| i as usize));
        let lanes = RayLanes::new(l, &packet);
        let mut t_max = [f32::NEG_INFINITY; PACKET];
        for (t, r) in t_max.iter_mut().zip(&packet.lanes[..n]) {
            *t = r.t_max;
        }
        let ray_t_max = t_max;
        let mut t_max = l.load(t_max);
        let all = (1u32 << n) - 1;
        let mut found = 0u32;
        let PacketStacks { packet: stack, alone } = stacks;
        self.traverse_packet::<L, false>(
            l,
            &lanes,
            all,
            &mut t_max,
            stack,
            #[inline(always)]
            |entry, mut entered, t_max| {
                if goes_alone(entered) {
                    if self.occluded_below(packet.lanes[entered.trailing_zeros() as usize], entry, alone) {
                        found |= entered;
                        *t_max = l.select(l.mask(entered), l.splat(f32::NEG_INFINITY), *t_max);
                    }
                    return found == all;
                }
                let index = (entry & LEAF_INDEX) as usize;
                if entry & PLANE != 0
                    && let Some(plane) = self.leaves[index].plane
                {
                    for i in set_bits(entered) {
                        if self.planes[plane as usize].clears(packet.lanes[i], ray_t_max[i]) {
                            entered &= !(1 << i);
                        }
                    }
                }
                let packet = &self.packets[index];
                for j in 0..packet.len() {
                    if entered == 0 {
                        break;
                    }
                    let (hit, _) = triangle_lanes(l, &lanes, &packet.triangles, j, *t_max, entered);
                    if hit != 0 {
                        found |= hit;
                        entered &= !hit;
                        // A blocked ray enters no box from now on.
                        *t_max = l.select(l.mask(hit), l.splat(f32::NEG_INFINITY), *t_max);
                    }
                }
                found == all
            },
        );
        for (i, &index) in indices.iter().enumerate() {
            blocked[index as usize] = found & (1 << i) != 0;
        }
    }

    /// Visit the nodes and leaves that the rays of `lanes` (those of `live`) may meet, calling
    /// `visit(its entry, the lanes that entered it, t_max)` for each leaf that several lanes
    /// enter, and for each node or leaf that one lane enters alone ([`goes_alone`]), whose
    /// subtree that lane's ray traverses alone (`visit`'s part: in a packet, it would test every
    /// box and triangle in eight lanes for one ray's sake). `visit` may shorten `t_max`, and
    /// returns true to end the traversal. With `CLOSEST`, children are visited nearest first
    /// (for the lowest lane that enters any) and entries beyond every entering lane's `t_max`
    /// are skipped.
    #[inline(always)]
    fn traverse_packet<L: Lanes8, const CLOSEST: bool>(
        &self,
        l: L,
        lanes: &RayLanes<L>,
        live: u32,
        t_max: &mut L::F,
        stack: &mut Vec<Pending<L::F>>,
        mut visit: impl FnMut(u32, u32, &mut L::F) -> bool,
    ) {
        stack.clear();
        let (mut current, mut entered) = (ROOT, live);
        loop {
            if current & LEAF == 0 && !goes_alone(entered) {
                let node = &self.nodes[current as usize];
                let tests: [(u32, L::F); 4] = [
                    lanes.enter(l, node, 0, *t_max),
                    lanes.enter(l, node, 1, *t_max),
                    lanes.enter(l, node, 2, *t_max),
                    lanes.enter(l, node, 3, *t_max),
                ];
                let entered_children = (tests[0].0 != 0) as u32
                    | ((tests[1].0 != 0) as u32) << 1
                    | ((tests[2].0 != 0) as u32) << 2
                    | ((tests[3].0 != 0) as u32) << 3;
                if entered_children != 0 {
                    let first = entered_children.trailing_zeros() as usize;
                    if entered_children & (entered_children - 1) == 0 {
                        (current, entered) = (node.children[first], tests[first].0);
                        continue;
                    }
                    // Children by the entry distance of the lowest lane entering any, nearest
                    // last (those it does not enter first).
                    let leader = (tests[0].0 | tests[1].0 | tests[2].0 | tests[3].0).trailing_zeros() as usize;
                    let mut order = [(0usize, 0.0f32); 4];
                    let mut count = 0;
                    for c in set_bits(entered_children) {
                        let (bits, t_near) = tests[c];
                        let key =
                            if CLOSEST && bits & (1 << leader) != 0 { l.store(t_near)[leader] } else { f32::INFINITY };
                        order[count] = (c, key);
                        count += 1;
                    }
                    if CLOSEST {
                        for i in 1..count {
                            let mut j = i;
                            while j > 0 && order[j - 1].1 < order[j].1 {
                                order.swap(j - 1, j);
                                j -= 1;
                            }
                        }
                    }
                    for &(c, _) in &order[..count - 1] {
                        stack.push(Pending { node: node.children[c], lanes: tests[c].0, t_near: tests[c].1 });
                    }
                    let (c, _) = order[count - 1];
                    (current, entered) = (node.children[c], tests[c].0);
                    continue;
                }
            } else if visit(current, entered, t_max) {
                return;
            }
            // Next: the latest entry some lane still enters before its t_max.
            loop {
                let Some(next) = stack.pop() else {
                    return;
                };
                let live = next.lanes & l.bits(l.le(next.t_near, *t_max));
                if live != 0 {
                    (current, entered) = (next.node, live);
                    break;
                }
            }
        }
    }
}

/// Whether the one to eight lanes `entered` go on alone from where they are: one lane does
/// ([`Bvh4::traverse_packet`]).
#[inline(always)]
fn goes_alone(entered: u32) -> bool {
    entered & (entered - 1) == 0
}

/// A query traced eight rays at a time: its answer per ray, and the packet's traversal.
pub(in crate::accel) trait PacketQuery {
    /// A ray's answer.
    type Answer: Copy;
    /// Answer the rays `rays[i]` for `i` in `indices` (one to eight), into `answers[i]`.
    fn trace<L: Lanes8>(
        bvh: &Bvh4,
        l: L,
        rays: &[Ray],
        indices: &[u32],
        answers: &mut [Self::Answer],
        stacks: &mut PacketStacks<L::F>,
    );
}

/// Closest hits ([`Bvh4::intersect_packet`]).
pub(in crate::accel) struct Closest;

impl PacketQuery for Closest {
    type Answer = Option<Hit>;
    #[inline(always)]
    fn trace<L: Lanes8>(
        bvh: &Bvh4,
        l: L,
        rays: &[Ray],
        indices: &[u32],
        hits: &mut [Option<Hit>],
        stacks: &mut PacketStacks<L::F>,
    ) {
        bvh.intersect_packet(l, rays, indices, hits, stacks);
    }
}

/// Whether anything blocks each ray ([`Bvh4::occluded_packet`]).
pub(in crate::accel) struct Occluded;

impl PacketQuery for Occluded {
    type Answer = bool;
    #[inline(always)]
    fn trace<L: Lanes8>(
        bvh: &Bvh4,
        l: L,
        rays: &[Ray],
        indices: &[u32],
        blocked: &mut [bool],
        stacks: &mut PacketStacks<L::F>,
    ) {
        bvh.occluded_packet(l, rays, indices, blocked, stacks);
    }
}

/// The answers of query `Q` for a batch of rays, traced eight at a time in packets of rays
/// alike ([`by_direction`], [`packet_end`]).
pub(in crate::accel) struct Batch<'a, Q: PacketQuery> {
    pub bvh: &'a Bvh4,
    pub rays: &'a [Ray],
    pub answers: &'a mut [Q::Answer],
}

impl<Q: PacketQuery> crate::simd::LaneKernel for Batch<'_, Q> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lanes8>(self, l: L) {
        let mut stacks = PacketStacks::new();
        let Batch { bvh, rays, answers } = self;
        // Rays alike traced together: sorted by direction, then cut into packets.
        let order = by_direction(rays);
        let mut start = 0;
        while start < order.len() {
            let end = packet_end(rays, &order, start);
            Q::trace(bvh, l, rays, &order[start..end], answers, &mut stacks);
            start = end;
        }
    }
}

/// The end of the packet that starts at `order[start]`, in an order of `rays` by direction
/// ([`by_direction`]): up to eight rays of one octant.
#[inline(always)]
fn packet_end(rays: &[Ray], order: &[u32], start: usize) -> usize {
    let octant = octant(&rays[order[start] as usize]);
    let mut end = start + 1;
    while end < order.len() && end - start < PACKET && self::octant(&rays[order[end] as usize]) == octant {
        end += 1;
    }
    end
}

/// Bins per axis of [`by_direction`]'s key (a power of two).
const BINS: usize = 8;
/// How many keys [`direction_key`] gives: an octant's bins of x by bins of y, for each octant.
const KEYS: usize = 8 * BINS * BINS;

/// An order of `rays` in which rays of like directions are neighbours, so that packets of
/// consecutive rays share their way through the tree: a counting sort (stable, so that the
/// order is the same on every run) by octant, then by |d.x| and |d.y| relative to
/// |d.x| + |d.y| + |d.z|, in [`BINS`] bins each. The wavefront hands over each pixel's paths in
/// turn; bounce rays of diffuse surfaces point everywhere, and sorted by direction, more of a
/// packet's rays enter each node it visits (scene A: 3.1 of the eight, against 2.3 in the
/// wavefront's order).
fn by_direction(rays: &[Ray]) -> Vec<u32> {
    let keys: Vec<u16> = rays.iter().map(direction_key).collect();
    let mut first = [0u32; KEYS + 1];
    for &k in &keys {
        first[k as usize + 1] += 1;
    }
    for i in 1..first.len() {
        first[i] += first[i - 1];
    }
    let mut order = vec![0u32; rays.len()];
    for (i, &k) in keys.iter().enumerate() {
        order[first[k as usize] as usize] = i as u32;
        first[k as usize] += 1;
    }
    order
}

/// [`by_direction`]'s key of `ray`: its octant, then |d.x| and |d.y| relative to
/// |d.x| + |d.y| + |d.z| rounded to one of [`BINS`] bins each.
#[inline(always)]
fn direction_key(ray: &Ray) -> u16 {
    let a = ray.d.abs();
    let scale = (BINS - 1) as f32 / (a.x + a.y + a.z);
    let (x, y) = (bin(a.x * scale), bin(a.y * scale));
    ((octant(ray) * BINS + x) * BINS + y) as u16
}

/// The whole number nearest `x` for `x` in [0, [`BINS`] - 1/2), read from the low bits of the
/// mantissa of `x + 2^23` (which rounds to whole numbers): three instructions, where a
/// conversion to an integer takes a dozen to saturate. Any other `x` (a NaN or infinite
/// scale) gives some bin in range too.
#[inline(always)]
fn bin(x: f32) -> usize {
    ((x + 8_388_608.0).to_bits() as usize) & (BINS - 1)
}

/// Whether `ray` enters the box `bounds` ([`Node::bounds`]' order), by the lanes' box test of
/// leaves, with the operations of `isa`.
#[cfg(test)]
pub(super) fn lanes_enter(isa: crate::simd::Isa, ray: &Ray, bounds: &[f32; 6]) -> bool {
    struct Enter<'a>(&'a Ray, &'a [f32; 6]);
    impl crate::simd::LaneKernel for Enter<'_> {
        type Output = bool;
        fn run<L: Lanes8>(self, l: L) -> bool {
            let rays = RayLanes::new(l, &PacketRays::new(std::slice::from_ref(self.0), 0..1));
            rays.enter_box(l, |plane| self.1[plane], l.splat(self.0.t_max)).0 & 1 != 0
        }
    }
    isa.run_lanes(Enter(ray, bounds))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn bins_round_to_the_nearest_whole_number_and_stay_in_range_for_any_input() {
        for (x, expected) in [(0.0, 0), (0.49, 0), (0.51, 1), (3.0, 3), (6.49, 6), (6.51, 7), (7.0, 7)] {
            assert_eq!(bin(x), expected, "{x}");
        }
        for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -3.0, 1e30, -0.0] {
            assert!(bin(x) < BINS, "{x}");
        }
    }

    #[test]
    fn rays_sorted_by_direction_are_grouped_by_octant_and_kept_in_order_within_a_key() {
        // Directions of every octant, and degenerate ones (zero, NaN), in an order that
        // interleaves them.
        let mut rays = Vec::new();
        for i in 0..200 {
            let f = i as f32;
            let d = Vec3::new((f * 0.37).sin(), (f * 0.91).cos(), (f * 1.3).sin() - 0.2);
            rays.push(Ray::new(Vec3::ZERO, if i % 50 == 7 { Vec3::ZERO } else { d }));
        }
        rays.push(Ray { o: Vec3::ZERO, d: Vec3::NAN, t_max: f32::INFINITY });
        let order = by_direction(&rays);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert!(seen.iter().copied().eq(0..rays.len() as u32), "a permutation of the rays");
        let keys: Vec<u16> = order.iter().map(|&i| direction_key(&rays[i as usize])).collect();
        assert!(keys.windows(2).all(|k| k[0] <= k[1]), "sorted by key");
        assert!(keys.iter().all(|&k| (k as usize) < KEYS));
        // Stable: equal keys keep the rays' order; octants never interleave.
        for w in order.windows(2) {
            let (a, b) = (&rays[w[0] as usize], &rays[w[1] as usize]);
            if direction_key(a) == direction_key(b) {
                assert!(w[0] < w[1]);
            }
            assert!(octant(a) <= octant(b));
        }
    }
}
