//! The built model [`BeckmannMixture`]: the map size, the lobe grid, the parameters and the lobes in
//! one of the two storages (full.rs, compact.rs), held as [`Storage`] and read through the
//! crate-private [`LobeStore`] interface (storage.rs). The build (moments, then the storage), the
//! accessors and the memory report are here; saving and loading in store.rs, patches in patch.rs.

use super::build;
use super::build_filter;
use super::compact::CompactStorage;
use super::compact_encode;
use super::full::FullStorage;
use super::levels::N_RES;
use super::params::{LobeStorage, MixtureMemory, MixtureParams, MomentMethod};
use super::storage::{LevelView, LobeStore};
use crate::error::{Error, Result};
use crate::glint::NormalMap;
use crate::glint::kernels::gmm::GmmPyramid;
use crate::ndf::SlopeGaussian;

/// The lobes of a mixture in one of the two storages of [`LobeStorage`].
#[derive(Clone, Debug)]
pub(super) enum Storage {
    Full(FullStorage),
    Compact(CompactStorage),
}

/// Runs `$body` with `$s` bound to the storage of `$storage` (`&Storage`), once per storage type.
macro_rules! with_storage {
    ($storage:expr, |$s:ident| $body:expr) => {
        match $storage {
            Storage::Full($s) => $body,
            Storage::Compact($s) => $body,
        }
    };
}

/// The Beckmann-mixture glint representation of a normal map (\[Chermain2019\]).
///
/// The microsurface is Σ_i D_i(ω_m) k_i(u) (eq. 1): seed points u_i on a grid of spacing h, Gaussian
/// kernels k_i of σ = h / (2√(2 ln 2)) (half the peak at the midpoint between neighbours) with
/// ∫ k_i = h², and per seed the Beckmann lobe D_i = P22_i / cos⁴θ (eq. 2, 4) whose slope Gaussian has
/// the moments of the interpolated map's slopes under k_i (eq. 5-6), built with
/// [`SlopeGaussian::from_moments`] (σ floored at σ_ε, covariance kept positive definite).
///
/// Stored per lobe under [`LobeStorage::Full`]: the 5 moments as `f32` (20 bytes, what files hold);
/// the lobe blocks derived from them (32 bytes: mean, Cholesky factor and its scaled inverse in
/// `f32`, structure-of-arrays tiles of 4 × 4 lobes that `d`, the exact masking and the samplers
/// evaluate 16 lanes at a time); the quadtree of slope boxes (~5.3 bytes per lobe), the moment mip
/// chain (~6.7 bytes per lobe), the filtered mixture's chain with its residuals (12 bytes per lobe:
/// level 1's components are its lobes, served from them) and the levels of
/// detail (~23 bytes per lobe for a full chain: merged lobes, blocks, quadtree, merge errors):
/// ~99 bytes per lobe, see [`BeckmannMixture::memory`] and docs/mixture.md ("Lobe blocks"). Under [`LobeStorage::Compact`] ([`MixtureParams::storage`])
/// only compact blocks of every level, their quadtree from level 2 up and one-byte merge errors:
/// ≤ 16 bytes per lobe, the model defined by the decoded lobes (docs/mixture.md, "Compact
/// storage").
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
    /// The lobes and their levels of detail.
    storage: Storage,
    params: MixtureParams,
    /// Half-width of the slope boxes in lobe standard deviations, k = √(−2 ln tail).
    box_k: f32,
    /// The filtered mixture's measured TV to the full mixture per level of its mip chain
    /// (src/glint/kernels/filtered_error.rs), measured by the build (or read from a file); empty
    /// without a filtered mixture (compact storage) or on a map too small to measure one.
    filtered_error: Vec<f32>,
}

