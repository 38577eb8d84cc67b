//! Reciprocity f(wo, wi) = f(wi, wo) of the classic BRDFs and of the microfacet BRDF (a tilted lobe in
//! its own projected-area measure), and the documented asymmetry of the non-reciprocal models.
//!
//! Run: `cargo test --test it bxdf_reciprocity::`.

use crate::support;

use brdf::bxdf::{
    BlinnPhongNormalization, Bxdf, Lambert, Masking, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, PhongNormalization, Sampling,
};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::{BlinnPhong, Ndf};
use glam::{Vec2, Vec3};
use support::bxdf::{
    PHONG_NORMS, TestGgx, blinn, crate_microfacets, ggx, phong, random_upper, slope_gaussian,
};

/// Asserts f(wo, wi) = f(wi, wo) to 1e-5 relative on 2000 random pairs (f32 evaluation of the same
/// symmetric expression in a different order: a few ulps).
fn assert_reciprocal(name: &str, b: &dyn Bxdf) {
    let mut rng = support::rng(11);
    for _ in 0..2000 {
        let (wo, wi) = (random_upper(&mut rng), random_upper(&mut rng));
        let (a, r) = (b.eval(wo, wi), b.eval(wi, wo));
        let scale = a.abs().max(r.abs()).max_element();
        // 1e-5 relative, plus f32's smallest normal number in absolute terms: a value far in the
        // tail (D ~ 1e-40, subnormal) keeps only a few significant bits through one more product.
        assert!(
            (a - r).abs().max_element() <= 1e-5 * scale + f32::MIN_POSITIVE,
            "{name}: {wo} {wi}: {a} vs {r}"
        );
    }
}

/// A BRDF seen in its projected-area measure: eval · cos θi / A(wi) (the symmetric P-BRDF f_P of a
/// non-centred NDF) where both A(wo) and A(wi) are positive (the relation's domain), else 0.
struct PatchMeasure<'a> {
    brdf: &'a dyn Bxdf,
    area: &'a dyn Fn(Vec3) -> f32,
}

impl Bxdf for PatchMeasure<'_> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let a = (self.area)(wi);
        if a > 0.0 && (self.area)(wo) > 0.0 {
            self.brdf.eval(wo, wi) * (wi.z / a)
        } else {
            Vec3::ZERO
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.brdf.pdf(wo, wi)
    }
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<brdf::BxdfSample> {
        self.brdf.sample(wo, uc, u)
    }
}

#[test]
fn reciprocal_models() {
    assert_reciprocal("lambert", &Lambert::new(Vec3::new(0.2, 0.5, 0.9)).unwrap());
    for norm in &PHONG_NORMS[..3] {
        let p = phong(0.3, 0.6, 12.0, *norm);
        assert!(p.is_reciprocal());
        assert_reciprocal(&format!("phong {norm:?}"), &p);
    }
    for norm in [
        BlinnPhongNormalization::RealTimeRendering,
        BlinnPhongNormalization::EnergyConserving,
    ] {
        assert_reciprocal(&format!("blinn {norm:?}"), &blinn(0.3, 0.6, 30.0, norm));
    }
    for masking in [Masking::Separable, Masking::HeightCorrelated] {
        assert_reciprocal(&format!("ggx {masking:?}"), &ggx(0.3).with_masking(masking));
        let schlick = MicrofacetBrdf::new(
            TestGgx { alpha: 0.3 },
            SchlickFresnel {
                f0: Vec3::splat(0.1),
            },
        )
        .with_masking(masking);
        assert_reciprocal(&format!("ggx+schlick {masking:?}"), &schlick);
        // A tilted lobe is reciprocal in its own measure: f(wo, wi) cos θi / A(wi) is symmetric.
        let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_masking(masking);
        let a = |w: Vec3| slope_gaussian().projected_area(w);
        let patch_measure = PatchMeasure {
            brdf: &sg,
            area: &a,
        };
        assert_reciprocal(&format!("slope gaussian {masking:?}"), &patch_measure);
        for (name, b) in crate_microfacets(0.3, masking, Sampling::VisibleNormals) {
            assert_reciprocal(&format!("{name} {masking:?}"), b.as_ref());
        }
        let bp =
            MicrofacetBrdf::new(BlinnPhong::new(30.0).unwrap(), NoFresnel).with_masking(masking);
        assert_reciprocal(&format!("blinn-phong ndf {masking:?}"), &bp);
    }
}

#[test]
fn non_reciprocal_models_show_their_asymmetry() {
    let (wo, wi) = (support::dir(20.0, 0.0), support::dir(70.0, 180.0));
    // Original Phong, specular only: f(wo, wi) / f(wi, wo) = cos θo / cos θi exactly (the 1/cos θi).
    let o = OriginalPhong::new(
        Vec3::ZERO,
        Vec3::ONE,
        5.0,
        OriginalPhongNormalization::EnergyConserving,
    )
    .unwrap();
    let ratio = o.eval(wo, wi).x / o.eval(wi, wo).x;
    assert!(
        (ratio - wo.z / wi.z).abs() < 1e-5 * ratio && ratio > 2.5,
        "{ratio}"
    );

    // Energy-normalised Phong: the ratio is N(wo)/N(wi) = I(γ, cos θi)/I(γ, cos θo) (here ≈ 0.6).
    for norm in &PHONG_NORMS[3..] {
        let p = phong(0.0, 1.0, 5.0, *norm);
        assert!(!p.is_reciprocal());
        let ratio = p.eval(wo, wi).x / p.eval(wi, wo).x;
        let want = p.normalizer(wo) / p.normalizer(wi);
        assert!(
            (ratio - want).abs() < 1e-5 && (ratio - 1.0).abs() > 0.1,
            "{norm:?}: {ratio}"
        );
    }

    // Schlick Fresnel at cos θo breaks reciprocity of the otherwise reciprocal Lafortune lobe.
    let p = phong(0.2, 0.3, 5.0, PhongNormalization::EnergyConserving).with_schlick_fresnel();
    assert!(!p.is_reciprocal());
    let (a, b) = (p.eval(wo, wi).x, p.eval(wi, wo).x);
    assert!((a - b).abs() > 0.01 * a.max(b), "{a} {b}");
}
