//! `ClearCoat`: a smooth dielectric coat over any base BxDF, through the public `Bxdf` API. White
//! furnace of a Lambertian base (= 1: Saunderson's series is exact there) the two ways a renderer
//! integrates it, furnace ≤ 1 over a conductor microfacet base and a glint base (and what the
//! plain ρ̄_b r_i series would give there), chi-square of the non-delta sampler, reciprocity,
//! η → 1, the density contract at grazing angles, the diffuse reflectances against a direct
//! quadrature, and bad input. The clear-coated `Material` (car paint) is in
//! tests/it/clear_coat_material.rs.

use crate::density_contract::{case, grid, run, u_grid};
use crate::support::{self, bxdf::random_upper, chi2::Chi2, quadrature::integrate_hemisphere};
use brdf::bxdf::{
    BaseAlbedo, Bxdf, ClearCoat, LobeFlags, MicrofacetBrdf, SpecularReflection,
    diffuse_external_reflectance, diffuse_internal_reflectance,
};
use brdf::fresnel::{ConductorFresnel, dielectric};
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{Footprint, GlintNdf};
use brdf::ndf::Ggx;
use brdf::{Error, Lambert, Vec2, Vec3};
use rand::RngExt;

/// Per channel mean and standard error of `sample().weight()` over `n` draws at `wo` (a missing
/// sample counts 0; delta samples count with their weight): the furnace a renderer sees.
pub(crate) fn sampled_furnace(b: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> (Vec3, Vec3) {
    let m = support::bxdf::stratified_weight_moments(b, wo, n, seed);
    (
        Vec3::new(m[0].0 as f32, m[1].0 as f32, m[2].0 as f32),
        Vec3::new(m[0].1 as f32, m[1].1 as f32, m[2].1 as f32),
    )
}

/// ∫ eval(wo, wi) cos θi dωi of channel 0 (the non-delta part) and the rule's error estimate.
fn quadrature(b: &dyn Bxdf, wo: Vec3, panels: usize) -> (f64, f64) {
    integrate_hemisphere(
        &|wi| b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64,
        panels,
        2 * panels,
    )
}

/// A procedural glint patch (8 facets per texel, α = 0.5 like the car paint, facets α_f = 0.02)
/// seen through a footprint of `area` texels.
fn procedural() -> ProceduralGlints {
    ProceduralGlints::new(ProceduralParams {
        alpha: Vec2::splat(0.5),
        facet_alpha: 0.02,
        density: 8.0,
        resolution: [256, 256],
        seed: 5,
        ..ProceduralParams::default()
    })
    .unwrap()
}

/// White Lambert under η = 1.33, 1.5, 2: E(wo) = F(θo) + ∫ eval cos θi = 1 (quadrature, to its
/// error estimate + 2·10⁻³, the f32 rounding of the r_i quadrature and of eval), and the mean of
/// `sample().weight()` (delta samples included) within 4 standard errors + 2·10⁻³ of 1, up to
/// θo = 85°. The brief's bound is 2 % for θo ≤ 80°; the model is exact for a Lambertian base.
#[test]
fn white_lambert_furnace_is_one() {
    let white = Lambert::new(Vec3::ONE).unwrap();
    for eta in [1.33f32, 1.5, 2.0] {
        let coat = ClearCoat::new(white, eta).unwrap();
        for theta in [0.0, 30.0, 60.0, 80.0, 85.0] {
            let wo = support::dir(theta, 25.0);
            let f = dielectric(wo.z, eta) as f64;
            let (base, err) = quadrature(&coat, wo, 64);
            let e_quad = f + base;
            let (e, se) = sampled_furnace(&coat, wo, 40_000, 11);
            println!(
                "η={eta} θo={theta}: F={f:.4}, quadrature E={e_quad:.5} (±{err:.1e}), sampled E={:.4} ± {:.4}",
                e.x, se.x
            );
            assert!(
                (e_quad - 1.0).abs() <= 4.0 * err + 2e-3,
                "η={eta} θo={theta}: quadrature {e_quad}"
            );
            assert!(
                (e.x as f64 - 1.0).abs() <= 4.0 * se.x as f64 + 2e-3,
                "η={eta} θo={theta}: sampled {} ± {}",
                e.x,
                se.x
            );
        }
    }
}

/// Without the internal reflections (round trip 0) a white Lambert under η = 1.5 returns only
/// F + T (1 − r_e)/η² ≈ 0.43 at normal incidence: what the series gives back.
#[test]
fn one_pass_alone_loses_most_of_a_white_base() {
    let white = Lambert::new(Vec3::ONE).unwrap();
    let no_series = BaseAlbedo::new(Vec3::ONE, Vec3::ZERO).unwrap();
    let coat = ClearCoat::with_base_albedo(white, 1.5, no_series).unwrap();
    let wo = Vec3::Z;
    let (base, err) = quadrature(&coat, wo, 64);
    let f = dielectric(1.0, 1.5) as f64;
    let expected = f + (1.0 - f) * (1.0 - diffuse_external_reflectance(1.5) as f64) / 2.25;
    println!("one pass: E = {:.4}, closed form {expected:.4}", f + base);
    assert!((f + base - expected).abs() <= 4.0 * err + 1e-4);
    assert!(f + base < 0.45);
}

/// The round trip a Lambertian base is given by `BaseAlbedo::estimate` is ρ r_i to rounding (the
/// exactness the white furnace rests on), and its albedo is ρ.
#[test]
fn estimate_is_exact_for_lambert() {
    for eta in [1.1f32, 1.5, 3.0] {
        let rho = Vec3::new(0.9, 0.5, 0.1);
        let est = BaseAlbedo::estimate(&Lambert::new(rho).unwrap(), eta);
        let exact = rho * diffuse_internal_reflectance(eta);
        assert!(
            (est.round_trip() - exact).abs().max_element() < 2e-6,
            "η={eta}: {} vs {exact}",
            est.round_trip()
        );
        assert!((est.albedo() - rho).abs().max_element() < 2e-6);
    }
}

/// r_e and r_i against a direct composite quadrature (4,096 midpoints in μ) of 2 ∫ F μ dμ from
/// each side, total internal reflection included: the étendue relation r_i = 1 − (1 − r_e)/η²
/// holds, and r_i(1.5) = 0.596 (Saunderson's internal reflectance of a glass-air interface).
#[test]
fn diffuse_reflectances_match_a_direct_quadrature() {
    let direct = |eta: f32, sign: f32| {
        let n = 4096;
        (0..n)
            .map(|k| {
                let mu = (k as f64 + 0.5) / n as f64;
                2.0 * dielectric(sign * mu as f32, eta) as f64 * mu / n as f64
            })
            .sum::<f64>()
    };
    for eta in [1.01f32, 1.33, 1.5, 2.0, 3.0] {
        let (re, ri) = (direct(eta, 1.0), direct(eta, -1.0));
        println!("η={eta}: r_e {re:.5}, r_i {ri:.5}");
        assert!(
            (diffuse_external_reflectance(eta) as f64 - re).abs() < 1e-5,
            "η={eta}"
        );
        assert!(
            (diffuse_internal_reflectance(eta) as f64 - ri).abs() < 1e-4,
            "η={eta}"
        );
    }
    assert!((diffuse_internal_reflectance(1.5) - 0.596).abs() < 1e-3);
}

/// The furnace bound of a coat over a glint patch of a few lobes (4 and 64 texels, where the
/// lattice's tent reads about four lobes per level): the patch's round trip q(wo') jumps between
/// its few lobes, and the estimate's six directions need not see its minimum (measured 0.745 at 4
/// texels and 1.026 ± 0.005 at 64, both at normal incidence; with four directions that missed
/// the normal, 1.058 at 4 texels).
const FEW_FACETS_BOUND: f32 = 1.06;

/// Conductor microfacet bases (gold and silver GGX α = 0.3, a silver mirror) and a glint base
/// (a procedural patch of silver facets at 1,024 texels): the coated furnace never exceeds 1 (4
/// standard errors + 10⁻³) in any channel, up to 85°; at 4 and 64 texels it stays below
/// [`FEW_FACETS_BOUND`]. The plain series 1/(1 − ρ̄_b r_i) with
/// ρ̄_b the base's albedo exceeds 1 on the same bases (asserted at normal incidence on gold GGX): why the round trip is measured from the base (src/bxdf/clear_coat.rs, "Internal
/// reflection").
#[test]
fn glossy_and_glint_bases_conserve_energy() {
    let glints = procedural();
    let patches: Vec<_> = [4.0f32, 64.0, 1024.0]
        .iter()
        .map(|&a| {
            glints.patch(&Footprint::isotropic_texels(
                Vec2::new(0.3, 0.7),
                a,
                256,
                256,
            ))
        })
        .collect();
    let ggx = Ggx::isotropic(0.3).unwrap();
    let mut bases: Vec<(String, Box<dyn Bxdf + '_>)> = vec![
        (
            "GGX gold".into(),
            Box::new(MicrofacetBrdf::new(ggx, ConductorFresnel::GOLD)),
        ),
        (
            "GGX silver".into(),
            Box::new(MicrofacetBrdf::new(ggx, ConductorFresnel::SILVER)),
        ),
        (
            "mirror silver".into(),
            Box::new(SpecularReflection::new(ConductorFresnel::SILVER)),
        ),
    ];
    for (p, a) in patches.iter().zip([4, 64, 1024]) {
        bases.push((
            format!("glint {a} texels"),
            Box::new(MicrofacetBrdf::new(p, ConductorFresnel::SILVER)),
        ));
    }
    for (name, base) in &bases {
        let coat = ClearCoat::new(base.as_ref(), 1.5).unwrap();
        let ba = coat.base_albedo();
        for theta in [0.0, 40.0, 70.0, 85.0] {
            let wo = support::dir(theta, 30.0);
            let (e, se) = sampled_furnace(&coat, wo, 20_000, 5);
            println!(
                "{name} θo={theta}: E={e:.4} ± {:.4} (albedo {:.3}, round trip {:.3})",
                se.max_element(),
                ba.albedo(),
                ba.round_trip()
            );
            let bound = if name.starts_with("glint 4 ") || name.starts_with("glint 64 ") {
                FEW_FACETS_BOUND
            } else {
                1.0 + 1e-3
            };
            assert!(
                (e - 4.0 * se).max_element() <= bound,
                "{name} θo={theta}: {e} ± {se}"
            );
        }
    }
    let gold = MicrofacetBrdf::new(ggx, ConductorFresnel::GOLD);
    let est = BaseAlbedo::estimate(&gold, 1.5);
    let naive = BaseAlbedo::new(
        est.albedo(),
        est.albedo() * diffuse_internal_reflectance(1.5),
    );
    let naive = ClearCoat::with_base_albedo(&gold, 1.5, naive.unwrap()).unwrap();
    let (e, se) = sampled_furnace(&naive, Vec3::Z, 20_000, 5);
    println!(
        "gold GGX, ρ̄_b r_i series: E(0°) = {e:.3} ± {:.3}",
        se.max_element()
    );
    assert!(e.x - 4.0 * se.x > 1.0, "{e}");
}

/// Chi-square of the sampler's non-delta part against `pdf`: delta samples (the coat's mirror)
/// and trapped draws go to the overflow cell, whose expected count is N (1 − ∫ pdf). Lambert
/// under η = 1.5 at 0°, 60°, 85°; anisotropic GGX gold (α = 0.4/0.15) under η = 1.33 at 30°, 80°.
#[test]
fn chi2_of_the_non_delta_sampler() {
    let lambert = ClearCoat::new(Lambert::new(Vec3::new(0.8, 0.5, 0.2)).unwrap(), 1.5).unwrap();
    let ggx = MicrofacetBrdf::new(Ggx::new(0.4, 0.15).unwrap(), ConductorFresnel::GOLD);
    let ggx = ClearCoat::new(ggx, 1.33).unwrap();
    let cases: [(&str, &dyn Bxdf, f64); 5] = [
        ("lambert-0", &lambert, 0.0),
        ("lambert-60", &lambert, 60.0),
        ("lambert-85", &lambert, 85.0),
        ("ggx-30", &ggx, 30.0),
        ("ggx-80", &ggx, 80.0),
    ];
    for (name, b, theta) in cases {
        let wo = support::dir(theta, 35.0);
        let chi2 = Chi2::new(format!("clear_coat_{name}"), cases.len());
        let sample = |uc: f32, u: Vec2| {
            b.sample(wo, uc, u)
                .filter(|s| !s.flags.contains(LobeFlags::SPECULAR))
                .map(|s| s.wi)
        };
        let p = chi2.run(sample, |wi| b.pdf(wo, wi) as f64);
        assert!(p.is_ok(), "{name}: {p:?}");
    }
}

/// Sample, eval and pdf agree on every non-delta draw (to f32 rounding of the refraction: the
/// base is evaluated at the direction refracted back in from the drawn one); delta draws are the
/// mirror direction with weight F(θo)/p.
#[test]
fn samples_agree_with_eval_and_pdf() {
    let ggx = MicrofacetBrdf::new(Ggx::isotropic(0.2).unwrap(), ConductorFresnel::COPPER);
    let coat = ClearCoat::new(ggx, 1.5).unwrap();
    let mut rng = support::rng(21);
    let (mut deltas, mut others) = (0, 0);
    for _ in 0..4000 {
        let wo = random_upper(&mut rng);
        let Some(s) = coat.sample(wo, rng.random(), Vec2::new(rng.random(), rng.random())) else {
            continue;
        };
        if s.flags.contains(LobeFlags::SPECULAR) {
            deltas += 1;
            assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z));
            let f = dielectric(wo.z.min(1.0), 1.5);
            assert!((s.weight().x - f / s.pdf).abs() <= 1e-5 * f / s.pdf);
            continue;
        }
        others += 1;
        let (f, pdf) = coat.eval_pdf(wo, s.wi);
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-3 * a.abs().max(b.abs()) + 1e-30;
        assert!(close(s.pdf, pdf), "wo {wo} wi {}: {} vs {pdf}", s.wi, s.pdf);
        for c in 0..3 {
            assert!(close(s.f[c], f[c]), "wo {wo} wi {}: {} vs {f}", s.wi, s.f);
        }
    }
    assert!(deltas > 100 && others > 1000, "{deltas} {others}");
}

