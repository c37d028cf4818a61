//! The PUPs interpolant (paper 002 Sec. 2): control points joined by their Delaunay
//! triangulation (the `spade` crate), weights from the axes along their edges, values blended
//! by the normalised weights and labels by the largest weight.
//!
//! - Axial weight (Eq. 1): A(p) = (1 - p)^2 (1 + 2p), p the projection of u - c onto the axis
//!   as a fraction of the axis' length times the axis scale (Fig. 4), clamped to [0, 1]. A has
//!   zero slope at both ends, so the weights are C1 where the clamping switches.
//! - Point weight (Eq. 2): the product of the axial weights over the point's axes (its edges).
//! - Orientation (Eq. 4): K = epsilon eta, eta = (u - c) . v / |u - c|; w' = w^(1 - K) for
//!   K >= 0, w^(1 / (1 + K)) otherwise.
//! - Value (Eq. 3): sum T_i W_i / sum W_i.
//!
//! Periodic fields triangulate the points with copies of them shifted by the unit square's
//! sides, over a band around it wide enough to give every point near the border its whole
//! neighbourhood, so that the field wraps exactly. Fields on the plain square are drawn with a
//! margin of points around it ([`super::points::Domain::Square`]), so that the square's border
//! is as well surrounded as its middle (no long hull edges or thin triangles inside it).
//!
//! A uniform grid over the unit square lists, per cell, the points whose weight can be
//! non-zero there (the polygon where every projection is below 1, clipped from the box around
//! the points), so that a lookup touches a handful of points.

use super::points::Domain;
use glam::{Vec2, Vec3};

/// What each control point carries.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlPoints {
    /// Positions (the unit square; a periodic field wraps them into it).
    pub positions: Vec<Vec2>,
    /// Values (scalars as grey).
    pub values: Vec<Vec3>,
    /// Labels (cells): the index into a palette.
    pub labels: Vec<u32>,
    /// Orientations: unit vectors of R^3 whose x and y shift the weight (Eq. 4); zero for none.
    pub orientations: Vec<Vec3>,
}

impl ControlPoints {
    /// Points with values and labels, no orientation.
    pub fn new(positions: Vec<Vec2>, values: Vec<Vec3>, labels: Vec<u32>) -> Self {
        let orientations = vec![Vec3::ZERO; positions.len()];
        ControlPoints { positions, values, labels, orientations }
    }
}

/// A PUPs field ready to evaluate.
#[derive(Clone, Debug)]
pub struct PupsField {
    domain: Domain,
    /// Centres of the triangulated points (copies included).
    centres: Vec<Vec2>,
    /// For each centre, the control point it is (a copy's original).
    source: Vec<u32>,
    /// Axes of centre i: axes[axis_start[i]..axis_start[i + 1]], each a / (scale |a|^2) so
    /// that the projection is a dot product.
    axis_start: Vec<u32>,
    axes: Vec<Vec2>,
    /// Grid over the unit square: the centres whose support meets cell c.
    cells: usize,
    cell_start: Vec<u32>,
    cell_centres: Vec<u32>,
    values: Vec<Vec3>,
    labels: Vec<u32>,
    orientations: Vec<Vec2>,
    epsilon: f32,
}

/// Eq. 1: the axial weight of a clamped projection.
#[inline]
pub fn axial_weight(p: f32) -> f32 {
    let p = p.clamp(0.0, 1.0);
    (1.0 - p) * (1.0 - p) * (1.0 + 2.0 * p)
}

/// Eq. 4: weight `w` shifted by K = epsilon eta.
#[inline]
pub fn shifted_weight(w: f32, k: f32) -> f32 {
    // libm: the same bits on every platform, so that presets reproduce their golden images.
    if k >= 0.0 { libm::powf(w, 1.0 - k) } else { libm::powf(w, 1.0 / (1.0 + k)) }
}

