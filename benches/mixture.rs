//! Cost of the Beckmann mixture of \[Chermain2019\]: the build, and per footprint size the patch
//! construction, D_P, the exact and approximate Λ_P and the visible sampler, each per-direction query
//! timed by the lobe blocks (`blocks`: the copy of the block loops the CPU selects at run time, AVX2
//! where it has it; `blocks_baseline`: the same patch forced onto the baseline copy, SSE2 on x86-64)
//! and by the scalar path (`scalar`, one lobe at a time rebuilt from its moments) in the same run. The blocks paths are the patch's `d`, exact `lambda` and
//! `sample_visible` (`lambda_blocks` / `sample_visible_blocks` are the same code, callable by name);
//! `d_scalar`, `lambda_scalar` and `sample_visible_scalar` are the former paths, all `#[doc(hidden)]`.
//!
//! Maps: the four procedural maps (bumpy, brushed, scratched, flakes) at 512², default parameters,
//! built before timing. Footprints: isotropic, 1 to 65 536 texels, the level of detail off (so that
//! every size times the mixture itself). Each `d` iteration evaluates 32 precomputed normals (half
//! drawn from the patch's own D_P cos, half uniform in a 40° cone: where a renderer's half vectors
//! fall), each Λ / sampler iteration 32 cosine-distributed views, so criterion's throughput is the
//! time per call.
//!
//! Run: `cargo bench --bench mixture -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//! (one map: append e.g. `/bumpy`; build times at 2048²:
//! `cargo test --release --test mixture -- --ignored build_2048 --nocapture`).

use brdf::glint::{
    BeckmannMixture, BrushedParams, FlakesParams, Footprint, GlintNdf, MaskingMode, MixtureParams,
    MixturePatch, NormalMap, PatchOptions, ScratchedParams, brushed, bumpy, flakes, scratched,
};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
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

fn params() -> MixtureParams {
    MixtureParams {
        patch: PatchOptions {
            masking: MaskingMode::Exact,
            lod_lobes: f32::INFINITY,
            lod_tolerance: 0.0,
            ..PatchOptions::default()
        },
        ..MixtureParams::default()
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

/// A copy of `patch` forced onto the baseline copy of the block loops (`blocks_baseline`; `blocks`
/// is what the patch runs: AVX2 where the CPU has it). Bit-identical results
/// (tests/mixture_dispatch.rs).
fn baseline<'a>(patch: &MixturePatch<'a>) -> MixturePatch<'a> {
    let mut base = patch.clone();
    base.force_baseline_simd(true);
    base
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
        let mix = BeckmannMixture::build(&map, params()).unwrap();

        let mut g = c.benchmark_group(format!("mixture_patch/{name}"));
        for area in AREAS {
            let f = footprint(area);
            g.bench_with_input(BenchmarkId::from_parameter(area), &f, |b, f| {
                b.iter(|| mix.patch(black_box(f)).lobe_count())
            });
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_d/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let patch = mix.patch(&footprint(area));
            let base = baseline(&patch);
            let m = normals(&patch, 7);
            g.bench_with_input(BenchmarkId::new("blocks", area), &m, |b, m| {
                b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
            });
            g.bench_with_input(BenchmarkId::new("blocks_baseline", area), &m, |b, m| {
                b.iter(|| m.iter().map(|&h| base.d(black_box(h))).sum::<f32>())
            });
            g.bench_with_input(BenchmarkId::new("scalar", area), &m, |b, m| {
                b.iter(|| m.iter().map(|&h| patch.d_scalar(black_box(h))).sum::<f32>())
            });
        }
        g.finish();

        let w = views(3);
        let mut g = c.benchmark_group(format!("mixture_lambda_exact/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let patch = mix.patch(&footprint(area));
            let _ = patch.lambda_scalar(Vec3::Z); // build the scalar path's lazy lobes before timing
            let base = baseline(&patch);
            g.bench_with_input(BenchmarkId::new("blocks", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, _)| patch.lambda_blocks(black_box(v)))
                        .sum::<f32>()
                })
            });
            g.bench_with_input(BenchmarkId::new("blocks_baseline", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, _)| base.lambda_blocks(black_box(v)))
                        .sum::<f32>()
                })
            });
            g.bench_with_input(BenchmarkId::new("scalar", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, _)| patch.lambda_scalar(black_box(v)))
                        .sum::<f32>()
                })
            });
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_sample_visible/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let patch = mix.patch(&footprint(area));
            let _ = patch.lambda_scalar(Vec3::Z);
            let base = baseline(&patch);
            g.bench_with_input(BenchmarkId::new("blocks", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, u)| patch.sample_visible_blocks(black_box(v), u).z)
                        .sum::<f32>()
                })
            });
            g.bench_with_input(BenchmarkId::new("blocks_baseline", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, u)| base.sample_visible_blocks(black_box(v), u).z)
                        .sum::<f32>()
                })
            });
            g.bench_with_input(BenchmarkId::new("scalar", area), &w, |b, w| {
                b.iter(|| {
                    w.iter()
                        .map(|&(v, u)| patch.sample_visible_scalar(black_box(v), u).z)
                        .sum::<f32>()
                })
            });
        }
        g.finish();

        let mut g = c.benchmark_group(format!("mixture_lambda_approximate/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in AREAS {
            let options = PatchOptions {
                masking: MaskingMode::Approximate,
                lod_lobes: f32::INFINITY,
                lod_tolerance: 0.0,
                ..PatchOptions::default()
            };
            let patch = mix.patch_with(&footprint(area), options);
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

/// Issue 15 item 3: the build with the default separable filter against the 256-node QMC build of
/// earlier versions, on the four procedural maps at 512² and 1024² (2048²:
/// `cargo test --lib -- --ignored build_timing_2048 --nocapture`, which alternates the two).
/// Run: `cargo bench --bench mixture -- mixture_build_method --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
fn build_method(c: &mut Criterion) {
    use brdf::glint::{BrushedParams, FlakesParams, MomentMethod, brushed, flakes};
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

/// The levels of detail (issue 15 item 2): `d` and `patch()` of the full mixture (`full`: tolerance 0,
/// no cap) against the default level of detail (`lod`: [`brdf::glint::DEFAULT_LOD_TOLERANCE`] and
/// the default cost cap), alternating per footprint, 256 to 65 536 texels; the same 32 normals
/// (drawn from the full patch) for both.
///
/// `cargo bench --bench mixture -- mixture_lod --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
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
            let m = normals(&mix.patch_with(&f, full), 7);
            for (label, o) in [("full", full), ("lod", lod)] {
                let patch = mix.patch_with(&f, o);
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
                    b.iter(|| mix.patch_with(black_box(f), o).lobe_count())
                });
            }
        }
        g.finish();
    }
}

