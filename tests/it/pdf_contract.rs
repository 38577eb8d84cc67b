//! The density contract (docs/robustness.md, "Densities and their support"), for every NDF, every
//! glint patch and every BRDF with a sampler:
//!
//! - an NDF's `pdf_visible(wo, m)` and `pdf_normal(m)` are 0 wherever `d(m)` is 0, and
//!   `pdf_visible` is 0 for every invalid `wo` (below or on the horizon, −0.0, zero, NaN, ∞);
//! - a BRDF's `pdf(wo, wi)` is positive wherever `eval(wo, wi)` is, for unit directions (the one
//!   documented exception, `MicrofacetBrdf` where the micronormal density is subnormal, is excluded
//!   by testing that density too).
//!
//! Property tests (proptest, fixed seed) over directions that reach every branch: grazing to
//! normal, unit and not, below the horizon, non-finite; for the BRDFs also the directions that the
//! other samplers produce (so that `eval` > 0 is common).

use crate::support;

use brdf::bxdf::{
    BlinnPhongNormalization, LayeredBrdf, OriginalPhongNormalization, PhongNormalization, Sampling,
};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::glint::binmap::{self, BinMapParams};
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions as MixtureOptions};
use brdf::glint::position_normal::{self, PositionNormalParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintNdf, MAX_SLOPE, NormalMap, PositionNormalBrdf,
    PositionNormalMap, bumpy,
};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};
use brdf::{BlinnPhongLobe, Bxdf, Lambert, Mat2, MicrofacetBrdf, OriginalPhong, Phong, Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::TestRunner;

// ---------------------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------------------

/// A unit direction with cos θ log-uniform in [1e-30, 1].
fn unit_dir() -> impl Strategy<Value = Vec3> {
    (-30.0f32..=0.0, 0.0f32..std::f32::consts::TAU).prop_map(|(log_cos, phi)| {
        let c = 10f32.powf(log_cos);
        let s = (1.0 - (c as f64) * (c as f64)).sqrt() as f32;
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    })
}

/// Directions no NDF or BRDF may count as valid views.
fn invalid_dirs() -> Vec<Vec3> {
    vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(0.6, 0.8, 0.0),
        Vec3::new(0.6, 0.0, -0.0),
        -Vec3::Z,
        Vec3::new(0.3, 0.4, -1e-30),
        Vec3::splat(f32::NAN),
        Vec3::new(0.0, 0.0, f32::NAN),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
        Vec3::new(f32::NEG_INFINITY, 0.0, 0.5),
    ]
}

/// Any direction: unit (mostly), mirrored below the horizon, unnormalised, or one of the invalid
/// ones.
fn any_dir() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        6 => unit_dir(),
        1 => unit_dir().prop_map(|w| Vec3::new(w.x, w.y, -w.z)),
        1 => (unit_dir(), -3.0f32..3.0).prop_map(|(w, e)| w * 10f32.powf(e)),
        1 => prop::sample::select(invalid_dirs()),
    ]
}

// ---------------------------------------------------------------------------------------------
// The NDFs and patches
// ---------------------------------------------------------------------------------------------

/// The glint models the patches borrow: small maps and builds.
struct Models {
    bin_map: BinMap,
    position_normal: PositionNormalMap,
    /// Rate 4 on a 1×1 map at the largest slope (the issue's case: d(Z) = 0, pdf_visible(Z, Z) =
    /// 4,773).
    position_normal_steep: PositionNormalMap,
    bin_map_flat: BinMap,
}

impl Models {
    fn build() -> Models {
        let map = bumpy(16, 16, 0.3, 3.0, 5).unwrap();
        let flat = NormalMap::from_slopes(1, 1, vec![Vec2::ZERO]).unwrap();
        let steep = NormalMap::from_slopes(1, 1, vec![Vec2::new(MAX_SLOPE, 0.0)]).unwrap();
        let small_bins = BinMapParams {
            bins_per_axis: 31,
            ..BinMapParams::default()
        };
        Models {
            bin_map: BinMap::build(&map, small_bins).unwrap(),
            position_normal: PositionNormalMap::build(&map, PositionNormalParams::default())
                .unwrap(),
            position_normal_steep: PositionNormalMap::build(
                &steep,
                PositionNormalParams {
                    sampling_rate: 4,
                    ..PositionNormalParams::default()
                },
            )
            .unwrap(),
            bin_map_flat: BinMap::build(&flat, BinMapParams::default()).unwrap(),
        }
    }
}

