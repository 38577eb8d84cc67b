//! One small example of every glint model registered in `GlintModel` (with each of its storages and
//! options worth covering), for the tests that must hold for every model: save/load and serde
//! through `GlintModel`, and no allocation in a warm scratch.
//!
//! [`examples`] asserts that its models cover every name of `GlintModel::NAMES`: a model added to
//! the registry without an example here fails every test that uses it.

use brdf::glint::binmap::{self, BinMapParams};
use brdf::glint::mixture::{LobeStorage, MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, GlintModel, GlintOptions, NormalMap, PositionNormalMap,
};

/// A registered model with the per-query options a test should use for it, and a label.
pub struct Example {
    pub label: &'static str,
    pub model: GlintModel,
    pub options: GlintOptions,
}

/// Every registered model on `map` (small builds: a few seconds in all for a 64² map), with the
/// variants that take different code paths (mixture storage and masking, bin-map smoothing).
///
/// # Panics
/// If a name of `GlintModel::NAMES` has no example: add one here for a new model.
pub fn examples(map: &NormalMap) -> Vec<Example> {
    let mixture = |masking, storage| {
        let params = MixtureParams {
            samples: 16,
            storage,
            patch: PatchOptions {
                masking,
                ..PatchOptions::default()
            },
            ..MixtureParams::default()
        };
        GlintModel::from(BeckmannMixture::build(map, params).unwrap())
    };
    let with_own_options = |label, model: GlintModel| {
        let options = brdf::glint::GlintNdf::options(&model);
        Example {
            label,
            model,
            options,
        }
    };
    let bin_map = GlintModel::from(BinMap::build(map, BinMapParams::default()).unwrap());
    let mut smoothed = brdf::glint::GlintNdf::options(&bin_map);
    smoothed.bin_map = binmap::PatchOptions {
        smoothing_alpha: 0.05,
    };
    let examples = vec![
        with_own_options(
            "mixture, exact masking",
            mixture(MaskingMode::Exact, LobeStorage::Full),
        ),
        with_own_options(
            "mixture, approximate masking",
            mixture(MaskingMode::Approximate, LobeStorage::Full),
        ),
        with_own_options(
            "mixture, compact storage",
            mixture(MaskingMode::Exact, LobeStorage::Compact),
        ),
        with_own_options("bin map", bin_map.clone()),
        Example {
            label: "bin map, smoothed",
            model: bin_map,
            options: smoothed,
        },
        with_own_options(
            "position-normal",
            PositionNormalMap::build(map, PositionNormalParams::default())
                .unwrap()
                .into(),
        ),
    ];
    for name in GlintModel::NAMES {
        assert!(
            examples.iter().any(|e| e.model.name() == *name),
            "the registered model {name:?} has no example in tests/support/registry.rs"
        );
    }
    examples
}
