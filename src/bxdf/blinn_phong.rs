//! The classic Blinn-Phong BRDF f = ρ_d/π + ρ_s N cos^γ θ_h, the lobe written on the half vector.
//!
//! cos θ_h = n·h with h = normalize(wo + wi) is symmetric in (wo, wi), so the model is reciprocal for
//! every constant N. The microfacet reading of the same lobe (D = (γ+2)/(2π) cos^γ θ_m inside
//! F·G·D/(4 cos θ_o cos θ_i)) is `MicrofacetBrdf<ndf::BlinnPhong, F>`; this type is the classic
//! empirical form without masking or the 1/(4 cos cos) factor.

use super::lambert::unit_rgb;
use super::lobe::{cosine_power, lobe_probability, sample_cosine_power};
use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::{Error, Result, non_negative};
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::{half_vector, half_vector_cos, is_upper, reflect};
use crate::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use core::f32::consts::{FRAC_1_PI, PI, TAU};
use glam::{Vec2, Vec3};

/// Normalisation N of the Blinn-Phong lobe ρ_s N cos^γ θ_h.
///
/// At normal incidence (wo = n, so θ_h = θ_i/2) the lobe's albedo is
/// ∫ cos^γ(θ_i/2) cos θ_i dω_i = 8π (γ + 2^(−γ/2)) / ((γ+2)(γ+4)) (substitute x = cos(θ_i/2)), and
/// it decreases toward grazing `wo` (checked by quadrature in `tests/it/bxdf_phong.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BlinnPhongNormalization {
    /// N = (γ+8)/(8π), the popular approximation (\[AkenineMoller2008\], §7.6). **Gains energy** near
    /// normal incidence: the albedo there is (γ+8)(γ + 2^(−γ/2)) / ((γ+2)(γ+4)), up to ≈ 1.075 near
    /// γ = 10 (→ 1 for γ = 0 and γ → ∞).
    RealTimeRendering,
    /// N = (γ+2)(γ+4) / (8π (γ + 2^(−γ/2))): the exact inverse of the normal-incidence albedo, so the
    /// specular albedo is ρ_s at normal incidence and below it elsewhere (energy conserving).
    EnergyConserving,
}

impl BlinnPhongNormalization {
    /// N for exponent γ.
    pub fn factor(self, gamma: f32) -> f32 {
        match self {
            BlinnPhongNormalization::RealTimeRendering => (gamma + 8.0) / (8.0 * PI),
            BlinnPhongNormalization::EnergyConserving => {
                (gamma + 2.0) * (gamma + 4.0) / (8.0 * PI * (gamma + (-0.5 * gamma).exp2()))
            }
        }
    }
}

/// The Blinn-Phong BRDF f = ρ_d/π + ρ_s N max(0, cos θ_h)^γ, h = normalize(wo + wi).
///
/// Reciprocal. Energy conserving with [`BlinnPhongNormalization::EnergyConserving`] and
/// ρ_d + ρ_s ≤ 1 (enforced); see [`BlinnPhongNormalization`] for the other factor.
///
/// Sampling: the specular lobe is chosen with probability s/(d+s), d = mean(ρ_d), s = mean(ρ_s) times
/// the lobe's normal-incidence albedo; it draws h with density (γ+1)/(2π) cos^γ θ_h about n and
/// reflects `wo` about it: p(wi) = (γ+1)/(2π) cos^γ θ_h / (4 wo·h) (\[Blinn1977\] lobe, the 1/(4 wo·h)
/// Jacobian of reflection as in \[Walter2007\], eq. 14). Draws with wo·h ≤ 0 or below the horizon →
/// `None`.
///
/// # Reference
/// \[Blinn1977\]; normalisations \[AkenineMoller2008\] and the derivation in docs/bxdf.md.
///
/// # Degenerate cases
/// `wo`, `wi` not strictly above the horizon, zero-length or non-finite: f = 0, pdf = 0, `sample` →
/// `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhongLobe {
    rho_d: Vec3,
    rho_s: Vec3,
    gamma: f32,
    normalization: BlinnPhongNormalization,
    factor: f32,
    lobe_albedo_max: f32,
}

impl BlinnPhongLobe {
    /// A Blinn-Phong BRDF. Errors (`Error::InvalidParameter`): `rho_d`, `rho_s` outside [0, 1] or
    /// non-finite in some channel, `rho_d + rho_s` > 1 in some channel, `gamma` negative or non-finite.
    pub fn new(
        rho_d: Vec3,
        rho_s: Vec3,
        gamma: f32,
        normalization: BlinnPhongNormalization,
    ) -> Result<BlinnPhongLobe> {
        let rho_d = unit_rgb("rho_d", rho_d)?;
        let rho_s = unit_rgb("rho_s", rho_s)?;
        let sum = (rho_d + rho_s).max_element();
        // Slack for f32 rounding of inputs such as 0.7 + 0.3.
        if sum > 1.0 + 1e-6 {
            return Err(Error::InvalidParameter {
                name: "rho_d + rho_s",
                value: sum as f64,
                reason: "must be <= 1 in every channel (energy conservation)",
            });
        }
        let gamma = non_negative("gamma", gamma)?;
        let factor = normalization.factor(gamma);
        let albedo_at_normal =
            8.0 * PI * (gamma + (-0.5 * gamma).exp2()) / ((gamma + 2.0) * (gamma + 4.0));
        Ok(BlinnPhongLobe {
            rho_d,
            rho_s,
            gamma,
            normalization,
            factor,
            lobe_albedo_max: factor * albedo_at_normal,
        })
    }

