//! Which masking a bin-map footprint gets, chosen by a measured error: between
//! [`MIN_MOMENT_MASKING_TEXELS`] and [`PatchOptions::exact_masking_texels`] a footprint takes the
//! O(1) moment-lobe masking (Scarf's bound from the footprint's filtered moments) instead of the
//! exact pass over its own bins where the map's measured G1 error of that lobe at the footprint's
//! level is within [`PatchOptions::moment_masking_tolerance`].
//!
//! **The error.** For a footprint, e = mean over views wo at θo ∈ {45°, 70°} and six azimuths of
//! |1 − G1_lobe(wo) / G1_bins(wo)|, G1 = 1/(1 + Λ): the relative error of the masking term the
//! renderer multiplies its radiance by at those views (the albedo's error follows it, docs/results.md
//! "Inverse bin map: the masking level of detail"). Per level l of the map (footprints of 4^l
//! texels, 256-4096 measured, four fixed centres; src/glint/kernels/filtered_error.rs), by the
//! build (~10-50 ms for a 1024² map) and stored in files. Footprints of 128-256
//! texels read the 256-texel level: the error varies little between levels (on the 256² procedural
//! maps it moves by at most 0.005 between 256 and 4096 texels, tests/it/binmap_masking_lod.rs), and
//! below 128 texels the moments are not the footprint's (the floor).

use super::{BinMap, MIN_MOMENT_MASKING_TEXELS, PatchOptions};
use crate::glint::kernels::filtered_error;
use crate::glint::{Footprint, GlintNdf};
use crate::ndf::Ndf;
use glam::Vec3;

/// The views at which the G1 error is measured: θo ∈ {45°, 70°} × six azimuths.
fn views() -> impl Iterator<Item = Vec3> {
    [45f32, 70.0].into_iter().flat_map(|t| {
        (0..6).map(move |k| {
            let (t, p) = (t.to_radians(), (k as f32 * 60.0 + 15.0).to_radians());
            Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        })
    })
}

impl BinMap {
    /// The moment-lobe masking's measured G1 error per level (index l: footprints of 4^l texels;
    /// 1 where not measured, below 256 texels): what [`PatchOptions::moment_masking_tolerance`] is
    /// compared with. Measured by the build (deterministic) and stored in files; see
    /// src/glint/binmap/masking_choice.rs.
    pub fn moment_masking_errors(&self) -> &[f32] {
        &self.moment_masking_error
    }

    /// The map with its moment-lobe masking's errors: `stored` when given (read from a file),
    /// else measured (the build's last step).
    pub(super) fn with_masking_errors(mut self, stored: Option<Vec<f32>>) -> Self {
        self.moment_masking_error = stored.unwrap_or_else(|| self.measure_masking_errors());
        self
    }

    /// The map with its moment-lobe masking's errors measured.
    pub(super) fn measured(self) -> Self {
        self.with_masking_errors(None)
    }

    /// Measures [`BinMap::moment_masking_errors`] (module docs).
    fn measure_masking_errors(&self) -> Vec<f32> {
        let area = (self.width * self.height) as f64;
        let levels = (0..)
            .take_while(|&l| (1u64 << (2 * l)) as f64 <= area)
            .count();
        let exact = PatchOptions {
            exact_masking_texels: f32::INFINITY,
            smoothing_alpha: 0.0,
            moment_masking_tolerance: 0.0,
        };
        let lobe = PatchOptions {
            exact_masking_texels: 0.0,
            ..exact
        };
        filtered_error::errors_per_level(
            levels,
            area,
            [1.0, 1.0],
            (self.width, self.height),
            |fp: &Footprint| {
                let bins = self.patch_with(fp, &exact, None);
                if bins.area_texels() <= MIN_MOMENT_MASKING_TEXELS as f64 {
                    return None;
                }
                let moment = self.patch_with(fp, &lobe, None);
                let g1 = |l: f32| 1.0 / (1.0 + l as f64);
                let (mut sum, mut n) = (0.0, 0);
                for wo in views() {
                    let e = g1(bins.lambda(wo));
                    if e > 0.0 {
                        sum += (1.0 - g1(moment.lambda(wo)) / e).abs();
                        n += 1;
                    }
                }
                (n > 0).then(|| (sum / n as f64).min(1.0))
            },
        )
    }

    /// Whether a footprint of `area` texels (after the footprint's clamps) takes its masking terms
    /// from its own bins under `options` (module docs).
    pub(super) fn exact_masking_for(&self, area: f64, options: &PatchOptions) -> bool {
        let limit = options.exact_masking_texels;
        let limit = if limit.is_nan() {
            MIN_MOMENT_MASKING_TEXELS
        } else {
            limit.max(MIN_MOMENT_MASKING_TEXELS)
        };
        if area > limit as f64 {
            return false;
        }
        let tolerance = options.moment_masking_tolerance;
        // NaN and non-positive tolerances never serve the lobe.
        let positive = tolerance > 0.0;
        if area <= MIN_MOMENT_MASKING_TEXELS as f64 || !positive {
            return true;
        }
        // The 256-texel level for 128-256 texels (module docs).
        let lod = (0.5 * area.log2()).max(4.0);
        let error = filtered_error::error_at(self.moment_masking_errors(), lod);
        let served = tolerance == f32::INFINITY || error <= tolerance;
        !served
    }
}
