//! The path tracer: unidirectional, with next-event estimation and multiple importance sampling
//! (power heuristic) for the lights that paths can hit, and Russian roulette.
//!
//! Paths are traced as a wavefront: every path of a batch is shaded at its current vertex, then
//! all their shadow rays are tested, then all their next rays are traced, and again, until
//! every path has ended. Each path draws its random numbers in the order of a path traced
//! alone and adds its terms to its radiance in that order (emission, then the light sample of
//! the vertex, then the next vertex's emission), so that the image does not depend on how the
//! paths are batched. The shading stage groups the paths by the material of their hit and
//! shades those whose material lanes support eight at a time in SIMD lanes
//! ([`super::lanes`]); the others one at a time (docs/design-decisions.md, "The wavefront",
//! "Shading in lanes").
//!
//! Path length follows Mitsuba 3's count: `max_depth` is the number of path segments, so 1
//! shows only emitters seen directly and 2 adds direct lighting. Russian roulette starts once
//! `rr_depth` segments are traced, continuing with probability min(max(throughput) eta^2, 0.95).

use super::lanes::{LANES, LaneBsdf};
use crate::accel::Hit;
use crate::color::Rgb;
use crate::geometry::{Frame, Ray, RayDifferential, SurfaceInteraction};
use crate::sampling::{PixelKey, Sampler, power_heuristic};
use crate::scene::Scene;
use crate::simd::Isa;
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
    pub(super) scene: &'a Scene,
    max_depth: u32,
    rr_depth: u32,
    /// Per material: whether a hit on it needs the texture footprint.
    needs_footprint: Vec<bool>,
    /// Whether the first hit is recorded at all (some AOV is written).
    record_first_hit: bool,
    /// Whether the first hit's footprint is recorded (the footprint AOV).
    record_footprint: bool,
    /// Per material: how lanes shade it, if they can ([`LaneBsdf::of`]).
    lane_bsdfs: Vec<Option<LaneBsdf>>,
    /// The instruction set of the lanes.
    pub(super) isa: Isa,
}

/// How the previous vertex sampled the current ray, for MIS at the next emitter hit.
#[derive(Clone, Copy, Debug)]
pub(super) struct PreviousVertex {
    pub(super) p: Vec3,
    pub(super) pdf: f32,
    pub(super) delta: bool,
}

/// One path of a wavefront: where it is, what it carries, what it has gathered.
#[derive(Clone, Debug)]
pub struct Path {
    /// The ray to the next vertex (the camera ray at first).
    pub(super) ray: Ray,
    /// The camera ray's differentials (for the footprint at the first hit).
    pub(super) diff: RayDifferential,
    /// The closest hit of `ray`, once traced.
    pub(super) hit: Option<Hit>,
    pub(super) sampler: Sampler,
    pub(super) throughput: Rgb,
    eta_scale: f32,
    pub(super) prev: PreviousVertex,
    /// Segments traced so far (0: the camera ray).
    pub(super) depth: u32,
    /// Radiance gathered so far (all of it once the path has ended).
    pub radiance: Rgb,
    /// The camera ray's first hit, where the tracer records first hits and the ray hit something.
    pub first_hit: Option<FirstHit>,
}

/// A light sample waiting for its shadow ray: the path it belongs to and what it adds.
pub(super) struct ShadowTest {
    pub(super) path: usize,
    pub(super) ray: Ray,
    pub(super) contribution: Rgb,
}

/// The buffers of [`PathTracer::start_wave`] and [`PathTracer::trace_wave`], kept from one wave
/// to the next.
#[derive(Default)]
pub struct WaveBuffers {
    /// Each camera sample's sampler, film position and lens sample ([`PathTracer::start_wave`]).
    camera_draws: Vec<(Sampler, Vec2, Vec2)>,
    active: Vec<usize>,
    /// The paths that go on after the current vertex.
    alive: Vec<usize>,
    /// Per material, the paths whose vertices lanes shade.
    lane_groups: Vec<Vec<usize>>,
    shadow: Vec<ShadowTest>,
    camera_rays: Vec<Ray>,
    camera_hits: Vec<Option<Hit>>,
    rays: Vec<Ray>,
    hits: Vec<Option<Hit>>,
    blocked: Vec<bool>,
}

