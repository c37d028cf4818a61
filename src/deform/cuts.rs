//! UV cuts and their boundary cells (paper 000 Sec. 5; DESIGN.md section 6).
//!
//! A cut edge is a mesh edge whose two faces give its endpoints different UVs: it is embedded
//! twice in the UV plane, a left and a right copy. Consecutive cut edges are merged breadth-first
//! into boundary cells until a cell is longer than a tile on both sides; each cell keeps the
//! midpoints b_l and b'_l of its most central edge on the two sides. The cut map stores, per
//! texel of the UV square, the cell whose band holds it and that side's centre, so that the
//! tiling-and-blending lookup can give every tile centred in the cell the same centre and shift
//! on both sides (Eq. 8).

use super::nearest::{NONE, clamped_pieces, distance2_to_segment, propagate_nearest};
use crate::geometry::TriangleMesh;
use crate::image::Bitmap;
use crate::math::largest_singular_value;
use glam::{Mat2, Vec2};
use std::collections::{HashMap, VecDeque};

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

    fn side_length(&self, side: usize) -> f32 {
        self.sides[side][0].distance(self.sides[side][1])
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

/// A boundary cell: consecutive cut edges, embedded on a left and a right side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryCell {
    /// b_l and b'_l: the midpoints, on the left and on the right, of the cell's most central
    /// edge (the same surface point).
    pub centres: [Vec2; 2],
    /// The cell's length in UV on each side.
    pub lengths: [f32; 2],
}

/// The cut edges of a mesh grouped into boundary cells.
#[derive(Clone, Debug, Default)]
pub struct Cuts {
    /// Cut edges, each with `sides[0]` on its cell's left.
    pub edges: Vec<CutEdge>,
    /// The cell of each edge.
    pub cell_of_edge: Vec<u32>,
    /// The cells.
    pub cells: Vec<BoundaryCell>,
    /// Edges with more than two faces, left out.
    pub non_manifold: usize,
}

impl Cuts {
    /// The cut edges of `mesh` (which must have UVs), merged breadth-first along the cuts into
    /// cells longer than `min_length` in UV on both sides where the cut is long enough (Sec. 5,
    /// steps 1-3).
    pub fn new(mesh: &TriangleMesh, min_length: f32) -> Self {
        let Some(uvs) = &mesh.uvs else { return Cuts::default() };
        let (welded, points) = mesh.welded_vertices();
        // The UVs each face gives each welded edge (lower vertex id first), edges in order of
        // first appearance.
        let mut index: HashMap<(u32, u32), usize> = HashMap::new();
        let mut keys: Vec<(u32, u32)> = Vec::new();
        let mut faces: Vec<Vec<[Vec2; 2]>> = Vec::new();
        for tri in &mesh.indices {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let (wa, wb) = (welded[a as usize], welded[b as usize]);
                if wa == wb {
                    continue;
                }
                let (key, uv) = if wa < wb {
                    ((wa, wb), [uvs[a as usize], uvs[b as usize]])
                } else {
                    ((wb, wa), [uvs[b as usize], uvs[a as usize]])
                };
                let slot = *index.entry(key).or_insert_with(|| {
                    keys.push(key);
                    faces.push(Vec::new());
                    faces.len() - 1
                });
                faces[slot].push(uv);
            }
        }
        let mut non_manifold = 0;
        let mut edges = Vec::new();
        for ((a, b), uv) in keys.into_iter().zip(faces) {
            match uv.as_slice() {
                [left, right]
                    if left[0].distance_squared(right[0]) > 1e-12 || left[1].distance_squared(right[1]) > 1e-12 =>
                {
                    let length = points[a as usize].distance(points[b as usize]);
                    edges.push(CutEdge { sides: [*left, *right], vertices: [a, b], length });
                }
                [_, _, _, ..] => non_manifold += 1,
                _ => {}
            }
        }
        let mut cuts = Cuts { edges, cell_of_edge: Vec::new(), cells: Vec::new(), non_manifold };
        cuts.merge_cells(min_length);
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

