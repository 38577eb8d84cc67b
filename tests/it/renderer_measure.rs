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
//! `cargo test --release --test it renderer_measure:: -- --ignored --nocapture`.

use crate::support;

use brdf::bxdf::{Bxdf, Masking, MicrofacetBrdf};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, Footprint, GlintNdf, NormalMap, PositionNormalMap};
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
    mixture: BeckmannMixture,
    bin_map: BinMap,
    position_normal: PositionNormalMap,
}

impl Models {
    fn build(map: &NormalMap) -> Models {
        let params = MixtureParams {
            samples: 64,
            ..MixtureParams::default()
        };
        Models {
            mixture: BeckmannMixture::build(map, params).unwrap(),
            bin_map: BinMap::build(map, BinMapParams::default()).unwrap(),
            position_normal: PositionNormalMap::build(map, PositionNormalParams::default())
                .unwrap(),
        }
    }

    /// Runs `f(name, patch)` for every glint patch of a footprint.
    fn for_each_patch(&self, fp: &Footprint, mut f: impl FnMut(&str, &dyn Ndf)) {
        let approximate = PatchOptions {
            masking: MaskingMode::Approximate,
            ..PatchOptions::default()
        };
        f("mixture exact", &self.mixture.patch(fp));
        f(
            "mixture approximate",
            &self.mixture.patch_with(fp, &approximate, None),
        );
        f("bin map", &self.bin_map.patch(fp));
        f(
            "bin map smoothed",
            &self.bin_map.patch_with(
                fp,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: SMOOTHING,
                    ..Default::default()
                },
                None,
            ),
        );
        f("position-normal", &self.position_normal.patch(fp));
    }
}

/// The weight estimator for both G2 forms and the eval estimator for the default (height-correlated)
/// form of `MicrofacetBrdf::new(patch, NoFresnel)`.
fn furnaces(patch: &dyn Ndf, wo: Vec3, n: usize) -> Vec<(String, (f64, f64))> {
    let hc = MicrofacetBrdf::new(patch, NoFresnel);
    let sep = hc.with_masking(Masking::Separable);
    vec![
        (
            "height-correlated weight".into(),
            furnace_by_weight(&hc, wo, n, 11),
        ),
        (
            "height-correlated eval".into(),
            furnace_by_eval(&hc, wo, n, 12),
        ),
        (
            "separable weight".into(),
            furnace_by_weight(&sep, wo, n, 13),
        ),
    ]
}

