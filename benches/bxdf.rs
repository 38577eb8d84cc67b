//! The classic BRDFs: time of `eval`, `pdf` and `sample` per call, on 1024 inputs generated before
//! timing (wo, wi uniform on the hemisphere; uc, u uniform).
//!
//! Run: `cargo bench -p brdf-benches --bench bxdf -- --warm-up-time 0.2 --measurement-time 0.5 --sample-size 10`
//! (the figures in docs/results.md, section "Classic BRDFs", come from this command).

use brdf::bxdf::{
    BlinnPhongLobe, BlinnPhongNormalization, Bxdf, Lambert, Masking, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, Phong, PhongNormalization, Sampling,
};
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, SlopeGaussian};
use brdf::warp::square_to_uniform_hemisphere;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Mat2, Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;

const N: usize = 1024;

struct Inputs {
    wo: Vec<Vec3>,
    wi: Vec<Vec3>,
    uc: Vec<f32>,
    u: Vec<Vec2>,
}

fn inputs() -> Inputs {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
    let mut dir = || square_to_uniform_hemisphere(Vec2::new(rng.random(), rng.random()));
    let wo: Vec<Vec3> = (0..N).map(|_| dir()).collect();
    let wi: Vec<Vec3> = (0..N).map(|_| dir()).collect();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(4);
    let uc = (0..N).map(|_| rng.random()).collect();
    let u = (0..N)
        .map(|_| Vec2::new(rng.random(), rng.random()))
        .collect();
    Inputs { wo, wi, uc, u }
}

fn models() -> Vec<(&'static str, Box<dyn Bxdf>)> {
    let (d, s, one) = (Vec3::splat(0.3), Vec3::splat(0.6), Vec3::ONE);
    let schlick = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    let tilted = SlopeGaussian::new(
        Vec2::new(0.3, -0.2),
        Mat2::from_cols_array(&[0.04, 0.015, 0.015, 0.02]),
    )
    .unwrap();
    let pn = |n| Phong::new(d, s, 20.0, n).unwrap();
    vec![
        ("lambert", Box::new(Lambert::new(one).unwrap())),
        (
            "phong/lafortune",
            Box::new(pn(PhongNormalization::EnergyConserving)),
        ),
        (
            "phong/arvo",
            Box::new(pn(PhongNormalization::EnergyNormalizedArvo)),
        ),
        (
            "phong/mallett_yuksel",
            Box::new(pn(PhongNormalization::EnergyNormalizedMallettYuksel)),
        ),
        (
            "phong/mallett_yuksel+schlick",
            Box::new(pn(PhongNormalization::EnergyNormalizedMallettYuksel).with_schlick_fresnel()),
        ),
        (
            "phong/original",
            Box::new(
                OriginalPhong::new(d, s, 20.0, OriginalPhongNormalization::EnergyConserving)
                    .unwrap(),
            ),
        ),
        (
            "blinn_phong_lobe",
            Box::new(
                BlinnPhongLobe::new(d, s, 80.0, BlinnPhongNormalization::EnergyConserving).unwrap(),
            ),
        ),
        (
            "microfacet/beckmann",
            Box::new(MicrofacetBrdf::new(
                Beckmann::isotropic(0.3).unwrap(),
                schlick,
            )),
        ),
        (
            "microfacet/beckmann/separable",
            Box::new(
                MicrofacetBrdf::new(Beckmann::isotropic(0.3).unwrap(), schlick)
                    .with_masking(Masking::Separable),
            ),
        ),
        (
            "microfacet/beckmann/normals",
            Box::new(
                MicrofacetBrdf::new(Beckmann::isotropic(0.3).unwrap(), schlick)
                    .with_sampling(Sampling::Normals),
            ),
        ),
        (
            "microfacet/ggx",
            Box::new(MicrofacetBrdf::new(Ggx::isotropic(0.3).unwrap(), schlick)),
        ),
        (
            "microfacet/ggx_aniso",
            Box::new(MicrofacetBrdf::new(Ggx::new(0.2, 0.5).unwrap(), schlick)),
        ),
        (
            "microfacet/ggx/normals",
            Box::new(
                MicrofacetBrdf::new(Ggx::isotropic(0.3).unwrap(), schlick)
                    .with_sampling(Sampling::Normals),
            ),
        ),
        (
            "microfacet/blinn_phong_ndf",
            Box::new(MicrofacetBrdf::new(BlinnPhong::new(20.0).unwrap(), schlick)),
        ),
        (
            "microfacet/slope_gaussian",
            Box::new(MicrofacetBrdf::new(tilted, NoFresnel)),
        ),
    ]
}

fn bxdf(c: &mut Criterion) {
    let x = inputs();
    let mut g = c.benchmark_group("bxdf");
    g.throughput(Throughput::Elements(N as u64));
    for (name, b) in models() {
        g.bench_function(BenchmarkId::new("eval", name), |bench| {
            bench.iter(|| {
                x.wo.iter()
                    .zip(&x.wi)
                    .map(|(&wo, &wi)| b.eval(black_box(wo), black_box(wi)))
                    .sum::<Vec3>()
            })
        });
        g.bench_function(BenchmarkId::new("pdf", name), |bench| {
            bench.iter(|| {
                x.wo.iter()
                    .zip(&x.wi)
                    .map(|(&wo, &wi)| b.pdf(black_box(wo), black_box(wi)))
                    .sum::<f32>()
            })
        });
        g.bench_function(BenchmarkId::new("sample", name), |bench| {
            bench.iter(|| {
                x.wo.iter()
                    .zip(&x.uc)
                    .zip(&x.u)
                    .filter_map(|((&wo, &uc), &u)| b.sample(black_box(wo), uc, u))
                    .map(|s| s.pdf)
                    .sum::<f32>()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bxdf);
criterion_main!(benches);
