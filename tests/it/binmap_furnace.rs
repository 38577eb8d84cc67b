//! Energy of the inverse bin map: the white furnace ≤ 1 (exact Smith terms, the smoothed variant, up
//! to θo = 89.9° with the horizon bound), and (ignored) the grazing-angle table and the budget of the
//! grazing furnace loss (docs/results.md).

use crate::support;

use brdf::bxdf::Masking;
use brdf::fresnel::NoFresnel;
use brdf::glint::GlintNdf;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::{
    BinMap, Footprint, HemisphereBins, NormalMap, ScratchedParams, bumpy, scratched,
};
use brdf::ndf::Ndf;
use brdf::{MicrofacetBrdf, Vec2, Vec3};
use support::albedo;
use support::binmap::test_maps;

/// The white furnace of the bin map's patches at the default build (255² bins): the footprint's
/// own bins (and the smoothed variant at 16 texels) at 16 and 1024 texels, the moment lobe at 8192,
/// both masking forms, θo up to 85°, at most 1 + 4 standard errors; prints the rows. (The flakes row
/// at 8192 texels read 1.0135 ± 0.0034 at 45° while the moment chain held the map's own slopes in
/// 4 × 4-texel cells; now 0.988.)
#[test]
fn white_furnace() {
    let mut lines = vec![];
    for (name, map) in test_maps() {
        let (w, h) = (map.width(), map.height());
        let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
        for area in [16.0, 1024.0, 8192.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), area, w, h);
            for (label, patch) in [
                ("bins", bm.patch(&fp)),
                (
                    "α=0.1",
                    bm.patch_with(
                        &fp,
                        &brdf::glint::binmap::PatchOptions {
                            smoothing_alpha: 0.1,
                            ..Default::default()
                        },
                        None,
                    ),
                ),
            ] {
                if label != "bins" && area != 16.0 {
                    continue;
                }
                let mut row = vec![];
                for masking in [Masking::Separable, Masking::HeightCorrelated] {
                    for theta in [0.0, 45.0, 70.0, 85.0] {
                        let wo = support::dir(theta, 60.0);
                        let brdf = MicrofacetBrdf::new(&patch, NoFresnel).with_masking(masking);
                        let (e, err) = albedo(&brdf, wo, support::depth(1000, 2000));
                        // ≤ 1 + 4 standard errors (stratified draws make the bound conservative).
                        assert!(
                            e <= 1.0 + 4.0 * err,
                            "{name} {label} {area} {masking:?} θo={theta}: {e} ± {err}"
                        );
                        row.push(format!("{e:.3}"));
                    }
                }
                lines.push(format!(
                    "| {name} | {label} | {area} | {} |",
                    row.join(" | ")
                ));
            }
        }
    }
    println!("{}", lines.join("\n"));
}