/// Clip the convex polygon `poly` to the half-plane d . q <= 1 with d = x - c.
fn clip(poly: &[Vec2], c: Vec2, q: Vec2) -> Vec<Vec2> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (k, &a) in poly.iter().enumerate() {
        let b = poly[(k + 1) % poly.len()];
        let (fa, fb) = ((a - c).dot(q) - 1.0, (b - c).dot(q) - 1.0);
        if fa <= 0.0 {
            out.push(a);
        }
        if (fa < 0.0) != (fb < 0.0) && fa != fb {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}

impl PupsField {
    /// The field of `points` over `domain`: axes `axis_scale` times their edges' length
    /// (Fig. 4; at least 0.5, so that the point nearest a lookup always has weight), orientation
    /// strength `epsilon` in [0, 1]. Errors on non-finite positions, fewer than three points,
    /// all points on a line, and more than [`super::points::MAX_POINTS`].
    pub fn new(points: &ControlPoints, domain: Domain, axis_scale: f32, epsilon: f32) -> Result<Self, String> {
        let n = points.positions.len();
        if !(0.5..=16.0).contains(&axis_scale) {
            return Err(format!("axis scale {axis_scale}: give 0.5 to 16"));
        }
        if !(0.0..=1.0).contains(&epsilon) {
            return Err(format!("orientation strength epsilon {epsilon}: give 0 to 1"));
        }
        if n < 3 {
            return Err(format!("{n} control point(s): a PUPs texture needs at least three, not all on a line"));
        }
        if points.values.len() != n || points.labels.len() != n || points.orientations.len() != n {
            return Err("every control point needs a value, a label and an orientation".into());
        }
        if let Some(i) = points.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("control point {} has a non-finite position", i + 1));
        }
        if let Some(i) = points.values.iter().position(|v| !v.is_finite()) {
            return Err(format!("control point {} has a non-finite value", i + 1));
        }
        let (centres, source, neighbours) = match domain {
            Domain::Square { .. } => {
                let centres = points.positions.clone();
                let neighbours = delaunay_neighbours(&centres)?;
                (centres, (0..n as u32).collect(), neighbours)
            }
            Domain::Periodic => periodic_triangulation(&points.positions, axis_scale)?,
        };
        // Axes, and each centre's support clipped from the box around all centres.
        let (lo, hi) =
            centres.iter().fold((Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)), |(lo, hi), c| (lo.min(*c), hi.max(*c)));
        let pad = (hi - lo).max_element() * axis_scale;
        let (lo, hi) = (lo - pad, hi + pad);
        let mut axis_start = vec![0u32];
        let mut axes = Vec::new();
        let cells = ((n as f32).sqrt().ceil() as usize).clamp(1, 1024);
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); cells * cells];
        for (i, c) in centres.iter().enumerate() {
            let mut poly = vec![lo, Vec2::new(hi.x, lo.y), hi, Vec2::new(lo.x, hi.y)];
            for &j in &neighbours[i] {
                let a = centres[j as usize] - *c;
                if !(a.length_squared() >= 1e-12 && a.length_squared().is_finite()) {
                    return Err(format!(
                        "control points {} and {} are closer than 1e-6 (or too far apart): their axis has no usable length",
                        source[i] + 1,
                        source[j as usize] + 1
                    ));
                }
                let q = a / (axis_scale * a.length_squared());
                axes.push(q);
                poly = clip(&poly, *c, q);
            }
            axis_start.push(axes.len() as u32);
            if poly.is_empty() {
                continue;
            }
            let (plo, phi) =
                poly.iter().fold((Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)), |(a, b), p| (a.min(*p), b.max(*p)));
            if phi.x < 0.0 || phi.y < 0.0 || plo.x > 1.0 || plo.y > 1.0 {
                continue;
            }
            let cell = |t: f32| ((t.clamp(0.0, 1.0) * cells as f32) as usize).min(cells - 1);
            for y in cell(plo.y)..=cell(phi.y) {
                for x in cell(plo.x)..=cell(phi.x) {
                    members[y * cells + x].push(i as u32);
                }
            }
        }
        let mut cell_start = vec![0u32];
        let mut cell_centres = Vec::new();
        for m in members {
            cell_centres.extend(m);
            cell_start.push(cell_centres.len() as u32);
        }
        let orientations = points.orientations.iter().map(|v| Vec2::new(v.x, v.y)).collect();
        Ok(PupsField {
            domain,
            centres,
            source,
            axis_start,
            axes,
            cells,
            cell_start,
            cell_centres,
            values: points.values.clone(),
            labels: points.labels.clone(),
            orientations,
            epsilon,
        })
    }

    /// The lookup point in the grid's square: wrapped when periodic, clamped otherwise.
    fn in_square(&self, u: Vec2) -> Vec2 {
        match self.domain {
            Domain::Periodic => u - u.floor(),
            Domain::Square { .. } => u.clamp(Vec2::ZERO, Vec2::ONE),
        }
    }

    /// The lookup point in the square and the centres the grid lists around it.
    fn candidates(&self, u: Vec2) -> (Vec2, &[u32]) {
        let g = self.in_square(u);
        let cell = |t: f32| ((t * self.cells as f32) as usize).min(self.cells - 1);
        let c = cell(g.y) * self.cells + cell(g.x);
        (g, &self.cell_centres[self.cell_start[c] as usize..self.cell_start[c + 1] as usize])
    }

    /// Eq. 2 and 4: the weight of centre `i` at `u` (unwrapped).
    #[inline]
    fn weight(&self, i: usize, u: Vec2) -> f32 {
        let d = u - self.centres[i];
        let mut w = 1.0;
        for q in &self.axes[self.axis_start[i] as usize..self.axis_start[i + 1] as usize] {
            let p = d.dot(*q);
            if p >= 1.0 {
                return 0.0;
            }
            if p > 0.0 {
                w *= axial_weight(p);
            }
        }
        let v = self.orientations[self.source[i] as usize];
        if self.epsilon > 0.0 && v != Vec2::ZERO {
            let length = d.length();
            if length > 0.0 {
                w = shifted_weight(w, self.epsilon * d.dot(v) / length);
            }
        }
        w
    }

    /// Call `f(control point, weight)` for every centre with a weight at `u`, in a fixed order.
    /// `u` is taken as it is (periodic fields see copies beyond the square).
    pub fn for_each_weight(&self, u: Vec2, mut f: impl FnMut(usize, f32)) {
        let (g, candidates) = self.candidates(u);
        // Evaluate at the wrapped point: the grid lists the centres around it.
        for &i in candidates {
            let w = self.weight(i as usize, g);
            if w > 0.0 {
                f(self.source[i as usize] as usize, w);
            }
        }
    }

    /// Eq. 3: the weighted mean of the values at `u`.
    pub fn value(&self, u: Vec2) -> Vec3 {
        let (mut sum, mut total) = (Vec3::ZERO, 0.0f32);
        self.for_each_weight(u, |i, w| {
            sum += self.values[i] * w;
            total += w;
        });
        if total > 0.0 { sum / total } else { self.values[self.nearest(u)] }
    }

    /// The label of the control point with the largest weight at `u` (cellular textures).
    pub fn label(&self, u: Vec2) -> u32 {
        let (mut best, mut label) = (0.0f32, None);
        self.for_each_weight(u, |i, w| {
            if w > best {
                best = w;
                label = Some(self.labels[i]);
            }
        });
        label.unwrap_or_else(|| self.labels[self.nearest(u)])
    }

    /// Sum of the weights at `u` (before normalisation).
    pub fn weight_sum(&self, u: Vec2) -> f32 {
        let mut total = 0.0;
        self.for_each_weight(u, |_, w| total += w);
        total
    }

    /// The control point nearest `u` among the grid cell's (a fallback where every weight has
    /// been shifted to zero by Eq. 4).
    fn nearest(&self, u: Vec2) -> usize {
        let (g, candidates) = self.candidates(u);
        candidates
            .iter()
            .min_by(|a, b| {
                let d = |i: u32| self.centres[i as usize].distance_squared(g);
                d(**a).total_cmp(&d(**b))
            })
            .map_or(0, |&i| self.source[i as usize] as usize)
    }

    /// Number of control points.
    pub fn point_count(&self) -> usize {
        self.values.len()
    }
}

