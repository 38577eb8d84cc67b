//! `Material`: every variant's `Bsdf` is the BRDF it names, value for value (the enum only
//! dispatches), the white furnace holds through it the way a renderer integrates, and bad
//! construction input is an error.

use crate::support;

use brdf::bxdf::{
    Bxdf, LobeFlags, MicrofacetBrdf, NormalMapMicrofacet, NormalMapTilt, ShadingNormal,
};
use brdf::fresnel::{ConductorFresnel, NoFresnel, SchlickFresnel};
use brdf::glint::{Footprint, GlintModel, GlintNdf, GlintScratch};
use brdf::material::{GlintMaterial, Material, NormalMappedMaterial, NormalMapping};
use brdf::ndf::{Beckmann, Ggx};
use brdf::{Lambert, Vec2, Vec3};
use std::sync::Arc;

/// (wo, wi, u) triples over the hemisphere, grazing views included.
fn queries() -> Vec<(Vec3, Vec3, Vec2)> {
    let mut q = Vec::new();
    for (k, t_o) in [0.0, 25.0, 50.0, 70.0, 85.0].into_iter().enumerate() {
        for (j, t_i) in [5.0, 30.0, 60.0, 80.0].into_iter().enumerate() {
            let wo = support::dir(t_o, 17.0 * k as f64);
            let wi = support::dir(t_i, 180.0 + 41.0 * j as f64);
            let u = Vec2::new(0.1 + 0.2 * j as f32, 0.9 - 0.17 * k as f32);
            q.push((wo, wi, u));
        }
    }
    q
}

/// The view the tests' `Bsdf`s are prepared for (`Material::bsdf`): one of the views of
/// [`queries`], so that [`same`] compares the prepared values at it and the values computed per
/// query at every other view.
fn view() -> Vec3 {
    support::dir(50.0, 34.0)
}

/// `a` and `b` agree bit for bit on eval, pdf, eval_pdf and sample at every query.
fn same(a: &impl Bxdf, b: &impl Bxdf, what: &str) {
    for (wo, wi, u) in queries() {
        assert_eq!(a.eval(wo, wi), b.eval(wo, wi), "{what}: eval");
        assert_eq!(a.pdf(wo, wi), b.pdf(wo, wi), "{what}: pdf");
        assert_eq!(a.eval_pdf(wo, wi), b.eval_pdf(wo, wi), "{what}: eval_pdf");
        assert_eq!(a.sample(wo, 0.4, u), b.sample(wo, 0.4, u), "{what}: sample");
    }
}

fn footprint() -> Footprint {
    Footprint::from_differentials(
        Vec2::new(0.31, 0.62),
        Vec2::new(0.02, 0.003),
        Vec2::new(-0.004, 0.015),
    )
}

#[test]
fn analytic_variants_are_their_brdfs() {
    let scratch = GlintScratch::default();
    let fp = footprint();
    let gold = ConductorFresnel::GOLD;
    let ggx = Ggx::new(0.2, 0.35).unwrap();
    let m = Material::microfacet(ggx, gold);
    same(
        &m.bsdf(&fp, view(), &scratch),
        &MicrofacetBrdf::new(ggx, gold),
        "GGX",
    );
    let beckmann = Beckmann::isotropic(0.4).unwrap();
    let m = Material::microfacet(beckmann, gold);
    same(
        &m.bsdf(&fp, view(), &scratch),
        &MicrofacetBrdf::new(beckmann, gold),
        "Beckmann",
    );
    let lambert = Lambert::new(Vec3::new(0.2, 0.5, 0.8)).unwrap();
    same(
        &Material::from(lambert).bsdf(&fp, view(), &scratch),
        &lambert,
        "Lambert",
    );
    let coat = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
    let base = Vec3::new(0.7, 0.2, 0.1);
    let m = Material::layered(ggx, coat, base).unwrap();
    let direct = brdf::LayeredBrdf::new(MicrofacetBrdf::new(ggx, coat), base).unwrap();
    same(&m.bsdf(&fp, view(), &scratch), &direct, "layered");
    let m = Material::microfacet_compensated(ggx, gold).unwrap();
    let direct = brdf::bxdf::EnergyCompensated::new(MicrofacetBrdf::new(ggx, gold)).unwrap();
    same(&m.bsdf(&fp, view(), &scratch), &direct, "compensated");
    let mirror = Material::mirror(gold);
    let direct = brdf::bxdf::SpecularReflection::new(gold);
    same(&mirror.bsdf(&fp, view(), &scratch), &direct, "mirror");
    let s =
        mirror
            .bsdf(&fp, view(), &scratch)
            .sample(support::dir(40.0, 10.0), 0.5, Vec2::splat(0.5));
    assert!(s.is_some_and(|s| s.flags.contains(LobeFlags::SPECULAR)));
}