/// Every glint model, every procedural map (32²), footprints of 0.25, 16 and 256 texels, views 0°,
/// 60°, 85° and 89.9°: the renderer's furnace ≤ 1 with both estimators (and both G2 forms). Larger
/// footprints (up to 65 536 texels, the mixture's level of detail) are in the `#[ignore]`d full grid.
/// Fails without the renderer's-measure factor A(wi)/cos θi in `MicrofacetBrdf::eval` (checked:
/// 1.023 ± 0.004 on scratched, mixture exact, 256 texels, θo = 60°).
#[test]
fn geometric_furnace_at_most_one_for_every_glint_model() {
    // 256 draws per estimate in the default run (support::depth): the bound is in standard errors.
    let n = support::depth(256, 512);
    for (map_name, map) in support::procedural_maps(32) {
        let models = Models::build(&map);
        for area in [0.25f32, 16.0, 256.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), area, 32, 32);
            models.for_each_patch(&fp, |name, patch| {
                for theta in [0.0, 60.0, 85.0, 89.9] {
                    let wo = support::dir(theta, 30.0);
                    for (est, e) in furnaces(patch, wo, n) {
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

/// The full grid of maps, models and footprints, printed as markdown rows for docs/results.md: per map, model and
/// footprint, the largest renderer's furnace over views 0 … 89.9° (weight estimator, height-correlated
/// G2), beside the value the previous contract (`eval` = the patch-measure f_P, integrated with the
/// geometric cosine) gives with today's masking terms, from the same samples: weight · cos θi / A(wi)
/// (a lower bound of it: directions with A(wi) ≤ 0, where f_P is not 0 but the renderer's f is, are
/// not counted).
/// `cargo test --release --test it renderer_measure:: -- --ignored --nocapture`
#[test]
#[ignore]
fn geometric_furnace_full_grid() {
    const N: usize = 512;
    let thetas = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9];
    println!("| map | model | texels | max E before (f_P cos θi) | max E now (± 4 SE) | at θo |");
    println!("|---|---|---|---|---|---|");
    for (map_name, map) in support::procedural_maps(128) {
        let models = Models::build(&map);
        for area in [0.25f32, 1.0, 16.0, 256.0, 4096.0, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), area, 128, 128);
            models.for_each_patch(&fp, |name, patch| {
                let brdf = MicrofacetBrdf::new(patch, NoFresnel);
                let (mut before_max, mut now_max, mut at) = (0.0f64, (0.0f64, 0.0f64), 0.0);
                for theta in thetas {
                    let wo = support::dir(theta, 30.0);
                    let (now, before) = furnace_now_and_before(&brdf, patch, wo, N);
                    assert_at_most_one(&format!("{map_name} {name} {area} θo={theta}°"), now);
                    before_max = before_max.max(before);
                    if now.0 > now_max.0 {
                        (now_max, at) = (now, theta);
                    }
                }
                println!(
                    "| {map_name} | {name} | {area} | {before_max:.3} | {:.3} ± {:.3} | {at}° |",
                    now_max.0,
                    4.0 * now_max.1
                );
            });
        }
    }
}

/// From one set of `n` stratified samples: the renderer's furnace (mean, se) of `sample().weight()`
/// and the furnace the previous patch-measure `eval` gave with the geometric cosine,
/// mean of weight · cos θi / A(wi).
fn furnace_now_and_before(
    brdf: &dyn Bxdf,
    patch: &dyn Ndf,
    wo: Vec3,
    n: usize,
) -> ((f64, f64), f64) {
    let mut rng = support::rng(31);
    let (mut s, mut s2, mut before) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        if let Some(smp) = brdf.sample(wo, rng.random(), u) {
            let w = smp.weight().x as f64;
            s += w;
            s2 += w * w;
            let a = patch.projected_area(smp.wi) as f64;
            if a > 0.0 {
                before += w * smp.wi.z as f64 / a;
            }
        }
    }
    (mean_se(s, s2, n), before / n as f64)
}

// ---------------------------------------------------------------------------------------------
// Footprints from what a renderer has
// ---------------------------------------------------------------------------------------------

/// The unit sphere's (u, v) = (φ / 2π, θ / π) parametrisation, in f64.
fn sphere_point(u: f64, v: f64) -> [f64; 3] {
    let (phi, theta) = (std::f64::consts::TAU * u, std::f64::consts::PI * v);
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

fn sphere_uv(p: [f64; 3]) -> [f64; 2] {
    let phi = p[1].atan2(p[0]).rem_euclid(std::f64::consts::TAU);
    [
        phi / std::f64::consts::TAU,
        p[2].clamp(-1.0, 1.0).acos() / std::f64::consts::PI,
    ]
}

/// The hit point on the unit sphere of the pinhole camera's ray through pixel (x, y): camera at
/// (0.3, −0.2, 4) looking down −z, 0.01 per pixel on the image plane at distance 1.
fn camera_hit(x: f64, y: f64) -> [f64; 3] {
    let o = [0.3, -0.2, 4.0];
    let d = [x * 0.01, y * 0.01, -1.0];
    let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = d.map(|c| c / n);
    let b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
    let c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - 1.0;
    assert!(b * b - c > 0.0, "pixel ({x}, {y}) misses the sphere");
    let t = -b - (b * b - c).sqrt();
    [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]]
}

/// `Footprint::from_surface_differentials` on a sphere: ∂uv/∂x from the least-squares solve of
/// ∂p/∂x = ∂p/∂u ∂u/∂x + ∂p/∂v ∂v/∂x matches the central finite difference of the hit's uv (f64,
/// step 1e-4 pixel, truncation error ~1e-8), to 1e-4 relative (f32 inputs and output).
#[test]
fn footprint_from_surface_differentials_matches_finite_differences_on_a_sphere() {
    let h = 1e-4;
    let v3 = |p: [f64; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    for (x, y) in [
        (0.0, 0.0),
        (-20.0, 5.0),
        (5.0, -10.0),
        (-5.0, 12.0),
        (12.0, 14.0),
    ] {
        let p = camera_hit(x, y);
        let [u, v] = sphere_uv(p);
        let (phi, theta) = (std::f64::consts::TAU * u, std::f64::consts::PI * v);
        let dpdu = [
            -std::f64::consts::TAU * theta.sin() * phi.sin(),
            std::f64::consts::TAU * theta.sin() * phi.cos(),
            0.0,
        ];
        let dpdv = [
            std::f64::consts::PI * theta.cos() * phi.cos(),
            std::f64::consts::PI * theta.cos() * phi.sin(),
            -std::f64::consts::PI * theta.sin(),
        ];
        // The parametrisation's derivatives are right (a check of the test itself).
        let q = sphere_point(u + h, v);
        let r = sphere_point(u - h, v);
        for k in 0..3 {
            let fd = (q[k] - r[k]) / (2.0 * h);
            assert!(
                (fd - dpdu[k]).abs() < 1e-6,
                "{x} {y} u={u} v={v} k={k}: {fd} vs {}",
                dpdu[k]
            );
        }
        let diff = |f: &dyn Fn(f64) -> [f64; 3]| -> [f64; 3] {
            let (a, b) = (f(h), f(-h));
            [0, 1, 2].map(|k| (a[k] - b[k]) / (2.0 * h))
        };
        let dpdx = diff(&|e| camera_hit(x + e, y));
        let dpdy = diff(&|e| camera_hit(x, y + e));
        let duv = |f: &dyn Fn(f64) -> [f64; 3]| -> [f64; 2] {
            let (a, b) = (sphere_uv(f(h)), sphere_uv(f(-h)));
            [0, 1].map(|k| (a[k] - b[k]) / (2.0 * h))
        };
        let ref_dx = duv(&|e| camera_hit(x + e, y));
        let ref_dy = duv(&|e| camera_hit(x, y + e));
        let fp = Footprint::from_surface_differentials(
            Vec2::new(u as f32, v as f32),
            v3(dpdu),
            v3(dpdv),
            v3(dpdx),
            v3(dpdy),
        );
        for (got, want) in [(fp.duv_dx(), ref_dx), (fp.duv_dy(), ref_dy)] {
            let scale = want[0].abs().max(want[1].abs());
            for k in 0..2 {
                assert!(
                    (got[k] as f64 - want[k]).abs() <= 1e-4 * scale,
                    "pixel ({x}, {y}): {got} vs {want:?}"
                );
            }
        }
        assert!((fp.center_uv() - Vec2::new(u as f32, v as f32)).length() < 1e-6);
    }
}

/// A singular parametrisation (∂p/∂u ∥ ∂p/∂v, a zero ∂p/∂v) or non-finite input gives the minimal
/// footprint, never NaN.
#[test]
fn footprint_from_degenerate_surface_differentials_is_minimal() {
    let (uv, dx, dy) = (
        Vec2::new(0.3, 0.4),
        Vec3::new(0.01, 0.0, 0.0),
        Vec3::new(0.0, 0.01, 0.0),
    );
    for (dpdu, dpdv) in [
        (Vec3::X, 2.0 * Vec3::X),
        (Vec3::X, Vec3::ZERO),
        (Vec3::ZERO, Vec3::ZERO),
        (Vec3::X, Vec3::new(f32::NAN, 1.0, 0.0)),
    ] {
        let fp = Footprint::from_surface_differentials(uv, dpdu, dpdv, dx, dy);
        assert_eq!(fp.duv_dx(), Vec2::ZERO, "{dpdu} {dpdv}");
        assert_eq!(fp.duv_dy(), Vec2::ZERO, "{dpdu} {dpdv}");
        assert!(fp.area_texels(64, 64).is_finite());
    }
}

// ---------------------------------------------------------------------------------------------
// Materials a renderer holds at run time
// ---------------------------------------------------------------------------------------------

/// Every `GlintModel` variant's patch (with per-query options: the bin map plain and smoothed) is
/// bit-identical to its model's own patch, without a scratch and with a reused scratch (queried after the scratch served larger and smaller
/// footprints), and the models share one `Vec<Arc<GlintModel>>`.
#[test]
fn glint_model_patches_equal_their_models_patches() {
    use brdf::glint::{GlintModel, GlintOptions, GlintScratch};
    use std::sync::Arc;
    let map = brdf::glint::scratched(32, 32, Default::default(), 5).unwrap();
    let models = Models::build(&map);
    let bin_map: Arc<GlintModel> = Arc::new(models.bin_map.clone().into());
    let mut smoothed = GlintOptions::default();
    smoothed.bin_map.smoothing_alpha = SMOOTHING;
    // (material, per-query options): the smoothed bin map is the bin map with smoothing options.
    let materials: Vec<(Arc<GlintModel>, GlintOptions)> = vec![
        (
            Arc::new(models.mixture.clone().into()),
            GlintOptions::default(),
        ),
        (bin_map.clone(), GlintOptions::default()),
        (bin_map, smoothed),
        (
            Arc::new(models.position_normal.clone().into()),
            GlintOptions::default(),
        ),
    ];
    let scratch = GlintScratch::default();
    let mut rng = support::rng(41);
    for area in [400.0f32, 2.0, 64.0] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.8), area, 32, 32);
        let own: [&dyn Ndf; 4] = [
            &models.mixture.patch(&fp),
            &models.bin_map.patch(&fp),
            &models.bin_map.patch_with(
                &fp,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: SMOOTHING,
                    ..Default::default()
                },
                None,
            ),
            &models.position_normal.patch(&fp),
        ];
        for ((material, options), own) in materials.iter().zip(own) {
            let via_patch = material.patch_with(&fp, options, None);
            let via_scratch = material.patch_with(&fp, options, Some(&scratch));
            for _ in 0..50 {
                let wo = support::dir(rng.random_range(0.0..89.0), rng.random_range(0.0..360.0));
                let m = support::dir(rng.random_range(0.0..60.0), rng.random_range(0.0..360.0));
                let u = Vec2::new(rng.random(), rng.random());
                for p in [&via_patch as &dyn Ndf, &via_scratch] {
                    let name = material.name();
                    assert_eq!(p.d(m).to_bits(), own.d(m).to_bits(), "{name} d");
                    assert_eq!(p.lambda(wo).to_bits(), own.lambda(wo).to_bits(), "{name} Λ");
                    assert_eq!(p.sample_visible(wo, u), own.sample_visible(wo, u), "{name}");
                    assert_eq!(
                        p.pdf_visible(wo, m).to_bits(),
                        own.pdf_visible(wo, m).to_bits()
                    );
                }
            }
        }
    }
}
