//! Standard-normal special functions in `f64` for the slope-Gaussian lobe: pdf, cdf, the ramp
//! G(z) = E[(z − Z)⁺], Mills' ratio by continued fraction, the inverse cdf, and the inversion sampler
//! of the tilted density ∝ (a − x)⁺ φ(x).
//!
//! Everything here is total on finite input and stays accurate far into the tails: the tail forms
//! are written with Mills' ratio so that nothing underflows to 0/0 where the answer is representable.
//! Accuracy targets are ~1e-13 relative (far below what the `f32` public API needs); each routine
//! says where it is worse.

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::f64::consts::{FRAC_1_SQRT_2, PI};

/// 1/√(2π).
const INV_SQRT_2PI: f64 = 0.398_942_280_401_432_7;
/// ln √(2π).
const LN_SQRT_2PI: f64 = 0.918_938_533_204_672_8;

/// Above this argument, [`ramp_neg`] and the scaled tails use the continued fraction of Mills' ratio
/// instead of φ − t Q (whose cancellation costs a factor ~1 + t² in relative accuracy: ≤ 26 here).
pub(crate) const T_CF: f64 = 5.0;

/// φ(x) = exp(−x²/2)/√(2π).
#[inline]
pub(crate) fn std_pdf(x: f64) -> f64 {
    INV_SQRT_2PI * (-0.5 * x * x).exp()
}

/// Φ(x) = P(Z ≤ x) = erfc(−x/√2)/2 (accurate in the lower tail; 1 − Φ is [`std_cdf`] of −x).
#[inline]
pub(crate) fn std_cdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x * FRAC_1_SQRT_2)
}

/// Mills' ratio R(t) = Q(t)/φ(t) and the tail ε(t) of its continued fraction, for t ≥ [`T_CF`].
///
/// R(t) = 1/(t + 1/(t + 2/(t + 3/(t + …)))) (Laplace's continued fraction), evaluated backwards
/// from a depth chosen by t so that both values are within ~3e-14 relative (checked against 40-digit
/// arithmetic: depth 20 at t = 5 → 2.8e-14; 14 at 7 → 1.3e-14; 10 at 10 → 1.2e-14; 6 at 20 → 2.1e-14).
/// ε(t) = 1/(t + 2/(t + 3/(t + …))) is the part after the first partial denominator, so that
/// 1 − t R(t) = ε(t) R(t) exactly (no cancellation).
///
/// # Reference
/// \[AbramowitzStegun1964\] 26.2.14.
#[inline]
pub(crate) fn mills_cf(t: f64) -> (f64, f64) {
    let depth = if t < 7.0 {
        20
    } else if t < 10.0 {
        14
    } else if t < 20.0 {
        10
    } else {
        6
    };
    // T_k = t + (k + 1)/T_{k+1}, started at T_{depth+1} = t.
    let mut tk = t;
    for k in (1..=depth).rev() {
        tk = t + (k + 1) as f64 / tk;
    }
    let t0 = t + 1.0 / tk;
    (1.0 / t0, 1.0 / tk)
}

/// G(−t) = E[(−t − Z)⁺] = φ(t) − t Q(t) for t ≥ 0 (Q = 1 − Φ), without cancellation.
///
/// For t ≤ [`T_CF`] the direct form (relative error ≲ (t²/2)(1 + t²)·4e-16 ≤ 1.5e-13: rounding of
/// the exponent's argument amplified by the cancellation); beyond, φ(t) R(t) ε(t) (≲ 3e-14 + the
/// argument rounding (t²/2)·2.2e-16 that any evaluation of φ(t) has).
/// Underflows to 0 only when the value is below ~1e-308 (t ≳ 37).
#[inline]
pub(crate) fn ramp_neg(t: f64) -> f64 {
    if t <= T_CF {
        std_pdf(t) - t * 0.5 * libm::erfc(t * FRAC_1_SQRT_2)
    } else {
        let p = std_pdf(t);
        if p == 0.0 {
            return 0.0;
        }
        let (r, e) = mills_cf(t);
        p * r * e
    }
}

/// ln N(x; y) and φ(x)/N(x; y), where N(x; y) = G(x) + y Φ(x) = ∫_{−∞}^x (x + y − s) φ(s) ds, y ≥ 0.
///
/// N(x; a − x) is the unnormalised cdf of the tilted density ∝ (a − s)⁺ φ(s) at x, and N(a; 0) = G(a)
/// its total mass. For x < −[`T_CF`] both are formed from Mills' ratio at τ = −x:
/// N = φ(x) R(τ) (ε(τ) + y), so neither underflows for any finite x.
#[inline]
pub(crate) fn ln_partial(x: f64, y: f64) -> (f64, f64) {
    if x >= -T_CF {
        // (x + y) Φ(x) + φ(x): one erfc and one exp. For x + y = a ≥ 0 both terms are ≥ 0; for
        // −T_CF ≤ a < 0 the cancellation costs the factor documented in `ramp_neg`.
        let p = std_pdf(x);
        let n = (x + y) * std_cdf(x) + p;
        (n.ln(), p / n)
    } else {
        let (r, e) = mills_cf(-x);
        let k = r * (e + y);
        (-0.5 * x * x - LN_SQRT_2PI + k.ln(), 1.0 / k)
    }
}

