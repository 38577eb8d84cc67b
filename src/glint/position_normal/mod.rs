//! The position-normal distribution of \[Yan2016\]: one 4D Gaussian "element" in (position, slope) per
//! sample of a normal map, a Gaussian ray footprint, and the closed-form P-NDF of their product,
//! summed through a bounding-box hierarchy. The baseline that \[Chermain2019\] and \[Atanasov2020\]
//! compare against.
//!
//! - [`PositionNormalMap::build`] linearises the slope field of the interpolated normal map at each
//!   element centre (slope ñ_i and Jacobian J_i = ∂ñ/∂u by central differences) and stores them
//!   (6 `f32` per element), with an implicit quadtree of footprint-independent slope boxes.
//! - [`PositionNormalMap::patch`] turns a [`Footprint`] into a [`PositionNormalPatch`], an
//!   [`Ndf`](crate::ndf::Ndf) whose D_P is the closed-form integral over positions of footprint ×
//!   element, normalised by the total footprint weight (∫ D_P cos θ dω = 1).
//! - [`PositionNormalBrdf`] is the BRDF as published, f = F G D_P / (4 cos θo cos θi) with the Smith G
//!   of a fixed Beckmann lobe, kept so that its energy error can be measured.
//!
//! The derivation, the deviations from the paper and the defaults with their sources are in
//! docs/position_normal.md.

mod brdf;
mod build;
mod filtered;
mod geometry;
mod patch;
mod store;

pub use brdf::{DEFAULT_MASKING_ALPHA, PositionNormalBrdf};
pub use patch::{EXACT_MASKING_ELEMENTS, PositionNormalPatch};

use crate::error::{Error, Result, positive};
use crate::glint::kernels::gmm::GmmPyramid;
use crate::glint::kernels::slope_tree::SlopeTree;
use crate::glint::{Footprint, GlintNdf, GlintScratch, NormalMap};
use glam::{Mat2, Vec2};
use std::sync::OnceLock;

/// Largest accepted truncation of the position weights, in standard deviations
/// ([`PositionNormalParams::weight_sigmas`]): 10, which keeps the enumerated region bounded.
pub const MAX_WEIGHT_SIGMAS: f32 = 10.0;

/// σ_h / h = 1/√(8 ln 2) (see [`PositionNormalMap::SIGMA_H_PER_SPACING`]).
pub(crate) const SIGMA_H_PER_SPACING: f64 = 0.424_660_900_144_009_5;

/// Build parameters of a [`PositionNormalMap`]: what the build needs, and nothing a query chooses
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
    fn validate(&self) -> Result<()> {
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

/// Per-query options of a position-normal patch (the [`GlintNdf::Options`] of
/// [`PositionNormalMap`]). Passed with every query ([`GlintNdf::patch_with`]); a map holds none and
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
    /// footprint's level ([`PositionNormalParams::DEFAULT_FILTERED_TOLERANCE`]; measured per map on
    /// first use, [`PositionNormalMap::filtered_mixture_errors`]) at which the filtered mixture
    /// serves a footprint of at least `filtered_area`; above it the elements are summed (under
    /// the cap `max_query_texels`). `f32::INFINITY` always serves it, NaN never.
    pub filtered_tolerance: f32,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            max_query_texels: PositionNormalParams::DEFAULT_MAX_QUERY_TEXELS,
            filtered_area: PositionNormalParams::DEFAULT_FILTERED_AREA,
            filtered_tolerance: PositionNormalParams::DEFAULT_FILTERED_TOLERANCE,
        }
    }
}

/// Memory held by a [`PositionNormalMap`], in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PositionNormalMemory {
    /// Number of elements.
    pub elements: usize,
    /// The elements' slopes and Jacobians (24 bytes each: 6 `f32`).
    pub element_bytes: usize,
    /// The slope-box quadtree (levels ≥ 1, 16 bytes per node).
    pub hierarchy_bytes: usize,
    /// The filtered mixture's chain (96 bytes per node of levels ≥ 1, ≤ 32 bytes per element),
    /// 0 until a footprint first needs it.
    pub filtered_bytes: usize,
}

