//! Beckmann mixture (Chermain 2019): build on an arbitrary small map with arbitrary parameters, patch
//! through an arbitrary footprint with arbitrary per-query options, query and sample the patch and its P-BRDF.
#![no_main]

use arbitrary::Arbitrary;
use brdf::glint::mixture::{LobeStorage, MaskingMode, MixtureParams, PatchOptions, SeedKernel};
use brdf::glint::{BeckmannMixture, GlintNdf};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{FootprintInput, MapInput, Probe, check_bxdf, check_ndf};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct Input {
    map: MapInput,
    spacing: f32,
    sigma_min: f32,
    samples: u8,
    approximate: bool,
    compact: bool,
    gaussian_seed: bool,
    lod_lobes: f32,
    cut_nodes: u32,
    cut_area: f32,
    cut_tolerance: f32,
    footprint: FootprintInput,
    probe: Probe,
}

fuzz_target!(|input: Input| {
    let Some(map) = input.map.build() else { return };
    let params = MixtureParams {
        spacing: input.spacing,
        sigma_min: input.sigma_min,
        samples: input.samples as usize % 64,
        storage: if input.compact {
            LobeStorage::Compact
        } else {
            LobeStorage::Full
        },
        seed: if input.gaussian_seed {
            SeedKernel::Gaussian
        } else {
            SeedKernel::Cell
        },
        ..MixtureParams::default()
    };
    // Out-of-range parameters must be refused at construction; the fuzzer keeps those that build.
    let Ok(mixture) = BeckmannMixture::build(&map, params) else {
        return;
    };
    // Per-query options are not validated: every value must give a total patch.
    let options = PatchOptions {
        masking: if input.approximate {
            MaskingMode::Approximate
        } else {
            MaskingMode::Exact
        },
        lod_lobes: input.lod_lobes,
        cut_nodes: input.cut_nodes,
        cut_area: input.cut_area,
        cut_tolerance: input.cut_tolerance,
        ..PatchOptions::default()
    };
    let patch = mixture.patch_with(&input.footprint.build(), &options, None);
    check_ndf(&patch, &input.probe);
    check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
});
