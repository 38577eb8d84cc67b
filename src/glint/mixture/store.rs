//! Saving and loading a built [`BeckmannMixture`] (format: docs/format.md, kinds 2 and 5).
//!
//! Full storage (kind 2) stores the map size, the build parameters (with the seed kernel since format
//! version 5; no per-query options: those are passed with each query), the lobes' moments (20 bytes
//! per lobe) and the merge-error bounds of the
//! levels of detail (N_RES `f32` per node of every level l ≥ 1: 4 bytes per lobe; files of format
//! version 2 do not hold them, and get them recomputed), and since format version 6 the filtered
//! mixture's chain with its residuals and measured errors (kernels/gmm_store.rs: 108 bytes per node
//! of the levels ≥ 1, ~36 per lobe; older files get them derived and measured as a build does). The
//! lobe blocks, the slope boxes' hierarchy, the moment mip chain and the levels' merged lobes are
//! rebuilt on load by the same code as the build (`FullStorage::new`, O(lobes), parallel): this keeps
//! files at ~60 bytes per lobe and every query of a loaded mixture bit-identical to the built one.
//! The merge errors are stored because their χ² bounds are most of the cost of a build's levels
//! (recomputing them takes ~80 % of a build at 2048²); a loader checks only that each is a finite
//! value in [0, 1] (the range of a total variation). They steer the level-of-detail choice and nothing else, so a
//! tampered error can change which level a patch uses, never make an evaluation non-finite.

use super::blocks::SIDE;
use super::compact::{self, CompactBlock, CompactStorage};
use super::levels::{N_RES, level_grids};
use super::model::{BeckmannMixture, Storage, box_sigmas, lobe_grid};
use super::params::{LobeStorage, MixtureParams, SeedKernel};
use crate::Result;
use crate::glint::MAX_SLOPE;
use crate::glint::io::format::{self, Decoder, Kind, Stored};
use crate::glint::kernels::gmm_store::{self, ChainBounds};
use crate::glint::kernels::slope_tree::level_sizes;
use crate::ndf::SlopeGaussian;
use std::io::{Read, Write};

/// Bound on stored mean slopes: 2 · [`MAX_SLOPE`]. Built moments average slopes of at most
/// `MAX_SLOPE` (interpolated slopes may exceed it by rounding only), so every built file passes with
/// a factor 2 to spare; the bound keeps squares and products finite in f32.
const MEAN_BOUND: f32 = 2.0 * MAX_SLOPE;

