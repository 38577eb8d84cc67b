//! Phong reflection: the original form ρ_s cos^γ θ_r / cos θ_i, and the modified form
//! ρ_d/π + ρ_s N cos^γ θ_r with every normalisation N the literature uses, down to the
//! energy-normalised ones of Arvo (1995) and Mallett & Yuksel (2020).
//!
//! θ_r is the angle between `wi` and the mirror direction r = reflect(wo, n) = (−wo.x, −wo.y, wo.z).
//! cos θ_r = wi·r is symmetric in (wo, wi), so a Phong lobe with a *constant* N is reciprocal; the
//! energy-normalised N(wo) = 1/I(γ, cos θ_o) and the original form's 1/cos θ_i are not.
//!
//! Sampling (both types): a lobe choice with `uc`, then either the cosine-weighted hemisphere (diffuse)
//! or the cosine-power lobe (γ+1)/(2π) cos^γ θ_r about r (specular). Specular draws that fall below the
//! horizon return `None`; `pdf` is the density of the whole mixture over the upper hemisphere (so it
//! integrates to less than 1 when part of the specular lobe is below the horizon).

use super::lambert::unit_rgb;
use super::lobe::{cosine_power, lobe_probability, pdf_cosine_power, sample_cosine_power_about};
use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::{Error, Result, non_negative};
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::is_upper;
use crate::fresnel::schlick;
use crate::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
use crate::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use core::f32::consts::{FRAC_1_PI, TAU};
use glam::{Vec2, Vec3};

/// Largest exponent accepted by [`PhongNormalization::EnergyNormalizedArvo`]: 2²⁴, the largest range in
/// which every integer is an exact `f32`. Arvo's recurrence costs O(γ) per evaluation.
pub const ARVO_MAX_GAMMA: f32 = 16_777_216.0;

/// Slack allowed on ρ_d + ρ_s ≤ 1 for f32 rounding of the inputs (0.7 + 0.3 may round above 1).
const SUM_SLACK: f32 = 1e-6;

/// The mirror direction r = reflect(wo, n) of the local frame.
#[inline]
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// Checks the lecture's condition ρ_d + ρ_s ≤ 1 per channel (the error names `rho_d + rho_s`).
fn check_sum(rho_d: Vec3, rho_s: Vec3) -> Result<()> {
    let sum = rho_d + rho_s;
    if sum.max_element() > 1.0 + SUM_SLACK {
        return Err(Error::InvalidParameter {
            name: "rho_d + rho_s",
            value: sum.max_element() as f64,
            reason: "must be <= 1 in every channel (energy conservation)",
        });
    }
    Ok(())
}

/// Probability of choosing the specular lobe: s / (d + s) with d, s the mean diffuse and specular
/// weights (½ when both vanish, where f = 0 anyway; within [2⁻²⁴, 1 − 2⁻²⁴] when both are positive,
/// see `lobe_probability`).
#[inline]
fn specular_probability(kd: Vec3, ks_weight: Vec3) -> f32 {
    lobe_probability(kd.element_sum() / 3.0, ks_weight.element_sum() / 3.0)
}

/// Density of the diffuse + cosine-power mixture used by both Phong types.
#[inline]
fn mixture_pdf(wo: Vec3, wi: Vec3, p_spec: f32, gamma: f32) -> f32 {
    (1.0 - p_spec) * pdf_cosine_hemisphere(wi)
        + p_spec * pdf_cosine_power(wi.dot(mirror(wo)), gamma)
}

/// Draws from the diffuse + cosine-power mixture; `None` when the draw is below the horizon.
#[inline]
fn sample_mixture(
    wo: Vec3,
    uc: f32,
    u: Vec2,
    p_spec: f32,
    gamma: f32,
) -> Option<(Vec3, LobeFlags)> {
    if !(uc.is_finite() && u.is_finite()) {
        return None;
    }
    let (wi, lobe) = if uc < p_spec {
        (
            sample_cosine_power_about(mirror(wo), u, gamma),
            LobeFlags::GLOSSY,
        )
    } else {
        (square_to_cosine_hemisphere(u), LobeFlags::DIFFUSE)
    };
    is_upper(wi).then_some((wi, LobeFlags::REFLECTION | lobe))
}

/// Finishes a sample: evaluates f and the pdf at the drawn direction so that both agree exactly with
/// `eval` and `pdf`; `None` unless usable ([`BxdfSample::checked`]).
#[inline]
fn finish(wi: Vec3, flags: LobeFlags, f: Vec3, pdf: f32) -> Option<BxdfSample> {
    BxdfSample::checked(wi, f, pdf, flags)
}

