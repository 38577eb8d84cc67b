//! Cost of the Beckmann mixture of \[Chermain2019\]: the build, and per footprint size, in full and
//! compact storage (`full` and `compact` ids of each group), the patch construction, D_P, the exact
//! Λ_P, the visible sampler and the P-BRDF's `eval_pdf`, and the approximate Λ_P (full storage).
//!
//! What is timed is the patch's public queries, i.e. the lobe-block kernels, in the copy of the block
//! loops the CPU selects at run time (AVX2 where it has it). `BRDF_SIMD=baseline` in the environment
//! forces the baseline copy (SSE2 on x86-64) for a whole run: run the same command twice to compare
//! the two copies (their results are bit-identical, tested in the library). The library holds no
//! scalar reference path to time against.
//!
//! Maps: the four procedural maps (bumpy, brushed, scratched, flakes) at 512², default parameters
//! with the level of detail off (so that every size times the mixture itself), built before timing.
//! Footprints: isotropic, 1 to 65 536 texels. Each `d` iteration evaluates 32 precomputed normals
//! (half drawn from the full patch's D_P cos, half uniform in a 40° cone: where a renderer's half
//! vectors fall), each Λ / sampler iteration 32 cosine-distributed views, each `eval_pdf` iteration
//! 32 (wo, wi) pairs (half reflected about the full patch's visible samples, half cosine-distributed),
//! the same inputs for both storages, so criterion's throughput is the time per call.
//!
//! Run: `cargo bench -p brdf-benches --bench mixture -- --warm-up-time 0.5 --measurement-time 2 --sample-size 10`
//! (the queries only: append `'^mixture_(patch|d|lambda_exact|sample_visible|eval_pdf)/'`; one map:
//! e.g. `/bumpy/`; build times at 2048²:
//! `cargo test --release --test it -- --ignored mixture::build_2048 --nocapture`).

use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::{LobeStorage, MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::{
    BeckmannMixture, BrushedParams, FlakesParams, Footprint, GlintNdf, NormalMap, ScratchedParams,
    brushed, bumpy, flakes, scratched,
};
use brdf::ndf::Ndf;
use brdf::{Bxdf, MicrofacetBrdf, Vec2, Vec3};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const SIZE: usize = 512;
const AREAS: [f32; 6] = [1.0, 16.0, 256.0, 4096.0, 16384.0, 65536.0];
const BATCH: usize = 32;

/// The four procedural maps with the parameters and seeds of the tests and the gallery.
fn maps() -> Vec<(&'static str, NormalMap)> {
    vec![
        ("bumpy", bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap()),
        (
            "brushed",
            brushed(SIZE, SIZE, BrushedParams::default(), 2).unwrap(),
        ),
        (
            "scratched",
            scratched(SIZE, SIZE, ScratchedParams::default(), 3).unwrap(),
        ),
        (
            "flakes",
            flakes(SIZE, SIZE, FlakesParams::default(), 4).unwrap(),
        ),
    ]
}

/// Default build parameters in the given storage.
fn params(storage: LobeStorage) -> MixtureParams {
    MixtureParams {
        storage,
        ..MixtureParams::default()
    }
}

/// Exact masking, the level of detail off: the patch options of every bench but the level-of-detail
/// ones.
fn exact() -> PatchOptions {
    PatchOptions {
        masking: MaskingMode::Exact,
        lod_lobes: f32::INFINITY,
        lod_tolerance: 0.0,
        ..PatchOptions::default()
    }
}

fn footprint(area: f32) -> Footprint {
    Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, SIZE, SIZE)
}

/// Half the normals from the patch's D_P cos, half uniform in a 40° cone about the pole.
fn normals(patch: &impl Ndf, seed: u64) -> Vec<Vec3> {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    (0..BATCH)
        .map(|k| {
            let u = Vec2::new(rng.random(), rng.random());
            if k % 2 == 0 {
                patch.sample_normal(u)
            } else {
                let c = 1.0 - u.x * (1.0 - 40f32.to_radians().cos());
                let s = (1.0 - c * c).max(0.0).sqrt();
                let p = std::f32::consts::TAU * u.y;
                Vec3::new(s * p.cos(), s * p.sin(), c)
            }
        })
        .collect()
}

