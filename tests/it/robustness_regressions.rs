//! Regression tests: one per finding of the property suites (tests/it/robustness_*.rs) and the fuzz
//! targets (fuzz/), each named by what it checks; the doc comment says what was found and fixed.

use crate::support;

use brdf::bxdf::{BlinnPhongNormalization, Masking};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, Footprint, GlintNdf, NormalMap, PositionNormalMap};
use brdf::ndf::{Beckmann, Ggx, Ndf, SlopeGaussian};
use brdf::{BlinnPhongLobe, Bxdf, Mat2, MicrofacetBrdf, Vec2, Vec3};
use support::robustness::{albedo, assert_energy, err_naming, small_bins};
use support::totality::check_ndf;

/// Found by `analytic_ndfs_are_total`: a finite but huge non-unit direction overflowed the GGX and
/// Beckmann visible areas (√(z² + n²) → ∞), and the default `projected_area` returned ∞ for w_z = ∞.
#[test]
fn regression_overflowing_directions_give_finite_areas() {
    let ggx = Ggx::isotropic(1.0).unwrap();
    let beckmann = Beckmann::isotropic(1.0).unwrap();
    for w in [
        Vec3::new(0.0, 0.0, 9.589_214e20),
        Vec3::new(-0.0, -1.256_735_1e23, 7.279_25e-29),
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ] {
        for ndf in [&ggx as &dyn Ndf, &beckmann] {
            assert!(ndf.visible_area(w).is_finite(), "{w}");
            assert!(ndf.projected_area(w).is_finite(), "{w}");
        }
    }
}

/// Found by `glint_models_are_total`: pdf_normal(m) = D(m)·m_z was 0·∞ = NaN for m = (0, 0, ∞), and
/// an f64 density cast to f32 overflowed to ∞.
#[test]
fn regression_pdf_normal_of_infinite_directions() {
    let map = NormalMap::from_slopes(1, 2, vec![Vec2::ZERO, Vec2::new(0.3, 0.0)]).unwrap();
    let fp = Footprint::from_differentials(Vec2::ZERO, Vec2::ZERO, Vec2::ZERO);
    let mixture = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
    for m in [
        Vec3::new(0.0, 0.0, f32::INFINITY),
        Vec3::new(0.0, -0.0, 4.839_110_6e37),
    ] {
        // The gathered mixture, where the regression was found (a zero footprint is otherwise
        // served by the sub-texel lobe, a single Gaussian: checked total below).
        let gathered = brdf::glint::mixture::PatchOptions {
            sub_texel_area: 0.0,
            ..Default::default()
        };
        assert_eq!(
            mixture.patch_with(&fp, &gathered, None).pdf_normal(m),
            0.0,
            "{m}"
        );
        let p = mixture.patch(&fp).pdf_normal(m);
        assert!(p.is_finite() && p >= 0.0, "{m}: {p}");
        let p = pn.patch(&fp).pdf_normal(m);
        assert!(p.is_finite() && p >= 0.0, "{m}: {p}");
    }
}

/// Found by `analytic_ndfs_are_total`: at cos θo ~ 10⁻⁴⁵ a microfacet sample had a finite f and pdf
/// but an infinite weight f cos θi / pdf; `BxdfSample::checked` now refuses such samples.
#[test]
fn regression_sample_weights_are_finite_at_extreme_grazing() {
    let wo = Vec3::new(-5.078_027_8e17, 0.0, 1.656_807_4e-27).normalize();
    let brdf = MicrofacetBrdf::new(Beckmann::isotropic(1.0).unwrap(), NoFresnel);
    let mut kept = 0;
    for k in 0..4096 {
        let u = Vec2::new((k % 64) as f32 / 64.0, (k / 64) as f32 / 64.0);
        if let Some(s) = brdf.sample(wo, 0.5, u) {
            assert!(s.weight().is_finite(), "{s:?}");
            kept += 1;
        }
    }
    // Not vacuous: most draws still give a (finite) sample; only the overflowing ones are refused.
    assert!(kept > 2048, "{kept} of 4096 draws kept");
}

/// Found by `analytic_energy_at_most_one`: the Blinn-Phong lobe's pdf took wo·h from the dot product,
/// which cancels where the sampler's reflection gives wi ≈ −wo (cos θo = 6·10⁻⁷); the estimate of the
/// albedo read 1.48 for a true 0.025. `frame::half_vector_cos` takes ‖wo + wi‖/2 instead.
#[test]
fn regression_blinn_phong_pdf_at_grazing_reflection() {
    let wo = Vec3::new(0.515_122_5, -0.857_116_6, 6.0263e-7).normalize();
    let b = BlinnPhongLobe::new(
        Vec3::splat(0.023_604_814),
        Vec3::splat(1.0 - 0.023_604_814),
        850.551_2,
        BlinnPhongNormalization::EnergyConserving,
    )
    .unwrap();
    let cos = |w: Vec3| w.z.max(0.0);
    assert_energy("blinn-phong lobe at cos θo = 6e-7", albedo(&b, wo, &cos));
    // wi = −wo + a tiny upward tilt: c = ‖wo + wi‖/2, not the cancelled dot product.
    let wi = Vec3::new(-wo.x, -wo.y, 4.287_358e-5).normalize();
    let (h, c) = brdf::frame::half_vector_cos(wo, wi).unwrap();
    assert!(
        c > 0.0 && (c - 0.5 * (wo + wi).length()).abs() <= 1e-6 * c,
        "{h} {c}"
    );
}

