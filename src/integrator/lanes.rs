//! Shading eight paths at a time (issue 19): the stage of [`PathTracer::trace_wave`] that
//! shades a group of up to eight path vertices on triangles of one material in SIMD lanes
//! ([`crate::simd`]), where the material is written over [`Real`]: rough conductors with
//! constant parameters and diffuse surfaces (their reflectance looked up path by path), without
//! normal maps or texture frames. Mesh lights and a constant environment are sampled in lanes,
//! other lights lane by lane ([`crate::light::Lights::sample_lanes`]). Other vertices are
//! shaded one at a time ([`PathTracer::shade`]).
//!
//! Lanes gather what they need path by path (the triangle, the ray, the sampler's stream, the
//! light's triangle, the texture's reflectance), writing each lane in place, compute the random
//! numbers, the hit point, the shading frame, the light sample, both BSDF evaluations, the MIS
//! weight, the shadow ray and the next ray eight at a time, and hand the results back path by
//! path. Each path draws the numbers that a path shaded alone draws, in the same order (the
//! light's choice, its point, the lobe, the direction, Russian roulette), and nothing a lane
//! computes depends on the other lanes, so the image depends neither on how paths are grouped
//! nor on the instruction set ([`crate::simd::Isa`]). It differs from one-at-a-time shading only
//! by the lanes' sine and cosine ([`crate::simd::trig`]), within the last bits of a sampled
//! direction.

use super::path::{Path, PathTracer, PreviousVertex, ShadowTest, lookup_at};
use crate::bsdf::fresnel::fresnel_conductor_of;
use crate::bsdf::{Bsdf, Conductor, ConductorFresnel, Diffuse, Ggx};
use crate::color::Rgb;
use crate::geometry::{
    Frame, FrameOf, Ray, SHADOW_RAY_T_MAX, SurfaceInteraction, TriangleSurface, offset_ray_origin_of, shadow_ray_to_of,
    triangle_surface_of,
};
use crate::material::{ColorParam, Material, MaterialKind};
use crate::sampling::{SamplerLanes, power_heuristic_of};
use crate::simd::{F32x8, M32x8, Real, V3};
use crate::texture::{TexCtx, Texture};
use glam::Vec2;

/// Eight lanes.
pub(super) const LANES: usize = 8;

/// How lanes shade a material ([`LaneBsdf::of`]).
#[derive(Clone, Copy, Debug)]
pub(super) enum LaneBsdf {
    /// A rough conductor with constant parameters.
    RoughConductor {
        /// Its microfacet distribution.
        ggx: Ggx,
        /// Real part of the IOR.
        eta: Rgb,
        /// Imaginary part of the IOR.
        k: Rgb,
        /// Factor on the reflectance.
        specular_reflectance: Rgb,
    },
    /// Lambertian reflection, its reflectance looked up path by path.
    Diffuse {
        /// The reflectance (a colour or a texture).
        reflectance: ColorParam,
    },
}

impl LaneBsdf {
    /// How lanes shade `material`, if they can: a rough conductor whose parameters are constant,
    /// or a diffuse BSDF; neither under a normal map or a texture frame.
    pub(super) fn of(material: &Material, textures: &[Texture]) -> Option<LaneBsdf> {
        if material.normal_map.is_some() || material.texture_frame.is_some() {
            return None;
        }
        if let MaterialKind::Diffuse { reflectance } = material.kind {
            return Some(LaneBsdf::Diffuse { reflectance });
        }
        let anywhere = TexCtx { uv: Vec2::ZERO, duv_dx: Vec2::ZERO, duv_dy: Vec2::ZERO, uv_mirrored: None };
        match material.bsdf(textures, &anywhere) {
            Bsdf::Conductor(Conductor {
                ggx: Some(ggx),
                fresnel: ConductorFresnel::Complex { eta, k },
                specular_reflectance,
            }) if material.textures().is_empty() => {
                Some(LaneBsdf::RoughConductor { ggx, eta, k, specular_reflectance })
            }
            _ => None,
        }
    }
}