/// A square footprint of `texels` texels per side at (0.37, 0.61) of an `n`² map.
fn footprint(texels: f32, n: usize) -> Footprint {
    let d = texels / n as f32;
    Footprint::from_differentials(Vec2::new(0.37, 0.61), Vec2::new(d, 0.0), Vec2::new(0.0, d))
}

type Named<'a> = (String, Box<dyn Ndf + 'a>);

fn analytic_ndfs() -> Vec<Named<'static>> {
    let mut v: Vec<Named<'static>> = Vec::new();
    for (ax, ay) in [
        (0.5, 0.5),
        (0.3, 0.1),
        (1e-4, 1e-4),
        (1e-7, 1e-7),
        (1e4, 1e4),
    ] {
        v.push((
            format!("Beckmann {ax}/{ay}"),
            Box::new(Beckmann::new(ax, ay).unwrap()),
        ));
        v.push((
            format!("GGX {ax}/{ay}"),
            Box::new(Ggx::new(ax, ay).unwrap()),
        ));
    }
    for g in [0.0, 10.0, 1e9] {
        v.push((
            format!("Blinn-Phong {g}"),
            Box::new(BlinnPhong::new(g).unwrap()),
        ));
    }
    for (mean, cov) in [
        (Vec2::ZERO, Mat2::from_diagonal(Vec2::splat(0.1))),
        (
            Vec2::new(-3.0, 2.0),
            Mat2::from_cols(Vec2::new(0.3, 0.1), Vec2::new(0.1, 0.05)),
        ),
        // The issue's case: a grazing wo gave pdf_visible 6.6e7 where d = 0.
        (Vec2::new(1e4, 0.0), Mat2::from_diagonal(Vec2::splat(1e-8))),
        (
            Vec2::new(0.0, -50.0),
            Mat2::from_diagonal(Vec2::splat(1e-9)),
        ),
    ] {
        v.push((
            format!("SlopeGaussian {mean} {cov}"),
            Box::new(SlopeGaussian::new(mean, cov).unwrap()),
        ));
    }
    v
}

fn glint_patches(models: &Models) -> Vec<Named<'_>> {
    let mut v: Vec<Named<'_>> = Vec::new();
    // 0.5 texels (exact bins), 8 (exact), 200 (beyond the exact-masking size: the moment lobe).
    for texels in [0.5f32, 8.0, 200.0] {
        for alpha in [0.0, 0.05, 3.0, 1e4, f32::MAX] {
            let options = binmap::PatchOptions {
                smoothing_alpha: alpha,
                ..Default::default()
            };
            v.push((
                format!("bin map {texels} texels α {alpha}"),
                Box::new(
                    models
                        .bin_map
                        .patch_with(&footprint(texels, 16), &options, None),
                ),
            ));
        }
        v.push((
            format!("position-normal {texels} texels"),
            Box::new(models.position_normal.patch_with(
                &footprint(texels, 16),
                &position_normal::PatchOptions::default(),
                None,
            )),
        ));
    }
    // The issue's cases: a 1×1 flat map with a 16-texel footprint (pdf_visible(X, Z) = 1.03e4
    // before), and the steep 1×1 map at rate 4 (pdf_visible(Z, Z) = 4,773 where d(Z) = 0).
    for alpha in [0.0, 0.05] {
        let options = binmap::PatchOptions {
            smoothing_alpha: alpha,
            ..Default::default()
        };
        v.push((
            format!("bin map 1×1 flat α {alpha}"),
            Box::new(
                models
                    .bin_map_flat
                    .patch_with(&footprint(16.0, 1), &options, None),
            ),
        ));
    }
    for texels in [0.25f32, 1.0] {
        v.push((
            format!("position-normal 1×1 steep {texels}"),
            Box::new(models.position_normal_steep.patch_with(
                &footprint(texels, 1),
                &position_normal::PatchOptions::default(),
                None,
            )),
        ));
    }
    v
}

/// The NDF half of the contract at one (wo, m): d = 0 ⇒ both pdfs 0; invalid wo ⇒ pdf_visible 0.
fn check_ndf(label: &str, ndf: &dyn Ndf, wo: Vec3, m: Vec3) -> Result<(), TestCaseError> {
    let (d, pv, pn) = (ndf.d(m), ndf.pdf_visible(wo, m), ndf.pdf_normal(m));
    prop_assert!(
        pv.is_finite() && pv >= 0.0 && pn.is_finite() && pn >= 0.0,
        "{label}: wo {wo:?} m {m:?}: pdf_visible {pv:e}, pdf_normal {pn:e}"
    );
    if d == 0.0 {
        prop_assert!(
            pv == 0.0,
            "{label}: d({m:?}) = 0 but pdf_visible({wo:?}, m) = {pv:e}"
        );
        prop_assert!(pn == 0.0, "{label}: d({m:?}) = 0 but pdf_normal = {pn:e}");
    }
    if !(wo.is_finite() && wo.z > 0.0) {
        prop_assert!(
            pv == 0.0,
            "{label}: invalid wo {wo:?}: pdf_visible({m:?}) = {pv:e}"
        );
    }
    Ok(())
}