/// The lobe grid (nx, ny) = max(1, round(size / spacing)) and the spacing actually used per axis.
pub(super) fn lobe_grid(
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

/// The slope-box half-width k = √(−2 ln tail) in lobe standard deviations.
pub(super) fn box_sigmas(slope_tail: f32) -> f32 {
    (-2.0 * (slope_tail as f64).ln()).sqrt() as f32
}

impl BeckmannMixture {
    /// The mixture of `map` without its filtered mixture's errors (measured.rs measures them:
    /// [`BeckmannMixture::build_with_progress`]).
    pub(super) fn build_unmeasured(
        map: &NormalMap,
        params: MixtureParams,
        progress: Option<&(dyn Fn(f32) + Sync)>,
    ) -> Result<Self> {
        params.validate()?;
        // The mixture holds (and files store) the kernel it was built with, never `Auto`.
        let params = MixtureParams {
            seed: params.seed.resolve(params.spacing),
            ..params
        };
        let (width, height) = (map.width(), map.height());
        let (grid, spacing) = lobe_grid(width, height, &params)?;
        let lobes = match params.moments {
            MomentMethod::Qmc => build::all_moments(map, &params, grid, spacing, progress),
            MomentMethod::Filter { supersampling } => build_filter::all_moments(
                map,
                grid,
                spacing,
                params.seed,
                params.kernel_sigmas as f64,
                supersampling,
                progress,
            ),
        };
        let box_k = box_sigmas(params.slope_tail);
        let [nx, ny] = grid;
        let storage = match params.storage {
            LobeStorage::Full => Storage::Full(FullStorage::new(
                nx,
                ny,
                lobes,
                params.sigma_min,
                box_k,
                None,
                None,
            )),
            LobeStorage::Compact => Storage::Compact(CompactStorage::new(
                compact_encode::build(nx, ny, &lobes, params.sigma_min, box_k),
                params.sigma_min,
            )),
        };
        Ok(Self::from_storage(
            width, height, grid, spacing, params, storage,
        ))
    }

    /// The mixture of stored moments in full storage (crate-private; see store.rs): validates
    /// `params`, derives the lobe grid as [`BeckmannMixture::build`] does and checks the lobe count
    /// against it, then derives the storage exactly as the build does, except that the levels' merge
    /// errors are `errors` when given (one entry per level l ≥ 1; the loader checks their sizes and
    /// range), and the filtered mixture's chain and measured errors are `chain` when given (read
    /// from a file, checked by the loader against this grid). The moments themselves are not
    /// checked here (the loader bounds them).
    pub(super) fn from_moments(
        width: usize,
        height: usize,
        params: MixtureParams,
        lobes: Vec<[f32; 5]>,
        errors: Option<Vec<[Vec<f32>; N_RES]>>,
        chain: Option<(GmmPyramid, Vec<f32>)>,
    ) -> Result<Self> {
        params.validate()?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))?;
        let (grid, spacing) = lobe_grid(width, height, &params)?;
        let [nx, ny] = grid;
        if lobes.len() != nx * ny {
            return Err(Error::InvalidSize {
                width: nx,
                height: ny,
                reason: "the lobe count does not match the lobe grid of the map size and spacing",
            });
        }
        let box_k = box_sigmas(params.slope_tail);
        let (gmm, filtered_errors) = chain.unzip();
        let storage = FullStorage::new(nx, ny, lobes, params.sigma_min, box_k, errors, gmm);
        Ok(
            Self::from_storage(width, height, grid, spacing, params, Storage::Full(storage))
                .with_filtered_errors(filtered_errors.unwrap_or_default()),
        )
    }

    /// A mixture of a map size, valid parameters, their lobe grid and spacing ([`lobe_grid`]) and
    /// the storage of that grid.
    pub(super) fn from_storage(
        width: usize,
        height: usize,
        grid: [usize; 2],
        spacing: [f64; 2],
        params: MixtureParams,
        storage: Storage,
    ) -> Self {
        BeckmannMixture {
            width,
            height,
            grid,
            spacing,
            storage,
            params,
            box_k: box_sigmas(params.slope_tail),
            filtered_error: Vec::new(),
        }
    }

    /// The mixture with its filtered mixture's measured errors (measured.rs measures them, a
    /// loader reads them).
    pub(super) fn with_filtered_errors(mut self, errors: Vec<f32>) -> Self {
        self.filtered_error = errors;
        self
    }

    /// The filtered mixture's measured errors ([`BeckmannMixture::filtered_mixture_errors`]).
    pub(super) fn filtered_errors(&self) -> &[f32] {
        &self.filtered_error
    }

    /// Levels of the filtered mixture's mip chain (0 under compact storage, which has none).
    pub(super) fn filtered_mixture_levels(&self) -> usize {
        match &self.storage {
            Storage::Full(s) => s.filtered_mixture_levels(),
            Storage::Compact(_) => 0,
        }
    }

    /// The lobes and their levels of detail.
    pub(super) fn lobe_storage(&self) -> &Storage {
        &self.storage
    }

    /// How the lobes are held.
    pub fn storage(&self) -> LobeStorage {
        self.params.storage
    }

    /// The parameters the mixture was built with, its seed kernel resolved
    /// ([`SeedKernel::resolve`](super::SeedKernel::resolve): the cell or the Gaussian, never `Auto`).
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

    /// The spacing in `f64` (texels per lobe along x and y).
    pub(super) fn spacing_f64(&self) -> [f64; 2] {
        self.spacing
    }

    /// The stored moments, row major over the lobe grid:
    /// `[E[x̃], E[ỹ], E[x̃²], E[ỹ²], E[x̃ỹ]]` of the interpolated map's slopes under k_i. Empty under
    /// [`LobeStorage::Compact`], which holds no moments (use [`BeckmannMixture::lobe`]).
    pub fn moments(&self) -> &[[f32; 5]] {
        match &self.storage {
            Storage::Full(s) => s.moments(),
            Storage::Compact(_) => &[],
        }
    }

    /// The lobe at grid position (i, j) (wrapping), as a [`SlopeGaussian`].
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 2-5.
    pub fn lobe(&self, i: i64, j: i64) -> SlopeGaussian {
        let (nx, ny) = (self.grid[0] as i64, self.grid[1] as i64);
        let k = (j.rem_euclid(ny) * nx + i.rem_euclid(nx)) as usize;
        with_storage!(&self.storage, |s| s.level(0).lobe(k))
    }

    /// The slope-box half-width k in lobe standard deviations: √(−2 ln `slope_tail`).
    pub fn box_sigmas(&self) -> f32 {
        self.box_k
    }

    /// Bytes held by the lobes, the hierarchy, the mip chain and the levels of detail (their split
    /// per storage: [`MixtureMemory`]).
    pub fn memory(&self) -> MixtureMemory {
        with_storage!(&self.storage, |s| s.memory())
    }

    /// Number of levels of detail, level 0 (the lobes) included: 1 + the number of times both
    /// sides of the lobe grid halve evenly.
    pub fn level_count(&self) -> usize {
        with_storage!(&self.storage, |s| s.level_count())
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
        match (&self.storage, l) {
            (Storage::Full(s), 1..) => s
                .merged()
                .get(l - 1)
                .and_then(|lv| lv.error.get(res))
                .map_or(&[], |e| e.as_slice()),
            _ => &[],
        }
    }

    /// The merge-error bound e(n) of node k (row major) of level l, in either storage (0 at level 0
    /// or out of range). Under [`LobeStorage::Compact`] the stored bound rounded up to its one-byte
    /// code, with the encoding's own error included (docs/mixture.md, "Compact storage").
    pub fn level_error(&self, l: usize, k: usize) -> f32 {
        if l == 0 || l >= self.level_count() {
            return 0.0;
        }
        with_storage!(&self.storage, |s| s.level(l).error(k, 0))
    }
}
