//! The anisotropic Beckmann NDF (Gaussian slopes) with its exact Smith Λ and exact samplers.
//!
//! Slopes ñ of the micronormals are Gaussian with per-axis standard deviation α/√2. D and Λ follow
//! Walter et al. 2007 and Heitz 2014 (the anisotropic form through α(φ)); the visible-normal sampler
//! is the stretch / sample / rotate / unstretch routine of Heitz & d'Eon 2014 with the 1D visible
//! slope inversion of Jakob 2014 (in the erf domain, safeguarded by bisection; Halley's method here).

use super::Ndf;
use super::beckmann_guess;
use crate::Result;
use crate::error::positive;
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::slope_to_normal;
use crate::math::{
    INV_SQRT_PI, atan2_pos, erf_with_exp_neg_sq, erfcx_small, erfinv, exp_neg_sq,
    is_positive_finite,
};
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// √π / 2.
const HALF_SQRT_PI: f32 = 0.886_226_9;

/// Smallest α used internally; larger requests pass through unchanged.
///
/// As in pbrt-v4, α is clamped to ≥ 10⁻⁴: D(ω_g) = 1/(π α_x α_y) ≤ 3.2·10⁷ and the products a
/// microfacet BRDF forms with it (D / (4 cos θo cos θi), pdf ratios) stay far inside `f32` range,
/// while a lobe of width 10⁻⁴ rad is already narrower than anything a renderer resolves (use a mirror
/// below that). The accuracy tests cover α ∈ [10⁻⁴, 10].
pub const MIN_ALPHA: f32 = 1e-4;

/// Largest α accepted by the Beckmann and GGX constructors: 10⁴ (an RMS slope of ~7000, normals
/// within ~10⁻⁴ rad of the horizon almost everywhere; the crate's [`MAX_SLOPE`](super::MAX_SLOPE)).
/// Beyond it the stretched samplers form vectors whose tiny z underflows against α-scaled x, y (a
/// fuzz finding at α = 3.5·10¹³: a sampled "normal" of length 0.99), and no material has such
/// roughness. Larger values are refused with an error naming the parameter.
pub const MAX_ALPHA: f32 = 1e4;

/// α = r²: the perceptual roughness r ∈ [0, 1] of Burley's parameterisation mapped to α.
///
/// Squaring makes equal steps of r look roughly equally spaced. Non-finite r gives 0 (which the
/// NDF constructors then reject, naming `alpha`).
///
/// # Reference
/// \[Burley2012\] §5.4 (α = roughness²).
pub fn alpha_from_roughness(r: f32) -> f32 {
    if r.is_finite() { r * r } else { 0.0 }
}

/// Beckmann α equivalent to a Phong / Blinn-Phong exponent γ: α = √(2/(γ + 2)).
///
/// The two NDFs then have the same second moment of the slope near the peak (Walter's mapping
/// γ = 2/α² − 2, inverted). γ = 0 gives α = 1. Negative or NaN γ is treated as 0; γ = +∞ gives 0.
///
/// # Reference
/// \[Walter2007\] §5.2.
pub fn beckmann_alpha_from_shininess(gamma: f32) -> f32 {
    let g = if gamma > 0.0 { gamma } else { 0.0 };
    (2.0 / (g + 2.0)).sqrt()
}

/// Phong / Blinn-Phong exponent equivalent to a Beckmann α: γ = 2/α² − 2, the inverse of
/// [`beckmann_alpha_from_shininess`].
///
/// Clamped to [0, `f32::MAX`]: |α| ≥ 1 gives 0 (Blinn-Phong cannot be rougher than uniform),
/// α = 0 gives `f32::MAX`, NaN gives 0.
///
/// # Reference
/// \[Walter2007\] §5.2.
pub fn shininess_from_beckmann_alpha(alpha: f32) -> f32 {
    if alpha.is_nan() {
        return 0.0;
    }
    let g = 2.0 / (alpha * alpha) - 2.0;
    if g.is_finite() { g.max(0.0) } else { f32::MAX }
}

/// The anisotropic Beckmann distribution.
///
/// D(m) = exp(−tan²θ_m (cos²φ_m/α_x² + sin²φ_m/α_y²)) / (π α_x α_y cos⁴θ_m) for cos θ_m > 0.
/// α_x acts along the tangent x; α = √2 σ with σ the RMS slope per axis.
///
/// # Reference
/// \[Walter2007\] §5.1 (isotropic D and Λ), \[Heitz2014\] (anisotropic form through α(φ)),
/// \[Heitz2014b\] and \[Jakob2014\] (visible-normal sampling).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann {
    alpha_x: f32,
    alpha_y: f32,
    /// 1/α_x, 1/α_y and 1/(π α_x α_y), precomputed so that `d` has one division.
    inv_alpha_x: f32,
    inv_alpha_y: f32,
    norm: f32,
}

impl Beckmann {
    /// An anisotropic Beckmann NDF with roughness `alpha_x` along x and `alpha_y` along y.
    ///
    /// Errors if either is non-finite, ≤ 0 or above [`MAX_ALPHA`] (the error names `alpha_x` or
    /// `alpha_y`). Values below [`MIN_ALPHA`] are clamped to it (see there why).
    pub fn new(alpha_x: f32, alpha_y: f32) -> Result<Self> {
        let (alpha_x, alpha_y) = validated_alphas(alpha_x, alpha_y)?;
        Ok(Self::from_valid(alpha_x, alpha_y))
    }