/// The position-normal glint representation of a normal map (\[Yan2016\]).
///
/// The map's slope field ñ(u) (of the bilinearly interpolated normals, [`NormalMap::slope_at_texel`])
/// is covered by elements on a grid of spacing h = 1/`sampling_rate` texels, centred at
/// u_i = (i + ½) h. Element i is the 4D Gaussian
///
/// G_i(u, ñ) = h² N(u; u_i, σ_h² I) · N(ñ; ñ_i + J_i (u − u_i), σ_r² I),
///
/// the linearisation of the slope field at u_i (ñ_i = ñ(u_i), J_i = ∂ñ/∂u by central differences of
/// step h/2) blurred by the intrinsic roughness σ_r, with σ_h = h/√(8 ln 2). Stored per element: ñ_i
/// and J_i, 6 `f32` (24 bytes; the paper stores 12 floats, a public adaptation 11: position, normal,
/// per-axis σ, area and J); positions, σ_h, σ_r and the area h² are implicit in the regular grid.
/// Plus a quadtree of slope boxes (16 bytes per node above the elements, ~5.3 bytes per element).
///
/// # Reference
/// \[Yan2016\] §4 (elements), §5 (P-NDF of a Gaussian footprint, hierarchy).
#[derive(Clone, Debug)]
pub struct PositionNormalMap {
    width: usize,
    height: usize,
    grid: [usize; 2],
    /// Element spacing h in texels.
    spacing: f64,
    /// Per element: [ñx, ñy, ∂ñx/∂u, ∂ñx/∂v, ∂ñy/∂u, ∂ñy/∂v] (texel units).
    elements: Vec<[f32; 6]>,
    tree: SlopeTree,
    params: PositionNormalParams,
    /// The filtered mixture's chain (filtered.rs), built on the first footprint that needs it.
    filtered: OnceLock<GmmPyramid>,
    /// Its measured error per level, measured on first use.
    filtered_error: OnceLock<Vec<f32>>,
}

/// The element grid (width, height) × sampling rate, at most 2³¹ elements.
fn element_grid(width: usize, height: usize, params: &PositionNormalParams) -> Result<[usize; 2]> {
    let r = params.sampling_rate;
    let (nx, ny) = (width.saturating_mul(r), height.saturating_mul(r));
    if nx.checked_mul(ny).is_none_or(|n| n > (1usize << 31)) {
        return Err(Error::InvalidSize {
            width: nx,
            height: ny,
            reason: "the element grid (map size × sampling rate) exceeds 2^31 elements",
        });
    }
    Ok([nx, ny])
}

impl PositionNormalMap {
    /// The positional standard deviation of an element in units of the element spacing h:
    /// σ_h = h / √(8 ln 2) ≈ 0.4247 h, so that the Gaussian's full width at half maximum is h
    /// (\[Yan2016\] §4).
    pub const SIGMA_H_PER_SPACING: f64 = SIGMA_H_PER_SPACING;

    /// Builds the elements of `map` (parallel, deterministic whatever the thread count).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the invalid field of `params` (`sampling_rate`, `sigma_r`,
    /// `weight_sigmas`, `slope_sigmas`); [`Error::InvalidSize`] if the element grid
    /// would exceed 2³¹ elements.
    pub fn build(map: &NormalMap, params: PositionNormalParams) -> Result<Self> {
        params.validate()?;
        let (width, height) = (map.width(), map.height());
        let grid = element_grid(width, height, &params)?;
        let spacing = 1.0 / params.sampling_rate as f64;
        let elements = build::elements(map, grid, spacing);
        Ok(Self::assemble(width, height, grid, params, elements))
    }

