//! The per-footprint work of a patch (done once, when it is made): the footprint's Gaussian in lobe
//! units, the level of detail's error pass and the gather at a level (choice.rs chooses the form):
//! the rectangle of nodes within `weight_sigmas` of the effective Gaussian k_i ∗ k_P (slots.rs),
//! their normalised weights W_i written in the lobe blocks' layout with a cdf per block, the patch
//! mean slope and covariance and the level's error bound. An axis of the rectangle at least one
//! period long is folded onto the node grid (a node's lane then carries the sum of its periodic
//! images' weights), so a patch never holds more slots than the level has nodes.
//!
//! Generic over the storage ([`LobeStore`], [`LevelView`]): compiled once per storage.

use super::blocks::SIDE;
use super::params::{PatchOptions, SeedKernel};
use super::slots::{AxisSlots, BlockRect, block_rects};
use super::storage::{LevelView, LobeStore};
use crate::glint::Footprint;
use crate::glint::kernels::lanes::LANES;
use crate::glint::scratch::Lent;
use glam::Vec2;

/// The per-slot buffers of a patch: the mixture's buffer type in a
/// [`GlintScratch`](crate::glint::GlintScratch).
#[derive(Clone, Debug, Default)]
pub(crate) struct SlotBuffers {
    /// The normalised weights W_i in the lobe blocks' layout: per [`BlockRect`], its blocks row
    /// major, 16 lanes each (0 for lanes outside the rectangle or the grid); they sum to 1.
    pub block_weights: Vec<f32>,
    /// Cumulative Σ W per block, in `block_weights`' order (f64; the last is Σ W).
    pub block_cdf: Vec<f64>,
    /// The raw weights of the level-of-detail search's error pass, per slot.
    work: Vec<f64>,
}

/// The gathered lobes of a footprint.
#[derive(Clone, Debug)]
pub(super) struct Gathered<'a> {
    pub axes: [AxisSlots; 2],
    /// Weights and their cdf, per slot, and the weights per block.
    pub bufs: Lent<'a, SlotBuffers>,
    /// The lobe rectangles (one per x segment × y segment) and how many there are.
    pub rects: [BlockRect; 4],
    pub n_rects: usize,
    /// Σ W_i μ_i: the patch mean slope.
    pub mean_slope: Vec2,
    /// Σ W_n e_r(n) at the patch's resolution r: the bound of the TV between this level's patch and
    /// the full mixture's, both blurred by N(0, r² I) in slope space (0 at level 0).
    pub lod_error: f64,
    /// The patch's slope covariance Σ_P = Σ W_i (Σ_i + μ_i μ_iᵀ) − μ_P μ_Pᵀ, [xx, xy, yy] (f64), with
    /// each lobe's covariance as its D uses it (floored, correlation clamped): the second moment that
    /// the approximate masking's Scarf bound needs, and only it (zero unless the gather was asked
    /// for second moments).
    pub slope_cov: [f64; 3],
}

/// The effective Gaussian k_i ∗ k_P in lobe units: centre and inverse covariance.
pub(super) struct Effective {
    c: [f64; 2],
    /// Σ_eff = [[a, b], [b, d]].
    cov: [f64; 3],
    /// Σ_eff⁻¹.
    inv: [f64; 3],
}

/// The footprint's Gaussian k_P in level-0 lobe units (lobe i centred at i + ½): centre and
/// covariance [xx, xy, yy]; with the seed kernel the lobes were built with.
pub(super) struct FootprintLobes {
    pub c: [f64; 2],
    pub cov: [f64; 3],
    /// The seed kernel and its truncation (the position weights read its variance, the sub-texel
    /// lobe both).
    seed: (SeedKernel, f32),
}

impl FootprintLobes {
    /// The footprint on a map of `map` = (width, height) texels whose lobes are `spacing` texels
    /// apart, seeded by `seed` (truncated at ±`kernel_sigmas` σ if Gaussian).
    pub fn new(
        footprint: &Footprint,
        map: (usize, usize),
        spacing: [f64; 2],
        seed: SeedKernel,
        kernel_sigmas: f32,
    ) -> Self {
        let (c, s) = footprint.gaussian_texels(map.0, map.1);
        let [hx, hy] = spacing;
        let o = seed.origin();
        FootprintLobes {
            seed: (seed, kernel_sigmas),
            c: [(c.x as f64 - o) / hx, (c.y as f64 - o) / hy],
            cov: [
                s.x_axis.x as f64 / (hx * hx),
                s.x_axis.y as f64 / (hx * hy),
                s.y_axis.y as f64 / (hy * hy),
            ],
        }
    }

