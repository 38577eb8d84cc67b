//! Integrals and closed forms of the centred analytic NDFs: the Phong lobe integrals against
//! quadrature, hemisphere integrals of the defining identities (∫ D cos = 1, the projected and
//! visible areas, the visible pdf), Blinn-Phong's exact Λ against Walter's approximation, and
//! Beckmann Λ and G1 against an independent f64 evaluation.
//!
//! Run: `cargo test --test it ndf_centred_integrals::`.

use crate::support;

use brdf::ndf::{Beckmann, BlinnPhong, Ndf, shininess_from_beckmann_alpha};
use glam::Vec3;
use rayon::prelude::*;
use support::ndf_centred::{ALPHAS, PHI_ANISO, THETAS, all_cases};

// ---------------------------------------------------------------------------------------------
// The Phong lobe integrals.

/// max(0, ω·a)^γ max(0, ω·z) for the axis a at polar angle acos(c) in the xz-plane, in f64.
fn phong_integrand(gamma: f64, c: f64) -> impl Fn(Vec3) -> f64 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    move |w: Vec3| {
        let d = s * w.x as f64 + c * w.z as f64;
        if d > 0.0 && w.z > 0.0 {
            d.powf(gamma) * w.z as f64
        } else {
            0.0
        }
    }
}

