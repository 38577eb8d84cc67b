//! No heap allocation per shading point: after a warm-up, `patch_in` + `eval` + `sample` + `pdf` of
//! `MicrofacetBrdf` over every glint model allocate nothing. A counting global allocator (this test
//! binary's own) counts the allocations made on the test's thread.

#[path = "it/support/mod.rs"]
mod support;

use brdf::bxdf::{Bxdf, MicrofacetBrdf};
use brdf::fresnel::SchlickFresnel;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{Footprint, GlintModel, GlintNdf, GlintOptions, GlintScratch, PositionNormalMap};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards every call to the system allocator unchanged; only counts (a `const`
// thread-local, which never allocates, so only this thread's allocations are seen).
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

/// One shading point as a renderer does it: patch, BRDF, a few samples, evaluations and pdfs.
fn shade(
    model: &GlintModel,
    options: &GlintOptions,
    scratch: &GlintScratch,
    fp: &Footprint,
    k: usize,
) -> f32 {
    let fresnel = SchlickFresnel::new(Vec3::splat(0.9)).unwrap();
    let brdf = MicrofacetBrdf::new(model.patch_with(fp, options, Some(scratch)), fresnel);
    let wo = support::dir(10.0 + 7.0 * (k % 11) as f64, 37.0 * k as f64);
    let mut acc = 0.0;
    for j in 0..4 {
        let u = Vec2::new((j as f32 + 0.5) / 4.0, ((k + j) % 7) as f32 / 7.0 + 0.05);
        if let Some(s) = brdf.sample(wo, 0.5, u) {
            acc += s.weight().x;
        }
        let wi = support::dir(20.0 + 10.0 * j as f64, 180.0 + 37.0 * k as f64);
        let (f, pdf) = brdf.eval_pdf(wo, wi);
        acc += f.x + pdf + brdf.pdf(wo, wi);
        // Every `Ndf` call of the patch itself.
        let ndf = brdf.ndf();
        let (h, m) = (ndf.sample_visible(wo, u), ndf.sample_normal(u));
        acc += ndf.d(h) + ndf.d(m) + ndf.pdf_visible(wo, h) + ndf.pdf_normal(m);
        acc += ndf.lambda(wi).min(1e3) + ndf.projected_area(wi) + ndf.visible_area(wi);
        acc += ndf.g1(wo, h) + ndf.g2(wo, wi, h) + ndf.g2_height_correlated(wo, wi, h);
    }
    acc
}

#[test]
fn shading_allocates_nothing_after_warm_up() {
    let map = brdf::glint::flakes(64, 64, Default::default(), 3).unwrap();
    // Every registered model, each storage, masking mode and smoothing (tests/it/support/registry.rs).
    let examples = support::registry::examples(&map);
    let footprints: Vec<Footprint> = [0.3f32, 4.0, 50.0, 700.0, 3000.0]
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            let c = Vec2::new(0.13 + 0.17 * k as f32, 0.71 - 0.11 * k as f32);
            Footprint::isotropic_texels(c, a, 64, 64)
        })
        .collect();
    for ex in &examples {
        let (model, options) = (&ex.model, &ex.options);
        let scratch = GlintScratch::default();
        // Warm-up: every footprint once grows every buffer to its size. (The largest footprint
        // alone is not enough under a coarse level of detail: it gathers few merged nodes, while a
        // smaller footprint below the cost cap gathers more lobes of level 0.)
        let mut sink = 0.0;
        for (k, fp) in footprints.iter().enumerate().rev() {
            sink += shade(model, options, &scratch, fp, k);
        }
        let before = allocations();
        for k in 0..40 {
            let fp = &footprints[k % footprints.len()];
            sink += shade(model, options, &scratch, fp, k);
        }
        let n = allocations() - before;
        assert!(sink.is_finite());
        assert_eq!(n, 0, "{}: {n} allocations in 40 shading points", ex.label);
    }
}