    /// The edges that continue edge `e`'s cut, with whether their sides are swapped relative to
    /// `e`'s.
    fn neighbours<'a>(&'a self, at: &'a HashMap<u32, Vec<u32>>, e: u32) -> impl Iterator<Item = (u32, bool)> + 'a {
        let edge = self.edges[e as usize];
        edge.vertices.into_iter().flat_map(move |v| {
            at[&v]
                .iter()
                .filter(move |&&f| f != e)
                .filter_map(move |&f| edge.continued_by(&self.edges[f as usize], v).map(|swapped| (f, swapped)))
        })
    }

    /// Sec. 5 step 2 and 3: breadth-first merging, sides made consistent within each cell, small
    /// leftovers merged into a neighbouring cell, the most central edge's midpoints kept.
    fn merge_cells(&mut self, min_length: f32) {
        let at = self.edges_at_vertices();
        let n = self.edges.len();
        let mut cell_of = vec![NONE; n];
        let mut members: Vec<Vec<u32>> = Vec::new();
        let mut lengths: Vec<[f32; 2]> = Vec::new();
        for start in 0..n as u32 {
            if cell_of[start as usize] != NONE {
                continue;
            }
            let cell = members.len() as u32;
            let (mut list, mut length) = (Vec::new(), [0.0f32; 2]);
            let mut queue = VecDeque::from([start]);
            cell_of[start as usize] = cell;
            while let Some(e) = queue.pop_front() {
                list.push(e);
                length[0] += self.edges[e as usize].side_length(0);
                length[1] += self.edges[e as usize].side_length(1);
                if length[0] > min_length && length[1] > min_length {
                    // Large enough: edges already queued stay in this cell.
                    list.extend(queue.drain(..));
                    break;
                }
                let next: Vec<(u32, bool)> = self.neighbours(&at, e).collect();
                for (f, swapped) in next {
                    if cell_of[f as usize] == NONE {
                        if swapped {
                            self.edges[f as usize].sides.swap(0, 1);
                        }
                        cell_of[f as usize] = cell;
                        queue.push_back(f);
                    }
                }
            }
            // Recounted: the queued edges joined the cell too.
            let length = list.iter().fold([0.0f32; 2], |l, &e| {
                let edge = &self.edges[e as usize];
                [l[0] + edge.side_length(0), l[1] + edge.side_length(1)]
            });
            members.push(list);
            lengths.push(length);
        }
        // Cells that stayed short (the end of a cut) join a neighbouring cell.
        for cell in 0..members.len() {
            if members[cell].is_empty() || lengths[cell][0].min(lengths[cell][1]) > min_length {
                continue;
            }
            let join = members[cell]
                .iter()
                .find_map(|&e| self.neighbours(&at, e).find(|&(f, _)| cell_of[f as usize] != cell as u32));
            let Some((f, swapped)) = join else { continue };
            let target = cell_of[f as usize] as usize;
            let moved = std::mem::take(&mut members[cell]);
            for &e in &moved {
                if swapped {
                    self.edges[e as usize].sides.swap(0, 1);
                }
                cell_of[e as usize] = target as u32;
            }
            members[target].extend(moved);
            let [left, right] = lengths[cell];
            let added = if swapped { [right, left] } else { [left, right] };
            lengths[target] = [lengths[target][0] + added[0], lengths[target][1] + added[1]];
        }
        // Compact the ids and keep each cell's most central edge.
        let mut renumber = vec![NONE; members.len()];
        for (cell, list) in members.iter().enumerate() {
            if list.is_empty() {
                continue;
            }
            renumber[cell] = self.cells.len() as u32;
            let midpoints = |e: u32| [0, 1].map(|side| self.edges[e as usize].point(side, 0.5));
            let mut centroid = [Vec2::ZERO; 2];
            let mut weight = [0.0f32; 2];
            for &e in list {
                for side in 0..2 {
                    let l = self.edges[e as usize].side_length(side).max(1e-12);
                    centroid[side] += midpoints(e)[side] * l;
                    weight[side] += l;
                }
            }
            let centroid = [centroid[0] / weight[0], centroid[1] / weight[1]];
            let spread = |e: u32| {
                let m = midpoints(e);
                m[0].distance_squared(centroid[0]) + m[1].distance_squared(centroid[1])
            };
            let central = list.iter().copied().min_by(|&a, &b| spread(a).total_cmp(&spread(b))).expect("non-empty");
            self.cells.push(BoundaryCell { centres: midpoints(central), lengths: lengths[cell] });
        }
        self.cell_of_edge = cell_of.iter().map(|&c| renumber[c as usize]).collect();
    }

