//! Multiple-scattering energy compensation (`EnergyCompensated`): the white furnace a renderer sees
//! (hemisphere quadrature of eval · cos θi and the mean of `sample().weight()`), the albedo tables
//! against fresh integration, reciprocity, sample / eval / pdf agreement, chi-square of the sampler,
//! the coloured-metal effect, the anisotropic furnace (tables over μ, φo, αx, αy), and the measured
//! furnace of what the compensation does not cover (glint patches).
//!
//! Full furnace grids: `cargo test --release --test it energy_compensation:: -- --ignored --nocapture`.

use crate::support;

use brdf::bxdf::{
    ALBEDO_GRID, AlbedoTable, Bxdf, EnergyCompensated, MicrofacetBrdf, TabulatedAlbedo,
};
use brdf::fresnel::{ConductorFresnel, Fresnel, NoFresnel, SchlickFresnel};
use brdf::glint::mixture::MixtureParams;
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf, bumpy};
use brdf::ndf::{Beckmann, Ggx, Ndf};
use brdf::{Vec2, Vec3};
use rand::RngExt;
use support::bxdf::random_upper;
use support::chi2::Chi2;
use support::quadrature::integrate_band;
use support::{dir, rng};

mod anisotropic;

/// The furnace target: |E − 1| ≤ 0.5 % for α ∈ [0.01, 1], θo ≤ 85°.
const TARGET: f64 = 5e-3;

/// ∫ eval(wo, wi) cos θi dωi (channel `c`) over the half vector m, wi = reflect(wo, m),
/// dωi = 4 (wo·m) dωm, with θm split into bands at atan(k α) (k = ½, 2, 6, 20, 60, 200) so that
/// the specular peak (width ~α) and the horizon cut near it get panels of their own size. Every wi
/// in the upper hemisphere has its half vector in the upper hemisphere, so this covers the
/// compensation lobe too. `scale` multiplies panels and φ points. Independent of the tables' rule
/// (a sampler's unit square).
fn albedo_quadrature(b: &dyn Bxdf, wo: Vec3, alpha: f64, c: usize, scale: usize) -> f64 {
    let g = |m: Vec3| {
        let k = wo.dot(m);
        if k <= 0.0 {
            return 0.0;
        }
        let wi = 2.0 * k * m - wo;
        b.eval(wo, wi)[c] as f64 * wi.z.max(0.0) as f64 * 4.0 * k as f64
    };
    let mut edges = vec![0.0];
    for k in [0.5, 2.0, 6.0, 20.0, 60.0, 200.0] {
        let t = (k * alpha).atan();
        if t < 1.5 {
            edges.push(t);
        }
    }
    edges.push(std::f64::consts::FRAC_PI_2);
    edges
        .windows(2)
        .map(|w| integrate_band(&g, w[0], w[1], 6 * scale, 96 * scale))
        .sum()
}

/// The quadrature furnace and its error estimate |I(2) − I(1)|.
fn furnace_by_eval(b: &dyn Bxdf, wo: Vec3, alpha: f64) -> (f64, f64) {
    let fine = albedo_quadrature(b, wo, alpha, 0, 2);
    let coarse = albedo_quadrature(b, wo, alpha, 0, 1);
    (fine, (fine - coarse).abs())
}

