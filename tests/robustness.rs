//! Hardening (docs/robustness.md): every public model under bad input and at the numerical edges.
//!
//! - Property suites over the public API: arbitrary directions (NaN, ±∞, zero-length, unnormalised,
//!   cos θ down to 1e-7, wo = ±wi, wo = wi = n), random numbers (any f32, 0, 1 − ε), parameters over
//!   their whole valid range (α from 1e-4 to 10, near-singular covariances), and the glint models on
//!   empty-to-tiny, 1×N, non-square, non-power-of-two, flat and extremely rough maps seen through zero,
//!   NaN, huge, far-away and extremely anisotropic footprints. Every value must be finite and ≥ 0, every
//!   sample must carry a positive pdf (tests/support/totality.rs, shared with the fuzz targets).
//! - Energy ≤ 1 for the physically based models, estimated by their own samplers on random cases.
//! - The outcome table of docs/robustness.md, asserted row by row (`documented_outcomes`).
//! - Regression tests for what the fuzz targets found.

mod support;

use brdf::bxdf::{
    BlinnPhongNormalization, Masking, OriginalPhongNormalization, PhongNormalization, Sampling,
};
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, NoFresnel, SchlickFresnel};
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, BinMapPatch, Footprint, GlintNdf, NormalMap, NormalRepair,
    PositionNormalBrdf, PositionNormalMap, TangentConvention,
};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};
use brdf::{
    BlinnPhongLobe, Bxdf, Error, Lambert, Mat2, MicrofacetBrdf, OriginalPhong, Phong, Vec2, Vec3,
};
use proptest::prelude::*;
use support::totality::{check_bxdf, check_ndf};

/// The smoothed bin-map patch through the one query path (`patch_with` and the bin map's options).
trait Smoothed {
    fn patch_smoothed(&self, fp: &Footprint, alpha: f32) -> BinMapPatch<'_>;
}

impl Smoothed for BinMap {
    fn patch_smoothed(&self, fp: &Footprint, alpha: f32) -> BinMapPatch<'_> {
        let options = brdf::glint::binmap::PatchOptions {
            smoothing_alpha: alpha,
        };
        self.patch_with(fp, &options, None)
    }
}

// ---------------------------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------------------------

/// A unit direction with cos θ log-uniform in [1e-7, 1] (grazing angles well represented).
fn grazing_dir() -> impl Strategy<Value = Vec3> {
    grazing_dir_from(1e-7)
}

/// A unit direction with cos θ log-uniform in [min_cos, 1].
fn grazing_dir_from(min_cos: f32) -> impl Strategy<Value = Vec3> {
    (min_cos.log10()..=0.0, 0.0f32..std::f32::consts::TAU).prop_map(|(log_cos, phi)| {
        let c = 10f32.powf(log_cos);
        let s = (1.0 - c * c).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    })
}

/// Any direction a caller could pass: valid and grazing, below the horizon, exactly on it,
/// unnormalised, zero-length, NaN or infinite components.
fn any_dir() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        4 => grazing_dir(),
        1 => grazing_dir().prop_map(|w| Vec3::new(w.x, w.y, -w.z)),
        1 => (proptest::num::f32::ANY, proptest::num::f32::ANY, proptest::num::f32::ANY)
            .prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        1 => prop::sample::select(vec![
            Vec3::ZERO,
            Vec3::Z,
            Vec3::X,
            -Vec3::Z,
            Vec3::new(0.0, 0.0, 1e-30),
            Vec3::new(3.0, -2.0, 5.0),
            Vec3::splat(f32::NAN),
            Vec3::new(0.0, 0.0, f32::INFINITY),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
        ]),
    ]
}

/// Random numbers: in [0, 1) mostly, with 0, 1 − ε, 1, negative, NaN and ∞.
fn any_u() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => 0.0f32..1.0,
        1 => prop::sample::select(vec![
            0.0,
            1.0 - f32::EPSILON / 2.0,
            1.0,
            -0.25,
            7.5,
            f32::NAN,
            f32::INFINITY,
        ]),
    ]
}