    /// The footprint's area in lobe cells (12 √det Σ_P: a uniform square of side a has σ² = a²/12).
    pub fn area(&self) -> f64 {
        let [sxx, sxy, syy] = self.cov;
        12.0 * (sxx * syy - sxy * sxy).max(0.0).sqrt()
    }

    /// The seed kernel and its truncation (what the sub-texel lobe reads).
    pub fn seed(&self) -> (SeedKernel, f32) {
        self.seed
    }

    /// The smaller eigenvalue of Σ_P (lobe units²).
    fn min_variance(&self) -> f64 {
        let [a, b, d] = self.cov;
        let m = 0.5 * (a + d);
        let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
        (m - r).max(0.0)
    }
}

impl Effective {
    /// The effective Gaussian of the nodes of level l, in that level's units (a node spans 2^l
    /// lobes): centre c / 2^l and covariance (Σ_P + (σ_k² + (4^l − 1)/12) I) / 4^l, σ_k² the seed
    /// kernel's weight variance (the Gaussian's, or the cell's 1/12, so that a cell node's is the
    /// 4^l/12 of its 2^l-lobe cell). The added (4^l − 1)/12 is the variance of the 2^l lobe positions
    /// a node spans along each axis, so a node's weight is the moment-matched Gaussian of the sum of
    /// its lobes' weights (exact at l = 0, where the formula is the level-0 effective Gaussian
    /// k_i ∗ k_P).
    pub(super) fn at_level(fp: &FootprintLobes, l: usize) -> Effective {
        let n2 = (1u64 << (2 * l)) as f64;
        let k2 = fp.seed.0.weight_variance() + (n2 - 1.0) / 12.0;
        let scale = 1.0 / (1u64 << l) as f64;
        let c = [fp.c[0] * scale, fp.c[1] * scale];
        let [sxx, sxy, syy] = fp.cov;
        let (a, b, d) = ((sxx + k2) / n2, sxy / n2, (syy + k2) / n2);
        let det = a * d - b * b;
        let inv = [d / det, -b / det, a / det];
        Effective {
            c,
            cov: [a, b, d],
            inv,
        }
    }

    /// The weights of lobes (i0, j), (i0 + 1, j), … along a row, by the exact recurrence of a
    /// Gaussian on a lattice: with q(i) the quadratic form at lobe i, q(i + 1) − q(i) is linear in i,
    /// so e(i + 1) = e(i) r(i) and r(i + 1) = r(i) e^{−Σ⁻¹ₓₓ}: three `exp` per row, two
    /// multiplications per lobe (relative drift ~1e-16 per step, negligible over a footprint).
    fn row_weights(&self, i0: i64, j: i64) -> impl Iterator<Item = f64> {
        let (mut e, mut r, s) = self.row_recurrence(i0, j);
        std::iter::repeat_with(move || {
            let out = e;
            e *= r;
            r *= s;
            out
        })
    }

    /// The state (e, r, s) of [`Effective::row_weights`]'s recurrence at lobe (i0, j): the weight
    /// e of (i0, j), the ratio r to the next lobe's and the ratio s of consecutive ratios; each step
    /// returns e, then e ← e r, r ← r s.
    #[inline]
    fn row_recurrence(&self, i0: i64, j: i64) -> (f64, f64, f64) {
        let [a, b, _] = self.inv;
        let dx = i0 as f64 + 0.5 - self.c[0];
        let dy = j as f64 + 0.5 - self.c[1];
        let e = self.weight(i0, j);
        let r = (-0.5 * (a * (2.0 * dx + 1.0) + 2.0 * b * dy)).exp();
        (e, r, (-a).exp())
    }

    #[inline]
    fn weight(&self, i: i64, j: i64) -> f64 {
        let dx = i as f64 + 0.5 - self.c[0];
        let dy = j as f64 + 0.5 - self.c[1];
        let q = self.inv[0] * dx * dx + 2.0 * self.inv[1] * dx * dy + self.inv[2] * dy * dy;
        (-0.5 * q).exp()
    }
}

