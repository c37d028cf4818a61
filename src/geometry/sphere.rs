//! The exact sphere (Mitsuba 3's `sphere`): intersection in closed form, its UVs, tangents and
//! normal, and sampling of the directions it subtends, as Mitsuba parameterises and samples it.
//!
//! The sphere is the unit sphere placed by a similarity transform (rotation, uniform scale,
//! translation, possibly a mirror). The rotation matters only to the UVs: with
//! `local = to_object(p)`, theta the angle from local +z and phi = atan2(local.y, local.x) in
//! [0, 2 pi), Mitsuba's uv is (phi / 2 pi, theta / pi) with v = 0 at the top of a bitmap, so in
//! tessera's convention (origin at the bottom-left, DESIGN.md section 3) it is
//! `(phi / 2 pi, 1 - theta / pi)`: the local +z pole is the image's top row.

use super::{Bounds, Frame, Ray, SurfaceInteraction, SurfacePoint};
use crate::sampling::warp;
use glam::{Mat3, Mat4, Vec2, Vec3};
use std::f32::consts::{PI, TAU};

/// A sphere: the unit sphere under a similarity transform.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    center: Vec3,
    radius: f32,
    /// World to the unit sphere's local space (where the UVs are defined).
    to_object: Mat4,
    /// Linear part of local to world (rotation, mirror and the radius).
    to_world_linear: Mat3,
    /// Whether the front (the side the normal faces, and the side an emitter lights) is inside.
    flip_normals: bool,
}

/// A point sampled on a sphere as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct SphereSample {
    /// The point on the surface.
    pub point: Vec3,
    /// The surface's geometric normal there (its front side).
    pub normal: Vec3,
    /// Density per unit solid angle at the reference point.
    pub pdf: f32,
}

/// Relative tolerance of [`Sphere::new`]'s check that a transform is a similarity.
const SIMILARITY_TOLERANCE: f32 = 1e-4;

impl Sphere {
    /// The unit sphere placed by `to_world`, which must be a similarity (equal, orthogonal
    /// axes): Mitsuba builds it as `to_world * translate(center) * scale(radius)`. A mirroring
    /// transform mirrors the UVs and keeps the front outside, as it does for meshes.
    pub fn new(to_world: Mat4, flip_normals: bool) -> Result<Self, String> {
        if !to_world.is_finite() || to_world.row(3) != glam::Vec4::W {
            return Err("a sphere's transform must be finite and affine".to_string());
        }
        let linear = Mat3::from_mat4(to_world);
        let radius = linear.x_axis.length();
        if !(radius > 0.0 && radius.is_finite() && (radius * radius).is_finite()) {
            return Err(format!("a sphere's radius must be positive and finite, not {radius}"));
        }
        let gram = linear.transpose() * linear / (radius * radius);
        let off = (gram - Mat3::IDENTITY).to_cols_array().iter().fold(0.0f32, |m, v| m.max(v.abs()));
        if !(off <= SIMILARITY_TOLERANCE) {
            return Err("a sphere's transform must be a rotation, a uniform scale and a translation \
                 (a non-uniform scale or a shear makes an ellipsoid: use a uv_sphere mesh)"
                .to_string());
        }
        Ok(Sphere {
            center: to_world.w_axis.truncate(),
            radius,
            to_object: to_world.inverse(),
            to_world_linear: linear,
            flip_normals,
        })
    }

    /// Centre in world space.
    pub fn center(&self) -> Vec3 {
        self.center
    }

    /// Radius in world units.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// Local (unit sphere) to world transform.
    pub fn to_world(&self) -> Mat4 {
        Mat4::from_translation(self.center) * Mat4::from_mat3(self.to_world_linear)
    }

    /// Whether the front side is inside.
    pub fn flip_normals(&self) -> bool {
        self.flip_normals
    }

    /// Surface area, 4 pi r^2.
    pub fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// Bounding box.
    pub fn bounds(&self) -> Bounds {
        Bounds { min: self.center - Vec3::splat(self.radius), max: self.center + Vec3::splat(self.radius) }
    }

    /// The front-side unit normal at surface point `p`.
    #[inline]
    fn normal_at(&self, p: Vec3) -> Vec3 {
        let n = (p - self.center).normalize();
        if self.flip_normals { -n } else { n }
    }