/// ln G(z) for any finite z (finite even where G(z) underflows).
#[inline]
pub(crate) fn ln_ramp(z: f64) -> f64 {
    ln_partial(z, 0.0).0
}

/// Φ⁻¹(p), the standard-normal quantile, for p ∈ (0, 1); ±∞ at 0 and 1, NaN outside.
///
/// Wichura's rational approximations (Algorithm AS 241, PPND16), relative error ~1e-16.
///
/// # Reference
/// \[Wichura1988\] (AS 241, PPND16).
// The coefficients are quoted with the digits Wichura published (more than f64 holds).
#[allow(clippy::excessive_precision)]
pub(crate) fn inv_std_cdf(p: f64) -> f64 {
    fn poly(c: &[f64; 8], x: f64) -> f64 {
        c.iter().rev().fold(0.0, |acc, &ci| acc * x + ci)
    }
    const A: [f64; 8] = [
        3.387_132_872_796_366_608,
        1.331_416_678_917_843_774_5e2,
        1.971_590_950_306_551_442_7e3,
        1.373_169_376_550_946_112_5e4,
        4.592_195_393_154_987_145_7e4,
        6.726_577_092_700_870_085_3e4,
        3.343_057_558_358_812_810_5e4,
        2.509_080_928_730_122_672_7e3,
    ];
    const B: [f64; 8] = [
        1.0,
        4.231_333_070_160_091_125_2e1,
        6.871_870_074_920_579_083e2,
        5.394_196_021_424_751_107_7e3,
        2.121_379_430_158_659_586_7e4,
        3.930_789_580_009_271_061e4,
        2.872_908_573_572_194_267_4e4,
        5.226_495_278_852_854_561e3,
    ];
    const C: [f64; 8] = [
        1.423_437_110_749_683_577_34,
        4.630_337_846_156_545_295_9,
        5.769_497_221_460_691_405_5,
        3.647_848_324_763_204_605_04,
        1.270_458_252_452_368_382_58,
        2.417_807_251_774_506_117_7e-1,
        2.272_384_498_926_918_458_33e-2,
        7.745_450_142_783_414_076_4e-4,
    ];
    const D: [f64; 8] = [
        1.0,
        2.053_191_626_637_758_821_87,
        1.676_384_830_183_803_849_4,
        6.897_673_349_851_000_045_5e-1,
        1.481_039_764_274_800_745_9e-1,
        1.519_866_656_361_645_719_66e-2,
        5.475_938_084_995_344_946e-4,
        1.050_750_071_644_416_843_24e-9,
    ];
    const E: [f64; 8] = [
        6.657_904_643_501_103_777_2,
        5.463_784_911_164_114_369_9,
        1.784_826_539_917_291_335_8,
        2.965_605_718_285_048_912_3e-1,
        2.653_218_952_657_612_309_3e-2,
        1.242_660_947_388_078_438_6e-3,
        2.711_555_568_743_487_578_15e-5,
        2.010_334_399_292_288_132_65e-7,
    ];
    const F: [f64; 8] = [
        1.0,
        5.998_322_065_558_879_376_9e-1,
        1.369_298_809_227_358_053_1e-1,
        1.487_536_129_085_061_485_25e-2,
        7.868_691_311_456_132_591e-4,
        1.846_318_317_510_054_681_8e-5,
        1.421_511_758_316_445_888_7e-7,
        2.044_263_103_389_939_785_64e-15,
    ];
    if p.is_nan() || !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180_625 - q * q;
        return q * poly(&A, r) / poly(&B, r);
    }
    let tail = if q < 0.0 { p } else { 1.0 - p };
    if tail <= 0.0 {
        return if q < 0.0 {
            f64::NEG_INFINITY
        } else {
            f64::INFINITY
        };
    }
    let r = (-tail.ln()).sqrt();
    let x = if r <= 5.0 {
        let r = r - 1.6;
        poly(&C, r) / poly(&D, r)
    } else {
        let r = r - 5.0;
        poly(&E, r) / poly(&F, r)
    };
    if q < 0.0 { -x } else { x }
}

