//! The per-footprint work of a patch (done once, when it is made): the footprint's Gaussian in lobe
//! units, the level of detail's error pass and the gather at a level (choice.rs chooses the form): the rectangle of nodes
//! within `weight_sigmas` of the effective Gaussian k_i ∗ k_P, their normalised weights W_i (stored
//! densely per "slot" of the rectangle, with a cdf for sampling, and again in the lobe blocks'
//! layout), the patch mean slope and covariance and the level's error bound. An axis of the
//! rectangle at least one period long is folded onto the node grid (a node's slot then carries the
//! sum of its periodic images' weights), so a patch never holds more slots than the level has
//! nodes.
//!
//! Generic over the storage ([`LobeStore`], [`LevelView`]): compiled once per storage.

use super::blocks::SIDE;
use super::params::{PatchOptions, SeedKernel};
use super::storage::{LevelView, LobeStore};
use crate::glint::Footprint;
use crate::glint::kernels::lanes::LANES;
use crate::glint::scratch::Lent;
use glam::Vec2;

/// The slots of one axis of the weight rectangle.
#[derive(Clone, Copy, Debug)]
pub(super) struct AxisSlots {
    /// First unwrapped lobe index (unused when folded).
    start: i64,
    /// Number of slots.
    pub len: usize,
    /// Lobes along this axis.
    pub n: usize,
    /// Folded onto [0, n) (slot = lobe index).
    folded: bool,
}

impl AxisSlots {
    /// Lobe indices I with |I + ½ − c| ≤ half, folded if they span a period or more.
    fn new(c: f64, half: f64, n: usize) -> AxisSlots {
        let lo = (c - 0.5 - half).ceil();
        let hi = (c - 0.5 + half).floor();
        let len = if hi >= lo { (hi - lo) as usize + 1 } else { 1 };
        let start = if hi >= lo {
            lo as i64
        } else {
            (c - 0.5).round() as i64
        };
        if len >= n {
            AxisSlots {
                start,
                len: n,
                n,
                folded: true,
            }
        } else {
            AxisSlots {
                start,
                len,
                n,
                folded: false,
            }
        }
    }

    /// The slot of unwrapped lobe index I (which must lie in the rectangle).
    #[inline]
    fn slot_of_unwrapped(&self, i: i64) -> usize {
        if self.folded {
            i.rem_euclid(self.n as i64) as usize
        } else {
            (i - self.start) as usize
        }
    }

    /// The lobe index of a slot.
    #[inline]
    pub fn lobe_of_slot(&self, s: usize) -> usize {
        if self.folded {
            s
        } else {
            (self.start + s as i64).rem_euclid(self.n as i64) as usize
        }
    }

    /// The unwrapped lobe indices whose weights are summed (the whole ±half range when folded).
    fn unwrapped_range(&self, c: f64, half: f64) -> (i64, i64) {
        if self.folded {
            (
                (c - 0.5 - half).ceil() as i64,
                (c - 0.5 + half).floor() as i64,
            )
        } else {
            (self.start, self.start + self.len as i64 - 1)
        }
    }

    /// Segments [lo, hi) of lobe indices with slot = i + off, covering the slots.
    fn segments(&self) -> ([(usize, usize, i64); 2], usize) {
        let mut out = [(0, 0, 0); 2];
        if self.folded {
            out[0] = (0, self.n, 0);
            return (out, 1);
        }
        let first = self.start.rem_euclid(self.n as i64) as usize;
        let run = self.len.min(self.n - first);
        out[0] = (first, first + run, -(first as i64));
        if run < self.len {
            out[1] = (0, self.len - run, run as i64);
            (out, 2)
        } else {
            (out, 1)
        }
    }
}

/// The per-slot buffers of a patch: the mixture's buffer type in a
/// [`GlintScratch`](crate::glint::GlintScratch).
#[derive(Clone, Debug, Default)]
pub(crate) struct SlotBuffers {
    /// Normalised W per slot, row major (slot_y * len_x + slot_x), summing to 1.
    pub weights: Vec<f32>,
    /// Cumulative weights (f64), last = Σ of `weights` in f64.
    pub cdf: Vec<f64>,
    /// The weights again in the lobe blocks' layout: per [`BlockRect`], its blocks row major, 16
    /// lanes each (0 for lanes outside the rectangle or the grid).
    pub block_weights: Vec<f32>,
}

