//! Compact storage of the mixture's lobes ([`super::LobeStorage::Compact`]): every
//! level of detail held only as quantised lobe blocks, 10 bytes per lobe, with the slope-box quadtree
//! from the block level up and one-byte merge errors; ≤ 16 bytes per lobe in all (docs/mixture.md,
//! "Compact storage").
//!
//! **A compact block** is the tile of 4 × 4 lobes of a [`LobeBlock`] (blocks.rs) in 80 `u16` words:
//! per lane the mean slope (μx, μy) quantised to 16 bits inside the block's *frame*, then the scaled
//! inverse Cholesky factor J = √(½ log₂ e) L⁻¹ (J₁₁, J₂₁, J₂₂) as IEEE binary16 (`half::f16`). The frame
//! is the block's box in the slope-box quadtree (level 2, `f32`): no extra storage. Decoding gives
//! μ = q · step + lo with step = (hi − lo) / 65535 (`f32`, in that order), J exactly (binary16 → `f32`
//! is exact), and L from J in `f32`: L₁₁ = s / J₁₁, L₂₂ = s / J₂₂, L₂₁ = −J₂₁ (L₁₁ L₂₂) / s with
//! s = √(½ log₂ e). The **model is defined by the decoded lobes**: D_P, the exact masking, both
//! samplers and their pdfs, the filtered lobe and `save` all read them, so sample, pdf and eval stay
//! mutually consistent exactly as in full storage.
//!
//! **Errors of the encoding** (against the full storage's lobe): |Δμ| ≤ step/2 plus the `f32`
//! roundings of the decode; each J entry within a relative 2⁻¹¹ (binary16's rounding, normal range:
//! |J| ∈ [2⁻¹⁴, 65504], guaranteed by `sigma_min` ≥ [`super::MIN_COMPACT_SIGMA`]; J₂₁ may be
//! subnormal, then its error is ≤ 2⁻²⁵ absolute).
//!
//! **Frames contain every decoded lobe's box** (mean ± k (L₁₁, |L row 2|), `hierarchy::lobe_box`), so
//! no lobe is ever culled wrongly: the frame starts as the union of the full lobes' boxes and is
//! widened and the means re-encoded until the decoded boxes fit (one or two rounds). The loader
//! checks it again.
//!
//! **Merge errors** e(n) of levels l ≥ 1 are stored in one byte each on a logarithmic scale (code c:
//! 0 for 0, else 2^((c − 255)/8), so 1 is code 255 and the smallest non-zero bound 2^−31.75), rounded
//! **up**; before that, each bound gets the encoding's own total variation added (the triangle
//! inequality: TV(decoded node, mixture of decoded lobes) ≤ TV(node, its encoding) + e(n) +
//! the largest TV of a level-0 lobe under n and its encoding, each by Pinsker's inequality on the
//! closed-form Gaussian KL). So Σ W_n e(n) remains an upper bound for the compact model.
//!
//! **The filtered lobe** (\[Chermain2019\] §4.2.2) is looked up trilinearly in the decoded levels of
//! detail (their raw moments), in place of the moment mip chain, which compact storage does not hold.
//!
//! This file holds the format, the decoder, the loader's checks and the storage; the encoder is
//! compact_encode.rs.

use super::blocks::{J_SCALE, LANES, LobeBlock, SIDE};
use super::params::MixtureMemory;
use super::storage::{LevelView, LobeStore};
use crate::glint::kernels::lobe_set::LobeSet;
use crate::glint::kernels::slope_tree::{SlopeTree, level_sizes};
use crate::ndf::SlopeGaussian;
use glam::Vec2;
use half::f16;
use half::slice::{HalfBitsSliceExt, HalfFloatSliceExt};
use rayon::prelude::*;

/// `u16` words per compact block: 16 μx, 16 μy, 16 J₁₁, 16 J₂₁, 16 J₂₂.
pub(super) const WORDS: usize = 5 * LANES;

/// One compact block (160 bytes).
pub(super) type CompactBlock = [u16; WORDS];

/// The largest quantised mean code.
pub(super) const QMAX: f32 = 65535.0;

