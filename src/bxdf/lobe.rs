//! Private sampling helper shared by the Phong-type BxDFs: the cosine-power lobe (γ+1)/(2π) cos^γ θ
//! about an arbitrary axis, as a sample / pdf pair (the cosine-weighted hemisphere is in
//! [`crate::warp`]).
//!
//! The sampler is written in the lobe's own frame (axis = z) and inverts its CDF exactly; the rotated
//! variant uses [`crate::frame::Frame`].

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::Frame;
use core::f32::consts::TAU;
use glam::{Vec2, Vec3};

/// The probability s / (d + s) of choosing the specular lobe of a diffuse + specular mixture with
/// weights d, s ≥ 0 (½ when both vanish, where f = 0 anyway), kept within
/// [2⁻²⁴, 1 − 2⁻²⁴] when both are positive: s / (d + s) rounds to exactly 1 (or 0) in `f32` once
/// one weight is below 6·10⁻⁸ of the other (the diffuse weight ρ_d (1 − F) of a Schlick-Fresnel
/// Phong at cos θo = 10⁻⁷), and a lobe chosen with probability 0 has pdf 0 where f > 0. 1 − p is
/// exact in `f32` for p ≥ ½, so `uc < p` and the mixture pdf p pdf_s + (1 − p) pdf_d agree.
#[inline]
pub(crate) fn lobe_probability(d: f32, s: f32) -> f32 {
    let total = d + s;
    if total.is_nan() || total <= 0.0 {
        return 0.5;
    }
    let p = s / total;
    if d > 0.0 && s > 0.0 {
        p.clamp(f32::EPSILON / 2.0, 1.0 - f32::EPSILON / 2.0)
    } else {
        p
    }
}

/// The lobe value max(0, c)^γ, with 0^0 = 0 so that the lobe's support is exactly c > 0, and 0
/// where c^γ is subnormal (below `f32::MIN_POSITIVE`).
///
/// The flush keeps a lobe's value and its sampling density (γ+1)/(2π) c^γ on one support: with a
/// subnormal c^γ the density's factor (γ+1)/(2π) < 1 (γ < 5.3) can round it to 0 while the value
/// ρ_s N c^γ stays positive (Phong at cos θo = 10⁻¹⁵, cos θi = 10⁻³⁰: c = 10⁻⁴⁵), which a
/// renderer with multiple importance sampling cannot weight. The flushed values are below 10⁻³⁷.
#[inline]
pub(crate) fn cosine_power(c: f32, gamma: f32) -> f32 {
    if c.is_nan() || c <= 0.0 {
        return 0.0;
    }
    let v = c.min(1.0).powf(gamma);
    if v >= f32::MIN_POSITIVE { v } else { 0.0 }
}

/// Direction with density (γ+1)/(2π) · cos^γ θ about z: cos θ = u.x^(1/(γ+1)), φ = 2π u.y.
#[inline]
pub(crate) fn sample_cosine_power(u: Vec2, gamma: f32) -> Vec3 {
    let z = u.x.clamp(0.0, 1.0).powf(1.0 / (gamma + 1.0));
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (TAU * u.y).sin_cos();
    Vec3::new(r * c, r * s, z)
}

/// Density of [`sample_cosine_power`] at cos θ = `c`: (γ+1)/(2π) · max(0, c)^γ.
#[inline]
pub(crate) fn pdf_cosine_power(c: f32, gamma: f32) -> f32 {
    (gamma + 1.0) / TAU * cosine_power(c, gamma)
}

/// [`sample_cosine_power`] rotated so that its axis is the unit vector `axis`.
#[inline]
pub(crate) fn sample_cosine_power_about(axis: Vec3, u: Vec2, gamma: f32) -> Vec3 {
    Frame::from_normal(axis).to_world(sample_cosine_power(u, gamma))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cosine_power_sampler_inverts_its_cdf() {
        // P(cos θ > t) = 1 − t^(γ+1): the sample at u.x has cos θ = u.x^(1/(γ+1)) exactly.
        for gamma in [0.0f32, 1.0, 7.5, 300.0] {
            for ux in [0.0f32, 0.25, 0.5, 0.99] {
                let w = sample_cosine_power(Vec2::new(ux, 0.3), gamma);
                assert!((w.length() - 1.0).abs() < 1e-6);
                assert!(
                    (w.z.powf(gamma + 1.0) - ux).abs() < 1e-5,
                    "{gamma} {ux} {w}"
                );
            }
        }
    }

    #[test]
    fn cosine_power_support() {
        assert_eq!(cosine_power(0.0, 0.0), 0.0);
        assert_eq!(cosine_power(-0.5, 2.0), 0.0);
        assert_eq!(cosine_power(1.5, 2.0), 1.0);
        assert_eq!(cosine_power(f32::NAN, 2.0), 0.0);
        // Subnormal values are flushed, so that the density (γ+1)/(2π) c^γ is positive wherever
        // the value is.
        assert_eq!(cosine_power(1e-45, 1.0), 0.0);
        assert_eq!(cosine_power(1e-20, 2.0), 0.0);
        assert_eq!(cosine_power(f32::MIN_POSITIVE, 1.0), f32::MIN_POSITIVE);
        assert!(pdf_cosine_power(f32::MIN_POSITIVE, 0.0) > 0.0);
        assert!((pdf_cosine_power(1.0, 3.0) - 4.0 / TAU).abs() < 1e-7);
    }

    #[test]
    fn rotated_lobe_is_centred_on_axis() {
        let axis = Vec3::new(0.3, -0.4, 0.866).normalize();
        let w = sample_cosine_power_about(axis, Vec2::new(1.0, 0.7), 10.0);
        assert!((w - axis).length() < 1e-5);
    }
}
