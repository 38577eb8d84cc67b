//! The bin map's masking without a bin list against its footprint's own visible area: the white
//! furnace is at most V_P(wo)/V(wo) (docs/binmap.md, "Furnace convention"), so the masking may not
//! use a V below the footprint's. Probe (ignored): the largest V_bins(wo)/V_moment(wo) over maps,
//! seeds, footprints and views, and the furnace at the worst view of each cell. Command:
//! `BRDF_PROBE_N=128 cargo test --test it binmap_masking_bound:: -- --ignored --nocapture`.

use crate::support;
use brdf::MicrofacetBrdf;
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::{BinMapParams, PatchOptions};
use brdf::glint::{BinMap, Footprint, GlintNdf};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};

fn dir(theta: f32, phi: f32) -> Vec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// `BRDF_PROBE_N` (map size, default 128), seeds 1-3.
#[test]
#[ignore]
fn visible_area_ratio_probe() {
    let n: usize = std::env::var("BRDF_PROBE_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(128);
    let exact = PatchOptions {
        exact_masking_texels: f32::INFINITY,
        moment_masking_tolerance: 0.0,
        ..PatchOptions::default()
    };
    let moment = PatchOptions {
        exact_masking_texels: 0.0,
        ..exact
    };
    for seed in 1..=3u64 {
        for (name, map) in support::procedural_maps_seeded(n, seed) {
            let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
            let mut row = vec![];
            for area in [128.0f32, 256.0, 1024.0, 4096.0, 8192.0] {
                let mut worst = 0.0f64;
                let mut worst_at = None;
                let mut mean = 0.0f64;
                let mut count = 0.0;
                for (cx, cy, aniso, rot) in [
                    (0.37f32, 0.61f32, 1.0f32, 0.0f32),
                    (0.71, 0.23, 1.0, 0.0),
                    (0.13, 0.87, 4.0, 0.5),
                    (0.52, 0.44, 8.0, 1.1),
                ] {
                    let fp = if aniso == 1.0 {
                        Footprint::isotropic_texels(Vec2::new(cx, cy), area, n, n)
                    } else {
                        let minor = (area / aniso).sqrt() / n as f32;
                        let major = minor * aniso;
                        let a = Vec2::new(rot.cos(), rot.sin()) * major;
                        let b = Vec2::new(-rot.sin(), rot.cos()) * minor;
                        Footprint::from_differentials(Vec2::new(cx, cy), a, b)
                    };
                    let pe = bm.patch_with(&fp, &exact, None);
                    let pm = bm.patch_with(&fp, &moment, None);
                    for theta in [0.0f32, 20.0, 40.0, 60.0, 70.0, 80.0] {
                        for k in 0..8 {
                            let wo = dir(theta, 22.5 + 45.0 * k as f32);
                            let ve = pe.visible_area(wo) as f64;
                            let vm = pm.visible_area(wo) as f64;
                            if ve > 0.0 && vm > 0.0 {
                                let r = ve / vm;
                                if r > worst {
                                    worst = r;
                                    worst_at = Some((fp, wo));
                                }
                                mean += r;
                                count += 1.0;
                            }
                        }
                    }
                }
                let (fp, wo) = worst_at.unwrap();
                let pm = bm.patch_with(&fp, &moment, None);
                let (e, se) = support::albedo(&MicrofacetBrdf::new(&pm, NoFresnel), wo, 4096);
                row.push(format!(
                    "{area}: max {worst:.4} (θ {:.0}°, E {e:.4} ± {se:.4}) mean {:.3}",
                    wo.z.acos().to_degrees(),
                    mean / count
                ));
            }
            println!("{name} seed {seed}: {}", row.join(" | "));
        }
    }
}
