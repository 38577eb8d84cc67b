//! The forms a glint model's patches take across footprint sizes (`GlintModel::forms`): each
//! model's documented thresholds, the options they come from, and no default form whose work grows
//! with the footprint at the largest footprints, on every procedural map.

use brdf::glint::binmap::MIN_MOMENT_MASKING_TEXELS;
use brdf::glint::mixture::{
    DEFAULT_CUT_NODES, DEFAULT_FILTERED_AREA, DEFAULT_FILTERED_TOLERANCE, DEFAULT_SUB_TEXEL_AREA,
    PatchOptions,
};
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, FormReport, GlintModel, GlintOptions, NormalMap, PatchForm,
    PositionNormalMap,
};

/// The four procedural maps at `size`², seed `seed`.
fn maps(size: usize, seed: u64) -> Vec<(&'static str, NormalMap)> {
    vec![
        (
            "bumpy",
            brdf::glint::bumpy(size, size, 0.25, 4.0, seed).unwrap(),
        ),
        (
            "brushed",
            brdf::glint::brushed(size, size, Default::default(), seed).unwrap(),
        ),
        (
            "scratched",
            brdf::glint::scratched(size, size, Default::default(), seed).unwrap(),
        ),
        (
            "flakes",
            brdf::glint::flakes(size, size, Default::default(), seed).unwrap(),
        ),
    ]
}

/// The three map-based models of `map` at their default parameters.
fn models(map: &NormalMap) -> [GlintModel; 3] {
    [
        BeckmannMixture::build(map, Default::default())
            .unwrap()
            .into(),
        BinMap::build(map, Default::default()).unwrap().into(),
        PositionNormalMap::build(map, Default::default())
            .unwrap()
            .into(),
    ]
}

/// At its defaults the mixture serves its sub-texel lobe below `DEFAULT_SUB_TEXEL_AREA`, gathers
/// up to `DEFAULT_FILTERED_AREA`, and from there serves the filtered mixture within its tolerance
/// or a cut within its node cap; with every level of detail off it gathers at every size. The
/// report reads patches made with the options it is given.
#[test]
fn the_mixture_reports_its_thresholds() {
    for (name, map) in maps(128, 1) {
        let model: GlintModel = BeckmannMixture::build(&map, Default::default())
            .unwrap()
            .into();
        let report = model.forms(&GlintOptions::default());
        assert_eq!(report.model, "Beckmann mixture");
        assert_eq!(report.rows.len(), 9, "{name}: ¼ to 16,384 texels");
        for r in &report.rows {
            let ok = if r.texels < DEFAULT_SUB_TEXEL_AREA {
                r.form == PatchForm::SubTexel
            } else if r.texels < DEFAULT_FILTERED_AREA {
                matches!(r.form, PatchForm::Gathered { level: 0, lobes } if lobes > 0)
            } else {
                match r.form {
                    PatchForm::FilteredMixture { lobes, error } => {
                        lobes > 0 && error <= DEFAULT_FILTERED_TOLERANCE
                    }
                    PatchForm::Cut { nodes, .. } => nodes as u32 <= DEFAULT_CUT_NODES,
                    _ => false,
                }
            };
            assert!(ok, "{name}, {} texels: {}", r.texels, r.form);
        }
        assert_eq!(report.bounded_from(), Some(DEFAULT_FILTERED_AREA), "{name}");

        let mut full = GlintOptions::default();
        full.mixture = PatchOptions::full();
        let report = model.forms(&full);
        assert!(
            report
                .rows
                .iter()
                .all(|r| matches!(r.form, PatchForm::Gathered { level: 0, .. })),
            "{name}:\n{report}"
        );
        assert_eq!(report.bounded_from(), None);
        // The gathered lobes grow with the footprint.
        let lobes: Vec<usize> = report
            .rows
            .iter()
            .map(|r| match r.form {
                PatchForm::Gathered { lobes, .. } => lobes,
                _ => 0,
            })
            .collect();
        assert!(lobes.windows(2).all(|w| w[0] <= w[1]), "{lobes:?}");
    }
}

/// No model's defaults leave a footprint of 16,384 texels or more to a form whose work grows with
/// the footprint, on the four procedural maps at two seeds: the mixture's and position-normal's
/// gathers stop at 4,096 texels (filtered mixture or cut), the bin map lists bins at most up to
/// its `exact_masking_texels` (4,096); and the bin map lists the footprint's bins up to
/// `MIN_MOMENT_MASKING_TEXELS` whatever its measured errors.
#[test]
fn no_default_form_grows_at_the_largest_footprints() {
    for seed in [1, 2] {
        for (name, map) in maps(256, seed) {
            for model in models(&map) {
                let report: FormReport = model.forms(&GlintOptions::default());
                let bounded = report.bounded_from();
                assert!(
                    bounded.is_some_and(|t| t <= 16384.0),
                    "{name}, seed {seed}:\n{report}"
                );
                if model.name() == "bin map" {
                    for r in &report.rows {
                        if r.texels <= MIN_MOMENT_MASKING_TEXELS {
                            assert!(
                                matches!(r.form, PatchForm::BinList { bins } if bins > 0),
                                "{name}, {} texels: {}",
                                r.texels,
                                r.form
                            );
                        }
                    }
                }
            }
        }
    }
}

/// The procedural surface is bounded at every footprint: facet lobes (at most a few tens) up to
/// its hand-over, then its limit NDF alone.
#[test]
fn the_procedural_surface_is_bounded_everywhere() {
    let model: GlintModel = ProceduralGlints::new(ProceduralParams::default())
        .unwrap()
        .into();
    let report = model.forms(&GlintOptions::default());
    assert_eq!(report.bounded_from(), Some(0.25), "{report}");
    for r in &report.rows {
        match r.form {
            PatchForm::Facets { lobes } => assert!((1..=33).contains(&lobes), "{report}"),
            PatchForm::Limit => {}
            other => panic!("{other}"),
        }
    }
    assert_eq!(report.rows.last().map(|r| r.form), Some(PatchForm::Limit));
}
