//! The mixture's parameters: the build parameters ([`MixtureParams`], validated by the build and the
//! loader), the per-query patch options ([`PatchOptions`], passed with every query and never held by
//! a mixture or its file), the choices they hold ([`MomentMethod`],
//! [`LobeStorage`], [`MaskingMode`]), their documented `DEFAULT_*` values and limits, and the memory
//! report [`MixtureMemory`].

use crate::error::{Error, Result, positive};

/// Default nodes per texel per axis of the filter build ([`MomentMethod::Filter`]) for seed spacings
/// h ≥ 1: 4 (a multiple of 4, so that texel centres are nodes). Finer spacings use proportionally
/// more (`nodes_per_texel` in src/glint/mixture/build_filter.rs).
pub const DEFAULT_SUPERSAMPLING: u32 = 4;

/// Default seed spacing h = 1 texel: one lobe per texel (\[Chermain2019\] §5.1.1); under the default
/// seed kernel (the cell at this spacing) each lobe is one bilinear patch, between four texel centres.
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
/// D_P ignores a lobe outside its box, so D_P integrates to at least 1 − tail; the samplers draw each
/// lobe within its box (redrawing the rare draws outside it), so their densities are D_P's own
/// lobes renormalised by at most 1/(1 − tail) each. The paper
/// uses the 99 % box (tail 0.01, k = 3.03): 1.8× fewer lobes touched per query (docs/mixture.md) but
/// a normalisation error up to 1 %.
pub const DEFAULT_SLOPE_TAIL: f32 = 1.0e-6;

/// Default cost cap of the level of detail: a patch whose footprint covers more than this many
/// nodes (area in cells of the chosen level) moves to coarser levels, whatever the tolerance; when
/// no level is coarse enough (grids that do not halve evenly), it is served by the single filtered
/// lobe (D, masking and sampling).
///
/// A cost bound, not an accuracy one: `d` costs ~20-40 ns per touched lobe, so 16384 nodes bound a
/// query to ~0.1-1 ms (docs/results.md). Set `f32::INFINITY` to let only the tolerance decide. The cap
/// picks the finest level of merged lobes under it, not the filtered lobe straight away (which costs
/// 4-26× the TV to the ground truth where a merged level exists; docs/mixture.md).
pub const DEFAULT_LOD_LOBES: f32 = 16384.0;

/// Default level-of-detail tolerance: the bound Σ W_n e_r(n) on the total variation between a
/// patch of merged lobes and the full mixture that a patch may spend (e_r(n) the merge error of
/// node n at the slope resolution r = [`PatchOptions::lod_resolution`], src/glint/mixture/levels.rs).
/// 0 keeps the full mixture.
///
/// Since |TV(lod, R) − TV(full, R)| ≤ TV(lod, full) for any reference R, at r = 0 the tolerance
/// bounds the increase of the TV to any (binned) ground truth, up to the node-weight approximation
/// (docs/mixture.md); at r > 0 it bounds the increase seen through a Gaussian blur of std r. 0.01 is
/// the budget chosen for that increase; the footprint sweep of docs/results.md ("Levels of detail
/// chosen by error") measured +0.013 at 0.1 on the scratched map (within that tolerance, over the
/// 0.01 budget) for 5× cheaper `d`. At 0.01 the tolerance alone merged nothing on the 512² maps of
/// that sweep at r = 0, 0.01 or 0.04: merged levels there change the P-NDF's shape by more than
/// 0.01 (docs/mixture.md, "Why merged levels lose"), and levels ≥ 1 come from the cost cap.
pub const DEFAULT_LOD_TOLERANCE: f32 = 0.01;

/// Default footprint area, in lobe cells (texels at the default spacing), below which a patch is
/// the sub-texel limit lobe (src/glint/mixture/sub_texel.rs): one slope Gaussian at the interpolated
/// slope of the footprint's centre, as wide as the slope variation the footprint covers plus σ_ε.
///
/// Below about a texel each mixture lobe carries the slope variation of its whole seed kernel
/// (σ_k = 0.42 texel), where the P-NDF tends to one slope; measured against the σ_ε-convolved truth
/// in docs/results.md ("Sub-texel footprints"), which is where this threshold comes from.
pub const DEFAULT_SUB_TEXEL_AREA: f32 = 2.0;

