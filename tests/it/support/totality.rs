//! Totality checks shared by the robustness property tests (tests/it/robustness_*.rs) and the fuzz
//! targets (fuzz/, which includes this file by path): what every evaluator of the crate promises on any
//! input, valid or not. Each check panics with the offending value.
//!
//! - Densities and values (`d`, `lambda`, `visible_area`, `pdf_*`, `eval`, `pdf`) are finite and ≥ 0;
//!   `projected_area` is finite (a leaning patch's A_P is signed, docs/mixture.md).
//! - G1 and both G2 lie in [0, 1].
//! - Samplers return an upper-hemisphere unit normal for any `u` (NaN included); a BRDF `sample` is
//!   `None` or carries a finite positive pdf, a finite value ≥ 0, an upper-hemisphere `wi` and a
//!   finite weight.

use brdf::ndf::Ndf;
use brdf::{Bxdf, Vec2, Vec3};

/// Asserts `x` is finite and ≥ 0.
pub fn finite_non_negative(what: &str, x: f32) {
    assert!(x.is_finite() && x >= 0.0, "{what} = {x}");
}

/// Asserts `m` is a finite unit vector with z ≥ 0.
pub fn unit_upper(what: &str, m: Vec3) {
    assert!(m.is_finite(), "{what} = {m}");
    assert!(
        m.z >= 0.0 && (m.length() - 1.0).abs() < 1e-3,
        "{what} = {m} is not an upper-hemisphere unit normal"
    );
}

/// The direction pairs a probe (wo, wi) expands to: as given, normalised, and the edges of the
/// issue list: wo = −wi, wo = wi, wo = wi = n, and the mirror direction of wo.
pub fn direction_pairs(wo: Vec3, wi: Vec3) -> [(Vec3, Vec3); 6] {
    let (no, ni) = (wo.normalize_or_zero(), wi.normalize_or_zero());
    [
        (wo, wi),
        (no, ni),
        (no, -no),
        (no, no),
        (Vec3::Z, Vec3::Z),
        (no, Vec3::new(-no.x, -no.y, no.z)),
    ]
}

/// The random-number pairs a probe (uc, u) expands to: as given (any f32), folded into [0, 1), and
/// the two edges 0 and 1 − ε.
pub fn random_numbers(uc: f32, u: Vec2) -> [(f32, Vec2); 4] {
    let unit = |x: f32| if x.is_finite() { x.abs().fract() } else { 0.0 };
    let one_minus = 1.0 - f32::EPSILON / 2.0;
    [
        (uc, u),
        (unit(uc), Vec2::new(unit(u.x), unit(u.y))),
        (0.0, Vec2::ZERO),
        (one_minus, Vec2::splat(one_minus)),
    ]
}

/// Every per-direction query of an NDF on one probe.
pub fn check_ndf(ndf: &dyn Ndf, wo: Vec3, wi: Vec3, uc: f32, u: Vec2) {
    for (wo, wi) in direction_pairs(wo, wi) {
        for w in [wo, wi] {
            finite_non_negative("d", ndf.d(w));
            finite_non_negative("lambda", ndf.lambda(w));
            finite_non_negative("visible_area", ndf.visible_area(w));
            finite_non_negative("pdf_normal", ndf.pdf_normal(w));
            let a = ndf.projected_area(w);
            assert!(a.is_finite(), "projected_area = {a}");
        }
        let h = (wo + wi).normalize_or_zero();
        for (what, g) in [
            ("g1", ndf.g1(wo, h)),
            ("g2", ndf.g2(wo, wi, h)),
            ("g2_height_correlated", ndf.g2_height_correlated(wo, wi, h)),
        ] {
            assert!((0.0..=1.0).contains(&g), "{what} = {g}");
        }
        finite_non_negative("pdf_visible", ndf.pdf_visible(wo, h));
        for (_, u) in random_numbers(uc, u) {
            unit_upper("sample_normal", ndf.sample_normal(u));
            unit_upper("sample_visible", ndf.sample_visible(wo, u));
        }
    }
}

/// Every query of a BRDF on one probe.
pub fn check_bxdf(bxdf: &dyn Bxdf, wo: Vec3, wi: Vec3, uc: f32, u: Vec2) {
    for (wo, wi) in direction_pairs(wo, wi) {
        let f = bxdf.eval(wo, wi);
        assert!(f.is_finite() && f.min_element() >= 0.0, "eval = {f}");
        finite_non_negative("pdf", bxdf.pdf(wo, wi));
        for (uc, u) in random_numbers(uc, u) {
            if let Some(s) = bxdf.sample(wo, uc, u) {
                assert!(s.pdf.is_finite() && s.pdf > 0.0, "sample pdf = {}", s.pdf);
                assert!(
                    s.f.is_finite() && s.f.min_element() >= 0.0,
                    "sample f = {}",
                    s.f
                );
                assert!(s.wi.is_finite() && s.wi.z > 0.0, "sample wi = {}", s.wi);
                assert!(s.weight().is_finite(), "sample weight = {}", s.weight());
            }
        }
    }
}
