//! The path tracer: unidirectional, with next-event estimation and multiple importance sampling
//! (power heuristic) for the lights that paths can hit, and Russian roulette.
//!
//! Path length follows Mitsuba 3's count: `max_depth` is the number of path segments, so 1
//! shows only emitters seen directly and 2 adds direct lighting. Russian roulette starts once
//! `rr_depth` segments are traced, continuing with probability min(max(throughput) eta^2, 0.95).

use crate::accel::Hit;
use crate::color::Rgb;
use crate::geometry::{Frame, Ray, RayDifferential};
use crate::sampling::{Sampler, power_heuristic};
use crate::scene::Scene;
use crate::texture::TexCtx;
use glam::{Vec2, Vec3};

/// What the camera ray's first hit looked like, for the AOVs.
#[derive(Clone, Copy, Debug, Default)]
pub struct FirstHit {
    /// The BSDF's reflectance colour.
    pub albedo: Rgb,
    /// Shading normal (world).
    pub normal: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// max(|duv/dx|, |duv/dy|).
    pub footprint: f32,
    /// World position.
    pub position: Vec3,
    /// Distance from the camera ray's origin.
    pub depth: f32,
}

/// Largest continuation probability of Russian roulette (Mitsuba's).
const RR_MAX_PROBABILITY: f32 = 0.95;

/// The path tracer over a scene.
pub struct PathTracer<'a> {
    scene: &'a Scene,
    max_depth: u32,
    rr_depth: u32,
    /// Per material: whether a hit on it needs the texture footprint.
    needs_footprint: Vec<bool>,
    /// Whether the first hit is recorded at all (some AOV is written).
    record_first_hit: bool,
    /// Whether the first hit's footprint is recorded (the footprint AOV).
    record_footprint: bool,
}

/// How the previous vertex sampled the current ray, for MIS at the next emitter hit.
struct PreviousVertex {
    p: Vec3,
    pdf: f32,
    delta: bool,
}

impl<'a> PathTracer<'a> {
    /// A tracer with the scene's settings; `record_first_hit` fills `trace`'s `first_hit`, and
    /// `record_footprint` computes its texture footprint even where no filtered texture needs it.
    pub fn new(scene: &'a Scene, record_first_hit: bool, record_footprint: bool) -> Self {
        let needs_footprint = scene
            .materials
            .iter()
            .map(|m| m.textures().iter().any(|id| scene.textures[id.0 as usize].uses_footprint()))
            .collect();
        PathTracer {
            scene,
            max_depth: scene.settings.max_depth.unwrap_or(u32::MAX),
            rr_depth: scene.settings.rr_depth,
            needs_footprint,
            record_first_hit,
            record_footprint,
        }
    }

