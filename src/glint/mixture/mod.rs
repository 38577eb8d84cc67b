//! The Beckmann-mixture P-NDF of \[Chermain2019\]: one non-centred anisotropic Beckmann lobe per seed
//! point of a normal map, Gaussian position weights, exact or approximate patch masking, and a
//! bounding-box hierarchy that keeps D_P evaluations local.
//!
//! - [`BeckmannMixture::build`] integrates the five slope moments of the *interpolated* normal map
//!   under each seed kernel k_i (eq. 5-6) and stores them (5 `f32` per lobe), with an implicit
//!   quadtree of slope boxes (§5), a mip chain of the moments (§4.2.2), and the lobes again as
//!   structure-of-arrays blocks of 4 × 4 with their P22 and masking coefficients precomputed in `f32`
//!   (blocks.rs), which the per-direction queries evaluate 16 lanes at a time; and levels of detail
//!   l ≥ 1 of merged lobes stored the same way, with a per-node merge-error bound (levels.rs).
//! - [`BeckmannMixture::patch`] turns a [`Footprint`] into a [`MixturePatch`], an [`Ndf`](crate::ndf::Ndf) whose
//!   D_P(h) = Σ W_i D_i(h) (eq. 9) and whose masking terms are exact (eq. 10-17) or approximate
//!   (§4.2.2), so that `MicrofacetBrdf::new(patch, fresnel)` is the P-BRDF of eq. 7; on the
//!   coarsest level of detail whose error bound meets [`PatchOptions::lod_tolerance`].
//!
//! The model, the hierarchy layout, the deviations from the paper and the defaults with their
//! measurements are in docs/mixture.md.

mod blocks;
mod build;
mod build_filter;
mod compact;
mod hierarchy;
mod levels;
mod patch;
mod store;

pub use build_filter::DEFAULT_SUPERSAMPLING;
pub use patch::MixturePatch;

use crate::error::{Error, Result, positive};
use crate::glint::kernels::slope_tree::SlopeTree;
use crate::glint::{Footprint, GlintNdf, NormalMap};
use crate::ndf::SlopeGaussian;
use blocks::LobeBlocks;
use compact::CompactLevel;
use hierarchy::LobePyramid;
use levels::{LevelRef, LobeLevel, build_levels};

/// Default seed spacing h = 1 texel: one lobe per texel, at the texel centres (\[Chermain2019\] §5.1.1).
pub const DEFAULT_SPACING: f32 = 1.0;

/// Default floor σ_ε = 0.01 of the lobes' slope standard deviation (\[Chermain2019\] §3.2).
pub const DEFAULT_SIGMA_MIN: f32 = crate::ndf::DEFAULT_SIGMA_MIN;

/// Smallest accepted seed spacing h: 1/8 texel. The interpolated map is bilinear per texel, so finer
/// lobes add memory (∝ 1/h²) without new slope information.
pub const MIN_SPACING: f32 = 0.125;

/// Largest accepted truncation, in standard deviations, of the seed kernels and position weights
/// (`kernel_sigmas`, `weight_sigmas`, and the position-normal map's `weight_sigmas`): 10.
pub const MAX_TRUNCATION_SIGMAS: f32 = 10.0;

/// Default number of quasi-Monte Carlo nodes per lobe for the moments (eq. 6) when
/// [`MixtureParams::moments`] is [`MomentMethod::Qmc`].
///
/// Measured (docs/results.md, `accuracy_table` test, 64² crops of the four procedural maps): the
/// largest error of any lobe's slope standard deviation against 16384 nodes is 0.29-0.87 σ_ε at 256
/// nodes (1.0-2.5 σ_ε at 64, 2.9-7.6 σ_ε at 16), the largest mean-slope error 1.7e-3-4.3e-3. Cost is
/// linear in the count (one interpolated-normal lookup per node).
pub const DEFAULT_SAMPLES: usize = 256;

/// Default truncation of the seed kernel k_i for the moment integral, in standard deviations per
/// axis: ±3 σ, the support \[Chermain2019\] §5 gives k_i (the box holds 99.46 % of its mass; the moments
/// are those of the truncated kernel).
pub const DEFAULT_KERNEL_SIGMAS: f32 = 3.0;

/// Default truncation of the position weights W_i: lobes whose centre lies more than this many
/// standard deviations of k_i ∗ k_P from the footprint centre, along either axis, are left out
/// (then the kept weights are renormalised to sum to 1). 3, as the paper's ±3σ boxes.
pub const DEFAULT_WEIGHT_SIGMAS: f32 = 3.0;

