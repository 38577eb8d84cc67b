//! Lane arithmetic of the mixture's lobe blocks (src/glint/mixture/blocks.rs) and of the few-lobe
//! sets (lobe_set.rs): the exponential [`exp2_lanes`], a
//! polynomial of stated error that vectorises (std's `exp` is a library call per lane), and V_P's
//! ramp term G(−t), [`ramp_neg_lanes`]: one fitted exponent and one such exponential, no `erfc`
//! call. Branch-free (selects by bit masks), so the lane loops that call them vectorise; each error
//! bound is measured by the tests below.

/// Lanes per block (a block is a tile of 4 × 4 lobes, blocks.rs).
pub(crate) const LANES: usize = 16;

/// 2^x for x ≤ 0 in `f32`, branch-free (vectorisable); 0 below −126 (the normal range).
///
/// x = n + f with n = round(x) (by the 1.5·2²³ rounding trick, no `floor` call) and f ∈ [−½, ½];
/// 2^f by its degree-7 Taylor polynomial in f·ln 2 (truncation < (½ ln 2)⁸/8! · √2 = 7.4·10⁻⁹
/// relative), 2^n by building the exponent bits. Maximum relative error against `f64` over
/// [−126, 0]: < 1·10⁻⁶ stated (Horner roundings, a few ulp), measured in `tests::exp2_error`.
/// x > 0 is clamped to 0 (the kernels only need x ≤ 0); NaN gives 0.
#[inline(always)]
pub(crate) fn exp2_lanes(x: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0; // 1.5 · 2²³: x + ROUND rounds x to an integer in the low bits
    // All-ones if x ≥ −126, else 0 (NaN too): a bit mask, not a branch.
    let keep = ((x >= -126.0) as u32).wrapping_neg();
    let x = x.clamp(-126.0, 0.0);
    let t = x + ROUND;
    let n = t - ROUND;
    let f = x - n;
    // n ∈ [−126, 0]: the bits of t are 0x4B40_0000 + n, so n + 127 ∈ [1, 127] is a normal exponent.
    let e = (t.to_bits() as i32 - 0x4B40_0000 + 127) as u32;
    let r = exp2_poly(f) * f32::from_bits(e << 23);
    f32::from_bits(r.to_bits() & keep)
}

/// 2^f for f ∈ [−½, ½]: the degree-7 Taylor polynomial in f·ln 2 (see [`exp2_lanes`]).
#[inline(always)]
fn exp2_poly(f: f32) -> f32 {
    // Taylor coefficients (ln 2)^k / k!.
    const C: [f32; 8] = [
        1.0,
        std::f32::consts::LN_2,
        0.240_226_5,
        0.055_504_11,
        0.009_618_129,
        0.001_333_355_8,
        0.000_154_035_3,
        1.525_273_4e-5,
    ];
    C[0] + f * (C[1] + f * (C[2] + f * (C[3] + f * (C[4] + f * (C[5] + f * (C[6] + f * C[7]))))))
}

/// `v` where `keep`, else +0.0, by a bit mask (branch-free; vectorises as an `and`).
#[inline(always)]
pub(crate) fn select(keep: bool, v: f32) -> f32 {
    f32::from_bits(v.to_bits() & (keep as u32).wrapping_neg())
}