/// A glint material is `MicrofacetBrdf` over the model's patch at the footprint scaled to the
/// map's uv, with the material's options (or that layer over the base); every registered model.
#[test]
fn glint_variants_are_their_patches() {
    let map = brdf::glint::scratched(64, 64, Default::default(), 9).unwrap();
    let scratch = GlintScratch::default();
    let fp = footprint();
    let scale = Vec2::new(3.0, 2.0);
    let scaled = Footprint::from_differentials(
        fp.center_uv() * scale,
        fp.duv_dx() * scale,
        fp.duv_dy() * scale,
    );
    let silver = ConductorFresnel::SILVER;
    for ex in support::registry::examples(&map) {
        let model = Arc::new(ex.model);
        let material = GlintMaterial::new(model.clone(), silver)
            .with_options(ex.options.clone())
            .with_uv_scale(scale)
            .unwrap();
        let direct = MicrofacetBrdf::new(model.patch_with(&scaled, &ex.options, None), silver);
        same(
            &Material::from(material.clone()).bsdf(&fp, view(), &scratch),
            &direct,
            ex.label,
        );
        let base = Vec3::new(0.4, 0.3, 0.2);
        let coat = Material::from(material.over_base(base).unwrap());
        let layer = MicrofacetBrdf::new(model.patch_with(&scaled, &ex.options, None), silver);
        let direct = brdf::LayeredBrdf::new(layer, base).unwrap();
        same(&coat.bsdf(&fp, view(), &scratch), &direct, ex.label);
    }
    // Without explicit options the material queries with the defaults, as `patch` does.
    let model: Arc<GlintModel> = Arc::new(support::registry::examples(&map).remove(0).model);
    let m = Material::from(GlintMaterial::new(model.clone(), silver));
    same(
        &m.bsdf(&fp, view(), &scratch),
        &MicrofacetBrdf::new(model.patch(&fp), silver),
        "own options",
    );
}

/// A normal-mapped material is the adapter over its base at the map's normal at the footprint's
/// centre (in the map's uv).
#[test]
fn normal_mapped_variants_are_their_adapters() {
    let map = Arc::new(brdf::glint::bumpy(32, 32, 0.4, 3.0, 2).unwrap());
    let scratch = GlintScratch::default();
    let fp = footprint();
    let scale = Vec2::new(2.0, 5.0);
    let ggx = Ggx::isotropic(0.3).unwrap();
    let base = Material::microfacet(ggx, ConductorFresnel::COPPER);
    let direct_base = MicrofacetBrdf::new(ggx, ConductorFresnel::COPPER);
    let n = ShadingNormal::new(map.normal_at(fp.center_uv() * scale), None).unwrap();
    assert!(n.normal().z < 0.999, "the test needs a tilted normal");
    let nm = NormalMappedMaterial::new(map.clone(), base)
        .unwrap()
        .with_uv_scale(scale)
        .unwrap();
    let microfacet = Material::from(nm.clone());
    same(
        &microfacet.bsdf(&fp, view(), &scratch),
        &NormalMapMicrofacet::new(direct_base, n),
        "microfacet mapping",
    );
    let tilt = Material::from(nm.with_mapping(NormalMapping::Tilt));
    same(
        &tilt.bsdf(&fp, view(), &scratch),
        &NormalMapTilt::new(direct_base, n),
        "tilt mapping",
    );
}

