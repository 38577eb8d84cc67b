//! One small example of every glint model registered in `GlintModel` (with each of its storages and
//! options worth covering), for the tests that must hold for every model: save/load and serde
//! through `GlintModel`, and no allocation in a warm scratch.
//!
//! [`examples`] asserts that its models cover every name of `GlintModel::NAMES`: a model added to
//! the registry without an example here fails every test that uses it.

use brdf::Vec2;
use brdf::glint::binmap::{self, BinMapParams};
use brdf::glint::mixture::{LobeStorage, MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::{self, PositionNormalParams};
use brdf::glint::procedural::{self, ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, GlintOptions, NormalMap,
    PositionNormalMap,
};
use brdf::ndf::Ndf;

/// A registered model with the per-query options a test should use for it, and a label.
pub struct Example {
    pub label: &'static str,
    pub model: GlintModel,
    pub options: GlintOptions,
}

/// Every registered model on `map` (small builds: a few seconds in all for a 64² map), with the
/// variants that take different code paths (mixture storage and masking, bin-map smoothing). Every
/// model has at least one example with options other than its defaults (a coarser level of detail
/// or footprint cap, bin-map smoothing).
///
/// # Panics
/// If a name of `GlintModel::NAMES` has no example: add one here for a new model.
pub fn examples(map: &NormalMap) -> Vec<Example> {
    let mixture = |storage| {
        let params = MixtureParams {
            samples: 16,
            storage,
            ..MixtureParams::default()
        };
        GlintModel::from(BeckmannMixture::build(map, params).unwrap())
    };
    let masked = |masking| {
        let mut options = GlintOptions::default();
        options.mixture.masking = masking;
        options
    };
    let example = |label, model, options| Example {
        label,
        model,
        options,
    };
    let full = mixture(LobeStorage::Full);
    let bin_map = GlintModel::from(BinMap::build(map, BinMapParams::default()).unwrap());
    let mut smoothed = GlintOptions::default();
    smoothed.bin_map = binmap::PatchOptions {
        smoothing_alpha: 0.05,
        ..Default::default()
    };
    let mut coarse = GlintOptions::default();
    coarse.mixture = PatchOptions {
        masking: MaskingMode::Approximate,
        lod_lobes: 64.0,
        lod_tolerance: 0.05,
        lod_resolution: 0.04,
        sub_texel_area: 0.0,
        filtered_area: f32::INFINITY,
        cut_nodes: 0,
        cut_tolerance: 0.0,
        cut_area: 0.0,
        filtered_tolerance: 0.0,
    };
    let mut filtered = GlintOptions::default();
    filtered.mixture = PatchOptions {
        filtered_area: 0.0,
        filtered_tolerance: f32::INFINITY,
        cut_nodes: 0,
        ..PatchOptions::default()
    };
    let mut capped = GlintOptions::default();
    capped.position_normal = position_normal::PatchOptions {
        max_query_texels: 8.0,
        cut_nodes: 0,
        filtered_area: f32::INFINITY,
        ..position_normal::PatchOptions::default()
    };
    let mut pn_filtered = GlintOptions::default();
    pn_filtered.position_normal = position_normal::PatchOptions {
        filtered_area: 0.0,
        filtered_tolerance: f32::INFINITY,
        ..position_normal::PatchOptions::default()
    };
    let position_normal =
        GlintModel::from(PositionNormalMap::build(map, PositionNormalParams::default()).unwrap());
    // Procedural glints at the map's resolution (the surface does not read the map).
    let procedural = GlintModel::from(
        ProceduralGlints::new(ProceduralParams {
            resolution: [map.width(), map.height()],
            density: 4.0,
            seed: 3,
            ..ProceduralParams::default()
        })
        .unwrap(),
    );
    let procedural_ggx = GlintModel::from(
        ProceduralGlints::new(ProceduralParams {
            resolution: [map.width(), map.height()],
            density: 4.0,
            seed: 4,
            limit: procedural::ProceduralLimit::Ggx,
            ..ProceduralParams::default()
        })
        .unwrap(),
    );
    let mut loose = GlintOptions::default();
    loose.procedural = procedural::PatchOptions { tolerance: 0.5 };
    let examples = vec![
        example(
            "mixture, exact masking",
            full.clone(),
            masked(MaskingMode::Exact),
        ),
        example(
            "mixture, approximate masking, coarse level of detail",
            full.clone(),
            coarse,
        ),
        example(
            "mixture, sub-texel lobe and filtered mixture at every footprint",
            full,
            filtered,
        ),
        example(
            "mixture, compact storage",
            mixture(LobeStorage::Compact),
            masked(MaskingMode::Exact),
        ),
        example("bin map", bin_map.clone(), GlintOptions::default()),
        example("bin map, smoothed", bin_map, smoothed),
        example(
            "position-normal, footprint cap 8 texels",
            position_normal.clone(),
            capped,
        ),
        example(
            "position-normal, filtered mixture at every footprint",
            position_normal,
            pn_filtered,
        ),
        example("procedural", procedural.clone(), GlintOptions::default()),
        example("procedural, tolerance 0.5", procedural, loose),
        example(
            "procedural, GGX limit",
            procedural_ggx,
            GlintOptions::default(),
        ),
    ];
    for name in GlintModel::NAMES {
        assert!(
            examples.iter().any(|e| e.model.name() == *name),
            "the registered model {name:?} has no example in tests/it/support/registry.rs"
        );
    }
    examples
}

/// The answers of a model's patches at a few footprints and directions, as bits.
pub fn fingerprint(model: &GlintModel, options: &GlintOptions) -> Vec<u32> {
    let mut out = Vec::new();
    for (k, area) in [0.5f32, 9.0, 200.0].into_iter().enumerate() {
        let c = Vec2::new(0.2 + 0.3 * k as f32, 0.7 - 0.2 * k as f32);
        let fp = Footprint::isotropic_texels(c, area, 32, 32);
        let patch = model.patch_with(&fp, options, None);
        for j in 0..4 {
            let w = super::dir(15.0 * j as f64, 40.0 * j as f64 + 10.0);
            let u = Vec2::new(0.2 + 0.2 * j as f32, 0.7 - 0.1 * j as f32);
            let m = patch.sample_visible(w, u);
            out.extend(
                [
                    patch.d(w),
                    patch.lambda(w),
                    patch.projected_area(w),
                    patch.pdf_visible(w, m),
                    m.x,
                    m.y,
                    m.z,
                ]
                .map(f32::to_bits),
            );
        }
    }
    out
}
