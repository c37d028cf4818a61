//! Light sources: emissive triangle meshes and the environment, and the choice among them for
//! next-event estimation (uniform over lights, as Mitsuba 3 does).

mod area;
mod environment;

pub use area::AreaLight;
pub use environment::{Environment, EnvironmentMap};

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
    /// The sampled point, already offset off the light's surface; None for the environment.
    pub point: Option<Vec3>,
}

/// All lights of a scene.
#[derive(Clone, Debug, Default)]
pub struct Lights {
    /// Emissive meshes.
    pub area: Vec<AreaLight>,
    /// The environment, if any.
    pub environment: Option<Environment>,
}

impl Lights {
    /// Number of lights NEE chooses among.
    pub fn count(&self) -> usize {
        self.area.len() + usize::from(self.environment.is_some())
    }

    /// Probability of choosing any one light.
    #[inline]
    pub fn selection_pdf(&self) -> f32 {
        1.0 / self.count().max(1) as f32
    }

    /// Choose a light uniformly with `u_select` and sample it from `p` with `u`.
    pub fn sample(&self, p: Vec3, u_select: f32, u: Vec2) -> Option<LightSample> {
        let n = self.count();
        if n == 0 {
            return None;
        }
        let i = ((u_select * n as f32) as usize).min(n - 1);
        let mut s = match self.area.get(i) {
            Some(light) => light.sample(p, u)?,
            None => self.environment.as_ref()?.sample(u)?,
        };
        s.pdf *= self.selection_pdf();
        Some(s)
    }

    /// Density with which [`Lights::sample`] picks direction `wi` towards the environment.
    pub fn environment_pdf(&self, wi: Vec3) -> f32 {
        self.environment.as_ref().map_or(0.0, |e| e.pdf(wi) * self.selection_pdf())
    }

    /// Density with which [`Lights::sample`] reaches point `p_light` (geometric normal
    /// `n_light`) of area light `light` from `p`.
    pub fn area_pdf(&self, light: usize, p: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
        self.area[light].pdf(p, p_light, n_light) * self.selection_pdf()
    }
}
