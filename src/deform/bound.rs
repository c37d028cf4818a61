//! What no deformation field can do better than on a given UV map (issue 20's targets).
//!
//! F is read from a map over UV space, so inside a chart it is continuous: at a point of an
//! edge between two faces A and B of one chart, both faces read the same F. Their texture maps
//! to the surface, D = J F^-1 (J = d position / d uv, DESIGN.md section 3), then differ by the
//! UV map's own jump, D_B = L D_A with L = J_B J_A^-1 (B unfolded into A's plane; L keeps the
//! edge's direction). Whatever F is:
//! - the texture's x axis turns by L across the edge while the orientation field turns by its
//!   own jump, so one of the two faces is off the field by at least the smallest
//!   max(angle(a, o_A), angle(L a, o_B)) over the directions a;
//! - the anisotropy of D_A and D_B cannot both be below sqrt(sigma_1 / sigma_2 of L), since
//!   that of L D_A is at least L's divided by D_A's;
//! - ln of the texture's scale, ln det D, jumps by ln det L.
//!
//! These bounds hold at the edges' points; the figures of [`super::analysis`] are taken at the
//! triangles' centres, where F is whatever the smoothing made it.

use super::Orientation;
use super::analysis::AngleError;
use super::deformation_gradient;
use super::edges::manifold_edges;
use crate::geometry::TriangleMesh;
use glam::{DVec2, Mat2, Vec2};

/// Lower bounds on the texture's orientation error and distortion at the edges inside charts,
/// for any F continuous in UV, edge-length weighted.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct ContinuityBound {
    /// The larger of the two faces' orientation errors, at its smallest over F; None without an
    /// orientation field.
    pub orientation: Option<AngleError>,
    /// The larger of the two faces' anisotropies sigma_1 / sigma_2, at its smallest over F:
    /// sqrt of L's; mean.
    pub anisotropy: f64,
    /// |ln det L|, the jump of ln(texture area) across the edge whatever F is: root mean square.
    pub log_area_jump: f64,
    /// Edges measured.
    pub edges: usize,
}

/// The bounds of [`ContinuityBound`] over the edges inside charts of `mesh` (cut edges, whose
/// sides read F at different UVs, constrain nothing), the orientation field per triangle from
/// `orientation`. None without UVs or such edges.
pub fn continuity_bound(mesh: &TriangleMesh, orientation: &Orientation) -> Option<ContinuityBound> {
    let directions = orientation.per_triangle(mesh);
    let (mut angles, mut total, mut anisotropy, mut log_area2, mut edges) = (Vec::new(), 0.0, 0.0, 0.0, 0);
    for edge in manifold_edges(mesh)?.iter().filter(|e| !e.cut) {
        // Each face's Jacobian in the first face's plane, the second unfolded.
        let jacobian = |side: usize| {
            let face = &edge.faces[side];
            let j = deformation_gradient(face.x, face.u)?;
            Some(Mat2::from_cols(edge.flat(side, j.x_axis), edge.flat(side, j.y_axis)))
        };
        let (Some(ja), Some(jb)) = (jacobian(0), jacobian(1)) else { continue };
        let jump = jb * ja.inverse();
        let det = jump.determinant();
        if !(det > 0.0 && det.is_finite()) {
            continue;
        }
        let weight = edge.length as f64;
        let field = |side: usize| directions[edge.faces[side].index].and_then(|o| edge.flat(side, o).try_normalize());
        if let (Some(oa), Some(ob)) = (field(0), field(1)) {
            angles.push((least_larger_angle(jump, oa, ob), weight));
        }
        let (s1, s2) = singular_values(jump);
        anisotropy += weight * (s1 / s2).sqrt();
        log_area2 += weight * (det as f64).ln().powi(2);
        total += weight;
        edges += 1;
    }
    (total > 0.0).then(|| ContinuityBound {
        orientation: AngleError::of(angles),
        anisotropy: anisotropy / total,
        log_area_jump: (log_area2 / total).sqrt(),
        edges,
    })
}