fn run_ndf_contract(ndfs: &[Named<'_>], cases: u32) {
    let mut runner = TestRunner::new(support::proptest_config(cases));
    runner
        .run(&(any_dir(), any_dir(), any::<[u16; 2]>()), |(wo, m, u)| {
            for (label, ndf) in ndfs {
                check_ndf(label, ndf.as_ref(), wo, m)?;
                // Also at the NDF's own draws from another view (where d > 0 is likely).
                // The far tails too (u.x = 2⁻³⁰: ~6.4 σ out, beyond the glint models' slope
                // truncations), where the samplers' Gaussians reach and a truncated D may not.
                let u = Vec2::new(u[0] as f32, u[1] as f32) / 65536.0;
                for u in [u, Vec2::new(2f32.powi(-30), u.y)] {
                    let drawn = ndf.sample_visible(Vec3::new(0.6, 0.0, 0.8), u);
                    check_ndf(label, ndf.as_ref(), wo, drawn)?;
                    check_ndf(label, ndf.as_ref(), wo, ndf.sample_normal(u))?;
                }
            }
            Ok(())
        })
        .unwrap();
    // Every invalid view at the NDF's mean-ish normals.
    for (label, ndf) in ndfs {
        for wo in invalid_dirs() {
            for m in [Vec3::Z, ndf.sample_normal(Vec2::splat(0.5))] {
                let p = ndf.pdf_visible(wo, m);
                assert_eq!(
                    p, 0.0,
                    "{label}: invalid wo {wo:?}: pdf_visible({m:?}) = {p:e}"
                );
            }
        }
    }
}

#[test]
fn analytic_ndf_pdfs_vanish_where_d_does() {
    run_ndf_contract(&analytic_ndfs(), 400);
}

#[test]
fn glint_patch_pdfs_vanish_where_d_does() {
    let models = Models::build();
    run_ndf_contract(&glint_patches(&models), 60);
}

/// The issue's three examples, as they were reported.
#[test]
fn issue_cases() {
    let models = Models::build();
    let flat =
        models
            .bin_map_flat
            .patch_with(&footprint(16.0, 1), &binmap::PatchOptions::default(), None);
    assert_eq!(flat.pdf_visible(Vec3::X, Vec3::Z), 0.0);
    let steep = models.position_normal_steep.patch_with(
        &footprint(1.0, 1),
        &position_normal::PatchOptions::default(),
        None,
    );
    assert_eq!(steep.d(Vec3::Z), 0.0);
    assert_eq!(steep.pdf_visible(Vec3::Z, Vec3::Z), 0.0);
    let lobe =
        SlopeGaussian::new(Vec2::new(1e4, 0.0), Mat2::from_diagonal(Vec2::splat(1e-8))).unwrap();
    for c in [1e-2f32, 1e-4, 1e-6] {
        let wo = Vec3::new(-(1.0 - c * c).sqrt(), 0.0, c);
        for k in 0..64 {
            let m = lobe.sample_visible(wo, Vec2::new((k as f32 + 0.5) / 64.0, 0.37));
            if lobe.d(m) == 0.0 {
                assert_eq!(lobe.pdf_visible(wo, m), 0.0, "wo {wo:?} m {m:?}");
            }
        }
    }
}

/// The mixture's patches: the same contract. `pdf_normal` and `pdf_visible` of the mixture sum its
/// lobes without the slope-box truncation that `d` applies, so they are 0 where `d` is by an
/// explicit check (src/glint/mixture/patch.rs).
#[test]
fn mixture_patch_pdfs_vanish_where_d_does() {
    let map = bumpy(16, 16, 0.3, 3.0, 5).unwrap();
    let quick = MixtureParams {
        samples: 16,
        ..MixtureParams::default()
    };
    let bumpy_mixture = BeckmannMixture::build(&map, quick).unwrap();
    let mut patches: Vec<(String, &BeckmannMixture, MixtureOptions)> = Vec::new();
    for masking in [MaskingMode::Exact, MaskingMode::Approximate] {
        let options = MixtureOptions {
            masking,
            ..MixtureOptions::default()
        };
        patches.push((format!("mixture {masking:?}"), &bumpy_mixture, options));
    }
    // A 2×2 map of isolated lobes, seen through sub-texel footprints: patches of one or two lobes,
    // whose truncated tails are not covered by any other lobe.
    let sparse = NormalMap::from_slopes(
        2,
        2,
        vec![
            Vec2::ZERO,
            Vec2::new(2.0, 0.0),
            Vec2::new(0.0, -3.0),
            Vec2::splat(1.0),
        ],
    )
    .unwrap();
    let sparse_mixture = BeckmannMixture::build(&sparse, quick).unwrap();
    patches.push((
        "mixture sparse".into(),
        &sparse_mixture,
        MixtureOptions::default(),
    ));
    let ndfs: Vec<Named<'_>> = patches
        .iter()
        .flat_map(|(label, m, options)| {
            let n = m.map_size().0;
            [0.25f32, 0.5, 8.0, 200.0].map(|t| -> Named<'_> {
                (
                    format!("{label} {t}"),
                    Box::new(m.patch_with(&footprint(t, n), options, None)),
                )
            })
        })
        .collect();
    run_ndf_contract(&ndfs, 60);
}

