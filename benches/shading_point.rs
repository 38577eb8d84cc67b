//! Cost of a renderer's shading point against the footprint's size, for every glint model at its
//! default build and per-query options and for an analytic GGX material: `Material::bsdf` with a
//! `GlintScratch` (the patch), `eval_pdf` toward two directions and one `sample`, all at one wo.
//! 512² `scratched` map, gold Fresnel; 32 shading points at fixed random uv and directions per
//! iteration (throughput: shading points), the inputs and calls of examples/common/shading_points.rs. The measuring example `shading_cost` charts the same
//! loop with the error of each patch (docs/results.md, "Cost and error of a shading point against
//! footprint").
//!
//! Run: `cargo bench -p brdf-benches --bench shading_point -- --warm-up-time 0.2 --measurement-time 1
//! --sample-size 10`

use brdf::fresnel::ConductorFresnel;
use brdf::glint::{
    BeckmannMixture, BinMap, GlintModel, GlintScratch, PositionNormalMap, ScratchedParams,
    scratched,
};
use brdf::material::{GlintMaterial, Material};
use brdf::ndf::Ggx;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::sync::Arc;

const SIZE: usize = 512;
const POINTS: usize = 32;

#[path = "../examples/common/shading_points.rs"]
mod shading_points;

fn shading_point(c: &mut Criterion) {
    let map = scratched(SIZE, SIZE, ScratchedParams::default(), 7).unwrap();
    let gold = ConductorFresnel::GOLD;
    let glint = |m: GlintModel| -> Material { GlintMaterial::new(Arc::new(m), gold).into() };
    let mixture = BeckmannMixture::build(&map, Default::default()).unwrap();
    let materials = [
        (
            "analytic GGX",
            Material::microfacet(Ggx::isotropic(0.1).unwrap(), gold),
        ),
        ("mixture", glint(mixture.into())),
        (
            "bin map",
            glint(BinMap::build(&map, Default::default()).unwrap().into()),
        ),
        (
            "position-normal",
            glint(
                PositionNormalMap::build(&map, Default::default())
                    .unwrap()
                    .into(),
            ),
        ),
    ];
    let pts = shading_points::points(POINTS, 11);
    let scratch = GlintScratch::default();
    for (name, material) in &materials {
        let mut g = c.benchmark_group(format!("shading_point/{name}"));
        g.throughput(Throughput::Elements(POINTS as u64));
        for area in [1.0f32, 16.0, 256.0, 4096.0, 65536.0] {
            g.bench_with_input(BenchmarkId::from_parameter(area), &area, |b, &area| {
                b.iter(|| {
                    for p in &pts {
                        shading_points::shade(material, p, area, SIZE, &scratch);
                    }
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, shading_point);
criterion_main!(benches);
