//! Point and spot lights (Mitsuba's `point` and `spot`, glTF's `KHR_lights_punctual` point and
//! spot): all light leaves one point, so next-event estimation reaches them with a delta
//! density and paths never hit them.
//!
//! Irradiance at distance d, at incidence angle theta on a surface, is
//! E = I s(w) w_r(d) cos theta / d^2, with I the radiant intensity (W/sr) on the axis, s the
//! spot's falloff profile (1 for a point light) and w_r glTF's range window (1 without a range).

use super::LightSample;
use crate::color::Rgb;
use glam::{Mat4, Vec3};

/// The angular falloff of a spot light between its full-intensity beam and its cutoff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpotFalloff {
    /// Mitsuba 3's `spot`: 1 within the beam width, then linear in the angle down to 0 at the
    /// cutoff: s = (cutoff - theta) / (cutoff - beam).
    LinearInAngle,
    /// glTF's recommended profile (`KHR_lights_punctual`): t = (cos theta - cos outer) /
    /// (cos inner - cos outer), clamped to [0, 1], and s = t^2; the beam is the inner cone and
    /// the cutoff the outer one.
    SquaredInCosine,
}

/// The cone of a spot light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotCone {
    /// Unit axis, the direction of full intensity.
    axis: Vec3,
    /// Half-angle (radians) within which the intensity is full.
    beam: f32,
    /// Half-angle (radians) beyond which no light leaves.
    cutoff: f32,
    /// Their cosines, compared with every shadow ray's.
    cos_beam: f32,
    cos_cutoff: f32,
    falloff: SpotFalloff,
}

impl SpotCone {
    /// A cone around `axis` with full intensity within `beam` and none beyond `cutoff`
    /// (half-angles in radians, 0 <= beam <= cutoff, 0 < cutoff <= pi).
    pub fn new(axis: Vec3, beam: f32, cutoff: f32, falloff: SpotFalloff) -> Result<Self, String> {
        let Some(axis) = axis.try_normalize() else {
            return Err(format!("the spot's direction {axis} has no length"));
        };
        if !(cutoff > 0.0 && cutoff <= std::f32::consts::PI) {
            return Err(format!("cutoff angle {} degrees is outside (0, 180]", cutoff.to_degrees()));
        }
        if !(0.0..=cutoff).contains(&beam) {
            return Err(format!(
                "beam width {} degrees is outside [0, cutoff angle {}]",
                beam.to_degrees(),
                cutoff.to_degrees()
            ));
        }
        Ok(SpotCone { axis, beam, cutoff, cos_beam: beam.cos(), cos_cutoff: cutoff.cos(), falloff })
    }

    /// The axis (unit).
    pub fn axis(&self) -> Vec3 {
        self.axis
    }

    /// Beam and cutoff half-angles in radians.
    pub fn angles(&self) -> (f32, f32) {
        (self.beam, self.cutoff)
    }

    /// The falloff profile.
    pub fn falloff(&self) -> SpotFalloff {
        self.falloff
    }

    /// The fraction s of the axis' intensity leaving along unit direction `w`.
    pub fn profile(&self, w: Vec3) -> f32 {
        let cos_theta = w.dot(self.axis).clamp(-1.0, 1.0);
        let (cos_beam, cos_cutoff) = (self.cos_beam, self.cos_cutoff);
        if cos_theta <= cos_cutoff {
            return 0.0;
        }
        if cos_theta >= cos_beam {
            return 1.0;
        }
        match self.falloff {
            SpotFalloff::LinearInAngle => (self.cutoff - cos_theta.acos()) / (self.cutoff - self.beam),
            SpotFalloff::SquaredInCosine => {
                let t = ((cos_theta - cos_cutoff) / (cos_beam - cos_cutoff)).clamp(0.0, 1.0);
                t * t
            }
        }
    }
}

/// A light at a point: all directions (a point light) or a cone (a spot light).
#[derive(Clone, Debug, PartialEq)]
pub struct PointLight {
    /// Where the light is.
    pub position: Vec3,
    /// Radiant intensity on the axis (W/sr per channel).
    pub intensity: Rgb,
    /// The cone of a spot light; None for a point light.
    pub spot: Option<SpotCone>,
    /// glTF's range: the distance where the light is windowed to zero; None for none.
    pub range: Option<f32>,
}

