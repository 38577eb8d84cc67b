//! Full storage of the mixture's lobes ([`super::LobeStorage::Full`]): every level of detail (level 0
//! = the lobes, levels l ≥ 1 the merged lobes of levels.rs) as raw moments (20 bytes per node), lobe
//! blocks in `f32` (32 bytes, blocks.rs) and the slope-box quadtree from level 1 up, the levels'
//! merge errors at every resolution of [`super::LOD_RESOLUTIONS`], the moment mip chain of the
//! lobes for the filtered lobe (hierarchy.rs) and the filtered mixture's chain (gmm.rs): ~99 bytes
//! per lobe, the fastest queries.
//!
//! Files store the moments, the merge errors and the filtered mixture's chain (its Runnalls
//! reductions and residuals are most of a build's derived work); everything else is derived from
//! them by the same code at build and at load ([`derive_blocks_and_tree`], `build_levels`), so
//! loaded and built mixtures answer bit-identically.

use super::blocks::{LobeBlocks, SIDE};
use super::hierarchy::{LobePyramid, lobe_box};
use super::levels::{LobeLevel, N_RES, build_levels};
use super::params::MixtureMemory;
use super::storage::{LevelView, LobeStore};
use crate::glint::kernels::gmm::GmmPyramid;
use crate::glint::kernels::lobe_set::LobeSet;
use crate::glint::kernels::slope_tree::{SlopeTree, level_sizes, parent_row};
use crate::ndf::{DEFAULT_SIGMA_MIN, SIGMA_MIN_FLOOR, SlopeGaussian};
use rayon::prelude::*;

/// The lobes in full storage (module docs).
#[derive(Clone, Debug)]
pub(super) struct FullStorage {
    /// Level 0 (the lobes; no merge errors), then the levels l ≥ 1 (levels.rs).
    levels: Vec<LobeLevel>,
    /// The moment mip chain over the lobes (for the filtered lobe).
    pyramid: LobePyramid,
    /// The filtered-mixture mip chain (gmm.rs).
    gmm: GmmPyramid,
    sigma_min: f32,
    /// σ² of the variance floor as [`SlopeGaussian::from_moments`] honours `sigma_min`.
    s2: f64,
}

impl FullStorage {
    /// Levels of the filtered-mixture mip chain (level 0 included).
    pub fn filtered_mixture_levels(&self) -> usize {
        self.gmm.levels()
    }

    /// The storage of the lobes `moments` (row major over `nx × ny`): level 0's blocks and quadtree,
    /// the mip chain and the levels of detail, with the levels' merge errors computed or, when
    /// given, taken from `errors` (one entry per level l ≥ 1; the loader checks their sizes and
    /// range), and the filtered mixture's chain built or, when given, `gmm` (read from a file and
    /// checked against this grid by the loader). `box_k` is the slope-box half-width in lobe
    /// standard deviations.
    pub fn new(
        nx: usize,
        ny: usize,
        moments: Vec<[f32; 5]>,
        sigma_min: f32,
        box_k: f32,
        errors: Option<Vec<[Vec<f32>; N_RES]>>,
        gmm: Option<GmmPyramid>,
    ) -> FullStorage {
        // Blocks and tree in one streaming pass (no whole-grid temporaries), then the mip chain.
        let (blocks, tree) = derive_blocks_and_tree(nx, ny, &moments, sigma_min, box_k);
        let pyramid = LobePyramid::build(nx, ny, &moments);
        let gmm = gmm.unwrap_or_else(|| {
            GmmPyramid::build(
                nx,
                ny,
                |k| SlopeGaussian::from_moments(moments[k], sigma_min),
                sigma_min,
            )
        });
        let pad = SlopeGaussian::from_moments([0.0; 5], sigma_min);
        let merged = build_levels(nx, ny, &moments, sigma_min, box_k, &pad, errors);
        let mut levels = Vec::with_capacity(1 + merged.len());
        levels.push(LobeLevel {
            grid: [nx, ny],
            finite: super::levels::all_finite(&moments),
            moments,
            blocks,
            tree,
            error: Default::default(),
        });
        levels.extend(merged);
        FullStorage {
            levels,
            pyramid,
            gmm,
            sigma_min,
            s2: sigma_floor_squared(sigma_min),
        }
    }

    /// The lobes' raw moments, row major.
    pub fn moments(&self) -> &[[f32; 5]] {
        &self.levels[0].moments
    }

    /// The filtered mixture's chain.
    pub fn gmm(&self) -> &GmmPyramid {
        &self.gmm
    }