/// Φ⁻¹(p) in `f32` for p ∈ (0, 1): Wichura's lower-precision rational approximations (Algorithm
/// AS 241, PPND7: degree 3/3 in the centre, one `ln` and one `sqrt` in the tails), within ~10⁻⁷ of
/// Φ⁻¹ relative (checked against [`inv_std_cdf`] in the tests); ±∞ at 0 and 1, NaN outside.
///
/// # Reference
/// \[Wichura1988\] (AS 241, PPND7).
#[cfg(feature = "std")]
#[allow(clippy::excessive_precision)]
pub(crate) fn inv_std_cdf_f32(p: f32) -> f32 {
    if p.is_nan() || !(0.0..=1.0).contains(&p) {
        return f32::NAN;
    }
    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180_625 - q * q;
        let num =
            ((59.109_374_720 * r + 159.291_132_02) * r + 50.434_271_938) * r + 3.387_132_717_9;
        let den = ((67.187_563_600 * r + 78.757_757_664) * r + 17.895_169_469) * r + 1.0;
        return q * num / den;
    }
    let tail = if q < 0.0 { p } else { 1.0 - p };
    if tail <= 0.0 {
        return if q < 0.0 {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        };
    }
    let r = (-libm::logf(tail)).sqrt();
    let x = if r <= 5.0 {
        let r = r - 1.6;
        (((0.170_238_211_03 * r + 1.306_728_481_6) * r + 2.756_815_390_0) * r + 1.423_437_277_7)
            / ((0.120_211_329_75 * r + 0.737_001_642_50) * r + 1.0)
    } else {
        let r = r - 5.0;
        (((0.017_337_203_997 * r + 0.428_682_943_37) * r + 3.081_226_386_0) * r + 6.657_905_115_0)
            / ((0.012_258_202_635 * r + 0.241_978_942_25) * r + 1.0)
    };
    if q < 0.0 { -x } else { x }
}

/// Beyond this `a`, [`sample_ramp`] returns Φ⁻¹(u): the tilted cdf differs from Φ by at most
/// φ(0)/a ≈ 4e-9 there.
const A_GAUSS: f64 = 1e8;
/// Iterations are capped here (never reached in the tests: see `sample_ramp_iterations`).
const MAX_NEWTON: usize = 64;

/// Inverts the cdf of the tilted normal density p(x) ∝ (a − x)⁺ φ(x): returns x ≤ a with
/// F(x) = u, F(x) = (a Φ(x) + φ(x)) / (a Φ(a) + φ(a)).
///
/// `u` must lie in (0, 1) and `a` be finite (callers clamp). Root finding on ln F (for a ≥ 0, in x)
/// or on ln S(y) = ln F(a − y) (for a < 0, in y = a − x ≥ 0). Both are concave and monotone because
/// the density is log-concave, so Newton's method converges monotonically from either side after
/// at most one overshoot; Halley's correction (f″ = −r (1 + x y + y² r) with r = φ(x)/N) is used
/// when it is small, which brings the mean count to ~3-4 steps (see the unit test
/// `sample_ramp_iterations`). Starting points:
/// - a ≥ 0: near the edge (y_edge (1 + a) < 0.3) x₀ = a − y_edge with y_edge = √(2 (1 − u) G(a)/φ(a)),
///   the leading-order root of 1 − F ≈ (a − x)² φ(a) / (2 G(a)); elsewhere the smaller of the
///   truncated-normal quantile Φ⁻¹(u Φ(a)) (X is stochastically smaller) and a − √(−2 ln u) (a − X is
///   stochastically larger than Rayleigh(1): the density ratio e^{a y − a²/2} grows with y); both
///   lie right of the root, and the second is exact at a = 0;
/// - a < 0: with t = −a, y has density ∝ y e^{−t y − y²/2}, stochastically smaller than Gamma(2, t)
///   and than Rayleigh(1); y₀ = the smaller of their quantiles (Gamma by two fixed-point steps of
///   w = −ln u + ln(1 + w)), or y_edge near the edge (y_edge (1 + t) < 0.3).
///
/// All cdf values are formed by [`ln_partial`], finite for every finite x, so any real `a` works
/// (grazing views of lobes tilted away give a ≪ 0; near-normal views give a ≫ 0).
pub(crate) fn sample_ramp(a: f64, u: f64) -> f64 {
    sample_ramp_counted(a, u).0
}

