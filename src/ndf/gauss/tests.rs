//! Unit tests of the standard-normal functions (src/ndf/gauss.rs).

use super::*;

/// ∫_lo^hi f by composite 8-point Gauss–Legendre on `n` panels (nodes from Newton on P₈),
/// written here so that the references below share no code with the functions under test.
fn integrate(f: impl Fn(f64) -> f64, lo: f64, hi: f64, n: usize) -> f64 {
    let mut nodes = Vec::new();
    for i in 0..8 {
        let mut x = (PI * (i as f64 + 0.75) / 8.5).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=8 {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = 8.0 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    let h = (hi - lo) / n as f64;
    let mut s = 0.0;
    for p in 0..n {
        let c = lo + (p as f64 + 0.5) * h;
        for &(x, w) in &nodes {
            s += w * f(c + 0.5 * h * x);
        }
    }
    s * 0.5 * h
}

/// G(z) = E[(z − Z)⁺] from `ramp_neg`, as the lobe's `visible_area` forms it.
fn ramp(z: f64) -> f64 {
    if z > 0.0 {
        z + ramp_neg(z)
    } else {
        ramp_neg(-z)
    }
}

#[test]
fn ramp_matches_quadrature() {
    // G(z) = ∫_{−∞}^z (z − s) φ(s) ds by quadrature on [z − 40, z] (the rest is < e^{−800}).
    // Tolerance 1e-12 relative: the 8-point rule on 400 panels of width 0.1 is exact to ~1e-15
    // for this smooth integrand; the CF branch is within 3e-14 (see `mills_cf`).
    for &z in &[
        -30.0, -12.0, -7.5, -5.5, -5.0, -4.9, -2.0, -0.3, 0.0, 0.7, 3.0, 6.0, 20.0,
    ] {
        let reference = integrate(
            |s: f64| (z - s) * (-0.5 * s * s).exp() * INV_SQRT_2PI,
            z - 40.0,
            z,
            400,
        );
        let got = ramp(z);
        assert!(
            ((got - reference) / reference).abs() < 1e-12,
            "G({z}) = {got:e}, quadrature {reference:e}"
        );
    }
}

#[test]
fn continued_fraction_agrees_with_direct_form() {
    // In the overlap 5 ≤ t ≤ 12 the direct form φ(t) − t Q(t) has relative error up to
    // ~(t²/2)·2.2e-16 (rounding of the exponent's argument, in φ and inside erfc) amplified by
    // the cancellation factor ~1 + t²: 2.3e-12 at t = 12. The CF itself is within 3e-14.
    for i in 0..=70 {
        let t = 5.0 + 0.1 * i as f64;
        let direct = std_pdf(t) - t * 0.5 * libm::erfc(t * FRAC_1_SQRT_2);
        let cf = ramp_neg(t);
        let tol = 4.4e-16 * (0.5 * t * t) * (1.0 + t * t) + 3e-14;
        assert!(
            ((cf - direct) / direct).abs() < tol,
            "t = {t}: {cf:e} vs {direct:e}"
        );
    }
}

#[test]
fn ln_partial_is_continuous_across_branches() {
    // The two branches of ln_partial meet at x = −T_CF; their values must agree there to the
    // accuracy of the CF (3e-14) plus the direct form's cancellation (~26 ulp).
    for &y in &[0.0, 1e-6, 0.3, 4.0, 100.0] {
        let (l0, r0) = ln_partial(-T_CF, y);
        let (r, e) = mills_cf(T_CF);
        let k = r * (e + y);
        let l1 = -0.5 * T_CF * T_CF - LN_SQRT_2PI + k.ln();
        assert!((l0 - l1).abs() < 1e-12, "y = {y}: {l0} vs {l1}");
        assert!(((r0 - 1.0 / k) * k).abs() < 1e-12);
    }
}

#[test]
fn inverse_cdf_round_trips() {
    // Φ(Φ⁻¹(p)) = p to ~1e-14 relative (AS 241 is accurate to ~1e-16; erfc to 1 ulp; the
    // round trip multiplies the quantile error by x·φ/Φ ≤ ~40 in the far tail).
    let mut p = 1e-300;
    while p < 0.5 {
        for q in [p, 1.0 - p] {
            if q >= 1.0 {
                continue;
            }
            let x = inv_std_cdf(q);
            // Compare in the tail that holds q, where Φ is accurate.
            let (tail, target) = if q < 0.5 {
                (std_cdf(x), q)
            } else {
                (std_cdf(-x), 1.0 - q)
            };
            // Relative error of Φ(x̂): d ln Φ/dx ≈ |x| in the tail, so a quantile good to ~1e-16
            // relative (AS 241) and erfc's argument rounding give ~1e-16 x² each.
            let tol = 1e-14 + 1e-15 * x * x;
            assert!(((tail - target) / target).abs() < tol, "p = {q:e}: x = {x}");
        }
        p *= 3.7;
    }
    assert_eq!(inv_std_cdf(0.5), 0.0);
    assert_eq!(inv_std_cdf(0.0), f64::NEG_INFINITY);
    assert_eq!(inv_std_cdf(1.0), f64::INFINITY);
    assert!(inv_std_cdf(f64::NAN).is_nan());
}

#[test]
fn f32_quantile_is_the_f64_one_to_float_precision() {
    // The 24-bit uniforms the procedural lattice draws (every 97th), then a log-spaced tail.
    let mut worst = 0.0f64;
    let mut check = |p: f32| {
        let (x, r) = (inv_std_cdf_f32(p) as f64, inv_std_cdf(p as f64));
        let err = (x - r).abs() / r.abs().max(1.0);
        worst = worst.max(err);
    };
    for k in (0..1u32 << 24).step_by(97) {
        check((k as f32 + 0.5) / (1u32 << 24) as f32);
    }
    let mut p = 1e-37f32;
    while p < 0.5 {
        check(p);
        check(1.0 - p);
        p *= 1.7;
    }
    assert!(worst < 5e-7, "worst relative error {worst:e}");
    assert_eq!(inv_std_cdf_f32(0.5), 0.0);
    assert_eq!(inv_std_cdf_f32(0.0), f32::NEG_INFINITY);
    assert_eq!(inv_std_cdf_f32(1.0), f32::INFINITY);
    assert!(inv_std_cdf_f32(f32::NAN).is_nan() && inv_std_cdf_f32(1.5).is_nan());
}

/// Independent reference for the tilted cdf at x (x ≤ a): for a ≥ 0 the closed form
/// (a Φ(x) + φ(x)) / (a Φ(a) + φ(a)) (no cancellation there); for a < 0 (where that form
/// cancels) the survival S(y) of y = a − x, density ∝ y e^{−t y − y²/2}, t = −a, by quadrature
/// on [0, min(80/t, 40)] (the rest weighs < e^{−80}).
fn tilted_cdf_reference(a: f64, x: f64) -> f64 {
    if a >= 0.0 {
        let phi = |s: f64| (-0.5 * s * s).exp() * INV_SQRT_2PI;
        let cdf = |s: f64| 0.5 * libm::erfc(-s * FRAC_1_SQRT_2);
        (a * cdf(x) + phi(x)) / (a * cdf(a) + phi(a))
    } else {
        let t = -a;
        let dens = |y: f64| y * (-t * y - 0.5 * y * y).exp();
        let hi = (80.0 / t).min(40.0);
        let y0 = a - x;
        let total = integrate(dens, 0.0, hi, 400);
        if y0 >= hi {
            return 0.0;
        }
        integrate(dens, y0, hi, 400) / total
    }
}

#[test]
fn sample_ramp_inverts_the_tilted_cdf() {
    let us = [
        2f64.powi(-26),
        1e-6,
        0.01,
        0.2,
        0.5,
        0.77,
        0.99,
        1.0 - 1e-6,
        1.0 - 2f64.powi(-26),
    ];
    let a_values = [
        -1e4, -300.0, -40.0, -9.0, -6.0, -5.0, -4.9, -2.0, -0.5, -1e-9, 0.0, 1e-9, 0.4, 1.0, 3.0,
        8.0, 50.0, 1e3, 1e6,
    ];
    for &a in &a_values {
        for &u in &us {
            let (x, steps) = sample_ramp_counted(a, u);
            assert!(x.is_finite() && x <= a, "a = {a}, u = {u}: x = {x}");
            assert!(steps < MAX_NEWTON, "a = {a}, u = {u}: {steps} steps");
            let f = tilted_cdf_reference(a, x);
            // Tolerance: relative 1e-9 on min(u, 1 − u) (the reference's own error is ≤ 1e-12;
            // the Newton stopping rule leaves ≤ 1e-13 (1 + |x|) in x, i.e. ≤ 1e-13 (1+|x|) · p(x)
            // in F). For |a| ≥ 1e3, x is only representable to ~1e-16·|a|, which moves F by
            // up to |a|·1e-16·p(x): the bound is widened accordingly.
            // Tolerance: 1e-9 relative to the tail min(u, 1 − u) (Newton stops at a step
            // ≤ 1e-13 (1 + |x|), which moves F by ≤ |x|·1e-13 relative in the tails), plus
            // 1e-15 absolute (the closed-form reference near F = 1 is good to ~1e-16), plus the
            // representation limit of x itself: x ≈ a is known to ~1e-16 |a|, and the density
            // reaches ~max(1, −a), so F is known to ~1e-16 |a| max(1, −a).
            // For −5 ≤ a < 0 the sampler forms N and G(a) directly, good to
            // ~(a²/2)(1 + a²)·4.4e-16 relative (see `ramp_neg`): 1.3e-13 at a = −4.9.
            let tail = u.min(1.0 - u);
            let direct = if (-T_CF..0.0).contains(&a) {
                4.4e-16 * 0.5 * a * a * (1.0 + a * a)
            } else {
                0.0
            };
            let tol =
                1e-9 * tail + 1e-15 + direct + 1e-15 * (1.0 + a.abs()) * (1.0 + (-a).max(0.0));
            assert!(
                (f - u).abs() <= tol.max(1e-15),
                "a = {a}, u = {u}: x = {x}, F(x) = {f} (|F − u| = {:e}, tol {tol:e})",
                (f - u).abs()
            );
        }
    }
}

#[test]
fn sample_ramp_iterations() {
    // Average Newton steps over a grid of u, per a; recorded in docs/slope_gaussian.md.
    for &a in &[-1e3, -20.0, -3.0, -0.5, 0.0, 0.5, 2.0, 10.0, 1e4] {
        let n = 999;
        let total: usize = (1..=n)
            .map(|i| sample_ramp_counted(a, i as f64 / (n + 1) as f64).1)
            .sum();
        let mean = total as f64 / n as f64;
        println!("a = {a}: {mean:.2} steps on average");
        assert!(mean < 8.0, "a = {a}: {mean} steps on average");
    }
}