/// √(½ log₂ e) and its inverse in `f32`, as the decoder uses them.
const JS: f32 = J_SCALE as f32;
const INV_JS: f32 = (1.0 / J_SCALE) as f32;

/// One level of detail in compact storage.
#[derive(Clone, Debug)]
pub(super) struct CompactLevel {
    /// Nodes along x and y.
    pub grid: [usize; 2],
    /// Blocks per row (⌈grid\[0\] / 4⌉).
    pub bnx: usize,
    /// The compact blocks, row major.
    pub blocks: Vec<CompactBlock>,
    /// The frame of the single block of a grid with no level-2 node (≤ 2 × 2 nodes); unused
    /// otherwise (the frames are the quadtree's level-2 boxes).
    pub frame0: [f32; 4],
    /// The slope-box quadtree from level 2 up (`SlopeTree::from_level2`).
    pub tree: SlopeTree,
    /// Merge-error codes (one byte per node; empty at level 0).
    pub error: Vec<u8>,
}

/// 2^(−r/8), r = 0..7 (any fixed values would do: encoding rounds up against these).
const FRAC: [f32; 8] = [
    1.0,
    0.917_004_04,
    0.840_896_4,
    0.771_105_4,
    0.707_106_77,
    0.648_419_8,
    0.594_603_55,
    0.545_253_9,
];

/// The merge error of code c (module docs): 0 for c = 0, else 2^((c − 255)/8) (the power of two
/// exact, the fraction from [`FRAC`]).
const fn error_of_code(c: u8) -> f32 {
    if c == 0 {
        return 0.0;
    }
    let k = 255 - c as u32;
    let (q, r) = (k / 8, k % 8);
    f32::from_bits((127 - q) << 23) * FRAC[r as usize]
}

const fn error_table() -> [f32; 256] {
    let mut t = [0.0f32; 256];
    let mut c = 0;
    while c < 256 {
        t[c] = error_of_code(c as u8);
        c += 1;
    }
    t
}

/// Decoded merge error per code.
static ERROR_TABLE: [f32; 256] = error_table();

/// The decoded merge error of code `c`.
#[inline]
pub(super) fn decode_error(c: u8) -> f32 {
    ERROR_TABLE[c as usize]
}

/// The smallest code whose decoded error is ≥ e (e ≥ 1, or NaN, gives 255 = 1.0; e ≤ 0 gives 0).
pub(super) fn encode_error(e: f64) -> u8 {
    if e.is_nan() || e >= 1.0 {
        return 255;
    }
    if e <= 0.0 {
        return 0;
    }
    // decode is increasing in c: the first code at or above e.
    let (mut lo, mut hi) = (1u16, 255u16);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if (ERROR_TABLE[mid as usize] as f64) >= e {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo as u8
}

/// The quantisation steps (x, y) of a frame: (hi − lo) / 65535 in `f32`.
#[inline]
pub(super) fn steps(frame: &[f32; 4]) -> (f32, f32) {
    ((frame[2] - frame[0]) / QMAX, (frame[3] - frame[1]) / QMAX)
}

/// The decoded mean component of code q in a frame axis [lo, ·] of step `step`.
#[inline(always)]
pub(super) fn decode_mean(q: u16, lo: f32, step: f32) -> f32 {
    q as f32 * step + lo
}

/// L = s J⁻¹ from J (module docs), in `f32`: (L₁₁, L₂₁, L₂₂).
#[inline(always)]
fn chol_of_j(j11: f32, j21: f32, j22: f32) -> (f32, f32, f32) {
    let l11 = JS / j11;
    let l22 = JS / j22;
    (l11, -(j21 * (l11 * l22)) * INV_JS, l22)
}

/// A decoded lane: mean, J and L.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Lane {
    pub mean: Vec2,
    pub j: [f32; 3],
    pub l: [f32; 3],
}

impl Lane {
    /// The lane's slope box, exactly as `hierarchy::lobe_box` computes it from a lobe of this mean
    /// and L.
    pub(super) fn slope_box(&self, k: f32) -> [f32; 4] {
        let [l11, l21, l22] = self.l;
        let hx = k * l11.abs();
        let hy = k * (l21 * l21 + l22 * l22).sqrt();
        let m = self.mean;
        [m.x - hx, m.y - hy, m.x + hx, m.y + hy]
    }

