//! Polar decomposition of 3x3 matrices (paper 000 Eq. 5): F = R S with R orthogonal and S
//! symmetric positive definite, from the eigen-decomposition of F^T F = V Sigma^2 V^T:
//! S = V Sigma V^T, R = F S^-1 = U V^T (the SVD's factors).

use glam::{DMat3, DVec3, Mat3};

/// Eigenvalues and unit eigenvectors (the columns of the matrix) of a symmetric 3x3 matrix, by
/// cyclic Jacobi rotations (Golub and Van Loan, Algorithm 8.5.2).
pub fn symmetric_eigen(m: DMat3) -> (DVec3, DMat3) {
    // a[i][j]: row i, column j.
    let mut a: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| m.col(j)[i]));
    let mut v = [[1.0f64, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let scale = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-28 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            // The rotation J (J_pp = J_qq = c, J_pq = s, J_qp = -s) with (J^T A J)_pq = 0.
            let tau = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = tau.signum() / (tau.abs() + (1.0 + tau * tau).sqrt());
            let c = 1.0 / (1.0 + t * t).sqrt();
            let s = t * c;
            for row in a.iter_mut() {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
            let (row_p, row_q) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * row_p[k] - s * row_q[k]);
            a[q] = std::array::from_fn(|k| s * row_p[k] + c * row_q[k]);
            for row in v.iter_mut() {
                let (x, y) = (row[p], row[q]);
                row[p] = c * x - s * y;
                row[q] = s * x + c * y;
            }
        }
    }
    let column = |j: usize| DVec3::new(v[0][j], v[1][j], v[2][j]);
    (DVec3::new(a[0][0], a[1][1], a[2][2]), DMat3::from_cols(column(0), column(1), column(2)))
}

/// F = R S (paper 000 Eq. 5): R orthogonal (a rotation when det F > 0, a reflection when
/// det F < 0), S symmetric positive definite; computed in double precision (F^T F squares
/// F's condition number). None when F is singular relative to its size.
pub fn polar_decomposition(f: Mat3) -> Option<(Mat3, Mat3)> {
    let f = f.as_dmat3();
    let (lambda, v) = symmetric_eigen(f.transpose() * f);
    let largest = lambda.max_element();
    if !(largest > 0.0 && largest.is_finite()) || lambda.min_element() <= 1e-12 * largest {
        return None;
    }
    let sigma = DVec3::new(lambda.x.sqrt(), lambda.y.sqrt(), lambda.z.sqrt());
    let s = v * DMat3::from_diagonal(sigma) * v.transpose();
    let s_inverse = v * DMat3::from_diagonal(sigma.recip()) * v.transpose();
    Some(((f * s_inverse).as_mat3(), s.as_mat3()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Sampler;
    use glam::Vec3;

    fn close(a: Mat3, b: Mat3, tol: f32) -> bool {
        (a - b).to_cols_array().iter().all(|x| x.abs() < tol)
    }

    #[test]
    fn eigen_decomposition_reconstructs_symmetric_matrices() {
        for i in 0..200 {
            let mut s = Sampler::new(1, i, 0);
            let b = Mat3::from_cols_array(&std::array::from_fn(|_| s.next_1d() * 2.0 - 1.0));
            let m = (b + b.transpose()).as_dmat3();
            let (values, vectors) = symmetric_eigen(m);
            assert!(close((vectors.transpose() * vectors).as_mat3(), Mat3::IDENTITY, 1e-6));
            assert!(close((vectors * DMat3::from_diagonal(values) * vectors.transpose()).as_mat3(), m.as_mat3(), 1e-6));
        }
    }

    #[test]
    fn polar_decomposition_factors() {
        for i in 0..500 {
            let mut s = Sampler::new(2, i, 0);
            let f = Mat3::from_cols_array(&std::array::from_fn(|_| s.next_1d() * 4.0 - 2.0));
            let Some((r, sym)) = polar_decomposition(f) else { continue };
            let scale = f.to_cols_array().iter().fold(0.0f32, |m, x| m.max(x.abs()));
            assert!(close(r.transpose() * r, Mat3::IDENTITY, 1e-4), "R not orthogonal for {f}");
            assert!((r.determinant() - f.determinant().signum()).abs() < 1e-4);
            assert!(close(sym, sym.transpose(), 1e-5 * scale));
            let (lambda, _) = symmetric_eigen(sym.as_dmat3());
            assert!(lambda.min_element() > 0.0, "S not positive definite for {f}");
            assert!(close(r * sym, f, 1e-4 * scale), "R S != F for {f}");
        }
        // A rotation times a stretch comes back as itself.
        let rot = Mat3::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let stretch = Mat3::from_cols(Vec3::new(2.0, 0.5, 0.0), Vec3::new(0.5, 1.0, 0.0), Vec3::Z);
        let (r, s) = polar_decomposition(rot * stretch).unwrap();
        assert!(close(r, rot, 1e-5) && close(s, stretch, 1e-5));
        assert!(polar_decomposition(Mat3::from_cols(Vec3::X, Vec3::X, Vec3::Z)).is_none());
    }
}
