//! Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)), four triangles at a time.
//!
//! The paper permutes the axes so that the ray direction's largest component is z, then shears
//! the ray onto +z. The permutation is per ray, so it only chooses which coordinate arrays of a
//! [`TrianglePacket`] are read; the shear is three multiply-adds per vertex, on four triangles
//! at once (SSE2 or NEON lanes through glam's `Vec4`).

use crate::geometry::Ray;
use glam::{BVec4A, Vec3, Vec4};

/// Four triangles in structure-of-arrays form: `v[k][axis]` holds coordinate `axis` of vertex
/// `k` of the four triangles, one per lane. Packets with fewer triangles repeat their first.
#[derive(Clone, Copy, Debug)]
pub(super) struct TrianglePacket {
    v: [[Vec4; 3]; 3],
}

impl TrianglePacket {
    /// Pack one to four triangles.
    pub(super) fn new(triangles: &[[Vec3; 3]]) -> Self {
        assert!((1..=4).contains(&triangles.len()), "a packet holds 1 to 4 triangles");
        let lane = |i: usize| triangles.get(i).unwrap_or(&triangles[0]);
        let v = std::array::from_fn(|k| {
            std::array::from_fn(|axis| Vec4::from_array(std::array::from_fn(|i| lane(i)[k][axis])))
        });
        TrianglePacket { v }
    }

    /// Coordinate `axis` of vertex `vertex` of the triangle in lane `lane`.
    #[inline(always)]
    pub(super) fn coordinate(&self, vertex: usize, axis: usize, lane: usize) -> f32 {
        self.v[vertex][axis].as_ref()[lane]
    }
}

/// The paper's permutation of the axes for a ray along `d`: [kx, ky, kz], kz the axis of the
/// largest component, kx and ky the other two in cyclic order, swapped where `d[kz]` is negative
/// so that the winding is kept.
#[inline(always)]
pub(super) fn permutation(d: Vec3) -> [usize; 3] {
    let a = d.abs();
    let kz = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    const CYCLIC: [[usize; 2]; 3] = [[1, 2], [2, 0], [0, 1]];
    let [kx, ky] = CYCLIC[kz];
    if d[kz] < 0.0 { [ky, kx, kz] } else { [kx, ky, kz] }
}

/// A hit on one lane of a packet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PacketHit {
    pub lane: usize,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// The lanes of a packet that a ray hits: distances, and barycentrics scaled by `det`.
struct LaneHits {
    valid: BVec4A,
    t: Vec4,
    v: Vec4,
    w: Vec4,
    det: Vec4,
}

/// Per-ray constants of the test: the axis permutation, and the origin and shear in permuted
/// axes, splatted over the four lanes.
pub(super) struct RayShear {
    /// Indices of the permuted x, y, z axes (z: the direction's largest component).
    k: [usize; 3],
    origin: [Vec4; 3],
    /// (Sx, Sy, Sz) of the paper.
    shear: [Vec4; 3],
}

impl RayShear {
    pub(super) fn new(ray: &Ray) -> Self {
        let (d, o) = (ray.d.to_array(), ray.o.to_array());
        let k @ [kx, ky, kz] = permutation(ray.d);
        let sz = 1.0 / d[kz];
        RayShear { k, origin: k.map(|axis| Vec4::splat(o[axis])), shear: [d[kx] * sz, d[ky] * sz, sz].map(Vec4::splat) }
    }

    /// The closest hit with `0 < t < t_max` among the packet's triangles, or None. Ties go to
    /// the lowest lane.
    #[inline(always)]
    pub(super) fn intersect(&self, packet: &TrianglePacket, t_max: f32) -> Option<PacketHit> {
        let LaneHits { valid, t, v, w, det } = self.lane_hits(packet, t_max)?;
        let lane = closest_lane(valid, t);
        let det = det.to_array()[lane];
        Some(PacketHit { lane, t: t.to_array()[lane], b1: v.to_array()[lane] / det, b2: w.to_array()[lane] / det })
    }

    /// Whether any of the packet's triangles lies on the ray with `0 < t < t_max`.
    #[inline(always)]
    pub(super) fn occludes(&self, packet: &TrianglePacket, t_max: f32) -> bool {
        self.lane_hits(packet, t_max).is_some()
    }

    /// The lanes hit with `0 < t < t_max`, with their distances and scaled barycentrics; None
    /// when no lane is hit.
    #[inline(always)]
    fn lane_hits(&self, packet: &TrianglePacket, t_max: f32) -> Option<LaneHits> {
        let [kx, ky, kz] = self.k;
        let [sx, sy, sz] = self.shear;
        // Vertices relative to the origin, permuted and sheared: the ray is now the +z axis.
        let sheared = |p: &[Vec4; 3]| {
            let z = p[kz] - self.origin[2];
            let x = (p[kx] - self.origin[0]) - sx * z;
            let y = (p[ky] - self.origin[1]) - sy * z;
            (x, y, sz * z)
        };
        let (ax, ay, az) = sheared(&packet.v[0]);
        let (bx, by, bz) = sheared(&packet.v[1]);
        let (cx, cy, cz) = sheared(&packet.v[2]);
        // Scaled barycentrics: signed areas of the sheared triangle seen from the ray.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        if on_edge.any() {
            // On an edge, recompute in double precision so that neighbours agree (paper, sec. 3).
            let (mut ua, mut va, mut wa) = (u.to_array(), v.to_array(), w.to_array());
            let f = |x: Vec4, lane: usize| x.to_array()[lane] as f64;
            for lane in (0..4).filter(|&lane| on_edge.test(lane)) {
                let (ax, ay, bx, by, cx, cy) =
                    (f(ax, lane), f(ay, lane), f(bx, lane), f(by, lane), f(cx, lane), f(cy, lane));
                ua[lane] = (cx * by - cy * bx) as f32;
                va[lane] = (ax * cy - ay * cx) as f32;
                wa[lane] = (bx * ay - by * ax) as f32;
            }
            (u, v, w) = (Vec4::from_array(ua), Vec4::from_array(va), Vec4::from_array(wa));
        }
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let det = u + v + w;
        let t = (u * az + v * bz + w * cz) / det;
        // A zero, infinite or NaN determinant gives a t that fails these comparisons.
        let valid = !(negative & positive) & det.cmpne(zero) & t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max));
        valid.any().then_some(LaneHits { valid, t, v, w, det })
    }
}

/// The lane of the smallest `t` among `valid` lanes (one at least), the lowest on ties.
#[inline(always)]
fn closest_lane(valid: BVec4A, t: Vec4) -> usize {
    let t = Vec4::select(valid, t, Vec4::INFINITY).to_array();
    let mut best = valid.bitmask().trailing_zeros() as usize;
    for lane in best + 1..4 {
        if t[lane] < t[best] {
            best = lane;
        }
    }
    best
}