    /// The smallest ray parameter t in (0, `ray.t_max`) where the ray meets the sphere.
    ///
    /// The quadratic is solved about the point of the ray nearest the centre, t_c (as Mitsuba
    /// does): there the offset from the centre is perpendicular to the ray and its squared
    /// length r^2 - |o + t_c d - c|^2 carries no cancellation from a far origin, so the roots
    /// t_c -+ sqrt(h^2 / |d|^2) are accurate to a few ulps of t wherever the ray starts.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let a = ray.d.length_squared();
        let t_c = (self.center - ray.o).dot(ray.d) / a;
        let perpendicular = ray.o + ray.d * t_c - self.center;
        let h2 = self.radius * self.radius - perpendicular.length_squared();
        if !(h2 >= 0.0) {
            return None;
        }
        let half_chord = (h2 / a).sqrt();
        let (near, far) = (t_c - half_chord, t_c + half_chord);
        if near > 0.0 && near < ray.t_max {
            Some(near)
        } else if far > 0.0 && far < ray.t_max {
            Some(far)
        } else {
            None
        }
    }

    /// The surface interaction where `ray` meets the sphere at parameter `t` (from
    /// [`Sphere::intersect`]); `primitive` is its index among the scene's primitives.
    ///
    /// The hit point is projected back onto the sphere. dp/du = 2 pi (-y, x, 0) and
    /// dp/dv = pi (-z cos phi, -z sin phi, sqrt(x^2 + y^2)) in local coordinates (Mitsuba's,
    /// with v reversed), taken to world by the transform; at a pole, where dp/du vanishes,
    /// dp/dv is Mitsuba's (1, 0, 0) and the frame falls back to one about the normal.
    pub fn interaction(&self, ray: &Ray, t: f32, primitive: u32) -> SurfaceInteraction {
        let outward = (ray.at(t) - self.center).normalize();
        let p = self.center + outward * self.radius;
        let ng = if self.flip_normals { -outward } else { outward };
        let local = self.to_object.transform_point3(p);
        let uv = local_uv(local);
        let rd = local.x.hypot(local.y);
        let dpdu_local = Vec3::new(-local.y, local.x, 0.0) * TAU;
        let dpdv_local = if rd > 0.0 {
            Vec3::new(-local.z * local.x / rd, -local.z * local.y / rd, rd) * PI
        } else {
            Vec3::new(-PI, 0.0, 0.0)
        };
        let (dpdu, dpdv) = (self.to_world_linear * dpdu_local, self.to_world_linear * dpdv_local);
        SurfaceInteraction::new(SurfacePoint { p, ng, shading_normal: ng, uv, dpdu, dpdv }, ray, t, primitive)
    }

    /// Whether `p` sees the sphere from outside: farther from the centre than the radius less
    /// a ray offset (so that a point on the surface counts as outside, as in Mitsuba).
    #[inline]
    fn sees_from_outside(&self, p: Vec3) -> bool {
        let slack = if self.flip_normals { 1.0 + OFFSET_FRACTION } else { 1.0 - OFFSET_FRACTION };
        (p - self.center).length_squared() > (self.radius * slack).powi(2)
    }

    /// A point on the sphere sampled from `p` with `u`: from outside, uniform over the cone of
    /// directions the sphere subtends (its visible cap; Mitsuba's `sample_direction`); from
    /// inside, uniform over the area. The density is per unit solid angle at `p`.
    pub fn sample_from(&self, p: Vec3, u: Vec2) -> Option<SphereSample> {
        let to_center = self.center - p;
        let dc2 = to_center.length_squared();
        let (point, pdf) = if self.sees_from_outside(p) {
            let dc = dc2.sqrt();
            let sin2_max = (self.radius * self.radius / dc2).min(1.0);
            let one_minus_cos_max = one_minus_cos_from_sin2(sin2_max);
            let w = warp::square_to_uniform_cone(u, one_minus_cos_max);
            // Along w, the near intersection lies at dc cos - sqrt(r^2 - dc^2 sin^2).
            let sin2 = w.x * w.x + w.y * w.y;
            let chord = (self.radius * self.radius - dc2 * sin2).max(0.0).sqrt();
            let dir = Frame::from_normal(to_center / dc).to_world(w);
            (p + dir * (dc * w.z - chord), warp::uniform_cone_pdf(one_minus_cos_max))
        } else {
            let point = self.center + self.to_world_linear * warp::square_to_uniform_sphere(u);
            (point, self.pdf_from(p, (point - p).normalize()))
        };
        let normal = self.normal_at(point);
        (pdf > 0.0 && pdf.is_finite()).then_some(SphereSample { point, normal, pdf })
    }

    /// The solid-angle density with which [`Sphere::sample_from`] picks the unit direction `w`
    /// from `p` (a direction towards the sphere): 1 / (2 pi (1 - cos theta_max)) from outside;
    /// inside, l^2 / (|cos| area) at the point l along `w` where the ray from `p` leaves.
    ///
    /// A density of the direction, not of a point: a path's next vertex is found from an
    /// origin moved off the surface, and at grazing angles inside a sphere the point it reaches
    /// lies measurably off the one the direction reaches from `p` (the two strategies' weights
    /// then fail to add up to 1: 3e-4 of the light inside a diffuse sphere went missing).
    pub fn pdf_from(&self, p: Vec3, w: Vec3) -> f32 {
        if self.sees_from_outside(p) {
            let sin2_max = (self.radius * self.radius / (self.center - p).length_squared()).min(1.0);
            return warp::uniform_cone_pdf(one_minus_cos_from_sin2(sin2_max));
        }
        // The far root of |p + l w - c| = r, about the point of the line nearest the centre.
        let t_c = (self.center - p).dot(w);
        let h2 = (self.radius * self.radius - (p + w * t_c - self.center).length_squared()).max(0.0);
        let l = t_c + h2.sqrt();
        let cos = (p + w * l - self.center).dot(w).abs() / self.radius;
        if l > 0.0 && cos > 0.0 { l * l / (cos * self.area()) } else { 0.0 }
    }
}

