//! The environment: light arriving from infinitely far away, constant or from an
//! equirectangular (latitude-longitude) map, importance-sampled by luminance.
//!
//! Mapping (DESIGN.md section 3, Mitsuba 3's `envmap` with identity transform): a direction d
//! towards the sky has u = atan2(d.x, -d.z) / 2 pi wrapped to [0, 1) and v = acos(d.y) / pi. The
//! map is read bilinearly at column u W - 0.5 (periodic) and row v (H - 1) (clamped): row 0 is
//! the zenith, the last row the nadir, the centre column faces +z and u = 0.25 faces +x.

use super::LightSample;
use crate::color::{Rgb, luminance};
use crate::image::Bitmap;
use crate::sampling::{Distribution2D, warp};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Environment lighting.
#[derive(Clone, Debug)]
pub enum Environment {
    /// The same radiance from every direction (Mitsuba's `constant`), sampled uniformly.
    Constant(Rgb),
    /// An equirectangular map.
    Map(EnvironmentMap),
}

/// An equirectangular environment map with its sampling distribution.
///
/// The lookup interpolates bilinearly between texel centres, so the radiance is exactly bilinear
/// on the cells between four neighbouring texel centres: columns x = u W - 0.5 in [i, i + 1]
/// (wrapping), rows y = v (H - 1) in [j, j + 1]. Sampling follows that: a cell is chosen with
/// probability proportional to the integral of luminance times sin(theta) over it (the mean of
/// its corners), then a point inside it with density proportional to the bilinear interpolation
/// of its corners (Mitsuba 3's `envmap` likewise samples the bilinear interpolant). The density
/// thus follows the radiance closely, even next to a one-texel sun.
#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    image: Bitmap,
    scale: f32,
    /// Luminance times sin(theta) at each texel centre, row-major (the cells' corner weights).
    weights: Vec<f32>,
    /// Over the W x (H - 1) cells.
    distribution: Distribution2D,
}

/// (u, v) of a unit direction.
#[inline]
fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) / (2.0 * PI);
    let u = if u < 0.0 { u + 1.0 } else { u };
    Vec2::new(u.min(1.0 - f32::EPSILON), d.y.clamp(-1.0, 1.0).acos() / PI)
}

/// Unit direction of (u, v).
#[inline]
fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (sin_t, cos_t) = (uv.y * PI).sin_cos();
    let (sin_p, cos_p) = (uv.x * 2.0 * PI).sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

impl EnvironmentMap {
    /// A map from an RGB(A) image (at least 2 rows), its radiance multiplied by `scale`.
    pub fn new(image: Bitmap, scale: f32) -> Self {
        let (w, h) = (image.width, image.height.max(2));
        let weights: Vec<f32> = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, (k / w).min(image.height - 1));
                let sin_theta = (PI * y as f32 / (h - 1) as f32).sin().max(0.0);
                luminance(Rgb::from_vec4(image.pixel(x, y))).max(0.0) * sin_theta
            })
            .collect();
        let cells: Vec<f32> = (0..w * (h - 1))
            .map(|k| {
                let corners = Self::corners(&weights, w, k % w, k / w);
                corners.iter().sum::<f32>() * 0.25
            })
            .collect();
        let distribution = Distribution2D::new(&cells, w, h - 1);
        EnvironmentMap { image, scale, weights, distribution }
    }

    /// Corner weights of cell (i, j): texel centres (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1),
    /// columns wrapping.
    #[inline]
    fn corners(weights: &[f32], w: usize, i: usize, j: usize) -> [f32; 4] {
        let i1 = (i + 1) % w;
        [weights[j * w + i], weights[j * w + i1], weights[(j + 1) * w + i], weights[(j + 1) * w + i1]]
    }

    /// The image (negative values already clamped to 0) and the radiance scale.
    pub fn image(&self) -> (&Bitmap, f32) {
        (&self.image, self.scale)
    }

    /// Bilinear radiance at (u, v).
    fn lookup_uv(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.image.width, self.image.height);
        let x = uv.x * w as f32 - 0.5;
        let y = (uv.y * (h - 1) as f32).clamp(0.0, (h - 1) as f32);
        let ((x0, fx), (y0, fy)) = (crate::math::floor_index(x), crate::math::floor_index(y));
        let col = |c: i64| crate::math::wrap_index(c, w);
        let (c0, c1) = (col(x0), col(x0 + 1));
        let r0 = y0 as usize;
        let r1 = (r0 + 1).min(h - 1);
        let px = |c: usize, r: usize| Rgb::from_vec4(self.image.pixel(c, r));
        let top = px(c0, r0) * (1.0 - fx) + px(c1, r0) * fx;
        let bottom = px(c0, r1) * (1.0 - fx) + px(c1, r1) * fx;
        (top * (1.0 - fy) + bottom * fy) * self.scale
    }

    /// Sample (u, v) and its density over the unit square.
    fn sample_uv(&self, u: Vec2) -> Option<(Vec2, f32)> {
        let (w, h) = (self.image.width, self.image.height.max(2));
        let (i, j, pmf, remapped) = self.distribution.sample_cell(u);
        let corners = Self::corners(&self.weights, w, i, j);
        let p = warp::square_to_bilinear(remapped, corners);
        let uv = Vec2::new(((i as f32 + 0.5 + p.x) / w as f32).fract(), (j as f32 + p.y) / (h - 1) as f32);
        let cell_area = 1.0 / (w * (h - 1)) as f32;
        let pdf = pmf * warp::bilinear_pdf(p, corners) / cell_area;
        (pdf > 0.0).then_some((uv, pdf))
    }

    /// Solid-angle density of sampling direction `d`, whose map coordinates are `uv`.
    fn pdf_of(&self, d: Vec3, uv: Vec2) -> f32 {
        let sin_theta = (1.0 - d.y * d.y).max(0.0).sqrt();
        if sin_theta == 0.0 {
            return 0.0;
        }
        self.pdf_uv(uv) / (2.0 * PI * PI * sin_theta)
    }

    /// Density over the unit square of [`EnvironmentMap::sample_uv`] at (u, v).
    fn pdf_uv(&self, uv: Vec2) -> f32 {
        let (w, h) = (self.image.width, self.image.height.max(2));
        let x = uv.x * w as f32 - 0.5;
        // x mod w; within one period of [0, w), as lookups are, without the division (the
        // same value: the remainder of |x| < w is x).
        let x = if (0.0..w as f32).contains(&x) {
            x
        } else if (-(w as f32)..0.0).contains(&x) {
            x + w as f32
        } else {
            x.rem_euclid(w as f32)
        };
        let y = (uv.y * (h - 1) as f32).clamp(0.0, (h - 1) as f32);
        let (i, j) = ((x as usize).min(w - 1), (y as usize).min(h - 2));
        let p = Vec2::new(x - i as f32, y - j as f32);
        let cell_area = 1.0 / (w * (h - 1)) as f32;
        self.distribution.cell_pmf(i, j) * warp::bilinear_pdf(p, Self::corners(&self.weights, w, i, j)) / cell_area
    }
}

