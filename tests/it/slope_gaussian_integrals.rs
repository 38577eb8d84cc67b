//! Integrals of `SlopeGaussian`, the non-centred anisotropic Beckmann lobe: hemisphere quadrature of
//! D cos, ⟨w, m⟩⁺ D, (w·m) D and the visible pdf against the closed forms; agreement with an
//! independent anisotropic Beckmann D and Λ and with Dupuy's closed form for tilted lobes; and a lobe
//! from the moments of a flat region.
//!
//! Quadrature strategy (all with `support::quadrature`, error estimate = |fine − half resolution|):
//! - ∫ D cos and ∫ (w·m) D have smooth integrands over the upper hemisphere of the shading frame.
//! - ∫ ⟨w, m⟩⁺ D and ∫ pdf_visible have a kink on the great circle w·m = 0. They are integrated in a
//!   frame whose pole is w, where that circle is the horizon: the integrand is then smooth (D itself
//!   vanishes faster than any power at the shading horizon).
//! - Narrow lobes (σ ≤ 0.02) would need ~10⁷ points on the whole hemisphere. For them the integral
//!   is a band θ' ∈ [0, θ_cap] in a frame whose pole is the lobe's mean normal, with θ_cap = 14 σ_max
//!   (σ_max = the largest slope standard deviation): an angle between normals is at most their slope
//!   distance, so the mass outside is < e^{−14²/2} ≈ 1e-43.
//!
//! Run: `cargo test --test it slope_gaussian_integrals::` (release-like: the test profile is opt-level 3).

use crate::support;

use brdf::frame::Frame;
use brdf::ndf::{Ndf, SlopeGaussian};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::f64::consts::PI;
use support::dir;
use support::quadrature::{integrate_band, integrate_hemisphere};
use support::slope_gaussian::lobe;

/// (name, lobe, σ_min, σ_max): the slope standard deviations along the covariance's eigenvectors.
struct Case {
    name: String,
    g: SlopeGaussian,
    sigma_minor: f64,
    sigma_major: f64,
}

fn case(mean: (f32, f32), sx: f32, sy: f32, rho: f32) -> Case {
    let (a, b, c) = ((sx * sx) as f64, (sy * sy) as f64, (rho * sx * sy) as f64);
    let m = 0.5 * (a + b);
    let d = (0.25 * (a - b).powi(2) + c * c).sqrt();
    Case {
        name: format!("mean({},{}) s({sx},{sy}) rho {rho}", mean.0, mean.1),
        g: lobe(mean, sx, sy, rho),
        sigma_minor: (m - d).sqrt(),
        sigma_major: (m + d).sqrt(),
    }
}

/// Lobes for the quadrature tests: mean slopes of norm up to 1, correlations ±0.8, σ from 0.01 to 1.
fn quadrature_cases() -> Vec<Case> {
    vec![
        case((0.0, 0.0), 0.3, 0.3, 0.0),
        case((0.0, 0.0), 1.0, 0.4, 0.8),
        case((0.3, -0.2), 0.1, 0.25, -0.8),
        case((0.6, 0.8), 0.2, 0.2, 0.0),
        case((-0.7, 0.5), 0.5, 1.0, 0.8),
        case((0.5, 0.5), 0.05, 0.08, -0.8),
        case((0.0, 0.0), 0.01, 0.01, 0.0),
        case((0.8, -0.6), 0.01, 0.02, 0.8),
        case((-0.4, 0.3), 0.015, 0.01, -0.8),
    ]
}

/// View directions: θ ∈ {0, 30, 60, 80, 89}° at azimuths 0°, 135°, 250° (θ = 0 once); every
/// third of them in the default run (support::depth), which keeps every θ at azimuth 250°.
fn directions() -> Vec<(f64, f64)> {
    let mut v = vec![(0.0, 0.0)];
    for t in [30.0, 60.0, 80.0, 89.0] {
        for p in [0.0, 135.0, 250.0] {
            v.push((t, p));
        }
    }
    v.into_iter().step_by(support::depth(3, 1)).collect()
}

/// Hemisphere resolution for a lobe: panel width and φ step ≲ 0.4 of the lobe's angular standard
/// deviation (≥ σ_minor cos²θ at tilt θ ≤ 60°), capped to keep the file fast.
fn resolution(c: &Case) -> (usize, usize) {
    let ang = 0.5 * c.sigma_minor;
    let panels = ((PI / 2.0) / (0.4 * ang)).ceil().clamp(32.0, 256.0) as usize;
    let n_phi = ((2.0 * PI) / (0.4 * ang)).ceil().clamp(128.0, 1024.0) as usize;
    (panels, n_phi)
}