/// Reciprocity over reciprocal bases (Lambert, anisotropic GGX gold): f(wo, wi) = f(wi, wo) to
/// 10⁻⁵ relative on 2,000 random pairs (grazing included). The factor T(θo) T(θi) / η² / (1 − q)
/// is symmetric, the base is evaluated at the swapped refracted pair. (A glint patch in the
/// renderer's measure, F G2 D_P / (4 A_P(wo) cos θi), is not reciprocal itself, nor then its coat.)
#[test]
fn reciprocal_over_reciprocal_bases() {
    let lambert = ClearCoat::new(Lambert::new(Vec3::new(0.7, 0.4, 0.1)).unwrap(), 1.5).unwrap();
    let ggx = MicrofacetBrdf::new(Ggx::new(0.3, 0.1).unwrap(), ConductorFresnel::GOLD);
    let ggx = ClearCoat::new(ggx, 2.0).unwrap();
    let cases: [(&str, &dyn Bxdf); 2] = [("lambert", &lambert), ("ggx", &ggx)];
    let mut rng = support::rng(8);
    for (name, b) in cases {
        for _ in 0..2000 {
            let (wo, wi) = (random_upper(&mut rng), random_upper(&mut rng));
            let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
            let tol = 1e-5 * a.max(c).max_element() + 1e-35;
            assert!(
                (a - c).abs().max_element() <= tol,
                "{name} {wo} {wi}: {a} vs {c}"
            );
        }
    }
}