/// Default footprint area, in lobe cells (texels at the default spacing), at and above which a
/// patch is the filtered mixture (src/glint/kernels/gmm.rs): [`GMM_LOBES`](super::GMM_LOBES) lobes
/// per node of a mip chain, read trilinearly, O(1) per query whatever the footprint (full storage;
/// compact storage serves the filtered lobe there).
///
/// Chosen from the cost and error of a shading point against footprint (docs/results.md, "Cost and
/// error of a shading point against footprint"): where the gathered mixture's cost has grown past
/// the filtered mixture's while its TV to the σ_ε-convolved truth has come within a few hundredths.
pub const DEFAULT_FILTERED_AREA: f32 = 4096.0;

/// Default tolerance of the filtered mixture: the largest TV to the full mixture, measured per
/// mixture and level at build time (src/glint/kernels/filtered_error.rs), at which it serves a large
/// footprint. See docs/results.md, "Cost and error of a shading point against footprint".
pub const DEFAULT_FILTERED_TOLERANCE: f32 = 0.15;

pub use crate::glint::kernels::cut::{DEFAULT_CUT_AREA, DEFAULT_CUT_NODES, DEFAULT_CUT_TOLERANCE};

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
/// docs/results.md, "Levels of detail chosen by error".
pub const DEFAULT_LOD_RESOLUTION: f32 = 0.01;

/// How the build integrates each lobe's five slope moments (\[Chermain2019\] eq. 6).
///
/// Both integrate the same quantity (the interpolated map's slopes under the seed kernel truncated
/// at ±`kernel_sigmas` σ per axis); they differ in cost and quadrature error. Measured against a
/// converged 65 536-node QMC reference (docs/mixture.md, docs/results.md, "Mixture build: filter against QMC").
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
    /// through the truncated Gaussian's inverse cdf). Slower than the filter at the same accuracy;
    /// reproduces the moments of mixtures built with it bit for bit.
    Qmc,
}

impl Default for MomentMethod {
    fn default() -> Self {
        MomentMethod::Filter {
            supersampling: DEFAULT_SUPERSAMPLING,
        }
    }
}

/// The seed kernel k_i whose slopes each lobe moment-matches (\[Chermain2019\] eq. 5-6): where the
/// lobes sit and which part of the interpolated surface each carries.
///
/// Measured on the orb (docs/results.md, "Bias floor decomposition": denoised relative RMSE against
/// the exact P-BRDF under a point light, σ_ε = 0.01, five maps at 1, 9 and 34 texels per pixel): at
/// spacing 1 the cell lowers the summed error of the fifteen cells by 12 % (at 34 texels per pixel
/// from 0.20-0.46 to 0.12-0.29, at 2,186 from 0.02-0.16 to 0.01-0.10); at spacings 0.5 and 0.25 the
/// Gaussian is the better one (summed error 18 % and 45 % lower), since its overlapping lobes sum to a
/// smoother P-NDF on smooth maps. [`SeedKernel::Auto`] picks accordingly.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum SeedKernel {
    /// The cell at spacings of one texel or more, the Gaussian below (the better of the two at each
    /// spacing measured, above). A build resolves it ([`SeedKernel::resolve`]): a built or loaded
    /// mixture's [`params`](super::BeckmannMixture::params) name the kernel it uses, never `Auto`.
    #[default]
    Auto,
    /// A box of one lobe cell (h × h texels) whose corners lie on texel centres: lobe i sits at
    /// (i + ½) h + ½ texels, so at spacing 1 each lobe is the moment match of exactly one bilinear
    /// patch of the interpolated map (the square between four texel centres). The cells partition
    /// the surface, and no lobe straddles the kinks the bilinear interpolation has at the texel
    /// centres. Position weights: the box as the Gaussian of its variance (h²/12 per axis) convolved
    /// with the footprint, exact in the limit of footprints wide against a cell (below two cells the
    /// sub-texel lobe serves, [`PatchOptions::sub_texel_area`]).
    Cell,
    /// The paper's Gaussian (\[Chermain2019\] §5.1.1): σ_k = 0.4247 h per axis (half of its peak at
    /// h/2), truncated at ±[`MixtureParams::kernel_sigmas`] σ_k, lobe i at (i + ½) h texels (the
    /// texel centres at h = 1). Neighbouring lobes overlap, and at h = 1 each spans the kinks of the
    /// bilinear interpolation at its texel centre.
    Gaussian,
}

