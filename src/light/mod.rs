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
use crate::simd::{F32x8, M32x8, Real, V3, set_bits};

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

/// Light samples for eight points in lanes ([`Lights::sample_lanes`]).
#[derive(Clone, Copy, Debug)]
pub struct LightSampleLanes {
    /// Unit directions towards the lights.
    pub wi: V3<F32x8>,
    /// Radiance arriving along `-wi`: red, green and blue as x, y and z.
    pub radiance: V3<F32x8>,
    /// Solid-angle densities, including the choice of the light.
    pub pdf: F32x8,
    /// The sampled points, offset off their lights, where the light is not at infinity.
    pub point: V3<F32x8>,
    /// Lanes whose light is at infinity (the environment, suns): their shadow rays have no end.
    pub at_infinity: M32x8,
    /// Lanes whose light is a delta light (`pdf` then is a discrete probability).
    pub delta: M32x8,
    /// Lanes whose sample holds.
    pub valid: M32x8,
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

    /// The light that `u_select` chooses, uniformly; None without lights.
    #[inline]
    fn choose(&self, u_select: f32) -> Option<usize> {
        let n = self.count();
        // Through u32, which x86-64 converts to and from f32 in one or two instructions (u64 and
        // usize take a branch each way); no scene holds 2^32 lights.
        (n > 0).then(|| ((u_select * n as u32 as f32) as u32 as usize).min(n - 1))
    }

    /// Choose a light uniformly with `u_select` and sample it from `p` with `u`.
    pub fn sample(&self, p: Vec3, u_select: f32, u: Vec2) -> Option<LightSample> {
        self.sample_chosen(self.choose(u_select)?, p, u)
    }

