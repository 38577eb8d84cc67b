//! Saving and loading a built [`BeckmannMixture`] (format: docs/format.md, kind 2).
//!
//! Stored: the map size, the build parameters, the lobes' moments (20 bytes per lobe) and, since
//! format version 3, the merge-error bounds of the levels of detail (N_RES `f32` per node of every
//! level l ≥ 1: 4 bytes per lobe). The lobe blocks, the slope boxes' hierarchy, the moment mip chain
//! and the levels' merged lobes are rebuilt on load by the same code as the build
//! ([`derive_blocks_and_tree`], O(lobes), parallel): this keeps files at 24 bytes per lobe and every
//! query of a loaded mixture bit-identical to the built one. The merge errors are stored because
//! their χ² bounds are most of the cost of a build's levels (recomputing them made a format-2 load
//! take 80 % of a build at 2048²); a loader checks only that each is a finite value in [0, 1] (the
//! range of a total variation). They steer the level-of-detail choice and nothing else, so a
//! tampered error can change which level a patch uses, never make an evaluation non-finite.

use super::blocks::{LobeBlocks, SIDE};
use super::compact::{self, CompactBlock};
use super::hierarchy::lobe_box;
use super::levels::{N_RES, level_grids};
use super::{BeckmannMixture, LobeStorage, MaskingMode, MixtureParams, PatchOptions};
use crate::Result;
use crate::glint::MAX_SLOPE;
use crate::glint::io::format::{self, Decoder, Kind, Stored};
use crate::glint::kernels::slope_tree::{SlopeTree, level_sizes, parent_row};
use crate::ndf::SlopeGaussian;
use rayon::prelude::*;
use std::io::{Read, Write};