    /// Diffuse albedo ρ_d.
    pub fn rho_d(&self) -> Vec3 {
        self.rho_d
    }

    /// Specular reflectance ρ_s.
    pub fn rho_s(&self) -> Vec3 {
        self.rho_s
    }

    /// Exponent γ.
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// The normalisation.
    pub fn normalization(&self) -> BlinnPhongNormalization {
        self.normalization
    }

    /// The factor N.
    pub fn normalizer(&self) -> f32 {
        self.factor
    }

    #[inline]
    fn p_spec(&self) -> f32 {
        let d = self.rho_d.element_sum() / 3.0;
        let s = self.rho_s.element_sum() / 3.0 * self.lobe_albedo_max;
        lobe_probability(d, s)
    }
}

impl Bxdf for BlinnPhongLobe {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !(is_upper(wo) && is_upper(wi)) {
            return Vec3::ZERO;
        }
        let Some(h) = half_vector(wo, wi) else {
            return Vec3::ZERO;
        };
        let v = self.rho_d * FRAC_1_PI + self.rho_s * (self.factor * cosine_power(h.z, self.gamma));
        if v.is_finite() { v } else { Vec3::ZERO }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(is_upper(wo) && is_upper(wi)) {
            return 0.0;
        }
        // c = ‖wo + wi‖/2, not wo·h, which cancels where wi → −wo (frame::half_vector_cos).
        let Some((h, c)) = half_vector_cos(wo, wi) else {
            return 0.0;
        };
        let p = self.p_spec();
        // The specular term only where its lobe is drawn (p > 0: 0 · ∞ would be NaN), and at most
        // `f32::MAX` where (γ+1)/(2π) c^γ / (4c) overflows (γ near `f32::MAX`), so that the density
        // stays positive wherever the lobe has a value.
        let spec = if p > 0.0 && c > 0.0 {
            let s = (self.gamma + 1.0) / TAU * cosine_power(h.z, self.gamma) / (4.0 * c);
            if s.is_nan() { 0.0 } else { s.min(f32::MAX) }
        } else {
            0.0
        };
        let v = ((1.0 - p) * pdf_cosine_hemisphere(wi) + p * spec).min(f32::MAX);
        if v.is_finite() { v } else { 0.0 }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && uc.is_finite() && u.is_finite()) {
            return None;
        }
        let (wi, lobe) = if uc < self.p_spec() {
            let h = sample_cosine_power(u, self.gamma);
            // wo·h ≤ 0 (or NaN): the mirror image of wo is below the microfacet.
            if wo.dot(h).is_nan() || wo.dot(h) <= 0.0 {
                return None;
            }
            (reflect(wo, h), LobeFlags::GLOSSY)
        } else {
            (square_to_cosine_hemisphere(u), LobeFlags::DIFFUSE)
        };
        if !is_upper(wi) {
            return None;
        }
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, LobeFlags::REFLECTION | lobe)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_at_gamma_zero_are_lambertian() {
        // γ = 0: the lobe is the constant N; both factors reduce to 1/π (albedo exactly 1).
        for k in [
            BlinnPhongNormalization::RealTimeRendering,
            BlinnPhongNormalization::EnergyConserving,
        ] {
            assert!((k.factor(0.0) - FRAC_1_PI).abs() < 1e-7);
        }
        // Large γ: both → γ/(8π) to first order.
        let g = 1e4;
        let r = BlinnPhongNormalization::RealTimeRendering.factor(g)
            / BlinnPhongNormalization::EnergyConserving.factor(g);
        assert!((r - 1.0).abs() < 1e-3, "{r}");
    }

    #[test]
    fn rejects_gain() {
        let e = BlinnPhongLobe::new(
            Vec3::splat(0.6),
            Vec3::splat(0.5),
            10.0,
            BlinnPhongNormalization::EnergyConserving,
        )
        .unwrap_err();
        assert!(e.to_string().contains("rho_d + rho_s"), "{e}");
        assert!(
            BlinnPhongLobe::new(
                Vec3::ZERO,
                Vec3::ONE,
                -1.0,
                BlinnPhongNormalization::EnergyConserving
            )
            .is_err()
        );
    }
}
