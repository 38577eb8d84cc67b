//! The inverse bin map's costs at 2048² (ignored; figures in docs/results.md): build time, bytes per
//! texel by structure, and per query the nodes visited, texels tested, D evaluation and `patch()`.

use crate::support;

use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{BinMap, BinMapPatch, Footprint, bumpy};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use rand::RngExt;

/// Build time, memory and query costs at 2048² (one run; figures in docs/results.md). Command:
/// `cargo test --release --test it -- --ignored binmap_cost::build_2048 --nocapture`
#[test]
#[ignore]
fn build_2048() {
    let n = 2048;
    let map = bumpy(n, n, 0.25, 4.0, 1).unwrap();
    for lookup in [BinLookup::Dense, BinLookup::Hash] {
        let t = std::time::Instant::now();
        let bm = BinMap::build(
            &map,
            BinMapParams {
                lookup,
                ..BinMapParams::default()
            },
        )
        .unwrap();
        let dt = t.elapsed();
        let mem = bm.memory();
        let tex = (n * n) as f64;
        println!(
            "{lookup:?}: build {:.2} s; B/texel: bin map {:.2}, inverse {:.2}, forest {:.3}, lookup {:.4}, bin tables {:.4}, moments {:.3}, total {:.2}",
            dt.as_secs_f64(),
            mem.bin_map as f64 / tex,
            mem.inverse as f64 / tex,
            mem.forest as f64 / tex,
            mem.lookup as f64 / tex,
            mem.bin_tables as f64 / tex,
            mem.moments as f64 / tex,
            mem.total() as f64 / tex
        );
    }
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let hashed = BinMap::build(
        &map,
        BinMapParams {
            lookup: BinLookup::Hash,
            ..BinMapParams::default()
        },
    )
    .unwrap();
    println!(
        "| footprint (texels) | nodes / query | texels tested / query | clipped / query | d dense | d hash | patch() |"
    );
    println!("|---|---|---|---|---|---|---|");
    for area in [1.0f32, 16.0, 256.0, 4096.0, 65536.0] {
        let patch = bm.patch(&Footprint::isotropic_texels(
            Vec2::new(0.43, 0.57),
            area,
            n,
            n,
        ));
        let mut rng = support::rng(1);
        let (mut nodes, mut texels, mut clipped) = (0, 0, 0);
        let q = 2000;
        for _ in 0..q {
            let m = patch.sample_normal(Vec2::new(rng.random(), rng.random()));
            let (_, s) = patch.bin_overlap_with_stats(bm.bins().bin_of(m).unwrap());
            nodes += s.nodes;
            texels += s.texels;
            clipped += s.clipped;
        }
        // Wall-clock per call (median of 5 passes over 2000 half vectors drawn from the patch).
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
        let hs: Vec<Vec3> = (0..q)
            .map(|_| patch.sample_normal(Vec2::new(rng.random(), rng.random())))
            .collect();
        let time_d = |p: &BinMapPatch| {
            let mut t: Vec<f64> = (0..5)
                .map(|_| {
                    let t0 = std::time::Instant::now();
                    let s: f32 = hs.iter().map(|&h| p.d(h)).sum();
                    std::hint::black_box(s);
                    t0.elapsed().as_secs_f64() / q as f64
                })
                .collect();
            t.sort_by(f64::total_cmp);
            t[2]
        };
        let (td, th) = (time_d(&patch), time_d(&hashed.patch(&fp)));
        let t0 = std::time::Instant::now();
        for _ in 0..20 {
            std::hint::black_box(bm.patch(&fp).area_texels());
        }
        let tp = t0.elapsed().as_secs_f64() / 20.0;
        println!(
            "| {area} | {:.1} | {:.1} | {:.1} | {:.2} µs | {:.2} µs | {:.1} µs |",
            nodes as f64 / q as f64,
            texels as f64 / q as f64,
            clipped as f64 / q as f64,
            td * 1e6,
            th * 1e6,
            tp * 1e6
        );
    }
}