    /// An isotropic Beckmann NDF; errors (naming `alpha`) if `alpha` is non-finite or ≤ 0.
    pub fn isotropic(alpha: f32) -> Result<Self> {
        let alpha = validated_alpha(alpha)?;
        Ok(Self::from_valid(alpha, alpha))
    }

    /// The NDF from validated, clamped α.
    fn from_valid(alpha_x: f32, alpha_y: f32) -> Self {
        Beckmann {
            alpha_x,
            alpha_y,
            inv_alpha_x: 1.0 / alpha_x,
            inv_alpha_y: 1.0 / alpha_y,
            norm: 1.0 / (PI * alpha_x * alpha_y),
        }
    }

    /// α along x (after the [`MIN_ALPHA`] clamp).
    pub fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    /// α along y (after the [`MIN_ALPHA`] clamp).
    pub fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    /// n² = α(φ)² sin²θ = |(α_x x, α_y y)|² for w = (x, y, z), unchecked (callers test the result).
    #[inline(always)]
    fn stretched_sin_sq(&self, w: Vec3) -> f32 {
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        x * x + y * y
    }

    /// a = 1 / (α(φ) tan θ) = z / |(α_x x, α_y y)| for w = (x, y, z): the argument of Λ.
    /// `None` below the horizon or for non-finite input; +∞ at normal incidence.
    #[inline]
    fn a_of(&self, w: Vec3) -> Option<f32> {
        if !(w.z > 0.0 && w.is_finite()) {
            return None;
        }
        let n = Vec2::new(self.alpha_x * w.x, self.alpha_y * w.y).length();
        Some(w.z / n)
    }
}

/// Exact Smith Λ of the Beckmann NDF as a function of a = 1/(α(φ) tan θ) > 0.
///
/// Λ(a) = (erf(a) − 1)/2 + e^(−a²)/(2a√π) = e^(−a²)/(2a√π) · g(a), g(a) = 1 − a√π e^(a²) erfc(a).
/// The difference cancels catastrophically for large a, so:
/// - a < 2: Λ = (e^(−a²)/(a√π) − erfc(a)) / 2 with the relative-accurate [`erfc`] (≤ 10 bits
///   lost at a = 2; measured relative error ≤ 3·10⁻⁶);
/// - 2 ≤ a < 10: g(a) = P/(P + Q) from the 16th convergent of Laplace's continued fraction
///   erfc(a) = e^(−a²)/√π · 1/(a + ½/(a + 1/(a + (3/2)/(a + …)))), whose numerator and denominator
///   are the polynomials below (all coefficients positive: no cancellation; truncation error
///   ≤ 1.4·10⁻⁷ relative for a ≥ 2);
/// - a ≥ 10: 0 (Λ < 10⁻⁴⁶, below the smallest `f32`).
///
/// Returns a finite value for every a > 0 (Λ ≈ 1/(2a√π) → capped at `f32::MAX` as a → 0).
///
/// # Reference
/// \[Walter2007\] §5.1 (Beckmann G1), \[Heitz2014\] (Λ of the Beckmann distribution); the continued fraction is \[AbramowitzStegun1964\] 7.1.14.
#[inline]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(a > 0)` also rejects NaN
fn lambda_of_a(a: f32) -> f32 {
    if !(a > 0.0) {
        return f32::MAX;
    }
    if a >= 10.0 {
        return 0.0;
    }
    let l = 0.5 * exp_neg_sq(a) * lambda_scaled(a);
    if l.is_finite() { l.max(0.0) } else { f32::MAX }
}

/// 2 e^(a²) Λ(a) for 0 < a < 10: 1/(a√π) − erfcx(a) for a < 2 (erfcx = e^(a²) erfc by the
/// polynomial [`erfcx_small`], relative accurate, no exponential; the difference loses ≤ 10 bits at a = 2), (1/(a√π)) P/(P + Q) for 2 ≤ a < 10 (see
/// [`lambda_of_a`]). Factoring e^(−a²) out of both branches leaves one exponential per Λ.
#[inline(always)]
fn lambda_scaled(a: f32) -> f32 {
    let inv = INV_SQRT_PI / a;
    if a < 2.0 {
        inv - erfcx_small(a)
    } else {
        // 16th convergent K = A₁₆/B₁₆ of K = ½/(a + 1/(a + (3/2)/(a + …))): A₁₆ = a·P(a²),
        // B₁₆ = Q(a²), so g = K/(a + K) = P/(P + Q).
        let z = a * a;
        let p = horner(z, &CF_P);
        let q = horner(z, &CF_Q);
        inv * (p / (p + q))
    }
}

/// Coefficients (ascending powers of a²) of P, from the recurrence X_n = a X_{n−1} + (n/2) X_{n−2}
/// with A₋₁ = 1, A₀ = 0 (checked against an exact re-derivation in the tests).
#[allow(clippy::excessive_precision)] // the exact dyadic values; rounding to f32 is intended
const CF_P: [f32; 8] = [
    94_287.128_906_25,
    261_358.945_312_5,
    201_152.109_375,
    65_293.593_75,
    10_384.687_5,
    843.375,
    33.25,
    0.5,
];
/// Coefficients of Q, same recurrence with B₋₁ = 0, B₀ = 1.
#[allow(clippy::excessive_precision)]
const CF_Q: [f32; 9] = [
    40_320.0,
    456_545.742_187_5,
    803_914.453_125,
    509_030.156_25,
    149_149.687_5,
    22_361.625,
    1_751.75,
    67.5,
    1.0,
];

/// Σ c_i xⁱ by Horner's scheme.
#[inline]
fn horner<const N: usize>(x: f32, c: &[f32; N]) -> f32 {
    c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
}