///   texels, docs/results.md) among the built levels; 0 when the tolerance is 0;
/// - finest: the smallest l whose node count (area / 4^l) is within the cost cap `lod_lobes`;
///   if that exceeds the built levels, the filtered lobe.
pub(super) fn level_range<S: LobeStore>(
    store: &S,
    fp: &FootprintLobes,
    area: f64,
    options: &PatchOptions,
) -> Option<(usize, usize)> {
    let top = store.level_count() - 1;
    let cap = options.lod_lobes as f64;
    let mut finest = 0;
    while area / (1u64 << (2 * finest)) as f64 > cap {
        finest += 1;
        if finest > top {
            return None;
        }
    }
    let mut coarsest = 0;
    if options.lod_tolerance > 0.0 {
        let s = fp.min_variance().sqrt();
        while coarsest < top && (2u64 << coarsest) as f64 <= 0.5 * s {
            coarsest += 1;
        }
    }
    Some((finest, coarsest.max(finest)))
}

/// The footprint's raw kernel weights of the level's nodes, summed per slot into `w`
/// (resized to the slot grid), and the slot axes (±`weight_sigmas` σ of Σ_eff per axis).
fn slot_weights<L: LevelView>(
    weight_sigmas: f32,
    lv: L,
    eff: &Effective,
    w: &mut Vec<f64>,
) -> [AxisSlots; 2] {
    let t = weight_sigmas as f64;
    let half = [t * eff.cov[0].sqrt(), t * eff.cov[2].sqrt()];
    let axes = [
        AxisSlots::new(eff.c[0], half[0], lv.grid()[0]),
        AxisSlots::new(eff.c[1], half[1], lv.grid()[1]),
    ];
    let (lx, ly) = (axes[0].len, axes[1].len);
    w.clear();
    let (i0, i1) = axes[0].unwrapped_range(eff.c[0], half[0]);
    let (j0, j1) = axes[1].unwrapped_range(eff.c[1], half[1]);
    if !axes[0].folded && !axes[1].folded {
        // One unwrapped lobe per slot, rows in slot order: written once, nothing to sum.
        for j in j0..=j1 {
            w.extend(eff.row_weights(i0, j).take(lx));
        }
        return axes;
    }
    w.resize(lx * ly, 0.0);
    for j in j0..=j1 {
        let sy = axes[1].slot_of_unwrapped(j);
        let row = &mut w[sy * lx..(sy + 1) * lx];
        if axes[0].folded {
            for (i, wi) in (i0..=i1).zip(eff.row_weights(i0, j)) {
                row[axes[0].slot_of_unwrapped(i)] += wi;
            }
        } else {
            // Unfolded: slot = i − i0, one unwrapped index per slot.
            for (slot, wi) in row.iter_mut().zip(eff.row_weights(i0, j)) {
                *slot += wi;
            }
        }
    }
    axes
}

/// Σ W_n e_r(n) of the level over the footprint at the resolution of index `res` (what
/// [`gather`] reports as `lod_error`), from the weights alone: the error-only pass of the
/// level-of-detail search.
pub(super) fn lod_error_of<L: LevelView>(
    weight_sigmas: f32,
    lv: L,
    eff: &Effective,
    res: usize,
    bufs: &mut Lent<'_, SlotBuffers>,
) -> f64 {
    let w = &mut bufs.work;
    let axes = slot_weights(weight_sigmas, lv, eff, w);
    let nx = lv.grid()[0];
    let (mut total, mut err) = (0.0f64, 0.0f64);
    for_each_slot_lobe(&axes, nx, w, |&mut wi, k| {
        total += wi;
        err += wi * lv.error(k, res) as f64;
    });
    if total > 0.0 { err / total } else { 0.0 }
}

/// Calls `f(slot, k)` for every slot of the rectangle `axes` (row major, `slots` holding one value
/// per slot) with k its node's index on a level of `nx` nodes per row: row by row, the node index
/// stepped along the row and wrapped at the grid's edge, so no slot divides its index out.
#[inline(always)]
fn for_each_slot_lobe<T>(
    axes: &[AxisSlots; 2],
    nx: usize,
    slots: &mut [T],
    mut f: impl FnMut(&mut T, usize),
) {
    let (x_first, grid_x) = (axes[0].lobe_of_slot(0), axes[0].n);
    for (sy, row) in slots.chunks_exact_mut(axes[0].len).enumerate() {
        let row_lobe = axes[1].lobe_of_slot(sy) * nx;
        let mut kx = x_first;
        for slot in row {
            f(slot, row_lobe + kx);
            kx += 1;
            if kx == grid_x {
                kx = 0;
            }
        }
    }
}

