//! The shading-normal adapters (src/bxdf/normal_mapping/): `NormalMapTilt` (conventional normal
//! mapping) and `NormalMapMicrofacet` (microfacet-based normal mapping, [Schussler2017]).
//!
//! - white furnace ≤ 1 with lossless inner BRDFs (Lambert ρ = 1, also with the whole walk; a
//!   near-mirror GGX with F = 1), and the energy the single-scattering evaluation loses, measured;
//! - no black regions: a shading normal tilted 60°, views down to grazing on the side it leans
//!   away from, where the tilt adapter reflects nothing;
//! - reciprocity of the microfacet adapter; sample/eval/pdf agreement; chi-square of both
//!   samplers; totality on hostile input.

use crate::support;

use brdf::bxdf::{
    Bxdf, Lambert, MicrofacetBrdf, NormalMapMicrofacet, NormalMapTilt, ShadingNormal,
};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::Ggx;
use brdf::{Vec2, Vec3};
use proptest::prelude::*;
use support::chi2::Chi2;
use support::dir;
use support::quadrature::integrate_hemisphere;
use support::robustness::{any_dir, any_u};
use support::totality::check_bxdf;

/// A shading normal tilted by `deg` degrees toward +x.
fn tilted(deg: f64) -> ShadingNormal {
    ShadingNormal::new(dir(deg, 0.0), None).unwrap()
}

fn white() -> Lambert {
    Lambert::new(Vec3::ONE).unwrap()
}

fn glossy(alpha: f32) -> MicrofacetBrdf<Ggx, NoFresnel> {
    MicrofacetBrdf::new(Ggx::isotropic(alpha).unwrap(), NoFresnel)
}

/// ∫ f cos θi dωi of channel 0 by quadrature (smooth inner BRDFs), with its error estimate.
fn furnace_quadrature(b: &dyn Bxdf, wo: Vec3) -> (f64, f64) {
    integrate_hemisphere(
        &|wi| b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64,
        128,
        256,
    )
}

/// ∫ f cos θi dωi of channel 0 the renderer's way (mean sample weight over a stratified 256 × 256
/// grid, `None` counting 0) with its standard error (peaked inner BRDFs).
fn furnace_sampled(b: &dyn Bxdf, wo: Vec3) -> (f64, f64) {
    let n = 256u32;
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for k in 0..n * n {
        let u = Vec2::new(
            ((k % n) as f32 + 0.5) / n as f32,
            ((k / n) as f32 + 0.5) / n as f32,
        );
        let uc = (k as f64 * 0.618_033_988_749_894_9).fract() as f32;
        let x = b.sample(wo, uc, u).map_or(0.0, |s| s.weight().x as f64);
        s1 += x;
        s2 += x * x;
    }
    let m = s1 / (n * n) as f64;
    (
        m,
        ((s2 / (n * n) as f64 - m * m).max(0.0) / (n * n) as f64).sqrt(),
    )
}

/// Views of the energy tests: toward, across and away from the lean, down to 89°.
fn views() -> Vec<Vec3> {
    let mut v = vec![];
    for theta in [0.0, 30.0, 60.0, 80.0, 89.0] {
        for phi in [0.0, 90.0, 180.0] {
            v.push(dir(theta, phi));
        }
    }
    v
}

