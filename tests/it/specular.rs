//! The smooth limit (src/bxdf/specular.rs): the delta-lobe convention of `SpecularReflection`,
//! its totality on hostile input, and the convergence of the microfacet BRDF to it as α → 0.

use crate::support;

use brdf::bxdf::{Bxdf, LobeFlags, MicrofacetBrdf, SpecularReflection};
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, Fresnel, NoFresnel, SchlickFresnel};
use brdf::ndf::{Beckmann, Ggx, Ndf};
use brdf::{Vec2, Vec3};
use proptest::prelude::*;
use support::dir;
use support::robustness::{any_dir, any_u};
use support::totality::check_bxdf;

/// Views of the convention and convergence tests (degrees).
const THETAS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];

/// A named mirror and its Fresnel term.
type Mirror = (&'static str, Box<dyn Bxdf>, Box<dyn Fresnel>);

/// Every mirror the tests use: conductors, a dielectric's reflection, Schlick, F = 1.
fn mirrors() -> Vec<Mirror> {
    let schlick = SchlickFresnel::new(Vec3::new(0.9, 0.6, 0.3)).unwrap();
    let glass = DielectricFresnel::new(1.5).unwrap();
    vec![
        (
            "gold",
            Box::new(SpecularReflection::new(ConductorFresnel::GOLD)),
            Box::new(ConductorFresnel::GOLD),
        ),
        (
            "glass",
            Box::new(SpecularReflection::new(glass)),
            Box::new(glass),
        ),
        (
            "schlick",
            Box::new(SpecularReflection::new(schlick)),
            Box::new(schlick),
        ),
        (
            "white",
            Box::new(SpecularReflection::new(NoFresnel)),
            Box::new(NoFresnel),
        ),
    ]
}

/// The convention: eval and pdf are 0 everywhere (the mirror direction included), the sample is
/// the mirror direction with flags SPECULAR | REFLECTION, pdf 1, and weight F(cos θo) to 2 ulps
/// (one f32 division F / cos θi, one f64 product rounded to f32).
#[test]
fn delta_convention() {
    for (name, m, fresnel) in mirrors() {
        for theta in THETAS {
            for phi in [0.0, 130.0] {
                let wo = dir(theta, phi);
                let s = m.sample(wo, 0.3, Vec2::new(0.5, 0.5)).unwrap();
                assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z), "{name}");
                assert_eq!(s.flags, LobeFlags::SPECULAR | LobeFlags::REFLECTION);
                assert_eq!(s.pdf, 1.0);
                let f = fresnel.eval(wo.z);
                let err = (s.weight() - f).abs().max_element();
                assert!(
                    err <= 2.0 * f32::EPSILON * f.max_element(),
                    "{name} θo={theta}: weight {} vs F {f}",
                    s.weight()
                );
                // No density for any pair, the mirror direction included.
                assert_eq!(m.eval(wo, s.wi), Vec3::ZERO);
                assert_eq!(m.pdf(wo, s.wi), 0.0);
                assert_eq!(m.eval_pdf(wo, dir(20.0, 10.0)), (Vec3::ZERO, 0.0));
            }
        }
        // Below the horizon, degenerate input: no sample.
        for wo in [-Vec3::Z, Vec3::X, Vec3::ZERO, Vec3::splat(f32::NAN)] {
            assert!(m.sample(wo, 0.5, Vec2::splat(0.5)).is_none(), "{name} {wo}");
        }
    }
}

/// The sample's weight is F at views down to cos θo = 1e-30 (F / cos θi stays finite there).
#[test]
fn weight_at_grazing_views() {
    let m = SpecularReflection::new(ConductorFresnel::COPPER);
    for c in [1e-3f32, 1e-7, 1e-15, 1e-30] {
        let s = (1.0 - (c as f64).powi(2)).sqrt() as f32;
        let wo = Vec3::new(s, 0.0, c);
        let smp = m.sample(wo, 0.0, Vec2::ZERO).unwrap();
        let f = ConductorFresnel::COPPER.eval(c);
        assert!(
            (smp.weight() - f).abs().max_element() <= 2.0 * f32::EPSILON,
            "{c}"
        );
    }
}

