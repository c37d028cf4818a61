//! Emissive triangle meshes (Mitsuba's `area` emitter): constant radiance leaving the front
//! side (the side the counter-clockwise winding faces).

use super::LightSample;
use crate::color::Rgb;
use crate::geometry::offset_ray_origin;
use crate::sampling::{Distribution1D, warp};
use glam::{Vec2, Vec3};

/// A mesh that emits `radiance` from the front of each of its triangles.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Radiance emitted towards the front side.
    pub radiance: Rgb,
    triangles: Vec<[Vec3; 3]>,
    /// Unit geometric normal of each triangle (the front side).
    normals: Vec<Vec3>,
    by_area: Distribution1D,
    area: f32,
}

impl AreaLight {
    /// A light over the given triangles (world space).
    pub fn new(triangles: Vec<[Vec3; 3]>, radiance: Rgb) -> Self {
        let cross: Vec<Vec3> = triangles.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a)).collect();
        let areas: Vec<f32> = cross.iter().map(|c| 0.5 * c.length()).collect();
        let area = areas.iter().sum();
        let normals = cross.iter().map(|c| c.normalize()).collect();
        AreaLight { radiance, by_area: Distribution1D::new(&areas), triangles, normals, area }
    }

    /// Total surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Radiance leaving a point with geometric normal `n` in direction `w` (towards the viewer).
    #[inline]
    pub fn emitted(&self, n: Vec3, w: Vec3) -> Rgb {
        if n.dot(w) > 0.0 { self.radiance } else { Rgb::ZERO }
    }

    /// Sample a point uniformly by area and convert to solid angle at `p`.
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let pick = self.by_area.sample_discrete(u.x);
        let [a, b, c] = self.triangles[pick.index];
        let bary = warp::square_to_uniform_triangle(Vec2::new(pick.u_remapped, u.y));
        let q = a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y;
        let n = self.normals[pick.index];
        let to_light = q - p;
        let dist2 = to_light.length_squared();
        let wi = to_light / dist2.sqrt();
        let cos_light = -n.dot(wi);
        if cos_light <= 0.0 || dist2 == 0.0 {
            return None;
        }
        let pdf = dist2 / (cos_light * self.area);
        Some(LightSample { wi, radiance: self.radiance, pdf, point: Some(offset_ray_origin(q, n, -wi)), delta: false })
    }

    /// Solid-angle density at `p` of sampling the point `q` with geometric normal `n`; zero where
    /// `p` sees the back of the light, since [`AreaLight::sample`] returns nothing there.
    pub fn pdf(&self, p: Vec3, q: Vec3, n: Vec3) -> f32 {
        let d = p - q;
        let dist2 = d.length_squared();
        let cos = n.dot(d) / dist2.sqrt();
        if !(cos > 0.0) { 0.0 } else { dist2 / (cos * self.area) }
    }
}