/// The points wrapped into the unit square and their copies shifted by its sides over a band
/// around it, triangulated: centres, the point each is a copy of, the neighbours. The band is
/// three axis lengths of the longest edge from a point of the square wide (or the whole 3 x 3
/// block), so that every centre whose weight reaches into the square has its whole periodic
/// neighbourhood; a first guess from the point count is widened until that holds.
#[allow(clippy::type_complexity)]
fn periodic_triangulation(positions: &[Vec2], axis_scale: f32) -> Result<(Vec<Vec2>, Vec<u32>, Vec<Vec<u32>>), String> {
    let n = positions.len();
    let wrapped: Vec<Vec2> = positions.iter().map(|p| *p - p.floor()).collect();
    let mut margin = (6.0 / (n as f32).sqrt()).min(1.0);
    loop {
        let mut centres = wrapped.clone();
        let mut source: Vec<u32> = (0..n as u32).collect();
        for dy in -1..=1 {
            for dx in -1..=1 {
                if (dx, dy) == (0, 0) {
                    continue;
                }
                let shift = Vec2::new(dx as f32, dy as f32);
                for (i, p) in wrapped.iter().enumerate() {
                    let q = *p + shift;
                    if q.cmpge(Vec2::splat(-margin)).all() && q.cmple(Vec2::splat(1.0 + margin)).all() {
                        centres.push(q);
                        source.push(i as u32);
                    }
                }
            }
        }
        if centres.len() > super::points::MAX_POINTS {
            return Err(format!(
                "{} control points (with the copies of a periodic domain), over tessera's limit of {}",
                centres.len(),
                super::points::MAX_POINTS
            ));
        }
        let neighbours = delaunay_neighbours(&centres)?;
        let longest = (0..n)
            .flat_map(|i| neighbours[i].iter().map(move |&j| (i, j)))
            .map(|(i, j)| centres[i].distance(centres[j as usize]))
            .fold(0.0f32, f32::max);
        let needed = 3.0 * axis_scale * longest;
        if margin >= 1.0 || margin >= needed {
            return Ok((centres, source, neighbours));
        }
        margin = needed.min(1.0);
    }
}