/// The 16 lanes' G(−t) = φ(t) − t Q(t) = E[(−t − Z)⁺] for t ≥ 0 (Z standard normal), branch-free, in
/// `f32` from `f64` t; 0 where it is below `f32`'s normal range (t ≳ 13.2), for t = ∞ and for NaN.
///
/// G(−t) = φ(t) h(t), h = 1 − t R(t) (R Mills' ratio), is formed as τ² e^{P(τ) − t²/2}/√(2π) with
/// τ = 1/(1 + t/4) ∈ (0, 1] and P a degree-9 polynomial in τ − 0.6 fitted (weighted least squares in
/// the Chebyshev basis, Lawson iterations toward minimax) to ln(h/τ²) over τ ∈ [0.2, 1] (t ∈ [0, 16];
/// h from erfc below t = 3, from Laplace's continued fraction above; `tools/fit_mixture_ramp.py`
/// reproduces the coefficients). Fit error < 9.4·10⁻⁸ in the
/// exponent; the exponent is assembled and range-reduced in `f64` ([`exp2_split`]), so t²/2
/// loses nothing to `f32` at large t. Measured maximum relative error against the `f64` G(−t)
/// (libm's erfc) over t ∈ [0, 13]: see `tests::ramp_neg_lanes_error` (bound 1·10⁻⁶ asserted).
/// One `f32` division (τ), no branch, no library call: the lanes vectorise.
///
/// # Reference
/// docs/slope_gaussian.md (G and V); \[AbramowitzStegun1964\] 26.2.14 (the continued fraction used
/// for the fit's reference values); the τ substitution as in \[Press1992\] §6.2 (`erfcc`).
#[inline(always)]
pub(crate) fn ramp_neg_lanes<const N: usize>(t: &[f64; N], out: &mut [f32; N]) {
    const INV_SQRT_2PI: f32 = 0.398_942_3;
    #[allow(clippy::excessive_precision)]
    const P: [f32; 10] = [
        -1.244_708_393_489_749_4,
        3.054_656_480_484_212,
        0.547_764_485_561_222_7,
        -0.928_449_119_805_369_7,
        -0.539_391_164_288_975_5,
        0.744_292_706_170_099_9,
        0.539_760_181_308_597_7,
        -0.793_917_658_569_022,
        -0.409_734_608_149_832_1,
        0.646_252_530_778_816_2,
    ];
    // The work is split into loops of one width each, so that the f32 steps fill whole registers
    // (4 lanes with SSE2) instead of running at the 2 lanes of the f64 steps.
    // t beyond 1e4 (∞, and NaN by `min`'s rule) gives 0 below like any t ≳ 13.2.
    let t: [f64; N] = std::array::from_fn(|i| t[i].min(1.0e4));
    let mut tau = [0.0f32; N];
    let mut p = [0.0f32; N];
    for i in 0..N {
        let ti = 1.0 / (1.0 + 0.25 * t[i] as f32);
        let u = ti - 0.6;
        tau[i] = ti;
        p[i] = P[0]
            + u * (P[1]
                + u * (P[2]
                    + u * (P[3]
                        + u * (P[4]
                            + u * (P[5] + u * (P[6] + u * (P[7] + u * (P[8] + u * P[9]))))))));
    }
    let mut f = [0.0f32; N];
    let mut scale = [0.0f32; N];
    for i in 0..N {
        let x = std::f64::consts::LOG2_E * (p[i] as f64 - 0.5 * t[i] * t[i]);
        (f[i], scale[i]) = exp2_split(x);
    }
    for i in 0..N {
        out[i] = INV_SQRT_2PI * (tau[i] * tau[i]) * (exp2_poly(f[i]) * scale[i]);
    }
}

/// e^(−q/2) for q ≥ 0 given in `f64`, in `f32`, inline (no library call): the Gaussian factor of
/// the few-lobe sets' P22. [`exp2_split`] then the polynomial of [`exp2_lanes`]: < 1·10⁻⁶ relative
/// (`tests::exp2_wide_error`, measured 1·10⁻⁷); 0 below `f32`'s normal range (q > 174.7) and for
/// NaN.
#[inline(always)]
pub(crate) fn exp_neg_half(q: f64) -> f32 {
    let (f, scale) = exp2_split(-0.5 * core::f64::consts::LOG2_E * q);
    exp2_poly(f) * scale
}

/// The range reduction of [`exp2_lanes_wide`]: x ≤ 0 in `f64` → (f, 2ⁿ) with x = n + f, f ∈ [−½, ½]
/// exact in `f32` up to its rounding, 2ⁿ an `f32` power of two; (any, +0) below −126 or for NaN.
#[inline(always)]
fn exp2_split(x: f64) -> (f32, f32) {
    const ROUND: f64 = 6_755_399_441_055_744.0; // 1.5 · 2⁵²
    let keep = ((x >= -126.0) as u32).wrapping_neg();
    // `max` then `min` (not `clamp`): NaN becomes −126, so f stays finite and 2ⁿ is masked to 0.
    #[allow(clippy::manual_clamp)]
    let x = x.max(-126.0).min(0.0);
    let t = x + ROUND;
    let n = t - ROUND;
    let f = (x - n) as f32;
    // The low 32 bits of t's bits are n (two's complement), n ∈ [−126, 0].
    let e = ((t.to_bits() as u32 as i32) + 127) as u32;
    (f, f32::from_bits((e << 23) & keep))
}