/// The relative distance by which [`super::offset_ray_origin`] moves a point off a surface, for the
/// inside/outside test of a point on the sphere.
const OFFSET_FRACTION: f32 = 1500.0 / 16_777_216.0;

/// 1 - cos theta from sin^2 theta without cancellation: sin^2 / (1 + cos).
#[inline]
fn one_minus_cos_from_sin2(sin2: f32) -> f32 {
    sin2 / (1.0 + (1.0 - sin2).max(0.0).sqrt())
}

/// tessera's uv of a point `local` on the unit sphere: (phi / 2 pi, 1 - theta / pi).
#[inline]
fn local_uv(local: Vec3) -> Vec2 {
    let mut phi = local.y.atan2(local.x);
    if phi < 0.0 {
        phi += TAU;
    }
    // theta from the z axis, as atan2 of the distance from it (accurate near the poles).
    let theta = local.x.hypot(local.y).atan2(local.z);
    Vec2::new(phi / TAU, 1.0 - theta / PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn placed() -> Sphere {
        let to_world = Mat4::from_translation(Vec3::new(0.5, -1.0, 2.0))
            * Mat4::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.7)
            * Mat4::from_scale(Vec3::splat(1.5));
        Sphere::new(to_world, false).unwrap()
    }

    #[test]
    fn sphere_rejects_what_is_not_a_similarity() {
        assert!(Sphere::new(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)), false).unwrap_err().contains("ellipsoid"));
        assert!(Sphere::new(Mat4::from_scale(Vec3::ZERO), false).unwrap_err().contains("radius"));
        assert!(Sphere::new(Mat4::from_scale(Vec3::splat(f32::NAN)), false).is_err());
        let mirrored = Sphere::new(Mat4::from_scale(Vec3::new(-2.0, 2.0, 2.0)), false).unwrap();
        assert_eq!(mirrored.radius(), 2.0);
    }

    #[test]
    fn sphere_hits_match_the_f64_quadratic_also_from_far_away() {
        let s = placed();
        let c = s.center().as_dvec3();
        for (i, (o, target)) in [
            (Vec3::new(3.0, 4.0, -5.0), Vec3::new(0.6, -0.9, 2.2)),
            (Vec3::new(1e4, -2e4, 3e4), Vec3::new(0.3, -1.2, 1.8)),
            (Vec3::new(0.5, -1.0, 2.0), Vec3::new(5.0, 1.0, 0.0)), // from the centre: the far root
        ]
        .into_iter()
        .enumerate()
        {
            let ray = Ray::new(o, target - o);
            let t = s.intersect(&ray).expect("aimed inside the sphere");
            let (o64, d64) = (o.as_dvec3(), ray.d.as_dvec3());
            let f = o64 - c;
            let (a, b, k) = (d64.dot(d64), f.dot(d64), f.dot(f) - 1.5f64 * 1.5);
            let disc = (b * b - a * k).sqrt();
            let exact = if (-b - disc) / a > 0.0 { (-b - disc) / a } else { (-b + disc) / a };
            assert!(((t as f64) - exact).abs() < 4e-6 * exact, "ray {i}: {t} against {exact}");
        }
        // A ray that passes by, and one that stops short, hit nothing.
        assert!(s.intersect(&Ray::new(Vec3::new(10.0, 10.0, 10.0), Vec3::X)).is_none());
        let mut short = Ray::new(Vec3::new(0.5, -1.0, 10.0), -Vec3::Z);
        short.t_max = 6.0;
        assert!(s.intersect(&short).is_none());
    }

    #[test]
    fn sphere_interaction_has_mitsubas_uv_and_consistent_derivatives() {
        let s = placed();
        let to_world = s.to_world();
        // Points given by Mitsuba's spherical coordinates (theta from local +z).
        for (theta, phi) in [(0.4f32, 0.3f32), (1.2, 2.5), (2.6, 4.0), (1.57, 6.0)] {
            let local = Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
            let p = to_world.transform_point3(local);
            let o = p + (p - s.center()) * 2.0;
            let ray = Ray::new(o, p - o);
            let t = s.intersect(&ray).unwrap();
            let si = s.interaction(&ray, t, 7);
            assert!(si.p.distance(p) < 1e-5, "{} against {p}", si.p);
            assert!(si.uv.distance(Vec2::new(phi / TAU, 1.0 - theta / PI)) < 1e-5, "uv {}", si.uv);
            assert!(si.ng.distance((p - s.center()) / 1.5) < 1e-5);
            assert_eq!(si.primitive, 7);
            // dp/du and dp/dv against central differences of the parameterisation.
            let at = |u: f64, v: f64| {
                let (phi, theta) = (u * std::f64::consts::TAU, (1.0 - v) * std::f64::consts::PI);
                let l = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                to_world.as_dmat4().transform_point3(l)
            };
            let (u, v, h) = (si.uv.x as f64, si.uv.y as f64, 1e-5);
            let dpdu = (at(u + h, v) - at(u - h, v)) / (2.0 * h);
            let dpdv = (at(u, v + h) - at(u, v - h)) / (2.0 * h);
            assert!(si.dpdu.as_dvec3().distance(dpdu) < 1e-3 * dpdu.length(), "{} vs {dpdu}", si.dpdu);
            assert!(si.dpdv.as_dvec3().distance(dpdv) < 1e-3 * dpdv.length(), "{} vs {dpdv}", si.dpdv);
            assert!(!si.uv_mirrored(), "east x north is outward");
            assert!(si.frame.s.distance(si.dpdu.normalize()) < 1e-5);
        }
        // Inside out: the normal (and with it the UV map's handedness) turns inward.
        let flipped = Sphere { flip_normals: true, ..s.clone() };
        let ray = Ray::new(s.center() + Vec3::new(5.0, 0.1, 0.2), -Vec3::X);
        let si = flipped.interaction(&ray, flipped.intersect(&ray).unwrap(), 0);
        assert!(si.ng.x < -0.98 && si.uv_mirrored());
        // At a pole the frame is still orthonormal and finite.
        let pole = to_world.transform_point3(Vec3::Z);
        let ray = Ray::new(pole + (pole - s.center()), s.center() - pole);
        let si = s.interaction(&ray, s.intersect(&ray).unwrap(), 0);
        assert!(si.frame.s.is_finite() && si.frame.s.dot(si.frame.n).abs() < 1e-5 && si.uv.y > 0.999);
    }

    #[test]
    fn sphere_samples_lie_on_the_visible_surface_with_the_pdf_of_their_direction() {
        let s = placed();
        for (p, inside) in [(Vec3::new(4.0, 2.0, -1.0), false), (Vec3::new(0.6, -0.8, 2.3), true)] {
            let mut seen = 0.0f64;
            let n = 64;
            for i in 0..n {
                for j in 0..n {
                    let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                    let Some(sample) = s.sample_from(p, u) else { continue };
                    assert!((sample.point.distance(s.center()) - 1.5).abs() < 1e-5);
                    let w = (sample.point - p).normalize();
                    assert!((sample.pdf - s.pdf_from(p, w)).abs() < 1e-4 * sample.pdf);
                    if !inside {
                        // The first surface along the sampled direction, so visible from p.
                        let ray = Ray::new(p, sample.point - p);
                        let t = s.intersect(&ray).unwrap();
                        assert!((t - 1.0).abs() < 1e-4, "t {t}");
                    }
                    seen += 1.0 / sample.pdf as f64;
                }
            }
            // Sum of 1/pdf estimates the solid angle sampled: the cone, or all directions.
            let dc2 = (s.center() - p).length_squared() as f64;
            let expected = if inside {
                4.0 * std::f64::consts::PI
            } else {
                std::f64::consts::TAU * (1.0 - (1.0 - 2.25 / dc2).sqrt())
            };
            let estimate = seen / (n * n) as f64;
            assert!((estimate - expected).abs() < 0.02 * expected, "{estimate} against {expected}");
        }
    }
}