/// What the lanes gather from the paths of a group.
#[derive(Default)]
struct Gathered {
    triangle: [V3<F32x8>; 3],
    normals: [V3<F32x8>; 3],
    uvs: [[F32x8; 2]; 3],
    b1: F32x8,
    b2: F32x8,
    direction: V3<F32x8>,
    throughput: V3<F32x8>,
    u_select: [f32; LANES],
    u_light: [F32x8; 2],
    u_direction: [F32x8; 2],
}

/// What the lanes hand back to the paths of a group.
struct Shaded {
    /// Where next-event estimation's sample adds `contribution` if `shadow_ray` is clear.
    contributes: M32x8,
    contribution: V3<F32x8>,
    shadow_origin: V3<F32x8>,
    shadow_direction: V3<F32x8>,
    shadow_t_max: F32x8,
    /// Where the BSDF sample continues the path.
    continues: M32x8,
    weight: V3<F32x8>,
    pdf: F32x8,
    next_origin: V3<F32x8>,
    next_direction: V3<F32x8>,
}

impl PathTracer<'_> {
    /// Shade the paths `group` (one to eight indices into `paths`), whose rays hit triangles of
    /// material `material` that lanes shade as `bsdf`: queue their light samples' shadow tests
    /// in `shadow`, continue their rays, and push the paths that go on to `alive`.
    pub(super) fn shade_lanes(
        &self,
        bsdf: LaneBsdf,
        material: u32,
        group: &[usize],
        paths: &mut [Path],
        shadow: &mut Vec<ShadowTest>,
        alive: &mut Vec<usize>,
    ) {
        debug_assert!((1..=LANES).contains(&group.len()));
        let (scene, isa) = (self.scene, self.isa);
        let gathered = &mut Gathered::default();
        self.gather(group, paths, gathered);
        let two_sided = scene.materials[material as usize].two_sided;
        // One AVX2 function for the whole stage, the reflectance lookups and the paths' updates
        // included: what one part returned to the next (hit points, frames, the shaded lanes)
        // was copied on the way.
        isa.run(
            #[inline(always)]
            || {
                let s =
                    triangle_surface_of(gathered.triangle, gathered.normals, gathered.uvs, gathered.b1, gathered.b2);
                let mut frame = FrameOf::from_normal_tangent(s.shading_normal, s.dpdu);
                let wo = -gathered.direction.normalize();
                let reflectance = match bsdf {
                    LaneBsdf::Diffuse { reflectance } => {
                        self.reflectances(reflectance, group, paths, material, &s, &frame, wo)
                    }
                    LaneBsdf::RoughConductor { .. } => V3::splat(0.0),
                };
                // Two-sided materials see the back as the front: the normal mirrored to the viewer.
                if two_sided {
                    frame.n = V3::select(frame.n.dot(wo).lt(F32x8::splat(0.0)), -frame.n, frame.n);
                }
                let shaded = shade(bsdf, &scene.lights, gathered, &s, &frame, wo, reflectance);
                self.scatter(&shaded, &s.p, group, paths, shadow, alive);
            },
        );
    }

    /// Hand the lanes' results `shaded` (at hit points `points`) back to the paths of `group`:
    /// queue their shadow tests in `shadow`, continue their rays, and push the paths that go on
    /// to `alive`.
    #[inline(always)]
    fn scatter(
        &self,
        shaded: &Shaded,
        points: &V3<F32x8>,
        group: &[usize],
        paths: &mut [Path],
        shadow: &mut Vec<ShadowTest>,
        alive: &mut Vec<usize>,
    ) {
        for (lane, &index) in group.iter().enumerate() {
            let path = &mut paths[index];
            if shaded.contributes.test(lane) {
                let ray = Ray {
                    o: shaded.shadow_origin.lane(lane),
                    d: shaded.shadow_direction.lane(lane),
                    t_max: shaded.shadow_t_max.0[lane],
                };
                shadow.push(ShadowTest { path: index, ray, contribution: shaded.contribution.lane(lane).into() });
            }
            if !shaded.continues.test(lane) {
                continue;
            }
            path.throughput *= Rgb::from(shaded.weight.lane(lane));
            path.prev = PreviousVertex { p: points.lane(lane), pdf: shaded.pdf.0[lane], delta: false };
            path.ray = Ray::new(shaded.next_origin.lane(lane), shaded.next_direction.lane(lane));
            path.depth += 1;
            if self.survives_roulette(path) {
                alive.push(index);
            }
        }
    }

    /// The group's triangles, rays and throughputs, and the numbers each path draws for its
    /// light sample and its BSDF sample (the lobe's number too, unused by these BSDFs, so that
    /// the paths draw what one-at-a-time shading draws). Lanes past the group's end repeat its
    /// last path, and its first path's numbers, without drawing. Written into `gathered`, lane
    /// by lane where they are kept: arrays transposed afterwards, or locals moved into the
    /// struct at the end, were copied.
    fn gather(&self, group: &[usize], paths: &mut [Path], gathered: &mut Gathered) {
        let Gathered { triangle, normals, uvs, b1, b2, direction, throughput, u_select, u_light, u_direction } =
            gathered;
        let mut draws = SamplerLanes { keys: [0; LANES], dimensions: [0; LANES] };
        let mut primitive = [0; LANES];
        for lane in 0..LANES {
            let path = &mut paths[group[lane.min(group.len() - 1)]];
            let hit = path.hit.expect("lanes shade hits");
            (primitive[lane], b1.0[lane], b2.0[lane]) = (hit.primitive, hit.b1, hit.b2);
            direction.set_lane(lane, path.ray.d);
            throughput.set_lane(lane, path.throughput.into());
            // The light's choice, its point, the lobe, the direction: four draws.
            (draws.keys[lane], draws.dimensions[lane]) =
                if lane < group.len() { path.sampler.reserve(4) } else { (draws.keys[0], draws.dimensions[0]) };
        }
        (*u_select, *u_light, *u_direction) = self.isa.run(
            #[inline(always)]
            || (draws.draw_1d(0), draws.draw_2d(1).map(F32x8), draws.draw_2d(3).map(F32x8)),
        );
        for (lane, &primitive) in primitive.iter().enumerate() {
            self.gather_triangle(primitive, lane, triangle, normals, uvs);
        }
    }

    /// Lane `lane` of the vertices, normals (zero where the mesh has none) and texture
    /// coordinates of triangle `primitive`.
    fn gather_triangle(
        &self,
        primitive: u32,
        lane: usize,
        triangle: &mut [V3<F32x8>; 3],
        normals: &mut [V3<F32x8>; 3],
        uvs: &mut [[F32x8; 2]; 3],
    ) {
        for corner in 0..3 {
            let (p, n, uv) = self.scene.geometry.triangle_corner(primitive as usize, corner);
            triangle[corner].set_lane(lane, p);
            normals[corner].set_lane(lane, n);
            uvs[corner][0].0[lane] = uv.x;
            uvs[corner][1].0[lane] = uv.y;
        }
    }

    /// The diffuse reflectance `reflectance` of each path of the group at its hit (`s`, with
    /// shading frame `frame`, seen from `wo`), looked up path by path with its texture footprint.
    /// Whether the UV map is mirrored is taken from the lanes, as are the hit's vectors: reading
    /// them back from a `SurfaceInteraction` written lane by lane stalls on its stores.
    #[allow(clippy::too_many_arguments)]
    fn reflectances(
        &self,
        reflectance: ColorParam,
        group: &[usize],
        paths: &[Path],
        material: u32,
        s: &TriangleSurface<F32x8>,
        frame: &FrameOf<F32x8>,
        wo: V3<F32x8>,
    ) -> V3<F32x8> {
        if group.iter().all(|&index| !self.wants_footprint(material, paths[index].depth))
            && let Some(reflectances) = self.image_reflectances_at_points(reflectance, s)
        {
            return reflectances;
        }
        let uv_mirrored = self.isa.run(
            #[inline(always)]
            || s.dpdu.cross(s.dpdv).dot(s.ng).lt(F32x8::splat(0.0)),
        );
        let mut reflectances = V3::splat(0.0);
        for (lane, &index) in group.iter().enumerate() {
            let path = &paths[index];
            let uv = Vec2::new(s.uv[0].0[lane], s.uv[1].0[lane]);
            let mirrored = uv_mirrored.test(lane);
            let ctx = if self.wants_footprint(material, path.depth) {
                let hit = path.hit.expect("lanes shade hits");
                let mut si = SurfaceInteraction {
                    p: s.p.lane(lane),
                    ng: s.ng.lane(lane),
                    frame: Frame { s: frame.s.lane(lane), t: frame.t.lane(lane), n: frame.n.lane(lane) },
                    uv,
                    dpdu: s.dpdu.lane(lane),
                    dpdv: s.dpdv.lane(lane),
                    duv_dx: Vec2::ZERO,
                    duv_dy: Vec2::ZERO,
                    wo: wo.lane(lane),
                    t: hit.t,
                    primitive: hit.primitive,
                };
                self.set_texture_footprint(&mut si, material, path.depth, path.ray.o, &path.diff);
                lookup_at(&si, mirrored)
            } else {
                // A lookup at the point: no hit point to build.
                TexCtx { uv, duv_dx: Vec2::ZERO, duv_dy: Vec2::ZERO, uv_mirrored: Some(mirrored) }
            };
            reflectances.set_lane(lane, reflectance.eval(&self.scene.textures, &ctx).into());
        }
        reflectances
    }

    /// The diffuse reflectance `reflectance` at the points `s` where it is an image looked up at
    /// the point (no footprint), four lookups' addresses at a time
    /// ([`crate::texture::ImageTexture::eval_prepared_x4`]): bit for bit [`ColorParam::eval`]
    /// there. None for other reflectances, and images that lanes do not serve.
    fn image_reflectances_at_points(&self, reflectance: ColorParam, s: &TriangleSurface<F32x8>) -> Option<V3<F32x8>> {
        let ColorParam::Texture { id, scale } = reflectance else { return None };
        let Texture::Image(image) = &self.scene.textures[id.0 as usize] else { return None };
        // The footprint every lookup without derivatives has.
        let footprint = image.prepare(Vec2::ZERO, Vec2::ZERO);
        let mut reflectances: V3<F32x8> = V3::splat(0.0);
        for quad in [0, 4] {
            let uv = std::array::from_fn(|l| Vec2::new(s.uv[0].0[quad + l], s.uv[1].0[quad + l]));
            let [r, g, b] = image.eval_rgb_x4(uv, &footprint)?;
            // Each lane's colour times the scale, channel by channel, as `ColorParam::eval`.
            let scaled = [r * scale.x, g * scale.y, b * scale.z];
            for (lanes, value) in
                [&mut reflectances.x, &mut reflectances.y, &mut reflectances.z].into_iter().zip(scaled)
            {
                lanes.0[quad..quad + 4].copy_from_slice(&value.to_array());
            }
        }
        Some(reflectances)
    }
}

