//! Light sources: emissive triangle meshes, point and spot lights, directional lights and suns,
//! and the environment, and the choice among them for next-event estimation (uniform over
//! lights, as Mitsuba 3 does).
//!
//! Delta lights (points, spots, directional lights) are reached by next-event estimation only,
//! with full weight; lights that paths can also hit (meshes, suns, the environment) weigh the two
//! strategies by the power heuristic.

mod area;
mod distant;
mod environment;
mod point;

pub use area::AreaLight;
pub use distant::DistantLight;
pub use environment::{Environment, EnvironmentMap};
pub use point::{PointLight, SpotCone, SpotFalloff};

use crate::sampling::power_heuristic;

use crate::color::Rgb;
use glam::{Vec2, Vec3};

/// A point or direction sampled on a light, as seen from a reference point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the reference point towards the light.
    pub wi: Vec3,
    /// Emitted radiance arriving along `-wi`.
    pub radiance: Rgb,
    /// Solid-angle density at the reference point, including the choice of this light.
    pub pdf: f32,
    /// The sampled point, already offset off the light's surface; None for lights at infinity.
    pub point: Option<Vec3>,
    /// Whether the light is a delta light (`pdf` then is a discrete probability, and no BSDF
    /// sample can reach it).
    pub delta: bool,
}

/// All lights of a scene.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// Emissive meshes.
    pub area: Vec<AreaLight>,
    /// Point and spot lights.
    pub points: Vec<PointLight>,
    /// Directional lights and suns.
    pub distant: Vec<DistantLight>,
    /// The environment, if any.
    pub environment: Option<Environment>,
}

impl Lights {
    /// Number of lights NEE chooses among.
    pub fn count(&self) -> usize {
        self.area.len() + self.points.len() + self.distant.len() + usize::from(self.environment.is_some())
    }

    /// Whether any light emits anything.
    pub fn any_emit(&self) -> bool {
        let environment_emits = match &self.environment {
            None => false,
            Some(Environment::Constant(c)) => c.max_element() > 0.0,
            Some(Environment::Map(_)) => true,
        };
        !self.area.is_empty() || !self.points.is_empty() || !self.distant.is_empty() || environment_emits
    }

    /// Probability of choosing any one light.
    #[inline]
    pub fn selection_pdf(&self) -> f32 {
        1.0 / self.count().max(1) as u32 as f32
    }

    /// Choose a light uniformly with `u_select` and sample it from `p` with `u`.
    pub fn sample(&self, p: Vec3, u_select: f32, u: Vec2) -> Option<LightSample> {
        let n = self.count();
        if n == 0 {
            return None;
        }
        // Through u32, which x86-64 converts to and from f32 in one or two instructions (u64 and
        // usize take a branch each way); no scene holds 2^32 lights.
        let i = ((u_select * n as u32 as f32) as u32 as usize).min(n - 1);
        let (points, distant) = (self.area.len(), self.area.len() + self.points.len());
        let environment = distant + self.distant.len();
        let mut s = match i {
            i if i < points => self.area[i].sample(p, u)?,
            i if i < distant => self.points[i - points].sample(p)?,
            i if i < environment => self.distant[i - distant].sample(u)?,
            _ => self.environment.as_ref()?.sample(u)?,
        };
        s.pdf *= self.selection_pdf();
        Some(s)
    }

    /// Radiance arriving along unit direction `d` from the lights at infinity (the environment
    /// and suns), seen by a path that left its last vertex along `d` with BSDF density
    /// `bsdf_pdf`, weighted against next-event estimation by the power heuristic; None for a
    /// direction sampled with a delta (the camera's, or a smooth BSDF's): full weight.
    pub fn arriving_from_infinity(&self, d: Vec3, bsdf_pdf: Option<f32>) -> Rgb {
        let weight =
            |light_pdf: f32| bsdf_pdf.map_or(1.0, |pdf| power_heuristic(pdf, light_pdf * self.selection_pdf()));
        let mut radiance = Rgb::ZERO;
        if let Some(env) = &self.environment {
            radiance += match bsdf_pdf {
                Some(_) => {
                    let (l, pdf) = env.radiance_and_pdf(d);
                    l * weight(pdf)
                }
                None => env.radiance(d),
            };
        }
        for sun in &self.distant {
            let l = sun.radiance(d);
            if l != Rgb::ZERO {
                radiance += l * weight(sun.pdf(d));
            }
        }
        radiance
    }

    /// Density with which [`Lights::sample`] reaches point `p_light` (geometric normal
    /// `n_light`) of area light `light` from `p`, where a path from `p` along the unit direction
    /// `w` met it ([`AreaLight::pdf`]).
    pub fn area_pdf(&self, light: usize, p: Vec3, w: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
        self.area[light].pdf(p, w, p_light, n_light) * self.selection_pdf()
    }
}
