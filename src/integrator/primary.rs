//! What camera rays through pixel centres see of one texture: the CPU side of
//! `tessera gpu-view`, which draws the same with a rasteriser and a fragment shader
//! (`shaders/view.wgsl`), and the comparison of the two.
//!
//! Each pixel's ray (film point (x + 1/2, y + 1/2), one sample per pixel, so differentials of
//! one pixel) meets the scene's closest triangle, and the texture is looked up there with the
//! footprint of its ray differentials, as the path tracer looks up a material's albedo at a
//! camera ray's first hit. Every surface shows the texture, whatever its material.

use crate::camera::Camera;
use crate::error::Result;
use crate::geometry::{Ray, SurfaceInteraction};
use crate::image::Bitmap;
use crate::image::compare::TexelDifference;
use crate::scene::{Geometry, Scene};
use crate::texture::{TexCtx, Texture};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// A view of one texture: per pixel its value, the footprint it was looked up with, and the
/// triangle seen.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimaryView {
    /// The texture's RGBA value; zero where nothing is seen.
    pub value: Bitmap,
    /// The footprint, RGBA = (du/dx, dv/dx, du/dy, dv/dy) for one-pixel steps right and down.
    pub footprint: Bitmap,
    /// The triangle seen, plus one; 0 where nothing is.
    pub triangle: Vec<u32>,
}

impl PrimaryView {
    /// An empty view (nothing seen) of `width` x `height` pixels.
    pub fn new(width: usize, height: usize) -> Self {
        PrimaryView {
            value: Bitmap::new(width, height, 4),
            footprint: Bitmap::new(width, height, 4),
            triangle: vec![0; width * height],
        }
    }
}

/// The texture lookup that the camera ray through film point `film` makes on the surface it
/// meets, and that surface.
pub fn primary_lookup(scene: &Scene, camera: &Camera, film: Vec2) -> Option<(TexCtx, SurfaceInteraction)> {
    let (ray, diff) = camera.generate_ray(film, glam::Vec2::ZERO);
    let hit = scene.accel.intersect(&ray)?;
    let mut si = scene.interaction(&ray, &hit);
    if !si.footprint_from_differential(ray.o, &diff) {
        let (dpdx, dpdy) = camera.approximate_dp_dxy(si.p, si.ng);
        si.set_footprint(dpdx, dpdy);
    }
    let ctx = super::path::lookup_at(&si, si.uv_mirrored());
    Some((ctx, si))
}

/// `texture` as `camera` sees it on `scene`'s surfaces at pixel centres (rows in parallel; the
/// result does not depend on the thread count).
pub fn primary_view(scene: &Scene, camera: &Camera, texture: &Texture) -> PrimaryView {
    let (width, height) = camera.resolution();
    let (width, height) = (width as usize, height as usize);
    let mut view = PrimaryView::new(width, height);
    view.value
        .data
        .par_chunks_mut(width * 4)
        .zip(view.footprint.data.par_chunks_mut(width * 4))
        .zip(view.triangle.par_chunks_mut(width))
        .enumerate()
        .for_each(|(y, ((value, footprint), triangle))| {
            for x in 0..width {
                let film = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                if let Some((ctx, si)) = primary_lookup(scene, camera, film) {
                    value[4 * x..4 * x + 4].copy_from_slice(&texture.eval(&ctx).to_array());
                    footprint[4 * x..4 * x + 4].copy_from_slice(&[
                        ctx.duv_dx.x,
                        ctx.duv_dx.y,
                        ctx.duv_dy.x,
                        ctx.duv_dy.y,
                    ]);
                    triangle[x] = si.primitive + 1;
                }
            }
        });
    view
}

/// Per pixel (row-major, 0 where nothing is seen), how far `texture`'s value at the camera
/// ray's hit moves when its UV moves by one f32 ulp along u or along v (the largest change over
/// channels and the two directions, the footprint kept): the difference that a view whose UVs
/// come from other arithmetic (a rasteriser's interpolation, another ray-triangle test, fused
/// multiply-adds) must expect from the UVs' last bits alone.
pub fn ulp_sensitivity(scene: &Scene, camera: &Camera, texture: &Texture) -> Vec<f32> {
    let (width, height) = camera.resolution();
    let (width, height) = (width as usize, height as usize);
    let mut sensitivity = vec![0.0; width * height];
    sensitivity.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let Some((ctx, _)) = primary_lookup(scene, camera, Vec2::new(x as f32 + 0.5, y as f32 + 0.5)) else {
                continue;
            };
            let value = texture.eval(&ctx);
            let moved = |uv: Vec2| (texture.eval(&TexCtx { uv, ..ctx }) - value).abs().max_element();
            // One ulp: the gap from |x| to the next larger f32.
            let ulp = |x: f32| f32::from_bits(x.abs().to_bits() + 1) - x.abs();
            let (du, dv) = (Vec2::new(ulp(ctx.uv.x), 0.0), Vec2::new(0.0, ulp(ctx.uv.y)));
            *out = moved(ctx.uv + du).max(moved(ctx.uv + dv));
        }
    });
    sensitivity
}

