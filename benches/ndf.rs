//! Per-call cost of the analytic NDFs: D, G1 and the visible-normal samplers.
//!
//! Each iteration evaluates a batch of 1024 precomputed inputs (directions from a seeded RNG,
//! cosine-distributed so that grazing angles appear as often as in a renderer), and criterion's
//! `Throughput::Elements(1024)` reports the time per call. Every input component passes through `black_box` (`table::bb3`)
//! and every result is stored to an output buffer (itself passed to `black_box`), so the figure is
//! the throughput of independent calls, as in a renderer's loop over pixels, not the latency of a
//! chain of additions into one accumulator (which capped the cheapest functions at one `f32` add
//! latency per call before 2026-11).
//!
//! `cargo bench -p brdf-benches --bench ndf -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//!
//! Table mode (the crate's column of the C++ comparison in docs/results.md,
//! "Analytic NDFs: speed against pbrt-v4 and Mitsuba 3"):
//! `BRDF_TABLE=1 cargo bench -p brdf-benches --bench ndf` prints, for α ∈ {0.1, 0.5, 1}, the minimum and median
//! ns per call over 5 × 1000 batches of 1024 calls on the inputs of `benches/cpp/analytic.cpp`
//! (see benches/cpp/README.md; `benches/cpp/run.sh` runs both sides alternately).

use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, shininess_from_beckmann_alpha};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group};
use glam::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

#[path = "cpp/table_common.rs"]
mod table;

const BATCH: usize = 1024;
const ALPHAS: [f32; 4] = [0.05, 0.125, 0.5, 1.0];

struct Inputs {
    /// Cosine-distributed directions (the wo of a renderer's camera rays).
    w: Vec<Vec3>,
    /// Normals near the lobe (half vectors of the pairs), for D.
    m: Vec<Vec3>,
    u: Vec<Vec2>,
}

fn inputs(alpha: f32) -> Inputs {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
    let mut cosine = || {
        let (a, b): (f32, f32) = (rng.random(), rng.random());
        let r = a.sqrt();
        let phi = std::f32::consts::TAU * b;
        Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - a).max(1e-6).sqrt())
    };
    let w: Vec<Vec3> = (0..BATCH).map(|_| cosine()).collect();
    let m: Vec<Vec3> = w
        .iter()
        .map(|v| Vec3::new(alpha * v.x, alpha * v.y, v.z).normalize())
        .collect();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(2);
    let u = (0..BATCH)
        .map(|_| Vec2::new(rng.random(), rng.random()))
        .collect();
    Inputs { w, m, u }
}

fn bench_ndf<N: Ndf>(c: &mut Criterion, family: &str, make: impl Fn(f32) -> N) {
    let mut d = c.benchmark_group(format!("{family}/d"));
    d.throughput(Throughput::Elements(BATCH as u64));
    for &a in &ALPHAS {
        let (ndf, inp) = (make(a), inputs(a));
        d.bench_with_input(BenchmarkId::from_parameter(a), &inp, |b, inp| {
            let mut out = vec![0.0f32; BATCH];
            b.iter(|| {
                for (o, &m) in out.iter_mut().zip(&inp.m) {
                    *o = ndf.d(table::bb3(m));
                }
                black_box(&mut out);
            })
        });
    }
    d.finish();

    let mut g = c.benchmark_group(format!("{family}/g1"));
    g.throughput(Throughput::Elements(BATCH as u64));
    for &a in &ALPHAS {
        let (ndf, inp) = (make(a), inputs(a));
        g.bench_with_input(BenchmarkId::from_parameter(a), &inp, |b, inp| {
            let mut out = vec![0.0f32; BATCH];
            b.iter(|| {
                for (o, (&w, &m)) in out.iter_mut().zip(inp.w.iter().zip(&inp.m)) {
                    *o = ndf.g1(table::bb3(w), table::bb3(m));
                }
                black_box(&mut out);
            })
        });
    }
    g.finish();

    let mut p = c.benchmark_group(format!("{family}/pdf_visible"));
    p.throughput(Throughput::Elements(BATCH as u64));
    for &a in &ALPHAS {
        let (ndf, inp) = (make(a), inputs(a));
        p.bench_with_input(BenchmarkId::from_parameter(a), &inp, |b, inp| {
            let mut out = vec![0.0f32; BATCH];
            b.iter(|| {
                for (o, (&w, &m)) in out.iter_mut().zip(inp.w.iter().zip(&inp.m)) {
                    *o = ndf.pdf_visible(table::bb3(w), table::bb3(m));
                }
                black_box(&mut out);
            })
        });
    }
    p.finish();

    let mut v = c.benchmark_group(format!("{family}/sample_visible"));
    v.throughput(Throughput::Elements(BATCH as u64));
    for &a in &ALPHAS {
        let (ndf, inp) = (make(a), inputs(a));
        v.bench_with_input(BenchmarkId::from_parameter(a), &inp, |b, inp| {
            let mut out = vec![Vec3::ZERO; BATCH];
            b.iter(|| {
                for (o, (&w, &u)) in out.iter_mut().zip(inp.w.iter().zip(&inp.u)) {
                    *o = ndf.sample_visible(table::bb3(w), table::bb2(u));
                }
                black_box(&mut out);
            })
        });
    }
    v.finish();
}

