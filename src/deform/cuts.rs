//! UV cuts (paper 000 Sec. 5; DESIGN.md section 6): the mesh edges the UV map embeds twice,
//! chained into cuts, and the cut curves the synthesis' cut bands follow.
//!
//! A cut edge is a mesh edge whose two faces give its endpoints different UVs: it is embedded
//! twice in the UV plane, a left and a right copy. Consecutive cut edges (the cut goes on
//! through their shared vertex with the same two UVs) are chained into cuts, their sides made
//! consistent along each; a cut ends where its two sides meet or where three charts meet.
//! Along each cut, the arc length s and the developed exemplar coordinate g (g' = F t, the mean
//! of the two sides' F) are integrated edge by edge: the shared coordinates of
//! [`crate::texture::tiling_blending::CutBands`].

use super::field::{ChartField, barycentric};
use crate::geometry::{Topology, TriangleMesh};
use crate::texture::tiling_blending::{CutCurve, CutPoint};
use glam::Vec2;
use std::collections::HashMap;

/// What two cuts embedded at the same UVs share, whichever their direction and the order of
/// their sides: each side's UVs (as bits) in the direction that starts at the lesser end, the
/// two sides in order.
fn uv_embedding(points: &[CutPoint]) -> [Vec<[u32; 2]>; 2] {
    let side = |k: usize| {
        let mut uvs: Vec<[u32; 2]> = points.iter().map(|p| p.uv[k].to_array().map(f32::to_bits)).collect();
        if uvs.last() < uvs.first() {
            uvs.reverse();
        }
        uvs
    };
    let (a, b) = (side(0), side(1));
    if a <= b { [a, b] } else { [b, a] }
}

/// A point of a cut seen from both sides: its UVs on the left and the right side of the cut,
/// and the surface length it stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeamPoint {
    /// UV on side 0.
    pub left: Vec2,
    /// UV on side 1.
    pub right: Vec2,
    /// Surface length represented.
    pub weight: f32,
    /// Whether its edge is a UV singularity ([`CutEdge::is_singular`]).
    pub singular: bool,
}

/// A mesh edge embedded twice in UV: the same two surface points seen from its two faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutEdge {
    /// The UV endpoints on the left and on the right face, both in the order of `vertices`.
    pub sides: [[Vec2; 2]; 2],
    /// The position-welded vertex ids of the endpoints.
    pub vertices: [u32; 2],
    /// The triangle on each side.
    pub faces: [u32; 2],
    /// Length on the surface.
    pub length: f32,
}

impl CutEdge {
    /// The point at parameter `t` in [0, 1] from the first vertex to the second, on `side` (0
    /// left, 1 right): corresponding parameters are the same surface point on both sides.
    pub fn point(&self, side: usize, t: f32) -> Vec2 {
        self.sides[side][0].lerp(self.sides[side][1], t)
    }

    /// Whether the two sides meet at one end: the edge opens a dart or a fan from a point
    /// that both faces map to the same UV, as the triangles around a lat-long sphere's pole do
    /// (a UV singularity), rather than running along a seam whose sides are apart throughout.
    pub fn is_singular(&self) -> bool {
        (0..2).any(|k| self.sides[0][k].distance_squared(self.sides[1][k]) < 1e-12)
    }

    fn uv_at(&self, side: usize, vertex: u32) -> Vec2 {
        self.sides[side][usize::from(self.vertices[1] == vertex)]
    }

    /// How `other` continues this edge through their shared `vertex`: Some(false) with the same
    /// left and right, Some(true) with the sides swapped, None when it is not the same cut
    /// (its UVs at the vertex differ, or the cut ends there: both sides meet).
    fn continued_by(&self, other: &CutEdge, vertex: u32) -> Option<bool> {
        let close = |a: Vec2, b: Vec2| a.distance_squared(b) <= 1e-12;
        let (a0, a1) = (self.uv_at(0, vertex), self.uv_at(1, vertex));
        let (b0, b1) = (other.uv_at(0, vertex), other.uv_at(1, vertex));
        if close(a0, a1) {
            None
        } else if close(a0, b0) && close(a1, b1) {
            Some(false)
        } else if close(a0, b1) && close(a1, b0) {
            Some(true)
        } else {
            None
        }
    }
}