    /// The lane as a [`SlopeGaussian`] (exactly its mean and L); `None` if it is not a valid lobe.
    pub(super) fn gaussian(&self) -> Option<SlopeGaussian> {
        let [l11, l21, l22] = self.l;
        SlopeGaussian::from_mean_cholesky(self.mean, l11, l21, l22)
    }

    /// Raw moments [E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ] of the lane, in `f64`.
    fn raw_moments(&self) -> [f64; 5] {
        let (mx, my) = (self.mean.x as f64, self.mean.y as f64);
        let [l11, l21, l22] = self.l.map(f64::from);
        [
            mx,
            my,
            l11 * l11 + mx * mx,
            l21 * l21 + l22 * l22 + my * my,
            l11 * l21 + mx * my,
        ]
    }
}

/// Decodes lane `lane` of a compact block in `frame` (the same values [`decode_block`] writes).
#[inline]
pub(super) fn decode_lane(b: &CompactBlock, frame: &[f32; 4], lane: usize) -> Lane {
    let (sx, sy) = steps(frame);
    let j = [
        f16::from_bits(b[2 * LANES + lane]).to_f32(),
        f16::from_bits(b[3 * LANES + lane]).to_f32(),
        f16::from_bits(b[4 * LANES + lane]).to_f32(),
    ];
    let (l11, l21, l22) = chol_of_j(j[0], j[1], j[2]);
    Lane {
        mean: Vec2::new(
            decode_mean(b[lane], frame[0], sx),
            decode_mean(b[LANES + lane], frame[1], sy),
        ),
        j,
        l: [l11, l21, l22],
    }
}

/// Decodes a compact block into the lane form the kernels read (blocks.rs), all 16 lanes (J by
/// `half`'s slice conversion: F16C when the CPU has it).
#[inline(always)]
pub(super) fn decode_block(b: &CompactBlock, frame: &[f32; 4], out: &mut LobeBlock) {
    let mut j = [0.0f32; 3 * LANES];
    b[2 * LANES..]
        .reinterpret_cast::<f16>()
        .convert_to_f32_slice(&mut j);
    let (sx, sy) = steps(frame);
    let [mx, my, j11, j21, j22, l11, l21, l22] = out.lanes_mut();
    for i in 0..LANES {
        mx[i] = decode_mean(b[i], frame[0], sx);
        my[i] = decode_mean(b[LANES + i], frame[1], sy);
    }
    for i in 0..LANES {
        let (a, c, d) = (j[i], j[LANES + i], j[2 * LANES + i]);
        j11[i] = a;
        j21[i] = c;
        j22[i] = d;
        let (x, y, z) = chol_of_j(a, c, d);
        l11[i] = x;
        l21[i] = y;
        l22[i] = z;
    }
}

#[inline]
pub(super) fn inside(inner: &[f32; 4], outer: &[f32; 4]) -> bool {
    inner[0] >= outer[0] && inner[1] >= outer[1] && inner[2] <= outer[2] && inner[3] <= outer[3]
}

/// A compact level from its stored parts (the frames one per block, as written by `save`).
pub(super) fn assemble(
    w: usize,
    h: usize,
    blocks: Vec<CompactBlock>,
    frames: Vec<[f32; 4]>,
    error: Vec<u8>,
) -> CompactLevel {
    let bnx = w.div_ceil(SIDE);
    let frame0 = frames.first().copied().unwrap_or([0.0; 4]);
    let has_level2 = level_sizes(w, h).len() >= 3;
    let tree = SlopeTree::from_level2(w, h, if has_level2 { frames } else { Vec::new() });
    CompactLevel {
        grid: [w, h],
        bnx,
        blocks,
        frame0,
        tree,
        error,
    }
}

impl CompactLevel {
    /// The frame of block (bx, by): its level-2 box, or `frame0` for grids without level 2.
    #[inline(always)]
    pub fn frame(&self, bx: usize, by: usize) -> &[f32; 4] {
        if self.tree.top() >= 2 {
            self.tree.node_box(2, bx, by)
        } else {
            &self.frame0
        }
    }

