//! The mixture's default level of detail against the σ_ε-convolved truth, from sub-texel to large
//! footprints, on the four procedural maps: below [`DEFAULT_SUB_TEXEL_AREA`] the sub-texel lobe is
//! no farther from the truth than the full mixture; above, the default patch is within the
//! filtered mixture's tolerance ([`DEFAULT_FILTERED_TOLERANCE`], a TV to the full mixture, so a
//! bound on the change of TV to any binned truth) of the full mixture's own distance, plus the
//! truth's and the measurement's noise.
//!
//! The default run covers 0.25-4096 texels on 128² maps; the sweep to 65 536 texels on 512² maps:
//! `cargo test --release --test it mixture_lod_tolerance:: -- --ignored --nocapture`.

use crate::support;

use brdf::Vec2;
use brdf::glint::mixture::{
    DEFAULT_FILTERED_TOLERANCE, DEFAULT_SUB_TEXEL_AREA, MixtureParams, PatchOptions,
};
use brdf::glint::{
    BeckmannMixture, Footprint, GlintNdf, HemisphereBins, Kernel, bin_masses, convolved_pndf,
};

/// Slack for the calibration's estimate (its standard error ≤ 0.016, and the measured error is a
/// mean over four footprint centres, not a maximum) and the truth's sampling noise.
const SLACK: f64 = 0.05;

/// How much further from the truth than the full mixture a default sub-texel lobe may be: the
/// +0.02 of the best setting that a default is held to.
const SUB_TEXEL_SLACK: f64 = 0.02;

fn check(n: usize, areas: &[f32], positions: usize) {
    let bins = HemisphereBins::new(63).unwrap();
    let sigma = brdf::ndf::DEFAULT_SIGMA_MIN as f64;
    let full = PatchOptions::full();
    for (name, map) in support::procedural_maps(n) {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for &area in areas {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let truth =
                convolved_pndf(&map, &fp, Kernel::Gaussian, &bins, positions, 9, sigma).unwrap();
            let default = mix.patch(&fp);
            let exact = mix.patch_with(&fp, &full, None);
            let tv_default = truth.tv_to_masses(&bin_masses(&default, &bins, 2)).unwrap();
            let tv_full = truth.tv_to_masses(&bin_masses(&exact, &bins, 2)).unwrap();
            let kind = if default.is_sub_texel() {
                "sub-texel lobe"
            } else if default.is_filtered_mixture() {
                "filtered mixture"
            } else {
                "gathered"
            };
            println!(
                "{name} {area:>8} texels: default ({kind}) {tv_default:.3}, full mixture {tv_full:.3} \
                 (truth noise {:.3})",
                truth.tv_error()
            );
            if area < DEFAULT_SUB_TEXEL_AREA {
                // The switch is a fixed area, not a per-map choice: where the full mixture is the
                // closer one (scratched at 1 texel, by 0.003 here), the lobe is held to the
                // accuracy target of a default, +0.02 of the best setting.
                assert!(default.is_sub_texel());
                assert!(
                    tv_default <= tv_full + SUB_TEXEL_SLACK + truth.tv_error(),
                    "{name} {area}: {tv_default} > {tv_full} + {SUB_TEXEL_SLACK}"
                );
            } else {
                let budget = DEFAULT_FILTERED_TOLERANCE as f64 + SLACK;
                assert!(
                    tv_default <= tv_full + budget,
                    "{name} {area}: {tv_default} > {tv_full} + {budget}"
                );
            }
        }
    }
}

#[test]
fn default_level_of_detail_respects_its_tolerance() {
    check(128, &[0.25, 1.0, 16.0, 256.0, 4096.0], 200_000);
}

#[test]
#[ignore]
fn default_level_of_detail_respects_its_tolerance_to_65536_texels() {
    check(
        512,
        &[
            0.25, 1.0, 4.0, 16.0, 64.0, 256.0, 1024.0, 4096.0, 16384.0, 65536.0,
        ],
        1_000_000,
    );
}
