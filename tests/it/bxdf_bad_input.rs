//! Bad input to the classic BRDFs and the microfacet BRDF: invalid parameters are named, degenerate
//! directions and random numbers give 0 / `None`, and property tests for NaN, ∞ and negative values
//! over the whole parameter range.
//!
//! Run: `cargo test --test it bxdf_bad_input::`.

use crate::support;

use brdf::bxdf::{
    BlinnPhongLobe, BlinnPhongNormalization, Bxdf, Lambert, Masking, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, Phong, PhongNormalization, Sampling,
};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use proptest::prelude::*;
use support::bxdf::{PHONG_NORMS, blinn, crate_microfacets, ggx, mf, phong, slope_gaussian};

#[test]
fn invalid_parameters_are_named() {
    let has = |r: Result<(), brdf::Error>, name: &str| {
        let e = r.expect_err(name);
        assert!(e.to_string().contains(name), "{e} does not name {name}");
    };
    let pn = PhongNormalization::EnergyConserving;
    has(Lambert::new(Vec3::new(1.1, 0.0, 0.0)).map(drop), "albedo");
    has(
        Lambert::new(Vec3::new(f32::NAN, 0.0, 0.0)).map(drop),
        "albedo",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::ONE, -1.0, pn).map(drop),
        "gamma",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::ONE, f32::INFINITY, pn).map(drop),
        "gamma",
    );
    has(
        Phong::new(
            Vec3::ZERO,
            Vec3::ONE,
            2.5,
            PhongNormalization::EnergyNormalizedArvo,
        )
        .map(drop),
        "gamma",
    );
    has(
        Phong::new(Vec3::splat(0.6), Vec3::splat(0.6), 2.0, pn).map(drop),
        "rho_d + rho_s",
    );
    has(
        Phong::new(Vec3::splat(-0.1), Vec3::ZERO, 2.0, pn).map(drop),
        "rho_d",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0), 2.0, pn).map(drop),
        "rho_s",
    );
    let on = OriginalPhongNormalization::EnergyConserving;
    has(
        OriginalPhong::new(Vec3::ZERO, Vec3::ONE, f32::NAN, on).map(drop),
        "gamma",
    );
    has(
        OriginalPhong::new(Vec3::ONE, Vec3::ONE, 1.0, on).map(drop),
        "rho_d + rho_s",
    );
    let bn = BlinnPhongNormalization::EnergyConserving;
    has(
        BlinnPhongLobe::new(Vec3::ZERO, Vec3::ONE, -0.5, bn).map(drop),
        "gamma",
    );
    has(
        BlinnPhongLobe::new(Vec3::splat(0.5), Vec3::splat(0.7), 1.0, bn).map(drop),
        "rho_d + rho_s",
    );
    // The boundary is allowed: ρ_d + ρ_s = 1 with f32 inputs 0.7 + 0.3.
    assert!(Phong::new(Vec3::splat(0.7), Vec3::splat(0.3), 1.0, pn).is_ok());
}

fn all_models() -> Vec<(String, Box<dyn Bxdf>)> {
    let mut v: Vec<(String, Box<dyn Bxdf>)> = vec![(
        "lambert".into(),
        Box::new(Lambert::new(Vec3::splat(0.5)).unwrap()),
    )];
    for norm in PHONG_NORMS {
        v.push((
            format!("phong {norm:?}"),
            Box::new(phong(0.3, 0.5, 6.0, norm)),
        ));
        v.push((
            format!("phong {norm:?} fresnel"),
            Box::new(phong(0.3, 0.5, 6.0, norm).with_schlick_fresnel()),
        ));
    }
    for norm in [
        OriginalPhongNormalization::Unnormalized,
        OriginalPhongNormalization::EnergyConserving,
    ] {
        v.push((
            format!("original {norm:?}"),
            Box::new(OriginalPhong::new(Vec3::splat(0.3), Vec3::splat(0.5), 6.0, norm).unwrap()),
        ));
    }
    for norm in [
        BlinnPhongNormalization::RealTimeRendering,
        BlinnPhongNormalization::EnergyConserving,
    ] {
        v.push((
            format!("blinn {norm:?}"),
            Box::new(blinn(0.3, 0.5, 6.0, norm)),
        ));
    }
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        for m in [Masking::Separable, Masking::HeightCorrelated] {
            v.push((
                format!("ggx {s:?} {m:?}"),
                Box::new(ggx(0.3).with_sampling(s).with_masking(m)),
            ));
            v.push((
                format!("slope gaussian {s:?} {m:?}"),
                Box::new(
                    MicrofacetBrdf::new(slope_gaussian(), NoFresnel)
                        .with_sampling(s)
                        .with_masking(m),
                ),
            ));
        }
    }
    for (name, b) in crate_microfacets(0.3, Masking::HeightCorrelated, Sampling::VisibleNormals) {
        v.push((name, b));
    }
    v.push((
        "blinn-phong ndf".into(),
        mf(
            BlinnPhong::new(40.0).unwrap(),
            Masking::HeightCorrelated,
            Sampling::VisibleNormals,
        ),
    ));
    v
}