/// Quantiles of a set of non-negative errors.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorQuantiles {
    /// The median.
    pub median: f32,
    /// The 99th percentile.
    pub p99: f32,
    /// The largest (NaN if any is NaN).
    pub max: f32,
}

impl ErrorQuantiles {
    /// The quantiles of `errors` (all zero when there are none).
    pub fn new(mut errors: Vec<f32>) -> Self {
        if errors.is_empty() {
            return Self::default();
        }
        let key = |e: &f32| if e.is_nan() { f32::INFINITY } else { *e };
        errors.sort_by(|a, b| key(a).total_cmp(&key(b)));
        let at = |q: f64| errors[((errors.len() - 1) as f64 * q).round() as usize];
        let max = if errors.iter().any(|e| e.is_nan()) { f32::NAN } else { at(1.0) };
        ErrorQuantiles { median: at(0.5), p99: at(0.99), max }
    }
}

/// How a view (a GPU's) departs from a reference view (tessera's).
#[derive(Debug)]
pub struct ViewDifference {
    /// Pixels where both see the same triangle: those compared.
    pub compared: usize,
    /// Pixels where one sees a surface and the other nothing (silhouettes, the near plane).
    pub coverage_differs: usize,
    /// Pixels where both see a surface but not the same triangle (the rasteriser's rules on
    /// shared edges against the ray's).
    pub triangle_differs: usize,
    /// The values' difference over the compared pixels.
    pub value: TexelDifference,
    /// Per compared pixel, the footprint's error relative to the reference's:
    /// max(|dx - dx_ref|, |dy - dy_ref|) / max(|dx_ref|, |dy_ref|) (Euclidean lengths in UV).
    pub footprint: ErrorQuantiles,
}

impl ViewDifference {
    /// Compare `test` with `reference` (views of the same size), keeping the `worst` largest
    /// value differences.
    pub fn new(test: &PrimaryView, reference: &PrimaryView, worst: usize) -> Result<Self> {
        let same: Vec<bool> = test.triangle.iter().zip(&reference.triangle).map(|(&t, &r)| t != 0 && t == r).collect();
        let value = TexelDifference::masked(&test.value, &reference.value, &same, worst)?;
        let footprint_error = |i: usize| {
            let steps = |f: &Bitmap| {
                let d = &f.data[4 * i..4 * i + 4];
                (Vec2::new(d[0], d[1]), Vec2::new(d[2], d[3]))
            };
            let (tx, ty) = steps(&test.footprint);
            let (rx, ry) = steps(&reference.footprint);
            let scale = rx.length().max(ry.length());
            (tx - rx).length().max((ty - ry).length()) / scale
        };
        let footprint = ErrorQuantiles::new((0..same.len()).filter(|&i| same[i]).map(footprint_error).collect());
        let covered = |t: u32| t != 0;
        let pairs = || test.triangle.iter().zip(&reference.triangle);
        Ok(ViewDifference {
            compared: same.iter().filter(|&&s| s).count(),
            coverage_differs: pairs().filter(|&(&t, &r)| covered(t) != covered(r)).count(),
            triangle_differs: pairs().filter(|&(&t, &r)| covered(t) && covered(r) && t != r).count(),
            value,
            footprint,
        })
    }
}

/// The world-to-clip projection and the camera rays of a view, as `shaders/view.wgsl` reads
/// them (a `#[repr(C)]` block uploaded as it is; `src/shader.rs` checks its layout).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewParams {
    /// [`Camera::clip_from_world`], column-major.
    pub clip_from_world: [f32; 16],
    /// The camera's position (w = 0).
    pub eye: [f32; 4],
    /// [`Camera::film_directions`]: through the film's top-left corner (w = 0).
    pub corner_direction: [f32; 4],
    /// Added per pixel right (w = 0).
    pub pixel_step_x: [f32; 4],
    /// Added per pixel down (w = 0).
    pub pixel_step_y: [f32; 4],
}

impl ViewParams {
    /// The block of `camera`, with the rasteriser's near plane at `near`.
    pub fn new(camera: &Camera, near: f32) -> Self {
        let (corner, [step_x, step_y]) = camera.film_directions();
        ViewParams {
            clip_from_world: camera.clip_from_world(near).to_cols_array(),
            eye: camera.position().extend(0.0).to_array(),
            corner_direction: corner.extend(0.0).to_array(),
            pixel_step_x: step_x.extend(0.0).to_array(),
            pixel_step_y: step_y.extend(0.0).to_array(),
        }
    }
}

