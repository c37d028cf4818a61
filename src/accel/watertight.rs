//! Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)).
//!
//! The paper permutes the axes so that the ray direction's largest component is z, then shears
//! the ray onto +z. Both steps are linear, so they are folded here into one per-ray 3x3 matrix
//! applied to each vertex (relative to the ray origin): the same arithmetic, without branching
//! on the permutation per triangle.

use crate::geometry::Ray;
use glam::{Mat3A, Vec3, Vec3A};

/// Per-ray constants: the origin and the permute-and-shear transform.
pub(super) struct RayShear {
    origin: Vec3A,
    /// Rows: (e_kx - Sx e_kz), (e_ky - Sy e_kz), Sz e_kz.
    shear: Mat3A,
}

impl RayShear {
    pub(super) fn new(ray: &Ray) -> Self {
        let d = ray.d;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding: swap when the dominant component is negative.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / d[kz];
        let (sx, sy) = (d[kx] * sz, d[ky] * sz);
        let e = |k: usize| Vec3A::from(Vec3::AXES[k]);
        let rows = [e(kx) - e(kz) * sx, e(ky) - e(kz) * sy, e(kz) * sz];
        RayShear { origin: Vec3A::from(ray.o), shear: Mat3A::from_cols(rows[0], rows[1], rows[2]).transpose() }
    }

    /// `(t, b1, b2)` of the hit with `0 < t < t_max`, or None.
    #[inline(always)]
    pub(super) fn intersect(&self, tri: &[Vec3A; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let a = self.shear * (tri[0] - self.origin);
        let b = self.shear * (tri[1] - self.origin);
        let c = self.shear * (tri[2] - self.origin);
        // Scaled barycentrics: signed areas of the sheared triangle seen from the ray.
        let mut u = c.x * b.y - c.y * b.x;
        let mut v = a.x * c.y - a.y * c.x;
        let mut w = b.x * a.y - b.y * a.x;
        // On an edge, recompute in double precision so that neighbours agree (paper, sec. 3).
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = (c.x as f64 * b.y as f64 - c.y as f64 * b.x as f64) as f32;
            v = (a.x as f64 * c.y as f64 - a.y as f64 * c.x as f64) as f32;
            w = (b.x as f64 * a.y as f64 - b.y as f64 * a.x as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let t_scaled = u * a.z + v * b.z + w * c.z;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, v * inv_det, w * inv_det))
    }
}
