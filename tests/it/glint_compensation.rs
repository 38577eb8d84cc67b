//! Energy compensation of glint patches (`ViewCompensated`, `LayeredBrdf::with_energy_compensation`,
//! `GlintMaterial::with_energy_compensation`): the white furnace a renderer computes (mean
//! `sample().weight()`) of compensated patches against 1, per view; the patches' own albedo
//! estimate against their uncompensated furnace; chi-square of the compensated samplers; and the
//! material path.

use crate::support;
use crate::support::chi2::Chi2;

use brdf::bxdf::{AlbedoEstimate, Bxdf, LayeredBrdf, ViewCompensated};
use brdf::fresnel::{ConductorFresnel, NoFresnel};
use brdf::glint::mixture::MixtureParams;
use brdf::glint::procedural::ProceduralParams;
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, GlintScratch, PositionNormalMap,
    ProceduralGlints,
};
use brdf::material::{GlintMaterial, Material};
use brdf::{MicrofacetBrdf, Vec2, Vec3};

/// Side of the test maps.
const N: usize = 128;

/// The footprints (texels) of the furnace checks: the range, 16-4,096, at full depth.
fn footprints() -> Vec<f32> {
    support::depth(vec![16.0, 1024.0], vec![16.0, 64.0, 256.0, 1024.0, 4096.0])
}

/// The views (θo in degrees, φo in degrees) of the furnace checks.
fn views() -> Vec<(f64, f64)> {
    let thetas: Vec<f64> = support::depth(
        vec![0.0, 60.0, 80.0],
        vec![0.0, 30.0, 45.0, 60.0, 70.0, 80.0],
    );
    let phis = [20.0, 200.0];
    thetas
        .iter()
        .flat_map(|&t| phis.iter().map(move |&p| (t, p)))
        .collect()
}

/// Draws per furnace cell.
const DRAWS: usize = 1024;

/// The largest |E − 1| a compensated patch may show beyond 4 standard errors: the estimate's own
/// error, measured at most 0.013 (bumpy) to 0.022 (flakes) for the mixture and 0.008 for the
/// procedural surface (docs/results.md, "Energy compensation of glint patches": the merge of many
/// lobes and the four-Gaussian stand-in for Λ_P at the reflected directions).
const TOLERANCE: f64 = 0.025;

/// For each cell: (label, uncompensated E, estimate, compensated E, its standard error).
fn furnace_cells(model: &GlintModel, label: &str) -> Vec<(String, f64, f64, f64, f64)> {
    let mut cells = Vec::new();
    for texels in footprints() {
        for c in [Vec2::new(0.37, 0.61)] {
            let fp = Footprint::isotropic_texels(c, texels, N, N);
            let patch = model.patch(&fp);
            for (theta, phi) in views() {
                let wo = support::dir(theta, phi);
                let plain = MicrofacetBrdf::new(patch.clone(), NoFresnel);
                let e = support::bxdf::stratified_weight_moments(&plain, wo, DRAWS, 7)[0].0;
                let est = patch.albedo_estimate(wo) as f64;
                let comp = ViewCompensated::new(MicrofacetBrdf::new(patch.clone(), NoFresnel), wo)
                    .unwrap();
                let (f, se) = support::bxdf::stratified_weight_moments(&comp, wo, DRAWS, 9)[0];
                cells.push((
                    format!("{label} {texels} texels at {c}, θo {theta}° φo {phi}°"),
                    e,
                    est,
                    f,
                    se,
                ));
            }
        }
    }
    cells
}

