//! The normalised Blinn-Phong NDF D(m) = (γ+2)/(2π) cos^γ θ_m, with its exact visible area.
//!
//! Its slopes follow a bivariate Student-t with ν = γ + 2 degrees of freedom; the Smith Λ has no
//! elementary closed form, but the visible projected area ∫⟨w, m⟩⁺ D dm does (through the Phong
//! lobe integral), so Λ, G1 and the visible-normal density are exact. Visible normals are drawn by
//! rejection from GGX visible normals, whose ⟨wo, m⟩ factor cancels in the acceptance ratio.

use super::beckmann::MIN_ALPHA;
use super::phong_integral::phong_lobe_integral;
use super::{Ggx, Ndf};
use crate::Result;
use crate::error::non_negative;
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// Largest exponent used internally: 2/MIN_ALPHA² − 2 ≈ 2·10⁸, the Blinn-Phong equivalent of the
/// smallest Beckmann α (and the narrowest GGX proposal the visible sampler can use).
pub const MAX_GAMMA: f32 = 2.0 / (MIN_ALPHA * MIN_ALPHA) - 2.0;

/// Most proposals [`BlinnPhong::sample_visible`] draws before giving up.
///
/// The acceptance probability is ≥ 0.38 for every γ and every wo (measured over a dense grid in
/// `tests::acceptance_lower_bound`; ≥ e/4 ≈ 0.68 at normal incidence), so the fallback is taken with
/// probability ≤ 0.62⁶⁴ < 10⁻¹³.
pub const MAX_VISIBLE_TRIES: u32 = 64;

/// The normalised Blinn-Phong distribution D(m) = (γ + 2)/(2π) cos^γ θ_m (isotropic).
///
/// Its Beckmann-equivalent roughness is α = √(2/(γ + 2)) ([`beckmann_alpha_from_shininess`]).
/// Masking: the exact Smith Λ(w) = V(w)/cos θ_w − 1 with the exact visible area
/// V(w) = (γ + 2)/(2π) · I(γ, cos θ_w) ([`phong_lobe_integral`]); Walter's rational approximation
/// is available as [`BlinnPhong::lambda_walter`] (see docs/ndf.md for why the exact one is the
/// default and how far the approximation is from it).
///
/// # Reference
/// \[Walter2007\] §5.2 (normalised D, Beckmann-equivalent exponent, approximate Λ),
/// \[MallettYuksel2020\] (the visible area in closed form).
///
/// [`beckmann_alpha_from_shininess`]: super::beckmann_alpha_from_shininess
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhong {
    gamma: f32,
    /// The GGX proposal of the visible sampler and ln of its bound M = sup D/D_GGX.
    proposal: Ggx,
    ln_m: f32,
}

impl BlinnPhong {
    /// A Blinn-Phong NDF with exponent (shininess) `gamma`.
    ///
    /// Errors (naming `gamma`) if it is negative or non-finite; values above [`MAX_GAMMA`] are
    /// clamped to it. γ = 0 is the uniform distribution D = 1/π.
    pub fn new(gamma: f32) -> Result<Self> {
        let gamma = non_negative("gamma", gamma)?.min(MAX_GAMMA);
        let proposal = Ggx::isotropic((2.0 / (gamma + 2.0)).sqrt())?;
        let a2 = proposal.alpha_x() * proposal.alpha_x();
        // sup over t = tan²θ of ln(D/D_GGX): stationary at t* = (4 − (γ+4)α²)/γ (= α² for the
        // Beckmann-equivalent α), or at t = 0 when that is ≤ 0.
        let t_star = if gamma > 0.0 {
            ((4.0 - (gamma + 4.0) * a2) / gamma).max(0.0)
        } else {
            0.0
        };
        let ln_m = ln_ratio(gamma, a2, t_star);
        Ok(BlinnPhong {
            gamma,
            proposal,
            ln_m,
        })
    }

    /// The exponent γ (after the clamp).
    pub fn gamma(&self) -> f32 {
        self.gamma
    }