/// σ of the Gaussian seed kernel for a spacing `h`: half of the peak at h/2,
/// exp(−(h/2)²/(2σ²)) = ½, so σ = h / (2 √(2 ln 2)) ≈ 0.4247 h.
pub(super) fn kernel_sigma(h: f64) -> f64 {
    h / (2.0 * (2.0 * std::f64::consts::LN_2).sqrt())
}

impl SeedKernel {
    /// The kernel a build at `spacing` texels uses: `Auto` becomes the cell at spacings ≥ 1 (and
    /// for a NaN spacing, which the build refuses anyway) and the Gaussian below; the others are
    /// themselves.
    pub fn resolve(self, spacing: f32) -> SeedKernel {
        match self {
            SeedKernel::Auto if spacing < 1.0 => SeedKernel::Gaussian,
            SeedKernel::Auto => SeedKernel::Cell,
            k => k,
        }
    }

    /// Offset in texels of the lobe centres beyond (i + ½) h: ½ for the cell, 0 for the Gaussian
    /// (lobe i sits at (i + ½) h + `origin()` texels along each axis). This and the variances below
    /// describe resolved kernels; `Auto` answers as the cell, what it is at the default spacing.
    pub fn origin(self) -> f64 {
        match self {
            SeedKernel::Cell | SeedKernel::Auto => 0.5,
            SeedKernel::Gaussian => 0.0,
        }
    }

    /// Per-axis variance of the kernel in lobe units² as the position weights use it: the cell's
    /// 1/12, the Gaussian's untruncated σ_k² (W_i = N(u_i; c_P, Σ_P + σ_k² I) in lobe units).
    pub fn weight_variance(self) -> f64 {
        match self {
            SeedKernel::Cell | SeedKernel::Auto => 1.0 / 12.0,
            SeedKernel::Gaussian => kernel_sigma(1.0).powi(2),
        }
    }

    /// Per-axis variance in lobe units² of the kernel the moments integrate: the cell's 1/12, the
    /// Gaussian truncated at ±`kernel_sigmas` σ_k, σ_k² (1 − 2 t φ(t) / (1 − 2 Φ(−t))).
    pub fn moment_variance(self, kernel_sigmas: f32) -> f64 {
        match self {
            SeedKernel::Cell | SeedKernel::Auto => 1.0 / 12.0,
            SeedKernel::Gaussian => {
                use crate::ndf::gauss;
                let t = kernel_sigmas as f64;
                let s2 = kernel_sigma(1.0).powi(2);
                let mass = 1.0 - 2.0 * gauss::std_cdf(-t);
                if mass > 0.0 {
                    s2 * (1.0 - 2.0 * t * gauss::std_pdf(t) / mass)
                } else {
                    s2
                }
            }
        }
    }

    /// The kernel's code in files (docs/format.md): 0 the Gaussian, 1 the cell (files hold resolved
    /// kernels; `Auto` writes as the cell, what it is at the default spacing).
    pub(super) fn code(self) -> u32 {
        match self {
            SeedKernel::Gaussian => 0,
            SeedKernel::Cell | SeedKernel::Auto => 1,
        }
    }

    /// The kernel of a file's code, `None` for an unknown one.
    pub(super) fn from_code(code: u32) -> Option<SeedKernel> {
        match code {
            0 => Some(SeedKernel::Gaussian),
            1 => Some(SeedKernel::Cell),
            _ => None,
        }
    }
}

/// Largest accepted [`MomentMethod::Filter`] supersampling: 64 nodes per texel per axis (the
/// node rows a band holds grow with it; the quadrature error is already ~1e-3 of 4's).
pub const MAX_SUPERSAMPLING: u32 = 64;

