//! `LayeredBrdf`: a microfacet layer (analytic or glint) over a Lambertian base. White furnace in the
//! renderer's measure (≤ 1; equal to 1 minus the coat's masking loss for a white base), the F = 1
//! limit, sample / eval / pdf agreement and chi-square of the sampler.

mod support;

use brdf::bxdf::{Bxdf, LayeredBrdf, MicrofacetBrdf};
use brdf::fresnel::{ConductorFresnel, Fresnel, NoFresnel, SchlickFresnel};
use brdf::glint::mixture::MixtureParams;
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf};
use brdf::ndf::{Ggx, Ndf};
use brdf::{Vec2, Vec3};
use rand::RngExt;
use support::chi2::Chi2;

/// Per channel (mean, standard error) of `sample().weight()` over `n` stratified draws: the renderer's
/// furnace; the channel with the largest mean is returned.
fn furnace(b: &dyn Bxdf, wo: Vec3, n: usize) -> (f64, f64) {
    let mut rng = support::rng(3);
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        let w = b
            .sample(wo, rng.random(), u)
            .map_or(Vec3::ZERO, |x| x.weight());
        for c in 0..3 {
            s[c] += w[c] as f64;
            s2[c] += (w[c] as f64).powi(2);
        }
    }
    (0..3)
        .map(|c| {
            let m = s[c] / n as f64;
            (m, ((s2[c] / n as f64 - m * m).max(0.0) / n as f64).sqrt())
        })
        .fold((f64::MIN, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

fn glint_patch_model() -> BeckmannMixture {
    let map = brdf::glint::bumpy(32, 32, 0.25, 4.0, 1).unwrap();
    BeckmannMixture::build(
        &map,
        MixtureParams {
            samples: 16,
            ..Default::default()
        },
    )
    .unwrap()
}

/// The coat's own albedo E_s(wo) (F included), by its sampler.
fn coat_albedo<D: Ndf, F: Fresnel>(coat: &MicrofacetBrdf<D, F>, wo: Vec3) -> f64 {
    furnace(coat, wo, 20_000).0
}

/// White base under a dielectric coat (Schlick, f0 = 0.04): the furnace is ≤ 1, and it is 1 minus
/// the coat's masking loss: E ≥ 1 − (1 − E_s/R̂)·R̂ − 0.01, i.e. the base returns what the coat does not
/// reflect at its first bounce (the 0.01 covers R̂'s 16-point quadrature error and Monte Carlo noise;
/// observed ≥ 0.97 up to 70° for α = 0.1).
#[test]
fn white_base_furnace_is_at_most_one_and_close_to_it() {
    let schlick = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    for alpha in [0.05f32, 0.3, 0.8] {
        let coat = MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), schlick);
        let layered = LayeredBrdf::new(coat, Vec3::ONE).unwrap();
        for theta in [0.0, 30.0, 60.0, 75.0, 85.0, 89.0] {
            let wo = support::dir(theta, 20.0);
            let (e, se) = furnace(&layered, wo, 20_000);
            assert!(
                e <= 1.0 + 4.0 * se + 2e-3,
                "α={alpha} θo={theta}: {e} ± {se}"
            );
            let r = layered.first_bounce_reflectance(wo).x as f64;
            let es = coat_albedo(layered.specular(), wo);
            // E = E_s + (1 − R̂): lower than 1 exactly by R̂ − E_s (the coat's masking loss).
            let expected = es + 1.0 - r;
            assert!(
                (e - expected).abs() <= 4.0 * se + 0.01,
                "α={alpha} θo={theta}: {e} vs E_s + 1 − R̂ = {expected}"
            );
            if alpha <= 0.3 && theta <= 60.0 {
                assert!(e >= 0.97, "α={alpha} θo={theta}: {e}");
            }
        }
    }
}

/// F = 1: nothing reaches the base, and the layered furnace is the coat's own (for a glint patch and
/// an analytic lobe).
#[test]
fn perfect_reflector_hides_the_base() {
    let model = glint_patch_model();
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 9.0, 32, 32);
    let patch = model.patch(&fp);
    let glint = LayeredBrdf::new(MicrofacetBrdf::new(&patch, NoFresnel), Vec3::ONE).unwrap();
    let ggx = LayeredBrdf::new(
        MicrofacetBrdf::new(Ggx::isotropic(0.4).unwrap(), NoFresnel),
        Vec3::ONE,
    )
    .unwrap();
    for theta in [0.0, 45.0, 80.0] {
        let wo = support::dir(theta, 40.0);
        assert_eq!(glint.first_bounce_reflectance(wo), Vec3::ONE);
        for (name, b) in [("glint", &glint as &dyn Bxdf), ("ggx", &ggx)] {
            let (e, se) = furnace(b, wo, 20_000);
            assert!(e <= 1.0 + 4.0 * se + 1e-4, "{name} θo={theta}: {e} ± {se}");
            // The base term is exactly 0: eval equals the coat's.
            let wi = support::dir(30.0, 200.0);
            let coat_f = match name {
                "glint" => glint.specular().eval(wo, wi),
                _ => ggx.specular().eval(wo, wi),
            };
            assert_eq!(b.eval(wo, wi), coat_f, "{name}");
        }
    }
}