/// 2^x for x ≤ 0 given in `f64`, result in `f32`, branch-free; 0 below −126 (what
/// [`ramp_neg_lanes`] computes through [`exp2_split`], for its error test). The integer part is
/// split off in `f64` (1.5·2⁵² rounding trick), so the `f32` polynomial sees f ∈ [−½, ½] exactly
/// and large |x| costs no accuracy (an `f32` argument of size 100 carries 4·10⁻⁶ absolute error).
/// Same polynomial and error as [`exp2_lanes`] (< 1·10⁻⁶ relative). NaN gives 0.
#[cfg(test)]
fn exp2_lanes_wide(x: f64) -> f32 {
    let (f, scale) = exp2_split(x);
    exp2_poly(f) * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp2_error() {
        // Dense grid over [−126, 0] plus the integers and half-integers (the reduction's edges).
        let mut worst = 0.0f64;
        let n = 2_000_000;
        for k in 0..=n {
            let x = -126.0 * k as f64 / n as f64;
            let x32 = x as f32;
            let want = (x32 as f64).exp2();
            let got = exp2_lanes(x32) as f64;
            worst = worst.max((got - want).abs() / want);
        }
        for k in 0..=252 {
            let x = -0.5 * k as f32;
            let want = (x as f64).exp2();
            worst = worst.max((exp2_lanes(x) as f64 - want).abs() / want);
        }
        println!("exp2_lanes: max relative error {worst:e}");
        assert!(worst < 1e-6, "max relative error {worst:e}");
        assert_eq!(exp2_lanes(-127.0), 0.0);
        assert_eq!(exp2_lanes(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp2_lanes(f32::NAN), 0.0);
        assert_eq!(exp2_lanes(0.0), 1.0);
    }

    /// [`ramp_neg_lanes`] at one t (in every lane).
    fn ramp_neg_one(t: f64) -> f32 {
        let mut out = [0.0f32; LANES];
        ramp_neg_lanes(&[t; LANES], &mut out);
        out[7]
    }

    /// G(−t) by the lanes against the `f64` G(−t) (libm's erfc, Laplace's continued fraction
    /// beyond t = 5), relative, over t ∈ [0, 13] (G(−13) ≈ 3·10⁻⁴¹·… is at `f32`'s normal limit).
    #[test]
    fn ramp_neg_lanes_error() {
        let mut worst = (0.0f64, 0.0f64);
        let n = 400_000;
        for k in 0..=n {
            let t = 13.0 * k as f64 / n as f64;
            let want = crate::ndf::gauss::ramp_neg(t);
            let got = ramp_neg_one(t) as f64;
            // Below 2^-120 the f32 result is subnormal or flushed: not part of the stated bound.
            if want > 2f64.powi(-120) {
                let e = (got - want).abs() / want;
                if e > worst.0 {
                    worst = (e, t);
                }
            }
        }
        println!(
            "ramp_neg_lanes: max relative error {:e} at t = {}",
            worst.0, worst.1
        );
        assert!(
            worst.0 < 1e-6,
            "max relative error {:e} at t = {}",
            worst.0,
            worst.1
        );
        assert_eq!(ramp_neg_one(1.0e4), 0.0);
        assert_eq!(ramp_neg_one(f64::INFINITY), 0.0);
        assert_eq!(ramp_neg_one(f64::NAN), 0.0);
    }

    #[test]
    fn exp2_wide_error() {
        let mut worst = 0.0f64;
        let n = 1_000_000;
        for k in 0..=n {
            let x = -126.0 * k as f64 / n as f64;
            let want = x.exp2();
            worst = worst.max((exp2_lanes_wide(x) as f64 - want).abs() / want);
        }
        println!("exp2_lanes_wide: max relative error {worst:e}");
        assert!(worst < 1e-6, "max relative error {worst:e}");
        assert_eq!(exp2_lanes_wide(-126.5), 0.0);
        assert_eq!(exp2_lanes_wide(f64::NAN), 0.0);
        assert_eq!(exp2_lanes_wide(0.0), 1.0);
    }
}
