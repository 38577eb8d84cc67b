//! Self-tests of the shared test helpers: the quadrature is exact where it must be, and the chi-square
//! harness accepts a correct sampler and rejects a wrong one (so that a passing sampler test means
//! something).

use crate::support;

use glam::Vec3;
use std::f64::consts::PI;
use support::chi2::Chi2;
use support::quadrature::{GL_N, gauss_legendre, integrate_hemisphere};

#[test]
fn gauss_legendre_is_exact_for_polynomials() {
    // An n-point rule integrates degree 2n − 1 exactly; x^14 with n = 8 is within float round-off.
    let gl = gauss_legendre(GL_N);
    let s: f64 = gl.iter().map(|&(x, w)| w * x.powi(14)).sum();
    assert!((s - 2.0 / 15.0).abs() < 1e-13, "{s}");
}

#[test]
fn hemisphere_area_and_cosine() {
    let (a, _) = integrate_hemisphere(&|_| 1.0, 8, 16);
    assert!((a - 2.0 * PI).abs() < 1e-12);
    let (c, err) = integrate_hemisphere(&|w| w.z as f64, 8, 16);
    // Directions are rounded to f32: the bound is f32 epsilon times the integral.
    assert!((c - PI).abs() < 1e-6 && err < 1e-6, "{c} ± {err}");
}

/// Cosine-weighted hemisphere sampling by Malley's method, written here independently of the crate.
fn cosine_sample(u: glam::Vec2) -> Vec3 {
    let r = u.x.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u.x).max(0.0).sqrt())
}

#[test]
fn chi2_accepts_a_correct_sampler() {
    let t = Chi2 {
        z_min: Some(0.0),
        ..Chi2::new("cosine/correct", 1)
    };
    let p = t
        .run(
            |_, u| Some(cosine_sample(u)),
            |w| (w.z.max(0.0) as f64) / PI,
        )
        .unwrap();
    assert!(p > 0.01);
}

#[test]
fn chi2_rejects_a_wrong_pdf() {
    // The sampler draws cos θ but the claimed density is cos^1.1 θ (renormalised): a 1 % kind of error.
    let t = Chi2 {
        z_min: Some(0.0),
        ..Chi2::new("cosine/wrong", 1)
    };
    let claimed = |w: Vec3| (w.z.max(0.0) as f64).powf(1.1) * 3.1 / (2.0 * PI);
    assert!(t.run(|_, u| Some(cosine_sample(u)), claimed).is_err());
}

#[test]
fn chi2_counts_none_as_lost_mass() {
    // Half the draws are rejected; the density integrates to 1/2 over the hemisphere.
    let t = Chi2 {
        z_min: Some(0.0),
        ..Chi2::new("cosine/half", 1)
    };
    let p = t.run(
        |uc, u| (uc < 0.5).then(|| cosine_sample(u)),
        |w| 0.5 * (w.z.max(0.0) as f64) / PI,
    );
    assert!(p.is_ok(), "{p:?}");
}