    /// The levels l ≥ 1 (`merged()[l - 1]`).
    pub fn merged(&self) -> &[LobeLevel] {
        &self.levels[1..]
    }
}

impl LobeStore for FullStorage {
    type Level<'a> = FullLevel<'a>;

    fn level_count(&self) -> usize {
        self.levels.len()
    }

    #[inline]
    fn level(&self, l: usize) -> FullLevel<'_> {
        let l = l.min(self.levels.len() - 1);
        FullLevel {
            level: l,
            data: &self.levels[l],
            sigma_min: self.sigma_min,
            s2: self.s2,
        }
    }

    /// The moment mip chain's trilinear lookup.
    fn filtered_moments(&self, p: [f64; 2], lod: f64) -> [f32; 5] {
        self.pyramid.filtered(self.moments(), p, lod)
    }

    fn lobe_moments(&self, i: i64, j: i64) -> [f32; 5] {
        let [nx, ny] = self.levels[0].grid;
        let (i, j) = (i.rem_euclid(nx as i64), j.rem_euclid(ny as i64));
        self.moments()[j as usize * nx + i as usize]
    }

    fn filtered_mixture(&self, p: [f64; 2], lod: f64, set: &mut LobeSet) -> bool {
        let lobes = self.moments();
        let sigma_min = self.sigma_min;
        self.gmm.lookup(
            |k| SlopeGaussian::from_moments(lobes[k], sigma_min),
            p,
            lod,
            set,
        );
        true
    }

    fn hierarchy(&self) -> Option<&GmmPyramid> {
        Some(&self.gmm)
    }

    fn memory(&self) -> MixtureMemory {
        let l0 = &self.levels[0];
        MixtureMemory {
            lobes: l0.moments.len(),
            lobe_bytes: l0.moments.len() * 20,
            hierarchy_bytes: l0.tree.bytes(),
            mip_bytes: self.pyramid.bytes() + self.gmm.bytes(),
            block_bytes: l0.blocks.bytes(),
            level_bytes: self.merged().iter().map(LobeLevel::bytes).sum(),
        }
    }
}

/// A level of [`FullStorage`] as a patch reads it.
#[derive(Clone, Copy)]
pub(super) struct FullLevel<'a> {
    level: usize,
    data: &'a LobeLevel,
    sigma_min: f32,
    s2: f64,
}

impl std::fmt::Debug for FullLevel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FullLevel")
            .field("level", &self.level)
            .field("grid", &self.data.grid)
            .finish_non_exhaustive()
    }
}

impl LevelView for FullLevel<'_> {
    type Scratch = ();

    #[inline(always)]
    fn scratch() {}

    #[inline(always)]
    fn level(&self) -> usize {
        self.level
    }

    #[inline(always)]
    fn grid(&self) -> [usize; 2] {
        self.data.grid
    }

    #[inline(always)]
    fn tree(&self) -> &SlopeTree {
        &self.data.tree
    }

    /// The stored block.
    #[inline(always)]
    fn block<'s>(&'s self, bx: usize, by: usize, _: &'s mut ()) -> &'s super::blocks::LobeBlock {
        self.data.blocks.block(bx, by)
    }

    #[inline]
    fn lobe(&self, k: usize) -> SlopeGaussian {
        SlopeGaussian::from_moments(self.data.moments[k], self.sigma_min)
    }

    /// From the raw moments in `f64` ([`lobe_mean_cov`]); the lobe's own (its fallback) for
    /// non-finite moments.
    #[inline]
    fn mean_cov(&self, k: usize) -> ([f64; 2], [f64; 3]) {
        lobe_mean_cov(&self.data.moments[k], self.s2).unwrap_or_else(|| {
            let lobe = self.lobe(k);
            let (mu, c) = (lobe.mean(), lobe.covariance());
            let c = [c.x_axis.x, c.x_axis.y, c.y_axis.y].map(f64::from);
            ([mu.x as f64, mu.y as f64], c)
        })
    }

    /// The raw moments' mean (the lobe's own, its fallback, for non-finite moments), as
    /// [`LevelView::mean_cov`] gives it, without the covariance. A level whose moments are all
    /// finite (every level a build or a load makes from a valid map) skips the test per node.
    #[inline]
    fn mean(&self, k: usize) -> [f64; 2] {
        let m = &self.data.moments[k];
        if self.data.finite {
            return [m[0] as f64, m[1] as f64];
        }
        // The f64 sum of five f32 values is finite exactly when each is (it cannot overflow).
        let sum: f64 = m.iter().map(|&v| v as f64).sum();
        if sum.is_finite() {
            [m[0] as f64, m[1] as f64]
        } else {
            let mu = self.lobe(k).mean();
            [mu.x as f64, mu.y as f64]
        }
    }

    #[inline(always)]
    fn prefetch_block(&self, bx: usize, by: usize) {
        self.data.blocks.block(bx, by).prefetch();
    }

    /// The stored block.
    #[inline(always)]
    fn stored_block(&self, bx: usize, by: usize) -> Option<&super::blocks::LobeBlock> {
        Some(self.data.blocks.block(bx, by))
    }

    #[inline]
    fn error(&self, k: usize, res: usize) -> f32 {
        self.data
            .error
            .get(res)
            .and_then(|e| e.get(k))
            .copied()
            .unwrap_or(0.0)
    }
}