/// End of the fitted range: from a = 1/(α(φ) tan θ) = 3.625 on (b = a² ≥ 13.140625), G1 = 1 and
/// V = cos θ exactly. The exact G1 rounds to 1.0 in f32 there (for every f32 a in [3.625, 10),
/// checked in `tests::g1_cutoff_is_exact`; beyond, Λ only decreases).
const G1_END: f32 = 3.625;
/// The visible sampler accepts a Halley step without evaluating the CDF at its result when the
/// predicted error after the step is below this fraction of the stopping tolerance (see
/// [`visible_slope_x`]); 0 verifies every step. The evaluation it saves (an `exp`, and another loop
/// turn) could only confirm: over the grid of `tests::visible_slope_inversion_error` every accepted
/// step returns the same slope as verifying it would, bit for bit (tested); from Jakob's guess it
/// took the evaluations per sample from 2.31 to 1.65 (1.03 with the tabulated guess).
const HALLEY_SAFETY: f32 = 0.1;
/// The prediction is the leading term of Halley's error, valid once the CDF error is small: it is
/// used only where |F(b) − u·total| ≤ this fraction of the total.
const HALLEY_PREDICT_BELOW: f32 = 1e-2;
/// b = a² at [`G1_END`] (exact in f32).
const G1_END_SQ: f32 = G1_END * G1_END;

/// The visible projected area V = cos θ (1 + Λ) = ∫⟨w, m⟩⁺ D dm = cos θ / G1 as a ratio (num, den),
/// from z = cos θ and s = n² = α(φ)² sin²θ = (α_x x)² + (α_y y)².
///
/// With a = z/n and b = a² = z²/s, V = z/2 + n E(b), where
/// E(b) = (e^(−b) + √(πb) erf(√b)) / (2√π) is entire in b (a·erf(a) is even) and V's two terms are
/// positive (no cancellation, accurate down to z → 0, where V → n/(2√π)). E ≈ P(b)/Q(b), a
/// degree-(4, 4) rational function with positive coefficients (so the polynomials add positive terms
/// for b ≥ 0), fitted on [0, 3.625²] by `tools/fit_beckmann_g1.py` (relative error 2.5·10⁻⁸ in
/// exact arithmetic, 5.2·10⁻⁸ with the coefficients rounded to f32); P, Q by Estrin's scheme.
/// Returns (z Q/2 + n P, Q) for b < 3.625², (z, 1) from there on (G1 = 1; also at normal
/// incidence, s = 0, b = +∞) and for NaN b (0/0). No `exp`, one division (b), one `sqrt` (n); the
/// caller divides once: G1 = z·den/num, pdf = ⟨wo, m⟩ D·den/num.
///
/// # Reference
/// \[Walter2007\] §5.1 and \[Heitz2014\] eq. 72 (Λ of the Beckmann distribution), eq. 17 (V); the
/// variable b = a² and the fit are ours (Walter's own fit of G1 is degree (2, 2) in a, 3·10⁻³).
#[inline(always)]
fn visible_area_ratio(z: f32, s: f32) -> (f32, f32) {
    let b = (z * z) / s;
    let n = s.sqrt();
    let (p, q) = e_fit(b);
    if b < G1_END_SQ {
        (0.5 * (z * q) + n * p, q)
    } else {
        (z, 1.0)
    }
}

/// (P(b), Q(b)) of [`visible_area_ratio`], both by Estrin's scheme (no cancellation for b ≥ 0).
#[inline(always)]
fn e_fit(b: f32) -> (f32, f32) {
    let b2 = b * b;
    let [p0, p1, p2, p3, p4] = G1_P;
    let [q0, q1, q2, q3, q4] = G1_Q;
    let p = (p0 + p1 * b) + b2 * ((p2 + p3 * b) + p4 * b2);
    let q = (q0 + q1 * b) + b2 * ((q2 + q3 * b) + q4 * b2);
    (p, q)
}

/// Numerator P(b) of E(b) ≈ P/Q in [`visible_area_ratio`], ascending powers of b = a²
/// (`python3 tools/fit_beckmann_g1.py`).
#[allow(clippy::excessive_precision)]
const G1_P: [f32; 5] = [
    0.282094806432724,
    0.3874117434024811,
    0.07436216622591019,
    0.008980266749858856,
    0.0002258723834529519,
];
/// Denominator Q(b), ascending powers of b.
#[allow(clippy::excessive_precision)]
const G1_Q: [f32; 5] = [
    1.0,
    0.3733389973640442,
    0.05693605914711952,
    0.0037825193721801043,
    2.3033771867631003e-05,
];

/// Smith G1 = 1/(1 + Λ) = z/V of the Beckmann NDF from z = cos θ and s = α(φ)² sin²θ (see
/// [`visible_area_ratio`]): relative error ≤ 4·10⁻⁷ against f64 (fit 5.2·10⁻⁸ plus f32 roundings,
/// `tests::g1_of_a_error`); exactly 1 at normal incidence and for a = z/√s ≥ 3.625; 0 at z = 0;
/// capped at 1. Only finite-or-NaN is guaranteed for degenerate input (callers reject z ≤ 0 and NaN).
///
/// # Reference
/// \[Walter2007\] §5.1 (Beckmann G1), \[Heitz2014\] eq. 72 (Λ).
#[inline(always)]
fn g1_zs(z: f32, s: f32) -> f32 {
    let b = (z * z) / s;
    if b < G1_END_SQ {
        let (p, q) = e_fit(b);
        let zq = z * q;
        // z Q/(z Q/2 + n P) with both sides doubled (exact): the same bits, one multiplication fewer.
        // The fit may exceed the truth by its error just below the cut-off, where G1 < 1 by less.
        ((zq + zq) / (zq + 2.0 * (s.sqrt() * p))).min(1.0)
    } else {
        // Also at normal incidence (b = +∞) and for b = NaN (z = s = 0, rejected by the callers).
        1.0
    }
}

