//! The Beckmann mixture's masking terms: the normalisation and Smith identities (V_P = ∫⟨w,m⟩⁺ D_P,
//! the signed projected area A_P = ∫(w·m) D_P) by quadrature per lobe and over the model's own D_P,
//! the paper's clamped projected area, the exact V_P by the lobe blocks against an `f64` sum, and the
//! white furnace of the P-BRDF in both masking modes.

use crate::support;

use brdf::bxdf::Masking;
use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf, MixturePatch};
use brdf::ndf::Ndf;
use brdf::{MicrofacetBrdf, Vec2, Vec3};
use support::mixture::*;

/// Σ_i W_i ∫ g(s) P22_i(s) ds, each lobe integrated in its whitened coordinates s = μ + L z on
/// z ∈ [−7, 7]² with step 0.25 (and 0.5 for the error estimate), P22_i from the lobe. The step is
/// that fine because g may have a kink (⟨w, m⟩⁺) inside a lobe, where the trapezoid rule is only
/// O(step²) and the two-step estimate can fall short of the error when the kink's position against
/// the grid happens to favour the coarse rule.
fn integrate_per_lobe(patch: &MixturePatch, g: &dyn Fn([f64; 2]) -> f64) -> (f64, f64) {
    let (mut fine, mut coarse) = (0.0, 0.0);
    for (w, lobe) in patch.weighted_lobes() {
        let l = lobe.cholesky();
        let (l11, l21, l22) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
        let mu = lobe.mean();
        let (mut f, mut c) = (0.0, 0.0);
        for j in -28i32..=28 {
            for i in -28i32..=28 {
                let (zx, zy) = (i as f64 * 0.25, j as f64 * 0.25);
                let s = [mu.x as f64 + l11 * zx, mu.y as f64 + l21 * zx + l22 * zy];
                let p = lobe.p22(Vec2::new(s[0] as f32, s[1] as f32)) as f64 * l11 * l22;
                let v = g(s) * p;
                f += v;
                if i % 2 == 0 && j % 2 == 0 {
                    c += v;
                }
            }
        }
        fine += w as f64 * f * 0.0625;
        coarse += w as f64 * c * 0.25;
    }
    (fine, (fine - coarse).abs())
}

/// The directions of the identity checks.
fn identity_dirs() -> Vec<Vec3> {
    let mut v = vec![];
    for theta in [0.0, 30.0, 60.0, 85.0] {
        for phi in [0.0, 135.0] {
            v.push(support::dir(theta, phi));
        }
    }
    v
}

fn proj(w: Vec3, s: [f64; 2]) -> f64 {
    w.z as f64 - w.x as f64 * s[0] - w.y as f64 * s[1]
}

/// The normalisation and Smith identities of every lobe of patches of 1, 16 and 256 texels, on every
/// test map; [`normalisation_and_smith_identities_per_lobe_at_4096`] adds the 4096-texel patches
/// (their thousands of lobes, each integrated on a 57² grid toward 8 directions, take 15-30 s).
#[test]
fn normalisation_and_smith_identities_per_lobe() {
    normalisation_and_smith_identities_per_lobe_at(&AREAS[..3]);
}

/// [`normalisation_and_smith_identities_per_lobe`] at every footprint of `AREAS`:
/// `cargo test --release --test it -- --ignored
/// mixture_masking::normalisation_and_smith_identities_per_lobe_at_4096`.
#[test]
#[ignore]
fn normalisation_and_smith_identities_per_lobe_at_4096() {
    normalisation_and_smith_identities_per_lobe_at(&AREAS);
}

fn normalisation_and_smith_identities_per_lobe_at(areas: &[f32]) {
    let mut worst = [0.0f64; 3];
    for (name, map) in maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for &area in areas {
            let patch = exact_patch(&mix, &footprint(area, Vec2::new(0.37, 0.61)));
            let (norm, err) = integrate_per_lobe(&patch, &|_| 1.0);
            // Trapezoid on whitened Gaussians: exponentially accurate (< 1e-9) + f32 P22 (1e-6).
            assert!(
                (norm - 1.0).abs() < 1e-4,
                "{name} {area}: ∫D cos = {norm} ± {err}"
            );
            worst[0] = worst[0].max((norm - 1.0).abs());
            for w in identity_dirs() {
                let (v, ev) = integrate_per_lobe(&patch, &|s| proj(w, s).max(0.0));
                let (a, ea) = integrate_per_lobe(&patch, &|s| proj(w, s));
                let v_model = patch.visible_area(w) as f64;
                let a_model = patch.signed_projected_area(w) as f64;
                let rel_v = (v - v_model).abs() / v_model.max(1e-3);
                // 1e-3 relative, plus 3× the quadrature error estimate ev: the kink of ⟨w,m⟩⁺ makes
                // the trapezoid rule O(step²) there, which matters only for tiny V at grazing w.
                assert!(
                    (v - v_model).abs() < 1e-3 * v_model + 3.0 * ev,
                    "{name} {area} {w}: V {v} ± {ev} vs {v_model}"
                );
                assert!(
                    (a - a_model).abs() < 1e-4,
                    "{name} {area} {w}: A {a} ± {ea} vs {a_model}"
                );
                worst[1] = worst[1].max(rel_v);
                worst[2] = worst[2].max((a - a_model).abs());
                if a_model > 1e-3 {
                    let l = patch.lambda(w) as f64;
                    assert!(
                        l >= 0.0 && ((1.0 + l) * a_model - v_model).abs() < 1e-4 * v_model + 1e-6
                    );
                }
            }
        }
    }
    println!(
        "per lobe: worst |∫D cos − 1| = {:.2e}, worst rel. V error = {:.2e}, worst A error = {:.2e}",
        worst[0], worst[1], worst[2]
    );
}

