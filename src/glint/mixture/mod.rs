//! The Beckmann-mixture P-NDF of \[Chermain2019\]: one non-centred anisotropic Beckmann lobe per seed
//! point of a normal map, Gaussian position weights, exact or approximate patch masking, and a
//! bounding-box hierarchy that keeps D_P evaluations local.
//!
//! - [`BeckmannMixture::build`] integrates the five slope moments of the *interpolated* normal map
//!   under each seed kernel k_i (eq. 5-6; by default the cell between four texel centres, one
//!   bilinear patch per lobe, rather than the paper's Gaussian: [`SeedKernel`]) and keeps the lobes in one of two storages
//!   ([`LobeStorage`]). Full storage holds the moments (5 `f32` per lobe), an implicit quadtree of
//!   slope boxes (§5), a mip chain of the moments (§4.2.2), and the lobes again as
//!   structure-of-arrays blocks of 4 × 4 with their P22 and masking coefficients precomputed in
//!   `f32` (blocks.rs), which the per-direction queries evaluate 16 lanes at a time; and levels of
//!   detail l ≥ 1 of merged lobes stored the same way, with a per-node merge-error bound
//!   (levels.rs). Compact storage holds every level only as quantised blocks, decoded on each visit
//!   (compact.rs).
//! - [`GlintNdf::patch_with`] turns a [`Footprint`] into a [`MixturePatch`], an
//!   [`Ndf`](crate::ndf::Ndf) whose D_P(h) = Σ W_i D_i(h) (eq. 9) and whose masking terms are exact
//!   (eq. 10-17) or approximate (§4.2.2), so that `MicrofacetBrdf::new(patch, fresnel)` is the P-BRDF
//!   of eq. 7. What the patch holds depends on the footprint's size (the level of detail a
//!   renderer never has to set, [`PatchOptions`]): below [`DEFAULT_SUB_TEXEL_AREA`] texels the
//!   sub-texel limit lobe (the interpolated slope at the footprint's centre, spread by the slope
//!   variation the footprint covers and σ_ε: sub_texel.rs); from [`DEFAULT_FILTERED_AREA`] texels
//!   the filtered mixture ([`GMM_LOBES`] lobes per node of a mip chain, O(1) per query:
//!   src/glint/kernels/gmm.rs) wherever its TV to the full mixture, measured per mixture
//!   (src/glint/kernels/filtered_error.rs), is within [`PatchOptions::filtered_tolerance`];
//!   otherwise the lobes gathered over the footprint, on the coarsest level of merged lobes whose
//!   error bound meets [`PatchOptions::lod_tolerance`] and the cost cap [`PatchOptions::lod_lobes`].
//!
//! The model, the hierarchy layout, the deviations from the paper and the defaults with their
//! measurements are in docs/mixture.md.
//!
//! **Files, bottom to top.** Each file imports only files listed before it (no cycles; unit-test
//! modules may also build mixtures through the public API):
//! 1. `params.rs`: build parameters, per-query options, `DEFAULT_*` constants, [`MixtureMemory`];
//! 2. `build.rs` (QMC moments), `build_filter.rs` (the separable filter's moments);
//! 3. src/glint/kernels/lanes.rs (lane arithmetic: `exp2`, the ramp term), `blocks.rs` (the 4 × 4 lobe blocks, their
//!    lane kernels and the walk to them), `simd.rs` (the baseline and AVX2 copies of the block loops);
//! 4. `hierarchy.rs` (slope boxes, moment mip chain), `levels.rs` (merged levels of detail and
//!    their error bounds); the filtered mixture's kernels (a few weighted lobes evaluated by brute
//!    force, its mip chain, its measured error, the prepared view) are shared with the position-normal
//!    map in src/glint/kernels/;
//! 5. `storage.rs` (the crate-private storage interface `LobeStore` / `LevelView`), `sub_texel.rs`
//!    (the sub-texel limit lobe), `full.rs` and `compact.rs` (its two implementations),
//!    `compact_encode.rs` (the compact encoder);
//! 6. `model.rs` ([`BeckmannMixture`]: the build's derived parts and accessors);
//! 7. `slots.rs` (a footprint's slot rectangle and its lobe blocks), `gather.rs` (per-footprint
//!    work: weights, the levels' error pass), `choice.rs` (which form
//!    serves a footprint: sub-texel lobe, filtered mixture, cut, filtered lobe or gather), `passes.rs` (the per-query loops over
//!    blocks, generic over the storage), `patch.rs` ([`MixturePatch`]);
//! 8. `measured.rs` (the public build, whose last step measures the filtered mixture's errors with
//!    patches: [`BeckmannMixture::filtered_mixture_errors`]), `store.rs` (save and load);
//! 9. this file: the re-exports and `impl GlintNdf`; and the unit test of the runtime dispatch
//!    (`dispatch_tests.rs`).

mod blocks;
mod build;
mod build_filter;
mod choice;
mod compact;
mod compact_encode;
#[cfg(test)]
mod dispatch_tests;
mod full;
mod gather;
mod hierarchy;
mod levels;
mod measured;
mod model;
mod params;
mod passes;
mod patch;
mod simd;
mod slots;
mod storage;
mod store;
mod sub_texel;

pub use crate::glint::kernels::cut::{CutStats, MAX_CUT_NODES};
pub use crate::glint::kernels::gmm::GMM_LOBES;
pub use model::BeckmannMixture;
pub use params::{
    DEFAULT_CUT_AREA, DEFAULT_CUT_NODES, DEFAULT_CUT_TOLERANCE, DEFAULT_FILTERED_AREA,
    DEFAULT_FILTERED_TOLERANCE, DEFAULT_KERNEL_SIGMAS, DEFAULT_LOD_LOBES, DEFAULT_LOD_RESOLUTION,
    DEFAULT_LOD_TOLERANCE, DEFAULT_MASKING, DEFAULT_SAMPLES, DEFAULT_SIGMA_MIN, DEFAULT_SLOPE_TAIL,
    DEFAULT_SPACING, DEFAULT_SUB_TEXEL_AREA, DEFAULT_SUPERSAMPLING, DEFAULT_WEIGHT_SIGMAS,
    LOD_RESOLUTIONS, LobeStorage, MAX_SUPERSAMPLING, MAX_TRUNCATION_SIGMAS, MIN_COMPACT_SIGMA,
    MIN_SPACING, MaskingMode, MixtureMemory, MixtureParams, MomentMethod, PatchOptions, SeedKernel,
};
pub use patch::MixturePatch;

use crate::glint::{Footprint, GlintNdf, GlintScratch};

impl GlintNdf for BeckmannMixture {
    type Patch<'a> = MixturePatch<'a>;
    type Options = PatchOptions;

    /// The P-NDF of a footprint ([`MixturePatch`]) with explicit options (masking mode, level of
    /// detail), its per-slot buffers lent by `scratch` if any.
    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> MixturePatch<'a> {
        MixturePatch::new(self, footprint, *options, scratch)
    }
}
