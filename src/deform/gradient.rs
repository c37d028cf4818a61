//! Per-triangle deformation of a UV-mapped mesh (paper 000 Sec. 4.1-4.3): the deformation
//! gradient (Eq. 4), its polar decomposition (Eq. 5), the stretch in the UV plane and the
//! orientation angle (Eq. 6).

use crate::math::polar_decomposition;
use glam::{Mat2, Mat3, Vec2, Vec3};

/// F3 = [x01 x02 n] [u01 u02 e3]^-1 (Eq. 4): the linear map from the extended UV space to 3D
/// that sends each UV edge of the triangle to its 3D edge and e3 to the unit normal. None when
/// the triangle is degenerate in 3D or in UV.
pub fn deformation_gradient(x: [Vec3; 3], u: [Vec2; 3]) -> Option<Mat3> {
    let (x01, x02) = (x[1] - x[0], x[2] - x[0]);
    let n = x01.cross(x02);
    let area2 = n.length();
    let scale = x01.length_squared().max(x02.length_squared());
    if !(area2 > 1e-12 * scale && area2.is_finite()) {
        return None;
    }
    let (u01, u02) = (u[1] - u[0], u[2] - u[0]);
    let uv_area2 = u01.perp_dot(u02);
    let uv_scale = u01.length_squared().max(u02.length_squared());
    if !(uv_area2.abs() > 1e-12 * uv_scale && uv_area2.is_finite()) {
        return None;
    }
    let geometric = Mat3::from_cols(x01, x02, n / area2);
    let parametric = Mat3::from_cols(u01.extend(0.0), u02.extend(0.0), Vec3::Z);
    Some(geometric * parametric.inverse())
}

/// The texture's x axis on the surface, J F^-1 e1 (DESIGN.md section 3), unit length, for a
/// triangle whose deformation gradient is `j` ([`deformation_gradient`]) and F = `f`; None where
/// F is singular or the axis degenerate.
pub fn texture_axis(j: Mat3, f: Mat2) -> Option<Vec3> {
    if !(f.determinant().abs() > 1e-12) {
        return None;
    }
    let axis_uv = f.inverse() * Vec2::X;
    (j.x_axis * axis_uv.x + j.y_axis * axis_uv.y).try_normalize()
}

/// What the texture synthesis needs of one triangle: F3 = R S (Eq. 5) reduced to the UV plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleDeformation {
    /// R: carries UV directions to the surface isometrically (orthogonal; a reflection where the
    /// triangle's UVs are mirrored).
    pub rotation: Mat3,
    /// The top-left 2x2 block of S (Sec. 4.2): sqrt(J^T J), J = d position / d uv.
    pub stretch: Mat2,
}

impl TriangleDeformation {
    /// Eq. 4 and 5 for a triangle; None when it is degenerate.
    pub fn new(x: [Vec3; 3], u: [Vec2; 3]) -> Option<Self> {
        let (rotation, s) = polar_decomposition(deformation_gradient(x, u)?)?;
        let stretch = Mat2::from_cols(s.x_axis.truncate(), s.y_axis.truncate());
        Some(TriangleDeformation { rotation, stretch })
    }

    /// Whether the triangle's UVs are mirrored (R is a reflection).
    pub fn mirrored(&self) -> bool {
        self.rotation.determinant() < 0.0
    }