fn benches(c: &mut Criterion) {
    bench_ndf(c, "ggx", |a| Ggx::isotropic(a).unwrap());
    bench_ndf(c, "beckmann", |a| Beckmann::isotropic(a).unwrap());
    bench_ndf(c, "blinn_phong", |a| {
        BlinnPhong::new(shininess_from_beckmann_alpha(a)).unwrap()
    });
}

/// The table mode: GGX and Beckmann D, G1, pdf_visible, sample_visible, timed as the C++ harness
/// times pbrt's and Mitsuba's versions.
fn table_rows<N: Ndf>(family: &str, alpha: f32, ndf: &N) {
    let inp = table::inputs(alpha);
    let (w, m, u) = (&inp.w, &inp.m, &inp.u);
    let mut of = vec![0.0f32; table::N];
    let mut ov = vec![Vec3::ZERO; table::N];
    table::time_it(&format!("{family}/d"), alpha, |r| {
        for (o, &m) in of.iter_mut().zip(&m[r]) {
            *o = ndf.d(table::bb3(m));
        }
        black_box(&mut of);
    });
    table::time_it(&format!("{family}/g1"), alpha, |r| {
        for (o, (&w, &m)) in of.iter_mut().zip(w[r.clone()].iter().zip(&m[r])) {
            *o = ndf.g1(table::bb3(w), table::bb3(m));
        }
        black_box(&mut of);
    });
    table::time_it(&format!("{family}/pdf_visible"), alpha, |r| {
        for (o, (&w, &m)) in of.iter_mut().zip(w[r.clone()].iter().zip(&m[r])) {
            *o = ndf.pdf_visible(table::bb3(w), table::bb3(m));
        }
        black_box(&mut of);
    });
    table::time_it(&format!("{family}/sample_visible"), alpha, |r| {
        for (o, (&w, &u)) in ov.iter_mut().zip(w[r.clone()].iter().zip(&u[r])) {
            *o = ndf.sample_visible(table::bb3(w), table::bb2(u));
        }
        black_box(&mut ov);
    });
}

fn table_mode() {
    println!("# function               variant  alpha   min_ns  median_ns");
    for alpha in [0.1f32, 0.5, 1.0] {
        println!("# inputs hash {:016x}", table::hash(&table::inputs(alpha)));
        table_rows("ggx", alpha, &Ggx::isotropic(alpha).unwrap());
        table_rows("beckmann", alpha, &Beckmann::isotropic(alpha).unwrap());
    }
}

criterion_group!(ndf, benches);

fn main() {
    if std::env::var_os("BRDF_TABLE").is_some() {
        table_mode();
        return;
    }
    ndf();
    Criterion::default().configure_from_args().final_summary();
}