/// White furnace of the microfacet adapter over Lambert ρ = 1 (a lossless inner BRDF), with its
/// single-scattering paths alone and with the whole walk (`with_multiple_bounces`): ≤ 1 at every
/// view (quadrature error × 4 + 10⁻⁵ for f32 evaluation), printed (docs/bxdf.md, "Normal mapping",
/// quotes it). The exact values (cos θp and 1) are asserted in `normal_mapping_energy`.
#[test]
fn microfacet_furnace_lambert() {
    for tilt in [30.0, 60.0] {
        let single = NormalMapMicrofacet::new(white(), tilted(tilt));
        let walk = single.with_multiple_bounces();
        for (what, b) in [("single scattering", &single), ("whole walk", &walk)] {
            let mut row = vec![];
            for wo in views() {
                let (e, err) = furnace_quadrature(b, wo);
                row.push(format!("{:.4}", e));
                assert!(
                    e <= 1.0 + 4.0 * err + 1e-5,
                    "{what} tilt {tilt} wo {wo}: {e} ± {err}"
                );
                assert!(e >= 0.0, "{what} tilt {tilt} wo {wo}: {e}");
            }
            println!(
                "microfacet(Lambert 1), {what}, tilt {tilt}°: furnace {}",
                row.join(" ")
            );
        }
    }
}

/// The same with a near-mirror GGX (α = 0.05, F = 1; its own albedo is ≥ 0.99 up to θ = 80°),
/// by the adapter's sampler: ≤ 1 within 4 standard errors + 10⁻⁴, and the conventional tilt
/// adapter's furnace beside it for the comparison in docs/bxdf.md.
#[test]
fn furnace_near_mirror() {
    for tilt in [30.0, 60.0] {
        let mf = NormalMapMicrofacet::new(glossy(0.05), tilted(tilt));
        let tl = NormalMapTilt::new(glossy(0.05), tilted(tilt));
        let (mut a, mut b) = (vec![], vec![]);
        for wo in views() {
            for (what, brdf, out) in [
                ("microfacet", &mf as &dyn Bxdf, &mut a),
                ("tilt", &tl as &dyn Bxdf, &mut b),
            ] {
                let (e, err) = furnace_sampled(brdf, wo);
                assert!(
                    e <= 1.0 + 4.0 * err + 1e-4,
                    "{what} tilt {tilt} wo {wo}: {e} ± {err}"
                );
                out.push(format!("{e:.3}"));
            }
        }
        println!("tilt {tilt}°, GGX 0.05: microfacet {}", a.join(" "));
        println!("tilt {tilt}°, GGX 0.05: tilt       {}", b.join(" "));
    }
}

/// No black regions at grazing views. Shading normal tilted 60° toward +x; views on the side it
/// leans away from (φ = 180°) with θo > 30° are below the shading horizon: the tilt adapter
/// reflects nothing there (asserted: exactly 0), while the microfacet adapter reflects through
/// the tangent facet (asserted: > 0; cos θp = 0.5 with Lambert ρ = 1).
#[test]
fn no_black_regions_at_grazing() {
    let sn = tilted(60.0);
    let mf = NormalMapMicrofacet::new(white(), sn);
    let tl = NormalMapTilt::new(white(), sn);
    for theta in [40.0, 60.0, 80.0, 85.0, 89.0] {
        let wo = dir(theta, 180.0);
        let (e_mf, _) = furnace_quadrature(&mf, wo);
        let (e_tl, _) = furnace_quadrature(&tl, wo);
        println!("θo = {theta}° away from the lean: microfacet {e_mf:.4}, tilt {e_tl:.4}");
        assert_eq!(e_tl, 0.0, "θo={theta}");
        assert!(e_mf > 0.0, "θo={theta}: {e_mf}");
    }
}

/// Reciprocity of the microfacet adapter with reciprocal inner BRDFs (and with the whole walk over
/// Lambert): f(wo, wi) = f(wi, wo) on random pairs, to 10⁻⁴ relative (a few f32 roundings in each of the four terms and the frame
/// rotations; the terms are exchanged, not recomputed alike, under wo ↔ wi).
#[test]
fn microfacet_is_reciprocal() {
    let mut rng = support::rng(11);
    for inner in 0..3 {
        for tilt in [20.0, 60.0, 80.0] {
            let sn = ShadingNormal::new(dir(tilt, 37.0), None).unwrap();
            let b: Box<dyn Bxdf> = match inner {
                0 => Box::new(NormalMapMicrofacet::new(white(), sn)),
                1 => Box::new(NormalMapMicrofacet::new(white(), sn).with_multiple_bounces()),
                _ => Box::new(NormalMapMicrofacet::new(glossy(0.4), sn)),
            };
            for _ in 0..2000 {
                let wo = support::bxdf::random_upper(&mut rng);
                let wi = support::bxdf::random_upper(&mut rng);
                let (a, c) = (b.eval(wo, wi).x, b.eval(wi, wo).x);
                assert!(
                    (a - c).abs() <= 1e-4 * a.max(c) + 1e-30,
                    "tilt {tilt}: f({wo}, {wi}) = {a}, swapped {c}"
                );
            }
        }
    }
}