impl<'a> PathTracer<'a> {
    /// A tracer with the scene's settings; `record_first_hit` fills each path's `first_hit`,
    /// and `record_footprint` computes its texture footprint even where no filtered texture
    /// needs it.
    pub fn new(scene: &'a Scene, record_first_hit: bool, record_footprint: bool) -> Self {
        let needs_footprint = scene
            .materials
            .iter()
            .map(|m| m.textures().iter().any(|id| scene.textures[id.0 as usize].uses_footprint()))
            .collect();
        let lane_bsdfs = scene.materials.iter().map(|m| LaneBsdf::of(m, &scene.textures)).collect();
        PathTracer {
            scene,
            lane_bsdfs,
            isa: Isa::selected(),
            max_depth: scene.settings.max_depth.unwrap_or(u32::MAX),
            rr_depth: scene.settings.rr_depth,
            needs_footprint,
            record_first_hit,
            record_footprint,
        }
    }

    /// A path that starts with the camera ray `ray` (differentials `diff`), drawing its random
    /// numbers from `sampler`, for [`PathTracer::trace_wave`].
    pub fn start(&self, ray: Ray, diff: RayDifferential, sampler: Sampler) -> Path {
        Path {
            ray,
            diff,
            hit: None,
            sampler,
            throughput: Rgb::ONE,
            eta_scale: 1.0,
            // The camera "samples" its ray with a delta: emitters seen directly get full weight.
            prev: PreviousVertex { p: ray.o, pdf: 1.0, delta: true },
            depth: 0,
            radiance: Rgb::ZERO,
            first_hit: None,
        }
    }

    /// The paths of samples `samples` of each pixel of `pixels` (image coordinates), in that
    /// order, in `paths` (cleared first): each sample's sampler, the film position and lens
    /// sample it draws first, and its camera ray. In two passes over the wave, the draws then
    /// the rays: in one, each sample's hashing, ray and normalisation made one chain of latency
    /// too long for the processor to overlap with the next sample's.
    pub fn start_wave(
        &self,
        pixels: impl Iterator<Item = (u32, u32)>,
        samples: std::ops::Range<u32>,
        buffers: &mut WaveBuffers,
        paths: &mut Vec<Path>,
    ) {
        let (s, camera) = (&self.scene.settings, &self.scene.camera);
        let draws = &mut buffers.camera_draws;
        draws.clear();
        for (px, py) in pixels {
            let key = PixelKey::new(s.seed, py as u64 * s.width as u64 + px as u64);
            for i in samples.clone() {
                let mut sampler = key.sampler(i);
                let film = s.pixel_filter.film_position(px, py, sampler.next_2d());
                // A thin lens takes the next two dimensions; other cameras none, so that their
                // paths draw the same numbers as before lenses existed.
                let lens = if camera.needs_lens_sample() { sampler.next_2d() } else { Vec2::ZERO };
                draws.push((sampler, film, lens));
            }
        }
        paths.clear();
        paths.extend(draws.drain(..).map(|(sampler, film, lens)| {
            let (ray, diff) = camera.generate_ray(film, lens);
            self.start(ray, diff, sampler)
        }));
    }