/// The normalised weights of the level's nodes over the footprint (`eff`) in the lobe blocks'
/// layout with their cdf per block, the patch mean slope, its covariance when `second_moments`
/// (what the approximate masking reads; the lobes' covariances are not read otherwise) and the
/// level-of-detail bound at the resolution of index `res`, in `bufs`.
///
/// One pass over the rectangle's unwrapped nodes, row by row: each node's raw Gaussian weight (the
/// row recurrence of [`Effective`]) is added straight into its block lane (a folded axis adds its
/// periodic images into the same lane) while the raw sums Σ w, Σ w μ (and Σ w (Σ + μ μᵀ), Σ w e)
/// accumulate in `f64`; a last pass over the lanes scales them by 1/Σ w and forms the block cdf.
pub(super) fn gather<'b, L: LevelView>(
    weight_sigmas: f32,
    lv: L,
    eff: &Effective,
    res: usize,
    second_moments: bool,
    mut bufs: Lent<'b, SlotBuffers>,
) -> Gathered<'b> {
    let t = weight_sigmas as f64;
    let half = [t * eff.cov[0].sqrt(), t * eff.cov[2].sqrt()];
    let axes = [
        AxisSlots::new(eff.c[0], half[0], lv.grid()[0]),
        AxisSlots::new(eff.c[1], half[1], lv.grid()[1]),
    ];
    let (rects, n_rects, lanes) = block_rects(&axes);
    let n_ys = axes[1].segments().1;
    // The slot at which each axis's second segment begins (its length when it has one).
    let run = [axes[0].first_run(), axes[1].first_run()];
    debug_assert!(run[0] >= axes[0].len || axes[0].segments().1 == 2);
    let (i0, i1) = axes[0].unwrapped_range(eff.c[0], half[0]);
    let (j0, j1) = axes[1].unwrapped_range(eff.c[1], half[1]);
    let count_x = (i1 - i0 + 1).max(0) as usize;
    let nx = lv.grid()[0];
    let SlotBuffers {
        block_weights,
        block_cdf,
        ..
    } = &mut *bufs;
    block_weights.clear();
    block_weights.resize(lanes, 0.0);
    // The blocks are asked for one block row ahead of the rows that read them (the first rows
    // now), so that their loads overlap instead of stalling one lane at a time; the passes then
    // find them in the caches.
    let prefetch_row = |by: usize| {
        for r in &rects[..n_rects] {
            if (r.by0..r.by0 + r.bh).contains(&by) {
                for bx in r.bx0..r.bx0 + r.bw {
                    lv.prefetch_block(bx, by);
                }
            }
        }
    };
    for r in &rects[..n_rects] {
        prefetch_row(r.by0);
    }
    let (mut total, mut lod_error) = (0.0f64, 0.0f64);
    // Σ w μ and Σ w (Σ + μ μᵀ) with the lobes' covariances as D uses them.
    let mut m1 = [0.0f64; 2];
    let mut m2 = [0.0f64; 3];
    // Level 0 has no merge error (its term is 0).
    let merged = lv.level() > 0;
    let sx0 = axes[0].slot_of_unwrapped(i0);
    let x0 = axes[0].lobe_of_slot(sx0);
    let n_x = axes[0].n;
    for j in j0..=j1 {
        let sy = axes[1].slot_of_unwrapped(j);
        let y = axes[1].lobe_of_slot(sy);
        let ry = usize::from(sy >= run[1]);
        let (by, lane_row) = (y / SIDE, (y % SIDE) * SIDE);
        if y.is_multiple_of(SIDE) {
            prefetch_row(by + 1);
        }
        let row_k = y * nx;
        let (mut e, mut r, s) = eff.row_recurrence(i0, j);
        let (mut sx, mut x, mut left) = (sx0, x0, count_x);
        // Runs of consecutive nodes up to the grid's edge, where the nodes wrap (into the second
        // segment of an unfolded axis, or onto the same lanes of a folded one).
        while left > 0 {
            let len = left.min(n_x - x);
            let rect = &rects[usize::from(sx >= run[0]) * n_ys + ry];
            let rect_row = rect.offset + (by - rect.by0) * rect.bw * LANES;
            // Each run in chunks of one block: its lanes and stored means read from one place.
            let (mut xx, end) = (x, x + len);
            while xx < end {
                let bx = xx / SIDE;
                let chunk_end = ((bx + 1) * SIDE).min(end);
                let lanes = rect_row + (bx - rect.bx0) * LANES + lane_row;
                let block = lv.stored_block(bx, by);
                for xi in xx..chunk_end {
                    let (w, k, lane) = (e, row_k + xi, lane_row + xi % SIDE);
                    e *= r;
                    r *= s;
                    total += w;
                    if second_moments {
                        let (mu, cov) = lv.mean_cov(k);
                        m1[0] += w * mu[0];
                        m1[1] += w * mu[1];
                        m2[0] += w * (cov[0] + mu[0] * mu[0]);
                        m2[1] += w * (cov[1] + mu[0] * mu[1]);
                        m2[2] += w * (cov[2] + mu[1] * mu[1]);
                    } else {
                        let mu = match block {
                            Some(b) => b.mean(lane),
                            None => lv.mean(k),
                        };
                        m1[0] += w * mu[0];
                        m1[1] += w * mu[1];
                    }
                    if merged {
                        lod_error += w * lv.error(k, res) as f64;
                    }
                    block_weights[lanes + xi % SIDE] += w as f32;
                }
                xx = chunk_end;
            }
            left -= len;
            (sx, x) = (if axes[0].folded { 0 } else { sx + len }, 0);
        }
    }
    // total ≥ the nearest node's weight ≥ exp(−½ · 2 · 0.5²/v) with v the smallest variance of
    // Σ_eff: σ_k² ≈ 0.18 at level 0 (≈ 0.06), (σ_k² + (4^l − 1)/12)/4^l > 1/12 at level l (> 0.04)
    // (|d| ≤ ½ per axis), so the division is safe.
    let inv = if total > 0.0 { 1.0 / total } else { 0.0 };
    let inv32 = inv as f32;
    block_cdf.clear();
    let mut acc = 0.0f64;
    for block in block_weights.chunks_exact_mut(LANES) {
        let mut sum = 0.0f64;
        for w in block.iter_mut() {
            *w *= inv32;
            sum += *w as f64;
        }
        acc += sum;
        block_cdf.push(acc);
    }
    let m1 = [m1[0] * inv, m1[1] * inv];
    // Σ W = 1 up to rounding; the covariance is floored at 0 against cancellation.
    let slope_cov = if second_moments {
        let m2 = m2.map(|v| v * inv);
        [
            (m2[0] - m1[0] * m1[0]).max(0.0),
            m2[1] - m1[0] * m1[1],
            (m2[2] - m1[1] * m1[1]).max(0.0),
        ]
    } else {
        [0.0; 3]
    };
    Gathered {
        axes,
        bufs,
        rects,
        n_rects,
        mean_slope: Vec2::new(m1[0] as f32, m1[1] as f32),
        lod_error: lod_error * inv,
        slope_cov,
    }
}