    /// The cut map over the UV square at the resolution of the square `f_map` it goes with
    /// (row 0 at the top, v = 1, as image textures are laid out; DESIGN.md section 6): each
    /// texel within `band` (UV units, at least a tile's support radius) of a cut edge's copy
    /// takes the cell of the nearest copy: channels (l + 1, b.x, b.y, reach) with b that side's
    /// centre and reach how far from b a tile of the cell reads in the exemplar through the F
    /// map, on either side: the largest sigma_max(F(c)) (|c - b| + `band`) over the cell's
    /// texels c, for shifts that keep the tiles inside the exemplar. Texels outside every band
    /// hold 0.
    pub fn cut_map(&self, f_map: &Bitmap, band: f32) -> Bitmap {
        let res = f_map.width;
        let f_at = |i: usize, j: usize| {
            let f = f_map.values(i, res - 1 - j);
            Mat2::from_cols(Vec2::new(f[0], f[2]), Vec2::new(f[1], f[3]))
        };
        let point = |i: usize, j: usize| Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / res as f32;
        let segment = |id: u32| self.edges[id as usize / 2].sides[id as usize % 2];
        let mut owner = vec![NONE; res * res];
        let mut best = vec![f32::INFINITY; res * res];
        // Seed the texels each copy passes through; a copy on or beyond the square's border
        // seeds the border texels nearest to it.
        let last = (res - 1) as f32;
        for id in 0..2 * self.edges.len() as u32 {
            let [a, b] = segment(id);
            // Step along the copy as the map sees it, clamped to the square: a few steps per
            // texel of that path, however long the copy is in UV (UVs far outside the square
            // would otherwise take millions of steps per edge).
            for [p0, q0] in clamped_pieces(a, b) {
                let steps = (p0.distance(q0) * res as f32 * 2.0).ceil() as usize + 1;
                for s in 0..=steps {
                    let p = (p0.lerp(q0, s as f32 / steps as f32) * res as f32).floor();
                    if !p.is_finite() {
                        continue;
                    }
                    let (i, j) = (p.x.clamp(0.0, last) as usize, p.y.clamp(0.0, last) as usize);
                    let d = distance2_to_segment(point(i, j), a, b);
                    if d < best[j * res + i] {
                        best[j * res + i] = d;
                        owner[j * res + i] = id;
                    }
                }
            }
        }
        propagate_nearest(res, &mut owner, &mut best, |i, j, id| {
            let [a, b] = segment(id);
            distance2_to_segment(point(i, j), a, b)
        });
        // Each band texel's cell and centre, then each cell's reach over its texels.
        let in_band = |k: usize| {
            (owner[k] != NONE && best[k] <= band * band).then(|| {
                let cell = self.cell_of_edge[owner[k] as usize / 2] as usize;
                (cell, self.cells[cell].centres[owner[k] as usize % 2])
            })
        };
        let mut reach = vec![0.0f32; self.cells.len()];
        for k in 0..res * res {
            if let Some((cell, b)) = in_band(k) {
                let (i, j) = (k % res, k / res);
                reach[cell] = reach[cell].max(largest_singular_value(f_at(i, j)) * (point(i, j).distance(b) + band));
            }
        }
        let mut map = Bitmap::new(res, res, 4);
        for k in 0..res * res {
            if let Some((cell, b)) = in_band(k) {
                map.values_mut(k % res, res - 1 - k / res).copy_from_slice(&[(cell + 1) as f32, b.x, b.y, reach[cell]]);
            }
        }
        map
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

    /// Mean over the cuts of |T(left) - T(right)|, the mean of `difference` of the texture at
    /// the [`Cuts::seam_points`], weighted by the edges' surface length. None without cut
    /// edges.
    pub fn seam_difference(&self, samples: usize, difference: impl Fn(Vec2, Vec2) -> f32) -> Option<f64> {
        let (mut sum, mut total) = (0.0f64, 0.0f64);
        for p in self.seam_points(samples) {
            sum += difference(p.left, p.right) as f64 * p.weight as f64;
            total += p.weight as f64;
        }
        (total > 0.0).then(|| sum / total)
    }
}
