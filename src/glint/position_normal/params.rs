//! Build parameters and per-query options of the position-normal model: [`PositionNormalParams`]
//! (what the build needs, validated), [`PatchOptions`] (what a query chooses) and their documented
//! `DEFAULT_*` values.

use crate::error::{Error, Result, positive};

/// Largest accepted truncation of the position weights, in standard deviations
/// ([`PositionNormalParams::weight_sigmas`]): 10, which keeps the enumerated region bounded.
pub const MAX_WEIGHT_SIGMAS: f32 = 10.0;

/// σ_h / h = 1/√(8 ln 2) (see
/// [`PositionNormalMap::SIGMA_H_PER_SPACING`](super::PositionNormalMap::SIGMA_H_PER_SPACING)).
pub(crate) const SIGMA_H_PER_SPACING: f64 = 0.424_660_900_144_009_5;

/// Build parameters of a [`PositionNormalMap`](super::PositionNormalMap): what the build needs, and
/// nothing a query chooses
/// (the footprint cap is a per-query [`PatchOptions`] field). `Default` gives the documented
/// associated `DEFAULT_*` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionNormalParams {
    /// Elements per texel side (≥ 1): the element spacing is h = 1 / rate texels.
    pub sampling_rate: usize,
    /// Intrinsic roughness σ_r: slope standard deviation of each element (in [10⁻⁴, 1]).
    pub sigma_r: f32,
    /// Truncation of the position weights, in σ (in [2, [`MAX_WEIGHT_SIGMAS`]]).
    pub weight_sigmas: f32,
    /// Truncation of the element slope densities, in σ per axis (> 0).
    pub slope_sigmas: f32,
}

impl PositionNormalParams {
    /// Default sampling rate: one element per texel side, centred on the texel centres
    /// (\[Yan2016\] §4; \[Atanasov2020\] Fig. 1 compares against "one Gaussian element per texel").
    pub const DEFAULT_SAMPLING_RATE: usize = 1;

    /// Default intrinsic roughness σ_r = 0.005, the slope standard deviation of every element around its
    /// linearised slope (\[Atanasov2020\] Fig. 1 caption: Yan 2016 rendered with one element per texel
    /// and σ_r = 0.005).
    pub const DEFAULT_SIGMA_R: f32 = 0.005;

    /// Default truncation of the position weights, in standard deviations: elements whose centre lies
    /// outside the ellipse of Mahalanobis radius 3 of the Gaussian footprint ∗ element kernel are left
    /// out (the released code truncates elements and footprints at 3 σ).
    pub const DEFAULT_WEIGHT_SIGMAS: f32 = 3.0;

    /// Default truncation of an element's slope density, in standard deviations per axis: 4 (the
    /// released code's normal truncation). D_P ignores an element outside its slope box, so D_P
    /// integrates to at least 1 − 4 Q(4) ≈ 1 − 1.3·10⁻⁴ (Q the normal tail).
    pub const DEFAULT_SLOPE_SIGMAS: f32 = 4.0;

    /// Default cap on the footprint ([`PatchOptions::max_query_texels`]): its standard deviation
    /// along each principal axis is clamped so that `weight_sigmas` · σ ≤ 128 texels (the released
    /// code's maximum query range, which bounds the per-patch work of the element sum where the
    /// filtered mixture does not serve).
    pub const DEFAULT_MAX_QUERY_TEXELS: f32 = 128.0;

    /// Default footprint area, in elements, from which a patch may be the filtered mixture
    /// ([`PatchOptions::filtered_area`]): 4096, the mixture's
    /// ([`crate::glint::mixture::DEFAULT_FILTERED_AREA`]), where the element sum costs ~10⁴
    /// element lobes per query (docs/results.md, "Cost and error of a shading point against
    /// footprint").
    pub const DEFAULT_FILTERED_AREA: f32 = 4096.0;

    /// Default tolerance of the filtered mixture ([`PatchOptions::filtered_tolerance`]): the
    /// largest measured TV to the exact element sum at which it serves, the mixture's
    /// ([`crate::glint::mixture::DEFAULT_FILTERED_TOLERANCE`]).
    pub const DEFAULT_FILTERED_TOLERANCE: f32 = 0.15;
}

impl Default for PositionNormalParams {
    fn default() -> Self {
        PositionNormalParams {
            sampling_rate: Self::DEFAULT_SAMPLING_RATE,
            sigma_r: Self::DEFAULT_SIGMA_R,
            weight_sigmas: Self::DEFAULT_WEIGHT_SIGMAS,
            slope_sigmas: Self::DEFAULT_SLOPE_SIGMAS,
        }
    }
}