/// The white furnace through `Material` the way a renderer integrates: the mean of
/// `sample().weight()` over stratified u is ≤ 1 (+ its noise) for every F = 1 material.
#[test]
fn white_furnace_through_materials() {
    let map = brdf::glint::bumpy(64, 64, 0.3, 4.0, 2).unwrap();
    let model = Arc::new(GlintModel::from(
        brdf::glint::BeckmannMixture::build(&map, Default::default()).unwrap(),
    ));
    let ggx = Ggx::isotropic(0.3).unwrap();
    let materials = [
        Material::microfacet(ggx, NoFresnel),
        Material::microfacet_compensated(Ggx::isotropic(0.9).unwrap(), NoFresnel).unwrap(),
        Material::mirror(NoFresnel),
        GlintMaterial::new(model, NoFresnel).into(),
        NormalMappedMaterial::new(Arc::new(map), Material::microfacet(ggx, NoFresnel))
            .unwrap()
            .into(),
    ];
    let scratch = GlintScratch::default();
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 40.0, 64, 64);
    let n = 64;
    for (k, m) in materials.iter().enumerate() {
        for theta in [0.0, 45.0, 80.0] {
            let wo = support::dir(theta, 20.0);
            let bsdf = m.bsdf(&fp, wo, &scratch);
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for i in 0..n * n {
                let u = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                let w = bsdf
                    .sample(wo, (i as f32 * 0.618).fract(), u)
                    .map_or(0.0, |s| s.weight().x as f64);
                sum += w;
                sum2 += w * w;
            }
            let count = (n * n) as f64;
            let mean = sum / count;
            let se = ((sum2 / count - mean * mean).max(0.0) / count).sqrt();
            assert!(
                mean <= 1.0 + 4.0 * se + 1e-4,
                "material {k} at {theta}°: furnace {mean} ± {se}"
            );
            assert!(mean > 0.2, "material {k} at {theta}°: furnace {mean}");
        }
    }
}

#[test]
fn bad_construction_input_is_an_error() {
    let map = Arc::new(brdf::glint::bumpy(16, 16, 0.2, 3.0, 1).unwrap());
    let model = Arc::new(GlintModel::from(
        brdf::glint::BeckmannMixture::build(&map, Default::default()).unwrap(),
    ));
    let glint = GlintMaterial::new(model, NoFresnel);
    for s in [
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, -2.0),
        Vec2::new(f32::NAN, 1.0),
        Vec2::new(1.0, f32::INFINITY),
    ] {
        let e = glint.clone().with_uv_scale(s).unwrap_err();
        assert!(e.to_string().contains("uv_scale"), "{e}");
    }
    for base in [Vec3::new(1.2, 0.0, 0.0), Vec3::new(0.5, f32::NAN, 0.5)] {
        let e = glint.clone().over_base(base).unwrap_err();
        assert!(e.to_string().contains("base"), "{e}");
    }
    let e = Material::microfacet_compensated(Ggx::new(0.5, 1.5).unwrap(), NoFresnel).unwrap_err();
    assert!(e.to_string().contains("alpha"), "{e}");
    let e = NormalMappedMaterial::new(map.clone(), Material::from(glint)).unwrap_err();
    assert!(e.to_string().contains("base"), "{e}");
    let lambert = Material::from(Lambert::new(Vec3::splat(0.5)).unwrap());
    let nm = NormalMappedMaterial::new(map.clone(), lambert).unwrap();
    let e = NormalMappedMaterial::new(map, Material::from(nm)).unwrap_err();
    assert!(e.to_string().contains("base"), "{e}");
}