/// How a [`BeckmannMixture`](super::BeckmannMixture) holds its lobes in memory (and in files).
///
/// Trade-off (docs/mixture.md, "Compact storage"; measured in docs/results.md): `Compact` holds
/// ≤ 16 bytes per lobe in all (15.4 measured, against ~119 for `Full`) and loads several times faster, at the cost
/// of a per-block decode in every query (`d`, the exact masking and the visible sampler run slower,
/// see the results) and of an encoding error far below the mixture's own (mean slopes to 16 bits
/// inside their block's slope box, the inverse Cholesky factor to binary16: TV change against the
/// ground truth ≤ 0.002 measured). Either way the model is self-consistent: `d`, the masking terms,
/// the samplers and their pdfs all read the same stored lobes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum LobeStorage {
    /// The raw moments (20 B per lobe), the lobe blocks in `f32` (32 B), the quadtree, the moment
    /// mip chain, the filtered mixture's chain and the levels of detail in the same form: ~99 bytes
    /// per lobe (99.1 measured: 76 for level 0 and its two mip chains, 23.1 for the levels l ≥ 1),
    /// the fastest queries.
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
    /// over-shadows; docs/results.md, "Exact and approximate masking").
    Approximate,
}

/// Per-query options of a mixture's patches: the masking mode and the level of detail (error
/// tolerance and cost cap). Passed with every query
/// ([`GlintNdf::patch_with`](crate::glint::GlintNdf::patch_with)); a mixture holds none and its file
/// stores none, so the same options give the same patch from a built or a loaded mixture.
///
/// Every value is accepted (evaluation is total): a NaN or negative `lod_tolerance` acts as 0, a NaN
/// `lod_lobes` as no cap, a negative one as a cap of 0 (the filtered lobe), and a NaN or negative
/// `lod_resolution` as 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchOptions {
    /// Exact or approximate masking terms ([`DEFAULT_MASKING`]).
    pub masking: MaskingMode,
    /// Cost cap ([`DEFAULT_LOD_LOBES`]): footprints of more than this many nodes of the chosen
    /// level move to coarser levels (the filtered lobe alone when none is coarse enough);
    /// `f32::INFINITY` disables the cap.
    pub lod_lobes: f32,
    /// Footprint area, in lobe cells (texels at the default spacing), below which the patch is the
    /// sub-texel limit lobe ([`DEFAULT_SUB_TEXEL_AREA`]; 0 never).
    pub sub_texel_area: f32,
    /// Footprint area, in lobe cells, at and above which the patch may be the filtered mixture
    /// ([`DEFAULT_FILTERED_AREA`]; `f32::INFINITY` never).
    pub filtered_area: f32,
    /// Largest measured TV between the filtered mixture and the full mixture at the footprint's
    /// level ([`DEFAULT_FILTERED_TOLERANCE`]; measured per mixture by its build,
    /// src/glint/kernels/filtered_error.rs) at which the filtered mixture serves a footprint of at
    /// least `filtered_area`; above it the footprint is gathered (the level of detail and the
    /// cost cap `lod_lobes` decide). `f32::INFINITY` always serves it.
    pub filtered_tolerance: f32,
    /// Error tolerance of the level of detail ([`DEFAULT_LOD_TOLERANCE`]): a patch uses the
    /// coarsest level of merged lobes whose weighted merge-error bound Σ W_n e(n) is at most this
    /// (and whose nodes are no wider than half the footprint's smaller standard deviation); 0 keeps the
    /// full mixture (level 0), unless the cost cap moves it.
    pub lod_tolerance: f32,
    /// Slope resolution r of the tolerance's error ([`DEFAULT_LOD_RESOLUTION`], slope units): the
    /// bound Σ W_n e_r(n) is on the TV between the two P-NDFs after both are blurred by an isotropic
    /// Gaussian of standard deviation r in slope space, read at the largest r of
    /// [`LOD_RESOLUTIONS`] not above this. 0: the continuous TV.
    pub lod_resolution: f32,
    /// Largest cut of the filtered-mixture hierarchy, in nodes ([`DEFAULT_CUT_NODES`], at most
    /// [`MAX_CUT_NODES`](super::MAX_CUT_NODES)); 0: no cut. A footprint of at least `cut_area`
    /// that the filtered mixture does not serve is served by the cut (full storage), whatever
    /// `lod_lobes` and `lod_tolerance`.
    pub cut_nodes: u32,
    /// Footprint area, in lobe cells, from which the cut serves ([`DEFAULT_CUT_AREA`]).
    pub cut_area: f32,
    /// Error budget of a node of the cut ([`DEFAULT_CUT_TOLERANCE`]; NaN or ≤ 0: split until
    /// `cut_nodes`).
    pub cut_tolerance: f32,
}