    /// Decodes block (bx, by) into `out`.
    #[inline(always)]
    pub fn decode(&self, bx: usize, by: usize, out: &mut LobeBlock) {
        decode_block(&self.blocks[by * self.bnx + bx], self.frame(bx, by), out);
    }

    /// Node k (row major) decoded.
    #[inline]
    pub fn lane(&self, k: usize) -> Lane {
        let (x, y) = (k % self.grid[0], k / self.grid[0]);
        let (bx, by) = (x / SIDE, y / SIDE);
        decode_lane(
            &self.blocks[by * self.bnx + bx],
            self.frame(bx, by),
            (y % SIDE) * SIDE + x % SIDE,
        )
    }

    /// Node k as a [`SlopeGaussian`] (the decoded lobe exactly; the σ_min lobe if a stored lane is
    /// not a valid lobe, which the builder and the loader rule out).
    #[inline]
    pub fn lobe(&self, k: usize, sigma_min: f32) -> SlopeGaussian {
        self.lane(k)
            .gaussian()
            .unwrap_or_else(|| SlopeGaussian::from_moments([0.0; 5], sigma_min))
    }

    /// The merge-error bound of node k (0 at level 0).
    #[inline]
    pub fn error_at(&self, k: usize) -> f32 {
        self.error.get(k).map_or(0.0, |&c| decode_error(c))
    }

    /// Bytes held: blocks, quadtree (levels ≥ 2), merge errors and the frame of small grids.
    pub fn bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<CompactBlock>()
            + self.tree.bytes()
            + self.error.len()
            + std::mem::size_of::<[f32; 4]>()
    }

    /// The frames as stored in files: one per block (the level-2 boxes, or `frame0`).
    pub fn frames(&self) -> Vec<[f32; 4]> {
        if self.tree.top() >= 2 {
            self.tree.boxes[1].clone()
        } else {
            vec![self.frame0]
        }
    }

    /// Checks a loaded level: every real lane a valid lobe (J₁₁, J₂₂ in binary16's normal range,
    /// J₂₁ finite, the decoded lobe valid with its mean within `mean_bound`) whose box lies in its
    /// block's frame. Returns the first offence.
    pub fn check(&self, box_k: f32, mean_bound: f32) -> std::result::Result<(), String> {
        let bad = (0..self.blocks.len())
            .into_par_iter()
            .map_init(LobeBlock::zeroed, |blk, b| {
                (!self.block_ok(b, blk, box_k, mean_bound))
                    .then(|| self.block_fault(b, box_k, mean_bound))
            })
            .find_map_first(|fault| fault.flatten());
        bad.map_or(Ok(()), Err)
    }

    /// Whether every lane of block `b` passes [`CompactLevel::check`], by the block decoder and
    /// branch-free lane tests (the loader's fast path). J in binary16's normal range and a mean
    /// within `MAX_SLOPE` make the decoded lobe valid (L, L⁻¹ and the normalisation are then normal
    /// `f32` numbers: |J| ∈ [2⁻¹⁴, 65504] gives L₁₁, L₂₂ ∈ [1.3·10⁻⁵, 1.4·10⁴]).
    fn block_ok(&self, b: usize, blk: &mut LobeBlock, box_k: f32, mean_bound: f32) -> bool {
        let [w, h] = self.grid;
        let (bx, by) = (b % self.bnx, b / self.bnx);
        let frame = self.frame(bx, by);
        decode_block(&self.blocks[b], frame, blk);
        let [mx, my, j11, j21, j22, l11, l21, l22] = blk.lanes();
        let (lo, hi) = (f16::MIN_POSITIVE.to_f32(), f16::MAX.to_f32());
        let mut ok = true;
        for i in 0..LANES {
            let (x, y) = (bx * SIDE + i % SIDE, by * SIDE + i / SIDE);
            let real = (x < w) & (y < h);
            let j_ok = (j11[i] >= lo)
                & (j11[i] <= hi)
                & (j22[i] >= lo)
                & (j22[i] <= hi)
                & j21[i].is_finite();
            let m_ok = (mx[i].abs() <= mean_bound) & (my[i].abs() <= mean_bound);
            let hx = box_k * l11[i].abs();
            let hy = box_k * (l21[i] * l21[i] + l22[i] * l22[i]).sqrt();
            let b_ok = (mx[i] - hx >= frame[0])
                & (my[i] - hy >= frame[1])
                & (mx[i] + hx <= frame[2])
                & (my[i] + hy <= frame[3]);
            ok &= j_ok & (!real | (m_ok & b_ok));
        }
        ok
    }

    /// The first offence in block `b` (see [`CompactLevel::check`]), lane by lane.
    fn block_fault(&self, b: usize, box_k: f32, mean_bound: f32) -> Option<String> {
        let [w, h] = self.grid;
        {
            let (bx, by) = (b % self.bnx, b / self.bnx);
            let frame = self.frame(bx, by);
            for lane in 0..LANES {
                let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
                let d = decode_lane(&self.blocks[b], frame, lane);
                let [j11, j21, j22] = d.j;
                let normal = |v: f32| (f16::MIN_POSITIVE.to_f32()..=f16::MAX.to_f32()).contains(&v);
                if !(normal(j11) && normal(j22) && j21.is_finite()) {
                    return Some(format!("block {b} lane {lane}: J = {:?} out of range", d.j));
                }
                if x >= w || y >= h {
                    continue;
                }
                if !(d.mean.x.abs() <= mean_bound && d.mean.y.abs() <= mean_bound)
                    || d.gaussian().is_none()
                {
                    return Some(format!("lobe ({x}, {y}): not a valid lobe ({d:?})"));
                }
                if !inside(&d.slope_box(box_k), frame) {
                    return Some(format!(
                        "lobe ({x}, {y}): its slope box lies outside its block's box {frame:?}"
                    ));
                }
            }
            None
        }
    }
}

