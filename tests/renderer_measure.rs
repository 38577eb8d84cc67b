//! Glints in the renderer's measure: the white furnace of every glint model computed the way a
//! renderer computes it, through the public `Bxdf` with the **geometric** cos θi.
//!
//! Two independent estimators of E(wo) = ∫ f(wo, wi) cos θi dωi (F = 1), both through the public API:
//! - `sample().weight()` averaged over stratified draws (what a path tracer does);
//! - one-sample multiple importance sampling of `eval(wo, wi) · cos θi`: wi drawn from the BRDF's
//!   sampler or from the cosine hemisphere with probability ½ each, weighted by
//!   1 / (½ pdf_brdf + ½ pdf_cos) (balance heuristic). It checks `eval` and `pdf` against each other
//!   and reaches directions the BRDF's sampler cannot (a renderer's light sampling).
//!
//! Both must be ≤ 1 up to Monte Carlo error (4 standard errors + 1e-4). The default run covers every
//! model on the four procedural maps at four footprint sizes and four views; the full grid (footprints
//! 0.25 … 65 536 texels, views up to 89.9°) is `#[ignore]`:
//! `cargo test --release --test renderer_measure -- --ignored --nocapture`.

mod support;

use brdf::bxdf::{Bxdf, Masking, MicrofacetBrdf};
use brdf::fresnel::NoFresnel;
use brdf::glint::{
    BeckmannMixture, BinMap, BinMapParams, Footprint, GlintNdf, MaskingMode, MixtureParams,
    NormalMap, PatchOptions, PositionNormalMap, PositionNormalParams,
};
use brdf::ndf::Ndf;
use brdf::warp;
use brdf::{Vec2, Vec3};
use rand::RngExt;

/// Smoothing σ of the smoothed bin-map variant (in slope units).
const SMOOTHING: f32 = 0.05;

/// (mean, standard error) of a sum of `n` samples.
fn mean_se(sum: f64, sum2: f64, n: usize) -> (f64, f64) {
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// E(wo) by the BRDF's own sampler: the mean of `sample().weight()` over `n` stratified draws.
fn furnace_by_weight(brdf: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = support::rng(seed);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        let w = brdf
            .sample(wo, rng.random(), u)
            .map_or(0.0, |smp| smp.weight().x as f64);
        s += w;
        s2 += w * w;
    }
    mean_se(s, s2, n)
}

/// E(wo) by one-sample MIS of `eval · cos θi` between the BRDF's sampler and the cosine hemisphere.
fn furnace_by_eval(brdf: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = support::rng(seed);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        let wi = if k % 2 == 0 {
            brdf.sample(wo, 0.5, u).map(|smp| smp.wi)
        } else {
            Some(warp::square_to_cosine_hemisphere(u))
        };
        let v = wi.map_or(0.0, |wi| {
            let (f, pdf) = brdf.eval_pdf(wo, wi);
            let p = 0.5 * pdf as f64 + 0.5 * warp::pdf_cosine_hemisphere(wi) as f64;
            if p > 0.0 {
                f.x as f64 * wi.z.max(0.0) as f64 / p
            } else {
                0.0
            }
        });
        s += v;
        s2 += v * v;
    }
    mean_se(s, s2, n)
}

fn assert_at_most_one(what: &str, (e, se): (f64, f64)) {
    assert!(e.is_finite() && e >= 0.0, "{what}: furnace {e}");
    assert!(e <= 1.0 + 4.0 * se + 1e-4, "{what}: furnace {e} ± {se} > 1");
}

/// The glint models of one map, built once.
struct Models {
    mixture_exact: BeckmannMixture,
    mixture_approx: BeckmannMixture,
    bin_map: BinMap,
    position_normal: PositionNormalMap,
}

impl Models {
    fn build(map: &NormalMap) -> Models {
        let mixture = |masking| {
            let params = MixtureParams {
                samples: 64,
                patch: PatchOptions {
                    masking,
                    ..PatchOptions::default()
                },
                ..MixtureParams::default()
            };
            BeckmannMixture::build(map, params).unwrap()
        };
        Models {
            mixture_exact: mixture(MaskingMode::Exact),
            mixture_approx: mixture(MaskingMode::Approximate),
            bin_map: BinMap::build(map, BinMapParams::default()).unwrap(),
            position_normal: PositionNormalMap::build(map, PositionNormalParams::default())
                .unwrap(),
        }
    }

    /// Runs `f(name, patch)` for every glint patch of a footprint.
    fn for_each_patch(&self, fp: &Footprint, mut f: impl FnMut(&str, &dyn Ndf)) {
        f("mixture exact", &self.mixture_exact.patch(fp));
        f("mixture approximate", &self.mixture_approx.patch(fp));
        f("bin map", &self.bin_map.patch(fp));
        f("bin map smoothed", &self.bin_map.patch_smoothed(fp, SMOOTHING));
        f("position-normal", &self.position_normal.patch(fp));
    }
}

