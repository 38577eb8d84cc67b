//! Fresnel terms and warps: time per call, on 1024 inputs generated before timing.
//!
//! Every input passes through `black_box` and every result is stored to an output buffer, so the
//! figure is the throughput of independent calls (as in a renderer), not the latency of a chain of
//! additions into one accumulator.
//!
//! Run: `cargo bench -p brdf-benches --bench fresnel -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//! (the figures in docs/results.md, section "Fresnel and warps", come from this command).
//!
//! Table mode (the Fresnel rows of the C++ comparison in docs/results.md,
//! "Analytic NDFs: speed against pbrt-v4 and Mitsuba 3"):
//! `BRDF_TABLE=1 cargo bench -p brdf-benches --bench fresnel` prints the minimum and median ns per call over
//! 5 × 1000 batches of 1024 calls on the inputs of `benches/cpp/analytic.cpp`.

use brdf::Vec3;
use brdf::fresnel::{ConductorFresnel, conductor, dielectric, schlick};
use brdf::warp::*;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use glam::Vec2;
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

#[path = "cpp/table_common.rs"]
mod table;

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
    let mut of = vec![0.0f32; N];
    let mut ov = vec![Vec3::ZERO; N];
    for eta in [1.5f32, 1.0 / 1.5] {
        g.bench_with_input(BenchmarkId::new("dielectric", eta), &eta, |b, &eta| {
            b.iter(|| {
                for (o, &c) in of.iter_mut().zip(&cos) {
                    *o = dielectric(table::opaque(c), eta);
                }
                black_box(&mut of);
            })
        });
    }
    let gold = ConductorFresnel::GOLD;
    g.bench_function("conductor/gold", |b| {
        b.iter(|| {
            for (o, &c) in ov.iter_mut().zip(&cos) {
                *o = conductor(table::opaque(c), gold.eta, gold.k);
            }
            black_box(&mut ov);
        })
    });
    let f0 = gold.f0();
    g.bench_function("schlick/gold", |b| {
        b.iter(|| {
            for (o, &c) in ov.iter_mut().zip(&cos) {
                *o = schlick(f0, table::opaque(c));
            }
            black_box(&mut ov);
        })
    });
    g.finish();
}

/// The table mode: the Fresnel rows of the C++ comparison, timed as `benches/cpp/analytic.cpp`
/// times pbrt's and Mitsuba's versions (η = 1.5 with cos uniform in [−1, 1); gold with cos uniform
/// in [0, 1)).
fn table_mode() {
    let inp = table::inputs(1.0);
    println!("# inputs hash {:016x}", table::hash(&inp));
    let mut of = vec![0.0f32; table::N];
    let mut ov = vec![Vec3::ZERO; table::N];
    table::time_it("fresnel/dielectric", 1.5, |r| {
        for (o, &c) in of.iter_mut().zip(&inp.cos_signed[r]) {
            *o = dielectric(table::opaque(c), 1.5);
        }
        black_box(&mut of);
    });
    let gold = ConductorFresnel::GOLD;
    table::time_it("fresnel/conductor", 0.0, |r| {
        for (o, &c) in ov.iter_mut().zip(&inp.cos_unit[r]) {
            *o = conductor(table::opaque(c), gold.eta, gold.k);
        }
        black_box(&mut ov);
    });
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

fn main() {
    if std::env::var_os("BRDF_TABLE").is_some() {
        table_mode();
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