/// The lobes in compact storage: every level of detail, level 0 first (module docs).
#[derive(Clone, Debug)]
pub(super) struct CompactStorage {
    levels: Vec<CompactLevel>,
    sigma_min: f32,
}

impl CompactStorage {
    /// The storage of compact levels (level 0 first, at least one): built (compact_encode.rs) or
    /// loaded and checked ([`CompactLevel::check`]).
    pub fn new(levels: Vec<CompactLevel>, sigma_min: f32) -> CompactStorage {
        debug_assert!(!levels.is_empty());
        CompactStorage { levels, sigma_min }
    }

    /// The levels, level 0 first.
    pub fn levels(&self) -> &[CompactLevel] {
        &self.levels
    }
}

impl LobeStore for CompactStorage {
    type Level<'a> = CompactView<'a>;

    fn level_count(&self) -> usize {
        self.levels.len()
    }

    #[inline]
    fn level(&self, l: usize) -> CompactView<'_> {
        let l = l.min(self.levels.len() - 1);
        CompactView {
            level: l,
            data: &self.levels[l],
            sigma_min: self.sigma_min,
        }
    }

    /// Trilinear in the decoded levels' raw moments ([`filtered`]).
    fn filtered_moments(&self, p: [f64; 2], lod: f64) -> [f32; 5] {
        filtered(&self.levels, p, lod)
    }

    /// False: compact storage holds no filtered-mixture chain (its footprints above the cost cap
    /// get the filtered lobe).
    fn lobe_moments(&self, i: i64, j: i64) -> [f32; 5] {
        let l0 = &self.levels[0];
        let [nx, ny] = l0.grid;
        let (i, j) = (i.rem_euclid(nx as i64), j.rem_euclid(ny as i64));
        l0.lane(j as usize * nx + i as usize)
            .raw_moments()
            .map(|v| v as f32)
    }

    fn filtered_mixture(&self, _p: [f64; 2], _lod: f64, _set: &mut LobeSet) -> bool {
        false
    }

    /// Level 0's compact blocks in `block_bytes`, its quadtree (levels ≥ 2) and frame in
    /// `hierarchy_bytes`, the levels l ≥ 1 in `level_bytes`; no moments, no mip chain.
    fn hierarchy(&self) -> Option<&crate::glint::kernels::gmm::GmmPyramid> {
        None
    }

    fn memory(&self) -> MixtureMemory {
        let l0 = &self.levels[0];
        MixtureMemory {
            lobes: l0.grid[0] * l0.grid[1],
            lobe_bytes: 0,
            hierarchy_bytes: l0.tree.bytes() + std::mem::size_of::<[f32; 4]>(),
            mip_bytes: 0,
            block_bytes: l0.blocks.len() * std::mem::size_of::<CompactBlock>(),
            level_bytes: self.levels[1..].iter().map(CompactLevel::bytes).sum(),
        }
    }
}