impl PositionNormalParams {
    pub(super) fn validate(&self) -> Result<()> {
        if self.sampling_rate == 0 || self.sampling_rate > 64 {
            return Err(Error::InvalidParameter {
                name: "sampling_rate",
                value: self.sampling_rate as f64,
                reason: "must be in 1..=64 elements per texel side",
            });
        }
        if !(self.sigma_r >= 1e-4 && self.sigma_r <= 1.0) {
            return Err(Error::InvalidParameter {
                name: "sigma_r",
                value: self.sigma_r as f64,
                reason: "must be in [1e-4, 1] (a slope standard deviation; below 1e-4 the element \
                         densities leave the f32 range)",
            });
        }
        if !(self.weight_sigmas >= 2.0 && self.weight_sigmas <= MAX_WEIGHT_SIGMAS) {
            return Err(Error::InvalidParameter {
                name: "weight_sigmas",
                value: self.weight_sigmas as f64,
                reason: "must be in [2, 10]: >= 2 so that the element nearest to any footprint \
                         centre, at Mahalanobis distance <= 1.67, is always kept; <= 10 \
                         (MAX_WEIGHT_SIGMAS) so that the enumerated region stays bounded",
            });
        }
        positive("slope_sigmas", self.slope_sigmas)?;
        Ok(())
    }
}

/// Per-query options of a position-normal patch (the
/// [`GlintNdf::Options`](crate::glint::GlintNdf::Options) of
/// [`PositionNormalMap`](super::PositionNormalMap)). Passed with every query
/// ([`GlintNdf::patch_with`](crate::glint::GlintNdf::patch_with)); a map holds none and
/// its file stores none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchOptions {
    /// The cost cap of the element sum: the footprint is shrunk about its centre until
    /// `weight_sigmas` · σ_footprint ≤ this many texels (`f32::INFINITY` keeps the exact footprint
    /// whatever its size; values not > 0, NaN included, shrink the footprint to its centre).
    /// Applies where the filtered mixture does not serve. `Default` gives
    /// [`PositionNormalParams::DEFAULT_MAX_QUERY_TEXELS`]. docs/position_normal.md gives the cost
    /// against accuracy.
    pub max_query_texels: f32,
    /// Footprint area, in elements (box-equivalent area 12 √det Σ_P), at and above which the patch
    /// may be the filtered mixture ([`PositionNormalParams::DEFAULT_FILTERED_AREA`];
    /// `f32::INFINITY` or NaN never).
    pub filtered_area: f32,
    /// Largest measured TV between the filtered mixture and the exact element sum at the
    /// footprint's level ([`PositionNormalParams::DEFAULT_FILTERED_TOLERANCE`]; measured per map by
    /// the build,
    /// [`PositionNormalMap::filtered_mixture_errors`](super::PositionNormalMap::filtered_mixture_errors))
    /// at which the filtered mixture
    /// serves a footprint of at least `filtered_area`; above it the elements are summed (under
    /// the cap `max_query_texels`). `f32::INFINITY` always serves it, NaN never.
    pub filtered_tolerance: f32,
    /// Largest cut of the filtered-mixture hierarchy, in nodes (the mixture's
    /// [`DEFAULT_CUT_NODES`](crate::glint::mixture::DEFAULT_CUT_NODES), at most
    /// [`MAX_CUT_NODES`](crate::glint::mixture::MAX_CUT_NODES)); 0: no cut. A footprint of at
    /// least `cut_area` elements that the filtered mixture does not serve is served by the cut
    /// (src/glint/kernels/cut.rs) instead of the capped element sum.
    pub cut_nodes: u32,
    /// Footprint area, in elements, from which the cut serves (the mixture's
    /// [`DEFAULT_CUT_AREA`](crate::glint::mixture::DEFAULT_CUT_AREA); NaN never).
    pub cut_area: f32,
    /// Error budget of a node of the cut (the mixture's
    /// [`DEFAULT_CUT_TOLERANCE`](crate::glint::mixture::DEFAULT_CUT_TOLERANCE); NaN or ≤ 0: split
    /// until `cut_nodes`).
    pub cut_tolerance: f32,
}

impl Default for PatchOptions {
    fn default() -> Self {
        use crate::glint::kernels::cut::{
            DEFAULT_CUT_AREA, DEFAULT_CUT_NODES, DEFAULT_CUT_TOLERANCE,
        };
        PatchOptions {
            max_query_texels: PositionNormalParams::DEFAULT_MAX_QUERY_TEXELS,
            filtered_area: PositionNormalParams::DEFAULT_FILTERED_AREA,
            filtered_tolerance: PositionNormalParams::DEFAULT_FILTERED_TOLERANCE,
            cut_nodes: DEFAULT_CUT_NODES,
            cut_area: DEFAULT_CUT_AREA,
            cut_tolerance: DEFAULT_CUT_TOLERANCE,
        }
    }
}