#[test]
fn degenerate_directions_give_zero_and_none() {
    let up = support::dir(30.0, 40.0);
    let below = Vec3::new(0.3, 0.1, -0.9).normalize();
    let horizon = Vec3::X;
    let bad = [
        below,
        horizon,
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ];
    for (name, b) in all_models() {
        for w in bad {
            for (wo, wi) in [(up, w), (w, up), (w, w)] {
                assert_eq!(b.eval(wo, wi), Vec3::ZERO, "{name}: eval({wo}, {wi})");
                assert_eq!(b.pdf(wo, wi), 0.0, "{name}: pdf({wo}, {wi})");
                assert_eq!(b.eval_pdf(wo, wi), (Vec3::ZERO, 0.0), "{name}");
            }
            assert!(
                b.sample(w, 0.3, Vec2::new(0.2, 0.7)).is_none(),
                "{name}: sample({w})"
            );
        }
        // wo = −wi: one of them is below the horizon.
        assert_eq!(b.eval(up, -up), Vec3::ZERO, "{name}");
        // wo = wi = n: a valid configuration; finite and non-negative.
        let (f, p) = b.eval_pdf(Vec3::Z, Vec3::Z);
        assert!(
            f.is_finite() && f.min_element() >= 0.0 && p.is_finite() && p >= 0.0,
            "{name}: {f} {p}"
        );
        // Non-finite random numbers: no sample, no panic.
        assert!(
            b.sample(up, f32::NAN, Vec2::new(f32::NAN, 0.5)).is_none(),
            "{name}"
        );
    }
}

// ---------------------------------------------------------------------------------------------------
// Property test.
// ---------------------------------------------------------------------------------------------------

/// A unit upper-hemisphere direction with cos θ = 10^(−7 t), t ∈ [0, 1], so down to cos θ = 1e-7.
fn upper_dir(t: f32, phi: f32) -> Vec3 {
    let z = 10f32.powf(-7.0 * t);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn check_values(
    name: &str,
    b: &dyn Bxdf,
    wo: Vec3,
    wi: Vec3,
    uc: f32,
    u: Vec2,
) -> Result<(), TestCaseError> {
    let (f, p) = b.eval_pdf(wo, wi);
    prop_assert!(
        f.is_finite() && f.min_element() >= 0.0,
        "{}: f = {} at {} {}",
        name,
        f,
        wo,
        wi
    );
    prop_assert!(
        p.is_finite() && p >= 0.0,
        "{}: pdf = {} at {} {}",
        name,
        p,
        wo,
        wi
    );
    if let Some(s) = b.sample(wo, uc, u) {
        prop_assert!(
            s.wi.is_finite() && s.f.is_finite() && s.f.min_element() >= 0.0,
            "{}: {:?}",
            name,
            s
        );
        prop_assert!(s.pdf.is_finite() && s.pdf > 0.0, "{}: {:?}", name, s);
        prop_assert!(s.weight().is_finite(), "{}: {:?}", name, s);
    }
    Ok(())
}

proptest! {
    #![proptest_config(crate::support::proptest_config(512))]

    #[test]
    fn no_nan_inf_or_negative(
        rho_d in 0.0f32..=1.0, split in 0.0f32..=1.0, gamma in 0.0f32..1e4, alpha in 1e-3f32..2.0,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        uc in 0.0f32..1.0, u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let rho_s = (1.0 - rho_d) * split;
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        let d = Vec3::splat(rho_d);
        let s = Vec3::splat(rho_s);
        check_values("lambert", &Lambert::new(d).unwrap(), wo, wi, uc, u)?;
        for norm in PHONG_NORMS {
            let g = if norm == PhongNormalization::EnergyNormalizedArvo { gamma.round().min(2000.0) } else { gamma };
            let p = Phong::new(d, s, g, norm).unwrap();
            check_values("phong", &p, wo, wi, uc, u)?;
            check_values("phong+fresnel", &p.with_schlick_fresnel(), wo, wi, uc, u)?;
        }
        for norm in [OriginalPhongNormalization::Unnormalized, OriginalPhongNormalization::EnergyConserving] {
            check_values("original", &OriginalPhong::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u)?;
        }
        for norm in [BlinnPhongNormalization::RealTimeRendering, BlinnPhongNormalization::EnergyConserving] {
            check_values("blinn", &BlinnPhongLobe::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u)?;
        }
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                check_values("ggx", &ggx(alpha).with_sampling(sm).with_masking(m), wo, wi, uc, u)?;
            }
        }
    }

    #[test]
    fn microfacet_slope_gaussian_no_nan_inf_or_negative(
        mx in -1.5f32..1.5, my in -1.5f32..1.5, sx in 0.005f32..1.0, sy in 0.005f32..1.0,
        rho in -0.95f32..0.95, f0 in 0.0f32..=1.0,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let c = rho * sx * sy;
        let sg = SlopeGaussian::new(Vec2::new(mx, my), Mat2::from_cols_array(&[sx * sx, c, c, sy * sy])).unwrap();
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        let fresnel = SchlickFresnel::new(Vec3::splat(f0)).unwrap();
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                let b = MicrofacetBrdf::new(&sg, fresnel).with_sampling(sm).with_masking(m);
                check_values("slope gaussian", &b, wo, wi, 0.5, u)?;
            }
        }
    }

    #[test]
    fn microfacet_crate_ndfs_no_nan_inf_or_negative(
        ax in 1e-3f32..2.0, ay in 1e-3f32..2.0, gamma in 0.0f32..1e4,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                check_values("beckmann", mf(Beckmann::new(ax, ay).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
                check_values("ggx", mf(Ggx::new(ax, ay).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
                check_values("blinn-phong ndf", mf(BlinnPhong::new(gamma).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
            }
        }
    }
}