/// A coloured conductor coat over a coloured base on a glint patch: furnace ≤ 1 per channel at every
/// view, and `sample` agrees with `eval` and `pdf`.
#[test]
fn glint_over_base_conserves_energy_and_agrees_with_itself() {
    let model = glint_patch_model();
    let gold = ConductorFresnel::GOLD;
    for area in [1.0f32, 64.0] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), area, 32, 32);
        let patch = model.patch(&fp);
        let b =
            LayeredBrdf::new(MicrofacetBrdf::new(&patch, gold), Vec3::new(0.9, 0.5, 0.2)).unwrap();
        for theta in [0.0, 50.0, 85.0, 89.9] {
            let wo = support::dir(theta, 10.0);
            let (e, se) = furnace(&b, wo, 8_000);
            assert!(e <= 1.0 + 4.0 * se + 1e-4, "{area} θo={theta}: {e} ± {se}");
            let mut rng = support::rng(9);
            for _ in 0..200 {
                let u = Vec2::new(rng.random(), rng.random());
                if let Some(s) = b.sample(wo, rng.random(), u) {
                    let (f, pdf) = b.eval_pdf(wo, s.wi);
                    assert_eq!(s.f, f);
                    assert_eq!(s.pdf, pdf);
                }
            }
        }
    }
}

/// Chi-square of the layered sampler against its pdf: an anisotropic analytic coat at three views
/// and an isotropic one at 89°, and a glint coat (mixture patch of a few lobes) at two.
///
/// The anisotropic coat at 89° is in tests/grazing_chi2.rs: at φo = 30° its reflected lobe is a
/// sliver 2-3 cells wide in φ at the horizon, which a fixed 6 × 6 rule per cell mis-integrates
/// (χ² = 3977 for 3085 dof, the bare `MicrofacetBrdf` too); the harness's adaptive rule
/// (tests/support/chi2.rs) integrates it as a 48 × 48 rule does, and the sampler passes.
#[test]
fn chi_square_of_the_layered_sampler() {
    let schlick = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    let ggx = LayeredBrdf::new(
        MicrofacetBrdf::new(Ggx::new(0.3, 0.1).unwrap(), schlick),
        Vec3::new(0.7, 0.3, 0.2),
    )
    .unwrap();
    let ggx_iso = LayeredBrdf::new(
        MicrofacetBrdf::new(Ggx::isotropic(0.3).unwrap(), schlick),
        Vec3::new(0.7, 0.3, 0.2),
    )
    .unwrap();
    let model = glint_patch_model();
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 4.0, 32, 32);
    let patch = model.patch(&fp);
    let glint = LayeredBrdf::new(MicrofacetBrdf::new(&patch, schlick), Vec3::splat(0.5)).unwrap();
    let mut cases: Vec<(String, &dyn Bxdf, Vec3, usize)> = vec![];
    for theta in [0.0, 45.0, 75.0] {
        cases.push((
            format!("layered ggx θo={theta}"),
            &ggx,
            support::dir(theta, 30.0),
            1_000_000,
        ));
    }
    cases.push((
        "layered iso ggx θo=89".into(),
        &ggx_iso,
        support::dir(89.0, 30.0),
        1_000_000,
    ));
    for theta in [20.0, 70.0] {
        cases.push((
            format!("layered glint θo={theta}"),
            &glint,
            support::dir(theta, 30.0),
            200_000,
        ));
    }
    let family = cases.len();
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(name, b, wo, n)| {
            Chi2 {
                samples: *n,
                ..Chi2::new(name, family)
            }
            .run(
                |uc, u| b.sample(*wo, uc, u).map(|s| s.wi),
                |w| b.pdf(*wo, w) as f64,
            )
            .err()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn rejects_a_bad_base() {
    let coat = MicrofacetBrdf::new(Ggx::isotropic(0.2).unwrap(), NoFresnel);
    for bad in [
        Vec3::new(1.2, 0.5, 0.5),
        Vec3::new(0.5, f32::NAN, 0.5),
        Vec3::splat(-0.1),
    ] {
        let e = LayeredBrdf::new(coat, bad).unwrap_err();
        assert!(e.to_string().contains("base"), "{e}");
    }
}