/// Default tail mass left outside a lobe's slope bounding box: 10⁻⁶.
///
/// The box is that of the ellipse holding 1 − tail of the lobe, k² = −2 ln(tail) (k = 5.26 here);
/// D_P ignores a lobe outside its box, so D_P integrates to at least 1 − tail and the samplers (which
/// draw the untruncated lobes) disagree with the pdf by at most `tail` in total variation. The paper
/// uses the 99 % box (tail 0.01, k = 3.03): 1.8× fewer lobes touched per query (docs/mixture.md) but
/// a normalisation error up to 1 %.
pub const DEFAULT_SLOPE_TAIL: f32 = 1.0e-6;

/// Default cost cap of the level of detail: a patch whose footprint covers more than this many
/// nodes (area in cells of the chosen level) moves to coarser levels, whatever the tolerance; when
/// no level is coarse enough (grids that do not halve evenly), it is served by the single filtered
/// lobe (D, masking and sampling).
///
/// A cost bound, not an accuracy one: `d` costs ~20-40 ns per touched lobe, so 16384 nodes bound a
/// query to ~0.1-1 ms (docs/results.md). Set `f32::INFINITY` to let only the tolerance decide. Before
/// issue 15 this threshold switched straight to the filtered lobe (a cliff in accuracy, 4-26× the
/// TV); it now picks the finest level of merged lobes under the cap. See docs/mixture.md.
pub const DEFAULT_LOD_LOBES: f32 = 16384.0;

/// Default level-of-detail tolerance: the bound Σ W_n e_r(n) on the total variation between a
/// patch of merged lobes and the full mixture that a patch may spend (e_r(n) the merge error of
/// node n at the slope resolution r = [`PatchOptions::lod_resolution`], src/glint/mixture/levels.rs).
/// 0 keeps the full mixture.
///
/// Since |TV(lod, R) − TV(full, R)| ≤ TV(lod, full) for any reference R, at r = 0 the tolerance
/// bounds the increase of the TV to any (binned) ground truth, up to the node-weight approximation
/// (docs/mixture.md); at r > 0 it bounds the increase seen through a Gaussian blur of std r. 0.01 is
/// issue 15's budget for that increase; the footprint sweep of docs/results.md ("Levels of detail
/// chosen by error") measured +0.013 at 0.1 on the scratched map (within that tolerance, over the
/// 0.01 budget) for 5× cheaper `d`. At 0.01 the tolerance alone merged nothing on the 512² maps of
/// that sweep at r = 0, 0.01 or 0.04: merged levels there change the P-NDF's shape by more than
/// 0.01 (docs/mixture.md, "Why merged levels lose"), and levels ≥ 1 come from the cost cap.
pub const DEFAULT_LOD_TOLERANCE: f32 = 0.01;

/// The slope resolutions r at which the levels store their merge-error bounds (slope units, an
/// isotropic Gaussian's standard deviation): a patch reads the bound at the largest of these ≤
/// [`PatchOptions::lod_resolution`], which also bounds the error at that resolution (the TV of
/// blurred densities can only shrink as the blur grows). 0 is the continuous bound.
pub const LOD_RESOLUTIONS: [f32; 3] = [0.0, 0.01, 0.04];

/// Default resolution of the level-of-detail error: r = 0.01 in slope (~0.57° of normal
/// direction), the standard deviation of an isotropic Gaussian blur applied to both P-NDFs before
/// their total variation is bounded (src/glint/mixture/levels.rs).
///
/// Why 0.01: the ground truth the crate measures against is binned on 64² equal-area hemisphere
/// bins, 0.039 wide in slope near the normal, whose uniform spread has a standard deviation of
/// 0.039/√12 = 0.011; and a renderer sees the P-NDF through its lights: a light of angular radius ρ
/// moves the half vector by ρ/2, so 0.01 is the spread of a light about 4.6° across (a sun, 0.53°,
/// blurs by 0.0012; r = 0 keeps the continuous bound for point lights). Measured effect in
/// docs/results.md "Levels of detail chosen by error (issue 15)".
pub const DEFAULT_LOD_RESOLUTION: f32 = 0.01;