/// Channel by channel product of two colours (red, green, blue as x, y, z).
#[inline(always)]
fn tint(a: V3<F32x8>, b: V3<F32x8>) -> V3<F32x8> {
    V3::new(a.x * b.x, a.y * b.y, a.z * b.z)
}

/// The rough conductor's colour F(cos_m) times its specular reflectance, channel by channel
/// ([`crate::bsdf::ConductorFresnel::eval`]).
#[inline(always)]
fn conductor_colour(cos_m: F32x8, eta: Rgb, k: Rgb, specular_reflectance: Rgb) -> V3<F32x8> {
    V3::new(
        conductor_channel(cos_m, eta.x, k.x, specular_reflectance.x),
        conductor_channel(cos_m, eta.y, k.y, specular_reflectance.y),
        conductor_channel(cos_m, eta.z, k.z, specular_reflectance.z),
    )
}

/// One channel of [`conductor_colour`] (a function, not a closure: lane code must inline into
/// [`crate::simd::Isa::run`]'s AVX2 function, and LLVM left the closure out of line).
#[inline(always)]
fn conductor_channel(cos_m: F32x8, eta: f32, k: f32, specular_reflectance: f32) -> F32x8 {
    fresnel_conductor_of(cos_m, F32x8::splat(eta), F32x8::splat(k)) * F32x8::splat(specular_reflectance)
}