/// The cut edges of a mesh chained into cuts.
#[derive(Clone, Debug, Default)]
pub struct Cuts {
    /// Cut edges, each with `sides` consistent along its chain.
    pub edges: Vec<CutEdge>,
    /// The cuts: their edges in order along each, with whether each is walked from its second
    /// vertex to its first.
    pub chains: Vec<Vec<(u32, bool)>>,
    /// Edges with more than two faces, left out.
    pub non_manifold: usize,
}

impl Cuts {
    /// The cut edges of `mesh` (which must have UVs), chained into cuts (Sec. 5, steps 1-2).
    pub fn new(mesh: &TriangleMesh) -> Self {
        let Some(uvs) = &mesh.uvs else { return Cuts::default() };
        let (welded, points) = mesh.welded_vertices();
        let triangles: Vec<[u32; 3]> = mesh.indices.iter().map(|t| t.map(|i| welded[i as usize])).collect();
        let topology = Topology::new(&triangles);
        // The UVs a face gives a half-edge's endpoints, lower welded vertex first.
        let uvs_along = |h: usize| {
            let (t, k) = (topology.face_of(h), topology.side_of(h));
            let tri = mesh.indices[t];
            let (a, b) = (uvs[tri[k] as usize], uvs[tri[(k + 1) % 3] as usize]);
            let [wa, wb] = topology.endpoints(h);
            if wa < wb { [a, b] } else { [b, a] }
        };
        let mut non_manifold = 0;
        let mut edges = Vec::new();
        for e in 0..topology.edge_count() {
            let [a, b] = topology.edge_vertices(e);
            match topology.halves(e) {
                _ if a == b => {}
                &[h0, h1] => {
                    let (left, right) = (uvs_along(h0 as usize), uvs_along(h1 as usize));
                    if left[0].distance_squared(right[0]) > 1e-12 || left[1].distance_squared(right[1]) > 1e-12 {
                        let length = points[a as usize].distance(points[b as usize]);
                        let faces = [topology.face_of(h0 as usize) as u32, topology.face_of(h1 as usize) as u32];
                        edges.push(CutEdge { sides: [left, right], vertices: [a, b], faces, length });
                    }
                }
                [_, _, _, ..] => non_manifold += 1,
                _ => {}
            }
        }
        let mut cuts = Cuts { edges, chains: Vec::new(), non_manifold };
        cuts.chain();
        cuts
    }

    /// Cut edges meeting at each welded vertex.
    fn edges_at_vertices(&self) -> HashMap<u32, Vec<u32>> {
        let mut at: HashMap<u32, Vec<u32>> = HashMap::new();
        for (e, edge) in self.edges.iter().enumerate() {
            for v in edge.vertices {
                at.entry(v).or_default().push(e as u32);
            }
        }
        at
    }

    /// Chain consecutive edges into cuts, swapping sides so that they agree along each.
    fn chain(&mut self) {
        let at = self.edges_at_vertices();
        let mut used = vec![false; self.edges.len()];
        for start in 0..self.edges.len() as u32 {
            if used[start as usize] {
                continue;
            }
            used[start as usize] = true;
            let [first, second] = self.edges[start as usize].vertices;
            // Walk on from the start edge's second vertex, then (reversed) from its first.
            let ahead = self.walk(&at, &mut used, start, second);
            let behind = self.walk(&at, &mut used, start, first);
            let mut chain: Vec<(u32, bool)> = behind.into_iter().rev().map(|(e, reversed)| (e, !reversed)).collect();
            chain.push((start, false));
            chain.extend(ahead);
            self.chains.push(chain);
        }
    }