/// Replaces a non-finite value by 0 (only reachable through f32 overflow at extreme parameters).
#[inline]
fn finite_or_zero(v: Vec3) -> Vec3 {
    if v.is_finite() { v } else { Vec3::ZERO }
}

/// The normalisation N of the modified Phong lobe ρ_s N cos^γ θ_r.
///
/// The specular directional albedo is E_s(wo) = ρ_s N I(γ, cos θ_o), with
/// I(γ, c) = ∫_{H²} max(0, ω·r)^γ cos θ dω (r the mirror direction of `wo`, cos θ_r = c).
/// I is largest at normal incidence, I(γ, 1) = 2π/(γ+2), and decreases toward grazing angles, where
/// the lobe is cut by the horizon and weighted by small cosines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PhongNormalization {
    /// N = 1: the lecture's formula with the normalisation "omitted for brevity".
    ///
    /// Reciprocal. Not energy conserving: E_s(n) = 2πρ_s/(γ+2) exceeds ρ_s for γ < 2π − 2 ≈ 4.28.
    Unnormalized,
    /// N = (γ+1)/(2π): the factor derived for the *original* Phong form (\[Phong1975\] as normalised in
    /// the lecture), applied to the modified form.
    ///
    /// Reciprocal; energy conserving (E_s ≤ ρ_s (γ+1)/(γ+2) < ρ_s) but loses energy everywhere.
    EnergyConservingOriginal,
    /// N = (γ+2)/(2π): the modified Phong of \[Lafortune1994\].
    ///
    /// Reciprocal; energy conserving, with E_s = ρ_s exactly at normal incidence only (it darkens toward
    /// grazing angles).
    EnergyConserving,
    /// N(wo) = 1/I(γ, cos θ_o) with I by Arvo's recurrence (\[Arvo1995\]); γ must be an integer
    /// (≤ [`ARVO_MAX_GAMMA`]), cost O(γ) per evaluation.
    ///
    /// Energy normalised: E_s(wo) = ρ_s for every `wo`. Not reciprocal (N depends on `wo` only).
    EnergyNormalizedArvo,
    /// N(wo) = 1/I(γ, cos θ_o) with I in closed form through the incomplete beta function
    /// (\[MallettYuksel2020\]); real γ, O(1) per evaluation (one `beta_inc`, ~200 ns).
    ///
    /// Energy normalised: E_s(wo) = ρ_s for every `wo`. Not reciprocal.
    EnergyNormalizedMallettYuksel,
}

impl PhongNormalization {
    /// Whether N is a constant (then the lobe is reciprocal) rather than a function of `wo`.
    pub fn is_constant(self) -> bool {
        matches!(
            self,
            PhongNormalization::Unnormalized
                | PhongNormalization::EnergyConservingOriginal
                | PhongNormalization::EnergyConserving
        )
    }

    /// Whether the specular albedo is exactly ρ_s for every `wo`.
    pub fn is_energy_normalized(self) -> bool {
        !self.is_constant()
    }
}