proptest! {
    #![proptest_config(support::proptest_config(256))]

    /// Totality on arbitrary directions and random numbers (tests/it/support/totality.rs).
    #[test]
    fn totality(wo in any_dir(), wi in any_dir(), uc in any_u(), ux in any_u(), uy in any_u()) {
        for (_, m, _) in mirrors() {
            check_bxdf(m.as_ref(), wo, wi, uc, Vec2::new(ux, uy));
        }
    }
}

/// A smooth positive environment: 1 + 0.5 x − 0.3 y + 0.4 z².
fn environment(w: Vec3) -> f64 {
    let (x, y, z) = (w.x as f64, w.y as f64, w.z as f64);
    1.0 + 0.5 * x - 0.3 * y + 0.4 * z * z
}

/// ∫ f L cos θi dωi the renderer's way: the mean of weight × L(wi) over a stratified 128 × 128
/// grid of the BRDF's own (visible-normal) sampler, per channel; a `None` sample counts 0.
fn reflected<B: Bxdf>(b: &B, wo: Vec3) -> [f64; 3] {
    let n = 128;
    let mut sum = [0.0f64; 3];
    for j in 0..n {
        for i in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            if let Some(s) = b.sample(wo, 0.5, u) {
                let w = s.weight();
                let l = environment(s.wi);
                for (k, acc) in sum.iter_mut().enumerate() {
                    *acc += w[k] as f64 * l;
                }
            }
        }
    }
    sum.map(|x| x / (n * n) as f64)
}

/// The largest deviation over channels and views of the microfacet BRDF at α from the delta's
/// F(cos θo) L(reflect(wo)).
fn deviation<D: Ndf + Copy>(ndf: D) -> f64 {
    let mut worst = 0.0f64;
    for theta in [0.0, 30.0, 60.0, 80.0] {
        let wo = dir(theta, 35.0);
        let rough = reflected(&MicrofacetBrdf::new(ndf, ConductorFresnel::GOLD), wo);
        let delta = SpecularReflection::new(ConductorFresnel::GOLD);
        let s = delta.sample(wo, 0.5, Vec2::ZERO).unwrap();
        let (w, l) = (s.weight(), environment(s.wi));
        for k in 0..3 {
            worst = worst.max((rough[k] - w[k] as f64 * l).abs());
        }
    }
    worst
}

/// Roughness → 0: the microfacet BRDF integrated against a smooth environment converges to the
/// delta's F(cos θo) L(reflect(wo)). The deviation has three sources, each O(α²) (GGX:
/// O(α² ln(1/α)), its slope variance being infinite and cut by the hemisphere): the masking loss
/// 1 − G2/G1 ≈ Λ(wi), the curvature of L over a lobe of width ~2α, and that of F(wo·h). Measured
/// (docs/bxdf.md, "Delta lobes"): 1.4·10⁻³, 8.9·10⁻⁶, 1.4·10⁻⁷ for GGX and 1.8·10⁻⁴, 1.8·10⁻⁶,
/// 1.4·10⁻⁷ for Beckmann at α = 10⁻², 10⁻³, 10⁻⁴, i.e. coefficients of α² (1 + ln(1/α)) of 2.5
/// and 0.33 at α = 10⁻²; the bound uses 5. 2·10⁻⁶ is the f32 floor (the weights are rounded to
/// f32, relative 6·10⁻⁸, summed over 16384 samples of L ≤ 2). The rate itself is checked: a
/// decade in α must shrink the deviation by at least 30 × until that floor.
#[test]
fn roughness_to_zero_converges_to_the_delta() {
    let bound = |a: f64| 5.0 * a * a * (1.0 + (1.0 / a).ln()) + 2e-6;
    for (name, devs) in [
        (
            "ggx",
            [1e-2f32, 1e-3, 1e-4].map(|a| deviation(Ggx::isotropic(a).unwrap())),
        ),
        (
            "beckmann",
            [1e-2f32, 1e-3, 1e-4].map(|a| deviation(Beckmann::isotropic(a).unwrap())),
        ),
    ] {
        println!("{name}: deviation at α = 1e-2, 1e-3, 1e-4: {devs:?}");
        for (a, d) in [1e-2, 1e-3, 1e-4].iter().zip(devs) {
            assert!(d <= bound(*a), "{name} α={a}: {d:e} > {:e}", bound(*a));
        }
        assert!(
            devs[1] <= devs[0] / 30.0 || devs[1] <= 2e-6,
            "{name}: {devs:?}"
        );
    }
}
