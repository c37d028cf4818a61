//! Fresnel reflectance of dielectric and conductor interfaces.

use crate::color::Rgb;
use crate::simd::{Real, V3};

/// Fresnel reflectance of a dielectric interface and the refracted direction's data.
#[derive(Clone, Copy, Debug)]
pub struct FresnelDielectric {
    /// Unpolarised reflectance.
    pub r: f32,
    /// Cosine of the refracted direction, with the sign opposite to the incident cosine
    /// (0 on total internal reflection).
    pub cos_theta_t: f32,
    /// Relative IOR of the side the light refracts into over the side it comes from.
    pub eta_it: f32,
    /// 1 / eta_it.
    pub eta_ti: f32,
}

/// Exact Fresnel reflectance for light arriving at cosine `cos_theta_i` (positive outside,
/// negative inside) on an interface of relative IOR `eta` = interior / exterior.
pub fn fresnel_dielectric(cos_theta_i: f32, eta: f32) -> FresnelDielectric {
    let outside = cos_theta_i >= 0.0;
    let (eta_it, eta_ti) = if outside { (eta, 1.0 / eta) } else { (1.0 / eta, eta) };
    // Snell: sin^2 theta_t = eta_ti^2 sin^2 theta_i.
    let cos_t2 = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * eta_ti * eta_ti;
    let cos_i = cos_theta_i.abs();
    let cos_t = cos_t2.max(0.0).sqrt();
    let r = if eta == 1.0 {
        0.0
    } else if cos_i == 0.0 {
        1.0
    } else {
        let a_s = (cos_i - eta_it * cos_t) / (cos_i + eta_it * cos_t);
        let a_p = (cos_t - eta_it * cos_i) / (cos_t + eta_it * cos_i);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    let cos_theta_t = if outside { -cos_t } else { cos_t };
    FresnelDielectric { r, cos_theta_t, eta_it, eta_ti }
}

/// Exact unpolarised Fresnel reflectance of a conductor with complex IOR `eta + i k` relative to
/// the exterior, per channel, at incident cosine `cos_theta_i` in [0, 1] (K. D. Moeller,
/// "Optics", 1988; the form Mitsuba 3 uses).
pub fn fresnel_conductor(cos_theta_i: f32, eta: Rgb, k: Rgb) -> Rgb {
    // The three channels at once, one per SIMD lane.
    fresnel_conductor_of(Rgb::splat(cos_theta_i), eta, k)
}

/// [`fresnel_conductor`] of one colour's channels (`Rgb`), or of one channel of eight paths.
#[inline(always)]
pub fn fresnel_conductor_of<C: Real>(cos_theta_i: C, eta: C, k: C) -> C {
    let (zero, half) = (C::splat(0.0), C::splat(0.5));
    let c2 = cos_theta_i * cos_theta_i;
    let s2 = C::splat(1.0) - c2;
    let s4 = s2 * s2;
    let temp = eta * eta - k * k - s2;
    let a2pb2 = (temp * temp + C::splat(4.0) * k * k * eta * eta).max(zero).sqrt();
    let a = (half * (a2pb2 + temp)).max(zero).sqrt();
    let t1 = a2pb2 + c2;
    let t2 = C::splat(2.0) * cos_theta_i * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = a2pb2 * c2 + s4;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    half * (rs + rp)
}

/// Schlick's approximation F0 + (1 - F0)(1 - cos)^5, the Fresnel term of glTF's metallic
/// base colour.
#[inline]
pub fn fresnel_schlick(f0: Rgb, cos_theta_i: f32) -> Rgb {
    let m = (1.0 - cos_theta_i).clamp(0.0, 1.0);
    let m5 = (m * m) * (m * m) * m;
    f0 + (Rgb::ONE - f0) * m5
}

/// Reflect `w` about the microfacet normal `m` (local frame).
#[inline]
pub fn reflect(w: glam::Vec3, m: glam::Vec3) -> glam::Vec3 {
    reflect_of(w.into(), m.into()).into()
}

/// [`reflect`] in one lane or eight: 2 (w . m) m - w.
#[inline(always)]
pub fn reflect_of<T: Real>(w: V3<T>, m: V3<T>) -> V3<T> {
    m * (T::splat(2.0) * w.dot(m)) - w
}

/// Refract `w` through the microfacet normal `m`, given the data of [`fresnel_dielectric`]
/// evaluated at `w . m`.
#[inline]
pub fn refract(w: glam::Vec3, m: glam::Vec3, cos_theta_t: f32, eta_ti: f32) -> glam::Vec3 {
    m * (w.dot(m) * eta_ti + cos_theta_t) - w * eta_ti
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_dielectric_known_values() {
        // Normal incidence: ((eta - 1) / (eta + 1))^2 = 0.04 for eta = 1.5, from either side.
        assert!((fresnel_dielectric(1.0, 1.5).r - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5).r - 0.04).abs() < 1e-6);
        // Total internal reflection beyond the critical angle (sin > 1/1.5) from inside.
        assert_eq!(fresnel_dielectric(-0.5, 1.5).r, 1.0);
        // Brewster's angle: tan theta = eta, p-polarised reflectance vanishes, r = Rs / 2.
        let theta_b = 1.5f32.atan();
        let f = fresnel_dielectric(theta_b.cos(), 1.5);
        let rs = ((theta_b.cos() - 1.5 * (-f.cos_theta_t)) / (theta_b.cos() + 1.5 * (-f.cos_theta_t))).powi(2);
        assert!((f.r - 0.5 * rs).abs() < 1e-6);
    }

    #[test]
    fn refraction_obeys_snell() {
        let w = glam::Vec3::new(0.6, 0.0, 0.8);
        let f = fresnel_dielectric(w.z, 1.5);
        let t = refract(w, glam::Vec3::Z, f.cos_theta_t, f.eta_ti);
        assert!((t.length() - 1.0).abs() < 1e-6);
        assert!((w.x.abs() - 1.5 * t.x.abs()).abs() < 1e-6, "sin_i = eta sin_t");
        assert!(t.z < 0.0 && t.x < 0.0);
    }

    #[test]
    fn fresnel_conductor_limits() {
        // eta = 0, k = 1 is Mitsuba's "none": a perfect mirror at every angle.
        for c in [1.0, 0.5, 0.01] {
            let f = fresnel_conductor(c, Rgb::ZERO, Rgb::ONE);
            assert!((f - Rgb::ONE).abs().max_element() < 1e-5, "{f}");
        }
        // With k = 0 it is the dielectric formula.
        let f = fresnel_conductor(0.7, Rgb::splat(1.5), Rgb::ZERO);
        assert!((f.x - fresnel_dielectric(0.7, 1.5).r).abs() < 1e-6);
        // Aluminium at normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
        let (n, k) = (1.6575f32, 9.22381f32);
        let expected = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let f = fresnel_conductor(1.0, Rgb::splat(n), Rgb::splat(k));
        assert!((f.x - expected).abs() < 1e-5);
    }
}