/// The modified Phong BRDF f = k_d/π + k_s N(wo) max(0, cos θ_r)^γ.
///
/// Without Fresnel k_d = ρ_d and k_s = ρ_s. With [`Phong::with_schlick_fresnel`], following the
/// lecture's energy-normalised form with Fresnel, k_s = F(cos θ_o) = Schlick(f0 = ρ_s, cos θ_o) and
/// k_d = ρ_d (1 − F(cos θ_o)), so that the energy taken by the specular lobe is removed from the diffuse
/// one. cos θ_r = wi · reflect(wo, n).
///
/// Properties (tested in `tests/it/bxdf_phong.rs` and `tests/it/bxdf_reciprocity.rs`):
/// - reciprocal iff N is constant and Fresnel is off ([`Phong::is_reciprocal`]);
/// - energy conserving for every normalisation but [`PhongNormalization::Unnormalized`] when
///   ρ_d + ρ_s ≤ 1 (enforced); with an energy-normalised N the specular albedo is exactly k_s for
///   every `wo` (a white furnace with ρ_d = 0, ρ_s = 1 returns 1).
///
/// Sampling: the specular lobe is chosen with probability s/(d+s), d = mean(k_d),
/// s = mean(k_s) · N · I(γ, 1) (the lobe's albedo at normal incidence, an upper bound of it for every
/// `wo`; exactly 1 for the energy-normalised variants), so no incomplete beta function is evaluated to
/// choose a lobe.
///
/// # Reference
/// Lecture \[VSB2024\] (slides "Modified Phong BRDF", "Energy-normalization"); \[Lafortune1994\];
/// \[Arvo1995\]; \[MallettYuksel2020\]; Fresnel \[Schlick1994\].
///
/// # Degenerate cases
/// `wo`, `wi` not strictly above the horizon, zero-length or non-finite: f = 0, pdf = 0, `sample` →
/// `None`. The specular lobe is 0 where cos θ_r ≤ 0 (also for γ = 0).
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, Phong, PhongNormalization};
/// use brdf::Vec3;
///
/// // Energy normalised: the specular lobe reflects exactly ρ_s for every wo (not reciprocal).
/// let p = Phong::new(Vec3::splat(0.2), Vec3::splat(0.8), 50.0,
///                    PhongNormalization::EnergyNormalizedMallettYuksel)?;
/// assert!(!p.is_reciprocal());
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// let mirror = Vec3::new(-0.6, 0.0, 0.8);
/// assert!(p.eval(wo, mirror).x > p.eval(wo, Vec3::Z).x);
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    rho_d: Vec3,
    rho_s: Vec3,
    gamma: f32,
    normalization: PhongNormalization,
    fresnel: bool,
    /// N for the constant normalisations (unused otherwise).
    constant: f32,
    /// Specular lobe albedo at normal incidence per unit k_s: N · I(γ, 1) (1 when energy normalised).
    lobe_albedo_max: f32,
}

impl Phong {
    /// A modified Phong BRDF with diffuse albedo `rho_d`, specular reflectance `rho_s`, exponent `gamma`
    /// and the given normalisation.
    ///
    /// Errors (`Error::InvalidParameter`): `rho_d` or `rho_s` outside [0, 1] or non-finite in some
    /// channel; `rho_d + rho_s` > 1 in some channel; `gamma` negative or non-finite; `gamma` not an
    /// integer in [0, [`ARVO_MAX_GAMMA`]] for [`PhongNormalization::EnergyNormalizedArvo`].
    pub fn new(
        rho_d: Vec3,
        rho_s: Vec3,
        gamma: f32,
        normalization: PhongNormalization,
    ) -> Result<Phong> {
        let rho_d = unit_rgb("rho_d", rho_d)?;
        let rho_s = unit_rgb("rho_s", rho_s)?;
        check_sum(rho_d, rho_s)?;
        let gamma = non_negative("gamma", gamma)?;
        if normalization == PhongNormalization::EnergyNormalizedArvo
            && !(gamma.fract() == 0.0 && gamma <= ARVO_MAX_GAMMA)
        {
            return Err(Error::InvalidParameter {
                name: "gamma",
                value: gamma as f64,
                reason: "Arvo's normalisation needs an integer exponent <= 2^24",
            });
        }
        let constant = match normalization {
            PhongNormalization::Unnormalized => 1.0,
            PhongNormalization::EnergyConservingOriginal => (gamma + 1.0) / TAU,
            PhongNormalization::EnergyConserving => (gamma + 2.0) / TAU,
            _ => 0.0,
        };
        let lobe_albedo_max = if normalization.is_constant() {
            constant * TAU / (gamma + 2.0)
        } else {
            1.0
        };
        Ok(Phong {
            rho_d,
            rho_s,
            gamma,
            normalization,
            fresnel: false,
            constant,
            lobe_albedo_max,
        })
    }

    /// The same BRDF with Schlick's Fresnel in place of ρ_s: k_s = Schlick(ρ_s, cos θ_o),
    /// k_d = ρ_d (1 − k_s). Breaks reciprocity (F depends on θ_o only).
    pub fn with_schlick_fresnel(mut self) -> Phong {
        self.fresnel = true;
        self
    }

    /// Diffuse albedo ρ_d.
    pub fn rho_d(&self) -> Vec3 {
        self.rho_d
    }

    /// Specular reflectance ρ_s (Schlick's f0 when Fresnel is on).
    pub fn rho_s(&self) -> Vec3 {
        self.rho_s
    }

    /// Phong exponent γ.
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// The normalisation.
    pub fn normalization(&self) -> PhongNormalization {
        self.normalization
    }

    /// Whether Schlick's Fresnel replaces ρ_s.
    pub fn has_fresnel(&self) -> bool {
        self.fresnel
    }

