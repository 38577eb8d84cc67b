//! Sampling of the classic BRDFs and the microfacet BRDF: chi-square goodness of fit of every sampler
//! (a subset by default, the full sweep ignored), the lost mass and the estimator's mean where the
//! harness cannot resolve the lobe, sample / eval / pdf agreement, and the weights of perfect
//! importance sampling.
//!
//! Run: `cargo test --test it bxdf_sampling::`. The full chi-square sweep:
//! `cargo test --test it -- --ignored bxdf_sampling::chi2_full`.

use crate::support;

use brdf::bxdf::{
    BlinnPhongNormalization, Bxdf, Lambert, Masking, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, PhongNormalization, Sampling,
};
use brdf::fresnel::NoFresnel;
use brdf::ndf::{Beckmann, BlinnPhong, Ggx};
use glam::{Vec2, Vec3};
use rand::RngExt;
use support::bxdf::{
    PHONG_NORMS, THETAS, albedo_half_vector, blinn, crate_microfacets, furnace_tol, ggx, mf, phong,
    random_upper, slope_gaussian,
};
use support::chi2::Chi2;
use support::quadrature::integrate_hemisphere;

/// One chi-square configuration: a model and an outgoing direction.
struct Case {
    name: String,
    bxdf: Box<dyn Bxdf>,
    wo: Vec3,
}

fn case(name: String, bxdf: impl Bxdf + 'static, theta_deg: f64) -> Case {
    Case {
        name: format!("{name} θo={theta_deg}"),
        bxdf: Box::new(bxdf),
        wo: support::dir(theta_deg, 30.0),
    }
}