/// One view's white furnace E(wo) = ∫ f_P A(wi) dωi (= the renderer's-measure ∫ f cos θi dωi) with
/// height-correlated Smith masking and the patch's visible-normal sampler, from the NDF alone: with
/// h ~ pdf_visible(wo, ·), wi = reflect(wo, h) and dωi = 4⟨wo, h⟩ dh, one sample's weight is
/// D(h) G2(wo, wi, h) ⟨wo, h⟩ / (A(wo) pdf_visible(wo, h)) (0 when wi is below the horizon: "lost").
/// Returns (mean, standard error, σ_w / mean, lost fraction) over `n` R2 points.
fn furnace_stats(patch: &impl Ndf, wo: Vec3, n: usize) -> (f64, f64, f64, f64) {
    let a_o = patch.projected_area(wo) as f64;
    let (mut sum, mut sum2, mut lost) = (0.0f64, 0.0f64, 0usize);
    for k in 0..n {
        let u = Vec2::new(
            (0.5 + k as f64 * 0.754_877_666_246_692_7).fract() as f32,
            (0.5 + k as f64 * 0.569_840_290_998_053_2).fract() as f32,
        );
        let h = patch.sample_visible(wo, u);
        let c = wo.dot(h);
        let wi = 2.0 * c * h - wo;
        let pdf = patch.pdf_visible(wo, h) as f64;
        if !(c > 0.0 && wi.z > 0.0 && pdf > 0.0 && a_o > 0.0) {
            lost += 1;
            continue;
        }
        let wi = wi.normalize();
        let g2 = patch.g2_height_correlated(wo, wi, h) as f64;
        let v = patch.d(h) as f64 * g2 * c as f64 / (a_o * pdf);
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (
        mean,
        (var / n as f64).sqrt(),
        var.sqrt() / mean.max(1e-30),
        lost as f64 / n as f64,
    )
}

/// Grazing-angle table (furnace, weight spread, lost samples) on 64-texel footprints of the 256²
/// bumpy and scratched maps, for 63² and 127² bins. Command:
/// `cargo test --test it -- --ignored binmap_furnace::grazing_table --nocapture`
#[test]
#[ignore]
fn grazing_table() {
    let maps = support::procedural_maps(256);
    println!("| map | bins | θo | furnace | ± | σ_w/E | lost | V / V_ref |");
    println!("|---|---|---|---|---|---|---|---|");
    for (name, map) in maps
        .iter()
        .filter(|(n, _)| *n == "bumpy" || *n == "scratched")
    {
        for n in [63usize, 127] {
            let bm = BinMap::build(
                map,
                BinMapParams {
                    bins_per_axis: n,
                    ..BinMapParams::default()
                },
            )
            .unwrap();
            let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 64.0, 256, 256);
            let patch = bm.patch(&fp);
            for phi in [30.0, 210.0] {
                for theta in [60.0, 85.0, 89.0, 89.9] {
                    let wo = support::dir(theta, phi);
                    if patch.projected_area(wo) <= 0.0 {
                        println!("| {name} | {n}² | {theta}, φ {phi} | A(wo) = 0 | | | |");
                        continue;
                    }
                    let (e, se, spread, lost) = furnace_stats(&patch, wo, 1 << 15);
                    // V_ref = ∫⟨wo, m⟩⁺ D dm by the normal sampler (2¹⁸ R2 points).
                    let k = 1usize << 18;
                    let v_ref = (0..k)
                        .map(|i| {
                            let u = Vec2::new(
                                (0.5 + i as f64 * 0.754_877_666_246_692_7).fract() as f32,
                                (0.5 + i as f64 * 0.569_840_290_998_053_2).fract() as f32,
                            );
                            let m = patch.sample_normal(u);
                            let p = patch.pdf_normal(m) as f64;
                            if p > 0.0 {
                                wo.dot(m).max(0.0) as f64 * patch.d(m) as f64 / p
                            } else {
                                0.0
                            }
                        })
                        .sum::<f64>()
                        / k as f64;
                    println!(
                        "| {name} | {n}² | {theta}, φ {phi} | {e:.3} | {se:.3} | {spread:.2} | {:.1} % | {:.3} |",
                        100.0 * lost,
                        patch.visible_area(wo) as f64 / v_ref
                    );
                }
            }
        }
    }
}

/// The white furnace up to θo = 89.9° with the visible-normal sampler and the tightened horizon
/// bound: ≤ 1 + 4 standard errors everywhere (V is an upper bound), on a flat 1 × 1 map (the case
/// that read 1.80 with the unsound centre-of-bin masking) and on the bumpy and scratched maps.
#[test]
fn furnace_up_to_grazing_stays_below_one() {
    let maps = vec![
        (
            "flat",
            NormalMap::from_slopes(1, 1, vec![Vec2::ZERO]).unwrap(),
            16.0,
        ),
        ("bumpy", bumpy(64, 64, 0.25, 4.0, 1).unwrap(), 64.0),
        (
            "scratched",
            scratched(64, 64, ScratchedParams::default(), 3).unwrap(),
            64.0,
        ),
    ];
    for (name, map, area) in &maps {
        for n in [15usize, 63] {
            let bm = BinMap::build(
                map,
                BinMapParams {
                    bins_per_axis: n,
                    ..BinMapParams::default()
                },
            )
            .unwrap();
            let fp = Footprint::isotropic_texels(
                Vec2::new(0.37, 0.61),
                *area,
                map.width(),
                map.height(),
            );
            for patch in [
                bm.patch(&fp),
                bm.patch_with(
                    &fp,
                    &brdf::glint::binmap::PatchOptions {
                        smoothing_alpha: 0.1,
                        ..Default::default()
                    },
                    None,
                ),
            ] {
                for theta in [70.0, 85.0, 89.0, 89.9] {
                    for phi in [30.0, 210.0] {
                        let wo = support::dir(theta, phi);
                        let (e, se, _, _) =
                            furnace_stats(&patch, wo, support::depth(1 << 11, 1 << 12));
                        assert!(
                            e <= 1.0 + 4.0 * se,
                            "{name} n={n} θo={theta} φ={phi}: {e} ± {se}"
                        );
                    }
                }
            }
        }
    }
}