    /// Walter et al.'s rational approximation of Λ through the Beckmann-equivalent α = √(2/(γ+2)):
    /// with a = 1/(α tan θ), Λ ≈ (1 − 1.259a + 0.396a²)/(3.535a + 2.181a²) for a < 1.6, else 0.
    ///
    /// Cheap (no special function) but approximate: it is Beckmann's Λ, not Blinn-Phong's (see
    /// docs/ndf.md for the measured difference). 0 below the horizon, finite at grazing.
    ///
    /// # Reference
    /// \[Walter2007\] §5.1–5.2 (the rational G1 and the Phong–Beckmann exponent mapping).
    pub fn lambda_walter(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let alpha = (2.0 / (self.gamma + 2.0)).sqrt();
        let a = w.z / (alpha * Vec2::new(w.x, w.y).length());
        if a >= 1.6 {
            return 0.0;
        }
        let l = (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
        if l.is_finite() { l.max(0.0) } else { f32::MAX }
    }

    /// cos θ of a direction of any length (`None` when not usable).
    fn cos_theta(w: Vec3) -> Option<f32> {
        let w = w.try_normalize()?;
        (w.z > 0.0).then_some(w.z)
    }
}

/// ln(D_BP/D_GGX) at t = tan²θ for exponent γ and GGX α² = a2:
/// ln((γ+2)α²/2) + 2 ln(1 + t/α²) − (γ+4)/2 · ln(1 + t).
#[inline]
fn ln_ratio(gamma: f32, a2: f32, t: f32) -> f32 {
    (0.5 * (gamma + 2.0) * a2).ln() + 2.0 * (t / a2).ln_1p() - 0.5 * (gamma + 4.0) * t.ln_1p()
}

/// A small counter-based generator (SplitMix64) seeded from the bits of `u`, for the extra
/// random numbers of the rejection sampler: a deterministic function of `u`, as the trait requires.
struct SplitMix(u64);

impl SplitMix {
    fn new(u: Vec2) -> Self {
        SplitMix(((u.x.to_bits() as u64) << 32 | u.y.to_bits() as u64) ^ 0x5851_f42d_4c95_7f2d)
    }

    /// A uniform number in (0, 1) (24 random bits, centred in their interval: never 0).
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        ((z >> 40) as f32 + 0.5) * (1.0 / 16_777_216.0)
    }
}