#[test]
fn phong_lobe_integral_matches_quadrature() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    let gammas = [0.0, 0.5, 1.0, 2.5, 10.0, 64.0, 300.0];
    let cosines = [1.0, 0.8, 0.5, 0.1, 0.0, -0.3];
    let jobs: Vec<(f64, f64)> = gammas
        .iter()
        .flat_map(|&g| cosines.iter().map(move |&c| (g, c)))
        .collect();
    let failures: Vec<String> = jobs
        .par_iter()
        .filter_map(|&(g, c)| {
            // 192 θ panels × 8 nodes and 768 φ nodes resolve a lobe of width 1/√300 ≈ 0.06 rad
            // with ≥ 10 nodes across it in both directions. Measured error estimates: ≤ 1e-6 for
            // γ > 0, up to 1.1e-4 for γ = 0 (the integrand is then discontinuous at ω·a = 0).
            let (q, err) =
                support::quadrature::integrate_hemisphere(&phong_integrand(g, c), 192, 768);
            let got = phong_lobe_integral(g as f32, c as f32) as f64;
            // Tolerance: 4× the quadrature's error estimate (which overestimates its true error)
            // + 1e-6 relative (directions are rounded to f32 inside the quadrature; the result
            // is rounded to f32) + 1e-9 absolute (I = 0 cases).
            let tol = 4.0 * err + 1e-6 * q.abs() + 1e-9;
            let mut msg = Vec::new();
            if (got - q).abs() > tol {
                msg.push(format!("MY γ={g} c={c}: {got} vs quadrature {q} ± {err}"));
            }
            if g.fract() == 0.0 {
                let arvo = phong_lobe_integral_arvo(g as u32, c as f32) as f64;
                if (arvo - q).abs() > tol {
                    msg.push(format!(
                        "Arvo n={g} c={c}: {arvo} vs quadrature {q} ± {err}"
                    ));
                }
            }
            (!msg.is_empty()).then(|| msg.join("\n"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn phong_arvo_equals_mallett_yuksel() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    let mut worst = 0.0f64;
    for n in (0..=40).chain([63, 64, 255, 256, 1000, 4097, 100_000]) {
        for i in 0..=200 {
            let c = -1.0 + 2.0 * i as f32 / 200.0;
            let a = phong_lobe_integral_arvo(n, c) as f64;
            let m = phong_lobe_integral(n as f32, c) as f64;
            // Both are f64 computations rounded to f32; Arvo's sum accumulates ~n·ε₆₄ and statrs'
            // incomplete beta is good to ~1e-13: relative 1e-6 (plus 1e-12 absolute where I ≈ 0
            // and the c < 0 identity cancels).
            let err = (a - m).abs() / m.abs().max(1e-6);
            worst = worst.max(err);
            assert!(
                (a - m).abs() <= 1e-6 * m.abs() + 1e-12,
                "n = {n}, c = {c}: Arvo {a} vs Mallett-Yuksel {m}"
            );
        }
    }
    println!("Arvo vs Mallett-Yuksel: worst relative difference {worst:e}");
}

#[test]
fn phong_lobe_integral_at_normal_incidence() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    for g in [0.0f32, 0.25, 1.0, 3.5, 20.0, 1e3, 1e6] {
        let expected = 2.0 * std::f64::consts::PI / (g as f64 + 2.0);
        let got = phong_lobe_integral(g, 1.0) as f64;
        // One f32 rounding of an f64 value: relative 6e-8, doubled for the Γ ratio.
        assert!((got / expected - 1.0).abs() < 2e-7, "γ = {g}");
        if g.fract() == 0.0 && g < 1e4 {
            let a = phong_lobe_integral_arvo(g as u32, 1.0) as f64;
            assert!((a / expected - 1.0).abs() < 2e-7, "Arvo n = {g}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Hemisphere integrals of the defining identities.

/// θ panels and φ nodes for the hemisphere integrals: 256 panels × 8 Gauss nodes put ≥ 10 nodes
/// across the narrowest lobe (α_y = 0.0125 rad); 384 φ nodes resolve its 4:1 azimuthal structure
/// and the kink of ⟨wo, m⟩⁺ at grazing wo. The tests also require the error estimate to be small.
const PANELS: usize = 256;
const N_PHI: usize = 384;

/// Checks |value − expected| ≤ 4·err + rel·|expected|, with err the quadrature's estimate (which
/// overestimates its true error) and `rel` the f32 evaluation error of the integrand; and that
/// err itself is below 1e-3 (so that the check has teeth).
fn check(name: &str, value: f64, err: f64, expected: f64, rel: f64) -> Option<String> {
    let tol = 4.0 * err + rel * expected.abs();
    ((value - expected).abs() > tol || err > 1e-3)
        .then(|| format!("{name}: quadrature {value} ± {err}, expected {expected} (tol {tol:e})"))
}

/// The identities at normal incidence, 60° and 89° (normal incidence and 89° in the default run,
/// `support::depth`); [`hemisphere_identities_every_view`] adds 30° and 80° (`THETAS`).
#[test]
fn hemisphere_identities() {
    hemisphere_identities_at(support::depth(&[0.0, 89.0], &[0.0, 60.0, 89.0]));
}

/// `cargo test --release --test it -- --ignored ndf_centred_integrals::hemisphere_identities_every_view`
#[test]
#[ignore]
fn hemisphere_identities_every_view() {
    hemisphere_identities_at(&THETAS);
}

/// ∫ D cos = 1 for every case, and at each view of `thetas` (degrees) the visible area, Smith's
/// A(1 + Λ) and the visible pdf's integral.
fn hemisphere_identities_at(thetas: &[f64]) {
    let cases = all_cases();
    let failures: Vec<String> = cases
        .par_iter()
        .flat_map(|case| {
            let mut out = Vec::new();
            let ndf = &case.ndf;
            // ∫ D cos = 1. The integrand is evaluated in f32: relative 1e-5 covers its rounding
            // (exp/pow of arguments up to ~50, a few ulp each) summed over 10⁶ nodes in f64.
            let (v, e) = support::quadrature::integrate_hemisphere(
                &|m| ndf.d(m) as f64 * m.z as f64,
                PANELS,
                N_PHI,
            );
            out.extend(check(&format!("{} ∫D cos", case.name), v, e, 1.0, 1e-5));
            for &theta in thetas {
                let wo = support::dir(theta, if case.aniso { PHI_ANISO } else { 0.0 });
                // ∫⟨wo, m⟩⁺ D dm = visible_area(wo) (= cos θ (1 + Λ) for Beckmann and GGX).
                let (v, e) = support::quadrature::integrate_hemisphere(
                    &|m| (wo.dot(m).max(0.0) * ndf.d(m)) as f64,
                    PANELS,
                    N_PHI,
                );
                let va = ndf.visible_area(wo) as f64;
                let name = format!("{} θ={theta}", case.name);
                // visible_area is an f32 result (≤ 4e-6 relative for Beckmann's Λ): 1e-5.
                out.extend(check(&format!("{name} ∫⟨wo,m⟩D = V"), v, e, va, 1e-5));
                let smith = wo.z as f64 * (1.0 + ndf.lambda(wo) as f64);
                if !case.name.starts_with("blinn") {
                    out.extend(check(
                        &format!("{name} ∫⟨wo,m⟩D = A(1+Λ)"),
                        v,
                        e,
                        smith,
                        1e-5,
                    ));
                }
                let (v, e) = support::quadrature::integrate_hemisphere(
                    &|m| ndf.pdf_visible(wo, m) as f64,
                    PANELS,
                    N_PHI,
                );
                out.extend(check(&format!("{name} ∫pdf_visible"), v, e, 1.0, 1e-5));
            }
            out
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Walter's rational Λ: checked against the exact Beckmann Λ it approximates, and its distance
/// from the exact Blinn-Phong Λ (the one `BlinnPhong::lambda` returns; Smith's identity for it is
/// checked in `hemisphere_identities`) is reported.
#[test]
fn blinn_phong_lambda_exact_vs_walter() {
    let (mut worst_bp, mut worst_beck) = ((0.0f64, 0.0f32, 0.0f64), (0.0f64, 0.0f32, 0.0f64));
    for &a in &ALPHAS {
        let bp = BlinnPhong::new(shininess_from_beckmann_alpha(a)).unwrap();
        let beck = Beckmann::isotropic(a).unwrap();
        for i in 1..=179 {
            let theta = i as f64 * 0.5;
            let w = support::dir(theta, 0.0);
            let g_exact = 1.0 / (1.0 + bp.lambda(w) as f64);
            let g_walter = 1.0 / (1.0 + bp.lambda_walter(w) as f64);
            let g_beck = 1.0 / (1.0 + beck.lambda(w) as f64);
            if (g_exact - g_walter).abs() > worst_bp.0 {
                worst_bp = ((g_exact - g_walter).abs(), a, theta);
            }
            if (g_beck - g_walter).abs() > worst_beck.0 {
                worst_beck = ((g_beck - g_walter).abs(), a, theta);
            }
        }
    }
    println!(
        "max |G1_BlinnPhong_exact − G1_Walter| = {:.4} (α = {}, θ = {}°); \
         max |G1_Beckmann − G1_Walter| = {:.5} (α = {}, θ = {}°)",
        worst_bp.0, worst_bp.1, worst_bp.2, worst_beck.0, worst_beck.1, worst_beck.2
    );
    // Walter's fit of Beckmann's G1 is accurate to a few 1e-3 (its stated purpose); a wrong
    // constant or sign would give differences of order 0.1–1.
    assert!(worst_beck.0 < 5e-3, "{worst_beck:?}");
    // Against Blinn-Phong the difference is a modelling error, largest at γ = 0 (α = 1), where
    // Blinn-Phong is exactly GGX with α = 1; it is reported in docs/ndf.md.
    assert!(worst_bp.0 < 0.25, "{worst_bp:?}");
}

// ---------------------------------------------------------------------------------------------
// Beckmann Λ against an independent f64 evaluation.

/// Λ(a) in f64: the direct formula with libm's erfc for a ≤ 20 (its cancellation costs ≤ 9 of
/// f64's 53 bits there).
fn beckmann_lambda_f64(a: f64) -> f64 {
    let sp = std::f64::consts::PI.sqrt();
    0.5 * ((-a * a).exp() / (a * sp) - libm::erfc(a))
}

#[test]
fn beckmann_lambda_against_f64() {
    let mut worst = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for i in 0..=100 {
        // α from 1e-4 to 10, log spaced.
        let alpha = 10f64.powf(-4.0 + 5.0 * i as f64 / 100.0);
        for (ax, ay) in [(alpha, alpha), (alpha, alpha / 4.0)] {
            let ndf = Beckmann::new(ax as f32, ay as f32).unwrap();
            for j in 0..=140 {
                // cos θ from 1e-7 to 1, log spaced.
                let c = 10f64.powf(-7.0 + 7.0 * j as f64 / 140.0);
                for phi in [0.0f64, 0.4, 1.3] {
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    let w = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
                    // a from the f32 direction actually passed, in f64.
                    let (ax, ay) = (ndf.alpha_x() as f64, ndf.alpha_y() as f64);
                    let n = ((ax * w.x as f64).powi(2) + (ay * w.y as f64).powi(2)).sqrt();
                    let a = w.z as f64 / n;
                    let truth = if a > 20.0 {
                        0.0
                    } else {
                        beckmann_lambda_f64(a)
                    };
                    let got = ndf.lambda(w) as f64;
                    // Tolerance: 4e-6 relative (lambda_of_a's measured bound 3e-6) plus the
                    // propagation of the f32 rounding of a (≈ 3 ulp = 2e-7 relative) through
                    // |d ln Λ / d ln a| ≤ 2a² + 1; plus 1e-38 absolute (Λ below the f32 normal
                    // range near a ≈ 9.3 is subnormal or flushed to 0).
                    let tol = if truth > 0.0 {
                        (4e-6 + 2e-7 * (2.0 * a * a + 1.0)) * truth + 1e-38
                    } else {
                        1e-38
                    };
                    let err = (got - truth).abs();
                    if err / tol > worst.0 {
                        worst = (err / tol, alpha, c, a);
                    }
                    assert!(
                        err <= tol,
                        "α = ({ax}, {ay}), cos θ = {c}, φ = {phi}, a = {a}: {got} vs {truth}"
                    );
                }
            }
        }
    }
    println!("Beckmann Λ: worst error/tolerance {worst:?}");
}

/// Beckmann G1 = 1/(1 + Λ) against an f64 reference computed independently (libm's erfc, with a
/// from the f32 direction actually passed): relative error ≤ 1e-6 for α over [1e-4, 10] (two
/// anisotropy ratios), cos θ over [1e-7, 1] and three azimuths (the fast G1 is as exact as the f64 formula).
#[test]
fn beckmann_g1_against_f64() {
    let sp = std::f64::consts::PI.sqrt();
    let mut worst = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..=100 {
        let alpha = 10f64.powf(-4.0 + 5.0 * i as f64 / 100.0);
        for (ax, ay) in [(alpha, alpha), (alpha, alpha / 4.0)] {
            let ndf = Beckmann::new(ax as f32, ay as f32).unwrap();
            let (ax, ay) = (ndf.alpha_x() as f64, ndf.alpha_y() as f64);
            for j in 0..=140 {
                let c = 10f64.powf(-7.0 + 7.0 * j as f64 / 140.0);
                for phi in [0.0f64, 0.4, 1.3] {
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    let w = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
                    let n = ((ax * w.x as f64).powi(2) + (ay * w.y as f64).powi(2)).sqrt();
                    let a = w.z as f64 / n;
                    // G1 = 2a√π / (2a√π + e^(−a²) − a√π erfc(a)); 1 to f64 precision for a > 27.
                    let truth = if a > 27.0 {
                        1.0
                    } else {
                        2.0 * a * sp / (2.0 * a * sp + (-a * a).exp() - a * sp * libm::erfc(a))
                    };
                    let got = ndf.g1(w, Vec3::Z) as f64;
                    let rel = (got / truth - 1.0).abs();
                    if rel > worst.0 {
                        worst = (rel, alpha, c);
                    }
                    assert!(
                        rel <= 1e-6,
                        "α = ({ax}, {ay}), cos θ = {c}, φ = {phi}, a = {a}: {got} vs {truth}"
                    );
                }
            }
        }
    }
    println!("Beckmann G1: worst relative error {worst:?}");
}