impl PointLight {
    /// The light moved by the affine transform `m` (its cone's axis turned with it; scale does
    /// not change the cone).
    pub fn transformed(&self, m: &Mat4) -> Self {
        let spot = self.spot.map(|cone| SpotCone { axis: m.transform_vector3(cone.axis).normalize(), ..cone });
        PointLight { position: m.transform_point3(self.position), spot, ..self.clone() }
    }

    /// glTF's recommended window: w_r = clamp(1 - (d / range)^4, 0, 1)^2 (1 without a range).
    fn range_window(&self, distance: f32) -> f32 {
        match self.range {
            None => 1.0,
            Some(range) => {
                let x = distance / range;
                let x2 = x * x;
                let w = (1.0 - x2 * x2).clamp(0.0, 1.0);
                w * w
            }
        }
    }

    /// The light as seen from `p`: direction, radiance-like value I s w_r / d^2 and a delta
    /// density (1); None where no light leaves towards `p`.
    pub fn sample(&self, p: Vec3) -> Option<LightSample> {
        let to_light = self.position - p;
        let dist2 = to_light.length_squared();
        if !(dist2 > 0.0) {
            return None;
        }
        let distance = dist2.sqrt();
        let wi = to_light / distance;
        let profile = self.spot.as_ref().map_or(1.0, |cone| cone.profile(-wi));
        let scale = profile * self.range_window(distance) / dist2;
        if !(scale > 0.0) {
            return None;
        }
        Some(LightSample { wi, radiance: self.intensity * scale, pdf: 1.0, point: Some(self.position), delta: true })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mitsuba_falloff_is_linear_in_angle_between_beam_and_cutoff() {
        let cone = SpotCone::new(Vec3::Z, 10f32.to_radians(), 30f32.to_radians(), SpotFalloff::LinearInAngle).unwrap();
        let at = |deg: f32| cone.profile(Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos()));
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(9.9), 1.0);
        assert!((at(20.0) - 0.5).abs() < 1e-4, "{}", at(20.0));
        assert!((at(25.0) - 0.25).abs() < 1e-4);
        assert_eq!(at(30.1), 0.0);
        assert_eq!(at(120.0), 0.0);
    }

    #[test]
    fn gltf_falloff_is_squared_in_cosine() {
        let (inner, outer) = (10f32.to_radians(), 30f32.to_radians());
        let cone = SpotCone::new(Vec3::Z, inner, outer, SpotFalloff::SquaredInCosine).unwrap();
        let theta = 20f32.to_radians();
        let t = (theta.cos() - outer.cos()) / (inner.cos() - outer.cos());
        assert!((cone.profile(Vec3::new(theta.sin(), 0.0, theta.cos())) - t * t).abs() < 1e-5);
    }

    #[test]
    fn bad_cones_are_refused() {
        assert!(SpotCone::new(Vec3::ZERO, 0.1, 0.2, SpotFalloff::LinearInAngle).is_err());
        assert!(SpotCone::new(Vec3::Z, 0.3, 0.2, SpotFalloff::LinearInAngle).is_err());
        assert!(SpotCone::new(Vec3::Z, 0.0, 0.0, SpotFalloff::LinearInAngle).is_err());
        assert!(SpotCone::new(Vec3::Z, 0.0, f32::NAN, SpotFalloff::LinearInAngle).is_err());
    }

    #[test]
    fn point_light_falls_off_with_the_square_of_distance_and_its_range_window() {
        let light =
            PointLight { position: Vec3::new(0.0, 2.0, 0.0), intensity: Rgb::splat(8.0), spot: None, range: None };
        let s = light.sample(Vec3::ZERO).unwrap();
        assert!(s.delta && s.wi.distance(Vec3::Y) < 1e-6);
        assert!((s.radiance.x - 2.0).abs() < 1e-6);
        let windowed = PointLight { range: Some(4.0), ..light };
        let w = (1.0f32 - 0.5f32.powi(4)).powi(2);
        assert!((windowed.sample(Vec3::ZERO).unwrap().radiance.x - 2.0 * w).abs() < 1e-6);
        assert!(PointLight { range: Some(1.5), ..windowed }.sample(Vec3::ZERO).is_none());
    }
}