    /// Whether f(wo, wi) = f(wi, wo): constant N and no Fresnel.
    pub fn is_reciprocal(&self) -> bool {
        self.normalization.is_constant() && !self.fresnel
    }

    /// The normalisation factor N(wo) of the specular lobe.
    ///
    /// Constant for the first three variants; 1/I(γ, cos θ_o) for the energy-normalised ones
    /// (0 when `wo` is not above the horizon or I underflows).
    pub fn normalizer(&self, wo: Vec3) -> f32 {
        let integral = match self.normalization {
            PhongNormalization::EnergyNormalizedArvo => {
                phong_lobe_integral_arvo(self.gamma as u32, wo.z)
            }
            PhongNormalization::EnergyNormalizedMallettYuksel => {
                phong_lobe_integral(self.gamma, wo.z)
            }
            _ => return self.constant,
        };
        if is_upper(wo) && integral > 0.0 && integral.is_finite() {
            1.0 / integral
        } else {
            0.0
        }
    }

    /// (k_d, k_s) for this `wo`: (ρ_d, ρ_s) or, with Fresnel, (ρ_d (1 − F), F), F = Schlick(ρ_s, cos θ_o).
    #[inline]
    fn reflectances(&self, wo: Vec3) -> (Vec3, Vec3) {
        if self.fresnel {
            let f = schlick(self.rho_s, wo.z);
            (self.rho_d * (Vec3::ONE - f), f)
        } else {
            (self.rho_d, self.rho_s)
        }
    }

    #[inline]
    fn p_spec(&self, kd: Vec3, ks: Vec3) -> f32 {
        specular_probability(kd, ks * self.lobe_albedo_max)
    }
}

impl Bxdf for Phong {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !(is_upper(wo) && is_upper(wi)) {
            return Vec3::ZERO;
        }
        let (kd, ks) = self.reflectances(wo);
        let lobe = cosine_power(wi.dot(mirror(wo)), self.gamma);
        let spec = if lobe > 0.0 {
            ks * (self.normalizer(wo) * lobe)
        } else {
            Vec3::ZERO
        };
        finite_or_zero(kd * FRAC_1_PI + spec)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(is_upper(wo) && is_upper(wi)) {
            return 0.0;
        }
        let (kd, ks) = self.reflectances(wo);
        mixture_pdf(wo, wi, self.p_spec(kd, ks), self.gamma)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !is_upper(wo) {
            return None;
        }
        let (kd, ks) = self.reflectances(wo);
        let (wi, flags) = sample_mixture(wo, uc, u, self.p_spec(kd, ks), self.gamma)?;
        let (f, pdf) = self.eval_pdf(wo, wi);
        finish(wi, flags, f, pdf)
    }
}

/// Normalisation of the original Phong form.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OriginalPhongNormalization {
    /// N = 1: Phong's shading formula read as a BRDF. Not energy conserving: the specular albedo at
    /// normal incidence is 2πρ_s/(γ+1), above ρ_s for γ < 2π − 1.
    Unnormalized,
    /// N = (γ+1)/(2π), derived in the lecture at normal incidence. Energy conserving for every `wo`:
    /// ∫ N max(0, cos θ_r)^γ dω_i over the upper hemisphere is at most the integral over the whole cap
    /// about r, which is exactly 1.
    EnergyConserving,
}

/// The original Phong BRDF f = ρ_d/π + ρ_s N max(0, cos θ_r)^γ / cos θ_i.
///
/// Phong's shading model multiplies the incident radiance by ρ_s cos^γ θ_r without the cosine of
/// incidence; written as a BRDF that is the division by cos θ_i above. Kept for what it is: it is **not
/// reciprocal** (the 1/cos θ_i is not symmetric) and, unnormalised, **not energy conserving**; f itself
/// diverges as θ_i → 90° (f cos θ_i stays bounded). Sampling: the cosine-power lobe about r is exact
/// importance sampling of f cos θ_i's specular part; lobe choice as in [`Phong`] with the specular
/// weight mean(ρ_s) · N · 2π/(γ+1).
///
/// # Reference
/// \[Phong1975\]; its reading as a BRDF and the normaliser (γ+1)/(2π): lecture \[VSB2024\] (slides
/// "Modified Phong BRDF", "Original Phong BRDF Energy-conserving").
///
/// # Degenerate cases
/// As [`Phong`]. f is set to 0 in the (f32-overflow) case where the division by cos θ_i is not finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OriginalPhong {
    rho_d: Vec3,
    rho_s: Vec3,
    gamma: f32,
    normalization: OriginalPhongNormalization,
    constant: f32,
    lobe_albedo_max: f32,
}

