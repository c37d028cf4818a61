//! Watertight ray-triangle intersection (Woop, Benthin, Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)).

use crate::geometry::Ray;
use glam::Vec3;

/// Per-ray constants: the axis permutation that makes the direction's largest component z, and
/// the shear that maps the ray onto the +z axis.
pub(super) struct RayShear {
    origin: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
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
        RayShear { origin: ray.o, kx, ky, kz, sx: d[kx] * sz, sy: d[ky] * sz, sz }
    }

    /// `(t, b1, b2)` of the hit with `0 < t < t_max`, or None.
    #[inline(always)]
    pub(super) fn intersect(&self, tri: &[Vec3; 3], t_max: f32) -> Option<(f32, f32, f32)> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = tri[0] - self.origin;
        let b = tri[1] - self.origin;
        let c = tri[2] - self.origin;
        let (ax, ay) = (a[kx] - self.sx * a[kz], a[ky] - self.sy * a[kz]);
        let (bx, by) = (b[kx] - self.sx * b[kz], b[ky] - self.sy * b[kz]);
        let (cx, cy) = (c[kx] - self.sx * c[kz], c[ky] - self.sy * c[kz]);
        // Scaled barycentrics: signed areas of the sheared triangle seen from the ray.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // On an edge, recompute in double precision so that neighbours agree (paper, sec. 3).
        if u == 0.0 || v == 0.0 || w == 0.0 {
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (az, bz, cz) = (self.sz * a[kz], self.sz * b[kz], self.sz * c[kz]);
        let t_scaled = u * az + v * bz + w * cz;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some((t, v * inv_det, w * inv_det))
    }
}
