//! The Beckmann mixture's merged levels of detail l ≥ 1 read like level 0: D_P against the
//! brute-force sum of the patch's merged lobes, both samplers' chi-square and the white furnace at a
//! merged level, and the level of detail's tolerance against the measured TV to the full mixture
//! (the bound's derivation: src/glint/mixture/levels.rs; its diagnosis at r > 0:
//! tests/it/mixture_lod.rs).

use crate::support;

use brdf::bxdf::Masking;
use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf, MixturePatch};
use brdf::ndf::Ndf;
use brdf::{MicrofacetBrdf, Vec2};
use support::mixture::*;

/// TV between a patch's D_P and another's grid values, ½ ∫ |P22_a − P22_b| ds on `b`'s slope grid
/// (every lobe of `b` to ±8 σ, step half the narrowest σ) by the trapezoid rule, with the
/// quadrature's own error estimate (the same sum at twice the step).
fn tv_to_grid(a: &MixturePatch, b: &GridValues) -> (f64, f64) {
    integrate_grid(b, &|s, p| {
        let (m, mz) = normal_of(s);
        0.5 * (a.d(m) as f64 * mz.powi(4) - p).abs()
    })
}

/// The patch at tolerance `tol` against the full mixture's grid values `full`: (its level, its
/// bound Σ W_n e(n), the TV between the two, the quadrature's error estimate of that TV).
fn lod_against_full(
    mix: &BeckmannMixture,
    fp: &Footprint,
    tol: f32,
    full: &GridValues,
) -> (usize, f64, f64, f64) {
    let p = mix.patch_with(
        fp,
        &PatchOptions {
            lod_tolerance: tol,
            // The continuous bound: this compares continuous TVs (tests/it/mixture_lod.rs checks the
            // bounds at r > 0 against blurred TVs).
            lod_resolution: 0.0,
            ..exact_options()
        },
        None,
    );
    let (tv, q) = tv_to_grid(&p, full);
    (p.level(), p.lod_error() as f64, tv, q)
}

/// The level of detail respects its tolerance: on the four procedural maps (64²) at a 256-texel
/// footprint, the TV between the level-of-detail patch and the full mixture (same footprint) is at
/// most the patch's bound Σ W_n e(n) (src/glint/mixture/levels.rs), which is at most the tolerance,
/// plus three times the quadrature's error estimate. The bound covers the merged lobes, not the
/// node weights (each node's weight is the moment-matched Gaussian of its lobes' weights, and the
/// weight is spread evenly over its lobes; docs/mixture.md): the test checks that this
/// approximation stays inside the bound's slack on these maps. At least three cases must pick a
/// level ≥ 1 (otherwise the test would check nothing).
#[test]
fn level_of_detail_respects_its_tolerance() {
    let centre = Vec2::new(0.43, 0.57);
    let mut merged = 0;
    for (name, map) in procedural_maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        let fp = footprint(256.0, centre);
        let full = exact_patch(&mix, &fp);
        assert_eq!(full.level(), 0);
        let gv = grid_values(&full);
        for tol in [0.02f32, 0.3] {
            let (level, bound, tv, q) = lod_against_full(&mix, &fp, tol, &gv);
            println!("{name} tol {tol}: level {level} bound {bound:.4} TV {tv:.4} (±{q:.1e})");
            assert!(
                bound <= tol as f64,
                "{name}: bound {bound} > tolerance {tol}"
            );
            assert!(
                tv <= bound + 3.0 * q,
                "{name} tol {tol}: TV {tv} > bound {bound} + 3 × {q}"
            );
            merged += (level > 0) as usize;
        }
    }
    assert!(merged >= 3, "only {merged} cases used a level ≥ 1");
}

/// A patch at a level of detail l ≥ 1 (tolerance 1: the coarsest level the footprint allows; the
/// filtered mixture off).
fn merged_patch<'a>(mix: &'a BeckmannMixture, area: f32, masking: MaskingMode) -> MixturePatch<'a> {
    let p = mix.patch_with(
        &footprint(area, Vec2::new(0.3, 0.3)),
        &PatchOptions {
            masking,
            lod_lobes: f32::INFINITY,
            lod_tolerance: 1.0,
            filtered_area: f32::INFINITY,
            cut_nodes: 0,
            ..PatchOptions::default()
        },
        None,
    );
    assert!(p.level() >= 1, "level {}", p.level());
    p
}

