//! A four-wide BVH for CPU traversal, collapsed from obvhs's binary BVH.
//!
//! obvhs builds the hierarchy (PLOC with reinsertion, leaves of up to four triangles chosen by
//! the SAH); this module lays it out for a CPU's 4-wide SIMD, as Embree's BVH4 does (Wald et al.
//! 2008, "Getting Rid of Packets"; Dammertz et al. 2008, "Shallow Bounding Volume Hierarchies"):
//! each node holds its four children's boxes in structure-of-arrays form, so that one ray is
//! tested against all four at once, and each leaf holds packets of four triangles tested at once
//! (`watertight.rs`). Collapsing opens, while a node has fewer than four children, the child of
//! largest surface area; subtrees of at most four triangles become one packet.
//!
//! Box tests are conservative as in Ize 2013 ("Robust BVH Ray Traversal", JCGT 2(2)): the far
//! distance is enlarged by 2 gamma(3), so that rounding never culls a box the ray touches.

use super::Hit;
use super::watertight::{PacketHit, RayShear, TrianglePacket};
use crate::geometry::Ray;
use glam::{Vec3, Vec3A, Vec4};
use obvhs::bvh2::Bvh2;

/// Children of a node that are leaves: `LEAF | index into Bvh4::leaves`.
const LEAF: u32 = 1 << 31;
/// 1 + 2 gamma(3) with gamma(n) = n eps / (1 - n eps), eps = 2^-24 (Ize 2013).
const ROBUST_FAR: f32 = 1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

/// Four child boxes and the children.
#[derive(Clone, Copy, Debug)]
#[repr(align(64))]
struct Node {
    /// `[min x, max x, min y, max y, min z, max z]`, lane i for child i; an unused slot has the
    /// empty box (min +inf, max -inf), which no ray enters.
    bounds: [Vec4; 6],
    /// A node index, or `LEAF | leaf index`.
    children: [u32; 4],
}

/// The triangles of one leaf: `count` packets from `first`.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    first: u32,
    count: u32,
}

/// The four-wide BVH; node 0 is the root.
pub(super) struct Bvh4 {
    nodes: Vec<Node>,
    leaves: Vec<Leaf>,
    packets: Vec<TrianglePacket>,
    /// Per packet, the triangle of each lane.
    packet_triangles: Vec<[u32; 4]>,
}

/// Per-ray constants of the box test.
struct RayBoxes {
    /// Per axis, 1 when the near plane is the max plane (a negative direction), else 0.
    near_is_max: [usize; 3],
    inv_d: [Vec4; 3],
    /// origin / direction, per axis.
    o_inv_d: [Vec4; 3],
}

impl RayBoxes {
    fn new(ray: &Ray) -> Self {
        // A zero component becomes a tiny one of the same sign: its reciprocal stays finite,
        // so that no 0 * inf makes a NaN in the slab test.
        let d = Vec3A::from(ray.d);
        let tiny = Vec3A::splat(1e-20);
        let inv_d = Vec3A::select(d.abs().cmplt(tiny), tiny.copysign(d), d).recip();
        let o_inv_d = Vec3A::from(ray.o) * inv_d;
        let negative = inv_d.cmplt(Vec3A::ZERO).bitmask() as usize;
        RayBoxes {
            near_is_max: [negative & 1, (negative >> 1) & 1, negative >> 2],
            inv_d: [Vec4::splat(inv_d.x), Vec4::splat(inv_d.y), Vec4::splat(inv_d.z)],
            o_inv_d: [Vec4::splat(o_inv_d.x), Vec4::splat(o_inv_d.y), Vec4::splat(o_inv_d.z)],
        }
    }

    /// Bit i set when the ray meets child i's box within (0, t_max); the entry distances.
    #[inline(always)]
    fn test(&self, node: &Node, t_max: f32) -> (u32, Vec4) {
        // Distance to the near (far: `max_side` 1) plane along `axis`; `& 1` keeps the index
        // provably in bounds.
        let slab = |axis: usize, max_side: usize| {
            node.bounds[2 * axis + (max_side & 1)] * self.inv_d[axis] - self.o_inv_d[axis]
        };
        let [nx, ny, nz] = self.near_is_max;
        let t_near = slab(0, nx).max(slab(1, ny)).max(slab(2, nz).max(Vec4::ZERO));
        let t_far = slab(0, nx ^ 1).min(slab(1, ny ^ 1)).min(slab(2, nz ^ 1).min(Vec4::splat(t_max)));
        (t_near.cmple(t_far * ROBUST_FAR).bitmask(), t_near)
    }
}

impl Bvh4 {
    /// Collapse `bvh2`, built over `triangles`, into a four-wide BVH.
    pub(super) fn from_bvh2(bvh2: &Bvh2, triangles: &[[Vec3; 3]]) -> Self {
        let mut builder = Builder {
            bvh2,
            triangles,
            sizes: subtree_sizes(bvh2),
            out: Bvh4 { nodes: Vec::new(), leaves: Vec::new(), packets: Vec::new(), packet_triangles: Vec::new() },
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
            + self.packets.len() * (size_of::<TrianglePacket>() + size_of::<[u32; 4]>())
    }

    /// The closest hit with `0 < t < ray.t_max`.
    pub(super) fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let shear = RayShear::new(ray);
        let mut closest: Option<Hit> = None;
        self.traverse::<true>(ray, |packets, t_max| {
            for p in packets {
                if let Some(PacketHit { lane, t, b1, b2 }) = shear.intersect(&self.packets[p], *t_max) {
                    closest = Some(Hit { triangle: self.packet_triangles[p][lane], t, b1, b2 });
                    *t_max = t;
                }
            }
            false
        });
        closest
    }