/// Runs every case (sample → `s.wi`, `None` → lost mass; density `bxdf.pdf(wo, ·)`), Šidák-corrected
/// over the whole list, and reports every failure at once.
fn run_chi2(cases: &[Case]) {
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| {
            Chi2::new(&c.name, cases.len())
                .run(
                    |uc, u| c.bxdf.sample(c.wo, uc, u).map(|s| s.wi),
                    |w| c.bxdf.pdf(c.wo, w) as f64,
                )
                .err()
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// Lambert, Phong (modified with a constant and an energy-normalised N, with Fresnel, and the original
/// form) and the Blinn-Phong lobe. `full`: γ ∈ {1, 20, 200} × θo ∈ {0, 45, 80, 89} (Lambert: every θo
/// of `THETAS`); otherwise one grazing and one normal-incidence case per model at γ = 20.
fn chi2_cases_classic(full: bool) -> Vec<Case> {
    let (gammas, thetas): (&[f32], &[f64]) = if full {
        (&[1.0, 20.0, 200.0], &[0.0, 45.0, 80.0, 89.0])
    } else {
        (&[20.0], &[0.0, 80.0])
    };
    let mut v = Vec::new();
    for &t in if full { &THETAS[..] } else { &[89.0][..] } {
        v.push(case(
            "lambert".into(),
            Lambert::new(Vec3::splat(0.7)).unwrap(),
            t,
        ));
    }
    for &g in gammas {
        for (k, &t) in thetas.iter().enumerate() {
            // Default run: alternate the angle between models so that each model sees one of them.
            let pick = |i: usize| full || (i + k).is_multiple_of(2);
            if pick(0) {
                let p = phong(0.5, 0.5, g, PhongNormalization::EnergyConserving);
                v.push(case(format!("phong lafortune γ={g}"), p, t));
            }
            if pick(1) {
                let p = phong(
                    0.3,
                    0.7,
                    g,
                    PhongNormalization::EnergyNormalizedMallettYuksel,
                )
                .with_schlick_fresnel();
                v.push(case(format!("phong M-Y+Schlick γ={g}"), p, t));
            }
            if pick(0) {
                let n = OriginalPhongNormalization::EnergyConserving;
                let o = OriginalPhong::new(Vec3::splat(0.2), Vec3::splat(0.8), g, n).unwrap();
                v.push(case(format!("original phong γ={g}"), o, t));
            }
            // Blinn-Phong γ = 200 at 89°: a half-vector lobe compressed in azimuth by the reflection,
            // too thin for the harness's cells (see `chi2_cases_microfacet`); in `grazing_cases`.
            if pick(1) && !(g > 100.0 && t > 85.0) {
                let b = blinn(0.4, 0.6, g, BlinnPhongNormalization::EnergyConserving);
                v.push(case(format!("blinn-phong γ={g}"), b, t));
            }
        }
    }
    v
}

/// The microfacet BRDF × both samplers × α × θo ∈ {0, 30, 60, 80, 89}°.
///
/// Excluded: α < 0.5 at θo = 89°. There the reflected lobe is thinner in azimuth than a harness cell
/// (its width is about 4 α cos θo: 0.007 rad for α = 0.1, against cells of 2π/80 ≈ 0.079 rad), so a
/// fixed 6 × 6 Gauss rule per cell cannot compute the expected counts. Observed for α = 0.25,
/// visible normals: the cells' expected counts add up to a lost mass of 0.414 %, whereas a fine
/// half-vector quadrature of the same pdf gives 0.470 % and the sampler loses 0.470 % (4·10⁶ draws);
/// the chi-square then fails on the overflow cell alone. Those configurations are covered by
/// `lost_mass_matches_the_pdf_deficit` and `sampling_estimator_is_unbiased_at_grazing_angles`
/// ([`grazing_cases`]). The non-centred lobe (slope σ ≈ 0.2) is excluded at 89° for the same reason.
/// The harness integrates each cell adaptively (tests/it/support/chi2.rs), which resolves these lobes:
/// their chi-square at 89° is in tests/grazing_chi2.rs.
fn chi2_cases_microfacet(full: bool) -> Vec<Case> {
    let mut v = Vec::new();
    let samplings = [Sampling::Normals, Sampling::VisibleNormals];
    if full {
        for alpha in [0.1f32, 0.25, 0.5, 1.0] {
            for &t in THETAS.iter().filter(|&&t| alpha >= 0.5 || t < 85.0) {
                for s in samplings {
                    v.push(case(
                        format!("test-ggx α={alpha} {s:?}"),
                        ggx(alpha).with_sampling(s),
                        t,
                    ));
                    for (name, b) in crate_microfacets(alpha, Masking::HeightCorrelated, s) {
                        // Anisotropic (α, 2.5α): the narrow axis is α, same exclusion rule.
                        v.push(Case {
                            name: format!("{name} {s:?} θo={t}"),
                            bxdf: b,
                            wo: support::dir(t, 30.0),
                        });
                    }
                }
            }
        }
        for gamma in [10.0f32, 100.0] {
            for &t in THETAS.iter().filter(|&&t| gamma <= 10.0 || t < 85.0) {
                for s in samplings {
                    let b = MicrofacetBrdf::new(BlinnPhong::new(gamma).unwrap(), NoFresnel)
                        .with_sampling(s);
                    v.push(case(format!("blinn-phong ndf γ={gamma} {s:?}"), b, t));
                }
            }
        }
    } else {
        for s in samplings {
            v.push(case(
                format!("test-ggx α=0.5 {s:?}"),
                ggx(0.5).with_sampling(s),
                89.0,
            ));
            let beckmann = Beckmann::isotropic(0.1).unwrap();
            v.push(case(
                format!("beckmann α=0.1 {s:?}"),
                MicrofacetBrdf::new(beckmann, NoFresnel).with_sampling(s),
                60.0,
            ));
        }
        let aniso = Ggx::new(0.2, 0.5).unwrap();
        v.push(case(
            "ggx α=(0.2, 0.5) VisibleNormals".into(),
            MicrofacetBrdf::new(aniso, NoFresnel),
            30.0,
        ));
        let bp = MicrofacetBrdf::new(BlinnPhong::new(20.0).unwrap(), NoFresnel);
        v.push(case("blinn-phong ndf γ=20 VisibleNormals".into(), bp, 0.0));
    }
    // θo = 89° excluded for the same reason as narrow GGX (σ ≈ 0.2 ≈ α 0.28), see `grazing_cases`.
    let sg_thetas: &[f64] = if full { &THETAS[..4] } else { &[80.0] };
    for &t in sg_thetas {
        for s in samplings {
            let b = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_sampling(s);
            v.push(case(format!("slope-gaussian {s:?}"), b, t));
        }
    }
    v
}

/// Configurations whose lobe the chi-square harness cannot resolve (see [`chi2_cases_microfacet`]):
/// narrow half-vector lobes at θo = 89°, where reflection compresses the lobe in azimuth.
fn grazing_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        v.push(case(
            format!("test-ggx α=0.1 {s:?}"),
            ggx(0.1).with_sampling(s),
            89.0,
        ));
        let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_sampling(s);
        v.push(case(format!("slope-gaussian {s:?}"), sg, 89.0));
    }
    let b = blinn(0.4, 0.6, 200.0, BlinnPhongNormalization::EnergyConserving);
    v.push(case("blinn-phong γ=200".into(), b, 89.0));
    v.push(case(
        "test-ggx α=0.05 Normals".into(),
        ggx(0.05).with_sampling(Sampling::Normals),
        85.0,
    ));
    v
}

