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
mod params;
mod patch;
mod store;

pub use brdf::{DEFAULT_MASKING_ALPHA, PositionNormalBrdf};
pub use params::{MAX_WEIGHT_SIGMAS, PatchOptions, PositionNormalParams};
pub use patch::{EXACT_MASKING_ELEMENTS, PositionNormalPatch};

use crate::error::{Error, Result};
use crate::glint::kernels::gmm::GmmPyramid;
use crate::glint::kernels::slope_tree::SlopeTree;
use crate::glint::{Footprint, GlintNdf, GlintScratch, NormalMap};
use glam::{Mat2, Vec2};
use params::SIGMA_H_PER_SPACING;

/// Memory held by a [`PositionNormalMap`], in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PositionNormalMemory {
    /// Number of elements.
    pub elements: usize,
    /// The elements' slopes and Jacobians (24 bytes each: 6 `f32`).
    pub element_bytes: usize,
    /// The slope-box quadtree (levels ≥ 1, 16 bytes per node).
    pub hierarchy_bytes: usize,
    /// The filtered mixture's chain, built with the map (96 bytes per node of levels ≥ 2 and a
    /// 12-byte residual per node of levels ≥ 1, ≤ 12 bytes per element; level 1's components are
    /// its elements' marginals, served from them).
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
    /// The filtered mixture's chain (filtered.rs), built with the elements (or read from a file).
    filtered: GmmPyramid,
    /// Its measured error per level, measured by the build (or read from a file).
    filtered_error: Vec<f32>,
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
        Ok(Self::assemble(width, height, grid, params, elements, None).measured())
    }

    /// The representation of stored parts (crate-private; see `store.rs`): validates `params`,
    /// derives the element grid as [`PositionNormalMap::build`] does and checks the element count
    /// against it, then rebuilds the slope-box hierarchy exactly as the build does; the filtered
    /// mixture's chain and measured errors are `chain` when given (read from a file, checked
    /// against the grid by the loader), else built and measured as the build does. The elements
    /// themselves are not checked here (the loader bounds them).
    pub(crate) fn from_parts(
        width: usize,
        height: usize,
        params: PositionNormalParams,
        elements: Vec<[f32; 6]>,
        chain: Option<(GmmPyramid, Vec<f32>)>,
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
        Ok(match chain {
            Some((gmm, errors)) => {
                let mut map = Self::assemble(width, height, grid, params, elements, Some(gmm));
                map.filtered_error = errors;
                map
            }
            None => Self::assemble(width, height, grid, params, elements, None).measured(),
        })
    }

    /// The map with its filtered mixture's errors measured (filtered.rs).
    fn measured(mut self) -> Self {
        self.filtered_error = self.measure_filtered_errors();
        self
    }

    /// The derived parts (slope boxes and their hierarchy, the filtered mixture's chain unless
    /// given) of given elements; no measured errors yet.
    fn assemble(
        width: usize,
        height: usize,
        grid: [usize; 2],
        params: PositionNormalParams,
        elements: Vec<[f32; 6]>,
        filtered: Option<GmmPyramid>,
    ) -> Self {
        let spacing = 1.0 / params.sampling_rate as f64;
        let sigma_h = SIGMA_H_PER_SPACING * spacing;
        // The element boxes are computed on the fly, once each, into level 1 of the tree (no
        // 16-byte-per-element level 0 is held).
        let tree = SlopeTree::build_with(grid[0], grid[1], |k| {
            build::slope_box(&elements[k], sigma_h, &params)
        });
        let mut map = PositionNormalMap {
            width,
            height,
            grid,
            spacing,
            elements,
            tree,
            params,
            filtered: GmmPyramid::empty(),
            filtered_error: Vec::new(),
        };
        let chain = filtered.unwrap_or_else(|| {
            GmmPyramid::build(
                grid[0],
                grid[1],
                |k| map.element_marginal(k),
                params.sigma_r,
            )
        });
        map.filtered = chain;
        map
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
            filtered_bytes: self.filtered.bytes(),
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
}