/// View directions (and random pairs) for Λ and the sampler: cosine-distributed views.
fn views(seed: u64) -> Vec<(Vec3, Vec2)> {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    (0..BATCH)
        .map(|_| {
            let (a, b): (f32, f32) = (rng.random(), rng.random());
            let r = a.sqrt();
            let p = std::f32::consts::TAU * b;
            let w = Vec3::new(r * p.cos(), r * p.sin(), (1.0 - a).max(1e-6).sqrt());
            (w, Vec2::new(rng.random(), rng.random()))
        })
        .collect()
}

/// (wo, wi) pairs for `eval_pdf`: wo cosine-distributed; wi reflected about the patch's visible
/// sample (even k: where the P-BRDF is large) or cosine-distributed (odd k).
fn pairs(patch: &impl Ndf) -> Vec<(Vec3, Vec3)> {
    let (wo, wi) = (views(3), views(5));
    (0..BATCH)
        .map(|k| {
            let (o, u) = wo[k];
            if k % 2 == 0 {
                let m = patch.sample_visible(o, u);
                (o, 2.0 * o.dot(m) * m - o)
            } else {
                (o, wi[k].0)
            }
        })
        .collect()
}

/// The two storages of one map, built with [`params`].
fn both_storages(map: &NormalMap) -> [(&'static str, BeckmannMixture); 2] {
    [LobeStorage::Full, LobeStorage::Compact].map(|s| {
        let label = match s {
            LobeStorage::Full => "full",
            LobeStorage::Compact => "compact",
        };
        (label, BeckmannMixture::build(map, params(s)).unwrap())
    })
}

fn build(c: &mut Criterion) {
    let map = bumpy(256, 256, 0.25, 4.0, 1).unwrap();
    let mut g = c.benchmark_group("mixture_build_256");
    g.sample_size(10);
    g.throughput(Throughput::Elements(256 * 256));
    g.bench_function("bumpy", |b| {
        b.iter(|| BeckmannMixture::build(black_box(&map), MixtureParams::default()).unwrap())
    });
    g.finish();
}

fn queries(c: &mut Criterion) {
    for (name, map) in maps() {
        let mixes = both_storages(&map);
        let full = &mixes[0].1;

        let mut g = c.benchmark_group(format!("mixture_patch/{name}"));
        for area in AREAS {
            let f = footprint(area);
            for (label, mix) in &mixes {
                g.bench_with_input(BenchmarkId::new(*label, area), &f, |b, f| {
                    b.iter(|| mix.patch_with(black_box(f), &exact(), None).lobe_count())
                });
            }
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_d/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let m = normals(&full.patch_with(&footprint(area), &exact(), None), 7);
            for (label, mix) in &mixes {
                let patch = mix.patch_with(&footprint(area), &exact(), None);
                g.bench_with_input(BenchmarkId::new(*label, area), &m, |b, m| {
                    b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
                });
            }
        }
        g.finish();

        let w = views(3);
        let mut g = c.benchmark_group(format!("mixture_lambda_exact/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            for (label, mix) in &mixes {
                let patch = mix.patch_with(&footprint(area), &exact(), None);
                g.bench_with_input(BenchmarkId::new(*label, area), &w, |b, w| {
                    b.iter(|| {
                        w.iter()
                            .map(|&(v, _)| patch.lambda(black_box(v)))
                            .sum::<f32>()
                    })
                });
            }
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_sample_visible/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            for (label, mix) in &mixes {
                let patch = mix.patch_with(&footprint(area), &exact(), None);
                g.bench_with_input(BenchmarkId::new(*label, area), &w, |b, w| {
                    b.iter(|| {
                        w.iter()
                            .map(|&(v, u)| patch.sample_visible(black_box(v), u).z)
                            .sum::<f32>()
                    })
                });
            }
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_eval_pdf/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let io = pairs(&full.patch_with(&footprint(area), &exact(), None));
            for (label, mix) in &mixes {
                let brdf = MicrofacetBrdf::new(
                    mix.patch_with(&footprint(area), &exact(), None),
                    NoFresnel,
                );
                g.bench_with_input(BenchmarkId::new(*label, area), &io, |b, io| {
                    b.iter(|| {
                        io.iter()
                            .map(|&(o, i)| {
                                let (f, p) = brdf.eval_pdf(black_box(o), i);
                                f.x + p
                            })
                            .sum::<f32>()
                    })
                });
            }
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_lambda_approximate/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let options = PatchOptions {
                masking: MaskingMode::Approximate,
                ..exact()
            };
            let patch = full.patch_with(&footprint(area), &options, None);
            g.bench_with_input(BenchmarkId::from_parameter(area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, _)| patch.lambda(black_box(v)))
                        .sum::<f32>()
                })
            });
        }
        g.finish();
    }
}

