//! Chi-square of the BRDF samplers at θo = 89° (docs/robustness.md, "The grazing chi-square").
//!
//! The BRDF-level harness used to reject the anisotropic microfacet BRDF at grazing views (GGX
//! α = 0.3/0.1 at θo = 89°, φo = 30°: χ² = 3977 on 3085 dof; Beckmann χ² = 193,335 on 248) while
//! the NDF-level warped grid passed. The cause was the harness: its fixed 6 × 6 Gauss-Legendre rule
//! per cell mis-integrates a reflected lobe that fills a sliver of a few cells near the horizon. A
//! 48 × 48 rule and a 96 × 96 rule per cell give the same expected counts as the harness's adaptive
//! rule (tests/it/support/chi2.rs), and with those counts the samplers pass. `fixed_rule_was_the_cause`
//! keeps the evidence: the same draws fail under the fixed rule and pass under the adaptive one.

use crate::support;

use brdf::bxdf::{Bxdf, LayeredBrdf, MicrofacetBrdf, Sampling};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::{Beckmann, Ggx, Ndf, SlopeGaussian};
use brdf::{Mat2, Vec2, Vec3};
use support::chi2::Chi2;

/// The issue's view: θo = 89°, φo = 30° (off both anisotropy axes).
fn wo() -> Vec3 {
    support::dir(89.0, 30.0)
}

fn microfacet<N: Ndf + 'static>(ndf: N, sampling: Sampling) -> Box<dyn Bxdf> {
    Box::new(MicrofacetBrdf::new(ndf, NoFresnel).with_sampling(sampling))
}

/// The anisotropic microfacet BRDFs at 89°: GGX and Beckmann α = (0.3, 0.1), both samplers, and
/// the layered coat of tests/it/layered.rs over the anisotropic GGX.
fn cases() -> Vec<(String, Box<dyn Bxdf>)> {
    let mut v: Vec<(String, Box<dyn Bxdf>)> = Vec::new();
    for s in [Sampling::VisibleNormals, Sampling::Normals] {
        v.push((
            format!("ggx 0.3/0.1 {s:?}"),
            microfacet(Ggx::new(0.3, 0.1).unwrap(), s),
        ));
        v.push((
            format!("beckmann 0.3/0.1 {s:?}"),
            microfacet(Beckmann::new(0.3, 0.1).unwrap(), s),
        ));
    }
    let schlick = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    v.push((
        "layered ggx 0.3/0.1".into(),
        Box::new(
            LayeredBrdf::new(
                MicrofacetBrdf::new(Ggx::new(0.3, 0.1).unwrap(), schlick),
                Vec3::new(0.7, 0.3, 0.2),
            )
            .unwrap(),
        ),
    ));
    v
}

/// Runs the cases at 89° under one harness configuration, returning the failures.
fn run(cases: &[(String, Box<dyn Bxdf>)], config: impl Fn(&str, usize) -> Chi2) -> Vec<String> {
    let wo = wo();
    cases
        .iter()
        .filter_map(|(name, b)| {
            config(name, cases.len())
                .run(
                    |uc, u| b.sample(wo, uc, u).map(|s| s.wi),
                    |w| b.pdf(wo, w) as f64,
                )
                .err()
        })
        .collect()
}

/// The anisotropic GGX and Beckmann BRDFs (and a layered coat) pass at θo = 89°.
#[test]
fn anisotropic_microfacet_at_89_degrees() {
    let failures = run(&cases(), |name, family| Chi2::new(name, family));
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The evidence that the harness, not the sampler, was wrong: the same draws of the issue's two
/// cases fail under the fixed 6 × 6 rule per cell (`max_depth` 0) and pass under a fixed 48 × 48
/// rule, an independent integration of the same pdf on the same cells. At 10⁶ draws in both runs
/// (the full-power setting, whatever `support::depth` chooses): with fewer draws the coarse rule's
/// error on one of the cases is within the noise.
#[test]
fn fixed_rule_was_the_cause() {
    let issue: Vec<(String, Box<dyn Bxdf>)> = cases()
        .into_iter()
        .filter(|(name, _)| name.ends_with("VisibleNormals"))
        .collect();
    assert_eq!(issue.len(), 2);
    let fixed = run(&issue, |name, family| Chi2 {
        samples: 1_000_000,
        max_depth: 0,
        ..Chi2::new(format!("{name} fixed 6×6"), family)
    });
    assert_eq!(
        fixed.len(),
        2,
        "the fixed rule should reject both: {fixed:#?}"
    );
    let fine = run(&issue, |name, family| Chi2 {
        samples: 1_000_000,
        max_depth: 0,
        quadrature: 48,
        ..Chi2::new(format!("{name} fixed 48×48"), family)
    });
    assert!(fine.is_empty(), "{fine:#?}");
}

/// The configurations tests/bxdf.rs leaves out of its chi-square at 89° for the harness's sake
/// (narrow lobes: GGX and Beckmann α = 0.1, the non-centred lobe of σ ≈ 0.2), now resolved by the
/// adaptive rule.
#[test]
fn narrow_lobes_at_89_degrees() {
    let lobe = SlopeGaussian::new(
        Vec2::new(0.3, -0.2),
        Mat2::from_cols_array(&[0.04, 0.015, 0.015, 0.02]),
    )
    .unwrap();
    let mut v: Vec<(String, Box<dyn Bxdf>)> = Vec::new();
    for s in [Sampling::VisibleNormals, Sampling::Normals] {
        v.push((
            format!("ggx 0.1 {s:?}"),
            microfacet(Ggx::isotropic(0.1).unwrap(), s),
        ));
        v.push((
            format!("beckmann 0.1 {s:?}"),
            microfacet(Beckmann::isotropic(0.1).unwrap(), s),
        ));
        v.push((format!("slope gaussian {s:?}"), microfacet(lobe, s)));
    }
    let failures = run(&v, |name, family| Chi2::new(name, family));
    assert!(failures.is_empty(), "{failures:#?}");
}
