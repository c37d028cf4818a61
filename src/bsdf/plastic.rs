//! Rough plastic: a rough dielectric coating over a diffuse base with internal scattering
//! (Mitsuba's `roughplastic`, `nonlinear = false`; Weidlich and Wilkie 2007 style layering).
//!
//! ```text
//! f = F(wo.m) D G / (4 cos_o cos_i) specular_reflectance
//!     + diffuse_reflectance / (1 - R_int) T(cos_o) T(cos_i) / (pi eta^2)
//! ```
//! where T(mu) is the rough interface's directional transmittance from outside and R_int the
//! cosine-weighted mean reflectance of the interface from inside, both tabulated at load
//! exactly as Mitsuba 3 defines them (64 cosines, linear interpolation).

use super::fresnel::{fresnel_dielectric, reflect, refract};
use super::{BsdfSample, Ggx};
use crate::color::Rgb;
use crate::math::gauss_legendre;
use crate::sampling::warp;
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

/// Number of cosines in the transmittance table (Mitsuba's `MI_ROUGH_TRANSMITTANCE_RES`).
const TABLE_RES: usize = 64;

/// Tabulated interface albedos of a rough plastic with a fixed IOR, on a grid of roughness
/// values (one value for a material with constant roughness, a grid when roughness is textured).
#[derive(Clone, Debug)]
pub struct PlasticTables {
    eta: f32,
    alphas: Vec<f32>,
    /// Per alpha: T(mu_j) for mu_j = max(1e-6, j / 63).
    transmittance: Vec<[f32; TABLE_RES]>,
    /// Per alpha: 2 mean_j(R_inside(mu_j) mu_j), Mitsuba's `m_internal_reflectance`.
    internal_reflectance: Vec<f32>,
}

impl PlasticTables {
    /// Tabulate for relative IOR `eta` at the roughness values `alphas` (ascending).
    pub fn new(eta: f32, alphas: &[f32]) -> Self {
        assert!(!alphas.is_empty() && alphas.windows(2).all(|w| w[0] < w[1]));
        let mut transmittance = Vec::with_capacity(alphas.len());
        let mut internal_reflectance = Vec::with_capacity(alphas.len());
        for &alpha in alphas {
            let ggx = Ggx::new(alpha, alpha);
            let mut t = [0.0f32; TABLE_RES];
            let mut r_mean = 0.0f64;
            for (j, tj) in t.iter_mut().enumerate() {
                let mu = (j as f32 / (TABLE_RES - 1) as f32).max(1e-6);
                let w = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
                *tj = interface_albedo(&ggx, w, eta, false);
                r_mean += (interface_albedo(&ggx, w, 1.0 / eta, true) * mu) as f64;
            }
            transmittance.push(t);
            internal_reflectance.push((2.0 * r_mean / TABLE_RES as f64) as f32);
        }
        PlasticTables { eta, alphas: alphas.to_vec(), transmittance, internal_reflectance }
    }

    /// A grid of roughness values for textured roughness: 32 values from 1e-3 to 1, uniform in
    /// sqrt(alpha).
    pub fn alpha_grid() -> Vec<f32> {
        (0..32)
            .map(|i| {
                let r = 0.0316 + (1.0 - 0.0316) * i as f32 / 31.0;
                r * r
            })
            .collect()
    }

    /// The relative IOR the tables were made for.
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// Index and weight of `alpha` between grid entries (clamped at the ends).
    fn alpha_lerp(&self, alpha: f32) -> (usize, f32) {
        let n = self.alphas.len();
        if n == 1 || alpha <= self.alphas[0] {
            return (0, 0.0);
        }
        if alpha >= self.alphas[n - 1] {
            return (n - 2, 1.0);
        }
        let i = self.alphas.partition_point(|&a| a <= alpha) - 1;
        (i, (alpha - self.alphas[i]) / (self.alphas[i + 1] - self.alphas[i]))
    }

    fn transmittance(&self, alpha: (usize, f32), mu: f32) -> f32 {
        let x = mu.clamp(0.0, 1.0) * (TABLE_RES - 1) as f32;
        let j = (x as usize).min(TABLE_RES - 2);
        let w = x - j as f32;
        let at = |t: &[f32; TABLE_RES]| t[j] * (1.0 - w) + t[j + 1] * w;
        let (i, a) = alpha;
        if a == 0.0 {
            at(&self.transmittance[i])
        } else {
            at(&self.transmittance[i]) * (1.0 - a) + at(&self.transmittance[i + 1]) * a
        }
    }

    fn internal_reflectance(&self, alpha: (usize, f32)) -> f32 {
        let (i, a) = alpha;
        if a == 0.0 {
            self.internal_reflectance[i]
        } else {
            self.internal_reflectance[i] * (1.0 - a) + self.internal_reflectance[i + 1] * a
        }
    }
}

