//! The constructor outcome table of docs/robustness.md: every documented input gives the error
//! naming its parameter, or `Ok`, row by row (`documented_outcomes`); `outcome_table` prints the
//! table (`cargo test --release --test it -- --ignored robustness_outcomes::outcome_table --nocapture`).

use crate::support;

use brdf::bxdf::PhongNormalization;
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, SchlickFresnel};
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MixtureParams, MomentMethod};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, NormalMap, NormalRepair, PositionNormalMap, TangentConvention,
};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, SlopeGaussian};
use brdf::{Error, Lambert, Mat2, Phong, Vec2, Vec3};
use support::robustness::outcome;

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
    // `samples` counts quasi-Monte Carlo nodes: checked under `MomentMethod::Qmc` only.
    v.push(mix(
        "samples 0, QMC moments",
        "samples",
        MixtureParams {
            samples: 0,
            moments: MomentMethod::Qmc,
            ..d
        },
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
/// `cargo test --release --test it -- --ignored robustness_outcomes::outcome_table --nocapture`.
#[test]
#[ignore]
fn outcome_table() {
    println!("| input | outcome |\n|---|---|");
    for c in constructor_cases() {
        println!("| `{}` | {} |", c.input, c.outcome.replace('|', "\\|"));
    }
}