/// Every `Some` sample carries exactly `eval` and `pdf` at its direction.
#[test]
fn samples_agree_with_eval_and_pdf() {
    let mut rng = support::rng(5);
    for tilt in [0.0, 30.0, 75.0] {
        let sn = ShadingNormal::new(dir(tilt, 120.0), None).unwrap();
        let models: [Box<dyn Bxdf>; 2] = [
            Box::new(NormalMapMicrofacet::new(glossy(0.2), sn)),
            Box::new(NormalMapTilt::new(glossy(0.2), sn)),
        ];
        for b in &models {
            for _ in 0..5000 {
                let wo = support::bxdf::random_upper(&mut rng);
                let u = Vec2::new(
                    rand::RngExt::random(&mut rng),
                    rand::RngExt::random(&mut rng),
                );
                if let Some(s) = b.sample(wo, rand::RngExt::random(&mut rng), u) {
                    assert_eq!((s.f, s.pdf), b.eval_pdf(wo, s.wi), "tilt {tilt}");
                }
            }
        }
    }
}

/// Chi-square of both samplers against their pdf (tests/it/support/chi2.rs; family of all cases,
/// Šidák-corrected): Lambert and GGX α = 0.3 with Schlick Fresnel, tilts 30° and 60°, views
/// toward and away from the lean, grazing included.
#[test]
fn chi2_samplers() {
    let schlick = SchlickFresnel::new(Vec3::splat(0.5)).unwrap();
    let ggx = MicrofacetBrdf::new(Ggx::isotropic(0.3).unwrap(), schlick);
    let lambert = Lambert::new(Vec3::splat(0.8)).unwrap();
    let mut cases: Vec<(String, Box<dyn Bxdf>, Vec3)> = vec![];
    for tilt in [30.0, 60.0] {
        let sn = ShadingNormal::new(dir(tilt, 20.0), None).unwrap();
        for (theta, phi) in [(0.0, 0.0), (25.0, 200.0), (70.0, 20.0), (80.0, 110.0)] {
            let wo = dir(theta, phi);
            let tag = format!("tilt {tilt} θo {theta} φo {phi}");
            cases.push((
                format!("mf lambert {tag}"),
                Box::new(NormalMapMicrofacet::new(lambert, sn)),
                wo,
            ));
            cases.push((
                format!("mf ggx {tag}"),
                Box::new(NormalMapMicrofacet::new(ggx, sn)),
                wo,
            ));
            cases.push((
                format!("tilt ggx {tag}"),
                Box::new(NormalMapTilt::new(ggx, sn)),
                wo,
            ));
        }
    }
    let family = cases.len();
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|(name, b, wo)| {
            Chi2 {
                samples: 300_000,
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

proptest! {
    #![proptest_config(support::proptest_config(256))]

    /// Totality on arbitrary directions, random numbers and shading normals.
    #[test]
    fn totality(
        wo in any_dir(), wi in any_dir(), n in any_dir(),
        uc in any_u(), ux in any_u(), uy in any_u(),
    ) {
        let Ok(sn) = ShadingNormal::new(n, Some(Vec3::new(0.3, -1.0, 0.2))) else {
            return Ok(());
        };
        let u = Vec2::new(ux, uy);
        check_bxdf(&NormalMapMicrofacet::new(glossy(0.2), sn), wo, wi, uc, u);
        check_bxdf(&NormalMapMicrofacet::new(white(), sn), wo, wi, uc, u);
        check_bxdf(&NormalMapMicrofacet::new(white(), sn).with_multiple_bounces(), wo, wi, uc, u);
        check_bxdf(&NormalMapTilt::new(glossy(0.2), sn), wo, wi, uc, u);
        check_bxdf(&NormalMapTilt::new(white(), sn), wo, wi, uc, u);
    }
}

/// The orb's reference (b) through the tilt adapter (examples/common/orb/render.rs,
/// `conventional_brdf`): per position of slope ñ, a Beckmann lobe in the shading frame with
/// α_x = √2 σ n_z² along the lean and α_y = √2 σ n_z, separable masking, reproduces the facet lobe
/// of `naive_brdf` (slope covariance σ² I in the geometric frame) in the renderer's measure,
/// naive × A(wi)/cos θi with A(wi) = ⟨wi, n⟩/n_z, to first order in σ. Checked at σ = 0.01 for
/// tilts up to 60° at the peak (wi = reflect(wo, n)) and at half vectors one σ off it along and
/// across the lean, to 3 % (the second-order terms: σ ≈ 1 % of slope, times the tilt's curvature
/// of the slope map; measured 1.4 % at most).
#[test]
fn tilt_adapter_matches_the_orb_facet_lobe() {
    use brdf::fresnel::NoFresnel;
    use brdf::glint::{NormalMap, naive_brdf};
    use brdf::ndf::Beckmann;
    let sigma = 0.01f32;
    let (mut worst, mut checked) = (0.0f32, 0);
    for (tilt, phi) in [(0.0, 0.0), (20.0, 40.0), (45.0, 200.0), (60.0, 300.0)] {
        let n = dir(tilt, phi);
        let slope = brdf::frame::normal_to_slope(n).unwrap();
        let map = NormalMap::from_slopes(4, 4, vec![slope; 16]).unwrap();
        let lean = Vec3::new(n.x, n.y, 0.0).try_normalize();
        let sn = ShadingNormal::new(n, lean).unwrap();
        let a = std::f32::consts::SQRT_2 * sigma;
        let inner = MicrofacetBrdf::new(Beckmann::new(a * n.z * n.z, a * n.z).unwrap(), NoFresnel)
            .with_masking(brdf::bxdf::Masking::Separable);
        let tilt_b = NormalMapTilt::new(inner, sn);
        let frame = sn.frame();
        for wo_local in [dir(10.0, 30.0), dir(40.0, 160.0)] {
            let wo = frame.to_world(wo_local);
            if wo.z <= 0.05 {
                continue;
            }
            for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (-1.0, -1.0)] {
                // A half vector offset from n by (dx, dy) σ in geometric slope space.
                let h = brdf::frame::slope_to_normal(slope + Vec2::new(dx, dy) * sigma);
                let wi = 2.0 * wo.dot(h) * h - wo;
                if wi.z <= 0.05 || wi.dot(n) <= 0.0 {
                    continue;
                }
                let naive =
                    naive_brdf(&map, Vec2::splat(0.5), wo, wi, sigma) * (wi.dot(n) / n.z) / wi.z;
                let ours = tilt_b.eval(wo, wi).x;
                let rel = (ours - naive).abs() / naive;
                worst = worst.max(rel);
                checked += 1;
                assert!(
                    rel < 0.03,
                    "tilt {tilt} φ {phi} wo {wo} offset ({dx}, {dy}): tilt adapter {ours}, facet lobe {naive}"
                );
            }
        }
    }
    println!("tilt adapter against the orb's facet lobe: worst relative difference {worst:.4}");
    assert!(checked >= 24, "only {checked} configurations checked");
}
