//! The glint-model registry is complete: every model registered in `GlintModel` saves and loads
//! through it (bit-identical patches) and is covered by the shared examples that the allocation test
//! (tests/alloc.rs) and the `serde` round trip (tests/serde.rs) also run.

use crate::support;

use brdf::Error;
use brdf::glint::{Footprint, GlintModel, GlintNdf, GlintOptions};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};

#[test]
fn every_registered_model_saves_and_loads_through_glint_model() {
    let map = brdf::glint::scratched(32, 32, Default::default(), 11).unwrap();
    for ex in support::registry::examples(&map) {
        let mut bytes = Vec::new();
        ex.model.save(&mut bytes).unwrap();
        let loaded = GlintModel::load(&mut bytes.as_slice()).unwrap();
        assert_eq!(loaded.name(), ex.model.name(), "{}", ex.label);
        assert_eq!(
            support::registry::fingerprint(&loaded, &ex.options),
            support::registry::fingerprint(&ex.model, &ex.options),
            "{}: the loaded model answers differently",
            ex.label
        );
        // Saving the loaded model writes the same file.
        let mut again = Vec::new();
        loaded.save(&mut again).unwrap();
        assert!(again == bytes, "{}: re-saved bytes differ", ex.label);
    }
}

/// A file of a type that is no glint model (a normal map) is refused by name, and a short file is
/// truncated, not a panic.
#[test]
fn glint_model_load_refuses_what_is_no_glint_model() {
    let map = brdf::glint::bumpy(8, 8, 0.2, 3.0, 1).unwrap();
    let mut bytes = Vec::new();
    map.save(&mut bytes).unwrap();
    match GlintModel::load(&mut bytes.as_slice()) {
        Err(Error::WrongModelKind { found, .. }) => assert_eq!(found, "NormalMap"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        GlintModel::load(&mut &bytes[..10]),
        Err(Error::Truncated { .. })
    ));
}

/// Options are per query: the same model answers with the options it is given, and `patch` uses
/// the defaults.
#[test]
fn options_are_per_query() {
    let map = brdf::glint::scratched(32, 32, Default::default(), 11).unwrap();
    let examples = support::registry::examples(&map);
    let plain = examples.iter().find(|e| e.label == "bin map").unwrap();
    let smoothed = examples
        .iter()
        .find(|e| e.label == "bin map, smoothed")
        .unwrap();
    assert_ne!(
        support::registry::fingerprint(&plain.model, &plain.options),
        support::registry::fingerprint(&plain.model, &smoothed.options)
    );
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 9.0, 32, 32);
    let w = Vec3::new(0.3, 0.1, 0.95).normalize();
    for ex in &examples {
        assert_eq!(
            ex.model.patch(&fp).d(w).to_bits(),
            ex.model
                .patch_with(&fp, &GlintOptions::default(), None)
                .d(w)
                .to_bits(),
            "{}",
            ex.label
        );
    }
}

/// Options survive save/load because no file holds them: a loaded model given the same non-default
/// options answers bit-identically to the built one, and its `patch` is the built model's patch at
/// the defaults (no option travels hidden in the file). Every registered model has an example whose
/// options change its answers, so the comparison can fail.
#[test]
fn options_survive_save_load() {
    let map = brdf::glint::scratched(32, 32, Default::default(), 11).unwrap();
    let defaults = GlintOptions::default();
    let mut changed = Vec::new();
    for ex in support::registry::examples(&map) {
        let mut bytes = Vec::new();
        ex.model.save(&mut bytes).unwrap();
        let loaded = GlintModel::load(&mut bytes.as_slice()).unwrap();
        let with_options = support::registry::fingerprint(&ex.model, &ex.options);
        let at_defaults = support::registry::fingerprint(&ex.model, &defaults);
        assert_eq!(
            support::registry::fingerprint(&loaded, &ex.options),
            with_options,
            "{}: the loaded model answers differently with the same options",
            ex.label
        );
        assert_eq!(
            support::registry::fingerprint(&loaded, &defaults),
            at_defaults,
            "{}: the loaded model's defaults differ from the built model's",
            ex.label
        );
        let (fp, w) = (
            Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 200.0, 32, 32),
            Vec3::new(0.3, 0.1, 0.95).normalize(),
        );
        assert_eq!(
            loaded.patch(&fp).d(w).to_bits(),
            ex.model.patch_with(&fp, &defaults, None).d(w).to_bits(),
            "{}: the loaded model's `patch` is not the default patch",
            ex.label
        );
        if with_options != at_defaults {
            changed.push(ex.model.name());
        }
    }
    for name in GlintModel::NAMES {
        assert!(
            changed.contains(name),
            "{name}: no example whose options change its answers (tests/it/support/registry.rs)"
        );
    }
}

/// Every registered model reports the size of the map it was built from, on a non-square map (so
/// that width and height cannot be swapped unseen), before and after a save / load, and a
/// footprint's area in its texels.
#[test]
fn every_registered_model_reports_its_map_size() {
    let map = brdf::glint::scratched(48, 32, Default::default(), 5).unwrap();
    let mut seen = Vec::new();
    for ex in support::registry::examples(&map) {
        assert_eq!(ex.model.map_size(), (48, 32), "{}", ex.label);
        assert_eq!(
            ex.model.texel_scale(),
            Vec2::new(48.0, 32.0),
            "{}",
            ex.label
        );
        let mut bytes = Vec::new();
        ex.model.save(&mut bytes).unwrap();
        let loaded = GlintModel::load(&mut bytes.as_slice()).unwrap();
        assert_eq!(loaded.map_size(), (48, 32), "{}: loaded", ex.label);
        // A 3 × 3-texel square of this map, and one whose uv differentials are a tenth of a period
        // along u and along v: 4.8 × 3.2 texels. (Tolerance: f32 rounding of the areas.)
        let square = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), 9.0, 48, 32);
        let a = ex.model.footprint_texels(&square);
        assert!((a - 9.0).abs() < 1e-4, "{}: {a}", ex.label);
        let tenth = Footprint::from_differentials(
            Vec2::new(0.3, 0.6),
            Vec2::new(0.1, 0.0),
            Vec2::new(0.0, 0.1),
        );
        let a = ex.model.footprint_texels(&tenth);
        assert!((a - 4.8 * 3.2).abs() < 1e-4, "{}: {a}", ex.label);
        seen.push(ex.model.name());
    }
    for name in GlintModel::NAMES {
        assert!(seen.contains(name), "{name}: no example");
    }
}