/// The build with the default separable filter against the 256-node QMC build
/// ([`brdf::glint::mixture::MomentMethod::Qmc`]), on the four procedural maps at 512² and 1024² (2048²:
/// `cargo test --lib -- --ignored build_timing_2048 --nocapture`, which alternates the two).
/// Run: `cargo bench -p brdf-benches --bench mixture -- mixture_build_method --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
fn build_method(c: &mut Criterion) {
    use brdf::glint::mixture::MomentMethod;
    for n in [512usize, 1024] {
        let maps = [
            ("bumpy", bumpy(n, n, 0.25, 4.0, 1).unwrap()),
            (
                "brushed",
                brushed(n, n, BrushedParams::default(), 2).unwrap(),
            ),
            (
                "scratched",
                scratched(n, n, ScratchedParams::default(), 3).unwrap(),
            ),
            ("flakes", flakes(n, n, FlakesParams::default(), 4).unwrap()),
        ];
        let mut g = c.benchmark_group(format!("mixture_build_method/{n}"));
        g.sample_size(10);
        g.throughput(Throughput::Elements((n * n) as u64));
        for (name, map) in &maps {
            for (label, moments) in [
                ("filter", MomentMethod::default()),
                ("qmc256", MomentMethod::Qmc),
            ] {
                let p = MixtureParams {
                    moments,
                    ..MixtureParams::default()
                };
                g.bench_function(BenchmarkId::new(label, name), |b| {
                    b.iter(|| BeckmannMixture::build(black_box(map), p).unwrap())
                });
            }
        }
        g.finish();
    }
}

/// The levels of detail: `d` and `patch()` of the full mixture (`full`: tolerance 0,
/// no cap) against the default level of detail (`lod`: [`brdf::glint::mixture::DEFAULT_LOD_TOLERANCE`] and
/// the default cost cap), alternating per footprint, 256 to 65 536 texels; the same 32 normals
/// (drawn from the full patch) for both.
///
/// `cargo bench -p brdf-benches --bench mixture -- mixture_lod --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
fn lod(c: &mut Criterion) {
    let full = PatchOptions {
        masking: MaskingMode::Exact,
        lod_lobes: f32::INFINITY,
        lod_tolerance: 0.0,
        ..PatchOptions::default()
    };
    let lod = PatchOptions::default();
    for (name, map) in maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        let mut g = c.benchmark_group(format!("mixture_lod_d/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in [256.0f32, 1024.0, 4096.0, 16384.0, 65536.0] {
            let f = footprint(area);
            let m = normals(&mix.patch_with(&f, &full, None), 7);
            for (label, o) in [("full", full), ("lod", lod)] {
                let patch = mix.patch_with(&f, &o, None);
                g.bench_with_input(BenchmarkId::new(label, area), &m, |b, m| {
                    b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
                });
            }
        }
        g.finish();
        let mut g = c.benchmark_group(format!("mixture_lod_patch/{name}"));
        for area in [256.0f32, 4096.0, 65536.0] {
            let f = footprint(area);
            for (label, o) in [("full", full), ("lod", lod)] {
                g.bench_with_input(BenchmarkId::new(label, area), &f, |b, f| {
                    b.iter(|| mix.patch_with(black_box(f), &o, None).lobe_count())
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, build, queries, build_method, lod);
criterion_main!(benches);
