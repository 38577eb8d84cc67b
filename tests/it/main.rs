//! The integration tests, one binary: each module answers one question (its doc says which); the
//! shared harnesses (chi-square, quadrature, seeded maps and RNGs, physics checks) are in `support`.
//! One binary links the crate once instead of once per file. Tests that need a binary of their own
//! stay beside this folder: `alloc` and `store_limits` (counting global allocators), `serde`
//! (feature `serde`) and `normal_map_pixels` (run with `std` but without `image` in CI).
//!
//! Run one module with `cargo test --test it MODULE::` (e.g. `cargo test --test it mixture_sampling::`).
//!
//! Two depths (`support::full`): the default run keeps every check with lighter settings (10⁵
//! chi-square draws instead of 10⁶, coarser furnace quadratures, every second direction of the
//! density sweeps), so that a fresh clone's `cargo test` takes minutes; `BRDF_TEST_FULL=1 cargo
//! test --test it` runs the same checks at the settings they were written with (CI runs
//! both). The heaviest sweeps and tables are `#[ignore]`d twins in either depth.

mod support;

mod binmap_accuracy;
mod binmap_bad_input;
mod binmap_cost;
mod binmap_furnace;
mod binmap_masking_bound;
mod binmap_masking_lod;
mod binmap_sampling;
mod binmap_structure;
mod bxdf_bad_input;
mod bxdf_microfacet;
mod bxdf_phong;
mod bxdf_reciprocity;
mod bxdf_sampling;
mod clear_coat;
mod clear_coat_material;
mod density_contract;
mod density_contract_glint;
mod docs_figures;
mod energy_compensation;
mod frame_handedness;
mod fresnel;
mod fresnel_index_matched;
mod glint_compensation;
mod glint_footprint;
mod glint_forms;
mod glint_measured;
mod glint_normal_map;
mod glint_normal_map_images;
mod glint_procedural;
mod glint_ray_differential;
mod glint_reference;
mod glint_registry;
mod grazing_chi2;
mod harness;
mod hostile_params;
mod hostile_sampling;
mod layered;
mod material;
mod mixture;
mod mixture_compact;
mod mixture_cut;
mod mixture_filtered;
mod mixture_levels;
mod mixture_lod;
mod mixture_lod_tolerance;
mod mixture_masking;
mod mixture_sampling;
mod mixture_sub_texel;
mod ndf_centred_bad_input;
mod ndf_centred_integrals;
mod ndf_centred_sampling;
mod normal_map_io;
mod normal_mapping;
mod normal_mapping_energy;
mod pdf_contract;
mod position_normal_brdf;
mod position_normal_cut;
mod position_normal_filtered;
mod position_normal_pndf;
mod position_normal_tables;
mod procedural_ggx;
mod procedural_glints;
mod ray_cone;
mod reference;
mod renderer_measure;
mod robustness_energy;
mod robustness_outcomes;
mod robustness_regressions;
mod robustness_totality;
mod slope_gaussian_bad_input;
mod slope_gaussian_integrals;
mod slope_gaussian_sampling;
mod specular;
mod store_corrupt_files;
mod store_forged_files;
mod store_forged_procedural;
mod store_fuzz_seeds;
mod store_header_errors;
mod store_roundtrip;
mod view_step;
mod warp;
