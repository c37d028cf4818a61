//! Light from infinitely far away in one direction: a directional light (Mitsuba's
//! `directional`, glTF's directional punctual light), whose rays are all parallel, or a sun: a
//! disc of constant radiance subtending a small cone, which casts soft-edged shadows.
//!
//! Both are given by their irradiance E on a surface facing them. The sun's disc of angular
//! radius alpha has radiance L = E / (pi sin^2 alpha), since a uniform disc delivers
//! E = integral of L cos theta over the cone = L pi sin^2 alpha; the irradiance on a surface
//! at angle theta to the sun is E cos theta exactly while the disc is wholly above its horizon.

use super::LightSample;
use crate::color::Rgb;
use crate::geometry::Frame;
use crate::sampling::warp;
use glam::{Mat4, Vec2, Vec3};
use std::f32::consts::PI;

/// A directional light or a sun disc.
#[derive(Clone, Debug, PartialEq)]
pub struct DistantLight {
    /// Unit direction towards the light (opposite to the direction its light travels).
    towards: Vec3,
    /// Irradiance on a surface facing the light.
    irradiance: Rgb,
    /// The disc: None for a directional light.
    disc: Option<Disc>,
}

/// The cone of directions a sun subtends.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Disc {
    /// Angular radius (radians).
    radius: f32,
    /// sin^2 of the angular radius, for the inside test (exact for small discs).
    sin2_radius: f32,
    /// 1 - cos of the angular radius, 2 sin^2(radius / 2), computed without cancellation.
    one_minus_cos: f32,
    /// Radiance of the disc.
    radiance: Rgb,
    /// A frame around the direction towards the sun.
    frame: Frame,
}

impl DistantLight {
    /// A light whose light travels along `direction`, with irradiance `irradiance` on a surface
    /// facing it, and a disc of `angular_diameter` radians (0: a directional light).
    pub fn new(direction: Vec3, irradiance: Rgb, angular_diameter: f32) -> Result<Self, String> {
        let Some(towards) = (-direction).try_normalize() else {
            return Err(format!("direction {direction} has no length"));
        };
        if !(0.0..PI).contains(&angular_diameter) {
            return Err(format!("angular diameter {} degrees is outside [0, 180)", angular_diameter.to_degrees()));
        }
        let disc = (angular_diameter > 0.0).then(|| {
            let radius = 0.5 * angular_diameter;
            let sin2_radius = radius.sin().powi(2);
            Disc {
                radius,
                sin2_radius,
                one_minus_cos: 2.0 * (0.5 * radius).sin().powi(2),
                radiance: irradiance / (PI * sin2_radius),
                frame: Frame::from_normal(towards),
            }
        });
        Ok(DistantLight { towards, irradiance, disc })
    }

    /// The light turned by the affine transform `m`; an error where `m` collapses its direction.
    pub fn transformed(&self, m: &Mat4) -> Result<Self, String> {
        Self::new(m.transform_vector3(self.direction()), self.irradiance, self.angular_diameter())
    }

    /// The direction its light travels (unit).
    pub fn direction(&self) -> Vec3 {
        -self.towards
    }

    /// Irradiance on a surface facing the light.
    pub fn irradiance(&self) -> Rgb {
        self.irradiance
    }

    /// The sun's angular diameter in radians; 0 for a directional light.
    pub fn angular_diameter(&self) -> f32 {
        self.disc.map_or(0.0, |d| 2.0 * d.radius)
    }

    /// Whether all its light arrives along one direction (no path can hit it).
    pub fn is_delta(&self) -> bool {
        self.disc.is_none()
    }

    /// Sample a direction towards the light: the one direction (with a delta density 1) or a
    /// uniform direction in the sun's cone.
    pub fn sample(&self, u: Vec2) -> Option<LightSample> {
        Some(match &self.disc {
            None => LightSample { wi: self.towards, radiance: self.irradiance, pdf: 1.0, point: None, delta: true },
            Some(disc) => {
                let wi = disc.frame.to_world(warp::square_to_uniform_cone(u, disc.one_minus_cos)).normalize();
                let pdf = warp::uniform_cone_pdf(disc.one_minus_cos);
                LightSample { wi, radiance: disc.radiance, pdf, point: None, delta: false }
            }
        })
    }

    /// Whether unit direction `w` looks into the sun's disc.
    fn sees_disc(disc: &Disc, towards: Vec3, w: Vec3) -> bool {
        w.dot(towards) > 0.0 && w.cross(towards).length_squared() < disc.sin2_radius
    }

    /// Radiance arriving along unit direction `w` from the light towards the viewer (the sun's
    /// where `w` looks into its disc; zero for a directional light, which no ray hits).
    pub fn radiance(&self, w: Vec3) -> Rgb {
        match &self.disc {
            Some(disc) if Self::sees_disc(disc, self.towards, w) => disc.radiance,
            _ => Rgb::ZERO,
        }
    }

    /// Solid-angle density with which [`DistantLight::sample`] returns unit direction `w`.
    pub fn pdf(&self, w: Vec3) -> f32 {
        match &self.disc {
            Some(disc) if Self::sees_disc(disc, self.towards, w) => warp::uniform_cone_pdf(disc.one_minus_cos),
            _ => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sun_samples_lie_in_its_disc_and_integrate_to_its_irradiance() {
        // Quarter-degree radius: the inside test and the density must agree at that scale.
        let sun = DistantLight::new(Vec3::new(0.3, -1.0, 0.2), Rgb::splat(3.0), 0.533f32.to_radians()).unwrap();
        let towards = -sun.direction();
        let mut sum = 0.0f64;
        let n = 4096;
        for i in 0..n {
            let u = Vec2::new((i % 64) as f32 / 64.0 + 0.007, (i / 64) as f32 / 64.0 + 0.007);
            let s = sun.sample(u).unwrap();
            assert!(!s.delta && sun.pdf(s.wi) == s.pdf, "sample {i} outside its own disc");
            assert_eq!(sun.radiance(s.wi), s.radiance);
            // Irradiance on a surface facing the sun: E = mean of L cos / pdf.
            sum += f64::from(s.radiance.x * s.wi.dot(towards) / s.pdf);
        }
        let e = sum / n as f64;
        assert!((e - 3.0).abs() < 3e-4, "irradiance {e}");
        assert_eq!(sun.radiance(-towards), Rgb::ZERO);
        let off = Frame::from_normal(towards).to_world(Vec3::new(0.01, 0.0, 1.0)).normalize();
        assert_eq!(sun.pdf(off), 0.0, "0.57 degrees off the axis is outside a 0.27-degree disc");
    }

    #[test]
    fn directional_light_is_a_delta() {
        let light = DistantLight::new(Vec3::new(0.0, -2.0, 0.0), Rgb::splat(2.0), 0.0).unwrap();
        let s = light.sample(Vec2::splat(0.5)).unwrap();
        assert!(s.delta && s.wi.distance(Vec3::Y) < 1e-6 && s.radiance == Rgb::splat(2.0));
        assert_eq!(light.radiance(Vec3::Y), Rgb::ZERO);
        assert!(DistantLight::new(Vec3::ZERO, Rgb::ONE, 0.0).is_err());
        assert!(DistantLight::new(Vec3::Y, Rgb::ONE, f32::NAN).is_err());
    }
}
