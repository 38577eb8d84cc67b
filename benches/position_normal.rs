//! Cost of the position-normal baseline (Yan 2016): building the elements of a 512² map, and per
//! footprint size (1 … 4096 texels) the patch construction, one `d` evaluation (at half vectors drawn
//! from the patch, so that they land on its glints) and one `sample_normal`.
//!
//! Inputs (map, representation, patches, directions) are generated before timing.
//!
//! Run: `cargo bench -p brdf-benches --bench position_normal -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`

use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{Footprint, GlintNdf, PositionNormalMap, bumpy};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;

const SIZE: usize = 512;
const AREAS: [f32; 4] = [1.0, 16.0, 256.0, 4096.0];

fn build(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let mut g = c.benchmark_group("position_normal_build_512");
    g.throughput(Throughput::Elements((SIZE * SIZE) as u64));
    for rate in [1usize, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            ..PositionNormalParams::default()
        };
        g.bench_with_input(BenchmarkId::from_parameter(rate), &params, |b, p| {
            b.iter(|| PositionNormalMap::build(&map, black_box(*p)).unwrap())
        });
    }
    g.finish();
}

fn footprint(area: f32) -> Footprint {
    Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE)
}

fn patch(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
    let mut g = c.benchmark_group("position_normal_patch");
    for area in AREAS {
        let fp = footprint(area);
        g.bench_with_input(BenchmarkId::from_parameter(area), &fp, |b, f| {
            b.iter(|| pn.patch(black_box(f)).element_count())
        });
    }
    g.finish();
}

fn eval(c: &mut Criterion) {
    let map = bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap();
    let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
    let mut g = c.benchmark_group("position_normal_d");
    g.throughput(Throughput::Elements(256));
    for area in AREAS {
        let patch = pn.patch(&footprint(area));
        let dirs: Vec<Vec3> = (0..256)
            .map(|k| {
                let u = Vec2::new(
                    (k as f32 * 0.618_034).fract(),
                    (k as f32 * 0.414_213_5 + 0.1).fract(),
                );
                patch.sample_normal(u)
            })
            .collect();
        g.bench_with_input(BenchmarkId::from_parameter(area), &dirs, |b, dirs| {
            b.iter(|| dirs.iter().map(|&m| patch.d(black_box(m))).sum::<f32>())
        });
    }
    g.finish();
    let mut g = c.benchmark_group("position_normal_sample_normal");
    g.throughput(Throughput::Elements(256));
    for area in AREAS {
        let patch = pn.patch(&footprint(area));
        let _ = patch.sample_normal(Vec2::splat(0.5)); // builds the per-element lobes
        let us: Vec<Vec2> = (0..256)
            .map(|k| {
                Vec2::new(
                    (k as f32 * 0.618_034).fract(),
                    (k as f32 * 0.414_213_5).fract(),
                )
            })
            .collect();
        g.bench_with_input(BenchmarkId::from_parameter(area), &us, |b, us| {
            b.iter(|| {
                us.iter()
                    .map(|&u| patch.sample_normal(black_box(u)).z)
                    .sum::<f32>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, build, patch, eval);
criterion_main!(benches);