/// ∫_{H²} pdf(wo, wi) dω_i by the half-vector change of variables (dω_i = 4 (wo·m) dω_m), which puts
/// half-vector lobes at the pole of the quadrature.
fn pdf_mass(b: &dyn Bxdf, wo: Vec3) -> (f64, f64) {
    integrate_hemisphere(
        &|m| {
            let c = wo.dot(m);
            if c <= 0.0 {
                return 0.0;
            }
            b.pdf(wo, 2.0 * c * m - wo) as f64 * 4.0 * c as f64
        },
        128,
        256,
    )
}

/// The probability that `sample` returns `None` equals 1 − ∫_{H²} pdf (the pdf is the density of the
/// directions actually produced), checked where the chi-square harness cannot resolve the lobe.
/// The None fraction over 5·10⁵ draws has binomial standard error √(p(1−p)/n); tolerance
/// 4 standard errors + 4 × the quadrature's error estimate.
#[test]
fn lost_mass_matches_the_pdf_deficit() {
    let mut rng = support::rng(17);
    for c in grazing_cases() {
        let (mass, err) = pdf_mass(c.bxdf.as_ref(), c.wo);
        let n = 500_000;
        let lost = (0..n)
            .filter(|_| {
                let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
                c.bxdf.sample(c.wo, uc, u).is_none()
            })
            .count() as f64
            / n as f64;
        let se = (lost * (1.0 - lost) / n as f64).sqrt();
        assert!(
            (lost - (1.0 - mass)).abs() < 4.0 * se + 4.0 * err,
            "{}: lost {lost} ± {se}, 1 − ∫pdf = {} ± {err}",
            c.name,
            1.0 - mass
        );
    }
}

#[test]
fn chi2_classic() {
    run_chi2(&chi2_cases_classic(false));
}

#[test]
fn chi2_microfacet() {
    run_chi2(&chi2_cases_microfacet(false));
}

/// The whole sweep (~1 min): `cargo test --test it -- --ignored bxdf_sampling::chi2_full`.
#[test]
#[ignore]
fn chi2_full_classic() {
    run_chi2(&chi2_cases_classic(true));
}

/// The whole sweep (~1 min): `cargo test --test it -- --ignored bxdf_sampling::chi2_full`.
#[test]
#[ignore]
fn chi2_full_microfacet() {
    run_chi2(&chi2_cases_microfacet(true));
}

/// Where the chi-square harness cannot resolve the lobe ([`grazing_cases`]), the sampler is also
/// checked through its estimator: if draws followed a density q ≠ pdf, the mean of f cos θi / pdf
/// would be ∫ f cos θi q/pdf ≠ ∫ f cos θi. The mean weight over 2·10⁵ draws (`None` counts 0) must
/// match the half-vector quadrature of ∫ f cos θi within 4 standard errors plus the quadrature
/// tolerance.
#[test]
fn sampling_estimator_is_unbiased_at_grazing_angles() {
    let mut rng = support::rng(21);
    for c in grazing_cases() {
        let (e, err) = albedo_half_vector(c.bxdf.as_ref(), c.wo, 128, 256);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
            let w = c
                .bxdf
                .sample(c.wo, uc, u)
                .map_or(0.0, |s| s.weight().x as f64);
            sum += w;
            sum2 += w * w;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        assert!(
            (mean - e).abs() < 4.0 * se + furnace_tol(err),
            "{}: MC {mean} ± {se} vs quadrature {e} ± {err}",
            c.name
        );
    }
}

