//! The position-normal baseline's tables for docs/results.md (all ignored): accuracy against the
//! ground truth, the white furnace of the published BRDF beside `MicrofacetBrdf`, and the
//! level-of-detail table behind the query cap.

use crate::support;

use brdf::fresnel::NoFresnel;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{Footprint, GlintNdf, PositionNormalBrdf, PositionNormalMap};
use brdf::ndf::Ndf;
use brdf::{Bxdf, MicrofacetBrdf, Vec2, Vec3};
use rand::RngExt;
use support::position_normal::build;

/// Accuracy against the ground truth (same maps, footprints and bins as the mixture's table).
/// `cargo test --release --test it -- --ignored position_normal_tables::accuracy_table --nocapture`
#[test]
#[ignore]
fn accuracy_table() {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, tv_distance};
    let n = 256;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | elements | TV position-normal | TV rate 2 | TV moments lobe | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, map) in &maps {
        let pn = build(map);
        let pn2 = PositionNormalMap::build(
            map,
            PositionNormalParams {
                sampling_rate: 2,
                ..PositionNormalParams::default()
            },
        )
        .unwrap();
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let reference = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let patch = pn.patch(&fp);
            let tv = tv_distance(&patch, &reference, 4);
            let tv2 = tv_distance(&pn2.patch(&fp), &reference, 4);
            let tv_lobe = tv_distance(patch.moments_lobe(), &reference, 4);
            println!(
                "| {name} | {area} | {} | {tv:.3} | {tv2:.3} | {tv_lobe:.3} | {:.3} |",
                patch.element_count(),
                reference.tv_error()
            );
        }
    }
    let pn = build(&maps[0].1);
    let m = pn.memory();
    println!(
        "\nmemory ({n}², rate 1): {} elements, {} bytes of elements, {} bytes of hierarchy ({:.1} bytes per element)",
        m.elements,
        m.element_bytes,
        m.hierarchy_bytes,
        (m.element_bytes + m.hierarchy_bytes) as f64 / m.elements as f64
    );
}

/// White furnace of the published BRDF (F = 1) and of `MicrofacetBrdf` on the same patch, by
/// importance sampling (2·10⁵ samples, ± one standard error).
/// `cargo test --release --test it -- --ignored position_normal_tables::furnace_table --nocapture`
#[test]
#[ignore]
fn furnace_table() {
    use brdf::glint::{FlakesParams, ScratchedParams, bumpy, flakes, scratched};
    let n = 256;
    let maps = vec![
        ("bumpy 0.25", bumpy(n, n, 0.25, 4.0, 1).unwrap()),
        ("bumpy 0.6", bumpy(n, n, 0.6, 4.0, 1).unwrap()),
        (
            "scratched",
            scratched(n, n, ScratchedParams::default(), 3).unwrap(),
        ),
        ("flakes", flakes(n, n, FlakesParams::default(), 4).unwrap()),
    ];
    println!(
        "| map | footprint (texels) | θo | published (Yan 2016) | MicrofacetBrdf (exact masking) |"
    );
    println!("|---|---|---|---|---|");
    for (name, map) in &maps {
        let pn = build(map);
        for area in [1.0f32, 16.0, 256.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let patch = pn.patch(&fp);
            let yan = PositionNormalBrdf::new(&patch, NoFresnel);
            let micro = MicrofacetBrdf::new(&patch, NoFresnel);
            for theta in [0.0, 45.0, 75.0] {
                let wo = support::dir(theta, 30.0);
                let est = |b: &dyn Bxdf| {
                    let mut rng = support::rng(11);
                    let k = 200_000;
                    let (mut s, mut s2) = (0.0f64, 0.0f64);
                    for _ in 0..k {
                        let w = b
                            .sample(wo, 0.5, Vec2::new(rng.random(), rng.random()))
                            .map_or(0.0, |x| x.weight().x as f64);
                        s += w;
                        s2 += w * w;
                    }
                    let m = s / k as f64;
                    (m, ((s2 / k as f64 - m * m) / k as f64).sqrt())
                };
                let (a, sa) = est(&yan);
                let (b, sb) = est(&micro);
                println!("| {name} | {area} | {theta}° | {a:.3} ± {sa:.3} | {b:.3} ± {sb:.3} |");
            }
        }
    }
}