    /// Radiance arriving along the camera ray `ray` (with differentials `diff`), whose closest
    /// hit is `primary` (the renderer traces a pixel's camera rays together, as a packet);
    /// `first_hit` is filled where the tracer records first hits and the ray hits something.
    pub fn trace(
        &self,
        mut ray: Ray,
        primary: Option<Hit>,
        diff: &RayDifferential,
        sampler: &mut Sampler,
        first_hit: &mut Option<FirstHit>,
    ) -> Rgb {
        let scene = self.scene;
        let lights = &scene.lights;
        let mut radiance = Rgb::ZERO;
        let mut throughput = Rgb::ONE;
        let mut eta_scale = 1.0f32;
        // The camera "samples" its ray with a delta: emitters seen directly get full weight.
        let mut prev = PreviousVertex { p: ray.o, pdf: 1.0, delta: true };
        let mut depth = 0u32;
        loop {
            let hit = if depth == 0 { primary } else { scene.accel.intersect(&ray) };
            let Some(hit) = hit else {
                let bsdf_pdf = (!prev.delta).then_some(prev.pdf);
                radiance += throughput * lights.arriving_from_infinity(ray.d.normalize(), bsdf_pdf);
                break;
            };
            let mut si = scene.interaction(&ray, &hit);
            let shape = scene.shape_of(si.primitive);

            if let Some(light) = shape.light {
                let emitted = lights.area[light as usize].emitted(si.ng, si.wo);
                if emitted != Rgb::ZERO {
                    let w = if prev.delta {
                        1.0
                    } else {
                        power_heuristic(prev.pdf, lights.area_pdf(light as usize, prev.p, -si.wo, si.p, si.ng))
                    };
                    radiance += throughput * emitted * w;
                }
            }
            if depth + 1 >= self.max_depth {
                break;
            }

            // Texture footprint, where a filtered texture needs it: from the camera ray's
            // differentials at the first hit, from the camera-based approximation after (pbrt-v4).
            let wants_footprint =
                self.needs_footprint[shape.material as usize] || (depth == 0 && self.record_footprint);
            if wants_footprint && (depth > 0 || !si.footprint_from_differential(ray.o, diff)) {
                let (dpdx, dpdy) = scene.camera.approximate_dp_dxy(si.p, si.ng);
                si.set_footprint(dpdx, dpdy);
            }
            let ctx = TexCtx { uv: si.uv, duv_dx: si.duv_dx, duv_dy: si.duv_dy, uv_mirrored: Some(si.uv_mirrored()) };
            let material = &scene.materials[shape.material as usize];
            let bsdf = material.bsdf(&scene.textures, &ctx);
            // Two-sided materials see the back as the front: mirror the local z axis to the
            // viewer's side (Mitsuba's `twosided`), before any normal map perturbs the frame.
            let mut base = si.frame;
            if material.two_sided && base.n.dot(si.wo) < 0.0 {
                base = Frame { n: -base.n, ..base };
            }
            let shading = material.shading(&scene.textures, &ctx, base, si.dpdu, si.dpdv);
            let frame = shading.frame;
            let wo = frame.to_local(si.wo);
            if depth == 0 && self.record_first_hit {
                *first_hit = Some(FirstHit {
                    albedo: bsdf.albedo(),
                    normal: frame.n,
                    uv: si.uv,
                    footprint: si.duv_dx.abs().max(si.duv_dy.abs()).max_element(),
                    position: si.p,
                    depth: si.p.distance(ray.o),
                });
            }

            // Next-event estimation.
            let u_light = sampler.next_1d();
            let u_light2 = sampler.next_2d();
            if !bsdf.is_delta() {
                if let Some(ls) = lights.sample(si.p, u_light, u_light2) {
                    let wi = frame.to_local(ls.wi);
                    let f = bsdf.eval(wo, wi) * shading.light_factor(ls.wi);
                    if f != Rgb::ZERO && ls.pdf > 0.0 {
                        let shadow = match ls.point {
                            Some(q) => si.spawn_ray_to(q),
                            None => si.spawn_ray(ls.wi),
                        };
                        if !scene.occluded(&shadow) {
                            let w = if ls.delta { 1.0 } else { power_heuristic(ls.pdf, bsdf.pdf(wo, wi)) };
                            radiance += throughput * f * ls.radiance * (w / ls.pdf);
                        }
                    }
                }
            }

            // Continue the path by sampling the BSDF.
            let u_lobe = sampler.next_1d();
            let u_dir = sampler.next_2d();
            let Some(bs) = bsdf.sample(wo, u_lobe, u_dir) else {
                break;
            };
            let wi = frame.to_world(bs.wi);
            let factor = shading.light_factor(wi);
            if factor == 0.0 {
                break;
            }
            throughput *= bs.weight * factor;
            eta_scale *= bs.eta;
            prev = PreviousVertex { p: si.p, pdf: bs.pdf, delta: bs.delta };
            ray = si.spawn_ray(wi);
            depth += 1;

            if depth >= self.rr_depth {
                let q = (throughput.max_element() * eta_scale * eta_scale).min(RR_MAX_PROBABILITY);
                if sampler.next_1d() >= q {
                    break;
                }
                throughput /= q;
            }
            if throughput.max_element() <= 0.0 {
                break;
            }
        }
        radiance
    }
}