/// At a level l ≥ 1, D_P through the level's quadtree and blocks = Σ W_n D_n over the patch's
/// (merged) lobes written here, as at level 0 (same bound: box truncation and f32 sums).
#[test]
fn level_d_equals_the_brute_force_sum() {
    let mut rng = support::rng(19);
    for (name, map) in maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for area in [256.0, 4096.0] {
            let patch = merged_patch(&mix, area, MaskingMode::Exact);
            let lobes: Vec<_> = patch.weighted_lobes().collect();
            let peak: f64 = lobes
                .iter()
                .map(|(w, g)| *w as f64 * g.d(g.mean_normal()) as f64)
                .sum();
            for k in 0..200 {
                let m = probe_normal(&patch, &mut rng, k);
                let brute: f64 = lobes.iter().map(|(w, g)| *w as f64 * g.d(m) as f64).sum();
                let d = patch.d(m) as f64;
                assert!(
                    (d - brute).abs() <= 1e-5 * brute + 2e-6 * peak,
                    "{name} {area} level {}: {d} vs {brute}",
                    patch.level()
                );
            }
        }
    }
}

/// Both samplers of a level-1 patch (white-noise map, 16-texel footprint, level forced by the cost
/// cap) against their pdfs, by
/// the chi-square harness (as `chi_square_of_both_samplers` at level 0), and the white furnace of
/// level ≥ 1 patches on the procedural maps (as `white_furnace_exact_and_approximate`): the merged
/// lobes go through the same D, masking and sampling code, with the same guarantees.
#[test]
fn chi_square_and_furnace_at_a_merged_level() {
    let mix = BeckmannMixture::build(&noise(N, 4), MixtureParams::default()).unwrap();
    // The cost cap forces level 1 on a 16-texel footprint (16 / 4 nodes ≤ 8 < 16): few nodes, so the
    // chi-square of the O(nodes) visible sampler stays cheap.
    let patch = mix.patch_with(
        &footprint(16.0, Vec2::new(0.3, 0.3)),
        &PatchOptions {
            masking: MaskingMode::Exact,
            lod_lobes: 8.0,
            lod_tolerance: 0.0,
            filtered_area: f32::INFINITY,
            cut_nodes: 0,
            ..PatchOptions::default()
        },
        None,
    );
    assert_eq!(patch.level(), 1);
    support::chi2_patch_samplers(&patch, "level-1", &[60.0], true);
    for (name, map) in procedural_maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for masking in [MaskingMode::Exact, MaskingMode::Approximate] {
            let patch = merged_patch(&mix, 1024.0, masking);
            for theta in [0.0, 70.0, 85.0] {
                let wo = support::dir(theta, 60.0);
                let brdf = MicrofacetBrdf::new(&patch, NoFresnel).with_masking(Masking::Separable);
                let (e, err) = support::albedo(&brdf, wo, 2000);
                // As in `white_furnace_exact_and_approximate`: 4 standard errors + 1e-5 (f32).
                assert!(
                    e.is_finite() && e <= 1.0 + 4.0 * err + 1e-5,
                    "{name} level {} {masking:?} θo={theta}: albedo {e} ± {err}",
                    patch.level()
                );
            }
        }
    }
}

/// The tolerance check of `level_of_detail_respects_its_tolerance` on the 512² procedural maps
/// (where nodes merge at more footprints), with its table for docs/results.md: per map, footprint
/// and tolerance, the level, the bound Σ W_n e(n) and the measured TV to the full mixture.
///
/// `cargo test --release --test it -- --ignored mixture_levels::lod_check --nocapture`
#[test]
#[ignore]
fn lod_check() {
    let n = 512;
    println!("| map | texels | tolerance | level | bound | TV to the full mixture |");
    println!("|---|---|---|---|---|---|");
    for (name, map) in support::procedural_maps(n) {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for area in [64.0f32, 256.0, 1024.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let full = exact_patch(&mix, &fp);
            let gv = grid_values(&full);
            for tol in [0.03f32, 0.1, 0.3] {
                let (level, bound, tv, q) = lod_against_full(&mix, &fp, tol, &gv);
                println!("| {name} | {area} | {tol} | {level} | {bound:.4} | {tv:.4} ± {q:.0e} |");
                assert!(
                    tv <= bound + 3.0 * q,
                    "{name} {area} {tol}: TV {tv} > {bound}"
                );
            }
        }
    }
}
