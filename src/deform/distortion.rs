//! How much texture mapping distorts the texture (issue metric for paper 000 Sec. 4): over the
//! surface, the singular values sigma_1 >= sigma_2 of the composite map surface -> exemplar,
//! d(exemplar) / d(surface) = F(u) J^+ (J = d position / d uv on the triangle, J^+ its
//! pseudo-inverse). A texture without distortion has sigma_1 = sigma_2 (no anisotropy) and the
//! same sigma_1 sigma_2 everywhere (no change of scale).

use super::deformation_gradient;
use crate::geometry::TriangleMesh;
use glam::{Mat2, Vec2};

/// Area-weighted statistics of the composite map's singular values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Distortion {
    /// Area-weighted mean of sigma_1 / sigma_2 (1 for a conformal map).
    pub mean_anisotropy: f64,
    /// Area-weighted standard deviation of ln(sigma_1 sigma_2) (0 for a map of uniform scale).
    pub std_log_area: f64,
    /// Triangles measured (non-degenerate).
    pub triangles: usize,
}

/// The distortion of the texture that reads exemplar coordinates F(u) u (locally) on `mesh`,
/// with F evaluated at each triangle's UV centroid by `f`. None without UVs or valid triangles.
pub fn distortion(mesh: &TriangleMesh, f: impl Fn(Vec2) -> Mat2) -> Option<Distortion> {
    let uvs = mesh.uvs.as_ref()?;
    let (mut total, mut sum_aniso, mut sum_log, mut sum_log2, mut count) = (0.0f64, 0.0, 0.0, 0.0, 0);
    for idx in &mesh.indices {
        let x = idx.map(|i| mesh.positions[i as usize]);
        let u = idx.map(|i| uvs[i as usize]);
        let Some(f3) = deformation_gradient(x, u) else { continue };
        // J^T J in the UV basis; the composite M = F J^+ has M M^T = F (J^T J)^-1 F^T.
        let (a, b) = (f3.x_axis, f3.y_axis);
        let metric = Mat2::from_cols(Vec2::new(a.dot(a), a.dot(b)), Vec2::new(a.dot(b), b.dot(b)));
        if metric.determinant() <= 0.0 {
            continue;
        }
        let fu = f((u[0] + u[1] + u[2]) / 3.0);
        let mmt = fu * metric.inverse() * fu.transpose();
        // Eigenvalues of the symmetric 2x2 M M^T are sigma^2.
        let (tr, det) = ((mmt.x_axis.x + mmt.y_axis.y) as f64, mmt.determinant() as f64);
        let disc = (tr * tr / 4.0 - det).max(0.0).sqrt();
        let (s1, s2) = ((tr / 2.0 + disc).sqrt(), (tr / 2.0 - disc).max(0.0).sqrt());
        if !(s2 > 0.0 && s1.is_finite()) {
            continue;
        }
        let area = a.cross(b).length() as f64 * (u[1] - u[0]).perp_dot(u[2] - u[0]).abs() as f64 / 2.0;
        let log_area = (s1 * s2).ln();
        total += area;
        sum_aniso += area * s1 / s2;
        sum_log += area * log_area;
        sum_log2 += area * log_area * log_area;
        count += 1;
    }
    (total > 0.0).then(|| {
        let mean_log = sum_log / total;
        Distortion {
            mean_anisotropy: sum_aniso / total,
            std_log_area: (sum_log2 / total - mean_log * mean_log).max(0.0).sqrt(),
            triangles: count,
        }
    })
}
