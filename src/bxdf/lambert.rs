//! The Lambertian (perfectly diffuse) BRDF f = ρ/π, sampled with the cosine-weighted hemisphere.
//!
//! It is reciprocal, and its directional albedo ∫ f cos θ_i dω_i is exactly ρ for every `wo`, so it
//! conserves energy whenever 0 ≤ ρ ≤ 1 (which the constructor enforces per channel).

use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::{Error, Result};
use crate::frame::is_upper;
use crate::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// Checks that every channel of an RGB reflectance is finite and in [0, 1].
pub(crate) fn unit_rgb(name: &'static str, v: Vec3) -> Result<Vec3> {
    for c in v.to_array() {
        if !(c.is_finite() && (0.0..=1.0).contains(&c)) {
            return Err(Error::InvalidParameter {
                name,
                value: c as f64,
                reason: "every channel must be finite and in [0, 1]",
            });
        }
    }
    Ok(v)
}

/// Lambertian reflection f(wo, wi) = ρ / π.
///
/// Directional albedo ∫ f cos θ_i dω_i = ρ for every `wo`; reciprocal. Sampling draws `wi` with density
/// cos θ_i / π (perfect importance sampling: the weight f cos θ_i / pdf is ρ).
///
/// # Reference
/// \[Lambert1760\]; the cosine-weighted hemisphere sampler is [`crate::warp::square_to_cosine_hemisphere`]
/// (Malley's method).
///
/// # Degenerate cases
/// `wo` or `wi` not strictly above the horizon, zero-length or non-finite: f = 0, pdf = 0, `sample`
/// returns `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambert {
    albedo: Vec3,
}

impl Lambert {
    /// The black BRDF (ρ = 0): a total stand-in where a valid material cannot be formed.
    #[cfg(feature = "std")] // used by `material`
    pub(crate) const BLACK: Lambert = Lambert { albedo: Vec3::ZERO };

    /// A Lambertian BRDF with RGB albedo ρ; every channel must be finite and in [0, 1]
    /// (`Error::InvalidParameter` naming `albedo` otherwise).
    pub fn new(albedo: Vec3) -> Result<Lambert> {
        Ok(Lambert {
            albedo: unit_rgb("albedo", albedo)?,
        })
    }

    /// The albedo ρ.
    pub fn albedo(&self) -> Vec3 {
        self.albedo
    }
}

impl Bxdf for Lambert {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if is_upper(wo) && is_upper(wi) {
            self.albedo * FRAC_1_PI
        } else {
            Vec3::ZERO
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if is_upper(wo) && is_upper(wi) {
            pdf_cosine_hemisphere(wi)
        } else {
            0.0
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !is_upper(wo) || !u.is_finite() {
            return None;
        }
        let wi = square_to_cosine_hemisphere(u);
        let pdf = self.pdf(wo, wi);
        BxdfSample::checked(
            wi,
            self.albedo * FRAC_1_PI,
            pdf,
            LobeFlags::REFLECTION | LobeFlags::DIFFUSE,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_and_weight() {
        let l = Lambert::new(Vec3::new(0.2, 0.5, 1.0)).unwrap();
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let s = l.sample(wo, 0.5, Vec2::new(0.3, 0.6)).unwrap();
        // Perfect importance sampling: f cos / pdf = (ρ/π) cos / (cos/π) = ρ, up to f32 rounding.
        assert!((s.weight() - l.albedo()).abs().max_element() < 1e-6);
        assert_eq!(l.eval(wo, -wo), Vec3::ZERO);
    }

    #[test]
    fn rejects_bad_albedo() {
        for bad in [1.01, -0.01, f32::NAN, f32::INFINITY] {
            let e = Lambert::new(Vec3::new(0.5, bad, 0.5)).unwrap_err();
            assert!(e.to_string().contains("albedo"), "{e}");
        }
    }
}
