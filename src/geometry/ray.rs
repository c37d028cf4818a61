//! Rays and ray differentials.

use glam::Vec3;

/// A ray `o + t d` for `t` in `(0, t_max)`. `d` need not be unit length: shadow rays use
/// `d = target - o` with `t_max` just below 1.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
    /// Largest parameter that counts as a hit.
    pub t_max: f32,
}

impl Ray {
    /// A ray from `o` along `d`, unbounded.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        debug_assert!(o.is_finite() && d.is_finite(), "ray {o} {d}");
        Ray { o, d, t_max: f32::INFINITY }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// The rays through the neighbouring pixels, one pixel to the right (x) and one down (y),
/// used to estimate a hit's texture footprint (Igehy 1999; pbrt-v4 `RayDifferential`).
#[derive(Clone, Copy, Debug)]
pub struct RayDifferential {
    /// Origin of the offset ray in x.
    pub rx_o: Vec3,
    /// Direction of the offset ray in x.
    pub rx_d: Vec3,
    /// Origin of the offset ray in y.
    pub ry_o: Vec3,
    /// Direction of the offset ray in y.
    pub ry_d: Vec3,
}

impl RayDifferential {
    /// Scale the offsets to neighbours that are `scale` pixels away instead of one, relative to
    /// the main ray `ray` (pbrt-v4 `ScaleDifferentials`).
    pub fn scaled(&self, ray: &Ray, scale: f32) -> Self {
        RayDifferential {
            rx_o: ray.o + (self.rx_o - ray.o) * scale,
            rx_d: ray.d + (self.rx_d - ray.d) * scale,
            ry_o: ray.o + (self.ry_o - ray.o) * scale,
            ry_d: ray.d + (self.ry_d - ray.d) * scale,
        }
    }
}