/// One triangle as the fragment shader's ray differentials need it: its corners, and what
/// [`SurfaceInteraction::from_triangle`] derives from them (constant over a triangle), computed
/// here by that same function.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewTriangle {
    /// Corner positions (w = 0).
    pub p0: [f32; 4],
    /// See `p0`.
    pub p1: [f32; 4],
    /// See `p0`.
    pub p2: [f32; 4],
    /// Geometric normal (w = 0).
    pub ng: [f32; 4],
    /// dp/du (w = 0).
    pub dpdu: [f32; 4],
    /// dp/dv (w = 0).
    pub dpdv: [f32; 4],
    /// Corner texture coordinates.
    pub uv0: [f32; 2],
    /// See `uv0`.
    pub uv1: [f32; 2],
    /// See `uv0`.
    pub uv2: [f32; 2],
    /// `SURFACE_MIRRORED` (2) where the UV map is mirrored, `SURFACE_UNMIRRORED` (1) elsewhere.
    pub surface: u32,
    /// Padding to 16 bytes.
    pub padding: u32,
}

/// One corner of a triangle as the vertex shader reads it (non-indexed: three per triangle).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ViewVertex {
    /// World position.
    pub position: [f32; 3],
    /// Texture coordinates.
    pub uv: [f32; 2],
    /// Index of its triangle in the scene (and in the triangle buffer).
    pub triangle: u32,
}

/// Where the fragment shader of `shaders/view.wgsl` takes its footprint from (its pipeline
/// constant `DERIVATIVES`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Derivatives {
    /// WGSL's `dpdx`, `dpdy` of the interpolated UVs: coarse or fine as the GPU chooses.
    Dpdx,
    /// `dpdxCoarse`, `dpdyCoarse`: one difference per 2 x 2 quad of pixels.
    Coarse,
    /// `dpdxFine`, `dpdyFine`: one difference per row and per column of a quad.
    Fine,
    /// Ray differentials as tessera computes them: the UVs and footprint where the rays through
    /// the pixel centre and the next pixels right and down meet the triangle's plane.
    Ray,
}

impl Derivatives {
    /// Every kind, the screen-space ones first.
    pub const ALL: [Derivatives; 4] = [Derivatives::Dpdx, Derivatives::Coarse, Derivatives::Fine, Derivatives::Ray];

    /// The shader's code (`DERIVATIVES_*` in `shaders/view.wgsl`).
    pub fn code(self) -> u32 {
        self as u32
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Derivatives::Dpdx => "dpdx",
            Derivatives::Coarse => "coarse",
            Derivatives::Fine => "fine",
            Derivatives::Ray => "ray",
        }
    }
}

/// The handedness codes of `shaders/tiling_blending/params.wgsl`'s `TexCtx::surface`.
pub const SURFACE_UNMIRRORED: u32 = 1;
/// See [`SURFACE_UNMIRRORED`].
pub const SURFACE_MIRRORED: u32 = 2;

/// The scene's triangles for the rasteriser: three vertices and one [`ViewTriangle`] each.
pub fn view_geometry(geometry: &Geometry) -> (Vec<ViewVertex>, Vec<ViewTriangle>) {
    let mut vertices = Vec::with_capacity(geometry.triangles.len() * 3);
    let mut triangles = Vec::with_capacity(geometry.triangles.len());
    let extend = |v: Vec3| v.extend(0.0).to_array();
    for i in 0..geometry.triangles.len() {
        let tri = geometry.triangle_vertices(i);
        let uv = tri.uv.unwrap_or([Vec2::ZERO, Vec2::X, Vec2::Y]);
        // dp/du, dp/dv and the normal do not depend on where the ray meets the triangle.
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let si = SurfaceInteraction::from_triangle(&tri, 1.0 / 3.0, 1.0 / 3.0, 0.0, &ray, i as u32);
        for (p, uv) in tri.p.iter().zip(uv) {
            vertices.push(ViewVertex { position: p.to_array(), uv: uv.to_array(), triangle: i as u32 });
        }
        triangles.push(ViewTriangle {
            p0: extend(tri.p[0]),
            p1: extend(tri.p[1]),
            p2: extend(tri.p[2]),
            ng: extend(si.ng),
            dpdu: extend(si.dpdu),
            dpdv: extend(si.dpdv),
            uv0: uv[0].to_array(),
            uv1: uv[1].to_array(),
            uv2: uv[2].to_array(),
            surface: if si.uv_mirrored() { SURFACE_MIRRORED } else { SURFACE_UNMIRRORED },
            padding: 0,
        });
    }
    (vertices, triangles)
}

/// A near plane for the rasteriser that clips nothing the rays see but what is closer than a
/// millionth of the scene's size.
pub fn near_plane(scene: &Scene) -> f32 {
    let bounds = scene.geometry.bounds();
    let size = (bounds.max - bounds.min).length();
    if size.is_finite() && size > 0.0 { size * 1e-6 } else { 1e-6 }
}