/// [`sample_ramp`] and the number of Newton steps it took (for tests and docs).
pub(crate) fn sample_ramp_counted(a: f64, u: f64) -> (f64, usize) {
    if a > A_GAUSS {
        return (inv_std_cdf(u).min(a), 0);
    }
    let ln_u = u.ln();
    // ln G(a), G(a)/φ(a) (for the edge guess) and Φ(a), sharing one erfc and one exp.
    let (ln_h, g_over_phi, cdf_a) = if a >= -T_CF {
        let (p, c) = (std_pdf(a), std_cdf(a));
        let h = a * c + p;
        (h.ln(), h / p, c)
    } else {
        let (r, e) = mills_cf(-a);
        let k = r * e;
        (-0.5 * a * a - LN_SQRT_2PI + k.ln(), k, 0.0)
    };
    // Edge guess: 1 − F ≈ y² φ(a) / (2 G(a)).
    let y_edge = (2.0 * (1.0 - u) * g_over_phi).sqrt();
    let mut steps = 0;
    if a >= 0.0 {
        let mut x = if y_edge * (1.0 + a) < 0.3 {
            a - y_edge
        } else {
            // Both bounds lie right of the root: take the tighter (exact at a = 0).
            inv_std_cdf(u * cdf_a).min(a - (-2.0 * ln_u).sqrt())
        };
        if x.partial_cmp(&a) != Some(core::cmp::Ordering::Less) {
            x = a - y_edge.max(f64::EPSILON * (1.0 + a));
        }
        let mut last = f64::INFINITY;
        while steps < MAX_NEWTON {
            steps += 1;
            let y = a - x;
            let (ln_n, r) = ln_partial(x, y);
            let f = ln_n - ln_h - ln_u;
            let (step, tol) = halley_step(f, y * r, -r * (1.0 + x * y + y * y * r));
            if !step.is_finite() {
                break;
            }
            let next = (x - step).min(a);
            let delta = (next - x).abs();
            let done = delta <= tol * (1.0 + x.abs()) || (steps > 2 && delta >= last);
            last = delta;
            x = next;
            if done {
                break;
            }
        }
        (x, steps)
    } else {
        let t = -a;
        let l = -ln_u;
        let w = l + (1.0 + l + (1.0 + l).ln()).ln();
        let y_gamma = w / t;
        let y_rayleigh = (2.0 * l).sqrt();
        let mut y = if y_edge * (1.0 + t) < 0.3 {
            y_edge
        } else {
            y_gamma.min(y_rayleigh)
        };
        if y.is_nan() || y <= 0.0 {
            y = f64::MIN_POSITIVE;
        }
        // For a < −T_CF, ln S(y) = −y (y + 2t)/2 + ln K(t + y) − ln K(t) with K = N/φ from Mills'
        // ratio: the Gaussian exponents cancel exactly instead of as −x²/2 + a²/2 (which would leave
        // an absolute error ~1e-16 a² and stall the iteration for |a| ≳ 1e3).
        let scaled = a < -T_CF;
        // In the scaled branch G(a) = φ(a) K(t), and g_over_phi holds K(t).
        let ln_k_a = if scaled { g_over_phi.ln() } else { ln_h };
        let mut last = f64::INFINITY;
        while steps < MAX_NEWTON {
            steps += 1;
            let (ln_s, r) = if scaled {
                let (rr, e) = mills_cf(t + y);
                let k = rr * (e + y);
                (-0.5 * y * (y + 2.0 * t) + k.ln() - ln_k_a, 1.0 / k)
            } else {
                let (ln_n, r) = ln_partial(a - y, y);
                (ln_n - ln_h, r)
            };
            // g(y) = ln F(a − y) − ln u: g' = −y r, g'' = −r (1 + x y + y² r) with x = a − y.
            let x = a - y;
            let (step, tol) = halley_step(ln_s - ln_u, -y * r, -r * (1.0 + x * y + y * y * r));
            if !step.is_finite() {
                break;
            }
            let next = (y - step).max(0.5 * y * f64::EPSILON);
            let delta = (next - y).abs();
            let done = delta <= tol * y || (steps > 2 && delta >= last);
            last = delta;
            y = next;
            if done {
                break;
            }
        }
        (a - y, steps)
    }
}

/// The Halley step for a root of f given f, f′, f″, (f/f′)/(1 − (f/f′) f″/(2f′)), or the Newton step
/// f/f′ when that correction is large (far from the root, where Halley's step is unreliable); with
/// the relative step size below which the iteration may stop *after* applying the step: the error
/// left is then O(step³) ≈ 1e-15 for Halley, O(step²) ≈ 1e-16 for Newton (relative to the local
/// scale of the density), far below `f32` resolution.
#[inline]
fn halley_step(f: f64, df: f64, ddf: f64) -> (f64, f64) {
    let newton = f / df;
    let q = newton * ddf / (2.0 * df);
    if q.abs() < 0.5 {
        (newton / (1.0 - q), 1e-5)
    } else {
        (newton, 1e-8)
    }
}

/// 2π, for the Box–Muller angle.
pub(crate) const TWO_PI: f64 = 2.0 * PI;

#[cfg(test)]
mod tests;