/// α log-uniform over [1e-4, 10], the range (and the crate's clamp at the low end).
fn any_alpha() -> impl Strategy<Value = f32> {
    (-4.0f32..=1.0).prop_map(|e| 10f32.powf(e))
}

/// A map of 1 to 9 texels per side (1×N, N×1, non-square, non-power-of-two): flat, random with an
/// RMS slope from 1e-3 to 1e3 (extremely rough), a single spike of slope length 0.99e4 (MAX_SLOPE = 1e4 is the largest accepted),
/// or a tilted plane.
fn any_map() -> impl Strategy<Value = NormalMap> {
    (1usize..=9, 1usize..=9, 0u8..4, -3.0f32..=3.0, any::<u64>()).prop_map(
        |(w, h, kind, log_scale, seed)| {
            let scale = 10f32.powf(log_scale);
            let mut state = seed | 1;
            let mut next = move || {
                // xorshift64*: a tiny deterministic generator, enough to scatter slopes.
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                ((state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32)
                    * 2.0
                    - 1.0
            };
            let slopes: Vec<Vec2> = (0..w * h)
                .map(|k| match kind {
                    0 => Vec2::ZERO,
                    1 => Vec2::new(next(), next()) * scale,
                    2 if k == 0 => Vec2::new(0.7, -0.7) * brdf::glint::MAX_SLOPE,
                    2 => Vec2::ZERO,
                    _ => Vec2::new(scale.min(50.0), -0.5),
                })
                .collect();
            NormalMap::from_slopes(w, h, slopes).expect("finite slopes within MAX_SLOPE")
        },
    )
}

/// Footprints from ray differentials of every kind: ordinary, zero, sub-texel, larger than the map,
/// NaN or infinite, extremely anisotropic, centred far outside [0, 1)².
fn any_footprint() -> impl Strategy<Value = Footprint> {
    let diff = prop_oneof![
        4 => (-0.5f32..0.5, -0.5f32..0.5).prop_map(|(x, y)| Vec2::new(x, y)),
        1 => prop::sample::select(vec![
            Vec2::ZERO,
            Vec2::new(1e-9, 0.0),
            Vec2::new(1e6, -1e6),
            Vec2::new(f32::NAN, 0.1),
            Vec2::new(f32::INFINITY, 0.0),
            Vec2::new(1.0, 1e-7),
        ]),
    ];
    let uv = prop_oneof![
        4 => (0.0f32..1.0, 0.0f32..1.0).prop_map(|(x, y)| Vec2::new(x, y)),
        1 => prop::sample::select(vec![
            Vec2::new(-1e6, 3e7),
            Vec2::new(f32::NAN, 0.5),
            Vec2::new(f32::INFINITY, f32::NEG_INFINITY),
            Vec2::new(123.456, -0.75),
        ]),
    ];
    (uv, diff.clone(), diff).prop_map(|(uv, dx, dy)| Footprint::from_differentials(uv, dx, dy))
}

// ---------------------------------------------------------------------------------------------
// Totality of the analytic models and classic BRDFs
// ---------------------------------------------------------------------------------------------

fn microfacet_variants<'a, D: Ndf + Copy + 'a>(
    ndf: D,
    f0: f32,
    eta: f32,
) -> Vec<Box<dyn Bxdf + 'a>> {
    let mut v: Vec<Box<dyn Bxdf + 'a>> = vec![];
    for sampling in [Sampling::Normals, Sampling::VisibleNormals] {
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let base = MicrofacetBrdf::new(ndf, NoFresnel)
                .with_sampling(sampling)
                .with_masking(masking);
            v.push(Box::new(base));
            let schlick = SchlickFresnel::new(Vec3::splat(f0)).unwrap();
            v.push(Box::new(
                MicrofacetBrdf::new(ndf, schlick)
                    .with_sampling(sampling)
                    .with_masking(masking),
            ));
        }
    }
    v.push(Box::new(MicrofacetBrdf::new(
        ndf,
        DielectricFresnel::new(eta).unwrap(),
    )));
    v.push(Box::new(MicrofacetBrdf::new(
        ndf,
        ConductorFresnel::new(Vec3::new(0.2, eta, 1.1), Vec3::new(3.9, 2.4, 0.0)).unwrap(),
    )));
    v
}

