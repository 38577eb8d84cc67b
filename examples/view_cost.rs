//! Instructions per shading point (callgrind): Material::bsdf + 2 eval_pdf + 1 sample at one wo.
use brdf::Vec2;
use brdf::bxdf::Bxdf;
use brdf::fresnel::ConductorFresnel;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintScratch, PositionNormalMap,
};
use brdf::material::{GlintMaterial, Material};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::sync::Arc;

fn dir(r: &mut rand_pcg::Pcg64Mcg, max_deg: f32) -> brdf::Vec3 {
    let t = r.random_range(0.0..max_deg).to_radians();
    let p = r.random_range(0.0..std::f32::consts::TAU);
    brdf::Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

#[inline(never)]
fn shade_all(m: &Material, area: f32, n: usize, size: usize, scratch: &GlintScratch) -> f32 {
    let mut r = rand_pcg::Pcg64Mcg::seed_from_u64(11);
    let mut acc = 0.0;
    for _ in 0..n {
        let uv = Vec2::new(r.random(), r.random());
        let fp = Footprint::isotropic_texels(uv, area, size, size);
        let wo = dir(&mut r, 80.0);
        let (w1, w2) = (dir(&mut r, 85.0), dir(&mut r, 85.0));
        let u = Vec2::new(r.random(), r.random());
        let b = m.bsdf(&fp, wo, scratch);
        acc += b.eval_pdf(wo, w1).1 + b.eval_pdf(wo, w2).1;
        if let Some(s) = b.sample(wo, 0.5, u) {
            acc += s.pdf;
        }
    }
    black_box(acc)
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (which, area, n) = (
        a[1].as_str(),
        a[2].parse::<f32>().unwrap(),
        a[3].parse::<usize>().unwrap(),
    );
    let size = 256;
    let map = brdf::glint::scratched(size, size, Default::default(), 3).unwrap();
    let model: GlintModel = match which {
        "mixture" => BeckmannMixture::build(&map, Default::default())
            .unwrap()
            .into(),
        "binmap" => BinMap::build(&map, Default::default()).unwrap().into(),
        "pn" => PositionNormalMap::build(&map, Default::default())
            .unwrap()
            .into(),
        _ => ProceduralGlints::new(ProceduralParams {
            resolution: [size, size],
            ..Default::default()
        })
        .unwrap()
        .into(),
    };
    let m: Material = GlintMaterial::new(Arc::new(model), ConductorFresnel::GOLD).into();
    let scratch = GlintScratch::default();
    println!("{}", shade_all(&m, area, n, size, &scratch));
}