/// How the build integrates each lobe's five slope moments (\[Chermain2019\] eq. 6).
///
/// Both integrate the same quantity (the interpolated map's slopes under the seed kernel truncated
/// at ±`kernel_sigmas` σ per axis); they differ in cost and quadrature error. Measured against a
/// converged 65 536-node QMC reference (docs/mixture.md, docs/results.md "Fast build (issue 15)").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MomentMethod {
    /// A separable filter of the interpolated map sampled on a grid of `supersampling` nodes per
    /// texel per axis (rounded up to even; multiplied by 1/h for spacings h < 1), linear between nodes
    /// and integrated exactly against the kernel; processed in parallel bands of lobe rows. Cost per
    /// lobe ~ (supersampling · h)² node lookups plus two short 1D filters; error O(1/supersampling²).
    /// `supersampling` in [1, 64].
    Filter {
        /// Nodes per texel per axis ([`DEFAULT_SUPERSAMPLING`]).
        supersampling: u32,
    },
    /// Quasi-Monte Carlo with [`MixtureParams::samples`] nodes per lobe (an R2 point set mapped
    /// through the truncated Gaussian's inverse cdf): the build of versions before issue 15, kept
    /// for reproducing their moments bit for bit.
    Qmc,
}

impl Default for MomentMethod {
    fn default() -> Self {
        MomentMethod::Filter {
            supersampling: DEFAULT_SUPERSAMPLING,
        }
    }
}

/// Largest accepted [`MomentMethod::Filter`] supersampling: 64 nodes per texel per axis (the
/// node rows a band holds grow with it; the quadrature error is already ~1e-3 of 4's).
pub const MAX_SUPERSAMPLING: u32 = 64;

/// How a [`BeckmannMixture`] holds its lobes in memory (and in files).
///
/// Trade-off (docs/mixture.md, "Compact storage"; measured in docs/results.md): `Compact` holds
/// ≤ 16 bytes per lobe in all (against ~84 for `Full`) and loads several times faster, at the cost
/// of a per-block decode in every query (`d`, the exact masking and the visible sampler run slower,
/// see the results) and of an encoding error far below the mixture's own (mean slopes to 16 bits
/// inside their block's slope box, the inverse Cholesky factor to binary16: TV change against the
/// ground truth ≤ 0.002 measured). Either way the model is self-consistent: `d`, the masking terms,
/// the samplers and their pdfs all read the same stored lobes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum LobeStorage {
    /// The raw moments (20 B per lobe), the lobe blocks in `f32` (32 B), the quadtree, the moment
    /// mip chain and the levels of detail in the same form: ~84 bytes per lobe, the fastest queries.
    #[default]
    Full,
    /// Every level of detail only as compact blocks (per lobe the mean slope as two `u16` inside its
    /// block's slope box and the scaled inverse Cholesky factor as three binary16: 10 bytes), the
    /// quadtree from the block level up, one-byte merge errors rounded up, no moments and no mip
    /// chain (the filtered lobe comes from the levels of detail): ≤ 16 bytes per lobe in all.
    /// Needs `sigma_min` ≥ [`MIN_COMPACT_SIGMA`].
    Compact,
}

/// Smallest `sigma_min` accepted with [`LobeStorage::Compact`]: 2·10⁻⁵. Every entry of the scaled
/// inverse Cholesky factor is at most √(½ log₂ e)/σ_min in magnitude (the covariance floor keeps every
/// direction's σ ≥ σ_min), which must stay below binary16's largest value 65504.
pub const MIN_COMPACT_SIGMA: f32 = 2.0e-5;

/// Default masking mode of patches.
pub const DEFAULT_MASKING: MaskingMode = MaskingMode::Exact;

/// How a patch computes A_P, Λ_P (and so G1, G2 and the P-BRDF's normalisation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum MaskingMode {
    /// Exact: V_P(w) = Σ W_i V_i(w) over every lobe of the footprint, A_P(w) from the patch mean
    /// slope (\[Chermain2019\] eq. 13-17). O(lobes) per direction.
    #[default]
    Exact,
    /// Approximate: A_P from the patch mean slope (exact) and V_P bounded from above by Scarf's
    /// bound on the patch's slope mean and covariance, gathered once per patch. O(1) per
    /// direction. Sound where the paper's filtered-lobe Λ (\[Chermain2019\] §4.2.2) is not: V is never
    /// under-estimated, so the white furnace stays ≤ 1; the price is darker grazing views (the bound
    /// over-shadows; docs/results.md, "Beckmann mixture").
    Approximate,
}

