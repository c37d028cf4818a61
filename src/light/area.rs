//! Emissive triangle meshes and spheres (Mitsuba's `area` emitter): constant radiance leaving
//! the front side (the side the counter-clockwise winding or the sphere's normal faces).

use super::LightSample;
use crate::color::Rgb;
use crate::geometry::{Sphere, offset_ray_origin};
use crate::sampling::{Distribution1D, warp};
use glam::{Vec2, Vec3};

/// A surface that emits `radiance` from its front: triangles of a mesh, or an exact sphere.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// Radiance emitted towards the front side.
    pub radiance: Rgb,
    surface: EmittingSurface,
    area: f32,
}

#[derive(Clone, Debug)]
enum EmittingSurface {
    /// Triangles sampled by area, each with its unit geometric normal (the front side).
    Triangles { triangles: Vec<[Vec3; 3]>, normals: Vec<Vec3>, by_area: Distribution1D },
    /// A sphere, sampled over the cone it subtends ([`Sphere::sample_from`]).
    Sphere(Sphere),
}

impl AreaLight {
    /// A light over the given triangles (world space).
    pub fn new(triangles: Vec<[Vec3; 3]>, radiance: Rgb) -> Self {
        let cross: Vec<Vec3> = triangles.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a)).collect();
        let areas: Vec<f32> = cross.iter().map(|c| 0.5 * c.length()).collect();
        let area = areas.iter().sum();
        let normals = cross.iter().map(|c| c.normalize()).collect();
        let surface = EmittingSurface::Triangles { by_area: Distribution1D::new(&areas), triangles, normals };
        AreaLight { radiance, surface, area }
    }

    /// A light over an exact sphere (Mitsuba's `area` emitter on a `sphere`).
    pub fn sphere(sphere: Sphere, radiance: Rgb) -> Self {
        AreaLight { radiance, area: sphere.area(), surface: EmittingSurface::Sphere(sphere) }
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

    /// Sample a point seen from `p`: on triangles uniformly by area, on a sphere uniformly over
    /// the directions it subtends; the density is converted to solid angle at `p`.
    pub fn sample(&self, p: Vec3, u: Vec2) -> Option<LightSample> {
        let (q, n, pdf) = match &self.surface {
            EmittingSurface::Triangles { triangles, normals, by_area } => {
                let pick = by_area.sample_discrete(u.x);
                let [a, b, c] = triangles[pick.index];
                let bary = warp::square_to_uniform_triangle(Vec2::new(pick.u_remapped, u.y));
                let q = a * (1.0 - bary.x - bary.y) + b * bary.x + c * bary.y;
                let n = normals[pick.index];
                let dist2 = (q - p).length_squared();
                let cos_light = -n.dot((q - p) / dist2.sqrt());
                (q, n, dist2 / (cos_light * self.area))
            }
            EmittingSurface::Sphere(sphere) => {
                let s = sphere.sample_from(p, u)?;
                (s.point, s.normal, s.pdf)
            }
        };
        let to_light = q - p;
        let dist2 = to_light.length_squared();
        let wi = to_light / dist2.sqrt();
        if !(n.dot(wi) < 0.0 && dist2 > 0.0 && pdf > 0.0) {
            return None;
        }
        Some(LightSample { wi, radiance: self.radiance, pdf, point: Some(offset_ray_origin(q, n, -wi)), delta: false })
    }

    /// Solid-angle density at `p` of sampling the point `q` with geometric normal `n`, reached
    /// from `p` along the unit direction `w`; zero where `p` sees the back of a triangle, since
    /// [`AreaLight::sample`] returns nothing there. A sphere's is the density of `w`
    /// ([`Sphere::pdf_from`]), a triangle's that of `q`.
    pub fn pdf(&self, p: Vec3, w: Vec3, q: Vec3, n: Vec3) -> f32 {
        match &self.surface {
            EmittingSurface::Triangles { .. } => {
                let d = p - q;
                let dist2 = d.length_squared();
                let cos = n.dot(d) / dist2.sqrt();
                if !(cos > 0.0) { 0.0 } else { dist2 / (cos * self.area) }
            }
            EmittingSurface::Sphere(sphere) => sphere.pdf_from(p, w),
        }
    }
}
