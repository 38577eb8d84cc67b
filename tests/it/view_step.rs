//! The view step: a glint patch of every registered model (through `GlintPatch::prepare_view`), a
//! `LayeredBrdf` and a `Material`'s `Bsdf` prepared for a view answer every query bit for bit as
//! the unprepared ones, at the prepared view and at every other view. What the step computes (a
//! patch's V(wo), the bin map's visible normalisation, a layer's R̂(wo)) is only shared, never
//! different.

use crate::support;

use brdf::bxdf::{Bxdf, MicrofacetBrdf, Sampling};
use brdf::fresnel::{ConductorFresnel, NoFresnel, SchlickFresnel};
use brdf::glint::{Footprint, GlintNdf, GlintPatch, GlintScratch};
use brdf::material::GlintMaterial;
use brdf::ndf::{Ggx, Ndf};
use brdf::{LayeredBrdf, Material, Vec2, Vec3};
use rand::RngExt;

/// Views, grazing ones included.
fn views() -> Vec<Vec3> {
    [(0.0, 0.0), (35.0, 20.0), (70.0, 200.0), (88.0, 300.0)]
        .into_iter()
        .map(|(t, p)| support::dir(t, p))
        .collect()
}

/// `prepared` (prepared for `wo`) against `plain` (unprepared): every `Ndf` query that reads a
/// view, and every `Bxdf` query through `MicrofacetBrdf` under both samplers, at `wo` and at
/// `other`, equal bit for bit.
fn same_patch(prepared: &GlintPatch, plain: &GlintPatch, wo: Vec3, other: Vec3, seed: u64) {
    let mut rng = support::rng(seed);
    for w in [wo, other] {
        assert_eq!(prepared.visible_area(w), plain.visible_area(w));
        assert_eq!(prepared.view_visible_area(w), plain.view_visible_area(w));
        assert_eq!(prepared.projected_area(w), plain.projected_area(w));
        for _ in 0..12 {
            let u = Vec2::new(rng.random(), rng.random());
            let m = plain.sample_visible(w, u);
            assert_eq!(prepared.sample_visible(w, u), m);
            let d = plain.d(m);
            assert_eq!(prepared.pdf_visible(w, m), plain.pdf_visible(w, m));
            assert_eq!(
                prepared.pdf_visible_over_cos_given_d(w, m, d),
                plain.pdf_visible_over_cos_given_d(w, m, d)
            );
            assert_eq!(
                prepared.pdf_normal_given_d(m, d),
                plain.pdf_normal_given_d(m, d)
            );
        }
        for sampling in [Sampling::VisibleNormals, Sampling::Normals] {
            let a = MicrofacetBrdf::new(prepared, NoFresnel).with_sampling(sampling);
            let b = MicrofacetBrdf::new(plain, NoFresnel).with_sampling(sampling);
            for _ in 0..12 {
                let wi = support::dir(rng.random_range(0.0..89.0), rng.random_range(0.0..360.0));
                assert_eq!(a.eval_pdf(w, wi), b.eval_pdf(w, wi));
                assert_eq!(a.eval(w, wi), b.eval(w, wi));
                assert_eq!(a.pdf(w, wi), b.pdf(w, wi));
                let u = Vec2::new(rng.random(), rng.random());
                assert_eq!(a.sample(w, 0.5, u), b.sample(w, 0.5, u));
            }
        }
    }
}

/// Every registered model (both mixture storages and masking modes, bin-map smoothing, the
/// procedural surface), footprints from a sub-texel one to beyond the filtered forms' thresholds.
#[test]
fn prepared_patches_answer_as_unprepared_ones() {
    let map = brdf::glint::scratched(64, 64, Default::default(), 4).unwrap();
    let views = views();
    for (e, ex) in support::registry::examples(&map).into_iter().enumerate() {
        for (k, area) in [0.5f32, 6.0, 90.0, 1500.0, 20000.0].into_iter().enumerate() {
            let c = Vec2::new(0.21 + 0.13 * k as f32, 0.67 - 0.09 * k as f32);
            let fp = Footprint::isotropic_texels(c, area, 64, 64);
            let plain = ex.model.patch_with(&fp, &ex.options, None);
            for (v, &wo) in views.iter().enumerate() {
                let mut prepared = plain.clone();
                prepared.prepare_view(wo);
                let other = views[(v + 1) % views.len()];
                let seed = (e * 100 + k * 10 + v) as u64;
                same_patch(&prepared, &plain, wo, other, seed);
            }
            // A patch prepared for one view and then for another holds the second.
            let mut twice = plain.clone();
            twice.prepare_view(views[1]);
            twice.prepare_view(views[2]);
            same_patch(&twice, &plain, views[2], views[1], 7);
            // Invalid views prepare nothing and stay total.
            for bad in [Vec3::new(0.0, 0.0, -1.0), Vec3::NAN, Vec3::ZERO] {
                let mut p = plain.clone();
                p.prepare_view(bad);
                same_patch(&p, &plain, views[1], views[3], 9);
                assert_eq!(
                    p.view_visible_area(bad),
                    plain.view_visible_area(bad),
                    "{}",
                    ex.label
                );
            }
        }
    }
}

