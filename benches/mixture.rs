//! Cost of the Beckmann mixture of \[Chermain2019\]: the build, and per footprint size the patch
//! construction, D_P, and the exact and approximate Λ_P.
//!
//! Maps: the procedural bumpy (RMS slope 0.25, correlation 4 texels) and scratched maps at 512², built
//! before timing. Footprints: isotropic, 1 to 16 384 texels, the level of detail off (so that every
//! size times the mixture itself) plus one row with the default level of detail. Each `d` iteration
//! evaluates 256 precomputed normals (half drawn from the patch's own D_P cos, half uniform in a 40°
//! cone: where a renderer's half vectors fall), so criterion's throughput is the time per call.
//!
//! Run: `cargo bench --bench mixture -- --warm-up-time 0.5 --measurement-time 2`
//! (build times at 2048²: `cargo test --release --test mixture -- --ignored build_2048 --nocapture`).

use brdf::glint::{
    BeckmannMixture, Footprint, GlintNdf, MaskingMode, MixtureParams, NormalMap, PatchOptions,
    ScratchedParams, bumpy, scratched,
};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const SIZE: usize = 512;
const AREAS: [f32; 5] = [1.0, 16.0, 256.0, 4096.0, 16384.0];
const BATCH: usize = 256;

fn maps() -> Vec<(&'static str, NormalMap)> {
    vec![
        ("bumpy", bumpy(SIZE, SIZE, 0.25, 4.0, 1).unwrap()),
        (
            "scratched",
            scratched(SIZE, SIZE, ScratchedParams::default(), 1).unwrap(),
        ),
    ]
}

fn params(lod_lobes: f32) -> MixtureParams {
    MixtureParams {
        patch: PatchOptions {
            masking: MaskingMode::Exact,
            lod_lobes,
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

/// View directions for Λ: cosine-distributed.
fn views(seed: u64) -> Vec<Vec3> {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    (0..BATCH)
        .map(|_| {
            let (a, b): (f32, f32) = (rng.random(), rng.random());
            let r = a.sqrt();
            let p = std::f32::consts::TAU * b;
            Vec3::new(r * p.cos(), r * p.sin(), (1.0 - a).max(1e-6).sqrt())
        })
        .collect()
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
        let mix = BeckmannMixture::build(&map, params(f32::INFINITY)).unwrap();
        let mix_lod = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();

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
            let m = normals(&patch, 7);
            g.bench_with_input(BenchmarkId::from_parameter(area), &m, |b, m| {
                b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
            });
        }
        let patch = mix_lod.patch(&footprint(16384.0));
        let m = normals(&patch, 7);
        g.bench_with_input(BenchmarkId::new("default_lod", 16384), &m, |b, m| {
            b.iter(|| m.iter().map(|&h| patch.d(black_box(h))).sum::<f32>())
        });
        g.finish();

        for (mode, label) in [
            (MaskingMode::Exact, "exact"),
            (MaskingMode::Approximate, "approximate"),
        ] {
            let mut g = c.benchmark_group(format!("mixture_lambda_{label}/{name}"));
            g.throughput(Throughput::Elements(BATCH as u64));
            let w = views(3);
            for area in AREAS {
                let options = PatchOptions {
                    masking: mode,
                    lod_lobes: f32::INFINITY,
                };
                let patch = mix.patch_with(&footprint(area), options);
                let _ = patch.lambda(Vec3::Z); // build the lazily gathered lobes before timing
                g.bench_with_input(BenchmarkId::from_parameter(area), &w, |b, w| {
                    b.iter(|| w.iter().map(|&v| patch.lambda(black_box(v))).sum::<f32>())
                });
            }
            g.finish();
        }
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

criterion_group!(benches, build, queries, build_method);
criterion_main!(benches);