/// The lanes' shading at hits `s` (shading frame `frame`, seen from `wo`): next-event
/// estimation's light sample with its BSDF value and MIS weight, and the BSDF sample that
/// continues each path; `reflectance` is the diffuse BSDF's.
#[inline(always)]
fn shade(
    bsdf: LaneBsdf,
    lights: &crate::light::Lights,
    gathered: &Gathered,
    s: &TriangleSurface<F32x8>,
    frame: &FrameOf<F32x8>,
    wo: V3<F32x8>,
    reflectance: V3<F32x8>,
) -> Shaded {
    let zero = F32x8::splat(0.0);
    let wo_local = frame.to_local(wo);

    // Next-event estimation.
    let light = lights.sample_lanes(s.p, gathered.u_select, gathered.u_light);
    let wi_local = frame.to_local(light.wi);
    let (f, bsdf_pdf) = match bsdf {
        LaneBsdf::RoughConductor { ggx, eta, k, specular_reflectance } => {
            let terms = Conductor::eval_terms(&ggx, wo_local, wi_local);
            let f = conductor_colour(terms.cos_m, eta, k, specular_reflectance) * terms.factor;
            (V3::select(terms.valid, f, V3::splat(0.0)), F32x8::select(terms.valid, terms.pdf, zero))
        }
        LaneBsdf::Diffuse { .. } => {
            let (factor, pdf, valid) = Diffuse::eval_terms(wo_local, wi_local);
            (V3::select(valid, reflectance * factor, V3::splat(0.0)), F32x8::select(valid, pdf, zero))
        }
    };
    let contributes = light.valid & !f.is_zero() & zero.lt(light.pdf);
    let weight = F32x8::select(light.delta, F32x8::splat(1.0), power_heuristic_of(light.pdf, bsdf_pdf));
    let contribution = tint(tint(gathered.throughput, f), light.radiance) * (weight / light.pdf);
    let (to_point, along_point) = shadow_ray_to_of(s.p, s.ng, light.point);
    let to_infinity = offset_ray_origin_of(s.p, s.ng, light.wi);

    // The BSDF sample that continues the path.
    let (wi_local, weight, pdf, continues) = match bsdf {
        LaneBsdf::RoughConductor { ggx, eta, k, specular_reflectance } => {
            let terms = Conductor::sample_terms(&ggx, wo_local, gathered.u_direction);
            let colour = conductor_colour(terms.cos_m, eta, k, specular_reflectance);
            (terms.wi, colour * terms.factor, terms.pdf, zero.lt(wo_local.z) & terms.valid)
        }
        LaneBsdf::Diffuse { .. } => {
            let (wi, pdf, valid) = Diffuse::sample_terms(wo_local, gathered.u_direction);
            (wi, reflectance, pdf, valid)
        }
    };
    let wi = frame.to_world(wi_local);
    Shaded {
        contributes,
        contribution,
        shadow_origin: V3::select(light.at_infinity, to_infinity, to_point),
        shadow_direction: V3::select(light.at_infinity, light.wi, along_point),
        shadow_t_max: F32x8::select(light.at_infinity, F32x8::splat(f32::INFINITY), F32x8::splat(SHADOW_RAY_T_MAX)),
        continues,
        weight,
        pdf,
        next_origin: offset_ray_origin_of(s.p, s.ng, wi),
        next_direction: wi,
    }
}