    /// Trace every path of `paths` (fresh from [`PathTracer::start`]) to its end: trace all
    /// their camera rays, then shade all at their vertices, test all their shadow rays, trace
    /// all their next rays, and again.
    pub fn trace_wave(&self, paths: &mut [Path], buffers: &mut WaveBuffers) {
        let WaveBuffers { active, alive, lane_groups, shadow, camera_rays, camera_hits, rays, hits, blocked, .. } =
            buffers;
        lane_groups.resize_with(self.scene.materials.len(), Vec::new);
        // Neighbouring camera rays (a pixel's samples, or neighbouring pixels' in a pass of few
        // samples) are nearly parallel: the accelerator traces them as packets.
        camera_rays.clear();
        camera_rays.extend(paths.iter().map(|p| p.ray));
        camera_hits.clear();
        camera_hits.resize(paths.len(), None);
        self.scene.accel.intersect_many(camera_rays, camera_hits);
        for (path, hit) in paths.iter_mut().zip(camera_hits.iter()) {
            path.hit = *hit;
        }
        active.clear();
        active.extend(0..paths.len());
        while !active.is_empty() {
            shadow.clear();
            alive.clear();
            for &i in active.iter() {
                match self.lane_material(&paths[i]) {
                    Some(material) => lane_groups[material as usize].push(i),
                    None => {
                        if self.shade(i, &mut paths[i], shadow) {
                            alive.push(i);
                        }
                    }
                }
            }
            for (material, group) in lane_groups.iter_mut().enumerate() {
                if let Some(bsdf) = self.lane_bsdfs[material] {
                    for lanes in group.chunks(LANES) {
                        self.shade_lanes(bsdf, material as u32, lanes, paths, shadow, alive);
                    }
                }
                group.clear();
            }
            std::mem::swap(active, alive);
            self.scene.accel.queries(|queries| {
                rays.clear();
                rays.extend(shadow.iter().map(|test| test.ray));
                blocked.clear();
                blocked.resize(rays.len(), false);
                queries.occluded_each(rays, blocked);
                for (test, &blocked) in shadow.iter().zip(blocked.iter()) {
                    if !blocked {
                        paths[test.path].radiance += test.contribution;
                    }
                }
                rays.clear();
                rays.extend(active.iter().map(|&i| paths[i].ray));
                hits.clear();
                hits.resize(rays.len(), None);
                queries.intersect_each(rays, hits);
                for (&i, &hit) in active.iter().zip(hits.iter()) {
                    paths[i].hit = hit;
                }
            });
        }
    }

    /// Whether hits on triangles of material `material` are shaded eight at a time in lanes
    /// (`integrator::lanes`), unless they are emitters, the last vertex, or first hits recorded
    /// for AOVs.
    pub fn shades_in_lanes(&self, material: u32) -> bool {
        self.lane_bsdfs.get(material as usize).is_some_and(Option::is_some)
    }

    /// The material of `path`'s hit where lanes shade it: a triangle of a material they shade,
    /// not emitting, before the last segment, and not the first hit where that is recorded.
    fn lane_material(&self, path: &Path) -> Option<u32> {
        let hit = path.hit?;
        if hit.primitive as usize >= self.scene.geometry.triangles.len()
            || path.depth + 1 >= self.max_depth
            || (path.depth == 0 && self.record_first_hit)
        {
            return None;
        }
        let shape = self.scene.shape_of(hit.primitive);
        (shape.light.is_none() && self.lane_bsdfs[shape.material as usize].is_some()).then_some(shape.material)
    }

