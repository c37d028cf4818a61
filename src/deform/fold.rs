//! The fold-over criterion of a tile's lookup (paper 000 Sec. 7, its open "cracks" problem): a
//! tile centred at c reads the exemplar at F(u)(u - c), whose Jacobian in u is
//! F(u) + dF(u - c) (column k: F e_k + (dF/du_k)(u - c)). Where F varies faster than a tile
//! spans, that Jacobian loses det F's sign (the lookup folds over itself: cracks, mirrored
//! content) or stretches the content against F by more than 2:1. A tile that reads F at its
//! centre instead, F(c)(u - c), is affine and folds only where det F changes sign.

use crate::math::largest_singular_value;
use glam::{Mat2, Vec2};

/// Directions of tile centres tried around a point.
pub const DIRECTIONS: usize = 8;

/// What a tile's lookup does near a point, over tile centres in every direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum LookupFold {
    /// Injective and within 2:1 of F.
    Fine,
    /// Injective, but stretched against F by more than 2:1.
    Stretched,
    /// Not injective: its Jacobian's determinant is 0 or of the other sign than det F.
    Folded,
}

/// How the lookup F(u)(u - c) ([`FieldAt::Point`]) behaves at u, given F = F(u) and its derivatives `du`, `dv`, for
/// tile centres c at distance `reach` in [`DIRECTIONS`] directions. None where F is singular.
///
/// [`FieldAt::Point`]: crate::texture::tiling_blending::FieldAt::Point
pub fn lookup_fold(f: Mat2, du: Mat2, dv: Mat2, reach: f32) -> Option<LookupFold> {
    let det = f.determinant();
    if !(det.abs() > 1e-12) {
        return None;
    }
    let inverse = f.inverse();
    let mut outcome = LookupFold::Fine;
    for k in 0..DIRECTIONS {
        let d = Vec2::from_angle(k as f32 * std::f32::consts::TAU / DIRECTIONS as f32) * reach;
        // d/du_k of F(u)(u - c) = F e_k + (dF/du_k)(u - c), with u - c = d.
        let jacobian = Mat2::from_cols(f.x_axis + du * d, f.y_axis + dv * d);
        if !(jacobian.determinant() / det > 0.0) {
            return Some(LookupFold::Folded);
        }
        if beyond_two_to_one(jacobian * inverse) {
            outcome = LookupFold::Stretched;
        }
    }
    Some(outcome)
}

/// How the lookup F(c)(u - c) of a tile that reads F at its centre c ([`FieldAt::TileCentre`])
/// behaves at u, F(u) = `f_u`, F(c) = `f_c`: affine, it folds only where det F(c) has not det
/// F(u)'s sign, and stretches where F(c) F(u)^-1 is beyond 2:1. None where F(u) is singular.
///
/// [`FieldAt::TileCentre`]: crate::texture::tiling_blending::FieldAt::TileCentre
pub fn centred_fold(f_u: Mat2, f_c: Mat2) -> Option<LookupFold> {
    let det = f_u.determinant();
    if !(det.abs() > 1e-12) {
        return None;
    }
    Some(if !(f_c.determinant() / det > 0.0) {
        LookupFold::Folded
    } else if beyond_two_to_one(f_c * f_u.inverse()) {
        LookupFold::Stretched
    } else {
        LookupFold::Fine
    })
}

/// Whether a singular value of `relative` (a lookup's Jacobian times F^-1) is above 2 or below
/// 1/2 (s_max s_min = |det|).
fn beyond_two_to_one(relative: Mat2) -> bool {
    let s_max = largest_singular_value(relative);
    s_max > 2.0 || relative.determinant().abs() / s_max < 0.5
}