/// Found by `glint_energy_at_most_one`: the bin map's exact masking replaced each bin by its centre
/// direction, which under-counts V where w's horizon cuts the bin: white furnace 1.80 ± 0.03 at
/// θo = 89.07° on a flat 1×1 map with 15² bins. Also the smoothed variant and the position-normal
/// patch (masking of the wrong lobe): furnace 1.25 and 1.42 at grazing angles on the bumpy map
/// (docs/robustness.md, grazing sweep).
#[test]
fn regression_glint_furnaces_at_grazing_angles() {
    let flat = NormalMap::from_slopes(1, 1, vec![Vec2::ZERO]).unwrap();
    let bins = BinMap::build(&flat, small_bins()).unwrap();
    let fp = Footprint::from_differentials(Vec2::ZERO, Vec2::ZERO, Vec2::ZERO);
    let patch = bins.patch(&fp);
    let wo = Vec3::new(0.999_869_17, 0.0, 0.016_174_955);
    let cos = |w: Vec3| w.z.max(0.0);
    let b = MicrofacetBrdf::new(&patch, NoFresnel).with_masking(Masking::Separable);
    assert_energy("flat 1×1 bin map at 89.07°", albedo(&b, wo, &cos));

    // The grazing sweep's configuration (examples/common/grazing.rs): bumpy 256², 64 texels.
    let bumpy = brdf::glint::bumpy(256, 256, 0.25, 4.0, 1).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 64.0, 256, 256);
    let bin_map = BinMap::build(&bumpy, BinMapParams::default()).unwrap();
    let pn = PositionNormalMap::build(&bumpy, PositionNormalParams::default()).unwrap();
    let (smoothed, pnp) = (
        bin_map.patch_with(
            &fp,
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: 0.1,
                ..Default::default()
            },
            None,
        ),
        pn.patch(&fp),
    );
    for theta in [85.0, 89.0, 89.9] {
        let wo = support::dir(theta, 30.0);
        for (name, patch) in [
            ("smoothed bin map", &smoothed as &dyn Ndf),
            ("position-normal", &pnp),
        ] {
            let b = MicrofacetBrdf::new(patch, NoFresnel);
            assert_energy(&format!("{name} at {theta}°"), albedo(&b, wo, &cos));
        }
    }
}

/// Found by the `analytic` fuzz target: a slope Gaussian of mean 1.3·10³⁶ was accepted, and its
/// visible-normal sampler returned a non-unit vector (slope squares overflow). Means beyond
/// `ndf::MAX_SLOPE` are now refused, and `from_moments` falls back.
#[test]
fn regression_slope_gaussian_mean_is_bounded() {
    let mean = Vec2::splat(1.305_771e36);
    err_naming(SlopeGaussian::new(mean, Mat2::IDENTITY), "mean");
    err_naming(
        SlopeGaussian::new(Vec2::ZERO, Mat2::from_diagonal(Vec2::splat(1e9))),
        "cov",
    );
    let sg = SlopeGaussian::from_moments([1.3e36, 1.3e36, 1.0, 1.0, 0.0], 0.01);
    assert_eq!(sg.mean(), Vec2::ZERO);
    let ok = SlopeGaussian::new(Vec2::splat(brdf::ndf::MAX_SLOPE), Mat2::IDENTITY).unwrap();
    check_ndf(
        &ok,
        Vec3::new(0.0, 1.258_146_3e-38, 2.2e-44),
        Vec3::Z,
        0.5,
        Vec2::splat(0.5),
    );
}

/// Found by the `analytic` and `glint_mixture` fuzz targets: the slope Gaussian's visible-normal
/// sampler fell back to returning wo itself, which is not a unit normal when the caller's wo is not
/// unit (here of length ~10⁻¹⁸).
#[test]
fn regression_visible_sampler_fallback_is_unit() {
    let sg = SlopeGaussian::new(
        Vec2::new(0.0, 7.968_867),
        Mat2::from_cols_array(&[1.0e-4, 0.0, 0.0, 1.0e-4]),
    )
    .unwrap();
    let wo = Vec3::new(5.455_156_4e-19, 5.459_277e-19, 5.458_350_3e-19);
    let one_minus = 1.0 - f32::EPSILON / 2.0;
    for u in [
        Vec2::ZERO,
        Vec2::new(9.1963e-41, -8.374_822e21),
        Vec2::splat(one_minus),
    ] {
        support::totality::unit_upper("sample_visible", sg.sample_visible(wo, u));
    }
}

