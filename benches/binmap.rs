//! Cost of the inverse bin map (Atanasov 2020): build at 512² and 2048², patch construction (owned
//! buffers and `patch_in` with a reused scratch), `d(h)` against the footprint size from 1 to 65 536
//! texels (the "roughly flat" claim) with the dense and the hashed bin lookup and with one or 2 × 2
//! sub-texels per texel, and the visible-normal sampler (sample + pdf) against the view angle.
//!
//! Inputs (maps, bin maps, half vectors) are generated before timing. Half vectors are drawn from
//! each patch's own sampler (so they hit occupied bins, the expensive case) and 1024 are evaluated
//! per iteration: divide the time by 1024.
//!
//! Run: `cargo bench -p brdf-benches --bench binmap -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//! (a group: append its name, e.g. `binmap_d_2048`).

use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{BinMap, Footprint, GlintScratch, bumpy};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

const SIZE: usize = 2048;
const AREAS: [f32; 9] = [
    1.0, 4.0, 16.0, 64.0, 256.0, 1024.0, 4096.0, 16384.0, 65536.0,
];

/// Deterministic numbers in [0, 1)² (R2 sequence).
fn r2(k: usize) -> Vec2 {
    Vec2::new(
        (0.5 + k as f64 * 0.754_877_666_246_692_7).fract() as f32,
        (0.5 + k as f64 * 0.569_840_290_998_053_2).fract() as f32,
    )
}

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("binmap_build");
    for size in [512usize, SIZE] {
        let map = bumpy(size, size, 0.25, 4.0, 1).unwrap();
        g.throughput(Throughput::Elements((size * size) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(size), &map, |b, map| {
            b.iter(|| BinMap::build(black_box(map), BinMapParams::default()).unwrap())
        });
    }
    g.finish();
}

fn eval(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    for (lookup, sub) in [
        (BinLookup::Dense, 2),
        (BinLookup::Hash, 2),
        (BinLookup::Dense, 1),
    ] {
        let bm = BinMap::build(
            &map,
            BinMapParams {
                lookup,
                subdivisions: sub,
                ..BinMapParams::default()
            },
        )
        .unwrap();
        let mut g = c.benchmark_group(format!("binmap_d_2048_{lookup:?}_s{sub}"));
        g.throughput(Throughput::Elements(1024));
        for area in AREAS {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE);
            let patch = bm.patch(&fp);
            let hs: Vec<Vec3> = (0..1024).map(|k| patch.sample_normal(r2(k))).collect();
            g.bench_with_input(BenchmarkId::from_parameter(area), &hs, |b, hs| {
                b.iter(|| hs.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
            });
        }
        g.finish();
    }
}

fn patch_construction(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let mut g = c.benchmark_group("binmap_patch_2048");
    for area in AREAS {
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE);
        g.bench_with_input(BenchmarkId::from_parameter(area), &fp, |b, fp| {
            b.iter(|| bm.patch(black_box(fp)).area_texels())
        });
    }
    g.finish();
    let mut g = c.benchmark_group("binmap_patch_in_2048");
    let scratch = GlintScratch::default();
    for area in AREAS {
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE);
        g.bench_with_input(BenchmarkId::from_parameter(area), &fp, |b, fp| {
            b.iter(|| bm.patch_in(black_box(fp), &scratch).area_texels())
        });
    }
    g.finish();
}

/// sample_visible + pdf_visible against θo at a 64-texel footprint and against the footprint at
/// θo = 60° (azimuth 210°, where the benchmark patch faces the view); 1024 calls per iteration. The
/// sampler is O(bins of the footprint) per call.
fn visible(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let dir = |theta: f32| {
        let (t, p) = (theta.to_radians(), 210f32.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    let mut g = c.benchmark_group("binmap_sample_visible_2048");
    g.throughput(Throughput::Elements(1024));
    for (area, theta) in [
        (64.0f32, 0.0f32),
        (64.0, 60.0),
        (64.0, 89.0),
        (1024.0, 60.0),
        (4096.0, 60.0),
    ] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE);
        let patch = bm.patch(&fp);
        let wo = dir(theta);
        let id = BenchmarkId::from_parameter(format!("{area}texels_{theta}deg"));
        g.bench_with_input(id, &wo, |b, &wo| {
            b.iter(|| {
                (0..1024)
                    .map(|k| {
                        let m = patch.sample_visible(black_box(wo), r2(k));
                        patch.pdf_visible(wo, m)
                    })
                    .sum::<f32>()
            })
        });
    }
    g.finish();
}

fn smoothed(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let mut g = c.benchmark_group("binmap_smoothed_d_2048_256texels");
    g.throughput(Throughput::Elements(1024));
    let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 256.0, SIZE, SIZE);
    for alpha in [0.01f32, 0.02, 0.05, 0.1] {
        let patch = bm.patch_with(
            &fp,
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: alpha,
                ..Default::default()
            },
            None,
        );
        let hs: Vec<Vec3> = (0..1024).map(|k| patch.sample_normal(r2(k))).collect();
        g.bench_with_input(BenchmarkId::from_parameter(alpha), &hs, |b, hs| {
            b.iter(|| hs.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
        });
    }
    g.finish();
    // The grazing example's setting (α = 0.1) against the footprint: patches with exact masking
    // terms (≤ 4096 texels) against the larger ones, which sum over a window of bins.
    let mut g = c.benchmark_group("binmap_smoothed_d_2048_alpha0.1");
    g.throughput(Throughput::Elements(1024));
    for area in [64.0f32, 1024.0, 4096.0, 16384.0] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE);
        let patch = bm.patch_with(
            &fp,
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: 0.1,
                ..Default::default()
            },
            None,
        );
        let hs: Vec<Vec3> = (0..1024).map(|k| patch.sample_normal(r2(k))).collect();
        g.bench_with_input(BenchmarkId::from_parameter(area), &hs, |b, hs| {
            b.iter(|| hs.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
        });
    }
    g.finish();
}

criterion_group!(benches, build, eval, patch_construction, visible, smoothed);
criterion_main!(benches);