/// ∫ g(ω) dω over the upper hemisphere of the shading frame, with an error estimate. Narrow lobes
/// are integrated over the cap around their mean normal (see the file's doc).
fn integrate_lobe(c: &Case, g: &(dyn Fn(Vec3) -> f64 + Sync)) -> (f64, f64) {
    if c.sigma_major > 0.02 {
        let (panels, n_phi) = resolution(c);
        integrate_hemisphere(g, panels, n_phi)
    } else {
        let frame = Frame::from_normal(c.g.mean_normal());
        let cap = 14.0 * c.sigma_major;
        let local = |w: Vec3| g(frame.to_world(w));
        // ~1/6 σ per panel in θ'; φ' at 128 (the lobe surrounds the pole, smooth in φ').
        let panels = 96;
        let fine = integrate_band(&local, 0.0, cap, panels, 128);
        let coarse = integrate_band(&local, 0.0, cap, panels / 2, 64);
        (fine, (fine - coarse).abs())
    }
}

/// ∫ over the hemisphere around `w` (pole w) of g, with an error estimate; narrow lobes as above.
fn integrate_around(c: &Case, w: Vec3, g: &(dyn Fn(Vec3) -> f64 + Sync)) -> (f64, f64) {
    if c.sigma_major > 0.02 {
        let frame = Frame::from_normal(w);
        let local = |v: Vec3| g(frame.to_world(v));
        let (panels, n_phi) = resolution(c);
        integrate_hemisphere(&local, panels, n_phi)
    } else {
        // The cap around the mean normal lies inside the upper hemisphere; g carries its own clamp.
        integrate_lobe(c, g)
    }
}

/// Float bound of a quadrature of D in `f32`: D's own rounding (the f32 `exp` of an argument up
/// to ~50 in the bulk: ≤ 50 · 1.2e-7 relative) and the f32 rounding of the quadrature directions,
/// which moves D by |∇ ln D| · 1.2e-7 with |∇ ln D| ≲ 6/σ_angle in the bulk.
fn float_bound(c: &Case, scale: f64) -> f64 {
    (6e-6 + 1.2e-7 * 6.0 / (0.5 * c.sigma_minor)) * scale
}