/// (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω by a q × q midpoint rule on the bin's cell: within L/(n q √2) of the
/// integral (⟨w, m⟩⁺ is 1-Lipschitz in m, the equal-area map L-Lipschitz).
fn visible_part_quadrature(bins: &HemisphereBins, bin: usize, w: Vec3, q: usize) -> f64 {
    let mut s = 0.0;
    for j in 0..q {
        for i in 0..q {
            let u = Vec2::new((i as f32 + 0.5) / q as f32, (j as f32 + 0.5) / q as f32);
            s += w.dot(bins.sample_in_bin(bin, u)).max(0.0) as f64;
        }
    }
    s / (q * q) as f64
}

/// How much of the grazing furnace loss is the horizon bound's (docs/results.md, "The bin map,
/// finished"): the compare example's view (1024² procedural maps, 256-texel footprint at uv
/// (0.43, 0.57), azimuth 30°) at θo = 85° and 89°, the furnace with height-correlated G2 (2¹⁵ R2
/// points, `furnace_stats`), and V(wo) against V_true(wo) = Σ_j (mass_j / c̄_j) × a 64² midpoint rule
/// of the bin's visible part (error ≤ 6·10⁻⁴ of a bin's term at 127²). With separable G2 the
/// furnace is ∝ 1/V(wo), so V/V_true − 1 bounds what any tighter upper bound of V can recover.
/// Command: `cargo test --test it -- --ignored binmap_furnace::grazing_furnace_budget --nocapture`
#[test]
#[ignore]
fn grazing_furnace_budget() {
    let n = 1024;
    let maps = support::procedural_maps(n);
    println!("| map | bins, s | θo | furnace | ± | V / V_true |");
    println!("|---|---|---|---|---|---|");
    let mut mean = std::collections::BTreeMap::new();
    for (name, map) in &maps {
        for (b, s) in [(127usize, 2usize), (127, 1), (255, 2)] {
            let bm = BinMap::build(
                map,
                BinMapParams {
                    bins_per_axis: b,
                    subdivisions: s,
                    ..BinMapParams::default()
                },
            )
            .unwrap();
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 256.0, n, n);
            let patch = bm.patch(&fp);
            let masses = patch.masses_on(bm.bins()).unwrap();
            for theta in [85.0, 89.0] {
                let wo = support::dir(theta, 30.0);
                let (e, se, _, _) = furnace_stats(&patch, wo, 1 << 15);
                let v_true: f64 = masses
                    .iter()
                    .enumerate()
                    .filter(|(_, m)| **m > 0.0)
                    .map(|(j, m)| {
                        m / bm.bins().mean_cos(j) * visible_part_quadrature(bm.bins(), j, wo, 64)
                    })
                    .sum();
                let ratio = patch.visible_area(wo) as f64 / v_true;
                println!("| {name} | {b}², {s} | {theta} | {e:.4} | {se:.4} | {ratio:.5} |");
                let k = mean.entry((b, s, theta as i64)).or_insert((0.0, 0.0));
                k.0 += e / 4.0;
                k.1 += ratio / 4.0;
            }
        }
    }
    for ((b, s, t), (e, r)) in mean {
        println!("| mean of the four | {b}², {s} | {t} | {e:.4} | | {r:.5} |");
    }
}