/// A level of [`CompactStorage`] as a patch reads it: every block decoded on each visit.
#[derive(Clone, Copy)]
pub(super) struct CompactView<'a> {
    level: usize,
    data: &'a CompactLevel,
    sigma_min: f32,
}

impl std::fmt::Debug for CompactView<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompactView")
            .field("level", &self.level)
            .field("grid", &self.data.grid)
            .finish_non_exhaustive()
    }
}

impl LevelView for CompactView<'_> {
    type Scratch = LobeBlock;

    #[inline(always)]
    fn scratch() -> LobeBlock {
        LobeBlock::zeroed()
    }

    #[inline(always)]
    fn level(&self) -> usize {
        self.level
    }

    #[inline(always)]
    fn grid(&self) -> [usize; 2] {
        self.data.grid
    }

    /// The quadtree from level 2 up (its level-2 boxes are the blocks' frames).
    #[inline(always)]
    fn tree(&self) -> &SlopeTree {
        &self.data.tree
    }

    /// The compact block decoded into `scratch`.
    #[inline(always)]
    fn block<'s>(&'s self, bx: usize, by: usize, scratch: &'s mut LobeBlock) -> &'s LobeBlock {
        self.data.decode(bx, by, scratch);
        scratch
    }

    #[inline]
    fn lobe(&self, k: usize) -> SlopeGaussian {
        self.data.lobe(k, self.sigma_min)
    }

    /// Σ = L Lᵀ of the decoded lane, in `f64`.
    #[inline]
    fn mean_cov(&self, k: usize) -> ([f64; 2], [f64; 3]) {
        let d = self.data.lane(k);
        let [l11, l21, l22] = d.l.map(f64::from);
        (
            [d.mean.x as f64, d.mean.y as f64],
            [l11 * l11, l11 * l21, l21 * l21 + l22 * l22],
        )
    }

    /// The one stored code per node, the bound at r = 0 plus the encoding's TV: an upper bound at
    /// every resolution r ≥ 0 (blurring both densities only shrinks a TV), so `res` is not read.
    #[inline]
    fn error(&self, k: usize, _res: usize) -> f32 {
        self.data.error_at(k)
    }
}

/// The filtered moments of a footprint centred at `p` (level-0 lobe units) at level of detail
/// `lod`, from compact levels: trilinear in the levels' decoded raw moments (as the moment mip chain
/// lookup, `hierarchy::LobePyramid::filtered`, with the levels of detail as its levels; lod clamped
/// to the coarsest level held, NaN → 0).
pub(super) fn filtered(levels: &[CompactLevel], p: [f64; 2], lod: f64) -> [f32; 5] {
    super::hierarchy::trilinear(
        levels.len(),
        p,
        lod,
        |l| levels[l].grid,
        |l, k| levels[l].lane(k).raw_moments(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_codes_round_up_and_are_monotone() {
        assert_eq!(decode_error(0), 0.0);
        assert_eq!(decode_error(255), 1.0);
        for c in 1..255u8 {
            assert!(decode_error(c) < decode_error(c + 1), "{c}");
        }
        let mut e = 1e-12f64;
        while e < 2.0 {
            let c = encode_error(e);
            assert!(decode_error(c) as f64 >= e.min(1.0), "{e}: {c}");
            if c > 1 {
                assert!(
                    (decode_error(c - 1) as f64) < e,
                    "{e}: {c} not the smallest"
                );
            }
            // Within a factor 2^(1/8) above e (when e is in the coded range).
            if e > 3e-10 && e <= 1.0 {
                assert!(decode_error(c) as f64 <= e * 1.0906 + 1e-12, "{e}: {c}");
            }
            e *= 1.013;
        }
        assert_eq!(encode_error(0.0), 0);
        assert_eq!(encode_error(f64::NAN), 255);
    }
}
