//! The last step of a build: the filtered mixture's errors measured against the full mixture
//! (src/glint/kernels/filtered_error.rs), which patches need before their first footprint. They
//! are measured here, once, by the build (and by the loader of a file that does not hold them), so
//! that a mixture holds no state filled on first use.

use super::model::{BeckmannMixture, Storage};
use super::params::{MixtureParams, PatchOptions};
use super::patch::MixturePatch;
use crate::Result;
use crate::glint::NormalMap;
use crate::glint::kernels::filtered_error;

impl BeckmannMixture {
    /// Builds the mixture of `map` (parallel, deterministic whatever the thread count), with its
    /// filtered mixture's measured errors ([`BeckmannMixture::filtered_mixture_errors`]).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming the field of `params` that is invalid (`spacing`,
    /// `sigma_min`, `samples` (under [`MomentMethod::Qmc`](super::MomentMethod::Qmc)),
    /// `supersampling`, `kernel_sigmas`, `weight_sigmas`, `slope_tail`);
    /// [`crate::Error::InvalidSize`] if the lobe grid would exceed 2³¹ lobes.
    pub fn build(map: &NormalMap, params: MixtureParams) -> Result<Self> {
        Self::build_with_progress(map, params, None)
    }

    /// [`BeckmannMixture::build`] reporting progress: `progress` receives fractions in (0, 1] as rows
    /// of lobes complete (possibly from several threads).
    ///
    /// # Errors
    /// As [`BeckmannMixture::build`].
    pub fn build_with_progress(
        map: &NormalMap,
        params: MixtureParams,
        progress: Option<&(dyn Fn(f32) + Sync)>,
    ) -> Result<Self> {
        Ok(Self::build_unmeasured(map, params, progress)?.measured())
    }

    /// The filtered mixture's measured TV to the full mixture per level of its mip chain (index l:
    /// footprints of 4^l lobe cells; 1 below the first measured level), empty under compact
    /// storage and on maps too small to measure any level (fewer than 64 lobes): what
    /// [`PatchOptions::filtered_tolerance`] is compared with. Measured by the build (~0.1-0.3 s,
    /// deterministic) and stored in files. See src/glint/kernels/filtered_error.rs.
    pub fn filtered_mixture_errors(&self) -> &[f32] {
        self.filtered_errors()
    }

    /// The mixture with its filtered mixture's errors measured (full storage; compact storage has
    /// no filtered mixture).
    pub(super) fn measured(self) -> Self {
        let errors = match self.lobe_storage() {
            Storage::Full(_) => measure(&self),
            Storage::Compact(_) => Vec::new(),
        };
        self.with_filtered_errors(errors)
    }
}

/// The filtered mixture's TV to the full mixture per level of its chain, measured on `mixture`.
fn measure(mixture: &BeckmannMixture) -> Vec<f32> {
    let (nx, ny) = mixture.grid();
    let (full, filtered) = compared_options();
    filtered_error::errors_per_level(
        mixture.filtered_mixture_levels(),
        (nx * ny) as f64,
        mixture.spacing_f64(),
        mixture.map_size(),
        |fp| {
            let exact = MixturePatch::new(mixture, fp, full, None);
            let few = MixturePatch::new(mixture, fp, filtered, None);
            few.is_filtered_mixture()
                .then(|| filtered_error::tv(&exact, &few))
        },
    )
}

/// The options of the two patches compared: the full mixture, and the filtered mixture at any
/// footprint (neither reads the measured errors).
fn compared_options() -> (PatchOptions, PatchOptions) {
    let full = PatchOptions::full();
    let filtered = PatchOptions {
        filtered_area: 0.0,
        filtered_tolerance: f32::INFINITY,
        ..full
    };
    (full, filtered)
}
