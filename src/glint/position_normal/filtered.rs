//! The position-normal map's level of detail for large footprints: the filtered mixture
//! (src/glint/kernels/gmm.rs) over the elements' slope marginals, served where its measured
//! distance to the element sum meets the caller's tolerance.
//!
//! **Level 0.** Element i alone, under a footprint much wider than σ_h, contributes the slope
//! density ∫ N(u; u_i, σ_h² I) N(ñ; ñ_i + J_i (u − u_i), σ_r² I) du = N(ñ; ñ_i, σ_h² J_i J_iᵀ + σ_r² I)
//! (σ_h in texels): the limit Σ_P → ∞ of the patch's per-element lobe, where K → 0 and
//! Σ_u → σ_h² I (\[Yan2016\] §5, docs/position_normal.md). The chain reduces these per 2 × 2 block
//! to [`GMM_LOBES`](crate::glint::kernels::gmm::GMM_LOBES) Gaussians per node, level by level.
//!
//! **Which footprints.** A footprint of at least
//! [`PatchOptions::filtered_area`](super::PatchOptions::filtered_area) elements (box-equivalent area
//! 12 √det Σ_P in element units) whose level's measured TV to the exact element sum
//! (src/glint/kernels/filtered_error.rs) is at most
//! [`PatchOptions::filtered_tolerance`](super::PatchOptions::filtered_tolerance). The chain and the
//! errors are made by the build (~20 ns per element for the chain, ~0.1-0.5 s per map for the
//! errors) and stored in files, so that a map holds no state filled on first use.

use super::{PatchOptions, PositionNormalMap, SIGMA_H_PER_SPACING};
use crate::glint::kernels::cut::{self, CutKernel, CutStats};
use crate::glint::kernels::filtered_error;
use crate::glint::kernels::gmm::GmmPyramid;
use crate::glint::kernels::lobe_set::LobeSet;
use crate::glint::{Footprint, GlintNdf};
use crate::ndf::SlopeGaussian;
use glam::{Mat2, Vec2};

/// The footprint's centre (element units, element i centred at i + ½) and box-equivalent area
/// 12 √det Σ_P (elements), Σ_P the footprint's Gaussian before any query cap.
pub(super) fn footprint_in_elements(
    map: &PositionNormalMap,
    footprint: &Footprint,
) -> ([f64; 2], f64) {
    let (c, s) = footprint.gaussian_texels(map.width, map.height);
    let h2 = map.spacing * map.spacing;
    let det = (s.x_axis.x as f64 * s.y_axis.y as f64 - (s.y_axis.x as f64).powi(2)).max(0.0);
    (
        [c.x as f64 / map.spacing, c.y as f64 / map.spacing],
        12.0 * det.sqrt() / h2,
    )
}

impl PositionNormalMap {
    /// Element k's slope marginal over its own position Gaussian, N(ñ_k, σ_h² J_k J_kᵀ + σ_r² I)
    /// (module docs), as a [`SlopeGaussian`].
    pub(super) fn element_marginal(&self, k: usize) -> SlopeGaussian {
        let e = &self.elements[k];
        let sh = SIGMA_H_PER_SPACING * self.spacing;
        let j = Mat2::from_cols(Vec2::new(e[2], e[4]), Vec2::new(e[3], e[5])) * sh as f32;
        let var_r = self.params.sigma_r * self.params.sigma_r;
        let cov = j * j.transpose() + Mat2::from_diagonal(Vec2::splat(var_r));
        let mean = Vec2::new(e[0], e[1]);
        SlopeGaussian::new(mean, cov).unwrap_or_else(|_| {
            SlopeGaussian::from_moments(
                [
                    mean.x,
                    mean.y,
                    cov.x_axis.x + mean.x * mean.x,
                    cov.y_axis.y + mean.y * mean.y,
                    cov.x_axis.y + mean.x * mean.y,
                ],
                self.params.sigma_r,
            )
        })
    }

    /// The filtered-mixture chain over the elements.
    pub(super) fn filtered_chain(&self) -> &GmmPyramid {
        &self.filtered
    }

    /// The filtered mixture's measured TV to the exact element sum per level of its chain (index
    /// l: footprints of 4^l elements; 1 where not measured, below the first measured level; empty
    /// on maps too small to measure any level): what [`PatchOptions::filtered_tolerance`] is
    /// compared with. Measured by the build (deterministic) and stored in files; see
    /// src/glint/kernels/filtered_error.rs.
    pub fn filtered_mixture_errors(&self) -> &[f32] {
        &self.filtered_error
    }

    /// Measures [`PositionNormalMap::filtered_mixture_errors`] (the build's last step).
    pub(super) fn measure_filtered_errors(&self) -> Vec<f32> {
        let [nx, ny] = self.grid;
        let full = PatchOptions {
            max_query_texels: f32::INFINITY,
            filtered_area: f32::INFINITY,
            cut_nodes: 0,
            ..PatchOptions::default()
        };
        let filtered = PatchOptions {
            filtered_area: 0.0,
            filtered_tolerance: f32::INFINITY,
            ..full
        };
        filtered_error::errors_per_level(
            self.filtered_chain().levels(),
            (nx * ny) as f64,
            [self.spacing, self.spacing],
            (self.width, self.height),
            |fp| {
                let exact = self.patch_with(fp, &full, None);
                let few = self.patch_with(fp, &filtered, None);
                few.is_filtered_mixture()
                    .then(|| filtered_error::tv(&exact, &few))
            },
        )
    }

    /// Whether `options` serve a footprint centred at `c` of `area` elements (as
    /// [`footprint_in_elements`] gives them) by the filtered mixture; if so, its lobes into `set`
    /// and its measured error at the footprint's level returned.
    pub(super) fn filtered_mixture(
        &self,
        c: [f64; 2],
        area: f64,
        options: &PatchOptions,
        set: &mut LobeSet,
    ) -> Option<f32> {
        // NaN options compare false: never served.
        let large = area >= options.filtered_area as f64;
        if !large {
            return None;
        }
        let lod = 0.5 * area.max(1e-300).log2();
        let tolerance = options.filtered_tolerance;
        let error = filtered_error::error_at(self.filtered_mixture_errors(), lod);
        if !(tolerance == f32::INFINITY || error <= tolerance) {
            return None;
        }
        self.filtered_chain()
            .lookup(|k| self.element_marginal(k), c, lod, set);
        (set.len() > 0).then_some(error)
    }

    /// A cut of the filtered-mixture hierarchy for `footprint` (src/glint/kernels/cut.rs) into
    /// `set`: the elements' position weights N(u_i; c_P, Σ_P + σ_h² I) in element units, leaves the
    /// elements' slope marginals (as the chain's level 0).
    pub(super) fn cut(
        &self,
        footprint: &Footprint,
        options: &PatchOptions,
        set: &mut LobeSet,
    ) -> CutStats {
        let (c, s) = footprint.gaussian_texels(self.width, self.height);
        let h = self.spacing;
        let h2 = h * h;
        let sh2 = SIGMA_H_PER_SPACING * SIGMA_H_PER_SPACING;
        let kernel = CutKernel {
            c: [c.x as f64 / h, c.y as f64 / h],
            s: [
                s.x_axis.x as f64 / h2 + sh2,
                s.x_axis.y as f64 / h2,
                s.y_axis.y as f64 / h2 + sh2,
            ],
            weight_sigmas: self.params.weight_sigmas as f64,
        };
        cut::cut(
            self.filtered_chain(),
            |k| self.element_marginal(k),
            kernel,
            options.cut_tolerance,
            options.cut_nodes as usize,
            set,
        )
    }
}