proptest! {
    #![proptest_config(support::proptest_config(400))]

    /// Beckmann, GGX, Blinn-Phong and the slope Gaussian as NDFs and inside every microfacet BRDF
    /// configuration (both samplers, both G2 forms, four Fresnel terms), α over [1e-4, 10].
    #[test]
    fn analytic_ndfs_are_total(
        ax in any_alpha(), ay in any_alpha(), gamma in 0.0f32..1e6,
        mx in -3.0f32..3.0, my in -3.0f32..3.0, log_sx in -4.0f32..1.0, log_sy in -4.0f32..1.0,
        rho in -1.0f32..=1.0, f0 in 0.0f32..=1.0, eta in 1e-3f32..10.0,
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        let (sx, sy) = (10f32.powf(log_sx), 10f32.powf(log_sy));
        // |ρ| up to 1: the covariance may be singular; the infallible moment constructor floors it.
        let c = rho * sx * sy;
        let sg = SlopeGaussian::from_moments(
            [mx, my, sx * sx + mx * mx, sy * sy + my * my, c + mx * my],
            brdf::ndf::DEFAULT_SIGMA_MIN,
        );
        let beckmann = Beckmann::new(ax, ay).unwrap();
        let ggx = Ggx::new(ax, ay).unwrap();
        let blinn = BlinnPhong::new(gamma).unwrap();
        let ndfs: [&dyn Ndf; 4] = [&beckmann, &ggx, &blinn, &sg];
        for ndf in ndfs {
            check_ndf(ndf, wo, wi, uc, u);
        }
        for b in microfacet_variants(beckmann, f0, eta)
            .into_iter()
            .chain(microfacet_variants(ggx, f0, eta))
            .chain(microfacet_variants(blinn, f0, eta))
            .chain(microfacet_variants(sg, f0, eta))
        {
            check_bxdf(b.as_ref(), wo, wi, uc, u);
        }
    }

    /// Lambert, every Phong normalisation (with and without Fresnel), original Phong and the
    /// Blinn-Phong lobe, γ over [0, 10⁴] (Arvo: integer γ ≤ 2000), albedos on the energy boundary.
    #[test]
    fn classic_brdfs_are_total(
        rho_d in 0.0f32..=1.0, split in 0.0f32..=1.0, gamma in 0.0f32..1e4,
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        let (d, s) = (Vec3::splat(rho_d), Vec3::splat((1.0 - rho_d) * split));
        check_bxdf(&Lambert::new(d).unwrap(), wo, wi, uc, u);
        for norm in [
            PhongNormalization::Unnormalized,
            PhongNormalization::EnergyConservingOriginal,
            PhongNormalization::EnergyConserving,
            PhongNormalization::EnergyNormalizedArvo,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        ] {
            let g = if norm == PhongNormalization::EnergyNormalizedArvo { gamma.round().min(2000.0) } else { gamma };
            let p = Phong::new(d, s, g, norm).unwrap();
            check_bxdf(&p, wo, wi, uc, u);
            check_bxdf(&p.with_schlick_fresnel(), wo, wi, uc, u);
        }
        for norm in [OriginalPhongNormalization::Unnormalized, OriginalPhongNormalization::EnergyConserving] {
            check_bxdf(&OriginalPhong::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u);
        }
        for norm in [BlinnPhongNormalization::RealTimeRendering, BlinnPhongNormalization::EnergyConserving] {
            check_bxdf(&BlinnPhongLobe::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Totality of the glint models
// ---------------------------------------------------------------------------------------------

/// Few QMC nodes: the build's accuracy does not matter here, its totality does.
fn quick_mixture_params(masking: MaskingMode, lod_lobes: f32) -> MixtureParams {
    MixtureParams {
        samples: 16,
        patch: PatchOptions {
            masking,
            lod_lobes,
            ..PatchOptions::default()
        },
        ..MixtureParams::default()
    }
}

fn small_bins() -> BinMapParams {
    BinMapParams {
        bins_per_axis: 15,
        ..BinMapParams::default()
    }
}

proptest! {
    #![proptest_config(support::proptest_config(160))]

    /// Every glint model (mixture with exact, approximate and level-of-detail terms; bin map plain and
    /// smoothed; position-normal Gaussians) built on degenerate and extreme maps, patched through
    /// degenerate footprints, queried with arbitrary directions: as an NDF, inside `MicrofacetBrdf`,
    /// and (position-normal) in its published BRDF.
    #[test]
    fn glint_models_are_total(
        map in any_map(), footprint in any_footprint(), smoothing in any_alpha(),
        wo in any_dir(), wi in any_dir(), uc in any_u(), u0 in any_u(), u1 in any_u(),
    ) {
        let u = Vec2::new(u0, u1);
        for (masking, lod) in [
            (MaskingMode::Exact, f32::INFINITY),
            (MaskingMode::Approximate, f32::INFINITY),
            (MaskingMode::Exact, 0.0),
        ] {
            let mixture = BeckmannMixture::build(&map, quick_mixture_params(masking, lod)).unwrap();
            let patch = mixture.patch(&footprint);
            check_ndf(&patch, wo, wi, uc, u);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        }
        let bin_map = BinMap::build(&map, small_bins()).unwrap();
        for patch in [bin_map.patch(&footprint), bin_map.patch_smoothed(&footprint, smoothing)] {
            check_ndf(&patch, wo, wi, uc, u);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        }
        let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
        let patch = pn.patch(&footprint);
        check_ndf(&patch, wo, wi, uc, u);
        check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
        check_bxdf(&PositionNormalBrdf::new(&patch, NoFresnel), wo, wi, uc, u);
    }
}

// ---------------------------------------------------------------------------------------------
// Energy ≤ 1 for the physically based models
// ---------------------------------------------------------------------------------------------

/// Samples per energy estimate: the standard error of a mean of weights ≤ w_max is ≤ w_max/√N.
const ENERGY_SAMPLES: u32 = 4096;

/// The albedo ∫ f c(wi) dωi estimated with the BRDF's own sampler over a stratified 64 × 64 grid of
/// `u` (one `uc` sequence), where c is `cosine(wi)` (cos θi, or a glint patch's A_P(wi)⁺), with its
/// standard error. A sampler that returns `None` contributes 0 (lost mass only lowers the estimate).
fn albedo(brdf: &dyn Bxdf, wo: Vec3, cosine: &dyn Fn(Vec3) -> f32) -> (f64, f64) {
    let n = (ENERGY_SAMPLES as f64).sqrt() as u32;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for k in 0..ENERGY_SAMPLES {
        let (i, j) = (k % n, k / n);
        let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
        let uc = ((k as f64 * 0.618_033_988_749_894_9).fract()) as f32;
        let x = brdf
            .sample(wo, uc, u)
            .map_or(0.0, |s| (s.f.max_element() * cosine(s.wi) / s.pdf) as f64);
        sum += x;
        sum2 += x * x;
    }
    let m = sum / ENERGY_SAMPLES as f64;
    let var = (sum2 / ENERGY_SAMPLES as f64 - m * m).max(0.0);
    (m, (var / ENERGY_SAMPLES as f64).sqrt())
}

/// The bound every energy assertion uses: 1 + 4 standard errors (the family below runs a few
/// hundred estimates; 4σ keeps a false alarm below 10⁻⁴ per estimate for a Gaussian mean, and
/// stratified draws make the plain standard error conservative) + 1e-4 for f32 evaluation of f and
/// pdf (a few ulps each, relative) summed over the samples.
fn assert_energy(what: &str, (e, err): (f64, f64)) {
    assert!(e.is_finite() && e >= 0.0, "{what}: albedo {e}");
    assert!(
        e <= 1.0 + 4.0 * err + 1e-4,
        "{what}: albedo {e} ± {err} > 1"
    );
}

proptest! {
    #![proptest_config(support::proptest_config(48))]

    /// ∫ f cos θi ≤ 1 for the analytic microfacet BRDFs (F = 1, both G2 forms, D cos sampling so that
    /// the sample weights vary), Lambert, the energy-conserving and energy-normalised Phong and the
    /// energy-conserving Blinn-Phong lobe, with ρd + ρs ≤ 1, θo up to 89.99°.
    #[test]
    fn analytic_energy_at_most_one(
        alpha in any_alpha(), aniso in 0.25f32..=1.0, gamma in 0.0f32..1e3,
        rho_d in 0.0f32..=1.0, wo in grazing_dir(),
    ) {
        let cos = |w: Vec3| w.z.max(0.0);
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let b = MicrofacetBrdf::new(Beckmann::new(alpha, alpha * aniso).unwrap(), NoFresnel)
                .with_masking(masking)
                .with_sampling(Sampling::Normals);
            assert_energy(&format!("beckmann α={alpha} {masking:?} wo={wo}"), albedo(&b, wo, &cos));
            let g = MicrofacetBrdf::new(Ggx::new(alpha, alpha * aniso).unwrap(), NoFresnel)
                .with_masking(masking)
                .with_sampling(Sampling::Normals);
            assert_energy(&format!("ggx α={alpha} {masking:?} wo={wo}"), albedo(&g, wo, &cos));
        }
        let (d, s) = (Vec3::splat(rho_d), Vec3::splat(1.0 - rho_d));
        assert_energy("lambert", albedo(&Lambert::new(Vec3::ONE).unwrap(), wo, &cos));
        for norm in [
            PhongNormalization::EnergyConservingOriginal,
            PhongNormalization::EnergyConserving,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        ] {
            let p = Phong::new(d, s, gamma, norm).unwrap();
            assert_energy(&format!("phong {norm:?} γ={gamma} wo={wo}"), albedo(&p, wo, &cos));
        }
        let b = BlinnPhongLobe::new(d, s, gamma, BlinnPhongNormalization::EnergyConserving).unwrap();
        assert_energy(&format!("blinn-phong lobe γ={gamma} wo={wo}"), albedo(&b, wo, &cos));
    }

    /// ∫ f cos θi ≤ 1 with the geometric cosine (the renderer's measure, README "Conventions") for
    /// `MicrofacetBrdf` over the mixture with exact and approximate terms, the bin map (plain and
    /// smoothed) and the position-normal patch, on random maps and footprints, θo up to 89.9°, both
    /// G2 forms. The published position-normal BRDF (the baseline's known error) is left out.
    #[test]
    fn glint_energy_at_most_one(
        map in any_map(), footprint in any_footprint(), smoothing in 0.01f32..1.0,
        wo in grazing_dir_from(1.75e-3), // θo ≤ 89.9°
    ) {
        let mixture = BeckmannMixture::build(&map, quick_mixture_params(MaskingMode::Exact, f32::INFINITY)).unwrap();
        let approximate = PatchOptions { masking: MaskingMode::Approximate, lod_lobes: f32::INFINITY, ..PatchOptions::default() };
        let bin_map = BinMap::build(&map, small_bins()).unwrap();
        let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
        let (mix, mix_approx, bins, smoothed, pnp) = (
            mixture.patch(&footprint),
            mixture.patch_with(&footprint, &approximate, None),
            bin_map.patch(&footprint),
            bin_map.patch_smoothed(&footprint, smoothing),
            pn.patch(&footprint),
        );
        let patches: [(&str, &dyn Ndf); 5] = [
            ("mixture", &mix), ("mixture approximate", &mix_approx), ("bin map", &bins),
            ("smoothed bin map", &smoothed), ("position-normal", &pnp),
        ];
        let cos = |w: Vec3| w.z.max(0.0);
        for (name, patch) in patches {
            for masking in [Masking::Separable, Masking::HeightCorrelated] {
                let b = MicrofacetBrdf::new(patch, NoFresnel).with_masking(masking);
                assert_energy(&format!("{name} {masking:?} wo={wo}"), albedo(&b, wo, &cos));
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The outcome table of docs/robustness.md
// ---------------------------------------------------------------------------------------------

/// The error's message, or "Ok".
fn outcome<T>(r: Result<T, Error>) -> String {
    match r {
        Ok(_) => "Ok".into(),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `r` is an error whose message contains `needle`.
fn err_naming<T>(r: Result<T, Error>, needle: &str) {
    let o = outcome(r);
    assert!(
        o != "Ok" && o.contains(needle),
        "expected an error naming `{needle}`, got {o}"
    );
}

/// One row of docs/robustness.md's constructor table: the input as written there, the outcome
/// (`outcome` of the constructor), and what it must be: `Some(needle)` an error whose message
/// names `needle`, `None` an `Ok`.
struct Case {
    input: String,
    outcome: String,
    expect: Option<&'static str>,
}

fn case<T>(input: impl Into<String>, r: Result<T, Error>, expect: Option<&'static str>) -> Case {
    Case {
        input: input.into(),
        outcome: outcome(r),
        expect,
    }
}

/// Every constructor input of docs/robustness.md (and a few more per parameter), once: asserted by
/// `documented_outcomes`, printed by `outcome_table`.
fn constructor_cases() -> Vec<Case> {
    let nan = f32::NAN;
    let mut v = vec![];
    // Analytic NDFs.
    for a in [0.0, -1.0, nan, f32::INFINITY, 2e4] {
        v.push(case(
            format!("Beckmann::new({a}, 0.5)"),
            Beckmann::new(a, 0.5),
            Some("alpha_x"),
        ));
        v.push(case(
            format!("Ggx::new(0.5, {a})"),
            Ggx::new(0.5, a),
            Some("alpha_y"),
        ));
        v.push(case(
            format!("Beckmann::isotropic({a})"),
            Beckmann::isotropic(a),
            Some("alpha"),
        ));
    }
    // α below 1e-4 is accepted and clamped (documented at MIN_ALPHA); α up to MAX_ALPHA is accepted.
    v.push(case("Ggx::isotropic(1e-7)", Ggx::isotropic(1e-7), None));
    v.push(case(
        "Ggx::isotropic(1e4)",
        Ggx::isotropic(brdf::ndf::MAX_ALPHA),
        None,
    ));
    v.push(case(
        "BlinnPhong::new(-1)",
        BlinnPhong::new(-1.0),
        Some("gamma"),
    ));
    v.push(case(
        "BlinnPhong::new(NaN)",
        BlinnPhong::new(nan),
        Some("gamma"),
    ));
    let singular = Mat2::from_cols_array(&[1.0, 1.0, 1.0, 1.0]);
    v.push(case(
        "SlopeGaussian::new(0, [[1,1],[1,1]])",
        SlopeGaussian::new(Vec2::ZERO, singular),
        Some("cov"),
    ));
    let asymmetric = Mat2::from_cols_array(&[1.0, 0.5, 0.0, 1.0]);
    v.push(case(
        "SlopeGaussian::new(0, [[1,0],[0.5,1]])",
        SlopeGaussian::new(Vec2::ZERO, asymmetric),
        Some("cov"),
    ));
    v.push(case(
        "SlopeGaussian::new(0, 1e9·I)",
        SlopeGaussian::new(Vec2::ZERO, Mat2::from_diagonal(Vec2::splat(1e9))),
        Some("cov"),
    ));
    v.push(case(
        "SlopeGaussian::new((NaN,0), I)",
        SlopeGaussian::new(Vec2::new(nan, 0.0), Mat2::IDENTITY),
        Some("mean"),
    ));
    // Fresnel.
    v.push(case(
        "DielectricFresnel::new(0)",
        DielectricFresnel::new(0.0),
        Some("eta"),
    ));
    v.push(case(
        "ConductorFresnel::new((1,-1,1), 1)",
        ConductorFresnel::new(Vec3::new(1.0, -1.0, 1.0), Vec3::ONE),
        Some("eta"),
    ));
    v.push(case(
        "ConductorFresnel::new(1, NaN)",
        ConductorFresnel::new(Vec3::ONE, Vec3::splat(nan)),
        Some("k"),
    ));
    v.push(case(
        "SchlickFresnel::new((0.5,1.5,0.5))",
        SchlickFresnel::new(Vec3::new(0.5, 1.5, 0.5)),
        Some("f0"),
    ));
    // Classic BRDFs.
    v.push(case(
        "Lambert::new(1.01)",
        Lambert::new(Vec3::splat(1.01)),
        Some("albedo"),
    ));
    let phong = |d: f32, s: f32, gamma: f32, n: PhongNormalization| {
        Phong::new(Vec3::splat(d), Vec3::splat(s), gamma, n)
    };
    v.push(case(
        "Phong::new(0.6, 0.6, 10, EnergyConserving)",
        phong(0.6, 0.6, 10.0, PhongNormalization::EnergyConserving),
        Some("rho"),
    ));
    v.push(case(
        "Phong::new(0, 1, -1, EnergyConserving)",
        phong(0.0, 1.0, -1.0, PhongNormalization::EnergyConserving),
        Some("gamma"),
    ));
    v.push(case(
        "Phong::new(0, 1, 2.5, EnergyNormalizedArvo)",
        phong(0.0, 1.0, 2.5, PhongNormalization::EnergyNormalizedArvo),
        Some("gamma"),
    ));
    // Normal maps.
    v.push(case(
        "NormalMap::from_slopes(0, 0, [])",
        NormalMap::from_slopes(0, 0, vec![]),
        Some("0×0"),
    ));
    v.push(case(
        "NormalMap::from_slopes(2, 2, 3 slopes)",
        NormalMap::from_slopes(2, 2, vec![Vec2::ZERO; 3]),
        Some("2×2"),
    ));
    v.push(case(
        "NormalMap::from_slopes(2, 1, [0, (NaN,0)])",
        NormalMap::from_slopes(2, 1, vec![Vec2::ZERO, Vec2::new(nan, 0.0)]),
        Some("texel (1, 0)"),
    ));
    v.push(case(
        "NormalMap::from_slopes(1, 1, [(2e4, 0)])",
        NormalMap::from_slopes(1, 1, vec![Vec2::new(2e4, 0.0)]),
        Some("MAX_SLOPE"),
    ));
    let below = [Vec3::new(0.0, 1.0, -0.1)];
    v.push(case(
        "NormalMap::from_normals(1, 1, [(0,1,-0.1)], Reject)",
        NormalMap::from_normals(1, 1, &below, NormalRepair::Reject),
        Some("texel (0, 0)"),
    ));
    v.push(case(
        "NormalMap::from_normals(1, 1, [(0,1,-0.1)], ClampZ(0.05))",
        NormalMap::from_normals(1, 1, &below, NormalRepair::ClampZ(0.05)),
        None,
    ));
    v.push(case(
        "NormalMap::from_image_bytes(b\"not an image\", \"bytes.png\")",
        NormalMap::from_image_bytes(
            b"not an image",
            "bytes.png",
            TangentConvention::OpenGl,
            NormalRepair::Reject,
        ),
        Some("bytes.png"),
    ));
    // Glint builders, on a 3×5 flat map.
    let map = NormalMap::from_slopes(3, 5, vec![Vec2::ZERO; 15]).unwrap();
    let mix = |label: &str, name: &'static str, p: MixtureParams| {
        case(
            format!("BeckmannMixture::build(3×5, {label})"),
            BeckmannMixture::build(&map, p),
            Some(name),
        )
    };
    let d = MixtureParams::default();
    v.push(mix(
        "spacing 0",
        "spacing",
        MixtureParams { spacing: 0.0, ..d },
    ));
    v.push(mix(
        "sigma_min -1",
        "sigma_min",
        MixtureParams {
            sigma_min: -1.0,
            ..d
        },
    ));
    v.push(mix(
        "samples 0",
        "samples",
        MixtureParams { samples: 0, ..d },
    ));
    v.push(mix(
        "slope_tail 1",
        "slope_tail",
        MixtureParams {
            slope_tail: 1.0,
            ..d
        },
    ));
    v.push(mix(
        "weight_sigmas 1e30",
        "weight_sigmas",
        MixtureParams {
            weight_sigmas: 1e30,
            ..d
        },
    ));
    let bins = |label: &str, name: &'static str, p: BinMapParams| {
        case(
            format!("BinMap::build(3×5, {label})"),
            BinMap::build(&map, p),
            Some(name),
        )
    };
    let d = BinMapParams::default();
    v.push(bins(
        "n = 0",
        "bins_per_axis",
        BinMapParams {
            bins_per_axis: 0,
            ..d
        },
    ));
    v.push(bins(
        "n = 64",
        "bins_per_axis",
        BinMapParams {
            bins_per_axis: 64,
            ..d
        },
    ));
    v.push(bins(
        "L = 0",
        "leaf_size",
        BinMapParams { leaf_size: 0, ..d },
    ));
    v.push(bins(
        "σ_min = NaN",
        "sigma_min",
        BinMapParams {
            sigma_min: nan,
            ..d
        },
    ));
    let pn = |label: &str, name: &'static str, p: PositionNormalParams| {
        case(
            format!("PositionNormalMap::build(3×5, {label})"),
            PositionNormalMap::build(&map, p),
            Some(name),
        )
    };
    let d = PositionNormalParams::default();
    v.push(pn(
        "rate 0",
        "sampling_rate",
        PositionNormalParams {
            sampling_rate: 0,
            ..d
        },
    ));
    v.push(pn(
        "σ_r = 0",
        "sigma_r",
        PositionNormalParams { sigma_r: 0.0, ..d },
    ));
    v.push(pn(
        "weight_sigmas 1",
        "weight_sigmas",
        PositionNormalParams {
            weight_sigmas: 1.0,
            ..d
        },
    ));
    v.push(pn(
        "weight_sigmas 1e30",
        "weight_sigmas",
        PositionNormalParams {
            weight_sigmas: 1e30,
            ..d
        },
    ));
    v
}

/// Each row of docs/robustness.md's constructor table: the input and the error (naming the
/// parameter) or `Ok` it must give.
#[test]
fn documented_outcomes() {
    for c in constructor_cases() {
        match c.expect {
            Some(needle) => assert!(
                c.outcome != "Ok" && c.outcome.contains(needle),
                "{}: expected an error naming `{needle}`, got {}",
                c.input,
                c.outcome
            ),
            None => assert_eq!(c.outcome, "Ok", "{}", c.input),
        }
    }
}

/// Prints the outcome of every input of `documented_outcomes`, for docs/robustness.md:
/// `cargo test --release --test robustness -- --ignored outcome_table --nocapture`.
#[test]
#[ignore]
fn outcome_table() {
    println!("| input | outcome |\n|---|---|");
    for c in constructor_cases() {
        println!("| `{}` | {} |", c.input, c.outcome.replace('|', "\\|"));
    }
}

// ---------------------------------------------------------------------------------------------
// Regression tests: one per finding of the property suites and the fuzz targets
// ---------------------------------------------------------------------------------------------

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
        assert_eq!(mixture.patch(&fp).pdf_normal(m), 0.0, "{m}");
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
    let (smoothed, pnp) = (bin_map.patch_smoothed(&fp, 0.1), pn.patch(&fp));
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