/// The mean of `sample().weight()` (channel 0) over `n` stratified draws, and its standard error.
fn furnace_by_weight(b: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut r = rng(seed);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let u = Vec2::new((k as f32 + r.random::<f32>()) / n as f32, r.random());
        let w = b
            .sample(wo, r.random(), u)
            .map_or(0.0, |x| x.weight().x as f64);
        s += w;
        s2 += w * w;
    }
    let mean = s / n as f64;
    (
        mean,
        ((s2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

fn compensated<D: TabulatedAlbedo, F: Fresnel>(ndf: D, f: F) -> EnergyCompensated<D, F> {
    EnergyCompensated::new(MicrofacetBrdf::new(ndf, f)).unwrap()
}

/// Both families at α, F = 1, compensated.
fn white(alpha: f32) -> Vec<(&'static str, Box<dyn Bxdf>)> {
    vec![
        (
            "ggx",
            Box::new(compensated(Ggx::isotropic(alpha).unwrap(), NoFresnel)),
        ),
        (
            "beckmann",
            Box::new(compensated(Beckmann::isotropic(alpha).unwrap(), NoFresnel)),
        ),
    ]
}

/// Checks the furnace of every family at every (α, θo) with both estimators; returns the largest
/// |E − 1| seen.
fn check_furnace(alphas: &[f32], thetas: &[f64], n: usize) -> f64 {
    let mut worst = 0.0f64;
    for &alpha in alphas {
        for (name, b) in white(alpha) {
            for &t in thetas {
                let wo = dir(t, 0.0);
                let (e, err) = furnace_by_eval(b.as_ref(), wo, alpha as f64);
                // The quadrature's own error must be far below the target for the check to mean
                // anything (it is ~1e-5 except where the horizon cuts a wide lobe).
                assert!(
                    err < 5e-4,
                    "{name} α={alpha} θo={t}: quadrature error {err}"
                );
                assert!(
                    (e - 1.0).abs() <= TARGET,
                    "{name} α={alpha} θo={t}: ∫ f cos = {e}"
                );
                let (m, se) = furnace_by_weight(b.as_ref(), wo, n, 17);
                // 4 standard errors of the mean on top of the target (the estimator's own noise).
                assert!(
                    (m - 1.0).abs() <= TARGET + 4.0 * se,
                    "{name} α={alpha} θo={t}: mean weight {m} ± {se}"
                );
                worst = worst.max((e - 1.0).abs()).max((m - 1.0).abs());
            }
        }
    }
    worst
}

#[test]
fn white_furnace_is_one_on_a_coarse_grid() {
    // α off the table's nodes (the interpolation error is largest between nodes), both ends of
    // the range included.
    let worst = check_furnace(
        &[0.01, 0.037, 0.13, 0.42, 0.77, 1.0],
        &[0.0, 40.0, 70.0, 85.0],
        100_000,
    );
    eprintln!("coarse grid: max |E − 1| = {worst:.2e}");
}

#[test]
#[ignore = "full grid, ~2 min: cargo test --release --test it energy_compensation:: -- --ignored"]
fn white_furnace_is_one_on_the_full_grid() {
    let alphas: Vec<f32> = (0..=24)
        .map(|k| 0.01 * 100f32.powf(k as f32 / 24.0))
        .collect();
    let thetas: Vec<f64> = (0..=17).map(|k| 5.0 * k as f64).collect();
    let worst = check_furnace(&alphas, &thetas, 200_000);
    eprintln!("full grid: max |E − 1| = {worst:.2e}");
}

/// The furnace table of docs/results.md: before (single scattering) and after, GGX and Beckmann.
#[test]
#[ignore = "prints the before/after table of docs/results.md"]
fn furnace_before_after_table() {
    let thetas = [0.0, 30.0, 60.0, 75.0, 85.0];
    for family in ["ggx", "beckmann"] {
        println!("{family}: before → after");
        for alpha in [0.01f32, 0.1, 0.25, 0.5, 0.75, 1.0] {
            let mut row = format!("| {alpha} |");
            for t in thetas {
                let wo = dir(t, 0.0);
                let (before, after) = match family {
                    "ggx" => {
                        let ss = MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), NoFresnel);
                        let ms = EnergyCompensated::new(ss).unwrap();
                        (
                            furnace_by_eval(&ss, wo, alpha as f64).0,
                            furnace_by_eval(&ms, wo, alpha as f64).0,
                        )
                    }
                    _ => {
                        let ss =
                            MicrofacetBrdf::new(Beckmann::isotropic(alpha).unwrap(), NoFresnel);
                        let ms = EnergyCompensated::new(ss).unwrap();
                        (
                            furnace_by_eval(&ss, wo, alpha as f64).0,
                            furnace_by_eval(&ms, wo, alpha as f64).0,
                        )
                    }
                };
                row += &format!(" {before:.4} → {after:.4} |");
            }
            println!("{row}");
        }
    }
}

#[test]
fn tables_match_fresh_integration() {
    // A coarse subset of nodes (α ≥ 0.02, θo ≤ 85°) recomputed by the banded half-vector
    // quadrature of the single-scattering BRDF's eval, not the generator's sampler rule. The
    // tolerance is the generator's stated quadrature error (its header: ≤ 2·10⁻³ at θo ≤ 85°)
    // plus this quadrature's own error estimate.
    let mut worst = 0.0f64;
    for j in [10, 25, 40, 52, ALBEDO_GRID - 1] {
        let alpha = AlbedoTable::alpha_node(j);
        for i in [6, 20, 45, ALBEDO_GRID - 1] {
            let mu = AlbedoTable::mu_node(i);
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            for (table, fresh) in [
                (
                    &AlbedoTable::GGX,
                    furnace_by_eval(
                        &MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), NoFresnel),
                        wo,
                        alpha as f64,
                    ),
                ),
                (
                    &AlbedoTable::BECKMANN,
                    furnace_by_eval(
                        &MicrofacetBrdf::new(Beckmann::isotropic(alpha).unwrap(), NoFresnel),
                        wo,
                        alpha as f64,
                    ),
                ),
            ] {
                let d = (table.entry(i, j) as f64 - fresh.0).abs();
                assert!(
                    d <= 2e-3 + 4.0 * fresh.1,
                    "{} μ={mu} α={alpha}: table {} vs fresh {} ± {}",
                    table.name(),
                    table.entry(i, j),
                    fresh.0,
                    fresh.1
                );
                worst = worst.max(d);
            }
        }
    }
    eprintln!("tables vs fresh integration: max |ΔE| = {worst:.2e}");
}