/// V = num/den of [`visible_area_ratio`] (one division).
#[inline(always)]
fn visible_area_zs(z: f32, s: f32) -> f32 {
    let (num, den) = visible_area_ratio(z, s);
    num / den
}

/// Draws the standard (α = 1) visible slope for a direction at polar angle θ in the xz-plane
/// (φ = 0), given cot θ and tan θ.
///
/// The x slope has density ∝ e^(−x²)(1 − x tan θ) on x < cot θ, whose CDF in b = erf(x) is
/// F(b) ∝ 1 + b + tan θ e^(−x²)/√π. F is inverted by Halley's method in b (F'(b) ∝ 1 − x tan θ,
/// F''(b) ∝ −tan θ (√π/2) e^(x²); cubic convergence), safeguarded by bisection on
/// [−1, erf(cot θ)], from a first iterate interpolated in a table of exact roots ([`guess_q`], in
/// place of the fitted guess b₀ = c − (1 + c)(1 − u)^(1 + θ(−0.876 + θ(0.4265 − 0.0594θ))) of Jakob 2014).
/// It stops when the CDF error is below 3·10⁻⁶ (after at most 12 steps), or when Halley's predicted
/// error after a step is below a tenth of that ([`HALLEY_SAFETY`]): a displacement of at most
/// 3·10⁻⁶ of the probability mass, below the f32 noise of the CDF's evaluation at grazing angles and
/// far below what a 10⁶-sample chi-square test resolves. Over 120 θ × 1001 u
/// (`tests::visible_slope_inversion_error`): 1.03 evaluations of erf⁻¹ and `exp` per sample, max
/// |F − u| 3.1·10⁻⁶, mean 5.3·10⁻⁸ (Jakob's guess with the same iteration: 2.31, 3.1·10⁻⁶,
/// 3.5·10⁻⁷; Newton's iteration from Jakob's guess with a 10⁻⁵ rule: 2.78, 1.0·10⁻⁵). The y slope
/// is Gaussian and independent: erf⁻¹(2u₂ − 1).
///
/// # Reference
/// \[Jakob2014\] (the inversion in b = erf(x) and the fitted guess), \[Heitz2014b\] §4 (the visible
/// slope distribution).
fn sample_visible_slope_std(cot_theta: f32, tan_theta: f32, theta: f32, u: Vec2) -> Vec2 {
    let x = visible_slope_x::<true>(cot_theta, tan_theta, theta, u.x, HALLEY_SAFETY).0;
    Vec2::new(x, erfinv(2.0 * u.y.clamp(0.0, 1.0) - 1.0))
}

/// The x slope of [`sample_visible_slope_std`] alone: the standard visible slope along the view's
/// azimuth, density ∝ (cot θ − x)⁺ e^(−x²), for `u` ∈ [0, 1] (the lobe of any Gaussian slope
/// distribution seen from a side its mean facet faces, in its own standardised frame:
/// `SlopeGaussian::sample_visible`).
#[inline]
pub(super) fn visible_slope_x_std(cot_theta: f32, tan_theta: f32, theta: f32, u: f32) -> f32 {
    visible_slope_x::<true>(cot_theta, tan_theta, theta, u, HALLEY_SAFETY).0
}

/// The visible sampler's first iterate: q(θ, u) = (erf(cot θ) − b)/(1 + erf(cot θ)) ∈ [0, 1], the
/// normalised distance of the root b from the top of its bracket, interpolated bilinearly in the
/// 33 × 33 table of [`beckmann_guess::Q`] (regular in θ ∈ [0, π/2] and u ∈ [0, 1]; 4.4 KB; generated
/// in f64 by `tools/beckmann_visible_guess.py`, checked by `tests::guess_table_is_the_root`).
#[inline(always)]
fn guess_q(theta: f32, u: f32) -> f32 {
    use beckmann_guess::{NT, NU, Q};
    let fi = (theta * (NT as f32 / core::f32::consts::FRAC_PI_2)).clamp(0.0, NT as f32 - 1e-3);
    let fj = (u * NU as f32).clamp(0.0, NU as f32 - 1e-3);
    // `as usize` of a clamped non-negative float (NaN gives 0): always in bounds.
    let (i, j) = (fi as usize, fj as usize);
    let (a, b) = (fi - i as f32, fj - j as f32);
    let (r0, r1) = (&Q[i], &Q[i + 1]);
    let q0 = r0[j] + b * (r0[j + 1] - r0[j]);
    let q1 = r1[j] + b * (r1[j + 1] - r1[j]);
    q0 + a * (q1 - q0)
}