    /// Shade path `index` at the hit of its ray: add what it sees there, queue its light
    /// sample's shadow test, and sample its next ray. False when the path ends here.
    fn shade(&self, index: usize, path: &mut Path, shadow: &mut Vec<ShadowTest>) -> bool {
        let scene = self.scene;
        let lights = &scene.lights;
        let Path { ray, diff, hit, sampler, throughput, eta_scale, prev, depth, radiance, first_hit } = path;
        let Some(hit) = *hit else {
            let bsdf_pdf = (!prev.delta).then_some(prev.pdf);
            *radiance += *throughput * lights.arriving_from_infinity(ray.d, bsdf_pdf);
            return false;
        };
        let shape = scene.shape_of(hit.primitive);
        let last = *depth + 1 >= self.max_depth;
        if last && shape.light.is_none() {
            // Nothing to add here and nothing to sample: no hit point needed.
            return false;
        }
        let mut si = scene.interaction(ray, &hit);

        if let Some(light) = shape.light {
            let emitted = lights.area[light as usize].emitted(si.ng, si.wo);
            if emitted != Rgb::ZERO {
                let w = if prev.delta {
                    1.0
                } else {
                    power_heuristic(prev.pdf, lights.area_pdf(light as usize, prev.p, -si.wo, si.p, si.ng))
                };
                *radiance += *throughput * emitted * w;
            }
        }
        if last {
            return false;
        }

        self.set_texture_footprint(&mut si, shape.material, *depth, ray.o, diff);
        let ctx = lookup_at(&si, si.uv_mirrored());
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
        if *depth == 0 && self.record_first_hit {
            *first_hit = Some(FirstHit {
                albedo: bsdf.albedo(),
                normal: frame.n,
                uv: si.uv,
                footprint: si.duv_dx.abs().max(si.duv_dy.abs()).max_element(),
                position: si.p,
                depth: si.p.distance(ray.o),
            });
        }

        // Next-event estimation: the light sample's contribution, added if its shadow ray is
        // clear.
        let u_light = sampler.next_1d();
        let u_light2 = sampler.next_2d();
        if !bsdf.is_delta()
            && let Some(ls) = lights.sample(si.p, u_light, u_light2)
        {
            let wi = frame.to_local(ls.wi);
            let (f, bsdf_pdf) = bsdf.eval_pdf(wo, wi);
            let f = f * shading.light_factor(ls.wi);
            if f != Rgb::ZERO && ls.pdf > 0.0 {
                let ray = match ls.point {
                    Some(q) => si.spawn_ray_to(q),
                    None => si.spawn_ray(ls.wi),
                };
                let w = if ls.delta { 1.0 } else { power_heuristic(ls.pdf, bsdf_pdf) };
                shadow.push(ShadowTest {
                    path: index,
                    ray,
                    contribution: *throughput * f * ls.radiance * (w / ls.pdf),
                });
            }
        }

        // Continue the path by sampling the BSDF.
        let u_lobe = sampler.next_1d();
        let u_dir = sampler.next_2d();
        let Some(bs) = bsdf.sample(wo, u_lobe, u_dir) else {
            return false;
        };
        let wi = frame.to_world(bs.wi);
        let factor = shading.light_factor(wi);
        if factor == 0.0 {
            return false;
        }
        *throughput *= bs.weight * factor;
        *eta_scale *= bs.eta;
        *prev = PreviousVertex { p: si.p, pdf: bs.pdf, delta: bs.delta };
        *ray = si.spawn_ray(wi);
        *depth += 1;
        self.survives_roulette(path)
    }

    /// Whether a hit on `material` after `depth` segments needs its texture footprint: a
    /// filtered texture reads it, or the footprint AOV records it.
    pub(super) fn wants_footprint(&self, material: u32, depth: u32) -> bool {
        self.needs_footprint[material as usize] || (depth == 0 && self.record_footprint)
    }

    /// Set the texture footprint of `si` on `material`, for a path that has traced `depth`
    /// segments along rays from `o` (the camera ray's differentials `diff`), where a filtered
    /// texture needs it: from the camera ray's differentials at the first hit, from the
    /// camera-based approximation after (pbrt-v4).
    pub(super) fn set_texture_footprint(
        &self,
        si: &mut SurfaceInteraction,
        material: u32,
        depth: u32,
        o: Vec3,
        diff: &RayDifferential,
    ) {
        if self.wants_footprint(material, depth) && (depth > 0 || !si.footprint_from_differential(o, diff)) {
            let (dpdx, dpdy) = self.scene.camera.approximate_dp_dxy(si.p, si.ng);
            si.set_footprint(dpdx, dpdy);
        }
    }

    /// Russian roulette for a path that has just been continued: once `rr_depth` segments are
    /// traced, it goes on with probability min(max(throughput) eta^2, 0.95), its throughput
    /// divided by that. False when the path ends here, or carries nothing.
    pub(super) fn survives_roulette(&self, path: &mut Path) -> bool {
        let Path { sampler, throughput, eta_scale, depth, .. } = path;
        if *depth >= self.rr_depth {
            let q = (throughput.max_element() * *eta_scale * *eta_scale).min(RR_MAX_PROBABILITY);
            if sampler.next_1d() >= q {
                return false;
            }
            *throughput /= q;
        }
        // (NaN throughput goes on, as it always has: the film counts the sample as invalid.)
        !(throughput.max_element() <= 0.0)
    }
}

/// The texture lookup at `si`, with its footprint, on a UV map that is `uv_mirrored` there.
#[inline]
pub(super) fn lookup_at(si: &SurfaceInteraction, uv_mirrored: bool) -> TexCtx {
    TexCtx { uv: si.uv, duv_dx: si.duv_dx, duv_dy: si.duv_dy, uv_mirrored: Some(uv_mirrored) }
}
