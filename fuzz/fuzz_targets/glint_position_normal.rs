//! Position-normal Gaussians (Yan 2016): build on an arbitrary small map with arbitrary parameters,
//! patch through an arbitrary footprint with an arbitrary footprint cap, filtered-mixture switch
//! and cut, query and sample the patch, the published BRDF and ours.
#![no_main]

use arbitrary::Arbitrary;
use brdf::glint::position_normal::{PatchOptions, PositionNormalParams};
use brdf::glint::{GlintNdf, PositionNormalBrdf, PositionNormalMap};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{FootprintInput, MapInput, Probe, check_bxdf, check_ndf};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
struct Input {
    map: MapInput,
    sampling_rate: u8,
    sigma_r: f32,
    weight_sigmas: f32,
    slope_sigmas: f32,
    max_query_texels: f32,
    filtered_area: f32,
    filtered_tolerance: f32,
    cut_nodes: u32,
    cut_area: f32,
    cut_tolerance: f32,
    footprint: FootprintInput,
    probe: Probe,
}

fuzz_target!(|input: Input| {
    let Some(map) = input.map.build() else { return };
    let params = PositionNormalParams {
        sampling_rate: input.sampling_rate as usize % 5,
        sigma_r: input.sigma_r,
        weight_sigmas: input.weight_sigmas,
        slope_sigmas: input.slope_sigmas,
    };
    let Ok(model) = PositionNormalMap::build(&map, params) else {
        return;
    };
    // Per-query options are not validated: every cap must give a total patch.
    let options = PatchOptions {
        max_query_texels: input.max_query_texels,
        filtered_area: input.filtered_area,
        filtered_tolerance: input.filtered_tolerance,
        cut_nodes: input.cut_nodes,
        cut_area: input.cut_area,
        cut_tolerance: input.cut_tolerance,
    };
    let patch = model.patch_with(&input.footprint.build(), &options, None);
    check_ndf(&patch, &input.probe);
    check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
    check_bxdf(&PositionNormalBrdf::new(&patch, NoFresnel), &input.probe);
});