/// A layer over a base prepared for a view: R̂(wo) and every query as the unprepared layer's.
#[test]
fn prepared_layers_answer_as_unprepared_ones() {
    let coat = MicrofacetBrdf::new(
        Ggx::new(0.15, 0.3).unwrap(),
        SchlickFresnel::new(Vec3::splat(0.04)).unwrap(),
    );
    let plain = LayeredBrdf::new(coat, Vec3::new(0.7, 0.3, 0.1)).unwrap();
    let mut rng = support::rng(11);
    for wo in views() {
        let mut prepared = plain.clone();
        prepared.prepare_view(wo);
        for w in [wo, support::dir(50.0, 10.0)] {
            assert_eq!(
                prepared.first_bounce_reflectance(w),
                plain.first_bounce_reflectance(w)
            );
            for _ in 0..16 {
                let wi = support::dir(rng.random_range(0.0..89.0), rng.random_range(0.0..360.0));
                assert_eq!(prepared.eval_pdf(w, wi), plain.eval_pdf(w, wi));
                let u = Vec2::new(rng.random(), rng.random());
                let uc = rng.random();
                assert_eq!(prepared.sample(w, uc, u), plain.sample(w, uc, u));
            }
        }
    }
}

/// `Material::bsdf` prepares for its `wo`: a glint material and a glint coat give the values of
/// the unprepared BRDFs at that view and at another.
#[test]
fn material_bsdfs_prepared_for_their_view() {
    let map = brdf::glint::bumpy(64, 64, 0.3, 4.0, 2).unwrap();
    let scratch = GlintScratch::default();
    let mut rng = support::rng(12);
    for ex in support::registry::examples(&map) {
        let model = std::sync::Arc::new(ex.model);
        let glint = GlintMaterial::new(model.clone(), ConductorFresnel::GOLD)
            .with_options(ex.options.clone());
        let coat = Material::from(glint.clone().over_base(Vec3::splat(0.5)).unwrap());
        let glint = Material::from(glint);
        for area in [3.0f32, 200.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.4), area, 64, 64);
            let patch = || model.patch_with(&fp, &ex.options, None);
            let plain = MicrofacetBrdf::new(patch(), ConductorFresnel::GOLD);
            let plain_coat = LayeredBrdf::new(
                MicrofacetBrdf::new(patch(), ConductorFresnel::GOLD),
                Vec3::splat(0.5),
            )
            .unwrap();
            for wo in views() {
                let a = glint.bsdf(&fp, wo, &scratch);
                let b = coat.bsdf(&fp, wo, &scratch);
                for w in [wo, support::dir(45.0, 123.0)] {
                    for _ in 0..8 {
                        let wi =
                            support::dir(rng.random_range(0.0..89.0), rng.random_range(0.0..360.0));
                        assert_eq!(a.eval_pdf(w, wi), plain.eval_pdf(w, wi), "{}", ex.label);
                        assert_eq!(
                            b.eval_pdf(w, wi),
                            plain_coat.eval_pdf(w, wi),
                            "{}",
                            ex.label
                        );
                        let u = Vec2::new(rng.random(), rng.random());
                        let uc = rng.random();
                        assert_eq!(a.sample(w, uc, u), plain.sample(w, uc, u));
                        assert_eq!(b.sample(w, uc, u), plain_coat.sample(w, uc, u));
                    }
                }
            }
        }
    }
}