impl Gathered<'_> {
    /// Number of slots (nodes with a weight) of the patch.
    pub fn slot_count(&self) -> usize {
        self.axes[0].len * self.axes[1].len
    }

    /// The weight lane of slot (sx, sy) in `block_weights`.
    fn lane_of_slot(&self, sx: usize, sy: usize) -> usize {
        let (x, y) = (self.axes[0].lobe_of_slot(sx), self.axes[1].lobe_of_slot(sy));
        let n_ys = self.axes[1].segments().1;
        let rx = usize::from(sx >= self.axes[0].first_run());
        let ry = usize::from(sy >= self.axes[1].first_run());
        let r = &self.rects[rx * n_ys + ry];
        r.offset
            + ((y / SIDE - r.by0) * r.bw + (x / SIDE - r.bx0)) * LANES
            + (y % SIDE) * SIDE
            + x % SIDE
    }

    /// The normalised weight W of slot s (row major over the slot rectangle) and its node's index
    /// on a level of `nx` nodes per row.
    pub fn slot(&self, s: usize, nx: usize) -> (f32, usize) {
        let lx = self.axes[0].len;
        let (sx, sy) = (s % lx, s / lx);
        let w = self.bufs.block_weights[self.lane_of_slot(sx, sy)];
        let k = self.axes[1].lobe_of_slot(sy) * nx + self.axes[0].lobe_of_slot(sx);
        (w, k)
    }

    /// The node of lane `lane` of `block_weights` on a level of `nx` nodes per row.
    pub fn node_of_lane(&self, lane: usize, nx: usize) -> usize {
        let r = self.rects[..self.n_rects]
            .iter()
            .rev()
            .find(|r| r.offset <= lane)
            .unwrap_or(&self.rects[0]);
        let local = lane - r.offset;
        let (b, l) = (local / LANES, local % LANES);
        let (bx, by) = (r.bx0 + b % r.bw.max(1), r.by0 + b / r.bw.max(1));
        (by * SIDE + l / SIDE) * nx + bx * SIDE + l % SIDE
    }
}

#[cfg(test)]
mod tests;