/// Asserts every compensated cell within [`TOLERANCE`] + 4 standard errors of 1, wherever the patch
/// returns any energy at all (a patch seen wholly from behind returns none, compensated or not);
/// returns the smallest uncompensated E (what the compensation had to give back).
fn assert_flat(cells: &[(String, f64, f64, f64, f64)]) -> f64 {
    let mut failures = Vec::new();
    let mut darkest: f64 = 1.0;
    for (label, e, est, f, se) in cells {
        if *e <= 0.0 {
            continue;
        }
        darkest = darkest.min(*e);
        if (f - 1.0).abs() > TOLERANCE + 4.0 * se {
            failures.push(format!(
                "{label}: E {e:.3}, estimate {est:.3}, compensated {f:.3} ± {se:.3}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    darkest
}

/// The Beckmann mixture at its defaults on the four procedural maps.
#[test]
fn compensated_mixture_patches_keep_the_furnace_at_one() {
    let mut darkest: f64 = 1.0;
    for (name, map) in support::procedural_maps(N) {
        let model: GlintModel = BeckmannMixture::build(&map, MixtureParams::default())
            .unwrap()
            .into();
        darkest = darkest.min(assert_flat(&furnace_cells(
            &model,
            &format!("mixture {name}"),
        )));
    }
    // Not vacuous: without compensation the same patches return much less.
    assert!(darkest < 0.9, "no cell lost energy: {darkest}");
}

/// The procedural model at its defaults (its own surface: no map).
#[test]
fn compensated_procedural_patches_keep_the_furnace_at_one() {
    let model: GlintModel = ProceduralGlints::new(ProceduralParams::default())
        .unwrap()
        .into();
    assert_flat(&furnace_cells(&model, "procedural"));
}

/// The table of docs/results.md, "Energy compensation of glint patches": every model at its
/// defaults on the four procedural maps at 256², footprints of 16-4,096 texels at two centres, θo 0-80°
/// at four azimuths, 2,048 draws per cell; per model and map the darkest uncompensated furnace, the
/// largest |E − estimate| and the compensated furnace farthest from 1. Measured, not asserted:
/// position-normal and the bin map stay outside the mixture's tolerance on some maps (see there).
/// `cargo test --release --test it -- --ignored glint_compensation::furnace_table --nocapture`;
/// `BRDF_ONLY=flakes,mixture` (comma-separated map names and model labels) keeps the rows whose map
/// or model is listed.
#[test]
#[ignore = "heavy: ~10 min in release"]
fn furnace_table() {
    const SIDE: usize = 256;
    println!("| model | map | darkest E | largest abs(E - estimate) | worst compensated E |");
    println!("|---|---|---|---|---|");
    for (name, map) in support::procedural_maps(SIDE) {
        let mut models: Vec<(&str, GlintModel)> = vec![
            (
                "mixture",
                BeckmannMixture::build(&map, MixtureParams::default())
                    .unwrap()
                    .into(),
            ),
            (
                "bin map",
                BinMap::build(&map, Default::default()).unwrap().into(),
            ),
            (
                "position-normal",
                PositionNormalMap::build(&map, Default::default())
                    .unwrap()
                    .into(),
            ),
        ];
        if name == "bumpy" {
            let p = ProceduralGlints::new(ProceduralParams::default()).unwrap();
            models.push(("procedural (own surface)", p.into()));
        }
        for (label, model) in &models {
            let only = std::env::var("BRDF_ONLY").unwrap_or_default();
            if !only.is_empty() && !only.split(',').any(|o| o == *label || o == name) {
                continue;
            }
            let (mut darkest, mut worst_est, mut worst) =
                (1.0f64, 0.0f64, (0.0f64, 1.0f64, 0.0f64));
            for texels in [16.0f32, 64.0, 256.0, 1024.0, 4096.0] {
                for c in [Vec2::new(0.37, 0.61), Vec2::new(0.71, 0.23)] {
                    let patch = model.patch(&Footprint::isotropic_texels(c, texels, SIDE, SIDE));
                    for theta in [0.0, 30.0, 45.0, 60.0, 70.0, 80.0] {
                        for phi in [20.0, 110.0, 200.0, 290.0] {
                            let wo = support::dir(theta, phi);
                            let plain = MicrofacetBrdf::new(patch.clone(), NoFresnel);
                            let e =
                                support::bxdf::stratified_weight_moments(&plain, wo, 2048, 7)[0].0;
                            if e <= 0.0 {
                                continue;
                            }
                            let est = patch.albedo_estimate(wo) as f64;
                            let comp = MicrofacetBrdf::new(patch.clone(), NoFresnel);
                            let comp = ViewCompensated::new(comp, wo).unwrap();
                            let (f, se) =
                                support::bxdf::stratified_weight_moments(&comp, wo, 2048, 9)[0];
                            darkest = darkest.min(e);
                            worst_est = worst_est.max((e - est).abs());
                            if (f - 1.0).abs() > worst.0 {
                                worst = ((f - 1.0).abs(), f, se);
                            }
                        }
                    }
                }
            }
            println!(
                "| {label} | {name} | {darkest:.3} | {worst_est:.3} | {:.3} ± {:.3} |",
                worst.1, worst.2
            );
        }
    }
}

/// The compensated BRDF's sampler draws what its pdf says (mixture patches at a small, a medium
/// and a large footprint, grazing and oblique views; the default run the small one at 70°), and so
/// does the compensated coat's.
#[test]
fn compensated_samplers_match_their_densities() {
    let (_, map) = support::procedural_maps(N).into_iter().next().unwrap();
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let f_avg = brdf::bxdf::average_fresnel(&ConductorFresnel::GOLD);
    let mut failures = Vec::new();
    let cases: &[(f32, f64)] = support::depth(
        &[(4.0, 70.0)][..],
        &[(4.0, 45.0), (256.0, 70.0), (8192.0, 80.0)][..],
    );
    let family = 2 * cases.len();
    for &(texels, theta) in cases {
        let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), texels, N, N);
        let wo = support::dir(theta, 30.0);
        let mut patch = mix.patch(&fp);
        patch.prepare_view(wo);
        let comp = ViewCompensated::new(
            MicrofacetBrdf::new(patch.clone(), ConductorFresnel::GOLD),
            wo,
        )
        .unwrap();
        // Prepared at wo, as `Material::bsdf` prepares it: without the view step every call
        // re-estimates E(wo).
        let mut coat = LayeredBrdf::new(
            MicrofacetBrdf::new(patch, ConductorFresnel::GOLD),
            Vec3::new(0.5, 0.2, 0.1),
        )
        .unwrap()
        .with_energy_compensation(f_avg);
        coat.prepare_view(wo);
        let runs: [(&str, &dyn Bxdf); 2] = [("compensated", &comp), ("compensated coat", &coat)];
        for (label, b) in runs {
            let name = format!("{label} mixture {texels} texels θo {theta}°");
            if let Err(e) = Chi2::new(name, family).run(
                |uc, u| b.sample(wo, uc, u).map(|s| s.wi),
                |w| b.pdf(wo, w) as f64,
            ) {
                failures.push(e);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A compensated glint coat over a white base with white Fresnel returns what it receives (the
/// layer's E plus the lobe's 1 − E; nothing reaches the base, R̂ = 1), and over a coloured base with
/// a gold Fresnel never more than it receives.
#[test]
fn compensated_coat_furnace() {
    let (_, map) = support::procedural_maps(N).into_iter().next().unwrap();
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 64.0, N, N);
    for theta in [0.0, 60.0, 80.0] {
        let wo = support::dir(theta, 20.0);
        let patch = mix.patch(&fp);
        let white = LayeredBrdf::new(MicrofacetBrdf::new(patch.clone(), NoFresnel), Vec3::ONE)
            .unwrap()
            .with_energy_compensation(Vec3::ONE);
        let (e, se) = support::bxdf::stratified_weight_moments(&white, wo, 4096, 3)[0];
        assert!(
            (e - 1.0).abs() <= TOLERANCE + 4.0 * se,
            "θo {theta}: {e} ± {se}"
        );
        let gold = LayeredBrdf::new(
            MicrofacetBrdf::new(patch, ConductorFresnel::GOLD),
            Vec3::splat(0.9),
        )
        .unwrap()
        .with_energy_compensation(brdf::bxdf::average_fresnel(&ConductorFresnel::GOLD));
        for (c, (m, se)) in support::bxdf::stratified_weight_moments(&gold, wo, 4096, 5)
            .into_iter()
            .enumerate()
        {
            assert!(m <= 1.0 + 4.0 * se, "θo {theta} channel {c}: {m} ± {se}");
        }
    }
}

/// `GlintMaterial::with_energy_compensation` through `Material::bsdf`: the same values as the
/// compensated BRDF built by hand, alone and over a base; off by default.
#[test]
fn the_material_gives_the_compensated_brdf() {
    let (_, map) = support::procedural_maps(64).into_iter().next().unwrap();
    let model: std::sync::Arc<GlintModel> = std::sync::Arc::new(
        BeckmannMixture::build(&map, MixtureParams::default())
            .unwrap()
            .into(),
    );
    let plain = GlintMaterial::new(model.clone(), NoFresnel);
    assert!(plain.energy_compensation().is_none());
    let glint = plain.clone().with_energy_compensation();
    assert_eq!(glint.energy_compensation(), Some(Vec3::ONE));
    let scratch = GlintScratch::default();
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 16.0, 64, 64);
    let (wo, wi) = (support::dir(70.0, 40.0), support::dir(50.0, 250.0));
    let material = Material::Glint(glint.clone());
    let bsdf = material.bsdf(&fp, wo, &scratch);
    let mut patch = model.patch_in(&glint.map_footprint(&fp), &scratch);
    patch.prepare_view(wo);
    let by_hand = ViewCompensated::new(MicrofacetBrdf::new(patch, NoFresnel), wo).unwrap();
    assert_eq!(bsdf.eval_pdf(wo, wi), by_hand.eval_pdf(wo, wi));
    let uncompensated = Material::Glint(plain).bsdf(&fp, wo, &scratch).eval(wo, wi);
    assert!(bsdf.eval(wo, wi).x > uncompensated.x, "the lobe adds to f");
    // Over a base the coat carries the lobe too (white Fresnel: R̂ = 1, the base gets nothing).
    let base = Vec3::splat(0.5);
    let coat = Material::Glint(glint.over_base(base).unwrap());
    let plain_coat = Material::Glint(
        GlintMaterial::new(model.clone(), NoFresnel)
            .over_base(base)
            .unwrap(),
    );
    let a = coat.bsdf(&fp, wo, &scratch).eval(wo, wi);
    let b = plain_coat.bsdf(&fp, wo, &scratch).eval(wo, wi);
    assert!(a.x > b.x, "{a} {b}");
}