#[test]
fn compensation_lobe_is_reciprocal() {
    let mut r = rng(3);
    let gold = compensated(Ggx::isotropic(0.6).unwrap(), ConductorFresnel::GOLD);
    let aniso = compensated(
        Beckmann::new(0.3, 0.9).unwrap(),
        SchlickFresnel::new(Vec3::splat(0.5)).unwrap(),
    );
    let extreme = compensated(Ggx::new(0.01, 1.0).unwrap(), ConductorFresnel::GOLD);
    let rough = compensated(Beckmann::new(1.0, 0.2).unwrap(), NoFresnel);
    assert!(aniso.is_anisotropic() && extreme.is_anisotropic() && !gold.is_anisotropic());
    for _ in 0..20_000 {
        let (wo, wi) = (random_upper(&mut r), random_upper(&mut r));
        for b in [&gold as &dyn Bxdf, &aniso, &extreme, &rough] {
            let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
            // f32 rounding of the two evaluation orders: a few ulps of the larger value.
            let tol = 4e-6 * a.max(c).max_element().max(1e-30);
            assert!((a - c).abs().max_element() <= tol, "{wo} {wi}: {a} vs {c}");
        }
    }
}

#[test]
fn sample_agrees_with_eval_and_pdf() {
    let mut r = rng(5);
    let b = compensated(Ggx::new(0.2, 0.7).unwrap(), ConductorFresnel::GOLD);
    let mut diffuse = 0;
    for _ in 0..20_000 {
        let wo = random_upper(&mut r);
        let (uc, u) = (r.random::<f32>(), Vec2::new(r.random(), r.random()));
        if let Some(s) = b.sample(wo, uc, u) {
            let (f, pdf) = b.eval_pdf(wo, s.wi);
            assert_eq!(s.f, f);
            assert_eq!(s.pdf, pdf);
            assert_eq!(b.pdf(wo, s.wi), pdf);
            assert!(s.weight().is_finite());
            diffuse += s.flags.contains(brdf::bxdf::LobeFlags::DIFFUSE) as usize;
        }
    }
    assert!(diffuse > 0, "the compensation lobe was never sampled");
}

#[test]
fn evaluation_is_total() {
    let b = compensated(Beckmann::isotropic(0.5).unwrap(), ConductorFresnel::GOLD);
    let bad = [
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::NAN,
        Vec3::ZERO,
        Vec3::new(f32::INFINITY, 0.0, 1.0),
    ];
    let good = Vec3::new(0.3, 0.1, 0.9).normalize();
    for w in bad {
        assert_eq!(b.eval(good, w), Vec3::ZERO);
        assert_eq!(b.eval(w, good), Vec3::ZERO);
        assert_eq!(b.pdf(good, w), 0.0);
        assert_eq!(b.pdf(w, good), 0.0);
        assert!(b.sample(w, 0.5, Vec2::splat(0.5)).is_none());
    }
    assert!(b.sample(good, f32::NAN, Vec2::splat(0.5)).is_none());
}