    /// Sample light `i` (areas first, then points, directional lights and suns, and the
    /// environment) from `p` with `u`; the density includes the light's choice.
    fn sample_chosen(&self, i: usize, p: Vec3, u: Vec2) -> Option<LightSample> {
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

    /// [`Lights::sample`] from eight points `p` in lanes, with the numbers `u_select` and the
    /// pairs `u` (their first numbers, then their second) of each lane. The light is chosen lane
    /// by lane, and a mesh light's triangle for the lanes that chose one; the point on the
    /// triangle and a constant environment's direction are computed in lanes, and the one each
    /// lane chose kept. Other lights (spheres, points, suns, environment maps) are sampled lane
    /// by lane ([`Lights::sample`]).
    #[inline(always)]
    pub fn sample_lanes(&self, p: V3<F32x8>, u_select: [f32; 8], u: [F32x8; 2]) -> LightSampleLanes {
        let [u_x, u_y] = u;
        // Lanes written in place (arrays transposed afterwards were copied).
        let mut triangle = [V3::splat(0.0); 3];
        let mut normal = V3::splat(0.0);
        let (mut u_triangle, mut area) = ([0.0; 8], [1.0; 8]);
        let mut radiance = V3::splat(0.0);
        // Lanes that chose a light, that chose the constant sky, and those sampled one at a time
        // (with what that gave).
        let (mut chosen, mut sky, mut alone) = ([false; 8], [false; 8], [false; 8]);
        let (mut alone_wi, mut alone_point, mut alone_pdf) = (V3::splat(0.0), V3::splat(0.0), [0.0; 8]);
        let (mut alone_valid, mut alone_at_infinity, mut delta) = ([false; 8], [false; 8], [false; 8]);
        // The environment's index, where there is one: after the areas, points and suns, and
        // its radiance where it is constant.
        let sky_index = self.area.len() + self.points.len() + self.distant.len();
        let constant_sky = match &self.environment {
            Some(Environment::Constant(c)) => Some(*c),
            _ => None,
        };
        // Each lane's light, and as bits the lanes that chose a mesh light and those sampled
        // one at a time, without a branch on the lane's choice: one is mispredicted for every
        // other lane in a scene of one area light and a sky.
        let (mut choice, mut meshes, mut others) = ([0; 8], 0u32, 0u32);
        for lane in 0..8 {
            let Some(i) = self.choose(u_select[lane]) else { continue };
            (choice[lane], chosen[lane]) = (i, true);
            sky[lane] = (i == sky_index) & constant_sky.is_some();
            meshes |= u32::from(i < self.area.len()) << lane;
            others |= u32::from((i >= self.area.len()) & !sky[lane]) << lane;
        }
        for lane in set_bits(meshes) {
            let light = &self.area[choice[lane]];
            let Some((vertices, n, u_remapped)) = light.pick_triangle(u_x.0[lane]) else {
                // A sphere light: sampled alone, below.
                others |= 1 << lane;
                continue;
            };
            for (corner, v) in triangle.iter_mut().zip(vertices) {
                corner.set_lane(lane, v);
            }
            normal.set_lane(lane, n);
            (u_triangle[lane], area[lane]) = (u_remapped, light.area());
            radiance.set_lane(lane, light.radiance.into());
        }
        for lane in set_bits(others) {
            alone[lane] = true;
            let Some(s) = self.sample_chosen(choice[lane], p.lane(lane), Vec2::new(u_x.0[lane], u_y.0[lane])) else {
                continue;
            };
            (alone_valid[lane], alone_pdf[lane]) = (true, s.pdf);
            alone_wi.set_lane(lane, s.wi);
            alone_point.set_lane(lane, s.point.unwrap_or(Vec3::ZERO));
            alone_at_infinity[lane] = s.point.is_none();
            radiance.set_lane(lane, s.radiance.into());
            delta[lane] = s.delta;
        }
        let (q, pdf) = area::triangle_point_of(p, triangle, normal, [F32x8(u_triangle), u_y], F32x8(area));
        let toward = area::toward_light_of(p, q, normal, pdf);
        let (sky, alone) = (M32x8::from_bools(sky), M32x8::from_bools(alone));
        let sky_radiance = V3::from([Vec3::from(constant_sky.unwrap_or(Rgb::ZERO)); 8]);
        let radiance = V3::select(sky, sky_radiance, radiance);
        let pdf = F32x8::select(sky, F32x8::splat(crate::sampling::warp::UNIFORM_SPHERE_PDF), pdf);
        let wi = V3::select(sky, crate::sampling::warp::square_to_uniform_sphere_of([u_x, u_y]), toward.wi);
        let in_lanes_valid = sky | toward.valid;
        LightSampleLanes {
            wi: V3::select(alone, alone_wi, wi),
            radiance,
            pdf: F32x8::select(alone, F32x8(alone_pdf), pdf * F32x8::splat(self.selection_pdf())),
            point: V3::select(alone, alone_point, toward.point),
            at_infinity: sky | M32x8::from_bools(alone_at_infinity),
            delta: M32x8::from_bools(delta),
            valid: M32x8::from_bools(chosen) & ((alone & M32x8::from_bools(alone_valid)) | (!alone & in_lanes_valid)),
        }
    }

    /// Radiance arriving along `direction` (of any length) from the lights at infinity (the
    /// environment and suns), seen by a path that left its last vertex along it with BSDF
    /// density `bsdf_pdf`, weighted against next-event estimation by the power heuristic; None
    /// for a direction sampled with a delta (the camera's, or a smooth BSDF's): full weight. The
    /// direction is normalised only where a light reads it: a constant sky alone does not, and
    /// a path that leaves the scene under one spends no square root and division here.
    pub fn arriving_from_infinity(&self, direction: Vec3, bsdf_pdf: Option<f32>) -> Rgb {
        let reads_direction = matches!(self.environment, Some(Environment::Map(_))) || !self.distant.is_empty();
        let d = if reads_direction { direction.normalize() } else { direction };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Sphere;
    use crate::simd::Isa;
    use crate::simd::testing::{direction, gather, isas, numbers};

    #[test]
    fn lanes_sample_the_lights_as_one_point_does() {
        // Two mesh lights (one of two triangles) of different radiance and a constant sky.
        let square = vec![
            [Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, 0.5)],
            [Vec3::new(-0.5, 2.0, -0.5), Vec3::new(0.5, 2.0, 0.5), Vec3::new(-0.5, 2.0, 0.5)],
        ];
        let tilted = vec![[Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0), Vec3::new(2.5, 0.0, 1.0)]];
        // A sphere light and a point light are sampled one lane at a time.
        let sphere = Sphere::new(glam::Mat4::from_translation(Vec3::new(-2.0, 0.5, 0.0)), false).unwrap();
        let lights = Lights {
            area: vec![
                AreaLight::new(square, Rgb::splat(5.0)),
                AreaLight::new(tilted, Rgb::new(1.0, 2.0, 3.0)),
                AreaLight::sphere(sphere, Rgb::new(3.0, 2.0, 1.0)),
            ],
            points: vec![PointLight {
                position: Vec3::new(0.0, 3.0, 1.0),
                intensity: Rgb::ONE,
                spot: None,
                range: None,
            }],
            environment: Some(Environment::Constant(Rgb::new(0.2, 0.3, 0.4))),
            ..Default::default()
        };
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        let mut seen = [0; 3];
        for isa in isas() {
            for chunk in 0..2000 {
                // Points around the lights: in front of them, behind, and on them.
                let p = |i: usize| match (chunk + i) % 53 {
                    0 => Vec3::new(0.1, 2.0, 0.1),
                    _ => direction(chunk * 8 + i) * 3.0,
                };
                let u_select: [f32; 8] = std::array::from_fn(|i| numbers(chunk + 7, i)[0]);
                let u: [[f32; 2]; 8] = std::array::from_fn(|i| numbers(chunk, i));
                let u_lanes = [F32x8::from_fn(|i| u[i][0]), F32x8::from_fn(|i| u[i][1])];
                let lanes = isa.run(|| lights.sample_lanes(gather(p), u_select, u_lanes));
                for i in 0..8 {
                    let Some(one) = lights.sample(p(i), u_select[i], Vec2::from(u[i])) else {
                        assert!(!lanes.valid.test(i), "{isa:?} p {} u {:?}", p(i), u[i]);
                        seen[2] += 1;
                        continue;
                    };
                    assert!(lanes.valid.test(i), "{isa:?} p {} u {:?}", p(i), u[i]);
                    assert_eq!(bits(lanes.radiance.lane(i)), bits(one.radiance.into()));
                    assert_eq!(lanes.pdf.0[i].to_bits(), one.pdf.to_bits());
                    assert_eq!(lanes.delta.test(i), one.delta);
                    match one.point {
                        // A mesh light's sample involves no sine, the others are one lane's:
                        // the same bits.
                        Some(point) => {
                            assert!(!lanes.at_infinity.test(i));
                            assert_eq!(bits(lanes.wi.lane(i)), bits(one.wi), "{isa:?} p {} u {:?}", p(i), u[i]);
                            assert_eq!(bits(lanes.point.lane(i)), bits(point));
                            seen[0] += 1;
                        }
                        // The sky's direction is within the lanes' sine of the libm one's.
                        None => {
                            assert!(lanes.at_infinity.test(i));
                            assert!(lanes.wi.lane(i).distance(one.wi) < 4e-7, "{} {}", lanes.wi.lane(i), one.wi);
                            seen[1] += 1;
                        }
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 500), "points, sky and failed samples seen {seen:?} times");
        // Without lights, no lane has a sample.
        let none =
            Isa::Portable.run(|| Lights::default().sample_lanes(gather(direction), [0.5; 8], [F32x8::splat(0.5); 2]));
        assert_eq!(none.valid, M32x8::from_bools([false; 8]));
    }
}