/// The x slope of [`sample_visible_slope_std`] and the number of CDF evaluations it took; `HALLEY`
/// false gives Newton's iteration from Jakob's guess (the alternative the tests compare against). `safety` scales the unverified-step rule ([`HALLEY_SAFETY`]; 0 verifies every step).
#[inline(always)]
fn visible_slope_x<const HALLEY: bool>(
    cot_theta: f32,
    tan_theta: f32,
    theta: f32,
    ux: f32,
    safety: f32,
) -> (f32, u32) {
    let e_cot = exp_neg_sq(cot_theta);
    let c = erf_with_exp_neg_sq(cot_theta, e_cot);
    let k = tan_theta * INV_SQRT_PI;
    let total = 1.0 + c + k * e_cot;
    let ux = ux.clamp(0.0, 1.0);
    let target = ux * total;
    let tol = if HALLEY { 3e-6 } else { 1e-5 } * total;

    let mut b = if HALLEY {
        c - (1.0 + c) * guess_q(theta, ux)
    } else {
        let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
        c - (1.0 + c) * (1.0 - ux).powf(fit)
    };
    let (mut lo, mut hi) = (-1.0f32, c);
    let mut x = 0.0;
    let mut evaluations = 0;
    for _ in 0..12 {
        evaluations += 1;
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        x = erfinv(b);
        let e = exp_neg_sq(x);
        let value = 1.0 + b + k * e - target;
        if value.abs() <= tol {
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        // Halley's step: F' = 1 − x tan θ, F'' = −tan θ (√π/2) e^(x²); multiplied through by
        // e^(−x²) so that one division remains. Where its denominator is not positive (far below
        // the root), Newton's step; the bracket above catches a step that leaves [lo, hi].
        let derivative = 1.0 - x * tan_theta;
        let den = 2.0 * derivative * derivative * e + value * tan_theta * HALF_SQRT_PI;
        b -= if HALLEY && den > 0.0 {
            2.0 * value * derivative * e / den
        } else {
            value / derivative
        };
        // Accept the step unverified if Halley's predicted error after it, |K| e³ |F'| with
        // e = value/F' (the error in b before the step) and
        // K = F'''/(6F') − F''²/(4F'²) = −π tan θ e^(2x²) (x/3 + tan θ/(4F'))/(4F'),
        // is below `safety` × tol; multiplied through by 4 e^(−2x²) F'⁴ (no division).
        let v = value.abs();
        let d2 = derivative * derivative;
        let predicted = core::f32::consts::PI
            * tan_theta
            * (derivative * x * (1.0 / 3.0) + 0.25 * tan_theta).abs()
            * (v * v * v);
        if HALLEY
            && v <= HALLEY_PREDICT_BELOW * total
            && predicted <= 4.0 * (e * e) * (d2 * d2) * (safety * tol)
            && b >= lo
            && b <= hi
        {
            x = erfinv(b);
            break;
        }
    }
    // b can round onto the bracket end erf(cot θ); the slope never exceeds cot θ.
    (x.min(cot_theta), evaluations)
}

/// α_x, α_y validated for an NDF constructor: finite, > 0 and ≤ [`MAX_ALPHA`] (the error names
/// `alpha_x` or `alpha_y`), then clamped to ≥ [`MIN_ALPHA`]. Shared by [`Beckmann`] and [`Ggx`](super::Ggx).
pub(super) fn validated_alphas(alpha_x: f32, alpha_y: f32) -> Result<(f32, f32)> {
    Ok((
        validated_named("alpha_x", alpha_x)?,
        validated_named("alpha_y", alpha_y)?,
    ))
}

/// An isotropic α validated like [`validated_alphas`], the error naming `alpha`.
pub(super) fn validated_alpha(alpha: f32) -> Result<f32> {
    validated_named("alpha", alpha)
}

/// Finite, > 0 and ≤ [`MAX_ALPHA`], then clamped to ≥ [`MIN_ALPHA`].
fn validated_named(name: &'static str, alpha: f32) -> Result<f32> {
    let a = positive(name, alpha)?;
    if a > MAX_ALPHA {
        return Err(crate::Error::InvalidParameter {
            name,
            value: a as f64,
            reason: "must be <= MAX_ALPHA = 1e4",
        });
    }
    Ok(a.max(MIN_ALPHA))
}

/// u clamped to [0, 1]², NaN components to 0 (`f32::max` returns the non-NaN operand).
#[inline(always)]
#[allow(clippy::manual_clamp)] // `clamp` would keep NaN; `max` maps it to 0
pub(super) fn unit_square(u: Vec2) -> Vec2 {
    Vec2::new(u.x.max(0.0).min(1.0), u.y.max(0.0).min(1.0))
}

/// Nudges a sampled normal that rounding left exactly on (or behind) the visibility boundary
/// m·wo = 0 toward wo by 10⁻⁶ rad, so that its pdf is positive. Affects only draws whose u lies
/// within ~10⁻⁶ of the end of the CDF.
#[inline]
pub(super) fn keep_visible(m: Vec3, wo: Vec3) -> Vec3 {
    if m.dot(wo) > 0.0 {
        m
    } else {
        (m + 1e-6 * wo).try_normalize().unwrap_or(Vec3::Z)
    }
}

impl Ndf for Beckmann {
    /// D(m) = exp(−((x/α_x)² + (y/α_y)²)/z²) / (π α_x α_y z⁴); 0 for z ≤ 0 or non-finite m
    /// (and where the numerator underflows, within ~10⁻¹¹ of the horizon).
    ///
    /// Checked last: one division (1/z²), one `exp`, and one comparison that rejects z ≤ 0 and any
    /// non-finite result.
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        let (sx, sy) = (m.x * self.inv_alpha_x, m.y * self.inv_alpha_y);
        let q = 1.0 / (m.z * m.z);
        let d = (-(sx * sx + sy * sy) * q).exp() * (self.norm * q * q);
        if m.z > 0.0 && d <= f32::MAX { d } else { 0.0 }
    }

    /// Exact Smith Λ(w) = (erf(a) − 1)/2 + e^(−a²)/(2a√π), a = 1/(α(φ) tan θ_w), evaluated without
    /// cancellation (see `lambda_of_a`). 0 at normal incidence and below the horizon; finite (capped
    /// at `f32::MAX`) as w approaches the horizon.
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        match self.a_of(w) {
            Some(a) => lambda_of_a(a),
            None => 0.0,
        }
    }

    /// ∫⟨w, m⟩⁺ D dm = cos θ (1 + Λ) = cos θ / G1 (see `visible_area_ratio`): accurate down to
    /// cos θ → 0. 0 below the horizon and where the sum is not finite (NaN
    /// components, or a huge non-unit w); checked once, on the result.
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        let s = self.stretched_sin_sq(w);
        let v = visible_area_zs(w.z, s);
        // `s >= 0` rejects a NaN x or y (which `visible_area_ratio` maps to V = z).
        if w.z > 0.0 && s >= 0.0 && v <= f32::MAX {
            v
        } else {
            0.0
        }
    }

    /// G1(w, m) = χ⁺(w·m) / (1 + Λ(w)), exact to f32 accuracy (see `g1_zs`). 0 below the horizon, for w·m ≤ 0, and where w·m is not finite (a NaN or
    /// infinite component in w or m).
    #[inline]
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        let c = w.dot(m);
        let g = g1_zs(w.z, self.stretched_sin_sq(w));
        if w.z > 0.0 && is_positive_finite(c) {
            g
        } else {
            0.0
        }
    }

    /// D_wo(m) = χ⁺(wo·m) ⟨wo, m⟩ D(m) / V(wo), V = cos θo (1 + Λ(wo)) (see `visible_area_ratio`):
    /// one `exp` (in D), no branch, exact to f32 accuracy. 0 for degenerate input (below-horizon wo or m, wo·m ≤ 0, NaN
    /// or infinite components); checked once, on the result.
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16 (the distribution of visible normals).
    #[inline]
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        let (num, den) = visible_area_ratio(wo.z, self.stretched_sin_sq(wo));
        let p = c * self.d(m) * den / num;
        // wo.z > 0 makes num ≥ wo.z·den/2 > 0 unless something is NaN, which `p <= f32::MAX`
        // rejects (a NaN x or y of wo also makes c NaN).
        if wo.z > 0.0 && c > 0.0 && p <= f32::MAX {
            p
        } else {
            0.0
        }
    }

    /// D(m) / V(wo), V = cos θo (1 + Λ(wo)): [`Ndf::pdf_visible`] without its factor ⟨wo, m⟩,
    /// which the reflection Jacobian cancels (no underflow at grazing views).
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16.
    #[inline]
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        // `visible_over_cos` checks wo (wo.z > 0, wo·m > 0) and the quotient's finiteness.
        let (num, den) = visible_area_ratio(wo.z, self.stretched_sin_sq(wo));
        super::visible_over_cos(wo, m, d_m, num / den)
    }

    /// D(m): [`Ndf::pdf_normal`] = D cos θ_m without its cosine.
    #[inline]
    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        super::normal_over_cos(m, d_m)
    }

    /// Height-correlated G2 = χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi)); 0 for degenerate input.
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        super::masking::g2_height_correlated_checked(self, wo, wi, m)
    }

    /// m ~ D(m) cos θ_m by exact inversion: the slopes are Gaussian, drawn by Box–Muller
    /// (r = √(−ln(1 − u₁)), φ = 2π u₂, ñ = (α_x r cos φ, α_y r sin φ)).
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let r = (-(1.0 - u.x.clamp(0.0, 1.0)).max(f32::MIN_POSITIVE).ln()).sqrt();
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        slope_to_normal(Vec2::new(self.alpha_x * r * c, self.alpha_y * r * s))
    }

    /// m ~ D_wo(m) exactly: stretch wo by (α_x, α_y), draw the standard visible slope
    /// ([`Jakob2014`'s inversion]), rotate it to wo's azimuth, unstretch, convert to a normal.
    /// Below-horizon or non-finite `wo` falls back to [`Ndf::sample_normal`].
    ///
    /// # Reference
    /// \[Heitz2014b\] §4 (stretch/rotate/unstretch), \[Jakob2014\] (1D inversion).
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let Some(a) = self.a_of(wo) else {
            return self.sample_normal(u);
        };
        let stretched = Vec2::new(self.alpha_x * wo.x, self.alpha_y * wo.y);
        let n = stretched.length();
        // (cos φ, sin φ) of the stretched direction; any azimuth at normal incidence.
        let cs = if n > 0.0 { stretched / n } else { Vec2::X };
        let tan_theta = n / wo.z;
        // θ only shapes the initial guess (the iteration corrects it): a 10⁻⁵-rad approximation will do.
        let theta = atan2_pos(n, wo.z);
        let s = sample_visible_slope_std(a, tan_theta, theta, u);
        let rotated = Vec2::new(cs.x * s.x - cs.y * s.y, cs.y * s.x + cs.x * s.y);
        let m = slope_to_normal(Vec2::new(
            self.alpha_x * rotated.x,
            self.alpha_y * rotated.y,
        ));
        keep_visible(m, wo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Λ(a) in f64 from libm's erfc by the direct formula; its cancellation costs at most 8 of f64's
    /// 53 bits for a ≤ 9, far below the f32 error under test.
    fn lambda_f64(a: f64) -> f64 {
        let sp = std::f64::consts::PI.sqrt();
        0.5 * ((-a * a).exp() / (a * sp) - libm::erfc(a))
    }

    #[test]
    fn lambda_of_a_matches_f64() {
        let mut worst = 0.0f64;
        let mut at = 0.0;
        let mut a = 1e-8f64;
        while a < 9.0 {
            let got = lambda_of_a(a as f32) as f64;
            // The f32 input a is itself rounded: compare against Λ at the rounded input.
            let truth_r = lambda_f64(a as f32 as f64);
            let rel = (got - truth_r).abs() / truth_r;
            if rel > worst {
                worst = rel;
                at = a;
            }
            a *= 1.0005;
        }
        println!("lambda_of_a: max relative error {worst:e} at a = {at}");
        // Bound 4·10⁻⁶: ~3 bits of cancellation just below a = 2 on erfc's 5·10⁻⁷ (see
        // lambda_of_a); elsewhere the error is a few f32 roundings.
        assert!(worst < 4e-6, "{worst:e} at {at}");
    }

    /// G1(a) = 1/(1 + Λ(a)) in f64 from libm's erfc (h = e^(−a²) − a√π erfc(a) = 2a√π Λ loses
    /// no digit that matters against the 10⁻⁷ under test for a ≤ 10).
    fn g1_f64(a: f64) -> f64 {
        let sp = std::f64::consts::PI.sqrt();
        let h = (-a * a).exp() - a * sp * libm::erfc(a);
        2.0 * a * sp / (2.0 * a * sp + h)
    }

    #[test]
    fn g1_of_a_error() {
        let (mut worst_g, mut worst_v) = ((0.0f64, 0.0f32), (0.0f64, 0.0f32));
        let n = 400_000;
        // A dense uniform grid over the table (12 500 points per cell) and beyond, then a geometric
        // one toward a → 0, where G1 → 2√π a must stay relative-accurate.
        let uniform = (1..=n).map(|i| (4.0 * i as f64 / n as f64) as f32);
        let small = (0..2000).map(|i| (1e-30f64 * 1.035f64.powi(i)) as f32);
        let mut max_g1 = 0.0f32;
        for a in uniform.chain(small.take_while(|&a| a < 0.2)) {
            let truth = g1_f64(a as f64);
            // G1 from z = a, s = n² = 1 (a = z/n exactly).
            let g = g1_zs(a, 1.0);
            max_g1 = max_g1.max(g);
            let err = (g as f64 / truth - 1.0).abs();
            if err > worst_g.0 {
                worst_g = (err, a);
            }
            // V/n = a/G1 at n = 1, z = a.
            let err = (visible_area_zs(a, 1.0) as f64 * truth / a as f64 - 1.0).abs();
            if err > worst_v.0 {
                worst_v = (err, a);
            }
        }
        println!("g1_zs: max relative error {worst_g:?}; visible_area_zs: {worst_v:?}");
        // Bound 4e-7: the fit's 5.2e-8 plus f32 roundings of 2⁻²⁴ = 6e-8: b = z²/s (two, damped by
        // b E'/E ≤ ½), the last add of each Estrin sum (the others are damped: positive terms),
        // z·Q and n·P, their sum, and the quotient; the f32 a itself is exact here (s = 1).
        assert!(worst_g.0 <= 4e-7, "{worst_g:?}");
        assert!(worst_v.0 <= 4e-7, "{worst_v:?}");
        assert!(max_g1 <= 1.0, "{max_g1}");
        assert_eq!(g1_zs(0.0, 1.0), 0.0);
        assert_eq!(g1_zs(0.5, 0.0), 1.0);
        assert_eq!(visible_area_zs(0.5, 0.0), 0.5);
        // s overflowing to +∞ (a huge non-unit w): G1 → 0, V → +∞, no NaN.
        assert_eq!(g1_zs(0.5, f32::INFINITY), 0.0);
    }

    /// The cut-off of the fit changes no bit: for every f32 a in [3.625, 10) the exact G1
    /// (in f64) rounds to 1.0f, which is what `g1_zs` returns there; Λ decreases beyond.
    #[test]
    fn g1_cutoff_is_exact() {
        let mut a = G1_END;
        while a < 10.0 {
            assert_eq!(g1_f64(a as f64) as f32, 1.0, "a = {a}");
            assert_eq!(g1_zs(a, 1.0), 1.0);
            a = f32::from_bits(a.to_bits() + 1);
        }
    }

    /// Accuracy of the visible-slope inversion: max |F(x) − u| over a grid of θ and u, F the
    /// normalised CDF of the standard visible x slope, F(x) = (1 + erf x + tan θ e^(−x²)/√π) /
    /// (1 + erf(cot θ) + tan θ e^(−cot²θ)/√π), evaluated in f64 from libm (independent of the
    /// crate's f32 erf / erfinv), at the f32 cot θ and tan θ the sampler was given.
    #[test]
    fn visible_slope_inversion_error() {
        let sp = std::f64::consts::PI.sqrt();
        // (max error, θ, u), sum of errors, sum of evaluations: [Newton, Halley].
        let mut worst = [(0.0f64, 0.0f32, 0.0f32); 2];
        let mut sum = [0.0f64; 2];
        let mut evals = [0u64; 2];
        let mut count = 0usize;
        let mut changed = 0usize;
        for i in 0..120 {
            let theta = 0.005f32 + (1.565 - 0.005) * i as f32 / 119.0;
            let (sin, cos) = theta.sin_cos();
            let (cot, tan) = (cos / sin, sin / cos);
            let cdf = |x: f64| 1.0 + libm::erf(x) + tan as f64 * (-x * x).exp() / sp;
            let total = cdf(cot as f64);
            for j in 0..=1000 {
                let u = j as f32 / 1000.0;
                let runs = [
                    visible_slope_x::<false>(cot, tan, theta, u, 0.0),
                    visible_slope_x::<true>(cot, tan, theta, u, HALLEY_SAFETY),
                ];
                // Accepting a Halley step unverified changes no result on this grid (see
                // `HALLEY_SAFETY`): the same slope as when every step is checked by an evaluation.
                let verified = visible_slope_x::<true>(cot, tan, theta, u, 0.0).0;
                if verified.to_bits() != runs[1].0.to_bits() {
                    changed += 1;
                }
                for (k, (x, n)) in runs.into_iter().enumerate() {
                    let err = (cdf(x as f64) / total - u as f64).abs();
                    sum[k] += err;
                    evals[k] += n as u64;
                    if err > worst[k].0 {
                        worst[k] = (err, theta, u);
                    }
                }
                count += 1;
            }
        }
        for (k, name) in ["Newton", "Halley"].iter().enumerate() {
            println!(
                "visible slope inversion ({name}): max |F(x) - u| = {:e} at (theta, u) = ({}, {}); \
                 mean {:e}; mean evaluations {:.3}",
                worst[k].0,
                worst[k].1,
                worst[k].2,
                sum[k] / count as f64,
                evals[k] as f64 / count as f64
            );
        }
        // Newton stopped at |F − u| ≤ 10⁻⁵ in the f32 evaluation of F; the f32 F itself is off by
        // a few 10⁻⁷ (erf, exp and the sum 1 + b + … rounded), and the returned slope is erf⁻¹ of
        // the last iterate (Giles' erfinv, relative 4·10⁻⁷, times the density ≤ 1.2 / total).
        // Measured 1.008e-5 for Newton.
        assert!(worst[0].0 <= 1.2e-5, "{:?}", worst[0]);
        // Halley's method (the one used) must be at least as accurate, in the worst case and on average.
        assert!(
            worst[1].0 <= worst[0].0 * 1.000_001,
            "{:?} vs {:?}",
            worst[1],
            worst[0]
        );
        assert!(sum[1] <= sum[0], "{} vs {}", sum[1], sum[0]);
        assert_eq!(changed, 0, "slopes changed by HALLEY_SAFETY");
    }

    /// Every node of the guess table is the root it claims to be: recomputed here in f64 from
    /// libm (bisection on x, independent of the generating script's Python) to f32 rounding.
    #[test]
    fn guess_table_is_the_root() {
        use beckmann_guess::{NT, NU, Q, THETA_MAX};
        let sp = std::f64::consts::PI.sqrt();
        for (i, row) in Q.iter().enumerate() {
            let theta = (i as f64 / NT as f64 * std::f64::consts::FRAC_PI_2).min(THETA_MAX);
            let (sin, cos) = theta.sin_cos();
            let cot = if sin > 0.0 {
                (cos / sin).min(10.0)
            } else {
                10.0
            };
            let k = sin / cos / sp;
            let cdf = |x: f64| 1.0 + libm::erf(x) + k * (-x * x).exp();
            let top = libm::erf(cot);
            for (j, &q) in row.iter().enumerate() {
                let target = j as f64 / NU as f64 * cdf(cot);
                let (mut lo, mut hi) = (-10.0f64, cot);
                for _ in 0..100 {
                    let mid = 0.5 * (lo + hi);
                    if cdf(mid) < target {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let truth = ((top - libm::erf(0.5 * (lo + hi))) / (1.0 + top)).clamp(0.0, 1.0);
                assert!(
                    (q as f64 - truth).abs() <= 1e-7,
                    "({i}, {j}): {q} vs {truth}"
                );
            }
        }
    }

    #[test]
    fn continued_fraction_coefficients() {
        // Re-derive the polynomial coefficients of the 16th convergent from the recurrence in f64
        // and compare with the literals above (a typo there would otherwise hide inside the
        // truncation error).
        let mut a_prev = vec![1.0f64]; // A_{-1} = 1, coefficients in powers of a
        let mut a_cur = vec![0.0f64]; // A_0 = 0
        let mut b_prev = vec![0.0f64];
        let mut b_cur = vec![1.0f64];
        for n in 1..=16 {
            let k = n as f64 / 2.0;
            let step = |cur: &Vec<f64>, prev: &Vec<f64>| {
                let mut out = vec![0.0; cur.len().max(prev.len()) + 1];
                for (i, c) in cur.iter().enumerate() {
                    out[i + 1] += c;
                }
                for (i, c) in prev.iter().enumerate() {
                    out[i] += k * c;
                }
                out
            };
            let a_new = step(&a_cur, &a_prev);
            let b_new = step(&b_cur, &b_prev);
            a_prev = std::mem::replace(&mut a_cur, a_new);
            b_prev = std::mem::replace(&mut b_cur, b_new);
        }
        // A_16 = a·P(a²): odd coefficients of A; B_16 = Q(a²): even coefficients of B.
        let p: Vec<f64> = a_cur.iter().skip(1).step_by(2).copied().collect();
        let q: Vec<f64> = b_cur.iter().step_by(2).copied().collect();
        assert_eq!(p.len(), CF_P.len());
        assert_eq!(q.len(), CF_Q.len());
        // The literals are the exact dyadic values rounded to f32: relative 2⁻²⁴.
        for (exact, lit) in p.iter().zip(CF_P).chain(q.iter().zip(CF_Q)) {
            assert!(
                (lit as f64 - exact).abs() <= 6e-8 * exact,
                "{lit} vs {exact}"
            );
        }
    }
}