/// sample / eval / pdf / eval_pdf agreement and weight() = f cos / pdf, on 5000 random draws.
fn assert_consistent(name: &str, b: &dyn Bxdf) {
    let mut rng = support::rng(5);
    let mut some = 0;
    for _ in 0..5000 {
        let wo = random_upper(&mut rng);
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
        let Some(s) = b.sample(wo, uc, u) else {
            continue;
        };
        some += 1;
        assert!(
            (s.wi.length() - 1.0).abs() < 1e-5,
            "{name}: |wi| = {}",
            s.wi.length()
        );
        assert!(
            s.wi.z > 0.0 && s.pdf > 0.0 && s.pdf.is_finite(),
            "{name}: {s:?}"
        );
        let (f, pdf) = (b.eval(wo, s.wi), b.pdf(wo, s.wi));
        let (f2, pdf2) = b.eval_pdf(wo, s.wi);
        // Same f32 expressions evaluated at the same direction: equal up to 1e-6 relative.
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * a.abs().max(b.abs());
        assert!(
            close(s.pdf, pdf) && close(pdf, pdf2),
            "{name}: pdf {} {pdf} {pdf2}",
            s.pdf
        );
        for k in 0..3 {
            assert!(
                close(s.f[k], f[k]) && close(f[k], f2[k]),
                "{name}: f {} {f} {f2}",
                s.f
            );
        }
        let w = s.f * s.wi.z / s.pdf;
        assert!(
            (s.weight() - w).abs().max_element() <= 1e-6 * w.max_element(),
            "{name}"
        );
    }
    assert!(some > 1000, "{name}: only {some} samples");
}

#[test]
fn sample_eval_pdf_agree() {
    assert_consistent("lambert", &Lambert::new(Vec3::new(0.1, 0.5, 1.0)).unwrap());
    for norm in PHONG_NORMS {
        assert_consistent(&format!("phong {norm:?}"), &phong(0.4, 0.5, 8.0, norm));
        assert_consistent(
            &format!("phong {norm:?} fresnel"),
            &phong(0.4, 0.5, 8.0, norm).with_schlick_fresnel(),
        );
    }
    for norm in [
        OriginalPhongNormalization::Unnormalized,
        OriginalPhongNormalization::EnergyConserving,
    ] {
        let o = OriginalPhong::new(Vec3::splat(0.3), Vec3::splat(0.6), 15.0, norm).unwrap();
        assert_consistent(&format!("original {norm:?}"), &o);
    }
    assert_consistent(
        "blinn",
        &blinn(0.3, 0.6, 40.0, BlinnPhongNormalization::EnergyConserving),
    );
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        for m in [Masking::Separable, Masking::HeightCorrelated] {
            let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel)
                .with_sampling(s)
                .with_masking(m);
            assert_consistent(&format!("slope gaussian {s:?} {m:?}"), &sg);
            for (name, b) in crate_microfacets(0.3, m, s) {
                assert_consistent(&format!("{name} {s:?} {m:?}"), b.as_ref());
            }
            let bp = mf(BlinnPhong::new(40.0).unwrap(), m, s);
            assert_consistent(&format!("blinn-phong ndf {s:?} {m:?}"), bp.as_ref());
            assert_consistent(
                &format!("ggx {s:?} {m:?}"),
                &ggx(0.3).with_sampling(s).with_masking(m),
            );
        }
    }
}

#[test]
fn weights_of_perfect_importance_sampling() {
    // Specular only (ρ_d = 0, so the lobe is always chosen) and pdf = (γ+1)/(2π) cos^γ θr:
    // original Phong: f cos θi / pdf = ρ_s N cos^γ θr / ((γ+1)/(2π) cos^γ θr) = 2π N/(γ+1) = 1 with
    // the energy-conserving N; modified Phong (Lafortune N): 2π N cos θi/(γ+1) = (γ+2)/(γ+1) cos θi.
    // f32 arithmetic: 1e-5 relative.
    let mut rng = support::rng(9);
    let g = 10.0;
    let o = OriginalPhong::new(
        Vec3::ZERO,
        Vec3::ONE,
        g,
        OriginalPhongNormalization::EnergyConserving,
    )
    .unwrap();
    let p = phong(0.0, 1.0, g, PhongNormalization::EnergyConserving);
    let mut count = 0;
    for _ in 0..2000 {
        let wo = random_upper(&mut rng);
        let u = Vec2::new(rng.random(), rng.random());
        if let Some(s) = o.sample(wo, 0.5, u) {
            assert!(
                (s.weight().x - 1.0).abs() < 1e-5,
                "original: {}",
                s.weight()
            );
            count += 1;
        }
        if let Some(s) = p.sample(wo, 0.5, u) {
            let want = (g + 2.0) / (g + 1.0) * s.wi.z;
            assert!(
                (s.weight().x - want).abs() < 1e-5 * want,
                "modified: {} vs {want}",
                s.weight()
            );
        }
    }
    assert!(count > 500, "{count}");
}