/// Directional albedo of a rough dielectric interface seen from `w` (`w.z > 0`): its reflection
/// lobe (`reflection`) or its transmission lobe, integrated over the visible normals with 64^2
/// Gauss-Legendre nodes (Mitsuba's `eval_reflectance` / `eval_transmittance`).
fn interface_albedo(ggx: &Ggx, w: Vec3, eta: f32, reflection: bool) -> f32 {
    let (nodes, weights) = gauss_legendre(64);
    let mut sum = 0.0f64;
    for (x, wx) in nodes.iter().zip(&weights) {
        for (y, wy) in nodes.iter().zip(&weights) {
            let u = Vec2::new(0.5 * (*x as f32) + 0.5, 0.5 * (*y as f32) + 0.5);
            let m = ggx.sample_visible(w, u);
            let f = fresnel_dielectric(w.dot(m), eta);
            let value = if reflection {
                let wr = reflect(w, m);
                if wr.z <= 0.0 { 0.0 } else { ggx.g1(wr, m) * f.r }
            } else {
                let wt = refract(w, m, f.cos_theta_t, f.eta_ti);
                if wt.z >= 0.0 { 0.0 } else { ggx.g1(wt, m) * (1.0 - f.r) }
            };
            sum += value as f64 * wx * wy * 0.25;
        }
    }
    sum as f32
}

/// The rough plastic model at a surface point.
#[derive(Clone, Copy, Debug)]
pub struct Plastic<'a> {
    /// Albedo of the diffuse base.
    pub diffuse_reflectance: Rgb,
    /// Factor on the specular coating (default 1).
    pub specular_reflectance: Rgb,
    /// Isotropic roughness of the coating.
    pub alpha: f32,
    /// Interface albedos for the coating's IOR.
    pub tables: &'a PlasticTables,
}

impl Plastic<'_> {
    fn ggx(&self) -> Ggx {
        Ggx::new(self.alpha, self.alpha)
    }

    /// Probability of sampling the specular lobe, from the coating's reflectance at `cos_o` and
    /// the ratio of mean specular to diffuse reflectance (Mitsuba's sampling weight).
    fn specular_probability(&self, t_o: f32) -> f32 {
        let s_mean = self.specular_reflectance.element_sum() / 3.0;
        let d_mean = self.diffuse_reflectance.element_sum() / 3.0;
        let weight = if s_mean + d_mean > 0.0 { s_mean / (s_mean + d_mean) } else { 0.5 };
        let (ps, pd) = ((1.0 - t_o) * weight, t_o * (1.0 - weight));
        if ps + pd > 0.0 { ps / (ps + pd) } else { 0.5 }
    }

    /// f |cos theta_i| of the coating plus the base, and the mixture density of the two lobes
    /// (they share the half vector, D, G1(wo) and the coating's transmittance towards wo).
    pub fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (Rgb::ZERO, 0.0);
        }
        let ggx = self.ggx();
        let eta = self.tables.eta;
        let m = (wo + wi).normalize();
        let (d, g1_o) = (ggx.d(m), ggx.g1(wo, m));
        let f = fresnel_dielectric(wo.dot(m), eta).r;
        let specular = self.specular_reflectance * (f * d * (g1_o * ggx.g1(wi, m)) / (4.0 * wo.z));
        let alpha = self.tables.alpha_lerp(self.alpha);
        let t_o = self.tables.transmittance(alpha, wo.z);
        let t_i = self.tables.transmittance(alpha, wi.z);
        let diffuse = self.diffuse_reflectance / (1.0 - self.tables.internal_reflectance(alpha));
        let value = specular + diffuse * (FRAC_1_PI / (eta * eta) * wi.z * t_o * t_i);
        let p_spec = self.specular_probability(t_o);
        let pdf_spec = d * g1_o / (4.0 * wo.z);
        (value, p_spec * pdf_spec + (1.0 - p_spec) * warp::cosine_hemisphere_pdf(wi))
    }

    /// Pick the coating or the base, sample it, and weight by the full mixture.
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let t_o = self.tables.transmittance(self.tables.alpha_lerp(self.alpha), wo.z);
        let wi = if u1 < self.specular_probability(t_o) {
            reflect(wo, self.ggx().sample_visible(wo, u2))
        } else {
            warp::square_to_cosine_hemisphere(u2)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let (f, pdf) = self.eval_pdf(wo, wi);
        if !(pdf > 0.0) {
            return None;
        }
        Some(BsdfSample { wi, weight: f / pdf, pdf, delta: false, eta: 1.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plastic_tables_smooth_limit_matches_fresnel() {
        // Nearly smooth: T(mu) -> 1 - F(mu), R_int -> 2 mean(F_inside(mu) mu).
        let eta = 1.5;
        let tables = PlasticTables::new(eta, &[1e-3]);
        for j in [8, 32, 63] {
            let mu = j as f32 / 63.0;
            let expected = 1.0 - fresnel_dielectric(mu, eta).r;
            assert!((tables.transmittance[0][j] - expected).abs() < 2e-3, "mu {mu}");
        }
        let expected: f32 = (0..64)
            .map(|j| {
                let mu = (j as f32 / 63.0).max(1e-6);
                fresnel_dielectric(mu, 1.0 / eta).r * mu
            })
            .sum::<f32>()
            * 2.0
            / 64.0;
        assert!(
            (tables.internal_reflectance[0] - expected).abs() < 3e-3,
            "{} vs {expected}",
            tables.internal_reflectance[0]
        );
    }

    #[test]
    fn plastic_tables_interpolate_over_alpha() {
        let grid = PlasticTables::new(1.5, &[0.1, 0.3]);
        let mid = PlasticTables::new(1.5, &[0.2]);
        let lerp = grid.transmittance(grid.alpha_lerp(0.2), 0.5);
        let exact = mid.transmittance((0, 0.0), 0.5);
        assert!((lerp - exact).abs() < 5e-3, "{lerp} vs {exact}");
    }
}