/// A renderer's path through `Material`: three live BSDFs of one scratch at once (a path's
/// vertices), every kind of material (analytic, layered, mirror, normal-mapped, each registered
/// glint model alone and over a base), evaluated and sampled while the others are alive; nothing allocates once the
/// scratch has grown to the largest footprint and the most live patches.
#[test]
fn materials_with_several_live_bsdfs_allocate_nothing() {
    use brdf::fresnel::ConductorFresnel;
    use brdf::material::{GlintMaterial, Material};
    use brdf::ndf::{Beckmann, Ggx};
    use std::sync::Arc;

    let map = brdf::glint::scratched(64, 64, Default::default(), 4).unwrap();
    let mut materials = vec![
        Material::from(brdf::Lambert::new(Vec3::splat(0.5)).unwrap()),
        Material::microfacet(Ggx::isotropic(0.3).unwrap(), ConductorFresnel::GOLD),
        Material::layered(
            Beckmann::new(0.2, 0.4).unwrap(),
            SchlickFresnel::new(Vec3::splat(0.04)).unwrap(),
            Vec3::new(0.8, 0.1, 0.1),
        )
        .unwrap(),
        Material::mirror(ConductorFresnel::SILVER),
        Material::microfacet_compensated(Ggx::isotropic(0.6).unwrap(), ConductorFresnel::GOLD)
            .unwrap(),
        brdf::material::NormalMappedMaterial::new(
            Arc::new(map.clone()),
            Material::microfacet(Ggx::isotropic(0.2).unwrap(), ConductorFresnel::COPPER),
        )
        .unwrap()
        .into(),
    ];
    for ex in support::registry::examples(&map) {
        let glint = GlintMaterial::new(Arc::new(ex.model), ConductorFresnel::SILVER)
            .with_options(ex.options)
            .with_uv_scale(Vec2::new(2.0, 1.0))
            .unwrap();
        materials.push(glint.clone().into());
        materials.push(glint.over_base(Vec3::splat(0.3)).unwrap().into());
    }
    let footprints: Vec<Footprint> = [3000.0f32, 0.3, 4.0, 50.0, 700.0]
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            let c = Vec2::new(0.13 + 0.17 * k as f32, 0.71 - 0.11 * k as f32);
            Footprint::isotropic_texels(c, a / 2.0, 64, 64)
        })
        .collect();
    let path = |scratch: &brdf::glint::GlintScratch, k: usize| -> f32 {
        let n = materials.len();
        let fp = |j: usize| &footprints[(k + j) % footprints.len()];
        let wo = support::dir(10.0 + 7.0 * (k % 11) as f64, 37.0 * k as f64);
        let (a, b, c) = (
            materials[k % n].bsdf(fp(0), wo, scratch),
            materials[(k + 1) % n].bsdf(fp(1), wo, scratch),
            materials[(k + 2) % n].bsdf(fp(2), wo, scratch),
        );
        let wi = support::dir(35.0, 180.0 + 37.0 * k as f64);
        let mut acc = 0.0;
        for bsdf in [&a, &b, &c] {
            if let Some(s) = bsdf.sample(wo, 0.3, Vec2::new(0.4, 0.6)) {
                acc += s.weight().x;
            }
            let (f, pdf) = bsdf.eval_pdf(wo, wi);
            acc += f.x + pdf;
        }
        acc
    };
    let scratch = GlintScratch::default();
    // Warm-up: every material at every footprint position of the cycle, three live at once.
    let mut sink = 0.0;
    for k in 0..materials.len() * footprints.len() {
        sink += path(&scratch, k);
    }
    let before = allocations();
    for k in 0..materials.len() * footprints.len() {
        sink += path(&scratch, k);
    }
    let n = allocations() - before;
    assert!(sink.is_finite());
    assert_eq!(n, 0, "{n} allocations in {} paths", materials.len());
}

/// The counter counts (a check of the test itself): `patch` without a scratch allocates.
#[test]
fn the_counter_sees_the_allocating_path() {
    let map = brdf::glint::bumpy(16, 16, 0.2, 3.0, 1).unwrap();
    let model: GlintModel = PositionNormalMap::build(&map, PositionNormalParams::default())
        .unwrap()
        .into();
    let fp = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 30.0, 16, 16);
    let before = allocations();
    let brdf = MicrofacetBrdf::new(model.patch(&fp), SchlickFresnel::new(Vec3::ONE).unwrap());
    let f = brdf.eval(Vec3::Z, support::dir(20.0, 0.0));
    assert!(f.is_finite());
    assert!(allocations() > before);
}
