//! Cost of the glint base layer: building each procedural map at 2048², a map's slope-moment mip
//! chain at 1024² and 4096², the reference P-NDF of a
//! 256-texel footprint on 64² bins, and the per-call cost of the interpolated normal lookup.
//!
//! Inputs (maps) are generated before timing. The reference uses short settings (2.5·10⁵ positions)
//! so that its cost per position can be read off: divide by `BinnedPndf::samples()`.
//!
//! Run: `cargo bench -p brdf-benches --bench glint -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`

use brdf::glint::{
    BrushedParams, FlakesParams, Footprint, HemisphereBins, Kernel, ScratchedParams, binned_pndf,
    brushed, bumpy, flakes, scratched,
};
use brdf::{Vec2, glint::NormalMap};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

const SIZE: usize = 2048;

fn build(c: &mut Criterion) {
    let mut g = c.benchmark_group("procedural_2048");
    g.throughput(Throughput::Elements((SIZE * SIZE) as u64));
    g.bench_function("bumpy", |b| {
        b.iter(|| bumpy(SIZE, SIZE, 0.25, 4.0, black_box(1)).unwrap())
    });
    g.bench_function("brushed", |b| {
        b.iter(|| brushed(SIZE, SIZE, BrushedParams::default(), black_box(1)).unwrap())
    });
    g.bench_function("scratched", |b| {
        b.iter(|| scratched(SIZE, SIZE, ScratchedParams::default(), black_box(1)).unwrap())
    });
    g.bench_function("flakes", |b| {
        b.iter(|| flakes(SIZE, SIZE, FlakesParams::default(), black_box(1)).unwrap())
    });
    g.finish();
    // The slope-moment mip chain of a map, built explicitly (`NormalMap::moment_pyramid`).
    let mut g = c.benchmark_group("moment_pyramid");
    for n in [1024, 4096] {
        let map = bumpy(n, n, 0.25, 4.0, 1).unwrap();
        g.throughput(Throughput::Elements((n * n) as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &map, |b, map| {
            b.iter(|| black_box(map).moment_pyramid())
        });
    }
    g.finish();
}

fn reference(c: &mut Criterion) {
    let map = bumpy(512, 512, 0.25, 4.0, 1).unwrap();
    let bins = HemisphereBins::new(64).unwrap();
    let f = Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 256.0, 512, 512);
    let samples = 250_000;
    let mut g = c.benchmark_group("reference_pndf_64bins_256texels");
    g.throughput(Throughput::Elements(samples as u64));
    for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
        g.bench_with_input(
            BenchmarkId::from_parameter(format!("{kernel:?}")),
            &kernel,
            |b, &k| b.iter(|| binned_pndf(&map, &f, k, &bins, samples, black_box(3))),
        );
    }
    g.finish();
}

fn lookups(c: &mut Criterion) {
    let map: NormalMap = bumpy(512, 512, 0.25, 4.0, 1).unwrap();
    let points: Vec<Vec2> = (0..1024)
        .map(|k| {
            Vec2::new(
                (k as f32 * 0.618_034).fract() * 512.0,
                (k as f32 * 0.414_213_5).fract() * 512.0,
            )
        })
        .collect();
    let mut g = c.benchmark_group("normal_map_1024_lookups");
    g.throughput(Throughput::Elements(points.len() as u64));
    g.bench_function("normal_at_texel", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|&p| map.normal_at_texel(black_box(p)).z)
                .sum::<f32>()
        })
    });
    g.bench_function("moment_pyramid_filtered", |b| {
        let pyramid = map.moment_pyramid(); // built before timing
        b.iter(|| {
            points
                .iter()
                .map(|&p| pyramid.filtered(black_box(p), 6.0)[2])
                .sum::<f32>()
        })
    });
    g.finish();
}

criterion_group!(benches, build, reference, lookups);
criterion_main!(benches);
