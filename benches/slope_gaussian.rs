//! Per-call cost of the slope-Gaussian lobe's per-direction methods: `d`, `visible_area`, `lambda`,
//! `sample_visible` (and `sample_normal`, `pdf_visible`), on batches of 1024 precomputed inputs.
//!
//! Inputs are generated before timing with a seeded RNG: lobes with mean slopes up to 1 and σ from
//! 0.05 to 0.5 (correlation ±0.7), directions uniform in cos θ ∈ (0.02, 1]. Reported per batch;
//! divide by 1024 for the per-call time.
//!
//! Run: `cargo bench -p brdf-benches --bench slope_gaussian -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`

use brdf::ndf::{Ndf, SlopeGaussian};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Mat2, Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::hint::black_box;

const BATCH: usize = 1024;

struct Inputs {
    lobes: Vec<SlopeGaussian>,
    dirs: Vec<Vec3>,
    normals: Vec<Vec3>,
    us: Vec<Vec2>,
}

/// `sigma`: the lobe's slope standard deviation scale.
fn inputs(sigma: f32) -> Inputs {
    let mut rng = Pcg64Mcg::seed_from_u64(99);
    let mut lobes = Vec::new();
    let mut dirs = Vec::new();
    let mut us = Vec::new();
    for _ in 0..BATCH {
        let mean = Vec2::new(rng.random_range(-0.7..0.7), rng.random_range(-0.7..0.7));
        let (sx, sy) = (
            sigma * rng.random_range(0.5..1.5f32),
            sigma * rng.random_range(0.5..1.5f32),
        );
        let rho: f32 = rng.random_range(-0.7..0.7);
        let c = rho * sx * sy;
        lobes.push(
            SlopeGaussian::new(mean, Mat2::from_cols_array(&[sx * sx, c, c, sy * sy])).unwrap(),
        );
        let z: f32 = rng.random_range(0.02..1.0);
        let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        dirs.push(Vec3::new(s * phi.cos(), s * phi.sin(), z));
        us.push(Vec2::new(rng.random(), rng.random()));
    }
    // Normals near each lobe (drawn from it), so that `d` does real work.
    let normals = lobes
        .iter()
        .zip(&us)
        .map(|(g, &u)| g.sample_normal(u))
        .collect();
    Inputs {
        lobes,
        dirs,
        normals,
        us,
    }
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("slope_gaussian");
    group.throughput(Throughput::Elements(BATCH as u64));
    for sigma in [0.05f32, 0.5] {
        let inp = inputs(sigma);
        let id = |name: &str| BenchmarkId::new(name, format!("sigma={sigma}"));
        group.bench_function(id("d"), |b| {
            b.iter(|| {
                let mut s = 0.0;
                for (g, &m) in inp.lobes.iter().zip(&inp.normals) {
                    s += g.d(black_box(m));
                }
                s
            })
        });
        group.bench_function(id("p22"), |b| {
            b.iter(|| {
                let mut s = 0.0;
                for (g, &m) in inp.lobes.iter().zip(&inp.normals) {
                    s += g.p22(black_box(Vec2::new(-m.x / m.z, -m.y / m.z)));
                }
                s
            })
        });
        group.bench_function(id("visible_area"), |b| {
            b.iter(|| {
                let mut s = 0.0;
                for (g, &w) in inp.lobes.iter().zip(&inp.dirs) {
                    s += g.visible_area(black_box(w));
                }
                s
            })
        });
        group.bench_function(id("lambda"), |b| {
            b.iter(|| {
                let mut s = 0.0;
                for (g, &w) in inp.lobes.iter().zip(&inp.dirs) {
                    s += g.lambda(black_box(w)).min(1e6);
                }
                s
            })
        });
        group.bench_function(id("sample_normal"), |b| {
            b.iter(|| {
                let mut s = Vec3::ZERO;
                for (g, &u) in inp.lobes.iter().zip(&inp.us) {
                    s += g.sample_normal(black_box(u));
                }
                s
            })
        });
        group.bench_function(id("sample_visible"), |b| {
            b.iter(|| {
                let mut s = Vec3::ZERO;
                for ((g, &w), &u) in inp.lobes.iter().zip(&inp.dirs).zip(&inp.us) {
                    s += g.sample_visible(black_box(w), black_box(u));
                }
                s
            })
        });
        group.bench_function(id("pdf_visible"), |b| {
            b.iter(|| {
                let mut s = 0.0;
                for ((g, &w), &m) in inp.lobes.iter().zip(&inp.dirs).zip(&inp.normals) {
                    s += g.pdf_visible(black_box(w), black_box(m));
                }
                s
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
