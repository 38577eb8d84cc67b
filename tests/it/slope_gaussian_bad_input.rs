//! Bad input to `SlopeGaussian`: property tests of totality and consistency on random lobes and
//! directions down to cos θ = 1e-7, degenerate directions and random numbers, and constructors that
//! name the bad parameter.

use crate::support;

use brdf::ndf::{Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use proptest::prelude::*;
use support::slope_gaussian::lobe;

/// A unit direction with cos θ = 10^`log_cos` (down to 1e-7) and azimuth φ.
fn direction(log_cos: f32, phi: f32) -> Vec3 {
    let c = 10f64.powf(log_cos as f64);
    let s = (1.0 - c * c).max(0.0).sqrt();
    let phi = phi as f64;
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32)
}

/// u with components replaced by 0 or 1 − ε according to `edge`.
fn edged(u: [f32; 2], edge: u8) -> Vec2 {
    let top = 1.0 - f32::EPSILON / 2.0;
    let pick = |v: f32, e: u8| match e {
        1 => 0.0,
        2 => top,
        _ => v,
    };
    Vec2::new(pick(u[0], edge % 3), pick(u[1], edge / 3 % 3))
}

proptest! {
    #![proptest_config(crate::support::proptest_config(2000))]

    /// Random valid lobes (σ ∈ [1e-3, 3] log-uniform, |μ| ≤ 3, ρ ∈ (−0.99, 0.99)) and directions
    /// down to cos θ = 1e-7: every value is finite and ≥ 0, G1 ≤ 1, sampled normals are unit and
    /// upper, and their densities are positive.
    #[test]
    fn total_and_consistent(
        ln_sx in (1e-3f32).ln()..(3f32).ln(),
        ln_sy in (1e-3f32).ln()..(3f32).ln(),
        rho in -0.99f32..0.99,
        mr in 0f32..3.0,
        mphi in 0f32..std::f32::consts::TAU,
        log_cos_o in -7f32..0.0,
        phi_o in 0f32..std::f32::consts::TAU,
        log_cos_m in -7f32..0.0,
        phi_m in 0f32..std::f32::consts::TAU,
        u in prop::array::uniform2(0f32..1.0),
        edge in 0u8..9,
    ) {
        let g = lobe((mr * mphi.cos(), mr * mphi.sin()), ln_sx.exp(), ln_sy.exp(), rho);
        let wo = direction(log_cos_o, phi_o);
        let m = direction(log_cos_m, phi_m);
        let u = edged(u, edge);
        for v in [
            g.d(m), g.lambda(wo), g.projected_area(wo), g.visible_area(wo),
            g.pdf_normal(m), g.pdf_visible(wo, m), g.g1(wo, m),
            g.g2(wo, m, m), g.g2_height_correlated(wo, m, m),
        ] {
            prop_assert!(v.is_finite() && v >= 0.0, "{v}");
        }
        prop_assert!(g.g1(wo, m) <= 1.0);
        let parts = g.visible_area_parts(wo);
        prop_assert!(parts.visible_area >= parts.signed_area.max(0.0));

        let n = g.sample_normal(u);
        prop_assert!(n.z > 0.0 && (n.length() - 1.0).abs() < 1e-6, "{n}");
        let p = g.pdf_normal(n);
        prop_assert!(p > 0.0 && p.is_finite(), "pdf_normal({n}) = {p}");

        let v = g.sample_visible(wo, u);
        prop_assert!(v.z > 0.0 && (v.length() - 1.0).abs() < 1e-6, "{v}");
        // Positive wherever D is (pdf_visible is 0 where D underflows f32; the f64 density is
        // positive on the whole visible support).
        let p = g.pdf_visible(wo, v);
        prop_assert!(p.is_finite() && (p > 0.0) == (g.d(v) > 0.0), "pdf_visible({wo}, {v}) = {p}");
        prop_assert!(g.ln_pdf_visible(wo, v).is_some_and(f64::is_finite), "{wo} {v}");
    }
}

#[test]
fn degenerate_directions_and_inputs() {
    let g = lobe((0.4, -0.3), 0.2, 0.1, 0.5);
    for w in [
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.6, 0.0, -0.8),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ] {
        assert_eq!(g.d(w), 0.0);
        assert_eq!(g.lambda(w), 0.0);
        assert_eq!(g.visible_area(w), 0.0);
        assert_eq!(g.projected_area(w), 0.0);
        assert_eq!(g.pdf_visible(w, Vec3::Z), 0.0);
        let m = g.sample_visible(w, Vec2::new(0.5, 0.5));
        assert!(m.z > 0.0 && (m.length() - 1.0).abs() < 1e-6);
    }
    // NaN random numbers are treated as ½ (documented), still giving valid normals.
    let m = g.sample_normal(Vec2::new(f32::NAN, f32::NAN));
    assert!(m.z > 0.0 && m.is_finite());
    // Constructors name the parameter.
    let e = SlopeGaussian::new(Vec2::new(0.0, f32::INFINITY), Mat2::IDENTITY).unwrap_err();
    assert!(e.to_string().contains("`mean`"), "{e}");
    let e =
        SlopeGaussian::new(Vec2::ZERO, Mat2::from_cols_array(&[1.0, 0.3, 0.0, 1.0])).unwrap_err();
    assert!(e.to_string().contains("`cov`"), "{e}");
    let e = SlopeGaussian::beckmann(-0.1, 0.1).unwrap_err();
    assert!(e.to_string().contains("`alpha_x`"), "{e}");
}
