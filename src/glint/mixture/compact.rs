//! Compact storage of the mixture's lobes (issue 16 item 5, [`super::LobeStorage::Compact`]): every
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

use super::blocks::{J_SCALE, LANES, LobeBlock, SIDE};
use super::hierarchy::lobe_box;
use super::levels::{LevelRef, LobeLevel};
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
const QMAX: f32 = 65535.0;

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
fn steps(frame: &[f32; 4]) -> (f32, f32) {
    ((frame[2] - frame[0]) / QMAX, (frame[3] - frame[1]) / QMAX)
}

/// The decoded mean component of code q in a frame axis [lo, ·] of step `step`.
#[inline(always)]
fn decode_mean(q: u16, lo: f32, step: f32) -> f32 {
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
    /// The lane's slope box, exactly as [`lobe_box`] computes it from a lobe of this mean and L.
    fn slope_box(&self, k: f32) -> [f32; 4] {
        let [l11, l21, l22] = self.l;
        let hx = k * l11.abs();
        let hy = k * (l21 * l21 + l22 * l22).sqrt();
        let m = self.mean;
        [m.x - hx, m.y - hy, m.x + hx, m.y + hy]
    }

    /// The lane as a [`SlopeGaussian`] (exactly its mean and L); `None` if it is not a valid lobe.
    fn gaussian(&self) -> Option<SlopeGaussian> {
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

/// J = √(½ log₂ e) L⁻¹ of a lobe in `f64`, rounded once to binary16 bits.
fn encode_j(g: &SlopeGaussian) -> [u16; 3] {
    let l = g.cholesky();
    let (a, b, c) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
    [J_SCALE / a, -J_SCALE * b / (a * c), J_SCALE / c].map(|v| {
        // Finite by MIN_COMPACT_SIGMA (|J| ≤ 0.85 / sigma_min ≤ 42 500); clamped for totality.
        f16::from_f64(v.clamp(-65504.0, 65504.0)).to_bits()
    })
}

/// The code whose decoded mean is nearest to `mu` (ties to the lower code).
fn encode_mean(mu: f32, lo: f32, step: f32) -> u16 {
    if step.is_nan() || step <= 0.0 {
        return 0;
    }
    let t = ((mu - lo) / step).round().clamp(0.0, QMAX) as i64;
    let mut best = (f32::INFINITY, 0u16);
    for q in (t - 1).max(0)..=(t + 1).min(65535) {
        let e = (decode_mean(q as u16, lo, step) - mu).abs();
        if e < best.0 {
            best = (e, q as u16);
        }
    }
    best.1
}

#[inline]
fn inside(inner: &[f32; 4], outer: &[f32; 4]) -> bool {
    inner[0] >= outer[0] && inner[1] >= outer[1] && inner[2] <= outer[2] && inner[3] <= outer[3]
}

/// An upper bound of the total variation between two slope Gaussians: Pinsker's √(KL/2) with the
/// closed-form KL(b ‖ a), capped at 1, in `f64`.
///
/// # Reference
/// KL of two Gaussians: ½ (tr(Σa⁻¹Σb) + (μa − μb)ᵀ Σa⁻¹ (μa − μb) − 2 + ln(|Σa| / |Σb|)).
pub(super) fn tv_bound(a: &SlopeGaussian, b: &SlopeGaussian) -> f64 {
    let la = a.cholesky();
    let lb = b.cholesky();
    let (a11, a21, a22) = (la.x_axis.x as f64, la.x_axis.y as f64, la.y_axis.y as f64);
    let (b11, b21, b22) = (lb.x_axis.x as f64, lb.x_axis.y as f64, lb.y_axis.y as f64);
    // M = La⁻¹ Lb (lower triangular): tr(Σa⁻¹ Σb) = |M|²_F.
    let m11 = b11 / a11;
    let m22 = b22 / a22;
    let m21 = (b21 - a21 * m11) / a22;
    let tr = m11 * m11 + m21 * m21 + m22 * m22;
    let d = a.mean() - b.mean();
    let (dx, dy) = (d.x as f64, d.y as f64);
    let zx = dx / a11;
    let zy = (dy - a21 * zx) / a22;
    let ln_det = 2.0 * ((a11 * a22).ln() - (b11 * b22).ln());
    let kl = 0.5 * (tr + zx * zx + zy * zy - 2.0 + ln_det);
    if kl.is_finite() {
        (0.5 * kl.max(0.0)).sqrt().min(1.0)
    } else {
        1.0
    }
}

/// The compact form of one block of lobes: the words, the frame and, per lane, the TV bound
/// between the lobe and its decoded form (0 for padding lanes).
fn encode_block(
    lobes: &[SlopeGaussian; LANES],
    real: u16,
    box_k: f32,
) -> (CompactBlock, [f32; 4], [f32; LANES]) {
    let mut words = [0u16; WORDS];
    let is_real = |i: usize| real & (1 << i) != 0;
    // J first: it does not depend on the frame.
    for (i, g) in lobes.iter().enumerate() {
        let j = encode_j(g);
        for (c, v) in j.into_iter().enumerate() {
            words[(2 + c) * LANES + i] = v;
        }
    }
    let mut frame = [
        f32::INFINITY,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NEG_INFINITY,
    ];
    for (i, g) in lobes.iter().enumerate().filter(|(i, _)| is_real(*i)) {
        let _ = i;
        let b = lobe_box(g, box_k);
        frame = [
            frame[0].min(b[0]),
            frame[1].min(b[1]),
            frame[2].max(b[2]),
            frame[3].max(b[3]),
        ];
    }
    // Means in the frame; widen until every decoded lane's box lies in it (module docs).
    for round in 0..64 {
        let (sx, sy) = steps(&frame);
        for (i, g) in lobes.iter().enumerate() {
            let mu = g.mean();
            if is_real(i) {
                words[i] = encode_mean(mu.x, frame[0], sx);
                words[LANES + i] = encode_mean(mu.y, frame[1], sy);
            } else {
                words[i] = 0;
                words[LANES + i] = 0;
            }
        }
        let mut u = frame;
        for i in (0..LANES).filter(|&i| is_real(i)) {
            let b = decode_lane(&words, &frame, i).slope_box(box_k);
            u = [
                u[0].min(b[0]),
                u[1].min(b[1]),
                u[2].max(b[2]),
                u[3].max(b[3]),
            ];
        }
        if u == frame {
            break;
        }
        // Grow past the union by a share of the width that rises with the rounds (the means move by
        // at most half a step, ~2⁻¹⁷ of the width, each time the frame changes).
        let grow = 2f32.powi(-14 + round.min(12));
        let (gx, gy) = ((u[2] - u[0]) * grow, (u[3] - u[1]) * grow);
        frame = [u[0] - gx, u[1] - gy, u[2] + gx, u[3] + gy];
    }
    let mut tv = [0.0f32; LANES];
    for i in (0..LANES).filter(|&i| is_real(i)) {
        let d = decode_lane(&words, &frame, i)
            .gaussian()
            .map_or(1.0, |g| tv_bound(&lobes[i], &g));
        // Rounded up to f32.
        tv[i] = (d as f32).max(d as f32 * (1.0 + f32::EPSILON));
    }
    (words, frame, tv)
}

/// A level of `w × h` lobes (`lobe(k)` row major) in compact storage, with the TV bound of each
/// lobe's encoding (row major); the merge errors are left empty. Blocks in parallel.
pub(super) fn encode_level(
    w: usize,
    h: usize,
    lobe: impl Fn(usize) -> SlopeGaussian + Sync,
    pad: &SlopeGaussian,
    box_k: f32,
) -> (CompactLevel, Vec<f32>) {
    let (bnx, bny) = (w.div_ceil(SIDE), h.div_ceil(SIDE));
    let coded: Vec<(CompactBlock, [f32; 4], [f32; LANES])> = (0..bnx * bny)
        .into_par_iter()
        .map(|b| {
            let (bx, by) = (b % bnx, b / bnx);
            let mut real = 0u16;
            let lobes: [SlopeGaussian; LANES] = std::array::from_fn(|lane| {
                let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
                if x < w && y < h {
                    real |= 1 << lane;
                    lobe(y * w + x)
                } else {
                    *pad
                }
            });
            encode_block(&lobes, real, box_k)
        })
        .collect();
    let mut tv = vec![0.0f32; w * h];
    let mut blocks = Vec::with_capacity(coded.len());
    let mut frames = Vec::with_capacity(coded.len());
    for (b, (words, frame, t)) in coded.into_iter().enumerate() {
        let (bx, by) = (b % bnx, b / bnx);
        for (lane, &v) in t.iter().enumerate() {
            let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
            if x < w && y < h {
                tv[y * w + x] = v;
            }
        }
        blocks.push(words);
        frames.push(frame);
    }
    (assemble(w, h, blocks, frames, Vec::new()), tv)
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

/// Every level of detail of the lobes `moments` (nx × ny, row major) in compact storage: level 0
/// encoded from the full lobes, levels l ≥ 1 from the merged lobes of [`super::levels::build_levels`]
/// with their merge errors raised by the encodings' TV bounds (module docs).
pub(super) fn build(
    nx: usize,
    ny: usize,
    moments: &[[f32; 5]],
    sigma_min: f32,
    box_k: f32,
    full_levels: Vec<LobeLevel>,
) -> Vec<CompactLevel> {
    let pad = SlopeGaussian::from_moments([0.0; 5], sigma_min);
    let (l0, mut qmax) = encode_level(
        nx,
        ny,
        |k| SlopeGaussian::from_moments(moments[k], sigma_min),
        &pad,
        box_k,
    );
    let mut out = vec![l0];
    let mut pw = nx;
    for lv in full_levels {
        let [w, h] = lv.grid;
        // The largest level-0 encoding TV under each node.
        let q0: Vec<f32> = (0..w * h)
            .into_par_iter()
            .map(|k| {
                let (x, y) = (k % w, k / w);
                [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|(dx, dy)| qmax[(2 * y + dy) * pw + 2 * x + dx])
                    .fold(0.0f32, f32::max)
            })
            .collect();
        let (mut cl, q) = encode_level(
            w,
            h,
            |k| SlopeGaussian::from_moments(lv.moments[k], sigma_min),
            &pad,
            box_k,
        );
        cl.error = (0..w * h)
            .into_par_iter()
            .map(|k| encode_error(lv.error[0][k] as f64 + q[k] as f64 + q0[k] as f64))
            .collect();
        out.push(cl);
        qmax = q0;
        pw = w;
    }
    out
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

impl<'a> LevelRef<'a> {
    /// Block (bx, by) in the kernels' form: the stored block, or the compact block decoded into
    /// `buf`.
    #[inline(always)]
    pub fn block<'s>(&'s self, bx: usize, by: usize, buf: &'s mut LobeBlock) -> &'s LobeBlock {
        match self.compact {
            None => self.blocks.block(bx, by),
            Some(c) => {
                c.decode(bx, by, buf);
                buf
            }
        }
    }

    /// Node k's mean and covariance [xx, xy, yy] in `f64` (Σ = L Lᵀ of the decoded lane) under
    /// compact storage; `None` in full storage (which has the moments).
    #[inline]
    pub fn mean_cov(&self, k: usize) -> Option<([f64; 2], [f64; 3])> {
        let d = self.compact?.lane(k);
        let [l11, l21, l22] = d.l.map(f64::from);
        Some((
            [d.mean.x as f64, d.mean.y as f64],
            [l11 * l11, l11 * l21, l21 * l21 + l22 * l22],
        ))
    }

    /// Calls `leaf(x, y)` for every lobe in the rectangle [x.0, x.1) × [y.0, y.1) whose ancestors'
    /// boxes contain `s` (the scalar walk): down to the leaves in full storage; in compact storage,
    /// whose quadtree stops at level 2, every lobe of each level-2 node reached.
    pub fn for_each_leaf(
        &self,
        x: (usize, usize),
        y: (usize, usize),
        s: Vec2,
        mut leaf: impl FnMut(usize, usize),
    ) {
        if self.compact.is_none() {
            self.tree.for_each_leaf(x, y, s, leaf);
            return;
        }
        let mut lanes = |bx: usize, by: usize| {
            for ly in by * SIDE..(by * SIDE + SIDE).min(y.1) {
                for lx in bx * SIDE..(bx * SIDE + SIDE).min(x.1) {
                    if lx >= x.0 && ly >= y.0 {
                        leaf(lx, ly);
                    }
                }
            }
        };
        if self.tree.top() < 2 {
            lanes(0, 0);
        } else {
            self.tree.for_each_node(2, x, y, s, lanes);
        }
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

    /// Lobes of every kind: small and large means, narrow (σ_min) and wide, correlated to the
    /// clamp, in blocks of 16.
    fn test_lobes(seed: u64) -> Vec<SlopeGaussian> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..16 * 64)
            .map(|k| {
                let scale = [0.01f32, 0.3, 3.0, 40.0][k % 4];
                let (mx, my) = (scale * (2.0 * next() - 1.0), scale * (2.0 * next() - 1.0));
                let sig = [0.0f32, 0.005, 0.05, 0.5][(k / 4) % 4];
                let (sx, sy, r) = (sig * next(), sig * next(), 2.0 * next() - 1.0);
                let r = if k % 7 == 0 { r.signum() } else { r };
                SlopeGaussian::from_moments(
                    [
                        mx,
                        my,
                        mx * mx + sx * sx,
                        my * my + sy * sy,
                        mx * my + r * sx * sy,
                    ],
                    0.01,
                )
            })
            .collect()
    }

    /// Decode error bounds against the `f64` values of the full lobe: each mean within half a
    /// quantisation step plus the decode's two `f32` roundings (½ ulp of q·step and of the sum);
    /// each J entry within a relative 2⁻¹¹ (binary16 rounding) of J_SCALE L⁻¹ formed in `f64`;
    /// every decoded box inside the frame; the block decoder equal to the lane decoder bit for bit;
    /// L · (J / J_SCALE) = I to `f32` rounding.
    #[test]
    fn decode_error_bounds() {
        let box_k = 5.26f32;
        let (mut worst_mu, mut worst_j) = (0.0f64, 0.0f64);
        for (c, chunk) in test_lobes(7).chunks(LANES).enumerate() {
            let lobes: [SlopeGaussian; LANES] = std::array::from_fn(|i| chunk[i]);
            let real = if c.is_multiple_of(3) { 0x7fff } else { 0xffff };
            let (words, frame, tv) = encode_block(&lobes, real, box_k);
            let (sx, sy) = steps(&frame);
            let mut blk = LobeBlock::zeroed();
            decode_block(&words, &frame, &mut blk);
            let lanes = blk.lanes();
            for (i, g) in lobes.iter().enumerate() {
                let d = decode_lane(&words, &frame, i);
                let from_block: Vec<u32> = lanes.iter().map(|a| a[i].to_bits()).collect();
                let from_lane: Vec<u32> = [
                    d.mean.x, d.mean.y, d.j[0], d.j[1], d.j[2], d.l[0], d.l[1], d.l[2],
                ]
                .iter()
                .map(|v| v.to_bits())
                .collect();
                assert_eq!(from_block, from_lane, "lane {i}");
                if real & (1 << i) == 0 {
                    continue;
                }
                assert!(inside(&d.slope_box(box_k), &frame), "{d:?} {frame:?}");
                let mu = g.mean();
                let ulp = |v: f32| f32::EPSILON as f64 * v.abs().max(f32::MIN_POSITIVE) as f64;
                for (got, want, step, lo) in [
                    (d.mean.x, mu.x, sx, frame[0]),
                    (d.mean.y, mu.y, sy, frame[1]),
                ] {
                    let bound =
                        0.5 * step as f64 + ulp(lo.abs().max(got.abs())) + ulp(step * 65535.0);
                    let e = (got as f64 - want as f64).abs();
                    assert!(e <= bound, "mean {got} vs {want}: {e:e} > {bound:e}");
                    worst_mu = worst_mu.max(e / (0.5 * step as f64));
                }
                let l = g.cholesky();
                let (a, b, c) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
                let want = [J_SCALE / a, -J_SCALE * b / (a * c), J_SCALE / c];
                for (got, want) in d.j.iter().zip(want) {
                    let e = (*got as f64 - want).abs();
                    let bound = 2f64.powi(-11) * want.abs() + 2f64.powi(-25);
                    assert!(e <= bound, "J {got} vs {want}");
                    if want.abs() > 1e-3 {
                        worst_j = worst_j.max(e / want.abs());
                    }
                }
                // L J / s = I.
                let [l11, l21, l22] = d.l.map(f64::from);
                let [j11, j21, j22] = d.j.map(f64::from);
                let s = J_SCALE;
                assert!((l11 * j11 / s - 1.0).abs() < 1e-6);
                assert!((l22 * j22 / s - 1.0).abs() < 1e-6);
                assert!(
                    (l21 * j11 + l22 * j21).abs() / s
                        < 1e-6 * (l21.abs() * j11 + l22 * j21.abs()) / s + 1e-12
                );
                // The TV bound of the encoding: in [0, 1] (its size depends on the spread of the
                // block's means against each lobe's width: these test blocks mix scales at random).
                assert!((0.0..=1.0).contains(&tv[i]), "{}", tv[i]);
            }
        }
        println!(
            "mean error / half step ≤ {worst_mu:.3}, J relative ≤ {worst_j:e} (2^-11 = {:e})",
            2f64.powi(-11)
        );
        assert!(worst_mu > 0.2, "the test lobes exercise the quantisation");
    }

    #[test]
    fn tv_bound_is_zero_for_equal_and_grows() {
        let a =
            SlopeGaussian::from_moments([0.1, -0.2, 0.01 + 0.01, 0.04 + 0.02, -0.02 + 0.001], 0.01);
        assert!(tv_bound(&a, &a) < 1e-7);
        let b = SlopeGaussian::from_moments(
            [0.11, -0.2, 0.0121 + 0.01, 0.04 + 0.02, -0.022 + 0.001],
            0.01,
        );
        let t = tv_bound(&a, &b);
        assert!(t > 0.01 && t < 0.2, "{t}");
    }
}