/// The lobe blocks (blocks.rs) and the slope-box quadtree (src/glint/slope_tree.rs) of the lobes
/// `moments` (row major over `nx × ny`), each lobe the [`SlopeGaussian::from_moments`] of its moments
/// (floor `sigma_min`) and its box [`lobe_box`] of half-width `box_k` standard deviations.
///
/// Equal, bit for bit, to `LobeBlocks::build` over all the lobes' Gaussians and `SlopeTree::build`
/// over all their boxes, but computed in parallel bands of 4 lobe rows (one block row, two rows of
/// the tree's level 1) whose Gaussians and boxes live only in a per-thread scratch: each lobe's
/// Gaussian is computed once, and neither the Gaussians (32 bytes per lobe) nor the boxes (16) are
/// ever held for the whole grid. Loading a mixture is bounded by the memory it fills (docs/results.md,
/// "Format version 2 and the faster loaders"), so leaving out those 48 bytes per lobe of temporaries
/// is most of the gain.
pub(super) fn derive_blocks_and_tree(
    nx: usize,
    ny: usize,
    moments: &[[f32; 5]],
    sigma_min: f32,
    box_k: f32,
) -> (LobeBlocks, SlopeTree) {
    let gaussian = |m: &[f32; 5]| SlopeGaussian::from_moments(*m, sigma_min);
    let pad = SlopeGaussian::from_moments([0.0; 5], sigma_min);
    let sizes = level_sizes(nx, ny);
    if sizes.len() < 2 {
        // A single lobe: nothing to stream.
        let g: Vec<SlopeGaussian> = moments.iter().map(gaussian).collect();
        let leaf: Vec<[f32; 4]> = g.iter().map(|g| lobe_box(g, box_k)).collect();
        return (
            LobeBlocks::build(nx, ny, &g, &pad),
            SlopeTree::build(nx, ny, &leaf),
        );
    }
    let (bnx, bny) = (nx.div_ceil(SIDE), ny.div_ceil(SIDE));
    let [w1, h1] = sizes[1];
    // The final storage, written band by band in place (rayon fills it in parallel, so the pages
    // are touched by both threads).
    let proto = LobeBlocks::build(1, 1, &[pad], &pad).blocks[0].clone();
    let mut blocks = Vec::with_capacity(bnx * bny);
    blocks.par_extend(rayon::iter::repeat_n(proto, bnx * bny));
    let mut level1 = vec![[0.0f32; 4]; w1 * h1];
    let bands = blocks
        .par_chunks_mut(bnx)
        .zip(level1.par_chunks_mut(2 * w1))
        .enumerate();
    bands.for_each_init(
        || (Vec::new(), Vec::new()),
        |(g, leaf): &mut (Vec<SlopeGaussian>, Vec<[f32; 4]>), (b, (out_blocks, out_level1))| {
            let y0 = b * SIDE;
            let rows = SIDE.min(ny - y0);
            let band = &moments[y0 * nx..(y0 + rows) * nx];
            g.clear();
            g.extend(band.iter().map(gaussian));
            leaf.clear();
            leaf.extend(g.iter().map(|g| lobe_box(g, box_k)));
            // Rows 2b and 2b + 1 of level 1 are the parents of lobe rows 4b .. 4b + 4, i.e. rows 0
            // and 1 of the level above this band; lanes of rows ≥ ny are padding in both.
            for (y, out) in out_level1.chunks_mut(w1).enumerate() {
                parent_row(nx, rows, y, |k| leaf[k], out);
            }
            out_blocks.clone_from_slice(&LobeBlocks::build(nx, rows, g, &pad).blocks);
        },
    );
    (
        LobeBlocks { bnx, blocks },
        SlopeTree::from_level1(nx, ny, level1),
    )
}

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
        let p = &self.params;
        let kind = match p.storage {
            LobeStorage::Full => Kind::BeckmannMixture,
            LobeStorage::Compact => Kind::BeckmannMixtureCompact,
        };
        format::save(w, kind, |e| {
            e.len(self.width)?;
            e.len(self.height)?;
            e.put(p.spacing)?;
            e.put(p.sigma_min)?;
            e.len(p.samples)?;
            e.put(p.kernel_sigmas)?;
            e.put(p.weight_sigmas)?;
            e.put(p.slope_tail)?;
            e.put(match p.patch.masking {
                MaskingMode::Exact => 0u32,
                MaskingMode::Approximate => 1u32,
            })?;
            e.put(p.patch.lod_lobes)?;
            if p.storage == LobeStorage::Full {
                e.array(self.lobes.iter().copied())?;
                // Format version 3: the levels' merge-error bounds (their derivation is most of a
                // build's levels; the merged moments are recomputed on load).
                e.len(self.levels.len())?;
                for l in &self.levels {
                    let n = l.error[0].len();
                    e.array(
                        (0..n).map(|i| std::array::from_fn::<f32, N_RES, _>(|r| l.error[r][i])),
                    )?;
                }
                return Ok(());
            }
            e.len(self.compact.len())?;
            for c in &self.compact {
                e.array(c.frames().into_iter())?;
                e.array(c.blocks.iter().copied())?;
                e.array(c.error.iter().map(|&b| [b]))?;
            }
            Ok(())
        })
    }

    /// Reads a mixture written by [`BeckmannMixture::save`], in either storage (the file's model
    /// kind). Its patches answer `d`, `lambda`, `projected_area`, `sample_visible` and `pdf_visible`
    /// bit-identically to the saved mixture's (with the same patch options: the level-of-detail
    /// tolerance is not stored).
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
    /// (docs/results.md, "Format version 2 and the faster loaders"). Memory is allocated only as data
    /// arrive (in 64 KiB steps), whatever the header claims.
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`], [`crate::Error::UnsupportedVersion`],
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
        let masking = match d.get::<u32>("masking")? {
            0 => MaskingMode::Exact,
            1 => MaskingMode::Approximate,
            m => {
                return Err(format::invalid(format!(
                    "masking mode {m} (0 or 1 expected)"
                )));
            }
        };
        let lod_lobes = d.get("lod_lobes")?;
        let params = MixtureParams {
            spacing,
            sigma_min,
            samples,
            kernel_sigmas,
            weight_sigmas,
            slope_tail,
            // The level-of-detail tolerance is not stored (the format is unchanged): the default.
            patch: PatchOptions {
                masking,
                lod_lobes,
                ..PatchOptions::default()
            },
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
        let ([nx, ny], _) = super::lobe_grid(width, height, &params).map_err(refused)?;
        if params.storage == LobeStorage::Compact {
            return load_compact(d, width, height, params, [nx, ny]);
        }
        let m2 = MEAN_BOUND * MEAN_BOUND;
        let lobes = d.array_in_range::<5>("lobes", nx * ny, |c| match c {
            0 | 1 => (-MEAN_BOUND, MEAN_BOUND),
            2 | 3 => (0.0, m2),
            _ => (-m2, m2),
        })?;
        // Version 3 stores the levels' merge errors (bounds of a total variation: in [0, 1]);
        // version 2 files did not, and get them recomputed.
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
        d.finish()?;
        BeckmannMixture::from_parts(width, height, params, lobes, errors).map_err(refused)
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
    let box_k = (-2.0 * (params.slope_tail as f64).ln()).sqrt() as f32;
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
    let (_, spacing) = super::lobe_grid(width, height, &params)?;
    Ok(BeckmannMixture::with_compact(
        width, height, grid, spacing, params, box_k, levels,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::kernels::slope_tree::reference_levels;
    use crate::glint::mixture::hierarchy::LobePyramid;

    /// Moments of every kind a file can hold: ordinary lobes, means of ±0 (the box unions take
    /// min/max of ±0, whose result depends on the order), degenerate and clamped covariances.
    fn moments(n: usize, seed: u64) -> Vec<[f32; 5]> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        (0..n)
            .map(|k| {
                let (mx, my) = match k % 5 {
                    0 => (0.0, -0.0),
                    1 => (-0.0, 0.0),
                    _ => (next(), next()),
                };
                let (sx, sy, r) = (0.3 * next().abs(), 0.3 * next().abs(), next());
                match k % 7 {
                    3 => [mx, my, 0.0, 0.0, 0.0],
                    _ => [
                        mx,
                        my,
                        mx * mx + sx * sx,
                        my * my + sy * sy,
                        mx * my + r * sx * sy,
                    ],
                }
            })
            .collect()
    }

    /// The blocks and the tree derived band by band equal, bit for bit, those of the whole-grid
    /// derivation (every Gaussian and box held, then `LobeBlocks::build`, and a quadtree built here
    /// by the straightforward loop), on grids with odd sizes and partial bands; the parallel mip
    /// chain equals the straightforward f64 average.
    #[test]
    fn derived_parts_match_the_whole_grid_derivation() {
        let (sigma_min, box_k) = (0.01, 5.26);
        for (nx, ny) in [
            (1, 1),
            (1, 7),
            (9, 1),
            (5, 3),
            (13, 6),
            (16, 16),
            (17, 11),
            (40, 9),
        ] {
            let m = moments(nx * ny, (nx * 31 + ny) as u64);
            let (blocks, tree) = derive_blocks_and_tree(nx, ny, &m, sigma_min, box_k);
            let g: Vec<SlopeGaussian> = m
                .iter()
                .map(|m| SlopeGaussian::from_moments(*m, sigma_min))
                .collect();
            let pad = SlopeGaussian::from_moments([0.0; 5], sigma_min);
            let want = LobeBlocks::build(nx, ny, &g, &pad);
            assert_eq!(blocks.bnx, want.bnx);
            assert_eq!(
                format!("{:?}", blocks.blocks),
                format!("{:?}", want.blocks),
                "{nx}×{ny} blocks"
            );
            // The quadtree by the straightforward loop over whole levels.
            let leaf: Vec<[f32; 4]> = g.iter().map(|g| lobe_box(g, box_k)).collect();
            let sizes = level_sizes(nx, ny);
            assert_eq!(tree.sizes, sizes);
            let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
            for (l, up) in reference_levels(nx, ny, leaf).iter().enumerate() {
                assert_eq!(bits(&tree.boxes[l]), bits(up), "{nx}×{ny} level {}", l + 1);
            }
            // The mip chain: each node the f64 mean of its (up to) 2 × 2 children.
            let pyramid = LobePyramid::build(nx, ny, &m);
            let mut prev = m.clone();
            for l in 1..sizes.len() {
                let ([pw, ph], [w, h]) = (sizes[l - 1], sizes[l]);
                let mut up = Vec::new();
                for y in 0..h {
                    for x in 0..w {
                        let mut acc = [0.0f64; 5];
                        let mut n = 0.0;
                        for cy in (2 * y)..(2 * y + 2).min(ph) {
                            for cx in (2 * x)..(2 * x + 2).min(pw) {
                                for k in 0..5 {
                                    acc[k] += prev[cy * pw + cx][k] as f64;
                                }
                                n += 1.0;
                            }
                        }
                        up.push(acc.map(|v| (v / n) as f32));
                    }
                }
                let bits =
                    |v: &[[f32; 5]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&pyramid.levels[l - 1]), bits(&up), "{nx}×{ny} mip {l}");
                prev = up;
            }
        }
    }
}