#[test]
fn normalisation_and_smith_identities_full_quadrature() {
    // The model's d() itself on a slope grid (step = half the narrowest σ): footprints of 1 and 16
    // texels (larger ones are covered per lobe above and by the brute-force agreement).
    let mut worst = [0.0f64; 2];
    for (name, map) in maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for area in [1.0, 16.0] {
            let patch = exact_patch(&mix, &footprint(area, Vec2::new(0.37, 0.61)));
            let gv = grid_values(&patch);
            let (norm, err) = integrate_grid(&gv, &|_, p| p);
            // Error estimate err from the doubled step (< 1e-6 here); target 1e-3.
            assert!(
                (norm - 1.0).abs() < 1e-3 && err < 1e-4,
                "{name} {area}: ∫D cos = {norm} ± {err}"
            );
            worst[0] = worst[0].max((norm - 1.0).abs());
            for w in identity_dirs() {
                let (v, ev) = integrate_grid(&gv, &|s, p| proj(w, s).max(0.0) * p);
                let v_model = patch.visible_area(w) as f64;
                let rel_v = (v - v_model).abs() / v_model.max(1e-3);
                assert!(rel_v < 1e-3, "{name} {area} {w}: V {v} ± {ev} vs {v_model}");
                worst[1] = worst[1].max(rel_v);
            }
        }
    }
    println!(
        "full grid: worst |∫D cos − 1| = {:.2e}, worst rel. V error = {:.2e}",
        worst[0], worst[1]
    );
}

#[test]
fn paper_projected_area_matches_per_lobe_clamped_integrals() {
    // Eq. 17 as printed: Σ W_i max(∫(w·m) D_i dm, 0), each lobe integrated by the trapezoid rule on
    // its own ±8σ grid from its own P22.
    let map = noise(16, 5);
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 4.0, 16, 16);
    let patch = exact_patch(&mix, &fp);
    for theta in [40.0, 80.0] {
        let w = support::dir(theta, 30.0);
        let mut sum = 0.0;
        for (wi, g) in patch.weighted_lobes() {
            let c = g.covariance();
            let (sx, sy) = ((c.x_axis.x as f64).sqrt(), (c.y_axis.y as f64).sqrt());
            let step = 0.25 * sx.min(sy);
            let m = g.mean();
            let n = (16.0 * sx.max(sy) / step) as i64;
            let mut a = 0.0;
            for j in -n..=n {
                for i in -n..=n {
                    let s = Vec2::new(
                        m.x + (i as f64 * step) as f32,
                        m.y + (j as f64 * step) as f32,
                    );
                    a += (w.z as f64 - w.x as f64 * s.x as f64 - w.y as f64 * s.y as f64)
                        * g.p22(s) as f64;
                }
            }
            sum += wi as f64 * (a * step * step).max(0.0);
        }
        let model = patch.paper_projected_area(w) as f64;
        // Trapezoid on Gaussians (exponential convergence) + f32 evaluation: 1e-4.
        assert!((sum - model).abs() < 1e-4, "θ={theta}: {sum} vs {model}");
        // Clamped ≥ signed: the paper's A_P over-counts back-facing lobes.
        assert!(model >= patch.signed_projected_area(w) as f64 - 1e-6);
    }
}