/// One (x segment × y segment) rectangle of a patch's lobes, with its blocks.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BlockRect {
    /// Lobe ranges [lo, hi) along x and y.
    pub x: (usize, usize),
    pub y: (usize, usize),
    /// First block and the block counts along x and y.
    pub bx0: usize,
    pub by0: usize,
    pub bw: usize,
    pub bh: usize,
    /// Offset of the rectangle's first block in `block_weights`, in lanes.
    offset: usize,
}

impl BlockRect {
    /// The lane weights of block (bx, by) (absolute block coordinates, inside the rectangle).
    /// `#[inline(always)]`: called inside the block passes, whose AVX2 copy inlines only what is
    /// forced (simd.rs, `dispatch`).
    #[inline(always)]
    pub fn weights<'w>(&self, bw: &'w [f32], bx: usize, by: usize) -> &'w [f32; LANES] {
        let o = self.offset + ((by - self.by0) * self.bw + (bx - self.bx0)) * LANES;
        bw[o..o + LANES].try_into().expect("16 lanes")
    }
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
        let [a, b, _] = self.inv;
        let dx = i0 as f64 + 0.5 - self.c[0];
        let dy = j as f64 + 0.5 - self.c[1];
        let mut e = self.weight(i0, j);
        let mut r = (-0.5 * (a * (2.0 * dx + 1.0) + 2.0 * b * dy)).exp();
        let s = (-a).exp();
        std::iter::repeat_with(move || {
            let out = e;
            e *= r;
            r *= s;
            out
        })
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
    let w = &mut bufs.cdf;
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

/// The normalised weights of the level's nodes over the footprint (`eff`), their cdf and block
/// layout, the patch mean slope, its covariance when `second_moments` (what the approximate
/// masking reads; the lobes' covariances are not read otherwise) and the level-of-detail bound at
/// the resolution of index `res`, in `bufs`.
pub(super) fn gather<'b, L: LevelView>(
    weight_sigmas: f32,
    lv: L,
    eff: &Effective,
    res: usize,
    second_moments: bool,
    mut bufs: Lent<'b, SlotBuffers>,
) -> Gathered<'b> {
    // Raw weights are summed into the cdf buffer, then normalised and accumulated in place.
    let SlotBuffers { weights, cdf, .. } = &mut *bufs;
    weights.clear();
    let axes = slot_weights(weight_sigmas, lv, eff, cdf);
    let nx = lv.grid()[0];
    let w = cdf;
    let total: f64 = w.iter().sum();
    // total ≥ the nearest node's weight ≥ exp(−½ · 2 · 0.5²/v) with v the smallest variance of
    // Σ_eff: σ_k² ≈ 0.18 at level 0 (≈ 0.06), (σ_k² + (4^l − 1)/12)/4^l > 1/12 at level l (> 0.04)
    // (|d| ≤ ½ per axis), so the division is safe.
    let inv = if total > 0.0 { 1.0 / total } else { 0.0 };
    let mut acc = 0.0;
    // Σ W μ and Σ W (Σ + μ μᵀ) with the lobes' covariances as D uses them.
    let mut m1 = [0.0f64; 2];
    let mut m2 = [0.0f64; 3];
    let mut lod_error = 0.0f64;
    // Level 0 has no merge error (its term is 0).
    let merged = lv.level() > 0;
    // Written in slot order, as the walk below visits the slots (no capacity test per slot).
    weights.clear();
    weights.resize(w.len(), 0.0);
    let mut out = weights.iter_mut();
    for_each_slot_lobe(&axes, nx, w, |wi, k| {
        let wn = *wi * inv;
        acc += wn;
        *wi = acc;
        if merged {
            lod_error += wn * lv.error(k, res) as f64;
        }
        if second_moments {
            let (mu, cov) = lv.mean_cov(k);
            m1[0] += wn * mu[0];
            m1[1] += wn * mu[1];
            m2[0] += wn * (cov[0] + mu[0] * mu[0]);
            m2[1] += wn * (cov[1] + mu[0] * mu[1]);
            m2[2] += wn * (cov[2] + mu[1] * mu[1]);
        } else {
            let mu = lv.mean(k);
            m1[0] += wn * mu[0];
            m1[1] += wn * mu[1];
        }
        if let Some(o) = out.next() {
            *o = wn as f32;
        }
    });
    let (rects, n_rects) = block_weights(&axes, &mut bufs);
    // Σ W = 1 up to rounding; the covariance is floored at 0 against cancellation.
    let slope_cov = if second_moments {
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
        lod_error,
        slope_cov,
    }
}

