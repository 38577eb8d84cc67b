//! The V-cavity masking-shadowing model (Torrance–Sparrow / Cook–Torrance V-grooves).
//!
//! Each micronormal m is paired with its mirror image (−m_x, −m_y, m_z) to form a symmetric
//! V-shaped groove; masking is then purely geometric and independent of the NDF. Unlike Smith's
//! model it does not depend on the distribution, and it is not the masking of any random height
//! field; it is kept for classic Cook–Torrance and for comparison.

use glam::Vec3;

/// V-cavity masking G1(w, m) = χ⁺(w·m / w·ω_g) · min(1, 2 (ω_g·m)(ω_g·w) / (w·m)).
///
/// Degenerate cases: 0 when w or m is at or below the horizon, when w·m ≤ 0 (a back-facing facet),
/// or when an input is not finite. The result is in [0, 1].
///
/// # Reference
/// \[Heitz2014\] (the V-cavity model) and the VSB 2024 BRDF lecture ("Microsurface models"
/// slide, G1 of the V-cavity model); \[CookTorrance1982\] (the geometric attenuation term).
#[inline]
pub fn g1_vcavity(w: Vec3, m: Vec3) -> f32 {
    let wm = w.dot(m);
    if !(w.z > 0.0 && m.z > 0.0 && wm > 0.0) {
        return 0.0;
    }
    let g = 2.0 * m.z * w.z / wm;
    if g.is_finite() { g.min(1.0) } else { 0.0 }
}

/// V-cavity masking-shadowing for reflection:
/// G2(wo, wi, m) = χ⁺(wo·m) χ⁺(wi·m) · min(1, 2 (ω_g·m)(ω_g·wo)/(wo·m), 2 (ω_g·m)(ω_g·wi)/(wi·m))
/// = min(G1(wo, m), G1(wi, m)).
///
/// Degenerate cases: 0 when wo, wi or m is at or below the horizon, when either direction sees the
/// back of the facet, or for non-finite input. (The transmission form max(0, G1o + G1i − 1) of
/// the lecture is not needed: the crate models reflection only.)
///
/// # Reference
/// \[Heitz2014\] (V-cavity G2 for reflection); \[CookTorrance1982\]; the DTU 2021 microfacet lecture ("The
/// Torrance-Sparrow BRDF", geometry term G).
#[inline]
pub fn g2_vcavity(wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
    g1_vcavity(wo, m).min(g1_vcavity(wi, m))
}

/// Height-correlated Smith masking-shadowing from the two Λ values: 1 / (1 + Λ(wo) + Λ(wi)).
///
/// The shared form behind [`Ndf::g2_height_correlated`](super::Ndf::g2_height_correlated), for
/// callers that already hold Λ(wo) and Λ(wi). Negative or NaN Λ are treated as 0 (never happens
/// for the NDFs of this crate); an infinite Λ gives 0.
///
/// # Reference
/// \[Heitz2014\] eq. 99.
#[inline]
pub fn g2_height_correlated_from_lambda(lambda_o: f32, lambda_i: f32) -> f32 {
    let lo = if lambda_o > 0.0 { lambda_o } else { 0.0 };
    let li = if lambda_i > 0.0 { lambda_i } else { 0.0 };
    1.0 / (1.0 + lo + li)
}

/// [`Ndf::g2_height_correlated`](super::Ndf::g2_height_correlated) with the finiteness checks the
/// trait default lacks: χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi)), 0 for degenerate input.
#[inline]
pub(super) fn g2_height_correlated_checked<N: super::Ndf + ?Sized>(
    ndf: &N,
    wo: Vec3,
    wi: Vec3,
    m: Vec3,
) -> f32 {
    let ok = wo.is_finite() && wi.is_finite() && m.is_finite();
    if !(ok && wo.z > 0.0 && wi.z > 0.0 && wo.dot(m) > 0.0 && wi.dot(m) > 0.0) {
        return 0.0;
    }
    g2_height_correlated_from_lambda(ndf.lambda(wo), ndf.lambda(wi))
}

/// Separable (uncorrelated) Smith masking-shadowing from the two Λ values:
/// 1 / ((1 + Λ(wo)) (1 + Λ(wi))). Same conventions as [`g2_height_correlated_from_lambda`].
///
/// # Reference
/// \[Heitz2014\] eq. 98.
#[inline]
pub fn g2_separable_from_lambda(lambda_o: f32, lambda_i: f32) -> f32 {
    let lo = if lambda_o > 0.0 { lambda_o } else { 0.0 };
    let li = if lambda_i > 0.0 { lambda_i } else { 0.0 };
    1.0 / ((1.0 + lo) * (1.0 + li))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vcavity_closed_forms() {
        // At normal incidence nothing is masked: 2 m_z · 1 / m_z = 2 → 1.
        let m = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(g1_vcavity(Vec3::Z, m), 1.0);
        // A grazing view across a steep groove: w = (−sin 80°, 0, cos 80°) against m tilted 36.87°
        // away: G1 = 2 · 0.8 · cos 80° / (w·m), computed here by hand.
        let t = 80f32.to_radians();
        let w = Vec3::new(-t.sin(), 0.0, t.cos());
        let expected = 2.0 * 0.8 * t.cos() / (-0.6 * t.sin() + 0.8 * t.cos());
        // w·m < 0 here (the facet faces away), so G1 must be 0 whatever the formula says.
        assert!(w.dot(m) < 0.0 && expected < 0.0);
        assert_eq!(g1_vcavity(w, m), 0.0);
        let w = Vec3::new(t.sin(), 0.0, t.cos());
        let wm = 0.6 * t.sin() + 0.8 * t.cos();
        let expected = (2.0 * 0.8 * t.cos() / wm).min(1.0);
        assert!((g1_vcavity(w, m) - expected).abs() < 1e-6 && expected < 1.0);
        // G2 is the smaller of the two.
        assert_eq!(g2_vcavity(w, Vec3::Z, m), g1_vcavity(w, m));
        assert_eq!(g2_vcavity(Vec3::Z, w, m), g1_vcavity(w, m));
    }

    #[test]
    fn vcavity_degenerate_inputs() {
        let m = Vec3::new(0.0, 0.0, 1.0);
        for bad in [
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(f32::NAN, 0.0, 1.0),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
        ] {
            assert_eq!(g1_vcavity(bad, m), 0.0, "{bad:?}");
            assert_eq!(g1_vcavity(Vec3::Z, bad), 0.0, "{bad:?}");
            assert_eq!(g2_vcavity(bad, Vec3::Z, m), 0.0);
            assert_eq!(g2_vcavity(Vec3::Z, bad, m), 0.0);
        }
    }

    #[test]
    fn lambda_forms() {
        assert_eq!(g2_height_correlated_from_lambda(0.0, 0.0), 1.0);
        assert_eq!(g2_height_correlated_from_lambda(1.0, 1.0), 1.0 / 3.0);
        assert_eq!(g2_separable_from_lambda(1.0, 1.0), 0.25);
        assert_eq!(g2_height_correlated_from_lambda(f32::INFINITY, 0.0), 0.0);
        assert_eq!(g2_height_correlated_from_lambda(f32::NAN, -1.0), 1.0);
    }
}