/// η → 1: the coat vanishes. At η = 1 + 10⁻⁵ eval equals the base's to 10⁻³ relative (the
/// interface's F ~ 10⁻¹¹, its refraction bends by ≤ 6·10⁻⁵ rad up to 80°, the round trip is
/// ~10⁻⁵), for views and lights up to 80°. (At 1 + 10⁻⁴ GGX α = 0.25 differs by 1.3·10⁻³ at
/// θo = 60°, θi = 80°: the bend of the refraction, tan θ (η − 1).)
#[test]
fn eta_to_one_reduces_to_the_base() {
    let ggx = MicrofacetBrdf::new(Ggx::isotropic(0.25).unwrap(), ConductorFresnel::GOLD);
    let lambert = Lambert::new(Vec3::new(0.6, 0.3, 0.9)).unwrap();
    let bases: [(&str, &dyn Bxdf); 2] = [("ggx", &ggx), ("lambert", &lambert)];
    for (name, base) in bases {
        let coat = ClearCoat::new(base, 1.0 + 1e-5).unwrap();
        for t_o in [0.0, 30.0, 60.0, 80.0] {
            for t_i in [0.0, 20.0, 45.0, 70.0, 80.0] {
                for phi in [0.0, 90.0, 180.0] {
                    let (wo, wi) = (support::dir(t_o, 10.0), support::dir(t_i, 10.0 + phi));
                    let (a, b) = (coat.eval(wo, wi), base.eval(wo, wi));
                    let tol = 1e-3 * b.max_element() + 1e-12;
                    assert!(
                        (a - b).abs().max_element() <= tol,
                        "{name} θo={t_o} θi={t_i} φ={phi}: {a} vs {b}"
                    );
                }
            }
        }
    }
}