/// The weight estimator for both G2 forms and the eval estimator for the default (height-correlated)
/// form of `MicrofacetBrdf::new(patch, NoFresnel)`.
fn furnaces(patch: &dyn Ndf, wo: Vec3, n: usize) -> Vec<(String, (f64, f64))> {
    let hc = MicrofacetBrdf::new(patch, NoFresnel);
    let sep = hc.with_masking(Masking::Separable);
    vec![
        ("height-correlated weight".into(), furnace_by_weight(&hc, wo, n, 11)),
        ("height-correlated eval".into(), furnace_by_eval(&hc, wo, n, 12)),
        ("separable weight".into(), furnace_by_weight(&sep, wo, n, 13)),
    ]
}

/// Every glint model, every procedural map (32²), footprints of 0.25, 16 and 256 texels, views 0°,
/// 60°, 85° and 89.9°: the renderer's furnace ≤ 1 with both estimators (and both G2 forms). Larger
/// footprints (up to 65 536 texels, the mixture's level of detail) are in the `#[ignore]`d full grid.
/// Fails without the renderer's-measure factor A(wi)/cos θi in `MicrofacetBrdf::eval` (checked:
/// 1.023 ± 0.004 on scratched, mixture exact, 256 texels, θo = 60°).
#[test]
fn geometric_furnace_at_most_one_for_every_glint_model() {
    const N: usize = 512;
    for (map_name, map) in support::procedural_maps(32) {
        let models = Models::build(&map);
        for area in [0.25f32, 16.0, 256.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), area, 32, 32);
            models.for_each_patch(&fp, |name, patch| {
                for theta in [0.0, 60.0, 85.0, 89.9] {
                    let wo = support::dir(theta, 30.0);
                    for (est, e) in furnaces(patch, wo, N) {
                        assert_at_most_one(
                            &format!("{map_name} {name} {area} texels θo={theta}° {est}"),
                            e,
                        );
                    }
                }
            });
        }
    }
}

/// The eval-based and the weight-based estimates agree (within Monte Carlo error): `sample`, `eval`
/// and `pdf` describe one BRDF, and the BRDF's sampler misses no part of it that the cosine
/// hemisphere reaches.
#[test]
fn weight_and_eval_estimators_agree() {
    const N: usize = 4096;
    let maps = support::procedural_maps(32);
    for (map_name, map) in maps.iter().filter(|(n, _)| *n == "flakes" || *n == "bumpy") {
        let models = Models::build(map);
        let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 4.0, 32, 32);
        models.for_each_patch(&fp, |name, patch| {
            for theta in [30.0, 70.0] {
                let wo = support::dir(theta, 30.0);
                let brdf = MicrofacetBrdf::new(patch, NoFresnel);
                let (a, sa) = furnace_by_weight(&brdf, wo, N, 21);
                let (b, sb) = furnace_by_eval(&brdf, wo, N, 22);
                let tol = 5.0 * (sa * sa + sb * sb).sqrt() + 1e-3;
                assert!(
                    (a - b).abs() <= tol,
                    "{map_name} {name} θo={theta}°: weight {a} ± {sa}, eval {b} ± {sb}"
                );
            }
        });
    }
}

/// The full grid of the issue, printed as markdown rows for docs/results.md: per map, model and
/// footprint, the largest renderer's furnace over views 0 … 89.9° (weight estimator, height-correlated
/// G2) with the patch-measure value the crate returned before (f_P cos θi, i.e. `eval` without the
/// A(wi)/cos θi factor: `eval · cos θi / A(wi) · cos θi`).
/// `cargo test --release --test renderer_measure -- --ignored --nocapture`
#[test]
#[ignore]
fn geometric_furnace_full_grid() {
    const N: usize = 4096;
    let thetas = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9];
    println!("| map | model | texels | max E, geometric (before) | max E, geometric (now) | at θo |");
    println!("|---|---|---|---|---|---|");
    for (map_name, map) in support::procedural_maps(128) {
        let models = Models::build(&map);
        for area in [0.25f32, 1.0, 16.0, 256.0, 4096.0, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), area, 128, 128);
            models.for_each_patch(&fp, |name, patch| {
                let brdf = MicrofacetBrdf::new(patch, NoFresnel);
                let mut worst = (0.0f64, 0.0f64, 0.0f64);
                for theta in thetas {
                    let wo = support::dir(theta, 30.0);
                    let now = furnace_by_weight(&brdf, wo, N, 31);
                    assert_at_most_one(&format!("{map_name} {name} {area} θo={theta}°"), now);
                    let before = furnace_before(&brdf, patch, wo, N);
                    if now.0 > worst.1 || before > worst.0 {
                        worst = (worst.0.max(before), worst.1.max(now.0), theta);
                    }
                }
                println!(
                    "| {map_name} | {name} | {area} | {:.3} | {:.3} | {}° |",
                    worst.0, worst.1, worst.2
                );
            });
        }
    }
}

/// The furnace the crate's previous `eval` (the patch-measure f_P) gave with the geometric cosine:
/// the mean of weight · cos θi / A(wi) over the same sampler.
fn furnace_before(brdf: &dyn Bxdf, patch: &dyn Ndf, wo: Vec3, n: usize) -> f64 {
    let mut rng = support::rng(31);
    let mut s = 0.0f64;
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        if let Some(smp) = brdf.sample(wo, rng.random(), u) {
            let a = patch.projected_area(smp.wi) as f64;
            if a > 0.0 {
                s += smp.weight().x as f64 * smp.wi.z as f64 / a;
            }
        }
    }
    s / n as f64
}