/// Per-patch options: the masking mode and the level of detail (error tolerance and cost cap).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchOptions {
    /// Exact or approximate masking terms ([`DEFAULT_MASKING`]).
    pub masking: MaskingMode,
    /// Cost cap ([`DEFAULT_LOD_LOBES`]): footprints of more than this many nodes of the chosen
    /// level move to coarser levels (the filtered lobe alone when none is coarse enough);
    /// `f32::INFINITY` disables the cap.
    pub lod_lobes: f32,
    /// Error tolerance of the level of detail ([`DEFAULT_LOD_TOLERANCE`]): a patch uses the
    /// coarsest level of merged lobes whose weighted merge-error bound Σ W_n e(n) is at most this
    /// (and whose nodes are no wider than half the footprint's smaller standard deviation); 0 keeps the
    /// full mixture (level 0), unless the cost cap moves it. Not stored in saved files.
    pub lod_tolerance: f32,
    /// Slope resolution r of the tolerance's error ([`DEFAULT_LOD_RESOLUTION`], slope units): the
    /// bound Σ W_n e_r(n) is on the TV between the two P-NDFs after both are blurred by an isotropic
    /// Gaussian of standard deviation r in slope space, read at the largest r of
    /// [`LOD_RESOLUTIONS`] not above this. 0: the continuous TV (the bound before this option). Not
    /// stored in saved files.
    pub lod_resolution: f32,
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            masking: DEFAULT_MASKING,
            lod_lobes: DEFAULT_LOD_LOBES,
            lod_tolerance: DEFAULT_LOD_TOLERANCE,
            lod_resolution: DEFAULT_LOD_RESOLUTION,
        }
    }
}

/// Build parameters of a [`BeckmannMixture`]. `Default` gives the documented `DEFAULT_*` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MixtureParams {
    /// Seed spacing h in texels (≥ [`MIN_SPACING`]). The lobe grid has max(1, round(width / h)) × max(1,
    /// round(height / h)) lobes, so the spacing actually used per axis is width / nx (height / ny):
    /// an integer number of lobes tiles the map.
    pub spacing: f32,
    /// Floor σ_ε of the lobes' slope standard deviation (> 0).
    pub sigma_min: f32,
    /// Quasi-Monte Carlo nodes per lobe for the moments (≥ 1), used when `moments` is
    /// [`MomentMethod::Qmc`].
    pub samples: usize,
    /// Truncation of k_i for the moment integral, in σ (in (0, [`MAX_TRUNCATION_SIGMAS`]]).
    pub kernel_sigmas: f32,
    /// Truncation of the position weights, in σ (in (0, [`MAX_TRUNCATION_SIGMAS`]]).
    pub weight_sigmas: f32,
    /// Mass left outside each lobe's slope box (0 < tail < 1).
    pub slope_tail: f32,
    /// Options of the patches made by [`GlintNdf::patch`].
    pub patch: PatchOptions,
    /// How the moments are integrated ([`MomentMethod::default`]: the filter). Not stored in saved
    /// files (a loaded mixture reads its moments and reports the default here).
    pub moments: MomentMethod,
    /// How the lobes are held ([`LobeStorage::Full`] by default). Stored in files (as the model
    /// kind, docs/format.md).
    pub storage: LobeStorage,
}

impl Default for MixtureParams {
    fn default() -> Self {
        MixtureParams {
            spacing: DEFAULT_SPACING,
            sigma_min: DEFAULT_SIGMA_MIN,
            samples: DEFAULT_SAMPLES,
            kernel_sigmas: DEFAULT_KERNEL_SIGMAS,
            weight_sigmas: DEFAULT_WEIGHT_SIGMAS,
            slope_tail: DEFAULT_SLOPE_TAIL,
            patch: PatchOptions::default(),
            moments: MomentMethod::default(),
            storage: LobeStorage::default(),
        }
    }
}