impl PatchOptions {
    /// Every level of detail off: the full mixture gathered at level 0 for every footprint (no
    /// sub-texel lobe, no cut, no filtered mixture, no merged level, no cost cap), masking as
    /// [`DEFAULT_MASKING`]. The reference the levels of detail are measured against; its cost grows
    /// with the footprint.
    pub fn full() -> PatchOptions {
        PatchOptions {
            lod_lobes: f32::INFINITY,
            lod_tolerance: 0.0,
            sub_texel_area: 0.0,
            filtered_area: f32::INFINITY,
            cut_nodes: 0,
            ..PatchOptions::default()
        }
    }
}

impl Default for PatchOptions {
    fn default() -> Self {
        PatchOptions {
            masking: DEFAULT_MASKING,
            lod_lobes: DEFAULT_LOD_LOBES,
            sub_texel_area: DEFAULT_SUB_TEXEL_AREA,
            filtered_area: DEFAULT_FILTERED_AREA,
            filtered_tolerance: DEFAULT_FILTERED_TOLERANCE,
            lod_tolerance: DEFAULT_LOD_TOLERANCE,
            lod_resolution: DEFAULT_LOD_RESOLUTION,
            cut_nodes: DEFAULT_CUT_NODES,
            cut_area: DEFAULT_CUT_AREA,
            cut_tolerance: DEFAULT_CUT_TOLERANCE,
        }
    }
}

/// Build parameters of a [`BeckmannMixture`](super::BeckmannMixture): what the build needs, and
/// nothing a query chooses (those are the [`PatchOptions`] passed with each query). `Default` gives
/// the documented `DEFAULT_*` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MixtureParams {
    /// Seed spacing h in texels (≥ [`MIN_SPACING`]). The lobe grid has max(1, round(width / h)) × max(1,
    /// round(height / h)) lobes, so the spacing actually used per axis is width / nx (height / ny):
    /// an integer number of lobes tiles the map.
    pub spacing: f32,
    /// Floor σ_ε of the lobes' slope standard deviation (> 0).
    pub sigma_min: f32,
    /// Quasi-Monte Carlo nodes per lobe for the moments, used (and required ≥ 1) when `moments` is
    /// [`MomentMethod::Qmc`]; ignored under [`MomentMethod::Filter`], where any value is accepted.
    pub samples: usize,
    /// The seed kernel k_i ([`SeedKernel::Auto`] by default: the cell at spacings ≥ 1, the Gaussian
    /// below). Resolved by the build and stored in files.
    pub seed: SeedKernel,
    /// Truncation of the Gaussian seed kernel for the moment integral, in σ (in (0,
    /// [`MAX_TRUNCATION_SIGMAS`]]; checked whatever the kernel, read under
    /// [`SeedKernel::Gaussian`] only).
    pub kernel_sigmas: f32,
    /// Truncation of the position weights, in σ (in (0, [`MAX_TRUNCATION_SIGMAS`]]).
    pub weight_sigmas: f32,
    /// Mass left outside each lobe's slope box (0 < tail < 1).
    pub slope_tail: f32,
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
            seed: SeedKernel::default(),
            kernel_sigmas: DEFAULT_KERNEL_SIGMAS,
            weight_sigmas: DEFAULT_WEIGHT_SIGMAS,
            slope_tail: DEFAULT_SLOPE_TAIL,
            moments: MomentMethod::default(),
            storage: LobeStorage::default(),
        }
    }
}

impl MixtureParams {
    /// Checks every field (the build's and the loader's gate).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the first invalid field.
    pub(super) fn validate(&self) -> Result<()> {
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
        // `samples` counts the QMC nodes: unused (and so not checked) under the filter.
        if self.moments == MomentMethod::Qmc && self.samples == 0 {
            return Err(Error::InvalidParameter {
                name: "samples",
                value: 0.0,
                reason: "must be at least 1 with MomentMethod::Qmc",
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
        Ok(())
    }
}

/// Memory held by a [`BeckmannMixture`](super::BeckmannMixture), in bytes.
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
    /// The moment mip chain above the lobes (20 bytes per node), for the filtered lobe
    /// ([`MixturePatch::filtered_lobe`](super::MixturePatch::filtered_lobe)).
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