impl OriginalPhong {
    /// An original Phong BRDF. Errors as [`Phong::new`] (`rho_d`, `rho_s`, `rho_d + rho_s`, `gamma`).
    pub fn new(
        rho_d: Vec3,
        rho_s: Vec3,
        gamma: f32,
        normalization: OriginalPhongNormalization,
    ) -> Result<OriginalPhong> {
        let rho_d = unit_rgb("rho_d", rho_d)?;
        let rho_s = unit_rgb("rho_s", rho_s)?;
        check_sum(rho_d, rho_s)?;
        let gamma = non_negative("gamma", gamma)?;
        let constant = match normalization {
            OriginalPhongNormalization::Unnormalized => 1.0,
            OriginalPhongNormalization::EnergyConserving => (gamma + 1.0) / TAU,
        };
        Ok(OriginalPhong {
            rho_d,
            rho_s,
            gamma,
            normalization,
            constant,
            lobe_albedo_max: constant * TAU / (gamma + 1.0),
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

    /// Phong exponent γ.
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// The normalisation.
    pub fn normalization(&self) -> OriginalPhongNormalization {
        self.normalization
    }

    /// The constant N.
    pub fn normalizer(&self) -> f32 {
        self.constant
    }

    #[inline]
    fn p_spec(&self) -> f32 {
        specular_probability(self.rho_d, self.rho_s * self.lobe_albedo_max)
    }
}

impl Bxdf for OriginalPhong {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !(is_upper(wo) && is_upper(wi)) {
            return Vec3::ZERO;
        }
        let lobe = cosine_power(wi.dot(mirror(wo)), self.gamma);
        let spec = self.rho_s * (self.constant * lobe / wi.z);
        finite_or_zero(self.rho_d * FRAC_1_PI + spec)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(is_upper(wo) && is_upper(wi)) {
            return 0.0;
        }
        mixture_pdf(wo, wi, self.p_spec(), self.gamma)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !is_upper(wo) {
            return None;
        }
        let (wi, flags) = sample_mixture(wo, uc, u, self.p_spec(), self.gamma)?;
        let (f, pdf) = self.eval_pdf(wo, wi);
        finish(wi, flags, f, pdf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_normalisers() {
        let g = 10.0;
        let n = |k| {
            Phong::new(Vec3::ZERO, Vec3::ONE, g, k)
                .unwrap()
                .normalizer(Vec3::Z)
        };
        assert_eq!(n(PhongNormalization::Unnormalized), 1.0);
        assert!((n(PhongNormalization::EnergyConservingOriginal) - 11.0 / TAU).abs() < 1e-6);
        assert!((n(PhongNormalization::EnergyConserving) - 12.0 / TAU).abs() < 1e-6);
        // At normal incidence I(γ, 1) = 2π/(γ+2), so the energy-normalised N equals Lafortune's there
        // (f32 bound on the closed form: a few ulps of 12/2π ≈ 1.9).
        assert!((n(PhongNormalization::EnergyNormalizedMallettYuksel) - 12.0 / TAU).abs() < 1e-5);
        assert!((n(PhongNormalization::EnergyNormalizedArvo) - 12.0 / TAU).abs() < 1e-5);
    }

    #[test]
    fn arvo_needs_an_integer_exponent() {
        let e = Phong::new(
            Vec3::ZERO,
            Vec3::ONE,
            2.5,
            PhongNormalization::EnergyNormalizedArvo,
        )
        .unwrap_err();
        assert!(e.to_string().contains("gamma"), "{e}");
        assert!(
            Phong::new(
                Vec3::ZERO,
                Vec3::ONE,
                2.5,
                PhongNormalization::EnergyNormalizedMallettYuksel
            )
            .is_ok()
        );
    }

    #[test]
    fn peak_at_the_mirror_direction() {
        let p = Phong::new(
            Vec3::ZERO,
            Vec3::ONE,
            50.0,
            PhongNormalization::EnergyConserving,
        )
        .unwrap();
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let at = p.eval(wo, mirror(wo)).x;
        assert!((at - 52.0 / TAU).abs() < 1e-4);
        let off = Vec3::new(-0.45, 0.1, 0.0).with_z((1.0f32 - 0.45 * 0.45 - 0.01).sqrt());
        assert!(p.eval(wo, off).x < at);
    }
}