impl Environment {
    /// Radiance arriving from direction `d` (unit, pointing away from the scene).
    pub fn radiance(&self, d: Vec3) -> Rgb {
        match self {
            Environment::Constant(c) => *c,
            Environment::Map(m) => m.lookup_uv(direction_to_uv(d)),
        }
    }

    /// Sample a direction towards the environment.
    pub fn sample(&self, u: Vec2) -> Option<LightSample> {
        let wi = match self {
            Environment::Constant(_) => warp::square_to_uniform_sphere(u),
            Environment::Map(m) => uv_to_direction(m.sample_uv(u)?.0),
        };
        // The density as `pdf` computes it from the direction, so that MIS weights use one
        // function (a map sample on a cell edge may round into the neighbouring cell).
        let (radiance, pdf) = self.radiance_and_pdf(wi);
        if pdf <= 0.0 {
            return None;
        }
        Some(LightSample { wi, radiance, pdf, point: None, delta: false })
    }

    /// [`Environment::radiance`] and [`Environment::pdf`] of `d` at once, mapping `d` to the
    /// map's coordinates once.
    pub fn radiance_and_pdf(&self, d: Vec3) -> (Rgb, f32) {
        match self {
            Environment::Constant(c) => (*c, warp::UNIFORM_SPHERE_PDF),
            Environment::Map(m) => {
                let uv = direction_to_uv(d);
                (m.lookup_uv(uv), m.pdf_of(d, uv))
            }
        }
    }

    /// Solid-angle density of [`Environment::sample`] returning `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        match self {
            Environment::Constant(_) => warp::UNIFORM_SPHERE_PDF,
            Environment::Map(m) => m.pdf_of(d, direction_to_uv(d)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn environment_mapping_matches_mitsuba_orientation() {
        // Centre column faces +z, u = 0.25 faces +x, row 0 is the zenith.
        assert!(uv_to_direction(Vec2::new(0.5, 0.5)).distance(Vec3::Z) < 1e-6);
        assert!(uv_to_direction(Vec2::new(0.25, 0.5)).distance(Vec3::X) < 1e-6);
        assert!(uv_to_direction(Vec2::new(0.3, 0.0)).distance(Vec3::Y) < 1e-6);
        for d in [Vec3::new(0.3, 0.4, -0.5), Vec3::new(-0.7, -0.1, 0.2)] {
            let d = d.normalize();
            assert!(uv_to_direction(direction_to_uv(d)).distance(d) < 1e-5);
        }
    }

    #[test]
    fn environment_map_pdf_integrates_to_one_and_matches_sampling() {
        let mut img = Bitmap::new(16, 8, 3);
        for (i, v) in img.data.iter_mut().enumerate() {
            *v = ((i * 37) % 11) as f32 + if i % 3 == 0 { 20.0 } else { 0.0 };
        }
        let env = Environment::Map(EnvironmentMap::new(img, 1.0));
        // int pdf dw = 1 over the sphere, by the midpoint rule in (theta, phi) with dw =
        // sin(theta) dtheta dphi (bounded integrand, unlike in cos(theta) near the poles).
        let n = 800;
        let mut total = 0.0f64;
        for i in 0..n {
            let theta = PI * (i as f32 + 0.5) / n as f32;
            for j in 0..2 * n {
                let phi = PI * (j as f32 + 0.5) / n as f32;
                let d = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                total += (env.pdf(d) * theta.sin()) as f64;
            }
        }
        total *= (std::f64::consts::PI / n as f64).powi(2);
        assert!((total - 1.0).abs() < 2e-3, "{total}");
        for u in [Vec2::new(0.1, 0.3), Vec2::new(0.77, 0.52), Vec2::new(0.5, 0.99)] {
            let s = env.sample(u).unwrap();
            assert!((env.pdf(s.wi) - s.pdf).abs() < 1e-3 * s.pdf, "{} vs {}", env.pdf(s.wi), s.pdf);
        }
    }
}
