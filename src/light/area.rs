//! Emissive triangle meshes and spheres (Mitsuba's `area` emitter): constant radiance leaving
//! the front side (the side the counter-clockwise winding or the sphere's normal faces).

use super::LightSample;
use crate::color::Rgb;
use crate::geometry::{Sphere, offset_ray_origin_of};
use crate::sampling::{Distribution1D, warp};
use crate::simd::{Real, V3};
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
            EmittingSurface::Triangles { .. } => {
                let (triangle, n, u_remapped) = self.pick_triangle(u.x).expect("a mesh light");
                let (q, pdf) =
                    triangle_point_of(p.into(), triangle.map(V3::from), n.into(), [u_remapped, u.y], self.area);
                (q.into(), n, pdf)
            }
            EmittingSurface::Sphere(sphere) => {
                let s = sphere.sample_from(p, u)?;
                (s.point, s.normal, s.pdf)
            }
        };
        let toward = toward_light_of(p.into(), q.into(), n.into(), pdf);
        if !toward.valid {
            return None;
        }
        let (wi, point) = (toward.wi.into(), toward.point.into());
        Some(LightSample { wi, radiance: self.radiance, pdf, point: Some(point), delta: false })
    }

    /// For a mesh light, the triangle that `u` picks in proportion to its area, its unit normal,
    /// and `u` remapped to [0, 1) within the pick, for the point on it; None for a sphere.
    #[inline]
    pub fn pick_triangle(&self, u: f32) -> Option<([Vec3; 3], Vec3, f32)> {
        let EmittingSurface::Triangles { triangles, normals, by_area } = &self.surface else {
            return None;
        };
        let pick = by_area.sample_discrete(u);
        Some((triangles[pick.index], normals[pick.index], pick.u_remapped))
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

/// A point q of the triangle with unit normal `n` drawn uniformly by area with `u`, and the
/// solid-angle density at `p` of drawing it, |q - p|^2 / (cos theta_q `area`), `area` being the
/// light's total area (the triangle was chosen in proportion to its own); in one lane or eight.
#[inline(always)]
pub fn triangle_point_of<T: Real>(p: V3<T>, [a, b, c]: [V3<T>; 3], n: V3<T>, u: [T; 2], area: T) -> (V3<T>, T) {
    let (b1, b2) = warp::square_to_uniform_triangle_of(u);
    let q = a * (T::splat(1.0) - b1 - b2) + b * b1 + c * b2;
    let d = q - p;
    let dist2 = d.dot(d);
    let cos_light = -n.dot(d / dist2.sqrt());
    (q, dist2 / (cos_light * area))
}

/// The direction from `p` to a light's point `q` (unit normal `n`, drawn with density `pdf`),
/// the point offset off the light towards `p` for the shadow ray, and whether the sample holds:
/// `p` in front of the light, apart from it, with a positive density.
#[derive(Clone, Copy, Debug)]
pub struct TowardLight<T: Real> {
    /// Unit direction from `p` to `q`.
    pub wi: V3<T>,
    /// `q` offset off the light's surface towards `p` ([`crate::geometry::offset_ray_origin`]).
    pub point: V3<T>,
    /// Where the sample holds.
    pub valid: T::Mask,
}

/// [`TowardLight`] from `p` to the light's point `q`, in one lane or eight.
#[inline(always)]
pub fn toward_light_of<T: Real>(p: V3<T>, q: V3<T>, n: V3<T>, pdf: T) -> TowardLight<T> {
    let zero = T::splat(0.0);
    let to_light = q - p;
    let dist2 = to_light.dot(to_light);
    let wi = to_light / dist2.sqrt();
    let valid = n.dot(wi).lt(zero) & zero.lt(dist2) & zero.lt(pdf);
    TowardLight { wi, point: offset_ray_origin_of(q, n, -wi), valid }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::F32x8;
    use crate::simd::testing::{direction, gather, isas, lane, numbers};

    #[test]
    fn lanes_sample_a_triangle_bit_for_bit_as_one_point_does() {
        let [a, b, c] = [Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, -0.5), Vec3::new(0.5, 2.1, 0.5)];
        let n = (b - a).cross(c - a).normalize();
        let area = 0.7;
        for isa in isas() {
            for chunk in 0..2000 {
                // Shading points around the triangle, in front of it and behind, and on it.
                let p = |i: usize| match (chunk + i) % 61 {
                    0 => a,
                    _ => direction(chunk * 8 + i) * 3.0 + Vec3::Y,
                };
                let u = |i: usize| numbers(chunk, i);
                let (q, pdf, toward) = isa.run(|| {
                    let u = [F32x8::from_fn(|i| u(i)[0]), F32x8::from_fn(|i| u(i)[1])];
                    let (q, pdf) = triangle_point_of(
                        gather(p),
                        [a, b, c].map(|v| gather(|_| v)),
                        gather(|_| n),
                        u,
                        F32x8::splat(area),
                    );
                    (q, pdf, toward_light_of(gather(p), q, gather(|_| n), pdf))
                });
                for i in 0..8 {
                    let (one_q, one_pdf) =
                        triangle_point_of(p(i).into(), [a, b, c].map(V3::from), n.into(), u(i), area);
                    let one = toward_light_of(p(i).into(), one_q, n.into(), one_pdf);
                    let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                    assert_eq!(
                        (bits(lane(q, i)), pdf.0[i].to_bits(), bits(lane(toward.wi, i)), bits(lane(toward.point, i))),
                        (bits(one_q.into()), one_pdf.to_bits(), bits(one.wi.into()), bits(one.point.into())),
                        "{isa:?} p {} u {:?}",
                        p(i),
                        u(i)
                    );
                    assert_eq!(toward.valid.test(i), one.valid, "{isa:?} p {}", p(i));
                }
            }
        }
    }
}