/// Found by the `analytic` fuzz target: GGX with α_y = 3.5·10¹³ sampled a "normal" of length 0.99 at a
/// grazing view (the stretched vector's z underflows against α-scaled x, y). α above
/// `ndf::MAX_ALPHA` = 10⁴ is now refused; at the bound the sampler stays unit.
#[test]
fn regression_alpha_is_bounded() {
    err_naming(Ggx::new(1.5e-36, 3.518_437_2e13), "alpha_y");
    err_naming(Beckmann::isotropic(2e4), "alpha");
    let wo = Vec3::new(-1.399_769_2e-12, 0.0, 6.428_48e-40);
    let u = Vec2::new(3.761_582e-37, 1.401_877_2e14);
    for ndf in [
        &Ggx::new(1.5e-36, brdf::ndf::MAX_ALPHA).unwrap() as &dyn Ndf,
        &Beckmann::new(1.5e-36, brdf::ndf::MAX_ALPHA).unwrap(),
    ] {
        check_ndf(ndf, wo, Vec3::Z, 0.0, u);
    }
}

/// Found by the `glint_mixture` fuzz target: the slope Gaussian's facing fallback normalised a wo of
/// length 2·10⁻²² (squared length subnormal in f32) to length 0.99.
#[test]
fn regression_tiny_wo_normalises_exactly() {
    let sg = SlopeGaussian::new(
        Vec2::new(0.0, 8319.8),
        Mat2::from_diagonal(Vec2::splat(1e-4)),
    )
    .unwrap();
    let wo = Vec3::splat(1.283_005_8e-22);
    let one_minus = 1.0 - f32::EPSILON / 2.0;
    for u in [
        Vec2::new(1.283_005_8e-22, -3.146_53e-24),
        Vec2::ZERO,
        Vec2::splat(one_minus),
    ] {
        support::totality::unit_upper("sample_visible", sg.sample_visible(wo, u));
    }
}

/// Found by the `analytic` fuzz target (third run): GGX's visible sampler at α = 10⁻⁴ (the clamp),
/// u = (1, 1) and a view along the normal built a half vector of length ~10⁻²⁰, whose squared length
/// is subnormal: the normalised "normal" had length 0.92. `frame::normalize_robust` rescales first.
#[test]
fn regression_ggx_visible_sampler_at_min_alpha() {
    let ggx = Ggx::new(5e-44, 4e-45).unwrap();
    let wo = Vec3::new(-0.000_354_243_27, -3.072_570_3e-22, 12_689.568).normalize();
    for u in [
        Vec2::ONE,
        Vec2::new(0.0, 0.249),
        Vec2::new(6.745_882e32, 12_680.249),
    ] {
        support::totality::unit_upper("sample_visible", ggx.sample_visible(wo, u));
    }
    for v in [
        Vec3::splat(1e-25),
        Vec3::new(3e30, -4e30, 0.0),
        Vec3::new(0.0, 1e-41, 1e-42),
    ] {
        let n = brdf::frame::normalize_robust(v).unwrap();
        assert!((n.length() - 1.0).abs() < 1e-6, "{v} -> {n}");
    }
    assert!(brdf::frame::normalize_robust(Vec3::ZERO).is_none());
    assert!(brdf::frame::normalize_robust(Vec3::splat(f32::NAN)).is_none());
}

/// Found by the `store_procedural` fuzz target (first run): the projected area of a set of lobes
/// (`LobeSet`, src/glint/kernels/lobe_set.rs: procedural patches, the mixture's filtered mixtures)
/// is cos θ − w_xy·μ, and for a finite but huge non-unit w (w_y = −2.5·10³⁸) against a leaning
/// mean (μ_y ≈ 1.9, a surface of α_y = 1.5 under a footprint that gathers one cell) the product
/// overflowed to ∞. It is now 0 where it is not finite, as for invalid w; finite values unchanged.
#[test]
fn regression_lobe_set_projected_area_of_huge_directions() {
    use brdf::glint::procedural::{PatchOptions, ProceduralGlints, ProceduralParams};
    let surface = ProceduralGlints::new(ProceduralParams {
        alpha: Vec2::new(0.045_605_47, 1.515_625),
        facet_alpha: 0.01,
        density: 0.2,
        resolution: [48, 16],
        seed: 5_927_300_059_587_086_911,
        ..ProceduralParams::default()
    })
    .unwrap();
    let fp = Footprint::from_differentials(
        Vec2::new(3.993_029_2e-35, 2.407_412_4e-35),
        Vec2::new(1.77e-43, 0.0),
        Vec2::new(-107_479_040.0, 6.648_12e-40),
    );
    let (wo, wi) = (
        Vec3::new(0.0, 0.000_171_661_42, f32::NAN),
        Vec3::new(0.0, -2.525_533_2e38, 1.0374e-41),
    );
    for tolerance in [PatchOptions::default().tolerance, 0.5] {
        let patch = surface.patch_with(&fp, &PatchOptions { tolerance }, None);
        assert!(
            patch.projected_area(wi).is_finite(),
            "tolerance {tolerance}"
        );
        check_ndf(
            &patch,
            wo,
            wi,
            -3.283_520_2e21,
            Vec2::new(2.475_797_3e-14, f32::NAN),
        );
    }
}