// ---------------------------------------------------------------------------------------------
// BRDFs: eval > 0 ⇒ pdf > 0
// ---------------------------------------------------------------------------------------------

/// A BRDF under test, with (for `MicrofacetBrdf`) its micronormal density at the half vector of
/// (wo, wi): where that density is subnormal the BRDF documents pdf = 0 (src/bxdf/microfacet.rs,
/// "Sample weights"), the one place where `eval` > 0 may meet `pdf` = 0.
struct Case<'a> {
    label: String,
    brdf: Box<dyn Bxdf + 'a>,
    micro: Option<Box<dyn Fn(Vec3, Vec3) -> f32 + 'a>>,
}

fn case<'a>(label: impl Into<String>, brdf: impl Bxdf + 'a) -> Case<'a> {
    Case {
        label: label.into(),
        brdf: Box::new(brdf),
        micro: None,
    }
}

/// A `MicrofacetBrdf` over `ndf` (no Fresnel) with the given sampler, and its micronormal density.
fn microfacet_case<'a, N: Ndf + Copy + 'a>(label: String, ndf: N, sampling: Sampling) -> Case<'a> {
    let density = move |wo: Vec3, wi: Vec3| {
        let h = (wo + wi).normalize();
        match sampling {
            Sampling::Normals => ndf.pdf_normal(h),
            Sampling::VisibleNormals => ndf.pdf_visible(wo, h),
        }
    };
    Case {
        label,
        brdf: Box::new(MicrofacetBrdf::new(ndf, NoFresnel).with_sampling(sampling)),
        micro: Some(Box::new(density)),
    }
}

/// The BRDF half of the contract at one (wo, wi) of unit directions.
fn check_brdf(c: &Case<'_>, wo: Vec3, wi: Vec3) -> Result<(), TestCaseError> {
    let (f, p) = c.brdf.eval_pdf(wo, wi);
    let label = &c.label;
    prop_assert!(
        f.is_finite() && f.min_element() >= 0.0 && p.is_finite() && p >= 0.0,
        "{label}: wo {wo:?} wi {wi:?}: f {f:?} pdf {p:e}"
    );
    let subnormal = c
        .micro
        .as_ref()
        .is_some_and(|m| m(wo, wi) < f32::MIN_POSITIVE);
    if f.max_element() > 0.0 && !subnormal {
        prop_assert!(
            p > 0.0,
            "{label}: wo {wo:?} wi {wi:?}: f {f:?} > 0 but pdf 0"
        );
    }
    Ok(())
}

fn run_brdf_contract(cases: &[Case<'_>], n: u32) {
    let mut runner = TestRunner::new(support::proptest_config(n));
    runner
        .run(
            &(unit_dir(), unit_dir(), any::<[u16; 3]>()),
            |(wo, wi, u)| {
                let u2 = Vec2::new(u[0] as f32, u[1] as f32) / 65536.0;
                let uc = u[2] as f32 / 65536.0;
                for c in cases {
                    check_brdf(c, wo, wi)?;
                    // The directions every other BRDF's sampler draws from this wo.
                    for other in cases {
                        if let Some(s) = other.brdf.sample(wo, uc, u2) {
                            check_brdf(c, wo, s.wi)?;
                        }
                    }
                }
                Ok(())
            },
        )
        .unwrap();
}

/// Every BRDF built on `ndf`: both samplers, and a layered coat (with Fresnel) over a base.
fn microfacet<'a, N: Ndf + Copy + 'a>(label: &str, ndf: N) -> Vec<Case<'a>> {
    let schlick = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    vec![
        microfacet_case(label.to_string(), ndf, Sampling::VisibleNormals),
        microfacet_case(format!("{label} normals"), ndf, Sampling::Normals),
        case(
            format!("{label} layered"),
            LayeredBrdf::new(MicrofacetBrdf::new(ndf, schlick), Vec3::splat(0.5)).unwrap(),
        ),
    ]
}