/// Lays the slot weights out per lobe block: one [`BlockRect`] per (x segment × y segment) of
/// the slots (at most 4, disjoint in lobe space), each covering the blocks its lobes touch.
fn block_weights(axes: &[AxisSlots; 2], bufs: &mut SlotBuffers) -> ([BlockRect; 4], usize) {
    let (xs, nxs) = axes[0].segments();
    let (ys, nys) = axes[1].segments();
    let mut rects = [BlockRect::default(); 4];
    let mut offs = [(0i64, 0i64); 4];
    let mut n = 0;
    let mut total = 0;
    for &(x_lo, x_hi, x_off) in &xs[..nxs] {
        for &(y_lo, y_hi, y_off) in &ys[..nys] {
            let (bx0, by0) = (x_lo / SIDE, y_lo / SIDE);
            let (bw, bh) = (x_hi.div_ceil(SIDE) - bx0, y_hi.div_ceil(SIDE) - by0);
            rects[n] = BlockRect {
                x: (x_lo, x_hi),
                y: (y_lo, y_hi),
                bx0,
                by0,
                bw,
                bh,
                offset: total,
            };
            offs[n] = (x_off, y_off);
            total += bw * bh * LANES;
            n += 1;
        }
    }
    let SlotBuffers {
        weights,
        block_weights,
        ..
    } = bufs;
    block_weights.clear();
    block_weights.resize(total, 0.0);
    let lx = axes[0].len;
    for (r, &(x_off, y_off)) in rects[..n].iter().zip(&offs[..n]) {
        for y in r.y.0..r.y.1 {
            let sy = (y as i64 + y_off) as usize;
            let src = &weights[sy * lx..(sy + 1) * lx];
            let row = r.offset + (y / SIDE - r.by0) * r.bw * LANES + (y % SIDE) * SIDE;
            // The row's lobes block by block: up to SIDE consecutive lanes per block.
            let mut x = r.x.0;
            while x < r.x.1 {
                let bx = x / SIDE;
                let end = ((bx + 1) * SIDE).min(r.x.1);
                let o = row + (bx - r.bx0) * LANES + x % SIDE;
                let sx = (x as i64 + x_off) as usize;
                let (dst, from) = (
                    &mut block_weights[o..o + (end - x)],
                    &src[sx..sx + (end - x)],
                );
                if let (Ok(d), Ok(f)) = (
                    <&mut [f32; SIDE]>::try_from(&mut *dst),
                    <&[f32; SIDE]>::try_from(from),
                ) {
                    // A whole block row: one fixed-size move (a library call per short slice
                    // otherwise).
                    *d = *f;
                } else {
                    for (d, f) in dst.iter_mut().zip(from) {
                        *d = *f;
                    }
                }
                x = end;
            }
        }
    }
    (rects, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_segments_cover_the_slots_once() {
        for &(c, half, n) in &[
            (0.2, 1.3, 8usize),
            (7.9, 2.0, 8),
            (3.5, 0.1, 8),
            (4.0, 9.0, 8),
            (0.5, 0.0, 1),
        ] {
            let a = AxisSlots::new(c, half, n);
            let (seg, k) = a.segments();
            let mut seen = vec![0; a.len];
            for &(lo, hi, off) in &seg[..k] {
                for i in lo..hi {
                    let s = (i as i64 + off) as usize;
                    assert_eq!(a.lobe_of_slot(s), i, "{c} {half} {n}");
                    seen[s] += 1;
                }
            }
            assert!(seen.iter().all(|&v| v == 1), "{c} {half} {n}: {seen:?}");
            let (lo, hi) = a.unwrapped_range(c, half);
            for i in lo..=hi {
                assert!(a.slot_of_unwrapped(i) < a.len);
            }
        }
    }
}