/// min over unit a of max(angle(a, `oa`), angle(`jump` a, `ob`)), in degrees: the best of a
/// grid of 10-degree steps, then a golden-section search within a step of it.
fn least_larger_angle(jump: Mat2, oa: Vec2, ob: Vec2) -> f64 {
    use std::f64::consts::{PI, TAU};
    let jump = jump.as_dmat2();
    let (to_a, to_b) = (f64::from(oa.y).atan2(f64::from(oa.x)), f64::from(ob.y).atan2(f64::from(ob.x)));
    let apart = |p: f64, q: f64| (p - q + PI).rem_euclid(TAU) - PI;
    let larger = |phi: f64| {
        let turned = jump * DVec2::from_angle(phi);
        apart(phi, to_a).abs().max(apart(turned.y.atan2(turned.x), to_b).abs())
    };
    let step = TAU / 36.0;
    let best = (0..36).map(|k| k as f64 * step).min_by(|p, q| larger(*p).total_cmp(&larger(*q))).expect("36 points");
    let (mut low, mut high) = (best - step, best + step);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..48 {
        let (p, q) = (high - ratio * (high - low), low + ratio * (high - low));
        if larger(p) < larger(q) {
            high = q;
        } else {
            low = p;
        }
    }
    larger((low + high) / 2.0).to_degrees()
}

/// Singular values sigma_1 >= sigma_2 of a 2x2 matrix, in f64.
fn singular_values(m: Mat2) -> (f64, f64) {
    let [a, b, c, d] = m.to_cols_array().map(f64::from);
    // sigma^2 are the eigenvalues of M^T M: trace t and determinant (ad - bc)^2.
    let t = a * a + b * b + c * c + d * d;
    let det = a * d - b * c;
    let disc = (t * t / 4.0 - det * det).max(0.0).sqrt();
    let s1 = (t / 2.0 + disc).sqrt();
    (s1, det.abs() / s1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The unit square in the plane z = 0 as two triangles meeting on the diagonal from (1, 0)
    /// to (0, 1), the corner (1, 1) given the UV (c, c): the UV map is the identity on the first
    /// triangle and turns the second into L = [[c, 1 - c], [1 - c, c]] / (2c - 1), which keeps the
    /// diagonal and stretches across it by 1 / (2c - 1).
    fn sheared_square(c: f32) -> TriangleMesh {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::splat(c)];
        TriangleMesh { positions, normals: None, uvs: Some(uvs), indices: vec![[0, 1, 2], [1, 3, 2]] }
    }

    #[test]
    fn an_isometric_uv_map_bounds_nothing() {
        let b = continuity_bound(&sheared_square(1.0), &Orientation::Fixed(Vec3::X)).expect("one inner edge");
        assert_eq!(b.edges, 1);
        assert!(b.orientation.expect("a field").mean < 0.01);
        assert!((b.anisotropy - 1.0).abs() < 1e-6 && b.log_area_jump < 1e-6, "{b:?}");
    }

    #[test]
    fn a_uv_jump_bounds_the_error_as_the_algebra_says() {
        // c = 3/4: L = [[1.5, 0.5], [0.5, 1.5]], singular values 2 and 1, det 2. The field
        // (1, 0) on both faces: the best axis a at angle phi has L a at -phi, that is
        // tan^2 phi + 6 tan phi + 1 = 0, phi = atan(2 sqrt 2 - 3), 9.7356 degrees.
        let b = continuity_bound(&sheared_square(0.75), &Orientation::Fixed(Vec3::X)).expect("one inner edge");
        let expected = (2.0f64.sqrt() * 2.0 - 3.0).atan().to_degrees().abs();
        let orientation = b.orientation.expect("a field");
        assert!((orientation.mean - expected).abs() < 0.01, "{orientation:?} against {expected}");
        assert!((b.anisotropy - 2.0f64.sqrt()).abs() < 1e-5, "{b:?}");
        assert!((b.log_area_jump - 2.0f64.ln()).abs() < 1e-5, "{b:?}");
    }
}