/// The level-of-detail chart behind `DEFAULT_MAX_QUERY_TEXELS`: on 512² procedural maps, for
/// footprints of 1 to 65 536 texels, the distance of the P-NDF to the ground truth (64² bins,
/// 4·10⁶ positions, one evaluation per bin) and the time of one `patch()` and one `d` (one thread,
/// 512 normals, half from D_P cos, half bin centres), with the query cap of 128 texels (the
/// released code's) and without a cap. Where the cap does not bite (`query_scale` 1) the two
/// patches are the same computation and one row is printed. Maps run in parallel (rayon).
///
/// `cargo test --test it -- --ignored position_normal_tables::lod_table --nocapture` (the test profile is
/// opt-level 3; times from one run on a loaded machine: read them as ratios).
#[test]
#[ignore]
fn lod_table() {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, tv_distance};
    use rayon::prelude::*;
    use std::time::Instant;
    let n = 512;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | cap (texels) | σ scale | elements | TV | patch() | d | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    maps.par_iter().for_each(|(name, map)| {
        let pn = build(map);
        for area in [1.0f32, 16.0, 256.0, 4096.0, 16384.0, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let reference = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let capped = pn
                .patch_with(
                    &fp,
                    &brdf::glint::position_normal::PatchOptions {
                        filtered_area: f32::INFINITY,
                        ..Default::default()
                    },
                    None,
                )
                .query_scale()
                < 1.0;
            let caps: &[f32] = if capped {
                &[128.0, f32::INFINITY]
            } else {
                &[128.0]
            };
            for &cap in caps {
                let patch = pn.patch_with(
                    &fp,
                    &brdf::glint::position_normal::PatchOptions {
                        max_query_texels: cap,
                        cut_nodes: 0,
                        filtered_area: f32::INFINITY,
                        ..Default::default()
                    },
                    None,
                );
                let tv = tv_distance(&patch, &reference, 1);
                let normals: Vec<Vec3> = (0..512)
                    .map(|k| {
                        let u = Vec2::new((k as f32 + 0.5) / 512.0, (k as f32 * 0.618_034).fract());
                        if k % 2 == 0 {
                            patch.sample_normal(u)
                        } else {
                            bins.center(k * 7 % bins.len())
                        }
                    })
                    .collect();
                let t = Instant::now();
                let s: f32 = normals.iter().map(|&m| patch.d(m)).sum();
                assert!(s.is_finite());
                let t_d = t.elapsed().as_secs_f64() / normals.len() as f64;
                let reps = 10;
                let t = Instant::now();
                for _ in 0..reps {
                    let p = pn.patch_with(
                        std::hint::black_box(&fp),
                        &brdf::glint::position_normal::PatchOptions {
                            max_query_texels: cap,
                            cut_nodes: 0,
                            filtered_area: f32::INFINITY,
                            ..Default::default()
                        },
                        None,
                    );
                    std::hint::black_box(p.element_count());
                }
                let t_patch = t.elapsed().as_secs_f64() / reps as f64;
                println!(
                    "| {name} | {area} | {} | {:.3} | {} | {tv:.3} | {:.1} µs | {:.1} µs | {:.3} |",
                    match (capped, cap.is_finite()) {
                        (false, _) => "any".to_string(),
                        (true, true) => format!("{cap}"),
                        (true, false) => "none".to_string(),
                    },
                    patch.query_scale(),
                    patch.element_count(),
                    t_patch * 1e6,
                    t_d * 1e6,
                    reference.tv_error()
                );
            }
        }
    });
}