    /// The edges continuing edge `from`'s cut through `vertex`, in order, each with whether it
    /// is walked from its second vertex to its first; their sides are swapped to agree.
    fn walk(&mut self, at: &HashMap<u32, Vec<u32>>, used: &mut [bool], from: u32, vertex: u32) -> Vec<(u32, bool)> {
        let (mut current, mut vertex, mut out) = (from, vertex, Vec::new());
        loop {
            let edge = self.edges[current as usize];
            let next = at[&vertex]
                .iter()
                .filter(|&&f| !used[f as usize])
                .find_map(|&f| edge.continued_by(&self.edges[f as usize], vertex).map(|swapped| (f, swapped)));
            let Some((f, swapped)) = next else { return out };
            used[f as usize] = true;
            let next_edge = &mut self.edges[f as usize];
            if swapped {
                next_edge.sides.swap(0, 1);
                next_edge.faces.swap(0, 1);
            }
            let reversed = next_edge.vertices[1] == vertex;
            vertex = next_edge.vertices[usize::from(!reversed)];
            out.push((f, reversed));
            current = f;
        }
    }

    /// The cut curves of the chains for the field `field` of the mesh whose UV triangles are
    /// `uv_triangles`: at each chain vertex its UVs on both sides, the arc length s and the
    /// developed coordinate g, integrated edge by edge as the mean of F dt on the two sides (F
    /// at each side's edge midpoint, in its face); the scale is the chain's length in map units
    /// over its mean length in UV. Chains of zero length are left out, and so are chains of
    /// singular edges only (the fans around a lat-long pole: each edge a cut of its own whose
    /// band, through F's vanishing stretch along the pole's row, would cover the whole row).
    /// A chain embedded at exactly the UVs of an earlier one (its twin on a stacked island: the
    /// mirror-image half of a character, a repeated part) is left out too: the F map and the
    /// bands' raster are keyed by UV, so the twin's hits read the first one's row (on the cut,
    /// the same values from both sides), and twin bands would fill a texel's two band slots.
    pub fn curves(&self, field: &ChartField, uv_triangles: &[[Vec2; 3]]) -> Vec<CutCurve> {
        let mut curves = Vec::with_capacity(self.chains.len());
        let mut embedded = std::collections::HashSet::new();
        for chain in &self.chains {
            if chain.iter().all(|&(e, _)| self.edges[e as usize].is_singular()) {
                continue;
            }
            let mut points = Vec::with_capacity(chain.len() + 1);
            let (mut s, mut g, mut uv_length) = (0.0f32, Vec2::ZERO, 0.0f32);
            for (n, &(e, reversed)) in chain.iter().enumerate() {
                let edge = &self.edges[e as usize];
                let ends = |side: usize| {
                    let [a, b] = edge.sides[side];
                    if reversed { [b, a] } else { [a, b] }
                };
                let (left, right) = (ends(0), ends(1));
                if n == 0 {
                    points.push(CutPoint { uv: [left[0], right[0]], s, g });
                }
                let step = |side: usize, [p, q]: [Vec2; 2]| {
                    let t = edge.faces[side] as usize;
                    let b = barycentric((p + q) / 2.0, uv_triangles[t]).unwrap_or(glam::Vec3::ONE);
                    field.at(t, b) * (q - p)
                };
                let dg = (step(0, left) + step(1, right)) / 2.0;
                g += dg;
                s += dg.length();
                uv_length += (left[0].distance(left[1]) + right[0].distance(right[1])) / 2.0;
                points.push(CutPoint { uv: [left[1], right[1]], s, g });
            }
            if s > 0.0
                && uv_length > 0.0
                && embedded.insert(uv_embedding(&points))
                && let Ok(curve) = CutCurve::new(points, s / uv_length)
            {
                curves.push(curve);
            }
        }
        curves
    }

    /// Corresponding points of the two sides of every cut edge: `samples` per edge, at the
    /// middles of equal parts, each weighted by the edge's surface length over `samples`.
    pub fn seam_points(&self, samples: usize) -> Vec<SeamPoint> {
        let mut points = Vec::with_capacity(self.edges.len() * samples);
        for edge in &self.edges {
            let (weight, singular) = (edge.length / samples as f32, edge.is_singular());
            for s in 0..samples {
                let t = (s as f32 + 0.5) / samples as f32;
                points.push(SeamPoint { left: edge.point(0, t), right: edge.point(1, t), weight, singular });
            }
        }
        points
    }
}