/// σ² of the variance floor as [`SlopeGaussian::from_moments`] honours `sigma_min`.
fn sigma_floor_squared(sigma_min: f32) -> f64 {
    let s = if sigma_min.is_finite() && sigma_min > 0.0 {
        sigma_min.max(SIGMA_MIN_FLOOR)
    } else {
        DEFAULT_SIGMA_MIN
    } as f64;
    s * s
}

/// A lobe's slope mean and covariance as D evaluates it, from its raw moments in `f64`: variances
/// floored at σ² = `s2`, correlation clamped so that the floored matrix stays positive
/// semi-definite (as [`SlopeGaussian::from_moments`]). `None` for non-finite moments (the lobe's
/// fallback applies).
#[inline]
fn lobe_mean_cov(m: &[f32; 5], s2: f64) -> Option<([f64; 2], [f64; 3])> {
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let [ex, ey, exx, eyy, exy] = m.map(f64::from);
    let vx = (exx - ex * ex).max(s2);
    let vy = (eyy - ey * ey).max(s2);
    let (c, p) = (exy - ex * ey, (vx - s2) * (vy - s2));
    // |c| < √p for sure when c² < p (1 − 10⁻⁹) (each side rounded once, √ correctly rounded):
    // the clamp changes nothing and its square root is skipped.
    let c = if c * c < p * (1.0 - 1e-9) {
        c
    } else {
        let c_max = p.sqrt();
        c.clamp(-c_max, c_max)
    };
    Some(([ex, ey], [vx, c, vy]))
}

/// The lobe blocks (blocks.rs) and the slope-box quadtree (src/glint/slope_tree.rs) of the lobes
/// `moments` (row major over `nx × ny`), each lobe the [`SlopeGaussian::from_moments`] of its moments
/// (floor `sigma_min`) and its box [`lobe_box`] of half-width `box_k` standard deviations.
///
/// Equal, bit for bit, to `LobeBlocks::build` over all the lobes' Gaussians and `SlopeTree::build`
/// over all their boxes, but computed in parallel bands of 4 lobe rows (one block row, two rows of
/// the tree's level 1) whose Gaussians and boxes live only in a per-thread scratch: each lobe's
/// Gaussian is computed once, and neither the Gaussians (32 bytes per lobe) nor the boxes (16) are
/// ever held for the whole grid. Loading a mixture is bounded by the memory it fills (docs/results.md,
/// "Loads of format version 3"), so not holding those 48 bytes per lobe of
/// temporaries is what keeps a load fast.
fn derive_blocks_and_tree(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::kernels::slope_tree::reference_levels;

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

    /// A node's mean read without the finiteness test (every moment of the level finite) is
    /// `mean_cov`'s mean bit for bit, and so it is with the test, on a level with a non-finite
    /// moment (the lobe's own mean there, its fallback).
    #[test]
    fn the_mean_is_mean_cov_s_bit_for_bit() {
        use super::super::storage::{LevelView, LobeStore};
        let (nx, ny) = (17, 11);
        for poisoned in [false, true] {
            let mut m = moments(nx * ny, 5);
            if poisoned {
                m[37] = [f32::NAN, 0.1, 0.2, f32::INFINITY, 0.0];
            }
            let s = FullStorage::new(nx, ny, m, 0.01, 5.26, None, None);
            assert_eq!(s.level(0).data.finite, !poisoned);
            for l in 0..s.levels.len() {
                let lv = s.level(l);
                for k in 0..lv.grid()[0] * lv.grid()[1] {
                    let (a, b) = (lv.mean(k), lv.mean_cov(k).0);
                    assert_eq!(
                        a.map(f64::to_bits),
                        b.map(f64::to_bits),
                        "level {l} node {k}"
                    );
                }
            }
        }
    }
}