/// The density contract (eval > 0 ⇒ pdf > 0, everything finite) and totality over the crate's
/// grazing grid (cos θ from 1 to 10⁻³⁰, both directions), the mirror neighbourhoods and the
/// sampler's own draws: coats of η = 1.001, 1.5 and 3 over Lambert, GGX at α = 10⁻³ and 1, and a
/// silver mirror (a delta base).
#[test]
fn density_contract_at_grazing_angles() {
    let mut cases = Vec::new();
    for eta in [1.001f32, 1.5, 3.0] {
        let lambert = Lambert::new(Vec3::ONE).unwrap();
        cases.push(case(
            format!("coat {eta} Lambert"),
            ClearCoat::new(lambert, eta).unwrap(),
            None,
        ));
        for alpha in [1e-3f32, 1.0] {
            let ggx = MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), ConductorFresnel::GOLD);
            let coat = ClearCoat::new(ggx, eta).unwrap();
            cases.push(case(format!("coat {eta} GGX {alpha}"), coat, None));
        }
        let mirror = SpecularReflection::new(ConductorFresnel::SILVER);
        cases.push(case(
            format!("coat {eta} mirror"),
            ClearCoat::new(mirror, eta).unwrap(),
            None,
        ));
    }
    let g = grid();
    run(&cases, &g, &g, &u_grid());
    // Below the horizon, on it, or non-finite: 0, never NaN, and no sample from such a wo.
    let coat = ClearCoat::new(Lambert::new(Vec3::ONE).unwrap(), 1.5).unwrap();
    let bad = [
        Vec3::new(0.0, 0.6, -0.8),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ];
    for w in bad {
        assert_eq!(coat.eval_pdf(w, Vec3::Z), (Vec3::ZERO, 0.0), "{w}");
        assert_eq!(coat.eval_pdf(Vec3::Z, w), (Vec3::ZERO, 0.0), "{w}");
        assert!(coat.sample(w, 0.5, Vec2::splat(0.5)).is_none(), "{w}");
        assert!(coat.sample(w, 0.01, Vec2::splat(0.5)).is_none(), "{w}");
    }
}

/// Bad input is an error naming the field: η outside (1, 3] (1 itself, below 1, above 3, NaN,
/// infinite), and `BaseAlbedo` values outside their ranges.
#[test]
fn bad_input_is_an_error() {
    let white = Lambert::new(Vec3::ONE).unwrap();
    for eta in [1.0f32, 0.5, 0.0, -1.5, 3.01, f32::NAN, f32::INFINITY] {
        match ClearCoat::new(white, eta) {
            Err(Error::InvalidParameter { name: "eta", .. }) => {}
            other => panic!("η={eta}: {other:?}"),
        }
    }
    for (albedo, round_trip, field) in [
        (Vec3::new(1.1, 0.5, 0.5), Vec3::ZERO, "albedo"),
        (Vec3::new(f32::NAN, 0.5, 0.5), Vec3::ZERO, "albedo"),
        (Vec3::ONE, Vec3::splat(1.0), "round_trip"),
        (Vec3::ONE, Vec3::new(0.1, -0.1, 0.1), "round_trip"),
    ] {
        match BaseAlbedo::new(albedo, round_trip) {
            Err(Error::InvalidParameter { name, .. }) if name == field => {}
            other => panic!("{albedo} {round_trip}: {other:?}"),
        }
    }
}