#[test]
fn d_cos_integrates_to_one() {
    // Every slope maps to an upper-hemisphere normal, so ∫_{H²} D cos = ∫_{ℝ²} P22 = 1 exactly,
    // whatever the tilt.
    let failures: Vec<String> = quadrature_cases()
        .par_iter()
        .filter_map(|c| {
            let (v, err) = integrate_lobe(c, &|m: Vec3| c.g.d(m) as f64 * m.z as f64);
            let tol = 4.0 * err + float_bound(c, 1.0);
            ((v - 1.0).abs() > tol)
                .then(|| format!("{}: ∫ D cos = {v} ± {err:e} (tol {tol:e})", c.name))
        })
        .collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn projected_areas_match_quadrature() {
    let jobs: Vec<(usize, (f64, f64))> = (0..quadrature_cases().len())
        .flat_map(|i| directions().into_iter().map(move |d| (i, d)))
        .collect();
    let cases = quadrature_cases();
    let failures: Vec<String> = jobs
        .par_iter()
        .filter_map(|&(i, (theta, phi))| {
            let c = &cases[i];
            let w = dir(theta, phi);
            let mut out = Vec::new();

            // Signed projected area ∫ (w·m) D dm = cos θ − sin θ q̄ (smooth integrand).
            let (a_q, a_err) = integrate_lobe(c, &|m: Vec3| w.dot(m) as f64 * c.g.d(m) as f64);
            let a = c.g.signed_projected_area(w) as f64;
            // Scale: ∫ |w·m| D ≤ ∫ D = E[√(1 + |ñ|²)] ≤ 2 for these lobes.
            let tol = 4.0 * a_err + float_bound(c, 2.0) + 1e-7;
            if (a_q - a).abs() > tol {
                out.push(format!(
                    "{} w({theta},{phi}): A_s = {a}, quadrature {a_q} ± {a_err:e}",
                    c.name
                ));
            }

            // Visible area ∫ ⟨w,m⟩⁺ D dm (kink moved to the horizon of the w-frame).
            let (v_q, v_err) = integrate_around(c, w, &|m: Vec3| {
                (w.dot(m) as f64).max(0.0) * c.g.d(m) as f64
            });
            let v = c.g.visible_area(w) as f64;
            let tol = 4.0 * v_err + float_bound(c, v.max(1e-30)) + 1e-7 * v;
            if (v_q - v).abs() > tol {
                out.push(format!(
                    "{} w({theta},{phi}): V = {v:e}, quadrature {v_q:e} ± {v_err:e} (tol {tol:e})",
                    c.name
                ));
            }
            // Λ = V/A − 1 from the quadrature, where A is not small (else the ratio amplifies the
            // quadrature error by V/A).
            if a > 0.05 && v_q > 0.0 {
                let l_q = v_q / a - 1.0;
                let l = c.g.lambda(w) as f64;
                let tol = (tol / a) * 2.0 + 1e-6 * (1.0 + l);
                if (l_q - l).abs() > tol {
                    out.push(format!(
                        "{} w({theta},{phi}): Λ = {l:e}, quadrature {l_q:e}",
                        c.name
                    ));
                }
            }

            // ∫ pdf_visible = 1 wherever V is resolvable by the f32 D used in the quadrature; at one
            // azimuth per θ (each pdf evaluation costs ~10 D evaluations: the file stays fast).
            if v > 1e-20 && (phi == 135.0 || theta == 0.0) {
                let (p_q, p_err) = integrate_around(c, w, &|m: Vec3| c.g.pdf_visible(w, m) as f64);
                let tol = 4.0 * p_err + float_bound(c, 1.0) + 1e-6;
                if (p_q - 1.0).abs() > tol {
                    out.push(format!(
                        "{} w({theta},{phi}): ∫ pdf_visible = {p_q} ± {p_err:e} (tol {tol:e})",
                        c.name
                    ));
                }
            }
            (!out.is_empty()).then(|| out.join("\n"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Anisotropic Beckmann D, written independently in f64:
/// D = exp(−(m_x²/αx² + m_y²/αy²)/m_z²) / (π αx αy m_z⁴).
fn beckmann_d(ax: f64, ay: f64, m: Vec3) -> f64 {
    let (x, y, z) = (m.x as f64, m.y as f64, m.z as f64);
    if z <= 0.0 {
        return 0.0;
    }
    (-(x * x / (ax * ax) + y * y / (ay * ay)) / (z * z)).exp() / (PI * ax * ay * z.powi(4))
}

/// Beckmann Λ(w) = (e^{−a²}/(a√π) − erfc(a))/2, a = 1/(α_φ tan θ), α_φ² = cos²φ αx² + sin²φ αy²
/// ([Heitz2014] eq. 72 with the anisotropic α_φ of eq. 80), in f64 with libm's erfc.
/// Returns (Λ, a).
fn beckmann_lambda(ax: f64, ay: f64, w: Vec3) -> (f64, f64) {
    let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
    let s2 = x * x + y * y;
    if s2 == 0.0 {
        return (0.0, f64::INFINITY);
    }
    let alpha = ((x * x * ax * ax + y * y * ay * ay) / s2).sqrt();
    let a = z / (alpha * s2.sqrt());
    (0.5 * ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a)), a)
}

#[test]
fn centred_lobe_is_anisotropic_beckmann() {
    for (ax, ay) in [(0.1f32, 0.1f32), (0.3, 0.05), (0.8, 0.4), (1.5, 0.7)] {
        let g = SlopeGaussian::beckmann(ax, ay).unwrap();
        let (ax64, ay64) = (ax as f64, ay as f64);
        for theta in [0.0, 5.0, 20.0, 45.0, 70.0, 85.0, 89.5] {
            for phi in [0.0, 30.0, 90.0, 200.0, 313.0] {
                let m = dir(theta, phi);
                let d_ref = beckmann_d(ax64, ay64, m);
                let d = g.d(m) as f64;
                // f32: exp of an argument ≤ ~90 (relative error ≤ 90 · 1.2e-7 ≈ 1e-5) and the slope
                // and (1 + |ñ|²)² computed from f32 components (a few 1e-7 each).
                assert!(
                    (d - d_ref).abs() <= 2e-5 * d_ref + 1e-37,
                    "α ({ax},{ay}) m({theta},{phi}): D = {d:e}, Beckmann {d_ref:e}"
                );
                let (l_ref, a) = beckmann_lambda(ax64, ay64, m);
                let l = g.lambda(m) as f64;
                // Λ ~ e^{−a²}: the f32 rounding of the direction and of the lobe (~1e-7 relative on
                // a) moves Λ by ~2a² · 1e-7 relative; the closed form cancels (~a² · 1e-16); Λ is
                // rounded to f32 (6e-8). Below the f32 normal range (1.2e-38) only "tiny" is checked.
                let tol = (1e-6 + 4e-7 * a * a) * l_ref;
                if l_ref < 1e-37 {
                    assert!(
                        l < 1e-36,
                        "α ({ax},{ay}) w({theta},{phi}): Λ = {l:e}, ref {l_ref:e}"
                    );
                    continue;
                }
                assert!(
                    (l - l_ref).abs() <= tol,
                    "α ({ax},{ay}) w({theta},{phi}): Λ = {l:e}, Beckmann {l_ref:e}"
                );
            }
        }
    }
}

#[test]
fn lambda_matches_dupuy_closed_form_for_tilted_lobes() {
    // Λ of the non-centred lobe, written from [Dupuy2013] in f64: ν = (cot θ − q̄)/(√2 s),
    // Λ = (e^{−ν²}/(ν√π) − erfc(ν))/2, q̄ = μ·(cos φ, sin φ), s² = (cos φ, sin φ) Σ (cos φ, sin φ)ᵀ.
    for c in quadrature_cases() {
        let mu = c.g.mean();
        let cov = c.g.covariance();
        for (theta, phi) in directions().into_iter().skip(1) {
            let w = dir(theta, phi);
            let (t, p) = (theta.to_radians(), phi.to_radians());
            let (cp, sp) = (p.cos(), p.sin());
            let q = mu.x as f64 * cp + mu.y as f64 * sp;
            let (sxx, sxy, syy) = (
                cov.x_axis.x as f64,
                cov.x_axis.y as f64,
                cov.y_axis.y as f64,
            );
            let s = (cp * cp * sxx + 2.0 * cp * sp * sxy + sp * sp * syy).sqrt();
            let nu = (1.0 / t.tan() - q) / (std::f64::consts::SQRT_2 * s);
            let l = c.g.lambda(w) as f64;
            if nu <= 0.0 {
                assert_eq!(l, f32::MAX as f64, "{} w({theta},{phi})", c.name);
                continue;
            }
            let l_ref = 0.5 * ((-nu * nu).exp() / (nu * PI.sqrt()) - libm::erfc(nu));
            // Relative tolerance: the crate sees the direction rounded to f32 (components ±6e-8),
            // which moves A_s = cos θ − sin θ q̄ by ~6e-8 (1 + |μ|) — relative to A_s, which may be
            // small — and s by ~1e-7 relative; Λ ~ e^{−ν²} turns a relative error δ of ν into 2ν²δ.
            // Plus the f32 rounding of Λ and the reference's cancellation (~ν² · 1e-16).
            // Below the f32 normal range (1.2e-38) only "tiny" is checked.
            let a_s = t.cos() - t.sin() * q;
            let mu_norm = (mu.x as f64).hypot(mu.y as f64);
            let rel_nu = 1.2e-7 * (1.0 + mu_norm) / a_s.abs() + 2e-7;
            let tol = (1e-6 + 2.0 * nu * nu * rel_nu) * l_ref;
            if l_ref < 1e-37 {
                assert!(
                    l < 1e-36,
                    "{} w({theta},{phi}): Λ = {l:e}, ref {l_ref:e}",
                    c.name
                );
            } else {
                assert!(
                    (l - l_ref).abs() <= tol,
                    "{} w({theta},{phi}): Λ = {l:e}, ref {l_ref:e}",
                    c.name
                );
            }
        }
    }
}

#[test]
fn from_moments_flat_region_is_sigma_min() {
    // All moments from one constant slope: no spread, so σ = σ_min on every axis, mean = that slope,
    // and the lobe integrates to 1 like any other (checked on the cap around its mean normal).
    let (x, y) = (0.35f32, -0.15f32);
    let g = SlopeGaussian::from_moments([x, y, x * x, y * y, x * y], 0.01);
    let cov = g.covariance();
    assert_eq!(g.mean(), Vec2::new(x, y));
    // Rounding of E[x̃]² vs E[x̃²] in f32 leaves a raw variance ≲ 1e-8 ≪ σ_min² = 1e-4.
    assert!((cov.x_axis.x - 1e-4).abs() < 1e-9 && (cov.y_axis.y - 1e-4).abs() < 1e-9);
    let c = Case {
        name: "flat".into(),
        g,
        sigma_minor: 0.01,
        sigma_major: 0.01,
    };
    let (v, err) = integrate_lobe(&c, &|m: Vec3| g.d(m) as f64 * m.z as f64);
    assert!(
        (v - 1.0).abs() <= 4.0 * err + float_bound(&c, 1.0),
        "{v} ± {err}"
    );
}