impl MixtureParams {
    fn validate(&self) -> Result<()> {
        if !(self.spacing >= MIN_SPACING && self.spacing.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "spacing",
                value: self.spacing as f64,
                reason: "must be finite and >= 0.125 texel (MIN_SPACING: finer lobes repeat the \
                         bilinear map's moments and multiply memory by 1/h²)",
            });
        }
        positive("sigma_min", self.sigma_min)?;
        for (name, v) in [
            ("kernel_sigmas", self.kernel_sigmas),
            ("weight_sigmas", self.weight_sigmas),
        ] {
            if !(v > 0.0 && v <= MAX_TRUNCATION_SIGMAS) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v as f64,
                    reason: "must be in (0, 10] (MAX_TRUNCATION_SIGMAS: beyond 10 σ a Gaussian \
                             holds < 1e-22 of its mass, and the enumerated region grows as its square)",
                });
            }
        }
        if self.samples == 0 {
            return Err(Error::InvalidParameter {
                name: "samples",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if let MomentMethod::Filter { supersampling } = self.moments
            && !(1..=MAX_SUPERSAMPLING).contains(&supersampling)
        {
            return Err(Error::InvalidParameter {
                name: "supersampling",
                value: supersampling as f64,
                reason: "must be in [1, 64] (MAX_SUPERSAMPLING)",
            });
        }
        if self.storage == LobeStorage::Compact
            && (self.sigma_min.is_nan() || self.sigma_min < MIN_COMPACT_SIGMA)
        {
            return Err(Error::InvalidParameter {
                name: "sigma_min",
                value: self.sigma_min as f64,
                reason: "must be >= 2e-5 (MIN_COMPACT_SIGMA) with LobeStorage::Compact: the \
                         inverse Cholesky factors must fit binary16",
            });
        }
        if !(self.slope_tail > 0.0 && self.slope_tail < 1.0) {
            return Err(Error::InvalidParameter {
                name: "slope_tail",
                value: self.slope_tail as f64,
                reason: "must be in (0, 1)",
            });
        }
        if self.patch.lod_lobes.is_nan() || self.patch.lod_lobes < 0.0 {
            return Err(Error::InvalidParameter {
                name: "lod_lobes",
                value: self.patch.lod_lobes as f64,
                reason: "must be >= 0 (infinity disables the level of detail)",
            });
        }
        let t = self.patch.lod_tolerance;
        if !(t >= 0.0 && t.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "lod_tolerance",
                value: t as f64,
                reason: "must be finite and >= 0 (0 keeps the full mixture)",
            });
        }
        let r = self.patch.lod_resolution;
        if !(r >= 0.0 && r.is_finite()) {
            return Err(Error::InvalidParameter {
                name: "lod_resolution",
                value: r as f64,
                reason: "must be finite and >= 0 (0: the continuous bound)",
            });
        }
        Ok(())
    }
}

/// Memory held by a [`BeckmannMixture`], in bytes.
///
/// Under [`LobeStorage::Compact`]: `lobe_bytes` and `mip_bytes` are 0 (no moments, no mip chain),
/// `block_bytes` holds level 0's compact blocks (160 bytes per 4 × 4 lobes), `hierarchy_bytes` its
/// quadtree from level 2 up, and `level_bytes` the levels l ≥ 1 in the same form with one byte of
/// merge error per node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MixtureMemory {
    /// Number of lobes.
    pub lobes: usize,
    /// The lobes' moments (20 bytes each).
    pub lobe_bytes: usize,
    /// The slope-box quadtree (levels ≥ 1, 16 bytes per node).
    pub hierarchy_bytes: usize,
    /// The moment mip chain above the lobes (20 bytes per node), for approximate masking and LOD.
    pub mip_bytes: usize,
    /// The lobe blocks: per lobe the mean, the Cholesky factor and its scaled inverse in `f32`
    /// (32 bytes per lobe, in tiles of 4 × 4 lobes; edge tiles padded), what `d`, the exact masking
    /// and the samplers read.
    pub block_bytes: usize,
    /// The levels of detail l ≥ 1 (per node: moments, block lanes, quadtree, merge error; ≤ ⅓ of
    /// level 0's lobes + blocks + quadtree for a full chain).
    pub level_bytes: usize,
}

impl MixtureMemory {
    /// Total bytes (lobes, hierarchy, mip chain, blocks and levels of detail).
    pub fn total(&self) -> usize {
        self.lobe_bytes
            + self.hierarchy_bytes
            + self.mip_bytes
            + self.block_bytes
            + self.level_bytes
    }
}

/// The Beckmann-mixture glint representation of a normal map (\[Chermain2019\]).
///
/// The microsurface is Σ_i D_i(ω_m) k_i(u) (eq. 1): seed points u_i on a grid of spacing h, Gaussian
/// kernels k_i of σ = h / (2√(2 ln 2)) (half the peak at the midpoint between neighbours) with
/// ∫ k_i = h², and per seed the Beckmann lobe D_i = P22_i / cos⁴θ (eq. 2, 4) whose slope Gaussian has
/// the moments of the interpolated map's slopes under k_i (eq. 5-6), built with
/// [`SlopeGaussian::from_moments`] (σ floored at σ_ε, covariance kept positive definite).
///
/// Stored per lobe: the 5 moments as `f32` (20 bytes, what files hold); the lobe blocks derived from
/// them (32 bytes: mean, Cholesky factor and its scaled inverse in `f32`, structure-of-arrays tiles of
/// 4 × 4 lobes that `d`, the exact masking and the samplers evaluate 16 lanes at a time); the quadtree
/// of slope boxes (~5.3 bytes per lobe), the moment mip chain (~6.7 bytes per lobe) and the levels of
/// detail (~20 bytes per lobe for a full chain: merged lobes, blocks, quadtree, merge error), see
/// [`BeckmannMixture::memory`] and docs/mixture.md ("Lobe blocks"). Under
/// [`LobeStorage::Compact`] ([`MixtureParams::storage`]) only compact blocks of every level, their
/// quadtree from level 2 up and one-byte merge errors: ≤ 16 bytes per lobe, the model defined by the
/// decoded lobes (docs/mixture.md, "Compact storage").
///
/// # Reference
/// \[Chermain2019\] §3 (eq. 1-6), §4 (eq. 7-17), §5 (hierarchy).
#[derive(Clone, Debug)]
pub struct BeckmannMixture {
    width: usize,
    height: usize,
    grid: [usize; 2],
    /// Texels per lobe along x and y.
    spacing: [f64; 2],
    lobes: Vec<[f32; 5]>,
    /// The lobes as structure-of-arrays blocks of 4 × 4 (derived from `lobes`).
    blocks: LobeBlocks,
    tree: SlopeTree,
    pyramid: LobePyramid,
    /// The levels of detail l ≥ 1 (`levels[l - 1]`), derived from the lobes (levels.rs).
    levels: Vec<LobeLevel>,
    /// Under [`LobeStorage::Compact`], every level (0 included) in compact form, and the fields
    /// above empty; empty under [`LobeStorage::Full`].
    compact: Vec<CompactLevel>,
    params: MixtureParams,
    /// Half-width of the slope boxes in lobe standard deviations, k = √(−2 ln tail).
    box_k: f32,
}