impl Ndf for BlinnPhong {
    /// D(m) = (γ + 2)/(2π) cos^γ θ_m, with cos^γ θ = exp(γ/2 · ln(1 − sin²θ)) near the pole (so that
    /// lobes narrower than the f32 spacing of cos θ near 1 are resolved) and exp(γ/2 · ln cos²θ)
    /// near the horizon (so that cos θ < 2⁻¹² is not rounded to 0). 0 for z ≤ 0 or non-finite m.
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        if !(m.z > 0.0 && m.is_finite()) {
            return 0.0;
        }
        let norm = (self.gamma + 2.0) * (0.5 / PI);
        if self.gamma == 0.0 {
            return norm;
        }
        let len2 = m.length_squared();
        let s2 = (m.x * m.x + m.y * m.y) / len2;
        // ln cos²θ: through ln(1 − sin²θ) near the pole (narrow lobes), directly from cos²θ near the
        // horizon, where 1 − sin²θ rounds to 0 in f32 although cos θ itself is representable.
        let ln_c2 = if s2 < 0.5 {
            (-s2).ln_1p()
        } else {
            (m.z * m.z / len2).ln()
        };
        let v = norm * (0.5 * self.gamma * ln_c2).exp();
        if v.is_finite() { v } else { 0.0 }
    }

    /// Exact Smith Λ(w) = V(w)/cos θ_w − 1 (see [`Ndf::visible_area`]); ≥ 0; 0 below the horizon,
    /// finite (capped at `f32::MAX`) at grazing. Cost: one incomplete beta function (~0.2 µs).
    fn lambda(&self, w: Vec3) -> f32 {
        let Some(c) = Self::cos_theta(w) else {
            return 0.0;
        };
        let l = self.visible_area(w) / c - 1.0;
        if l.is_finite() { l.max(0.0) } else { f32::MAX }
    }

    /// G1(w, m) = χ⁺(w·m) cos θ_w / V(w) = χ⁺(w·m) / (1 + Λ(w)) with the exact Λ; 0 for
    /// degenerate input.
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        if !(w.dot(m) > 0.0 && m.is_finite()) {
            return 0.0;
        }
        let (Some(c), v) = (Self::cos_theta(w), self.visible_area(w)) else {
            return 0.0;
        };
        if v > 0.0 {
            (c / v).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Exact ∫⟨w, m⟩⁺ D(m) dm = (γ + 2)/(2π) · I(γ, cos θ_w), I the Phong lobe integral (the
    /// integrand max(0, m·w) max(0, m·z)^γ is the Phong integrand with the axis and the normal
    /// swapped). 0 below the horizon.
    ///
    /// # Reference
    /// \[MallettYuksel2020\].
    fn visible_area(&self, w: Vec3) -> f32 {
        match Self::cos_theta(w) {
            Some(c) => (self.gamma + 2.0) * (0.5 / PI) * phong_lobe_integral(self.gamma, c),
            None => 0.0,
        }
    }

    /// D(m) / V(wo): the default [`Ndf::pdf_visible`] without its factor ⟨wo, m⟩, which the
    /// reflection Jacobian cancels (no underflow at grazing views).
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16.
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        super::visible_over_cos(wo, m, d_m, self.visible_area(wo))
    }

    /// D(m): [`Ndf::pdf_normal`] = D cos θ_m without its cosine.
    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        super::normal_over_cos(m, d_m)
    }

    /// Height-correlated G2 = χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi)); 0 for degenerate input.
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        super::masking::g2_height_correlated_checked(self, wo, wi, m)
    }

    /// m ~ D(m) cos θ_m exactly: cos θ = (1 − u₁)^(1/(γ+2)), sin²θ = −expm1(2 ln(1 − u₁)/(γ+2))
    /// (no cancellation for narrow lobes), φ = 2π u₂.
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let l = (-u.x.clamp(0.0, 1.0 - f32::EPSILON / 2.0)).ln_1p() / (self.gamma + 2.0);
        let s2 = (-(2.0 * l).exp_m1()).clamp(0.0, 1.0);
        let cos_t = l.exp();
        let sin_t = s2.sqrt();
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        Vec3::new(sin_t * c, sin_t * s, cos_t)
            .try_normalize()
            .unwrap_or(Vec3::Z)
    }

    /// m ~ D_wo(m) exactly, by rejection: propose m from the GGX visible-normal sampler with the
    /// Beckmann-equivalent α = √(2/(γ+2)), accept with probability D(m)/(M D_GGX(m)),
    /// M = sup D/D_GGX = 4((γ+2)/(γ+4))^((γ+4)/2) ∈ [1, 4/e]. The factor ⟨wo, m⟩ and both visible
    /// areas cancel, so accepted normals have density exactly ⟨wo, m⟩⁺ D(m)/V(wo).
    ///
    /// Random numbers: the first proposal uses `u` itself (so stratification of `u` carries over to
    /// the accepted majority); the acceptance tests and later proposals use a SplitMix64 stream
    /// seeded from the bits of `u`. After [`MAX_VISIBLE_TRIES`] rejections (probability < 10⁻¹³)
    /// the last GGX proposal is returned. Below-horizon or non-finite `wo` falls back to
    /// [`Ndf::sample_normal`].
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if !(wo.z > 0.0 && wo.is_finite()) {
            return self.sample_normal(u);
        }
        let a2 = self.proposal.alpha_x() * self.proposal.alpha_x();
        let mut rng = SplitMix::new(u);
        let mut uu = u;
        let mut m = Vec3::Z;
        for _ in 0..MAX_VISIBLE_TRIES {
            m = self.proposal.sample_visible(wo, uu);
            let t = (m.x * m.x + m.y * m.y) / (m.z * m.z);
            if rng.next().ln() <= ln_ratio(self.gamma, a2, t) - self.ln_m {
                return m;
            }
            uu = Vec2::new(rng.next(), rng.next());
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The acceptance probability of the rejection sampler, V(wo) / (M · V_GGX(wo)), over γ and θ.
    #[test]
    fn acceptance_lower_bound() {
        let mut worst = f32::MAX;
        let mut at = (0.0, 0.0);
        for g in [
            0.0f32, 0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0, 1e3, 1e4, 1e5, 1e6, 1e8,
        ] {
            let bp = BlinnPhong::new(g).unwrap();
            for i in 0..=400 {
                let theta = (i as f32 / 400.0) * 89.999f32.to_radians();
                let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                let p = bp.visible_area(wo) / (bp.ln_m.exp() * bp.proposal.visible_area(wo));
                if p < worst {
                    worst = p;
                    at = (g, theta.to_degrees());
                }
            }
        }
        println!("minimum acceptance {worst} at (γ, θ) = {at:?}");
        // The bound documented on MAX_VISIBLE_TRIES.
        assert!(worst >= 0.38, "{worst} at {at:?}");
    }

    #[test]
    fn bound_is_the_supremum() {
        // M must dominate D/D_GGX everywhere (else the sampler would be biased): scan t = tan²θ.
        for g in [0.0f32, 0.3, 1.0, 8.0, 100.0, 1e4, 1e7] {
            let bp = BlinnPhong::new(g).unwrap();
            let a2 = bp.proposal.alpha_x().powi(2);
            let mut sup = f32::MIN;
            for k in -400..=400 {
                let t = a2 * 10f32.powf(k as f32 / 50.0);
                sup = sup.max(ln_ratio(g, a2, t));
            }
            sup = sup.max(ln_ratio(g, a2, 0.0));
            // ln M is the analytic maximum: the scan may not exceed it beyond f32 rounding
            // (|ln R| ≲ 2, a few ulp), and reaches it within the grid spacing.
            assert!(
                sup <= bp.ln_m + 1e-5,
                "γ = {g}: scan {sup} > ln M {}",
                bp.ln_m
            );
            assert!(
                sup >= bp.ln_m - 1e-3,
                "γ = {g}: scan {sup} ≪ ln M {}",
                bp.ln_m
            );
        }
        // M = 1 at γ = 0 (D is then exactly GGX with α = 1), 4/e as γ → ∞.
        assert!(BlinnPhong::new(0.0).unwrap().ln_m.abs() < 1e-6);
        let big = BlinnPhong::new(1e6).unwrap().ln_m;
        assert!((big - (4.0f32.ln() - 1.0)).abs() < 1e-4, "{big}");
    }
}