    /// Whether anything lies on the ray with `0 < t < ray.t_max`.
    pub(super) fn occluded(&self, ray: &Ray) -> bool {
        let shear = RayShear::new(ray);
        let mut blocked = false;
        self.traverse::<false>(ray, |mut packets, t_max| {
            blocked = packets.any(|p| shear.occludes(&self.packets[p], *t_max));
            blocked
        });
        blocked
    }

    /// Visit the leaves whose boxes the ray enters, calling `leaf(packets, t_max)`, which may
    /// shorten `t_max` to a hit and returns true to end the traversal. With `CLOSEST`, children
    /// are visited nearest first and boxes beyond `t_max` are skipped; without, in any order (a
    /// shadow ray needs any hit, not the nearest).
    #[inline(always)]
    fn traverse<const CLOSEST: bool>(&self, ray: &Ray, mut leaf: impl FnMut(std::ops::Range<usize>, &mut f32) -> bool) {
        let boxes = RayBoxes::new(ray);
        let mut t_max = ray.t_max;
        TRAVERSAL_STACK.with_borrow_mut(|stack| {
            stack.clear();
            let mut current = 0u32;
            loop {
                if current & LEAF == 0 {
                    let node = &self.nodes[current as usize];
                    let (mut mask, t_near) = boxes.test(node, t_max);
                    if mask != 0 {
                        let t_near = t_near.to_array();
                        if mask & (mask - 1) == 0 {
                            current = node.children[mask.trailing_zeros() as usize];
                            continue;
                        }
                        let mut rest = mask & (mask - 1);
                        if !CLOSEST {
                            // Any order: visit the first, push the others.
                            current = node.children[mask.trailing_zeros() as usize];
                            while rest != 0 {
                                let i = rest.trailing_zeros() as usize;
                                rest &= rest - 1;
                                stack.push((node.children[i], 0.0));
                            }
                            continue;
                        }
                        if rest & (rest - 1) == 0 {
                            // Two: visit the nearer, push the other (the order the sort below
                            // would give, ties included).
                            let (i, j) = (mask.trailing_zeros() as usize, rest.trailing_zeros() as usize);
                            let (near, far) = if t_near[i] < t_near[j] { (i, j) } else { (j, i) };
                            stack.push((node.children[far], t_near[far]));
                            current = node.children[near];
                            continue;
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
                        current = hits[n - 1].0;
                        continue;
                    }
                } else {
                    let Leaf { first, count } = self.leaves[(current & !LEAF) as usize];
                    if leaf(first as usize..(first + count) as usize, &mut t_max) {
                        return;
                    }
                }
                // Next: the nearest entry on the stack that is not beyond the closest hit.
                loop {
                    let Some((next, t_near)) = stack.pop() else {
                        return;
                    };
                    if !CLOSEST || t_near <= t_max {
                        current = next;
                        break;
                    }
                }
            }
        })
    }
}

thread_local! {
    /// Each thread's traversal stack of (child, entry distance), reused by every query so that
    /// none allocates or initialises one (queries do not nest: `leaf` never starts another).
    static TRAVERSAL_STACK: std::cell::RefCell<Vec<(u32, f32)>> = const { std::cell::RefCell::new(Vec::new()) };
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

struct Builder<'a> {
    bvh2: &'a Bvh2,
    triangles: &'a [[Vec3; 3]],
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
        // Plane 2 axis + 0 / 1: min / max along the axis; unused lanes get the empty box.
        let bounds = std::array::from_fn(|plane| {
            Vec4::from_array(std::array::from_fn(|lane| match children.get(lane) {
                Some(&c) if plane % 2 == 0 => nodes[c].aabb().min[plane / 2],
                Some(&c) => nodes[c].aabb().max[plane / 2],
                None if plane % 2 == 0 => f32::INFINITY,
                None => f32::NEG_INFINITY,
            }))
        });
        self.out.nodes.push(Node { bounds, children: [LEAF; 4] });
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

    /// Emit all triangles under binary node `n2` as one leaf; `LEAF | its index`.
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
        let out = &mut self.out;
        let first = out.packets.len() as u32;
        for chunk in ids.chunks(4) {
            let tris: Vec<[Vec3; 3]> = chunk.iter().map(|&i| self.triangles[i as usize]).collect();
            out.packets.push(TrianglePacket::new(&tris));
            out.packet_triangles.push(std::array::from_fn(|lane| *chunk.get(lane).unwrap_or(&chunk[0])));
        }
        out.leaves.push(Leaf { first, count: out.packets.len() as u32 - first });
        LEAF | (out.leaves.len() as u32 - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collapsed_bvh_keeps_every_triangle_once_inside_its_boxes() {
        let tris = crate::accel::tests::lopsided_scene();
        let bvh = crate::accel::build_bvh4(&tris);

        // Walk the tree: every triangle is reached exactly once, inside every box above it.
        let mut seen = vec![0u32; tris.len()];
        let mut pending = vec![(0u32, Vec3::NEG_INFINITY, Vec3::INFINITY)];
        while let Some((child, lo, hi)) = pending.pop() {
            if child & LEAF != 0 {
                let leaf = bvh.leaves[(child & !LEAF) as usize];
                for p in leaf.first..leaf.first + leaf.count {
                    // Short packets repeat their first triangle.
                    let mut lanes = bvh.packet_triangles[p as usize].to_vec();
                    lanes.sort();
                    lanes.dedup();
                    for t in lanes {
                        seen[t as usize] += 1;
                        assert!(tris[t as usize].iter().all(|v| v.cmpge(lo).all() && v.cmple(hi).all()));
                    }
                }
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
}
