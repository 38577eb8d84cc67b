//! Fresnel terms and warps: time per call, on 1024 inputs generated before timing.
//!
//! Run: `cargo bench --bench fresnel -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//! (the figures in docs/results.md, section "Fresnel and warps", come from this command).

use brdf::Vec3;
use brdf::fresnel::{ConductorFresnel, conductor, dielectric, schlick};
use brdf::warp::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec2;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const N: usize = 1024;

fn inputs() -> (Vec<f32>, Vec<Vec2>, Vec<Vec3>) {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
    let cos: Vec<f32> = (0..N).map(|_| rng.random_range(-1.0f32..1.0)).collect();
    let u: Vec<Vec2> = (0..N)
        .map(|_| Vec2::new(rng.random(), rng.random()))
        .collect();
    let w: Vec<Vec3> = u.iter().map(|&u| square_to_uniform_hemisphere(u)).collect();
    (cos, u, w)
}

fn fresnel(c: &mut Criterion) {
    let (cos, _, _) = inputs();
    let mut g = c.benchmark_group("fresnel");
    g.throughput(Throughput::Elements(N as u64));
    for eta in [1.5f32, 1.0 / 1.5] {
        g.bench_with_input(BenchmarkId::new("dielectric", eta), &eta, |b, &eta| {
            b.iter(|| {
                cos.iter()
                    .map(|&c| dielectric(black_box(c), eta))
                    .sum::<f32>()
            })
        });
    }
    let gold = ConductorFresnel::GOLD;
    g.bench_function("conductor/gold", |b| {
        b.iter(|| {
            cos.iter()
                .map(|&c| conductor(black_box(c), gold.eta, gold.k))
                .sum::<Vec3>()
        })
    });
    let f0 = gold.f0();
    g.bench_function("schlick/gold", |b| {
        b.iter(|| cos.iter().map(|&c| schlick(f0, black_box(c))).sum::<Vec3>())
    });
    g.finish();
}

fn warps(c: &mut Criterion) {
    let (_, u, w) = inputs();
    let mut g = c.benchmark_group("warp");
    g.throughput(Throughput::Elements(N as u64));
    type Forward = (&'static str, fn(Vec2) -> Vec3);
    let forward: [Forward; 3] = [
        ("cosine", square_to_cosine_hemisphere),
        ("uniform", square_to_uniform_hemisphere),
        ("equal_area", square_to_hemisphere_equal_area),
    ];
    for (name, f) in forward {
        g.bench_function(BenchmarkId::new("sample", name), |b| {
            b.iter(|| u.iter().map(|&u| f(black_box(u))).sum::<Vec3>())
        });
    }
    type Inverse = (&'static str, fn(Vec3) -> Vec2);
    let inverse: [Inverse; 3] = [
        ("cosine", cosine_hemisphere_to_square),
        ("uniform", uniform_hemisphere_to_square),
        ("equal_area", hemisphere_to_square_equal_area),
    ];
    for (name, f) in inverse {
        g.bench_function(BenchmarkId::new("invert", name), |b| {
            b.iter(|| w.iter().map(|&w| f(black_box(w))).sum::<Vec2>())
        });
    }
    g.bench_function(BenchmarkId::new("sample", "gaussian_2d"), |b| {
        b.iter(|| {
            u.iter()
                .map(|&u| square_to_gaussian_2d(black_box(u)))
                .sum::<Vec2>()
        })
    });
    g.finish();
}

criterion_group!(benches, fresnel, warps);
criterion_main!(benches);
