//! Unit tests of the glint albedo estimate (src/glint/kernels/albedo.rs).

use super::*;
use crate::bxdf::{AlbedoTable, Bxdf, MicrofacetBrdf};
use crate::fresnel::NoFresnel;
use crate::glint::kernels::lobe_set::LobeSet;

/// The furnace a renderer computes of the lobe set with white Fresnel: the mean
/// `sample().weight()` of 2¹⁶ stratified draws through `MicrofacetBrdf`.
fn sampled_furnace(set: &LobeSet, wo: Vec3) -> f32 {
    let brdf = MicrofacetBrdf::new(set.clone(), NoFresnel);
    let n = 1 << 16;
    let mut sum = 0.0f64;
    for k in 0..n {
        let u = Vec2::new(
            (k as f32 + 0.5) / n as f32,
            ((k as f64 * 0.618_033_988_75).fract()) as f32,
        );
        sum += brdf.sample(wo, 0.5, u).map_or(0.0, |s| s.weight().x as f64);
    }
    (sum / n as f64) as f32
}

/// One centred isotropic Beckmann lobe is a Beckmann surface: the estimate against the
/// crate's tabulated albedo of Beckmann (its own quadrature, docs/results.md), over roughness
/// and view. The rule is a cubature of the lobe's visible normals, so this checks the rule and
/// g, not the pooled Λ (a single lobe is its own pool).
#[test]
fn one_beckmann_lobe_has_the_tabulated_albedo() {
    let mut worst = 0.0f32;
    for alpha in [0.02f32, 0.05, 0.1, 0.2, 0.3, 0.5] {
        let s = alpha / core::f32::consts::SQRT_2;
        let lobe = SlopeGaussian::from_moments([0.0, 0.0, s * s, s * s, 0.0], SIGMA_MIN_FLOOR);
        for deg in [0.0f32, 30.0, 45.0, 60.0, 70.0, 80.0] {
            let t = deg.to_radians();
            let wo = Vec3::new(t.sin(), 0.0, t.cos());
            let e = lobes_albedo(
                wo,
                lobe.lambda(wo),
                core::iter::once(Lobe::of(1.0, &lobe)),
                None,
                &[],
            );
            let table = AlbedoTable::BECKMANN.albedo(wo.z, alpha);
            worst = worst.max((e - table).abs());
        }
    }
    // Measured 0.0094 (α = 0.5 at normal incidence: the 8 × 3 grid on the widest lobe).
    assert!(worst < 0.012, "{worst}");
}

/// Far from grazing every lobe of a patch reflects above the horizon with Λ ≈ 0: E = 1.
#[test]
fn narrow_lobes_at_normal_incidence_lose_nothing() {
    let a = SlopeGaussian::from_moments([0.05, 0.0, 0.0026, 0.0001, 0.0], 0.01);
    let b = SlopeGaussian::from_moments([-0.1, 0.02, 0.0101, 0.0005, 0.0], 0.01);
    let lobes = [(0.3, a), (0.7, b)];
    let e = lobes_albedo(
        Vec3::Z,
        0.0,
        lobes.iter().map(|(w, g)| Lobe::of(*w, g)),
        None,
        &[],
    );
    assert!((e - 1.0).abs() < 1e-4, "{e}");
    // And a view from below, or a patch without lobes, gives back nothing.
    assert_eq!(
        lobes_albedo(
            -Vec3::Z,
            0.0,
            lobes.iter().map(|(w, g)| Lobe::of(*w, g)),
            None,
            &[]
        ),
        1.0
    );
    assert_eq!(
        lobes_albedo(Vec3::Z, 0.0, core::iter::empty(), None, &[]),
        1.0
    );
}

/// Two tilted lobes at a grazing view: the estimate against the furnace a renderer computes
/// with the patch's own sampler (mean `sample().weight()`, 2¹⁶ stratified draws) of the same
/// mixture through `MicrofacetBrdf`.
#[test]
fn two_lobes_match_their_sampled_furnace() {
    let a = SlopeGaussian::from_moments([0.3, 0.0, 0.09 + 0.0004, 0.0004, 0.0], 0.02);
    let b = SlopeGaussian::from_moments([-0.2, 0.1, 0.04 + 0.0009, 0.01 + 0.0009, -0.02], 0.03);
    let mut set = LobeSet::default();
    set.push(0.4, a);
    set.push(0.6, b);
    set.normalise();
    for deg in [45.0f32, 70.0, 80.0] {
        for phi in [0.0f32, 2.0] {
            let t = deg.to_radians();
            let wo = Vec3::new(t.sin() * phi.cos(), t.sin() * phi.sin(), t.cos());
            let lobes: Vec<(f32, SlopeGaussian)> = set.iter().map(|(w, g)| (w, *g)).collect();
            let e = lobes_albedo(
                wo,
                set.lambda(wo),
                lobes.iter().map(|(w, g)| Lobe::of(*w, g)),
                None,
                &[],
            );
            let furnace = sampled_furnace(&set, wo);
            // Measured within 0.008: the four-Gaussian stand-in for Λ_P at the reflected
            // directions (the cubature alone is within 10⁻⁴ of a 64² quadrature here).
            assert!(
                (e - furnace).abs() < 0.012,
                "{deg}° φ {phi}: {e} against {furnace}"
            );
        }
    }
}

/// One tilted narrow lobe (a flake) at views whose reflections sweep through the horizon: the
/// estimate, with the step located ([`refined_average`]), against the furnace of the same lobe
/// by its own sampler: measured within 0.007, where the 8-point rule alone is off by up to 0.047
/// (a step between two of its nodes). A single lobe carries the whole patch, so it always takes
/// the refined rule.
#[test]
fn a_flake_crossing_the_horizon_matches_its_sampled_furnace() {
    let flake =
        SlopeGaussian::from_moments([0.45, 0.1, 0.2025 + 0.0025, 0.01 + 0.0016, 0.045], 0.03);
    let mut set = LobeSet::default();
    set.push(1.0, flake);
    set.normalise();
    let mut worst = 0.0f32;
    // The flake leans ~25° away from these views: its mean reflection meets the horizon at
    // θo ≈ 40°.
    for deg in (28..=56).step_by(2) {
        let t = (deg as f32).to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let e = lobes_albedo(
            wo,
            set.lambda(wo),
            core::iter::once(Lobe::of(1.0, &flake)),
            None,
            &[],
        );
        let furnace = sampled_furnace(&set, wo);
        worst = worst.max((e - furnace).abs());
    }
    assert!(worst < 0.01, "largest |estimate − furnace| {worst}");
}