    /// The angle theta of F = R(theta) [M] S (Eq. 6 and Sec. 4.3; M where the UVs are mirrored)
    /// that turns the texture's own x axis onto the tangent `direction`: the x axis reaches the
    /// surface along J F^-1 e1 = R [M] R(-theta) e1, which is along `direction` when
    /// theta = -angle of [M] R^-1 direction from e1. Zero when `direction` has no part in the
    /// triangle's plane.
    pub fn orientation_angle(&self, direction: Vec3) -> f32 {
        let local = self.rotation.transpose() * direction;
        let y = if self.mirrored() { -local.y } else { local.y };
        if local.truncate().length_squared() > 1e-20 { -y.atan2(local.x) } else { 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deform::FieldSample;

    #[test]
    fn gradient_of_an_affine_uv_map_is_that_map() {
        // x = A u + b with A a 3x2 map: F3 sends e1, e2 to A's columns and e3 to the normal.
        let (a1, a2, b) = (Vec3::new(2.0, 0.5, -1.0), Vec3::new(0.3, 1.5, 0.7), Vec3::new(4.0, -2.0, 1.0));
        let u = [Vec2::new(0.1, 0.2), Vec2::new(0.7, 0.25), Vec2::new(0.3, 0.9)];
        let x = u.map(|u| a1 * u.x + a2 * u.y + b);
        let f = deformation_gradient(x, u).unwrap();
        assert!((f * Vec3::X - a1).length() < 1e-5 && (f * Vec3::Y - a2).length() < 1e-5);
        assert!((f * Vec3::Z - a1.cross(a2).normalize()).length() < 1e-5);
        // Its stretch is sqrt(A^T A).
        let d = TriangleDeformation::new(x, u).unwrap();
        let ata = Mat2::from_cols(Vec2::new(a1.dot(a1), a1.dot(a2)), Vec2::new(a2.dot(a1), a2.dot(a2)));
        let s2 = d.stretch * d.stretch;
        assert!((s2 - ata).to_cols_array().iter().all(|e| e.abs() < 1e-4), "{s2} vs {ata}");
    }

    #[test]
    fn degenerate_triangles_have_no_gradient() {
        let u = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let x = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(deformation_gradient(x, u).is_some());
        assert!(deformation_gradient([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], u).is_none());
        assert!(deformation_gradient(x, [Vec2::ZERO, Vec2::X, Vec2::X * 3.0]).is_none());
        assert!(deformation_gradient([Vec3::ZERO, Vec3::X, Vec3::NAN], u).is_none());
    }

    #[test]
    fn orientation_turns_the_texture_onto_the_direction() {
        // A skewed, stretched UV map of a triangle in 3D.
        let u = [Vec2::new(0.1, 0.2), Vec2::new(0.5, 0.3), Vec2::new(0.2, 0.6)];
        let x = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.2, 0.3), Vec3::new(-0.2, 0.9, 0.4)];
        let d = TriangleDeformation::new(x, u).unwrap();
        let j = deformation_gradient(x, u).unwrap();
        let n = (x[1] - x[0]).cross(x[2] - x[0]).normalize();
        for direction in [Vec3::X, Vec3::new(0.3, -1.0, 0.2), Vec3::Y + Vec3::Z] {
            let theta = d.orientation_angle(direction);
            let f = FieldSample { direction: Vec2::from_angle(theta), stretch: d.stretch }.deformation(d.mirrored());
            let along = f.inverse() * Vec2::X;
            let on_surface = (j * along.extend(0.0)).normalize();
            let tangent = (direction - n * n.dot(direction)).normalize();
            assert!(on_surface.distance(tangent) < 1e-4, "{on_surface} vs {tangent}");
        }
    }

    #[test]
    fn mirrored_uvs_get_a_mirrored_f_and_an_unmirrored_texture() {
        // The same triangle with its UVs mirrored (v -> -v): the texture must still reach the
        // surface with its x axis along the direction and its y axis on the side n x x.
        let u = [Vec2::new(0.1, -0.2), Vec2::new(0.5, -0.3), Vec2::new(0.2, -0.6)];
        let x = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.2, 0.3), Vec3::new(-0.2, 0.9, 0.4)];
        let d = TriangleDeformation::new(x, u).unwrap();
        assert!(d.mirrored());
        let j = deformation_gradient(x, u).unwrap();
        let n = (x[1] - x[0]).cross(x[2] - x[0]).normalize();
        for direction in [Vec3::X, Vec3::new(0.3, -1.0, 0.2)] {
            let f = FieldSample { direction: Vec2::from_angle(d.orientation_angle(direction)), stretch: d.stretch }
                .deformation(d.mirrored());
            assert!(f.determinant() < 0.0);
            let inverse = f.inverse();
            let x_axis = j * (inverse * Vec2::X).extend(0.0);
            let y_axis = j * (inverse * Vec2::Y).extend(0.0);
            let tangent = (direction - n * n.dot(direction)).normalize();
            assert!(x_axis.normalize().distance(tangent) < 1e-4, "{x_axis} vs {tangent}");
            // A similarity onto the surface, keeping the surface's orientation.
            assert!(y_axis.normalize().distance(n.cross(x_axis).normalize()) < 1e-4);
            assert!((x_axis.length() - y_axis.length()).abs() < 1e-4 * x_axis.length());
        }
    }
}
