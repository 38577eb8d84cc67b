//! The anisotropic Beckmann NDF (Gaussian slopes) with its exact Smith Λ and exact samplers.
//!
//! Slopes ñ of the micronormals are Gaussian with per-axis standard deviation α/√2. D and Λ follow
//! Walter et al. 2007 and Heitz 2014 (the anisotropic form through α(φ)); the visible-normal sampler
//! is the stretch / sample / rotate / unstretch routine of Heitz & d'Eon 2014 with the 1D visible
//! slope inversion of Jakob 2014 (Newton in the erf domain, safeguarded by bisection).

use super::Ndf;
use crate::Result;
use crate::error::positive;
use crate::frame::slope_to_normal;
use crate::math::{INV_SQRT_PI, atan2_pos, erf, erfcx_small, erfinv, exp_neg_sq};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

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

    /// n = α(φ) sin θ = |(α_x x, α_y y)| for w = (x, y, z), unchecked (callers test the result).
    #[inline(always)]
    fn stretched_sin(&self, w: Vec3) -> f32 {
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        (x * x + y * y).sqrt()
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

/// End of the tabulated range of [`a_lambda`]: from a = 29/8 = 3.625 on, k(a) is taken as 0, so that
/// G1 = 1 and V = cos θ exactly. The exact G1 rounds to 1.0 in f32 there (for every f32 a in
/// [3.625, 10), checked in `tests::g1_cutoff_is_exact`; beyond, Λ only decreases).
const G1_END: f32 = 3.625;
/// Cells per unit of a in [`K_TABLE`] (a power of two, so that 8a and its fractional part are exact).
const K_SCALE: f32 = 8.0;
/// Number of polynomial cells of [`K_TABLE`] before its final all-zero row: 29 = 3.625 · 8.
const K_CELLS: u32 = 29;

/// k(a) = a Λ(a) = (e^(−a²) − a√π erfc(a)) / (2√π), a = 1/(α(φ) tan θ) ≥ 0, from a table of degree-4
/// polynomials on the 29 cells [i/8, (i+1)/8) of [0, 3.625), and 0 from 3.625 on.
///
/// k is entire (no pole near a = 0, unlike G1 or G1/a, whose pole at a ≈ −0.56 is what forced a
/// degree-(6, 6) rational fit before), decreasing from 1/(2√π) to ~2·10⁻⁸ over the range, so low-degree
/// pieces on a uniform grid reach f32 accuracy: with t = 8a − i ∈ [0, 1) (exact), one row load and
/// four multiply-adds (Horner). The coefficients are each cell's Chebyshev interpolant rounded to f32,
/// generated by `tools/beckmann_lambda_table.py` (mpmath, 40 digits): error ≤ 5.2·10⁻⁸ relative to
/// a + k(a) in exact arithmetic (measured against f64 in `tests::g1_of_a_error`).
///
/// The callers use G1 = a/(a + k) = z/(z + n k) and V = cos θ (1 + Λ) = z + n k with z = cos θ,
/// n = α(φ) sin θ, a = z/n: one division each, no `exp`, no branch; the sums add positive terms (no cancellation).
///
/// NaN and a ≥ 3.625 (including +∞ at normal incidence) select the zero row; a < 0 is treated as 0
/// (callers discard below-horizon results). Never NaN or infinite.
///
/// # Reference
/// \[Walter2007\] §5.1 and \[Heitz2014\] eq. 72 (Λ of the Beckmann distribution); the table is ours.
#[inline(always)]
fn a_lambda(a: f32) -> f32 {
    // `a < G1_END` is false for NaN: the zero row.
    let u = if a < G1_END { a * K_SCALE } else { K_CELLS as f32 };
    let u = if u > 0.0 { u } else { 0.0 };
    // u ∈ [0, 29]: the conversion is exact (truncation), the `min` only proves the index in range.
    let i = (u as u32).min(K_CELLS);
    let t = u - i as f32;
    let [c0, c1, c2, c3, c4] = K_TABLE[i as usize];
    c0 + t * (c1 + t * (c2 + t * (c3 + t * c4)))
}

/// Rows [k(i/8 + t/8) ≈ c₀ + c₁t + c₂t² + c₃t³ + c₄t⁴] of [`a_lambda`], generated by
/// `python3 tools/beckmann_lambda_table.py` (its output pasted verbatim; per-row error in the comments,
/// relative to a + k(a), f32-rounded coefficients in exact arithmetic).
#[allow(clippy::excessive_precision, clippy::approx_constant)]
#[rustfmt::skip]
const K_TABLE: [[f32; 5]; 30] = [
    [0.282094806432724, -0.0625000074505806, 0.00440779747441411, -1.6724060003525665e-07, -1.1333406291669235e-05], // [0/8, 1/8): 5.2e-8
    [0.22399108111858368, -0.05373026430606842, 0.004339618142694235, -4.580974200507626e-05, -1.0293426385032944e-05], // [1/8, 2/8): 4.4e-9
    [0.1745443344116211, -0.04522964358329773, 0.004141025710850954, -8.72209420776926e-05, -8.370891919184942e-06], // [2/8, 3/8): 7.8e-9
    [0.1333601176738739, -0.037242744117975235, 0.0038299220614135265, -0.00012083966430509463, -5.8476266531215515e-06], // [3/8, 4/8): 1.4e-8
    [0.09982061386108398, -0.029968811199069023, 0.0034331802744418383, -0.0001442523644072935, -3.07263144350145e-06], // [4/8, 5/8): 4.0e-9
    [0.07313766330480576, -0.023547494783997536, 0.0029828206170350313, -0.00015646211977582425, -3.9542797480862646e-07], // [5/8, 6/8): 5.3e-9
    [0.052416130900382996, -0.018052812665700912, 0.0025117748882621527, -0.00015788638847880065, 1.8938764014819753e-06], // [6/8, 7/8): 1.7e-9
    [0.036719102412462234, -0.013495337218046188, 0.0020500128157436848, -0.00015011180948931724, 3.6050380458618747e-06], // [7/8, 8/8): 2.1e-9
    [0.025127271190285683, -0.009831216186285019, 0.0016216384246945381, -0.0001354864944005385, 4.662399533117423e-06], // [8/8, 9/8): 5.5e-10
    [0.01678686961531639, -0.006975739262998104, 0.00124328990932554, -0.00011665478814393282, 5.094988409837242e-06], // [9/8, 10/8): 4.2e-10
    [0.010942860506474972, -0.0048187365755438805, 0.0009238703059963882, -9.613446309231222e-05, 5.008902917325031e-06], // [10/8, 11/8): 2.1e-10
    [0.006956868339329958, -0.0032393592409789562, 0.0006653792806901038, -7.600754906889051e-05, 4.551729489321588e-06], // [11/8, 12/8): 2.6e-10
    [0.004311431664973497, -0.002118414267897606, 0.0004644581931643188, -5.775600584456697e-05, 3.878389634337509e-06], // [12/8, 13/8): 3.7e-10
    [0.002603597706183791, -0.0013472518185153604, 0.0003142263158224523, -4.2235671571688727e-05, 3.1251063319359673e-06], // [13/8, 14/8): 1.9e-10
    [0.0015314610209316015, -0.0008330068085342646, 0.00020604235760401934, -2.9754581191809848e-05, 2.3944683107401943e-06], // [14/8, 15/8): 1.6e-10
    [0.0008771359571255744, -0.0005006097489967942, 0.0001309447397943586, -2.021053842327092e-05, 1.7511720216134563e-06], // [15/8, 16/8): 1.3e-10
    [0.0004890111740678549, -0.0002923491701949388, 8.06560055934824e-05, -1.3244631190900691e-05, 1.2257644357305253e-06], // [16/8, 17/8): 9.3e-11
    [0.00026529881870374084, -0.0001658699184190482, 4.8150646762223914e-05, -8.378686288779136e-06, 8.228602155213594e-07], // [17/8, 18/8): 6.6e-11
    [0.00014002349053043872, -9.141487680608407e-05, 2.7860174668603577e-05, -5.118962690175977e-06, 5.305952299750061e-07], // [18/8, 19/8): 4.7e-11
    [7.188026211224496e-05, -4.893032746622339e-05, 1.562361285323277e-05, -3.0214966955099953e-06, 3.2904191016314144e-07], // [19/8, 20/8): 2.9e-11
    [3.58809920726344e-05, -2.5432365873712115e-05, 8.491702828905545e-06, -1.7235963696293766e-06, 1.9643404414182442e-07], // [20/8, 21/8): 1.7e-11
    [1.741310188663192e-05, -1.2834666449634824e-05, 4.473251919989707e-06, -9.504760782874655e-07, 1.1298168800522035e-07], // [21/8, 22/8): 1.0e-11
    [8.214153240260202e-06, -6.288090389716672e-06, 2.2838466975372285e-06, -5.068056339041505e-07, 6.264886565077177e-08], // [22/8, 23/8): 5.7e-12
    [3.76572984350787e-06, -2.990484290421591e-06, 1.1301218592052464e-06, -2.6135165853702347e-07, 3.350992727746416e-08], // [23/8, 24/8): 3.1e-12
    [1.6775126141510555e-06, -1.3804140053252922e-06, 5.41998474545835e-07, -1.303677805708503e-07, 1.729789467219689e-08], // [24/8, 25/8): 1.6e-12
    [7.260204029080342e-07, -6.184185963320488e-07, 2.5193304509230074e-07, -6.291364229582541e-08, 8.62079474472921e-09], // [25/8, 26/8): 8.2e-13
    [3.052384442980838e-07, -2.688592530830647e-07, 1.1349747808253596e-07, -2.9377117627404914e-08, 4.149409260634229e-09], // [26/8, 27/8): 3.9e-13
    [1.246471583726816e-07, -1.1342364558686313e-07, 4.955655796834435e-08, -1.3274463306345297e-08, 1.9294841280270703e-09], // [27/8, 28/8): 1.9e-13
    [4.9434248694524285e-08, -4.642885542693875e-08, 2.097151075020065e-08, -5.8051847773299414e-09, 8.670153484047205e-10], // [28/8, 29/8): 8.4e-14
    [0.0, 0.0, 0.0, 0.0, 0.0], // a >= 29/8: k = 0
];

/// Smith G1 = 1/(1 + Λ) of the Beckmann NDF from z = cos θ and n = α(φ) sin θ: z/(z + n k(z/n))
/// (see [`a_lambda`]). Relative error ≤ 4·10⁻⁷ against f64 (table 5.2·10⁻⁸ plus f32 roundings,
/// `tests::g1_of_a_error`); exactly 1 at normal incidence (n = 0) and for z/n ≥ 3.625; 0 at z = 0.
/// Only ≤ 1 is guaranteed for degenerate input (callers reject z ≤ 0 and NaN).
///
/// # Reference
/// \[Walter2007\] §5.1 (Beckmann G1), \[Heitz2014\] eq. 72 (Λ).
#[inline(always)]
fn g1_zn(z: f32, n: f32) -> f32 {
    z / visible_area_zn(z, n)
}

/// The visible projected area V = cos θ (1 + Λ) = ∫⟨w, m⟩⁺ D dm = cos θ / G1 from z = cos θ and
/// n = α(φ) sin θ: z + n k(z/n) (see [`a_lambda`]); accurate down to z → 0, where V → n/(2√π).
/// z at normal incidence (n = 0) and for z/n ≥ 3.625. One division (z/n), no `exp`.
///
/// # Reference
/// \[Heitz2014\] eq. 17 and §5.1 (the projected area of the visible microfacets).
#[inline(always)]
fn visible_area_zn(z: f32, n: f32) -> f32 {
    z + n * a_lambda(z / n)
}

/// Draws the standard (α = 1) visible slope for a direction at polar angle θ in the xz-plane
/// (φ = 0), given cot θ and tan θ.
///
/// The x slope has density ∝ e^(−x²)(1 − x tan θ) on x < cot θ, whose CDF in b = erf(x) is
/// F(b) ∝ 1 + b + tan θ e^(−x²)/√π. F is inverted by Newton's method in b (F'(b) ∝ 1 − x tan θ),
/// safeguarded by bisection on [−1, erf(cot θ)], starting from Jakob's fitted guess
/// b₀ = c − (1 + c)(1 − u)^(1 + θ(−0.876 + θ(0.4265 − 0.0594θ))). It stops when the CDF error is
/// below 10⁻⁵ (after at most 12 steps): a displacement of at most 10⁻⁵ of the probability mass,
/// below the f32 noise of the CDF's evaluation at grazing angles and far below what a 10⁶-sample
/// chi-square test resolves. The y slope is Gaussian and independent: erf⁻¹(2u₂ − 1).
///
/// # Reference
/// \[Jakob2014\] (inversion and initial guess), \[Heitz2014b\] §4 (the visible slope distribution).
fn sample_visible_slope_std(cot_theta: f32, tan_theta: f32, theta: f32, u: Vec2) -> Vec2 {
    let c = erf(cot_theta);
    let k = tan_theta * INV_SQRT_PI;
    let total = 1.0 + c + k * exp_neg_sq(cot_theta);
    let ux = u.x.clamp(0.0, 1.0);
    let target = ux * total;
    let tol = 1e-5 * total;

    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let mut b = c - (1.0 + c) * (1.0 - ux).powf(fit);
    let (mut lo, mut hi) = (-1.0f32, c);
    let mut x = 0.0;
    for _ in 0..12 {
        if !(b >= lo && b <= hi) {
            b = 0.5 * (lo + hi);
        }
        x = erfinv(b);
        let value = 1.0 + b + k * exp_neg_sq(x) - target;
        if value.abs() <= tol {
            break;
        }
        if value > 0.0 {
            hi = b;
        } else {
            lo = b;
        }
        let derivative = 1.0 - x * tan_theta;
        b -= value / derivative;
    }
    // b can round onto the bracket end erf(cot θ); the slope never exceeds cot θ.
    let x = x.min(cot_theta);
    Vec2::new(x, erfinv(2.0 * u.y.clamp(0.0, 1.0) - 1.0))
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

    /// ∫⟨w, m⟩⁺ D dm = cos θ (1 + Λ) = cos θ / G1 (see `visible_area_zn`): accurate down to
    /// cos θ → 0. 0 below the horizon and where the sum is not finite (NaN
    /// components, or a huge non-unit w); checked once, on the result.
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        let n = self.stretched_sin(w);
        let v = visible_area_zn(w.z, n);
        // `n >= 0` rejects a NaN x or y (which `visible_area_zn` maps to V = z).
        if w.z > 0.0 && n >= 0.0 && v <= f32::MAX {
            v
        } else {
            0.0
        }
    }

    /// G1(w, m) = χ⁺(w·m) / (1 + Λ(w)), exact to f32 accuracy (see `g1_zn`). 0 below the horizon, for w·m ≤ 0, and where w·m is not finite (a NaN or
    /// infinite component in w or m).
    #[inline]
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        let c = w.dot(m);
        let g = g1_zn(w.z, self.stretched_sin(w));
        if w.z > 0.0 && c > 0.0 && c <= f32::MAX {
            g
        } else {
            0.0
        }
    }

    /// D_wo(m) = χ⁺(wo·m) ⟨wo, m⟩ D(m) / V(wo), V = cos θo (1 + Λ(wo)) (see `visible_area_zn`):
    /// one `exp` (in D), no branch, exact to f32 accuracy. 0 for degenerate input (below-horizon wo or m, wo·m ≤ 0, NaN
    /// or infinite components); checked once, on the result.
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16 (the distribution of visible normals).
    #[inline]
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        let v = visible_area_zn(wo.z, self.stretched_sin(wo));
        let p = c * self.d(m) / v;
        // wo.z > 0 makes v ≥ wo.z > 0 unless something is NaN, which `p <= f32::MAX` rejects.
        if wo.z > 0.0 && c > 0.0 && p <= f32::MAX {
            p
        } else {
            0.0
        }
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
        // θ only shapes the initial guess (Newton corrects it): a 10⁻⁵-rad approximation will do.
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
            // G1 from z = a, n = 1 (a = z/n exactly).
            let g = g1_zn(a, 1.0);
            max_g1 = max_g1.max(g);
            let err = (g as f64 / truth - 1.0).abs();
            if err > worst_g.0 {
                worst_g = (err, a);
            }
            // V/n = a/G1 at n = 1, z = a.
            let err = (visible_area_zn(a, 1.0) as f64 * truth / a as f64 - 1.0).abs();
            if err > worst_v.0 {
                worst_v = (err, a);
            }
        }
        println!("g1_zn: max relative error {worst_g:?}; visible_area_zn: {worst_v:?}");
        // Bound 4e-7: the table's 5.2e-8 (relative to a + k) plus f32 roundings of 2⁻²⁴ = 6e-8 on
        // the path to the result: Horner's last add (the earlier ones are damped by t|c₁|/c₀ < 0.3),
        // n·k, z + n·k, the division; ~4 roundings, 2.4e-7, plus the table's 5.2e-8.
        assert!(worst_g.0 <= 4e-7, "{worst_g:?}");
        assert!(worst_v.0 <= 4e-7, "{worst_v:?}");
        assert!(max_g1 <= 1.0, "{max_g1}");
        assert_eq!(g1_zn(0.0, 1.0), 0.0);
        assert_eq!(g1_zn(0.5, 0.0), 1.0);
        assert_eq!(visible_area_zn(0.5, 0.0), 0.5);
        // Degenerate arguments stay finite (the callers' checks then reject them).
        for (z, n) in [(-0.5, 1.0), (0.5, f32::NAN), (f32::NAN, 1.0), (0.0, 0.0), (0.5, f32::MAX)] {
            assert!(!a_lambda(z / n).is_nan() && a_lambda(z / n).is_finite(), "{z} {n}");
        }
    }

    /// The cut-off of the table changes no bit: for every f32 a in [3.625, 10) the exact G1
    /// (in f64) rounds to 1.0f, which is what `g1_zn` returns there; Λ decreases beyond.
    #[test]
    fn g1_cutoff_is_exact() {
        let mut a = G1_END;
        while a < 10.0 {
            assert_eq!(g1_f64(a as f64) as f32, 1.0, "a = {a}");
            assert_eq!(g1_zn(a, 1.0), 1.0);
            a = f32::from_bits(a.to_bits() + 1);
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