#[test]
fn sampler_passes_chi_square() {
    let cases: Vec<(&str, Box<dyn Bxdf>, f64)> = vec![
        (
            "ggx 0.5 white 30°",
            Box::new(compensated(Ggx::isotropic(0.5).unwrap(), NoFresnel)),
            30.0,
        ),
        (
            "ggx 1.0 gold 70°",
            Box::new(compensated(
                Ggx::isotropic(1.0).unwrap(),
                ConductorFresnel::GOLD,
            )),
            70.0,
        ),
        (
            "beckmann 0.8 white 60°",
            Box::new(compensated(Beckmann::isotropic(0.8).unwrap(), NoFresnel)),
            60.0,
        ),
        (
            "ggx 0.15/0.9 gold 45°",
            Box::new(compensated(
                Ggx::new(0.15, 0.9).unwrap(),
                ConductorFresnel::GOLD,
            )),
            45.0,
        ),
        (
            "ggx 0.01/1.0 white 70°",
            Box::new(compensated(Ggx::new(0.01, 1.0).unwrap(), NoFresnel)),
            70.0,
        ),
        (
            "beckmann 1.0/0.05 gold 80°",
            Box::new(compensated(
                Beckmann::new(1.0, 0.05).unwrap(),
                ConductorFresnel::GOLD,
            )),
            80.0,
        ),
    ];
    let family = cases.len();
    for (name, b, t) in cases {
        let wo = dir(t, 20.0);
        let p = Chi2::new(format!("energy {name}"), family).run(
            |uc, u| b.sample(wo, uc, u).map(|s| s.wi),
            |w| b.pdf(wo, w) as f64,
        );
        assert!(p.is_ok(), "{name}: {}", p.unwrap_err());
    }
}

/// Per-channel furnace of a coloured BRDF by quadrature.
fn rgb_furnace(b: &dyn Bxdf, wo: Vec3, alpha: f64) -> Vec3 {
    Vec3::new(
        albedo_quadrature(b, wo, alpha, 0, 1) as f32,
        albedo_quadrature(b, wo, alpha, 1, 1) as f32,
        albedo_quadrature(b, wo, alpha, 2, 1) as f32,
    )
}

#[test]
fn rough_gold_gains_saturated_energy() {
    // Each extra bounce multiplies by F ≈ F_avg, so the energy given back is F_ms ~ F_avg² / ...:
    // proportionally more in red than in blue, and the compensated gold stays below white.
    let alpha = 0.8;
    let ss = MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), ConductorFresnel::GOLD);
    let ms = EnergyCompensated::new(ss).unwrap();
    let wo = dir(30.0, 0.0);
    let (before, after) = (
        rgb_furnace(&ss, wo, alpha as f64),
        rgb_furnace(&ms, wo, alpha as f64),
    );
    eprintln!("gold α={alpha} θo=30°: before {before}, after {after}");
    assert!(after.cmpgt(before).all(), "{before} → {after}");
    assert!(after.max_element() < 1.0);
    let gain = after / before;
    assert!(
        gain.x > gain.z,
        "gain {gain}: red should gain more than blue"
    );
}

#[test]
fn glint_patch_furnace_is_measured() {
    // Glint patches get no compensation (docs/bxdf.md): a bumpy BeckmannMixture patch at a
    // footprint of 64 texels², furnace by the mean sample weight (renderer's measure). Its loss is
    // stated in docs/results.md; here it must stay ≤ 1 and be a loss of the size of the equivalent
    // Beckmann surface's (RMS slope 0.25: α ≈ 0.35), not an artefact.
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let model = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 64.0, 64, 64);
    let patch = model.patch(&fp);
    let brdf = MicrofacetBrdf::new(&patch as &dyn Ndf, NoFresnel);
    let equivalent =
        MicrofacetBrdf::new(Beckmann::isotropic(0.25 * 2f32.sqrt()).unwrap(), NoFresnel);
    for t in [0.0, 45.0, 70.0, 85.0] {
        let wo = dir(t, 0.0);
        let n = crate::support::depth(50_000, 200_000);
        let (e, se) = furnace_by_weight(&brdf, wo, n, 23);
        let (eq, _) = furnace_by_weight(&equivalent, wo, n, 23);
        eprintln!(
            "glint patch θo={t}: E = {e:.4} ± {se:.1e} (equivalent Beckmann α=0.354: {eq:.4})"
        );
        assert!(e <= 1.0 + 4.0 * se, "θo={t}: {e}");
        assert!((e - eq).abs() < 0.1, "θo={t}: patch {e} vs equivalent {eq}");
    }
}