impl BeckmannMixture {
    /// Writes the mixture in the crate's binary format (docs/format.md): map size, parameters and
    /// moments, exactly (f32 bits), about 20 bytes per lobe (model kind 2); under
    /// [`LobeStorage::Compact`], the compact levels of detail instead (frames, compact blocks and
    /// merge-error codes, exactly; about 15 bytes per lobe, model kind 5). Writes in 64 KiB blocks.
    ///
    /// # Errors
    /// [`crate::Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl Write) -> Result<()> {
        let p = self.params();
        let (width, height) = self.map_size();
        let kind = match self.lobe_storage() {
            Storage::Full(_) => Kind::BeckmannMixture,
            Storage::Compact(_) => Kind::BeckmannMixtureCompact,
        };
        format::save(w, kind, |e| {
            e.len(width)?;
            e.len(height)?;
            e.put(p.spacing)?;
            e.put(p.sigma_min)?;
            e.len(p.samples)?;
            e.put(p.kernel_sigmas)?;
            e.put(p.weight_sigmas)?;
            e.put(p.slope_tail)?;
            e.put(p.seed.code())?;
            match self.lobe_storage() {
                Storage::Full(s) => {
                    e.array(s.moments().iter().copied())?;
                    // The levels' merge-error bounds (their derivation is most of a build's levels;
                    // the merged moments are recomputed on load).
                    e.len(s.merged().len())?;
                    for l in s.merged() {
                        let n = l.error[0].len();
                        e.array(
                            (0..n).map(|i| std::array::from_fn::<f32, N_RES, _>(|r| l.error[r][i])),
                        )?;
                    }
                    // The filtered mixture's chain and its measured errors (since version 6).
                    let (lobes, sigma_min) = (s.moments(), p.sigma_min);
                    gmm_store::save_chain(
                        e,
                        s.gmm(),
                        |k| SlopeGaussian::from_moments(lobes[k], sigma_min),
                        self.filtered_mixture_errors(),
                    )?;
                }
                Storage::Compact(s) => {
                    e.len(s.levels().len())?;
                    for c in s.levels() {
                        e.array(c.frames().into_iter())?;
                        e.array(c.blocks.iter().copied())?;
                        e.array(c.error.iter().map(|&b| [b]))?;
                    }
                }
            }
            Ok(())
        })
    }

    /// Reads a mixture written by [`BeckmannMixture::save`], in either storage (the file's model
    /// kind). Its patches answer `d`, `lambda`, `projected_area`, `sample_visible` and `pdf_visible`
    /// bit-identically to the saved mixture's with the same per-query [`PatchOptions`]
    /// (which no file holds: the masking mode and cost cap that files of format versions 2 and 3
    /// stored are read and ignored).
    ///
    /// [`PatchOptions`]: super::PatchOptions
    ///
    /// Compact files (kind 5): one read, the level count, frame, block and error counts checked
    /// against the grid before allocating, then every lane checked (binary16 range, a valid lobe
    /// with its mean within `MAX_SLOPE`, its slope box inside its block's frame), block-decoded in
    /// parallel; only the quadtree's levels ≥ 3 are derived. ~23× faster than a build at 2048²
    /// (docs/results.md, "Compact storage").
    ///
    /// Cost: one pass over the file (read, checksum and range check together) plus the O(lobes) lobe
    /// blocks, quadtree and mip chain (parallel, derived in bands of 4 lobe rows); no moment integration.
    /// On a 2-core machine the time is mostly the page faults of the model's fresh 64 bytes per lobe
    /// (docs/results.md, "Loads of format version 3"). Memory is allocated only as data
    /// arrive (in 64 KiB steps), whatever the header claims.
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`] (foreign bytes), [`crate::Error::CorruptHeader`] (a damaged header,
    /// docs/format.md "Damaged or unsupported"), [`crate::Error::UnsupportedVersion`],
    /// [`crate::Error::WrongModelKind`], [`crate::Error::Truncated`],
    /// [`crate::Error::ChecksumMismatch`], [`crate::Error::Stream`]; [`crate::Error::InvalidFile`] for
    /// parameters the builder refuses, a map size out of range, a lobe count that does not match the
    /// grid the size and spacing give, or moments that no built mixture holds (non-finite, means
    /// beyond 2 · `MAX_SLOPE`, second moments beyond its square or negative); for compact files, a
    /// level count, frame, block or error count that does not match the grid, a frame out of range
    /// or with lo > hi, or a lane that fails the checks above.
    pub fn load(r: &mut impl Read) -> Result<Self> {
        let (mut d, kind) =
            Decoder::open_any(r, &[Kind::BeckmannMixture, Kind::BeckmannMixtureCompact])?;
        let width = d.len("width", i32::MAX as usize)?;
        let height = d.len("height", i32::MAX as usize)?;
        let spacing = d.get("spacing")?;
        let sigma_min = d.get("sigma_min")?;
        let samples = d.len("samples", usize::MAX)?;
        let kernel_sigmas = d.get("kernel_sigmas")?;
        let weight_sigmas = d.get("weight_sigmas")?;
        let slope_tail = d.get("slope_tail")?;
        if d.version() < 4 {
            // Versions 2 and 3 stored two patch options (masking mode, cost cap); options are per
            // query, so they are read past and dropped.
            let _masking: u32 = d.get("masking")?;
            let _lod_lobes: f32 = d.get("lod_lobes")?;
        }
        // Versions before 5 knew only the Gaussian seed kernel.
        let seed = if d.version() >= 5 {
            let code: u32 = d.get("seed")?;
            SeedKernel::from_code(code)
                .ok_or_else(|| format::invalid(format!("unknown seed kernel code {code}")))?
        } else {
            SeedKernel::Gaussian
        };
        let params = MixtureParams {
            spacing,
            sigma_min,
            samples,
            seed,
            kernel_sigmas,
            weight_sigmas,
            slope_tail,
            storage: match kind {
                Kind::BeckmannMixtureCompact => LobeStorage::Compact,
                _ => LobeStorage::Full,
            },
            ..MixtureParams::default()
        };
        let refused = |e: crate::Error| format::invalid(format!("stored mixture refused: {e}"));
        params.validate().map_err(refused)?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))
            .map_err(refused)?;
        let ([nx, ny], _) = lobe_grid(width, height, &params).map_err(refused)?;
        if params.storage == LobeStorage::Compact {
            return load_compact(d, width, height, params, [nx, ny]);
        }
        let m2 = MEAN_BOUND * MEAN_BOUND;
        let lobes = d.array_in_range::<5>("lobes", nx * ny, |c| match c {
            0 | 1 => (-MEAN_BOUND, MEAN_BOUND),
            2 | 3 => (0.0, m2),
            _ => (-m2, m2),
        })?;
        // Format version 3 holds the levels' merge errors (bounds of a total variation: in [0, 1]);
        // version 2 files do not, and get them recomputed.
        let errors = if d.version() >= 3 {
            let grids = level_grids(nx, ny);
            let n = d.len("levels", usize::MAX)?;
            if n != grids.len() {
                return Err(format::invalid(format!(
                    "levels = {n} but the lobe grid {nx}×{ny} has {} levels of detail above the lobes",
                    grids.len()
                )));
            }
            let mut errors = Vec::with_capacity(n);
            for &[w, h] in &grids {
                let e = d.array_in_range::<N_RES>("merge errors", w * h, |_| (0.0, 1.0))?;
                errors.push(std::array::from_fn(|r| e.iter().map(|v| v[r]).collect()));
            }
            Some(errors)
        } else {
            None
        };
        // Format version 6 holds the filtered mixture's chain and measured errors; older files get
        // them derived and measured, as a build does.
        let chain = if d.version() >= 6 {
            let bounds = ChainBounds {
                mean: MEAN_BOUND,
                second: m2,
            };
            Some(gmm_store::load_chain(&mut d, nx, ny, bounds)?)
        } else {
            None
        };
        d.finish()?;
        let chain = chain
            .map(|c| c.into_chain(nx, ny, params.sigma_min))
            .transpose()?;
        let measured = chain.is_some();
        let mixture = BeckmannMixture::from_moments(width, height, params, lobes, errors, chain)
            .map_err(refused)?;
        Ok(if measured {
            mixture
        } else {
            mixture.measured()
        })
    }
}

impl Stored for BeckmannMixture {
    const KINDS: &'static [Kind] = &[Kind::BeckmannMixture, Kind::BeckmannMixtureCompact];
    fn save_to(&self, mut w: &mut dyn Write) -> Result<()> {
        self.save(&mut w)
    }
    fn load_from(mut r: &mut dyn Read) -> Result<Self> {
        Self::load(&mut r)
    }
}

/// The rest of a compact mixture's file (after the parameters): the levels' frames, blocks and
/// merge-error codes (docs/format.md, kind 5), then the checksum, then the values.
fn load_compact(
    mut d: Decoder<'_>,
    width: usize,
    height: usize,
    params: MixtureParams,
    grid: [usize; 2],
) -> Result<BeckmannMixture> {
    let box_k = box_sigmas(params.slope_tail);
    // The level grids exactly as the build makes them (levels.rs: while both sides halve).
    let mut grids = vec![grid];
    grids.extend(level_grids(grid[0], grid[1]));
    let n = d.len("levels", usize::MAX)?;
    if n != grids.len() {
        return Err(format::invalid(format!(
            "levels = {n} but the lobe grid {}×{} has {} levels of detail",
            grid[0],
            grid[1],
            grids.len()
        )));
    }
    // Frames: the union of lobe boxes of lobes with means within MAX_SLOPE and σ ≤ √2 MAX_SLOPE
    // (variances ≤ MAX_SLOPE², merged ones ≤ 2 MAX_SLOPE²), widened by the encoder a little.
    let fb = 2.0 * MAX_SLOPE * (1.0 + box_k);
    let mut parts = Vec::with_capacity(grids.len());
    for (l, &[w, h]) in grids.iter().enumerate() {
        let n2 = if level_sizes(w, h).len() >= 3 {
            w.div_ceil(4) * h.div_ceil(4)
        } else {
            1
        };
        let frames = d.array_in_range::<4>("frames", n2, |_| (-fb, fb))?;
        let blocks: Vec<CompactBlock> = d.array("blocks", w.div_ceil(SIDE) * h.div_ceil(SIDE))?;
        let errors: Vec<[u8; 1]> = d.array("errors", if l == 0 { 0 } else { w * h })?;
        parts.push((frames, blocks, errors));
    }
    d.finish()?;
    let mut levels = Vec::with_capacity(parts.len());
    for ((frames, blocks, errors), &[w, h]) in parts.into_iter().zip(&grids) {
        if let Some(f) = frames.iter().find(|f| !(f[0] <= f[2] && f[1] <= f[3])) {
            return Err(format::invalid(format!("frames: box {f:?} has lo > hi")));
        }
        let level = compact::assemble(
            w,
            h,
            blocks,
            frames,
            errors.into_iter().map(|e| e[0]).collect(),
        );
        level.check(box_k, MAX_SLOPE).map_err(|e| {
            format::invalid(format!("level {} of {}: {e}", levels.len(), grids.len()))
        })?;
        levels.push(level);
    }
    let (_, spacing) = lobe_grid(width, height, &params)?;
    let storage = CompactStorage::new(levels, params.sigma_min);
    Ok(BeckmannMixture::from_storage(
        width,
        height,
        grid,
        spacing,
        params,
        Storage::Compact(storage),
    ))
}