/// The Delaunay neighbours of every point (spade), in the order spade walks them.
fn delaunay_neighbours(points: &[Vec2]) -> Result<Vec<Vec<u32>>, String> {
    use spade::{DelaunayTriangulation, Point2, Triangulation};
    let mut triangulation: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    let mut vertex_of = Vec::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        let handle = triangulation
            .insert(Point2::new(p.x as f64, p.y as f64))
            .map_err(|e| format!("control point {} at ({}, {}): {e}", i + 1, p.x, p.y))?;
        vertex_of.push(handle);
    }
    if triangulation.num_vertices() != points.len() {
        return Err(format!(
            "{} of the {} control points fall on others: give distinct positions",
            points.len() - triangulation.num_vertices(),
            points.len()
        ));
    }
    if triangulation.num_inner_faces() == 0 {
        return Err("the control points all lie on one line: they span no triangle".into());
    }
    let mut neighbours = vec![Vec::new(); points.len()];
    for (i, handle) in vertex_of.iter().enumerate() {
        for edge in triangulation.vertex(*handle).out_edges() {
            neighbours[i].push(edge.to().fix().index() as u32);
        }
    }
    Ok(neighbours)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pups::points::poisson_disk;

    fn field(domain: Domain, epsilon: f32, seed: u64) -> PupsField {
        let positions = poisson_disk(domain, 0.08, 0.08, &|_| 0.08, seed).unwrap();
        let mut sampler = crate::sampling::Sampler::new(seed, 1, 0);
        let values = positions.iter().map(|_| Vec3::splat(sampler.next_1d())).collect();
        let labels = (0..positions.len() as u32).collect();
        let mut points = ControlPoints::new(positions, values, labels);
        for o in &mut points.orientations {
            let a = sampler.next_1d() * std::f32::consts::TAU;
            *o = Vec3::new(a.cos(), a.sin(), 0.0);
        }
        PupsField::new(&points, domain, 1.0, epsilon).unwrap()
    }

    /// Eq. 1 at its ends and midpoint, and Eq. 4's two branches worked by hand.
    #[test]
    fn axial_weight_and_orientation_shift() {
        assert_eq!(axial_weight(0.0), 1.0);
        assert_eq!(axial_weight(1.0), 0.0);
        assert_eq!(axial_weight(0.5), 0.5);
        assert_eq!(axial_weight(-3.0), 1.0);
        // K = 0.5: w^0.5; K = -0.5: w^2.
        assert!((shifted_weight(0.25, 0.5) - 0.5).abs() < 1e-6);
        assert!((shifted_weight(0.5, -0.5) - 0.25).abs() < 1e-6);
        assert_eq!(shifted_weight(0.3, 0.0), 0.3);
    }

    /// The orientation raises the weight on the side it points to and lowers it on the other,
    /// by exactly Eq. 4.
    #[test]
    fn orientation_shifts_the_weight_as_eq_4_says() {
        let plain = field(Domain::Periodic, 0.0, 4);
        let shifted = field(Domain::Periodic, 0.5, 4);
        let c = shifted.centres[0];
        let v = shifted.orientations[0];
        for (side, sign) in [("towards", 1.0f32), ("away from", -1.0)] {
            let u = c + v * 0.03 * sign;
            let w = plain.weight(0, u);
            let k = 0.5 * sign;
            assert!(w > 0.0 && w < 1.0);
            let expected = if k >= 0.0 { w.powf(1.0 - k) } else { w.powf(1.0 / (1.0 + k)) };
            assert!((shifted.weight(0, u) - expected).abs() < 1e-6, "{side}");
            assert!((shifted.weight(0, u) > w) == (sign > 0.0), "{side}");
        }
    }

    #[test]
    fn bad_point_sets_are_errors() {
        let points = |p: Vec<Vec2>| {
            let n = p.len();
            ControlPoints::new(p, vec![Vec3::ONE; n], vec![0; n])
        };
        let square = Domain::Square { margin: 0.0 };
        let one = PupsField::new(&points(vec![Vec2::ZERO]), square, 1.0, 0.0).unwrap_err();
        assert!(one.contains("at least three"), "{one}");
        let line = points((0..10).map(|i| Vec2::new(i as f32 * 0.1, 0.5)).collect());
        assert!(PupsField::new(&line, square, 1.0, 0.0).unwrap_err().contains("one line"));
        let nan = points(vec![Vec2::ZERO, Vec2::X, Vec2::new(f32::NAN, 0.5)]);
        assert!(PupsField::new(&nan, square, 1.0, 0.0).unwrap_err().contains("non-finite"));
        let twice = points(vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::Y]);
        assert!(PupsField::new(&twice, square, 1.0, 0.0).unwrap_err().contains("distinct"));
        let close = points(vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::new(1e-7, 0.0)]);
        assert!(PupsField::new(&close, square, 1.0, 0.0).unwrap_err().contains("closer than"));
    }

    /// The normalised weights are a partition of unity (the raw sum is positive everywhere),
    /// and the field is C1: finite differences of the value agree with its slope from both
    /// sides, across Delaunay edges and at control points alike.
    #[test]
    fn weights_cover_the_square_and_the_value_is_c1() {
        let f = field(Domain::Periodic, 0.0, 7);
        let mut sampler = crate::sampling::Sampler::new(9, 0, 0);
        for _ in 0..4000 {
            let u = sampler.next_2d();
            assert!(f.weight_sum(u) > 0.0, "no weight at {u}");
            let mut normalised = 0.0;
            let total = f.weight_sum(u);
            f.for_each_weight(u, |_, w| normalised += w / total);
            assert!((normalised - 1.0).abs() < 1e-5);
        }
        // C1: the one-sided slopes from the left and from the right differ by O(h) (the
        // curvature times h), so a quarter of the step leaves about a quarter of the gap; a
        // kink would leave the jump of the slope whatever h: with the 0.02 allowed for f32
        // rounding (values to about 1e-6 over steps of 5e-4), any kink whose slope jumps by more
        // than 0.04 fails. At random points and at the control points themselves.
        let slope = |u: Vec2, d: Vec2, h: f32| (f.value(u + d * h).x - f.value(u).x) / h;
        let gap = |u: Vec2, d: Vec2, h: f32| (slope(u, d, h) + slope(u, -d, h)).abs();
        let probes: Vec<Vec2> = (0..2000).map(|_| sampler.next_2d()).chain(f.centres[..50].iter().copied()).collect();
        for u in probes {
            for d in [Vec2::X, Vec2::Y] {
                let (coarse, fine) = (gap(u, d, 2e-3), gap(u, d, 5e-4));
                assert!(
                    fine < 0.5 * coarse + 0.02,
                    "slopes at {u} along {d}: gap {coarse} at h = 2e-3, {fine} at h = 5e-4"
                );
            }
        }
    }

    /// Labels (cells): constant around every control point (its own label within a fifth of
    /// the spacing) and changing only where the two largest weights meet: wherever the label
    /// differs between neighbouring samples 1e-3 apart, the two winners' weights at the
    /// midpoint differ by no more than their slopes allow over that step.
    #[test]
    fn labels_are_constant_in_cells_and_change_only_at_boundaries() {
        let f = field(Domain::Periodic, 0.5, 5);
        for (i, c) in f.centres[..f.point_count()].iter().enumerate() {
            for k in 0..8 {
                let a = std::f32::consts::TAU * k as f32 / 8.0;
                let u = *c + Vec2::new(a.cos(), a.sin()) * 0.016;
                assert_eq!(f.label(u), f.labels[i], "around point {i}");
            }
        }
        let top_two = |u: Vec2| {
            let mut w: Vec<(f32, u32)> = Vec::new();
            f.for_each_weight(u, |i, x| w.push((x, f.labels[i])));
            w.sort_by(|a, b| b.0.total_cmp(&a.0));
            w
        };
        let step = 1e-3;
        let mut changes = 0;
        for y in 0..200 {
            for x in 0..999 {
                let (a, b) =
                    (Vec2::new(x as f32 * step, y as f32 / 200.0), Vec2::new((x + 1) as f32 * step, y as f32 / 200.0));
                let (la, lb) = (f.label(a), f.label(b));
                if la != lb {
                    changes += 1;
                    let w = top_two((a + b) * 0.5);
                    // Weight slopes are at most a few over the spacing (0.08): 30 per unit.
                    assert!(w[0].0 - w[1].0 <= 30.0 * step, "label {la} -> {lb} at {a}: weights {w:?}");
                }
            }
        }
        assert!(changes > 100, "{changes} label changes");
    }

    /// A periodic field wraps: the raw field just past the right edge (read through the copies)
    /// equals the field at the left edge.
    #[test]
    fn periodic_fields_wrap_exactly() {
        let f = field(Domain::Periodic, 0.5, 11);
        for k in 0..200 {
            let y = (k as f32 + 0.5) / 200.0;
            for (a, b) in [(Vec2::new(0.0, y), Vec2::new(1.0, y)), (Vec2::new(y, 0.0), Vec2::new(y, 1.0))] {
                assert!((f.value(a) - f.value(b)).abs().max_element() < 1e-5);
                // Through the copies, without wrapping: centres beyond the square.
                let mut raw = (Vec3::ZERO, 0.0);
                for i in 0..f.centres.len() {
                    let w = f.weight(i, b);
                    raw.0 += f.values[f.source[i] as usize] * w;
                    raw.1 += w;
                }
                assert!((raw.0 / raw.1 - f.value(a)).abs().max_element() < 1e-4, "at {a}");
            }
        }
    }
}
