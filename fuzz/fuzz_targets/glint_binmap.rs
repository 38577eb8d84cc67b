//! Inverse bin map (Atanasov 2020): build on an arbitrary small map with arbitrary bin counts, leaf
//! sizes and sub-texel resolutions, patch (plain and smoothed) through an arbitrary footprint, query and sample.
#![no_main]

use arbitrary::Arbitrary;
use brdf::glint::BinMap;
use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{FootprintInput, MapInput, Probe, check_bxdf, check_ndf};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct Input {
    map: MapInput,
    bins_per_axis: u8,
    leaf_size: u8,
    /// Sub-texel resolution s (issue 17); out-of-range values (0, > `MAX_SUBDIVISIONS`) must be
    /// refused by the builder.
    subdivisions: u8,
    hashed: bool,
    sigma_min: f32,
    smoothing_alpha: f32,
    /// The masking level of detail: any value (NaN, negative, huge) must give a total patch.
    exact_masking_texels: f32,
    /// The tolerance on the moment lobe's measured masking error: any value must give a total patch.
    moment_masking_tolerance: f32,
    footprint: FootprintInput,
    probe: Probe,
}

fuzz_target!(|input: Input| {
    let Some(map) = input.map.build() else { return };
    let params = BinMapParams {
        bins_per_axis: input.bins_per_axis as usize,
        leaf_size: input.leaf_size as usize,
        lookup: if input.hashed {
            BinLookup::Hash
        } else {
            BinLookup::Dense
        },
        sigma_min: input.sigma_min,
        subdivisions: input.subdivisions as usize,
    };
    let Ok(bin_map) = BinMap::build(&map, params) else {
        return;
    };
    let footprint = input.footprint.build();
    let patch = bin_map.patch(&footprint);
    check_ndf(&patch, &input.probe);
    check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
    let smoothed = bin_map.patch_with(
        &footprint,
        &brdf::glint::binmap::PatchOptions {
            smoothing_alpha: input.smoothing_alpha,
            exact_masking_texels: input.exact_masking_texels,
            moment_masking_tolerance: input.moment_masking_tolerance,
        },
        None,
    );
    check_ndf(&smoothed, &input.probe);
    check_bxdf(&MicrofacetBrdf::new(&smoothed, NoFresnel), &input.probe);
});