/// Compact storage (issue 16 item 5): `patch()`, `d`, exact-masking `lambda` and `sample_visible` of full
/// (`full`) against compact storage (`compact`: every block decoded on each visit), alternating
/// per footprint, 256 and 4096 texels, the level of detail off (the full mixture); the same 32
/// normals (drawn from the full patch) and views for both.
///
/// `cargo bench --bench mixture -- mixture_storage --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
fn storage(c: &mut Criterion) {
    use brdf::glint::LobeStorage;
    for (name, map) in maps() {
        let full = BeckmannMixture::build(&map, params()).unwrap();
        let compact = BeckmannMixture::build(
            &map,
            MixtureParams {
                storage: LobeStorage::Compact,
                ..params()
            },
        )
        .unwrap();
        let w = views(3);
        let areas = [256.0f32, 4096.0];
        let mut g = c.benchmark_group(format!("mixture_storage_patch/{name}"));
        for area in areas {
            let f = footprint(area);
            for (label, mix) in [("full", &full), ("compact", &compact)] {
                g.bench_with_input(BenchmarkId::new(label, area), &f, |b, f| {
                    b.iter(|| mix.patch(black_box(f)).lobe_count())
                });
            }
        }
        g.finish();
        let mut g = c.benchmark_group(format!("mixture_storage_d/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in areas {
            let m = normals(&full.patch(&footprint(area)), 7);
            for (label, mix) in [("full", &full), ("compact", &compact)] {
                let patch = mix.patch(&footprint(area));
                g.bench_with_input(BenchmarkId::new(label, area), &m, |b, m| {
                    b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
                });
            }
        }
        g.finish();
        let mut g = c.benchmark_group(format!("mixture_storage_lambda/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in areas {
            for (label, mix) in [("full", &full), ("compact", &compact)] {
                let patch = mix.patch(&footprint(area));
                g.bench_with_input(BenchmarkId::new(label, area), &w, |b, w| {
                    b.iter(|| {
                        w.iter()
                            .map(|&(v, _)| patch.lambda(black_box(v)))
                            .sum::<f32>()
                    })
                });
            }
        }
        g.finish();
        let mut g = c.benchmark_group(format!("mixture_storage_sample_visible/{name}"));
        g.throughput(Throughput::Elements(BATCH as u64));
        for area in areas {
            for (label, mix) in [("full", &full), ("compact", &compact)] {
                let patch = mix.patch(&footprint(area));
                g.bench_with_input(BenchmarkId::new(label, area), &w, |b, w| {
                    b.iter(|| {
                        w.iter()
                            .map(|&(v, u)| patch.sample_visible(black_box(v), u).z)
                            .sum::<f32>()
                    })
                });
            }
        }
        g.finish();
    }
}

criterion_group!(benches, build, queries, build_method, lod, storage);
criterion_main!(benches);
