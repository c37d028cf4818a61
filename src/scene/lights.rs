//! A scene file's `[[lights]]` made into lights: points and spots, directional lights and suns.

use super::desc::{LightDesc, RgbValue, SpotFalloffDesc};
use crate::color::Rgb;
use crate::light::{DistantLight, Lights, PointLight, SpotCone, SpotFalloff};
use glam::Vec3;

/// The sun's mean angular diameter seen from Earth, in degrees.
const SUN_ANGULAR_DIAMETER_DEGREES: f32 = 0.533;

/// Add the light `desc` to `lights`; the error says which parameter is wrong. Intensities and
/// the radiance they imply must lie in [0, `max_radiance`].
pub(super) fn add_light(lights: &mut Lights, desc: &LightDesc, max_radiance: f32) -> Result<(), String> {
    let power = |key: &str, RgbValue(v): &RgbValue| {
        if v.iter().all(|c| (0.0..=max_radiance).contains(c)) {
            Ok(Rgb::from(*v))
        } else {
            Err(format!("{key}: {v:?} is outside [0, {max_radiance:e}]"))
        }
    };
    match desc {
        LightDesc::Point { position, intensity } => lights.points.push(PointLight {
            position: Vec3::from(*position),
            intensity: power("intensity", intensity)?,
            spot: None,
            range: None,
        }),
        LightDesc::Spot { position, direction, target, intensity, cutoff_angle, beam_width, falloff } => {
            let position = Vec3::from(*position);
            let axis = match (direction, target) {
                (Some(d), None) => Vec3::from(*d),
                (None, Some(t)) => Vec3::from(*t) - position,
                _ => return Err("give exactly one of direction and target".into()),
            };
            let cutoff = cutoff_angle.unwrap_or(20.0);
            let beam = beam_width.unwrap_or(0.75 * cutoff);
            let falloff = match falloff.unwrap_or(SpotFalloffDesc::Mitsuba) {
                SpotFalloffDesc::Mitsuba => SpotFalloff::LinearInAngle,
                SpotFalloffDesc::Gltf => SpotFalloff::SquaredInCosine,
            };
            let cone = SpotCone::new(axis, beam.to_radians(), cutoff.to_radians(), falloff)?;
            lights.points.push(PointLight {
                position,
                intensity: power("intensity", intensity)?,
                spot: Some(cone),
                range: None,
            });
        }
        LightDesc::Directional { direction, irradiance } => {
            lights.distant.push(DistantLight::new(Vec3::from(*direction), power("irradiance", irradiance)?, 0.0)?)
        }
        LightDesc::Sun { direction, irradiance, angular_diameter } => {
            let diameter = angular_diameter.unwrap_or(SUN_ANGULAR_DIAMETER_DEGREES);
            if !(diameter > 0.0) {
                return Err(format!(
                    "angular_diameter: {diameter} degrees: a sun needs a disc (use a directional light for none)"
                ));
            }
            let sun =
                DistantLight::new(Vec3::from(*direction), power("irradiance", irradiance)?, diameter.to_radians())?;
            let radiance = sun.radiance(-sun.direction()).max_element();
            if !(radiance <= max_radiance) {
                return Err(format!(
                    "the disc's radiance, irradiance / (pi sin^2 radius) = {radiance:e}, is above {max_radiance:e}"
                ));
            }
            lights.distant.push(sun);
        }
    }
    Ok(())
}