/// The lobe grid (nx, ny) = max(1, round(size / spacing)) and the spacing actually used per axis.
fn lobe_grid(
    width: usize,
    height: usize,
    params: &MixtureParams,
) -> Result<([usize; 2], [f64; 2])> {
    let h = params.spacing as f64;
    let nx = ((width as f64 / h).round() as usize).max(1);
    let ny = ((height as f64 / h).round() as usize).max(1);
    if nx.checked_mul(ny).is_none_or(|n| n > (1usize << 31)) {
        return Err(Error::InvalidSize {
            width: nx,
            height: ny,
            reason: "the lobe grid (map size / spacing) exceeds 2^31 lobes",
        });
    }
    Ok((
        [nx, ny],
        [width as f64 / nx as f64, height as f64 / ny as f64],
    ))
}

impl BeckmannMixture {
    /// Builds the mixture of `map` (parallel, deterministic whatever the thread count).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the field of `params` that is invalid (`spacing`,
    /// `sigma_min`, `samples`, `supersampling`, `kernel_sigmas`, `weight_sigmas`, `slope_tail`,
    /// `lod_lobes`);
    /// [`Error::InvalidSize`] if the lobe grid would exceed 2³¹ lobes.
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
        params.validate()?;
        let (width, height) = (map.width(), map.height());
        let (grid, spacing) = lobe_grid(width, height, &params)?;
        let lobes = match params.moments {
            MomentMethod::Qmc => build::all_moments(map, &params, grid, spacing, progress),
            MomentMethod::Filter { supersampling } => build_filter::all_moments(
                map,
                grid,
                spacing,
                spacing.map(build::kernel_sigma),
                params.kernel_sigmas as f64,
                supersampling,
                progress,
            ),
        };
        Ok(Self::assemble(
            width, height, grid, spacing, params, lobes, None,
        ))
    }

    /// The mixture of stored parts (crate-private; see `store.rs`): validates `params`, derives the
    /// lobe grid as [`BeckmannMixture::build`] does and checks the lobe count against it, then
    /// rebuilds the hierarchy, the mip chain and the levels of detail exactly as the build does,
    /// except that the levels' merge errors are `errors` when given (one entry per level, the
    /// loader checks their sizes and range). The moments themselves are not checked here (the
    /// loader bounds them).
    pub(crate) fn from_parts(
        width: usize,
        height: usize,
        params: MixtureParams,
        lobes: Vec<[f32; 5]>,
        errors: Option<Vec<[Vec<f32>; levels::N_RES]>>,
    ) -> Result<Self> {
        params.validate()?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))?;
        let (grid, spacing) = lobe_grid(width, height, &params)?;
        if lobes.len() != grid[0] * grid[1] {
            return Err(Error::InvalidSize {
                width: grid[0],
                height: grid[1],
                reason: "the lobe count does not match the lobe grid of the map size and spacing",
            });
        }
        Ok(Self::assemble(
            width, height, grid, spacing, params, lobes, errors,
        ))
    }

    /// The derived parts (slope boxes, hierarchy, mip chain, levels of detail) of given lobes; the
    /// levels' merge errors computed, or taken from `errors` (full storage only).
    fn assemble(
        width: usize,
        height: usize,
        grid: [usize; 2],
        spacing: [f64; 2],
        params: MixtureParams,
        lobes: Vec<[f32; 5]>,
        errors: Option<Vec<[Vec<f32>; levels::N_RES]>>,
    ) -> Self {
        let [nx, ny] = grid;
        let box_k = (-2.0 * (params.slope_tail as f64).ln()).sqrt() as f32;
        if params.storage == LobeStorage::Compact {
            let pad = SlopeGaussian::from_moments([0.0; 5], params.sigma_min);
            let full_levels = build_levels(nx, ny, &lobes, params.sigma_min, box_k, &pad, None);
            let compact = compact::build(nx, ny, &lobes, params.sigma_min, box_k, full_levels);
            return Self::with_compact(width, height, grid, spacing, params, box_k, compact);
        }
        // Blocks and tree in one streaming pass (no whole-grid temporaries), then the mip chain.
        let (blocks, tree) = store::derive_blocks_and_tree(nx, ny, &lobes, params.sigma_min, box_k);
        let pyramid = LobePyramid::build(nx, ny, &lobes);
        let pad = SlopeGaussian::from_moments([0.0; 5], params.sigma_min);
        let levels = build_levels(nx, ny, &lobes, params.sigma_min, box_k, &pad, errors);
        BeckmannMixture {
            width,
            height,
            grid,
            spacing,
            lobes,
            blocks,
            tree,
            pyramid,
            levels,
            compact: Vec::new(),
            params,
            box_k,
        }
    }

    /// A mixture in compact storage from its compact levels (level 0 first).
    fn with_compact(
        width: usize,
        height: usize,
        grid: [usize; 2],
        spacing: [f64; 2],
        params: MixtureParams,
        box_k: f32,
        compact: Vec<CompactLevel>,
    ) -> Self {
        BeckmannMixture {
            width,
            height,
            grid,
            spacing,
            lobes: Vec::new(),
            blocks: LobeBlocks {
                bnx: 0,
                blocks: Vec::new(),
            },
            tree: SlopeTree::from_level2(1, 1, Vec::new()),
            pyramid: LobePyramid::build(1, 1, &[[0.0; 5]]),
            levels: Vec::new(),
            compact,
            params,
            box_k,
        }
    }

    /// How the lobes are held.
    pub fn storage(&self) -> LobeStorage {
        self.params.storage
    }

    /// The filtered moments at a position (level-0 lobe units) and level of detail: the moment mip
    /// chain's trilinear lookup, or under compact storage the levels of detail's (compact.rs).
    pub(super) fn filtered_moments(&self, p: [f64; 2], lod: f64) -> [f32; 5] {
        if self.compact.is_empty() {
            self.pyramid.filtered(&self.lobes, p, lod)
        } else {
            compact::filtered(&self.compact, p, lod)
        }
    }

    /// The parameters the mixture was built with.
    pub fn params(&self) -> &MixtureParams {
        &self.params
    }

    /// The map size (width, height) in texels.
    pub fn map_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The lobe grid (nx, ny).
    pub fn grid(&self) -> (usize, usize) {
        (self.grid[0], self.grid[1])
    }

    /// The spacing actually used, in texels per lobe along x and y.
    pub fn spacing(&self) -> (f32, f32) {
        (self.spacing[0] as f32, self.spacing[1] as f32)
    }

    /// The stored moments, row major over the lobe grid:
    /// `[E[x̃], E[ỹ], E[x̃²], E[ỹ²], E[x̃ỹ]]` of the interpolated map's slopes under k_i. Empty under
    /// [`LobeStorage::Compact`], which holds no moments (use [`BeckmannMixture::lobe`]).
    pub fn moments(&self) -> &[[f32; 5]] {
        &self.lobes
    }

    /// The lobe at grid position (i, j) (wrapping), as a [`SlopeGaussian`].
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 2-5.
    pub fn lobe(&self, i: i64, j: i64) -> SlopeGaussian {
        let (nx, ny) = (self.grid[0] as i64, self.grid[1] as i64);
        let k = (j.rem_euclid(ny) * nx + i.rem_euclid(nx)) as usize;
        self.lobe_at(k)
    }

    #[inline]
    fn lobe_at(&self, k: usize) -> SlopeGaussian {
        self.level_ref(0).lobe_at(k)
    }

    /// The slope-box half-width k in lobe standard deviations: √(−2 ln `slope_tail`).
    pub fn box_sigmas(&self) -> f32 {
        self.box_k
    }

    /// Bytes held by the lobes, the hierarchy and the mip chain.
    pub fn memory(&self) -> MixtureMemory {
        if let Some(l0) = self.compact.first() {
            return MixtureMemory {
                lobes: self.grid[0] * self.grid[1],
                lobe_bytes: 0,
                hierarchy_bytes: l0.tree.bytes() + std::mem::size_of::<[f32; 4]>(),
                mip_bytes: 0,
                block_bytes: l0.blocks.len() * std::mem::size_of::<compact::CompactBlock>(),
                level_bytes: self.compact[1..].iter().map(CompactLevel::bytes).sum(),
            };
        }
        MixtureMemory {
            lobes: self.lobes.len(),
            lobe_bytes: self.lobes.len() * 20,
            hierarchy_bytes: self.tree.bytes(),
            mip_bytes: self.pyramid.bytes(),
            block_bytes: self.blocks.bytes(),
            level_bytes: self.levels.iter().map(LobeLevel::bytes).sum(),
        }
    }

    /// Number of levels of detail, level 0 (the lobes) included: 1 + the number of times both
    /// sides of the lobe grid halve evenly.
    pub fn level_count(&self) -> usize {
        if self.compact.is_empty() {
            1 + self.levels.len()
        } else {
            self.compact.len()
        }
    }

    /// Level l (clamped to the coarsest) as the patch reads it.
    fn level_ref(&self, l: usize) -> LevelRef<'_> {
        if !self.compact.is_empty() {
            let l = l.min(self.compact.len() - 1);
            let c = &self.compact[l];
            return LevelRef {
                level: l,
                grid: c.grid,
                moments: &[],
                blocks: &self.blocks,
                tree: &c.tree,
                error: &[],
                sigma_min: self.params.sigma_min,
                compact: Some(c),
            };
        }
        let l = l.min(self.levels.len());
        match l {
            0 => LevelRef {
                level: 0,
                grid: self.grid,
                moments: &self.lobes,
                blocks: &self.blocks,
                tree: &self.tree,
                error: &[],
                sigma_min: self.params.sigma_min,
                compact: None,
            },
            _ => {
                let lv = &self.levels[l - 1];
                LevelRef {
                    level: l,
                    grid: lv.grid,
                    moments: &lv.moments,
                    blocks: &lv.blocks,
                    tree: &lv.tree,
                    error: lv.error.as_slice(),
                    sigma_min: self.params.sigma_min,
                    compact: None,
                }
            }
        }
    }

    /// The merge-error bounds e(n) of level l ≥ 1 (row major over its nodes; empty for level 0 or
    /// beyond the coarsest level): upper bounds of the TV between each merged lobe and the mixture
    /// of the level-0 lobes it replaces (src/glint/mixture/levels.rs), in continuous slope space
    /// (r = 0); [`BeckmannMixture::level_errors_at`] for the other resolutions. Empty under
    /// [`LobeStorage::Compact`], whose errors are one-byte codes: see [`BeckmannMixture::level_error`].
    pub fn level_errors(&self, l: usize) -> &[f32] {
        self.level_errors_at(l, 0)
    }

    /// [`BeckmannMixture::level_errors`] at the resolution `LOD_RESOLUTIONS[res]`: bounds of the TV
    /// after both densities are blurred by an isotropic Gaussian of that standard deviation in
    /// slope space (empty for `res` out of range).
    pub fn level_errors_at(&self, l: usize, res: usize) -> &[f32] {
        if l == 0 {
            &[]
        } else {
            self.levels
                .get(l - 1)
                .and_then(|lv| lv.error.get(res))
                .map_or(&[], |e| e.as_slice())
        }
    }

    /// The merge-error bound e(n) of node k (row major) of level l, in either storage (0 at level 0
    /// or out of range). Under [`LobeStorage::Compact`] the stored bound rounded up to its one-byte
    /// code, with the encoding's own error included (docs/mixture.md, "Compact storage").
    pub fn level_error(&self, l: usize, k: usize) -> f32 {
        if l == 0 || l >= self.level_count() {
            return 0.0;
        }
        self.level_ref(l).error_at(k, 0)
    }
}

impl GlintNdf for BeckmannMixture {
    type Patch<'a> = MixturePatch<'a>;
    type Options = PatchOptions;

    /// The options the mixture was built with, [`MixtureParams::patch`].
    fn options(&self) -> PatchOptions {
        self.params.patch
    }

    /// The P-NDF of a footprint ([`MixturePatch`]) with explicit options (masking mode, level of
    /// detail), its per-slot buffers lent by `scratch` if any.
    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a mut crate::glint::GlintScratch>,
    ) -> MixturePatch<'a> {
        MixturePatch::new_in(self, footprint, *options, scratch)
    }
}