/// The white furnace of the P-BRDF (F = 1, separable G2) in the renderer's measure, with exact and
/// approximate masking: ∫ f cos θi dωi = ∫ D_wo(m) G1(wi, m) dm ≤ 1 whenever V_P(wo) is exact or an
/// upper bound (src/bxdf/microfacet.rs, "The renderer's measure"), which both modes guarantee (the
/// approximate one through Scarf's bound): asserted for both. Prints markdown rows for
/// docs/results.md (`cargo test --release --test it mixture_masking::white_furnace -- --nocapture`).
#[test]
fn white_furnace_exact_and_approximate() {
    let mut lines = vec![];
    let thetas = [0.0, 45.0, 70.0, 85.0];
    for (name, map) in procedural_maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for area in AREAS {
            let mut row = vec![];
            for masking in [MaskingMode::Exact, MaskingMode::Approximate] {
                let options = PatchOptions {
                    masking,
                    lod_lobes: f32::INFINITY,
                    lod_tolerance: 0.0,
                    ..PatchOptions::default()
                };
                let patch = mix.patch_with(&footprint(area, Vec2::new(0.37, 0.61)), &options, None);
                for theta in thetas {
                    let wo = support::dir(theta, 60.0);
                    let brdf =
                        MicrofacetBrdf::new(&patch, NoFresnel).with_masking(Masking::Separable);
                    let (e, err) = support::albedo(&brdf, wo, 2000);
                    // ≤ 1 + 4 standard errors (stratified draws make the bound conservative)
                    // + 1e-5 for the f32 evaluation of f, pdf and A (a few ulps each): a patch
                    // that is a single mirror-like lobe sits at 1 with a tiny error.
                    assert!(
                        e.is_finite() && e <= 1.0 + 4.0 * err + 1e-5,
                        "{name} {area} {masking:?} θo={theta}: albedo {e} ± {err}"
                    );
                    row.push(format!("{e:.3}"));
                }
            }
            lines.push(format!("| {name} | {area} | {} |", row.join(" | ")));
        }
    }
    println!(
        "renderer's-measure albedo\n| map | footprint | exact 0° | 45° | 70° | 85° | approximate 0° | 45° | 70° | 85° |\n|{}\n{}",
        "---|".repeat(10),
        lines.join("\n")
    );
}

/// V = ∫⟨w, m⟩⁺ D dm of one lobe in f64 from its public mean and Cholesky factor:
/// s_w G(A_s/s_w), G(z) = z Φ(z) + φ(z) (docs/slope_gaussian.md), with libm's erfc.
fn visible_f64(g: &brdf::ndf::SlopeGaussian, w: Vec3) -> f64 {
    let (mu, l) = (g.mean(), g.cholesky());
    let (wx, wy, wz) = (w.x as f64, w.y as f64, w.z as f64);
    let a = wz - (mu.x as f64 * wx + mu.y as f64 * wy);
    let vx = l.x_axis.x as f64 * wx + l.x_axis.y as f64 * wy;
    let vy = l.y_axis.y as f64 * wy;
    let s = (vx * vx + vy * vy).sqrt();
    if s == 0.0 {
        return a.max(0.0);
    }
    let z = a / s;
    let phi = (-0.5 * z * z).exp() / (std::f64::consts::TAU).sqrt();
    let cdf = 0.5 * libm::erfc(-z / std::f64::consts::SQRT_2);
    // For z < 0, z Φ(z) + φ(z) cancels; its magnitude stays above f64's resolution for z > −20.
    s * (z * cdf + phi)
}

proptest::proptest! {
    #![proptest_config(support::proptest_config(256))]

    /// Exact V_P(w) by the lobe blocks' lane kernel (`visible_area_blocks`, the patch's exact V_P)
    /// = Σ W_i V_i(w) summed here in f64 (libm erfc) over the patch's public lobes, to 1.2e-6
    /// relative, for views from normal incidence to 89°; the patch's `visible_area` is the same
    /// number.
    #[test]
    fn block_visible_area_equals_the_f64_sum_of_the_lobes(
        which in 0usize..5, cx in 0.0f32..1.0, cy in 0.0f32..1.0,
        log_area in -2.0f32..13.0, theta in 0.0f32..89.0, phi in 0.0f32..360.0,
    ) {
        let (name, mix) = &block_mixtures()[which];
        let fp = Footprint::isotropic_texels(Vec2::new(cx, cy), log_area.exp2(), N, N);
        let patch = exact_patch(mix, &fp);
        let w = support::dir(theta as f64, phi as f64);
        let reference: f64 = patch
            .weighted_lobes()
            .map(|(wi, g)| wi as f64 * visible_f64(&g, w))
            .sum();
        let v = patch.visible_area_exact(w) as f64;
        proptest::prop_assert_eq!(v, patch.visible_area(w) as f64);
        // 1.2e-6 relative: the lanes' stated bound, 1e-6 on each W_i V_i (G(−t) by a fitted
        // exponent, blocks of lobes all at z ≥ 5 skip a term < 1.07e-8 V), plus the f32 rounding of
        // the returned V_P (6e-8) and of the f32 A_s in the skip test's threshold; 1e-37: f32's
        // normal range.
        proptest::prop_assert!(
            (v - reference).abs() <= 1.2e-6 * reference + 1e-37,
            "{name} θ {theta}: V_P {v} vs f64 sum {reference}"
        );
        // Λ_P = V_P/A_P − 1 with the same A_P: 1 + Λ carries V_P's relative error, plus the f32
        // rounding of Λ (6e-8 of Λ); A_P ≤ 0 gives f32::MAX either way.
        let a = patch.projected_area(w) as f64;
        let l = patch.lambda(w) as f64;
        if a > 0.0 {
            let want = reference / a - 1.0;
            proptest::prop_assert!(
                (l - want).abs() <= 1.3e-6 * (1.0 + want.abs()) + 1e-37 / a,
                "{name} θ {theta}: Λ_P {l} vs f64 {want}"
            );
        } else {
            proptest::prop_assert_eq!(l, f32::MAX as f64);
        }
    }
}