    /// The representation of stored parts (crate-private; see `store.rs`): validates `params`,
    /// derives the element grid as [`PositionNormalMap::build`] does and checks the element count
    /// against it, then rebuilds the slope-box hierarchy exactly as the build does. The elements
    /// themselves are not checked here (the loader bounds them).
    pub(crate) fn from_parts(
        width: usize,
        height: usize,
        params: PositionNormalParams,
        elements: Vec<[f32; 6]>,
    ) -> Result<Self> {
        params.validate()?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))?;
        let grid = element_grid(width, height, &params)?;
        if elements.len() != grid[0] * grid[1] {
            return Err(Error::InvalidSize {
                width: grid[0],
                height: grid[1],
                reason: "the element count does not match the element grid of the map size and rate",
            });
        }
        Ok(Self::assemble(width, height, grid, params, elements))
    }

    /// The derived parts (slope boxes and their hierarchy) of given elements.
    fn assemble(
        width: usize,
        height: usize,
        grid: [usize; 2],
        params: PositionNormalParams,
        elements: Vec<[f32; 6]>,
    ) -> Self {
        let spacing = 1.0 / params.sampling_rate as f64;
        let sigma_h = SIGMA_H_PER_SPACING * spacing;
        // The element boxes are computed on the fly, once each, into level 1 of the tree (no
        // 16-byte-per-element level 0 is held).
        let tree = SlopeTree::build_with(grid[0], grid[1], |k| {
            build::slope_box(&elements[k], sigma_h, &params)
        });
        PositionNormalMap {
            width,
            height,
            grid,
            spacing,
            elements,
            tree,
            params,
            filtered: OnceLock::new(),
            filtered_error: OnceLock::new(),
        }
    }

    /// The parameters the representation was built with.
    pub fn params(&self) -> &PositionNormalParams {
        &self.params
    }

    /// The map size (width, height) in texels.
    pub fn map_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The element grid (nx, ny) = (width, height) × sampling rate.
    pub fn grid(&self) -> (usize, usize) {
        (self.grid[0], self.grid[1])
    }

    /// The element spacing h in texels (1 / sampling rate).
    pub fn spacing(&self) -> f32 {
        self.spacing as f32
    }

    /// The positional standard deviation σ_h = h / √(8 ln 2) in texels.
    ///
    /// # Reference
    /// \[Yan2016\] §4.
    pub fn sigma_h(&self) -> f32 {
        (SIGMA_H_PER_SPACING * self.spacing) as f32
    }

    /// Element (i, j) of the grid (wrapping): its centre u_i in texels, its slope ñ_i and its Jacobian
    /// J_i = ∂ñ/∂u (per texel; columns ∂/∂u and ∂/∂v).
    pub fn element(&self, i: i64, j: i64) -> (Vec2, Vec2, Mat2) {
        let (nx, ny) = (self.grid[0] as i64, self.grid[1] as i64);
        let (iw, jw) = (i.rem_euclid(nx), j.rem_euclid(ny));
        let e = self.elements[(jw * nx + iw) as usize];
        let h = self.spacing;
        let centre = Vec2::new(
            ((iw as f64 + 0.5) * h) as f32,
            ((jw as f64 + 0.5) * h) as f32,
        );
        let jac = Mat2::from_cols(Vec2::new(e[2], e[4]), Vec2::new(e[3], e[5]));
        (centre, Vec2::new(e[0], e[1]), jac)
    }

    /// Bytes held by the elements and the hierarchy.
    pub fn memory(&self) -> PositionNormalMemory {
        PositionNormalMemory {
            elements: self.elements.len(),
            element_bytes: self.elements.len() * 24,
            hierarchy_bytes: self.tree.bytes(),
            filtered_bytes: self.filtered.get().map_or(0, GmmPyramid::bytes),
        }
    }
}

impl GlintNdf for PositionNormalMap {
    type Patch<'a> = PositionNormalPatch<'a>;
    type Options = PatchOptions;

    /// The position-normal P-NDF of a footprint ([`PositionNormalPatch`]) at the level of detail
    /// of `options`: the filtered mixture where it serves, else the element sum under the query
    /// cap.
    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> PositionNormalPatch<'a> {
        PositionNormalPatch::new(self, footprint, options, scratch)
    }

    /// Builds the filtered mixture's chain and measures its errors
    /// ([`PositionNormalMap::filtered_mixture_errors`]).
    fn prepare(&self) {
        self.filtered_mixture_errors();
    }
}