#[test]
fn classic_and_microfacet_brdfs_sample_where_they_reflect() {
    let mut cases: Vec<Case<'static>> = Vec::new();
    cases.extend(microfacet(
        "Beckmann 0.5",
        Beckmann::isotropic(0.5).unwrap(),
    ));
    cases.extend(microfacet("GGX 0.3/0.1", Ggx::new(0.3, 0.1).unwrap()));
    cases.extend(microfacet("Blinn-Phong 50", BlinnPhong::new(50.0).unwrap()));
    cases.extend(microfacet(
        "SlopeGaussian",
        SlopeGaussian::new(Vec2::new(0.5, -0.2), Mat2::from_diagonal(Vec2::splat(0.05))).unwrap(),
    ));
    cases.push(case("Lambert", Lambert::new(Vec3::splat(0.5)).unwrap()));
    for normalization in [
        PhongNormalization::Unnormalized,
        PhongNormalization::EnergyConserving,
    ] {
        let p = Phong::new(Vec3::splat(0.05), Vec3::splat(0.95), 20.0, normalization).unwrap();
        cases.push(case(format!("Phong {normalization:?}"), p));
        // The issue's case: Phong + Schlick at cos θo = 1e-7 had eval 7.6e-9 where pdf = 0.
        cases.push(case(
            format!("Phong + Schlick {normalization:?}"),
            p.with_schlick_fresnel(),
        ));
    }
    cases.push(case(
        "original Phong",
        OriginalPhong::new(
            Vec3::splat(0.3),
            Vec3::splat(0.6),
            20.0,
            OriginalPhongNormalization::EnergyConserving,
        )
        .unwrap(),
    ));
    cases.push(case(
        "Blinn-Phong lobe",
        BlinnPhongLobe::new(
            Vec3::splat(0.3),
            Vec3::splat(0.6),
            20.0,
            BlinnPhongNormalization::EnergyConserving,
        )
        .unwrap(),
    ));
    run_brdf_contract(&cases, 300);
}

/// The issue's Phong case: with Schlick's Fresnel at cos θo = 1e-7 the diffuse weight
/// ρ_d (1 − F) is ~10⁻⁸ of the specular one, the lobe probability rounded to 1 and the diffuse
/// directions outside the specular lobe had f ≈ 10⁻⁹ with pdf 0.
#[test]
fn phong_schlick_at_grazing_view() {
    let p = Phong::new(
        Vec3::splat(0.1),
        Vec3::splat(0.9),
        10.0,
        PhongNormalization::EnergyConserving,
    )
    .unwrap()
    .with_schlick_fresnel();
    let wo = Vec3::new((1.0f32 - 1e-14).sqrt(), 0.0, 1e-7);
    let mut positive = 0;
    for k in 0..100 {
        // wi on wo's side, away from the mirror lobe (wi · mirror(wo) < 0): only the diffuse term.
        let wi = support::dir(5.0 + k as f64 * 0.8, -60.0 + 1.2 * k as f64);
        let (f, pdf) = p.eval_pdf(wo, wi);
        positive += (f.max_element() > 0.0) as usize;
        assert!(
            f.max_element() == 0.0 || pdf > 0.0,
            "wi {wi:?}: f {f:?}, pdf {pdf:e}"
        );
    }
    assert!(positive > 0);
}

#[test]
fn glint_brdfs_sample_where_they_reflect() {
    let models = Models::build();
    let patches = glint_patches(&models);
    let pn = models.position_normal.patch_with(
        &footprint(8.0, 16),
        &position_normal::PatchOptions::default(),
        None,
    );
    let mut cases: Vec<Case<'_>> = Vec::new();
    for (label, patch) in &patches {
        let p: &dyn Ndf = patch.as_ref();
        cases.push(microfacet_case(label.clone(), p, Sampling::VisibleNormals));
        cases.push(microfacet_case(
            format!("{label} normals"),
            p,
            Sampling::Normals,
        ));
    }
    cases.push(case(
        "position-normal published",
        PositionNormalBrdf::new(&pn, NoFresnel),
    ));
    run_brdf_contract(&cases, 12);
}
