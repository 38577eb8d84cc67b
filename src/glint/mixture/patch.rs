//! The patch of a footprint: position weights W_i, D_P through the slope-box quadtree, exact and
//! approximate masking terms, and the two samplers (\[Chermain2019\] §4-5).
//!
//! Per-footprint work (done once in [`MixturePatch::new`]): the effective Gaussian k_i ∗ k_P in lobe
//! units, the rectangle of lobes within `weight_sigmas` of it, their normalised weights W_i (stored
//! densely per "slot" of the rectangle, with a cdf for sampling), the patch mean slope and the
//! filtered lobe of the moment mip chain. All of it at one level of detail (levels.rs): the coarsest
//! whose weighted merge-error bound meets the tolerance, moved coarser by the cost cap; the
//! "lobes" below are that level's nodes (the lobes themselves at level 0). An axis of the rectangle at least one period long is
//! folded onto the lobe grid (a lobe's slot then carries the sum of its periodic images' weights),
//! so a patch never holds more slots than the map has lobes.

use super::blocks::{self, LANES, SIDE};
use super::hierarchy::lobe_box;
use super::levels::{LevelRef, resolution_index};
use super::{BeckmannMixture, MaskingMode, PatchOptions, build::kernel_sigma};
use crate::frame::normal_to_slope;
use crate::glint::Footprint;
use crate::glint::GlintScratch;
use crate::glint::kernels::cdf::{invert_cdf, pick_streaming};
use crate::glint::kernels::slope_tree::contains;
use crate::glint::scratch::{Lent, Loan};
use crate::math::{finite_f32, finite_or_zero};
use crate::ndf::{DEFAULT_SIGMA_MIN, Ndf, SIGMA_MIN_FLOOR, SlopeGaussian};
use glam::{Vec2, Vec3};

/// The slots of one axis of the weight rectangle.
#[derive(Clone, Copy, Debug)]
struct AxisSlots {
    /// First unwrapped lobe index (unused when folded).
    start: i64,
    /// Number of slots.
    len: usize,
    /// Lobes along this axis.
    n: usize,
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
    fn lobe_of_slot(&self, s: usize) -> usize {
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

/// The per-slot buffers of a patch; also part of the mixture's share of [`GlintScratch`].
#[derive(Clone, Debug, Default)]
pub(crate) struct SlotBuffers {
    /// Normalised W per slot, row major (slot_y * len_x + slot_x), summing to 1.
    weights: Vec<f32>,
    /// Cumulative weights (f64), last = Σ of `weights` in f64.
    cdf: Vec<f64>,
    /// The weights again in the lobe blocks' layout: per [`BlockRect`], its blocks row major, 16
    /// lanes each (0 for lanes outside the rectangle or the grid).
    block_weights: Vec<f32>,
}

/// One (x segment × y segment) rectangle of a patch's lobes, with its blocks.
#[derive(Clone, Copy, Debug, Default)]
struct BlockRect {
    /// Lobe ranges [lo, hi) along x and y.
    x: (usize, usize),
    y: (usize, usize),
    /// First block and the block counts along x and y.
    bx0: usize,
    by0: usize,
    bw: usize,
    bh: usize,
    /// Offset of the rectangle's first block in `block_weights`, in lanes.
    offset: usize,
}

impl BlockRect {
    /// The lane weights of block (bx, by) (absolute block coordinates, inside the rectangle).
    /// `#[inline(always)]`: called inside the block passes, whose AVX2 copy inlines only what is
    /// forced (blocks.rs, `dispatch`).
    #[inline(always)]
    fn weights<'w>(&self, bw: &'w [f32], bx: usize, by: usize) -> &'w [f32; LANES] {
        let o = self.offset + ((by - self.by0) * self.bw + (bx - self.bx0)) * LANES;
        bw[o..o + LANES].try_into().expect("16 lanes")
    }
}

/// The mixture's share of [`GlintScratch`]: the buffers a patch borrows.
#[derive(Debug, Default)]
pub(crate) struct MixtureScratch {
    slots: SlotBuffers,
    lobes: Vec<SlopeGaussian>,
}

/// The gathered lobes of a footprint.
#[derive(Clone, Debug)]
struct Gathered<'a> {
    axes: [AxisSlots; 2],
    /// Weights and their cdf, per slot, and the weights per block.
    bufs: Lent<'a, SlotBuffers>,
    /// The lobe rectangles (one per x segment × y segment) and how many there are.
    rects: [BlockRect; 4],
    n_rects: usize,
    /// Σ W_i μ_i: the patch mean slope.
    mean_slope: Vec2,
    /// Σ W_n e_r(n) at the patch's resolution r: the bound of the TV between this level's patch and
    /// the full mixture's, both blurred by N(0, r² I) in slope space (0 at level 0).
    lod_error: f64,
    /// The patch's slope covariance Σ_P = Σ W_i (Σ_i + μ_i μ_iᵀ) − μ_P μ_Pᵀ, [xx, xy, yy] (f64), with
    /// each lobe's covariance as its D uses it (floored, correlation clamped): the second moment that
    /// the approximate masking's Scarf bound needs.
    slope_cov: [f64; 3],
}

/// A lobe's slope mean and covariance as D evaluates it: variances floored at σ², correlation
/// clamped so that the floored matrix stays positive semi-definite (as
/// [`SlopeGaussian::from_moments`]). `None` for non-finite moments (the lobe's fallback applies).
#[inline]
fn lobe_mean_cov(m: &[f32; 5], s2: f64) -> Option<([f64; 2], [f64; 3])> {
    if !m.iter().all(|v| v.is_finite()) {
        return None;
    }
    let [ex, ey, exx, eyy, exy] = m.map(f64::from);
    let vx = (exx - ex * ex).max(s2);
    let vy = (eyy - ey * ey).max(s2);
    Some((
        [ex, ey],
        [vx, clamped_covariance(vx, vy, exy - ex * ey, s2), vy],
    ))
}

/// The covariance c clamped to ±√((σx² − σ²)(σy² − σ²)), so that the floored matrix stays positive
/// semi-definite (as [`SlopeGaussian::from_moments`]).
#[inline]
fn clamped_covariance(vx: f64, vy: f64, c: f64, s2: f64) -> f64 {
    let c_max = ((vx - s2) * (vy - s2)).sqrt();
    c.clamp(-c_max, c_max)
}

/// The P-NDF of one footprint of a [`BeckmannMixture`]: an [`Ndf`] with D_P(h) = Σ W_i D_i(h).
///
/// - `d`: \[Chermain2019\] eq. 9 through the slope-box quadtree down to the lobe blocks (4 × 4
///   lobes), then 16 lanes at a time; lobes whose slope box (1 − `slope_tail` of their mass) does
///   not contain h's slope contribute 0 (a masked lane).
/// - Masking, [`MaskingMode::Exact`]: V_P(w) = Σ W_i V_i(w) (V_i = ∫⟨w,m⟩⁺D_i, always ≥ 0), and the
///   **signed** patch projected area A_P(w) = Σ W_i (cos θ − w_xy·μ_i) = cos θ − w_xy·μ_P (μ_P the
///   patch mean slope), clamped at 0; Λ_P = V_P/A_P − 1, G1 = A_P/V_P (eq. 10-17, see
///   docs/mixture.md for why the per-lobe areas are not clamped as in eq. 17).
///   [`MaskingMode::Approximate`]: the same A_P and Scarf's upper bound of V_P from the patch's slope
///   mean and covariance (O(1) per direction; sound: never creates energy, see docs/mixture.md).
/// - Samplers: `sample_normal` draws a lobe ∝ W_i then its slope Gaussian (exactly D_P cos θ);
///   `sample_visible` draws a lobe ∝ W_i V_i(wo) then that lobe's visible normal, density
///   Σ W_i ⟨wo,m⟩⁺ D_i / V_P(wo) = `pdf_visible` (exact V_P in both masking modes).
/// - Level of detail: the patch is made of the nodes of one level l of merged lobes
///   (src/glint/mixture/levels.rs; l = 0 is the lobes themselves): the coarsest level whose nodes
///   are no wider than half the footprint's smaller standard deviation and whose bound Σ W_n e_r(n) on the
///   TV to the full mixture at slope resolution r = `lod_resolution` (both P-NDFs blurred by
///   N(0, r² I)) is at most `lod_tolerance`, then moved coarser if the footprint still
///   covers more than `lod_lobes` nodes (the filtered lobe alone if no level is coarse enough).
///   D_P, both masking modes, both samplers and their pdfs all use that one level.
///
/// # Reference
/// \[Chermain2019\] eq. 7-17, §4.2.2, §5.
#[derive(Clone, Debug)]
pub struct MixturePatch<'a> {
    mixture: &'a BeckmannMixture,
    /// The level of detail the patch reads (its lobes, blocks, quadtree): see [`MixturePatch::lv`].
    /// (An index, not a [`LevelRef`], to keep the patch small inside `GlintPatch`.)
    level: usize,
    masking: MaskingMode,
    /// The Beckmann lobe of the filtered moments (§4.2.2).
    filtered: SlopeGaussian,
    /// `None` when the level of detail serves the filtered lobe alone.
    gathered: Option<Gathered<'a>>,
    /// The gathered lobes as [`SlopeGaussian`]s (per slot), built on the first call that loops over
    /// all of them (exact masking, visible sampling): 32 bytes per slot.
    lobes: Loan<'a, Vec<SlopeGaussian>>,
    /// The compiled copy of the block loops the patch runs ([`blocks::Simd::detected`] unless a
    /// bench or test forces the baseline).
    simd: blocks::Simd,
}

/// The effective Gaussian k_i ∗ k_P in lobe units: centre and inverse covariance.
struct Effective {
    c: [f64; 2],
    /// Σ_eff = [[a, b], [b, d]].
    cov: [f64; 3],
    /// Σ_eff⁻¹.
    inv: [f64; 3],
}

/// The footprint's Gaussian k_P in level-0 lobe units: centre and covariance [xx, xy, yy].
struct FootprintLobes {
    c: [f64; 2],
    cov: [f64; 3],
}

impl FootprintLobes {
    fn new(mix: &BeckmannMixture, footprint: &Footprint) -> FootprintLobes {
        let (c, s) = footprint.gaussian_texels(mix.width, mix.height);
        let [hx, hy] = mix.spacing;
        FootprintLobes {
            c: [c.x as f64 / hx, c.y as f64 / hy],
            cov: [
                s.x_axis.x as f64 / (hx * hx),
                s.x_axis.y as f64 / (hx * hy),
                s.y_axis.y as f64 / (hy * hy),
            ],
        }
    }

    /// The footprint's area in lobe cells (12 √det Σ_P: a uniform square of side a has σ² = a²/12).
    fn area(&self) -> f64 {
        let [sxx, sxy, syy] = self.cov;
        12.0 * (sxx * syy - sxy * sxy).max(0.0).sqrt()
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
    /// lobes): centre c / 2^l and covariance (Σ_P + (σ_k² + (4^l − 1)/12) I) / 4^l. The added
    /// (4^l − 1)/12 is the variance of the 2^l lobe positions a node spans along each axis, so a
    /// node's weight is the moment-matched Gaussian of the sum of its lobes' weights (exact at
    /// l = 0, where the formula is the level-0 effective Gaussian k_i ∗ k_P).
    fn at_level(fp: &FootprintLobes, l: usize) -> Effective {
        let n2 = (1u64 << (2 * l)) as f64;
        let k2 = kernel_sigma(1.0).powi(2) + (n2 - 1.0) / 12.0;
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

/// Outcome of the leaf test of the D_P walk.
enum Leaf {
    /// s lies outside the lobe's slope box: the lobe is skipped.
    Outside,
    /// s lies in the box; the lobe's P22 at s.
    Inside(f64),
    /// A moment is not finite: use [`SlopeGaussian::from_moments`]'s fallback.
    Degenerate,
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

/// The leaf work of the D_P walk straight from a lobe's five stored moments: the box test and P22
/// without building a [`SlopeGaussian`] (which validates and factors the covariance in `f64`, about
/// ten times the cost). Same covariance as [`SlopeGaussian::from_moments`] (variances floored at σ²,
/// correlation clamped so that the floored matrix stays positive definite) and the same box as
/// [`lobe_box`] (|s − μ| ≤ k √Σ per axis), in `f64` up to the final `exp`.
struct LeafEval {
    /// Floor σ² of the variances (σ as `from_moments` honours it).
    s2: f64,
    /// Squared box half-width k², in standard deviations.
    k2: f64,
}

impl LeafEval {
    fn new(sigma_min: f32, box_k: f32) -> LeafEval {
        LeafEval {
            s2: sigma_floor_squared(sigma_min),
            k2: box_k as f64 * box_k as f64,
        }
    }

    /// P22(s) = exp(−½ dᵀ Σ⁻¹ d) / (2π √det Σ), d = s − μ, if s is in the lobe's box.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 4-6 (the lobe), §5 (the box).
    #[inline]
    fn p22_in_box(&self, m: &[f32; 5], s: Vec2) -> Leaf {
        if !m.iter().all(|v| v.is_finite()) {
            return Leaf::Degenerate;
        }
        let [ex, ey, exx, eyy, exy] = m.map(f64::from);
        let vx = (exx - ex * ex).max(self.s2);
        let vy = (eyy - ey * ey).max(self.s2);
        let (dx, dy) = (s.x as f64 - ex, s.y as f64 - ey);
        // The box test first: most visited leaves end here, before the correlation's square root.
        if dx * dx > self.k2 * vx || dy * dy > self.k2 * vy {
            return Leaf::Outside;
        }
        let c = clamped_covariance(vx, vy, exy - ex * ey, self.s2);
        let det = vx * vy - c * c;
        let q = (vy * dx * dx - 2.0 * c * dx * dy + vx * dy * dy) / det;
        let p = (-0.5 * q as f32).exp() as f64 / (std::f64::consts::TAU * det.sqrt());
        if p.is_finite() && q >= 0.0 {
            Leaf::Inside(p)
        } else {
            Leaf::Degenerate
        }
    }
}

impl<'a> MixturePatch<'a> {
    /// Gathers the footprint's lobes (see the module docs). Total: any footprint works.
    pub fn new(
        mixture: &'a BeckmannMixture,
        footprint: &Footprint,
        options: PatchOptions,
    ) -> MixturePatch<'a> {
        Self::new_in(mixture, footprint, options, None)
    }

    /// [`MixturePatch::new`] with its per-slot buffers lent by `scratch` (given back when the patch
    /// drops): no heap allocation once the scratch has grown to the footprint's size.
    pub fn new_in(
        mixture: &'a BeckmannMixture,
        footprint: &Footprint,
        options: PatchOptions,
        scratch: Option<&'a mut GlintScratch>,
    ) -> MixturePatch<'a> {
        let (slots, lobes) = match scratch {
            Some(s) => {
                let m = s.slot::<MixtureScratch>();
                (Some(&mut m.slots), Some(&mut m.lobes))
            }
            None => (None, None),
        };
        let fp = FootprintLobes::new(mixture, footprint);
        let area = fp.area();
        let lod = 0.5 * area.max(1e-300).log2();
        let filtered_m = mixture.filtered_moments(fp.c, lod);
        let filtered = SlopeGaussian::from_moments(filtered_m, mixture.params.sigma_min);
        let res = resolution_index(options.lod_resolution);
        let (lv, gathered) = match Self::level_range(mixture, &fp, area, &options) {
            None => (mixture.level_ref(0), None),
            Some((finest, coarsest)) => {
                let mut bufs = Lent::new(slots);
                // From the finest allowed level up while the next level's Σ W_n e(n) meets the
                // tolerance (an error-only pass: weights, no moments, no block layout), then one
                // gather at the level chosen. The bound grows with the level (a node's e(n) includes
                // the mean of its children's; up to the per-level weight approximation), so this
                // stops where a coarse-to-fine search would; a footprint that merges nothing pays one
                // error pass at level finest + 1 (a quarter of the nodes) instead of a gather per
                // level.
                let mut l = finest;
                while l < coarsest {
                    let next = mixture.level_ref(l + 1);
                    let eff = Effective::at_level(&fp, l + 1);
                    let e = Self::lod_error_of(mixture, next, &eff, res, &mut bufs);
                    if e > options.lod_tolerance as f64 {
                        break;
                    }
                    l += 1;
                }
                let lv = mixture.level_ref(l);
                (
                    lv,
                    Some(Self::gather(
                        mixture,
                        lv,
                        &Effective::at_level(&fp, l),
                        res,
                        bufs,
                    )),
                )
            }
        };
        MixturePatch {
            mixture,
            level: lv.level,
            masking: options.masking,
            filtered,
            gathered,
            lobes: Loan::new(lobes),
            simd: blocks::Simd::detected(),
        }
    }

    /// The levels a patch may use, (finest, coarsest), searched from the finest up while the next
    /// level's Σ W_n e(n) meets the tolerance (the finest is taken regardless); `None` for the
    /// filtered lobe alone.
    ///
    /// - coarsest: the largest l with 2^l ≤ σ_min(Σ_P)/2 (a node no wider than half the
    ///   footprint's smaller standard deviation, so that its lobes' weights vary little across it:
    ///   with nodes as wide as σ the weight approximation alone cost 0.02 in TV on scratched at 64
    ///   texels, docs/results.md) among the built levels; 0 when the tolerance is 0;
    /// - finest: the smallest l whose node count (area / 4^l) is within the cost cap `lod_lobes`;
    ///   if that exceeds the built levels, the filtered lobe.
    fn level_range(
        mix: &BeckmannMixture,
        fp: &FootprintLobes,
        area: f64,
        options: &PatchOptions,
    ) -> Option<(usize, usize)> {
        let top = mix.level_count() - 1;
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
    fn slot_weights(
        weight_sigmas: f32,
        lv: LevelRef<'_>,
        eff: &Effective,
        w: &mut Vec<f64>,
    ) -> [AxisSlots; 2] {
        let t = weight_sigmas as f64;
        let half = [t * eff.cov[0].sqrt(), t * eff.cov[2].sqrt()];
        let axes = [
            AxisSlots::new(eff.c[0], half[0], lv.grid[0]),
            AxisSlots::new(eff.c[1], half[1], lv.grid[1]),
        ];
        let (lx, ly) = (axes[0].len, axes[1].len);
        w.clear();
        w.resize(lx * ly, 0.0);
        let (i0, i1) = axes[0].unwrapped_range(eff.c[0], half[0]);
        let (j0, j1) = axes[1].unwrapped_range(eff.c[1], half[1]);
        for j in j0..=j1 {
            let sy = axes[1].slot_of_unwrapped(j);
            let row = &mut w[sy * lx..(sy + 1) * lx];
            for (i, wi) in (i0..=i1).zip(eff.row_weights(i0, j)) {
                row[axes[0].slot_of_unwrapped(i)] += wi;
            }
        }
        axes
    }

    /// Σ W_n e_r(n) of the level over the footprint at the resolution of index `res` (what
    /// [`Self::gather`] reports as `lod_error`), from the weights alone: the error-only pass of the
    /// level-of-detail search.
    fn lod_error_of(
        mix: &BeckmannMixture,
        lv: LevelRef<'_>,
        eff: &Effective,
        res: usize,
        bufs: &mut Lent<'_, SlotBuffers>,
    ) -> f64 {
        let w = &mut bufs.cdf;
        let axes = Self::slot_weights(mix.params.weight_sigmas, lv, eff, w);
        let lx = axes[0].len;
        let (mut total, mut err) = (0.0f64, 0.0f64);
        for (s, &wi) in w.iter().enumerate() {
            let k = axes[1].lobe_of_slot(s / lx) * lv.grid[0] + axes[0].lobe_of_slot(s % lx);
            total += wi;
            err += wi * lv.error_at(k, res) as f64;
        }
        if total > 0.0 { err / total } else { 0.0 }
    }

    fn gather<'b>(
        mix: &BeckmannMixture,
        lv: LevelRef<'_>,
        eff: &Effective,
        res: usize,
        mut bufs: Lent<'b, SlotBuffers>,
    ) -> Gathered<'b> {
        // Raw weights are summed into the cdf buffer, then normalised and accumulated in place.
        let SlotBuffers { weights, cdf, .. } = &mut *bufs;
        weights.clear();
        let axes = Self::slot_weights(mix.params.weight_sigmas, lv, eff, cdf);
        let lx = axes[0].len;
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
        let s2 = sigma_floor_squared(mix.params.sigma_min);
        weights.extend(w.iter_mut().enumerate().map(|(s, wi)| {
            let wn = *wi * inv;
            acc += wn;
            *wi = acc;
            let k = axes[1].lobe_of_slot(s / lx) * lv.grid[0] + axes[0].lobe_of_slot(s % lx);
            lod_error += wn * lv.error_at(k, res) as f64;
            // No stored moments (compact storage): the decoded lobe's mean and L Lᵀ.
            let m = lv.moments.get(k);
            let (mu, cov) = m
                .and_then(|m| lobe_mean_cov(m, s2))
                .or_else(|| lv.mean_cov(k))
                .unwrap_or_else(|| {
                    let lobe = lv.lobe_at(k);
                    let (mu, c) = (lobe.mean(), lobe.covariance());
                    let c = [c.x_axis.x, c.x_axis.y, c.y_axis.y].map(f64::from);
                    ([mu.x as f64, mu.y as f64], c)
                });
            m1[0] += wn * mu[0];
            m1[1] += wn * mu[1];
            m2[0] += wn * (cov[0] + mu[0] * mu[0]);
            m2[1] += wn * (cov[1] + mu[0] * mu[1]);
            m2[2] += wn * (cov[2] + mu[1] * mu[1]);
            wn as f32
        }));
        let (rects, n_rects) = Self::block_weights(&axes, &mut bufs);
        // Σ W = 1 up to rounding; the covariance is floored at 0 against cancellation.
        let slope_cov = [
            (m2[0] - m1[0] * m1[0]).max(0.0),
            m2[1] - m1[0] * m1[1],
            (m2[2] - m1[1] * m1[1]).max(0.0),
        ];
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
                let row = r.offset + (y / SIDE - r.by0) * r.bw * LANES + (y % SIDE) * SIDE;
                for x in r.x.0..r.x.1 {
                    let sx = (x as i64 + x_off) as usize;
                    let o = row + (x / SIDE - r.bx0) * LANES + x % SIDE;
                    block_weights[o] = weights[sy * lx + sx];
                }
            }
        }
        (rects, n)
    }

    /// The masking mode.
    pub fn masking(&self) -> MaskingMode {
        self.masking
    }

    /// Whether the level of detail replaced the mixture by the filtered lobe.
    pub fn is_filtered_lobe(&self) -> bool {
        self.gathered.is_none()
    }

    /// The level of detail l the patch reads: its lobes are the merged lobes of 2^l × 2^l blocks of
    /// the mixture's lobes (0: the lobes themselves; also 0 under the filtered lobe).
    pub fn level(&self) -> usize {
        self.level
    }

    /// The level the patch reads.
    #[inline]
    fn lv(&self) -> LevelRef<'a> {
        self.mixture.level_ref(self.level)
    }

    /// The level of detail's error bound Σ W_n e_r(n): an upper bound of the TV between this
    /// patch's slope density and that of the level-0 lobes its nodes replace, each node's weight
    /// W_n spread evenly over its lobes, both blurred by an isotropic Gaussian of std r in slope
    /// space, r the largest of [`super::LOD_RESOLUTIONS`] not above `PatchOptions::lod_resolution`
    /// (0 at level 0; 1 under the filtered lobe, which has no bound). The difference between that
    /// even spread and the full mixture's own weights is not bounded (measured 0.0005-0.013 in TV,
    /// docs/mixture.md). See src/glint/mixture/levels.rs.
    pub fn lod_error(&self) -> f32 {
        self.gathered.as_ref().map_or(1.0, |g| g.lod_error as f32)
    }

    /// The Beckmann lobe of the footprint's filtered moments (\[Chermain2019\] §4.2.2): trilinear lookup
    /// in the moment mip chain at level log₂(√(footprint area in lobes)).
    pub fn filtered_lobe(&self) -> &SlopeGaussian {
        &self.filtered
    }

    /// Number of lobe slots (weights) the patch holds (0 for the filtered lobe).
    pub fn lobe_count(&self) -> usize {
        self.gathered.as_ref().map_or(0, |g| g.bufs.weights.len())
    }

    /// The patch mean slope μ_P = Σ W_i μ_i (the filtered lobe's mean under the level of detail).
    pub fn mean_slope(&self) -> Vec2 {
        self.gathered
            .as_ref()
            .map_or(self.filtered.mean(), |g| g.mean_slope)
    }

    /// The normalised weights W_i and their lobes, for tests and tools: (W, lobe) per slot.
    pub fn weighted_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + '_ {
        let g = self.gathered.as_ref();
        let n = g.map_or(0, |g| g.bufs.weights.len());
        (0..n).filter_map(move |s| g.map(|g| (g.bufs.weights[s], self.slot_lobe(g, s))))
    }

    #[inline]
    fn slot_lobe(&self, g: &Gathered, s: usize) -> SlopeGaussian {
        let lx = g.axes[0].len;
        let lv = self.lv();
        let k = g.axes[1].lobe_of_slot(s / lx) * lv.grid[0] + g.axes[0].lobe_of_slot(s % lx);
        lv.lobe_at(k)
    }

    /// D_P(m) and the number of lobes whose D_i was evaluated: 16 per lobe block whose box (and
    /// whose ancestors' boxes) contain m's slope.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 9, §5.
    pub fn d_with_stats(&self, m: Vec3) -> (f32, usize) {
        self.d_by(m, Self::sum_p22)
    }

    /// Forces the patch's per-query block loops (`d`, exact `lambda` / `visible_area`,
    /// `sample_visible`, `pdf_visible`, `pdf_normal`) onto the baseline copy (`true`) or back to the
    /// copy the CPU supports (`false`: AVX2 where detected; docs/mixture.md "Runtime dispatch").
    /// Results are bit-identical either way: for the benches' and tests' comparisons.
    #[doc(hidden)]
    pub fn force_baseline_simd(&mut self, baseline: bool) {
        self.simd = if baseline {
            blocks::Simd::BASELINE
        } else {
            blocks::Simd::detected()
        };
    }

    /// The copy of the block loops the patch runs: `"avx2"` or `"baseline"`.
    #[doc(hidden)]
    pub fn simd_path(&self) -> &'static str {
        self.simd.name()
    }

    /// D_P(m) by the former scalar path (one lobe at a time, each rebuilt from its moments in `f64`):
    /// kept as the reference of the benches and tests. Equal to [`Ndf::d`] to ~1e-6 relative.
    #[doc(hidden)]
    pub fn d_scalar(&self, m: Vec3) -> f32 {
        self.d_by(m, Self::sum_p22_scalar).0
    }

    #[inline]
    fn d_by(&self, m: Vec3, sum: impl Fn(&Self, &Gathered, Vec2) -> (f64, usize)) -> (f32, usize) {
        let Some(g) = &self.gathered else {
            return (self.filtered.d(m), 0);
        };
        let Some(s) = normal_to_slope(m) else {
            return (0.0, 0);
        };
        if !s.is_finite() {
            return (0.0, 0);
        }
        let (p22, touched) = sum(self, g, s);
        let c = 1.0 + s.length_squared() as f64;
        let d = (p22 * c * c) as f32;
        (if d.is_finite() { d } else { f32::MAX }, touched)
    }

    /// Σ W_i P22_i(s) over the lobes whose slope box contains s: a depth-first walk of the quadtree
    /// down to the lobe blocks (level 2) restricted to each lobe rectangle of the footprint, then
    /// the 16 lanes of each block reached at once ([`blocks::p22_lanes`]).
    fn sum_p22(&self, g: &Gathered, s: Vec2) -> (f64, usize) {
        let (sum, blocks_seen) = blocks::dispatch(self.simd, SumP22 { patch: self, g, s });
        (sum * blocks::p22_scale(), blocks_seen * LANES)
    }

    /// The scalar walk (former path): Σ W_i P22_i(s) over the lobes whose slope box contains s, by
    /// a depth-first walk of the quadtree to its leaves, each lobe rebuilt from its moments.
    fn sum_p22_scalar(&self, g: &Gathered, s: Vec2) -> (f64, usize) {
        let (mix, lv) = (self.mixture, self.lv());
        let [nx, _] = lv.grid;
        let lx = g.axes[0].len;
        let (xs, nxs) = g.axes[0].segments();
        let (ys, nys) = g.axes[1].segments();
        let leaf = LeafEval::new(mix.params.sigma_min, mix.box_k);
        let mut acc = 0.0f64;
        let mut touched = 0usize;
        for &(x_lo, x_hi, x_off) in &xs[..nxs] {
            for &(y_lo, y_hi, y_off) in &ys[..nys] {
                lv.for_each_leaf((x_lo, x_hi), (y_lo, y_hi), s, |x, y| {
                    let k = y * nx + x;
                    let leaf_of = |m| leaf.p22_in_box(m, s);
                    let p22 = match lv.moments.get(k).map_or(Leaf::Degenerate, leaf_of) {
                        Leaf::Outside => return,
                        Leaf::Inside(p) => p,
                        // Non-finite moments: the lobe's documented fallback (and compact
                        // storage, which holds no moments: the decoded lobe).
                        Leaf::Degenerate => {
                            let lobe = lv.lobe_at(k);
                            if !contains(&lobe_box(&lobe, mix.box_k), s) {
                                return;
                            }
                            lobe.p22(s) as f64
                        }
                    };
                    touched += 1;
                    let sx = (x as i64 + x_off) as usize;
                    let sy = (y as i64 + y_off) as usize;
                    acc += g.bufs.weights[sy * lx + sx] as f64 * p22;
                });
            }
        }
        (acc, touched)
    }

    /// The gathered lobes per slot (built once).
    fn slot_lobes(&self, g: &Gathered) -> &[SlopeGaussian] {
        self.lobes.get_or_init(|mut lobes| {
            lobes.clear();
            lobes.extend((0..g.bufs.weights.len()).map(|s| self.slot_lobe(g, s)));
            lobes
        })
    }

    /// Calls `f(block, lane weights, bx, by)` for every lobe block of the patch.
    #[inline(always)]
    fn for_each_patch_block(
        &self,
        g: &Gathered,
        mut f: impl FnMut(&blocks::LobeBlock, &[f32; LANES], usize, usize),
    ) {
        let bw = &g.bufs.block_weights;
        let lv = self.lv();
        let mut buf = blocks::LobeBlock::zeroed();
        for r in &g.rects[..g.n_rects] {
            for by in r.by0..r.by0 + r.bh {
                for bx in r.bx0..r.bx0 + r.bw {
                    f(lv.block(bx, by, &mut buf), r.weights(bw, bx, by), bx, by);
                }
            }
        }
    }

    /// Exact V_P(w) = Σ W_i V_i(w) (0 for invalid w) by the lobe blocks
    /// ([`MixturePatch::visible_area_blocks`]; relative error ≤ 1e-6, docs/mixture.md "Lobe blocks").
    fn exact_visible_area(&self, g: &Gathered, w: Vec3) -> f64 {
        self.exact_visible_area_blocks(g, w)
    }

    /// V_P(w) by the lobe blocks ([`blocks::visible_lanes`]: the ramp term G(−t) in lanes only in
    /// blocks that hold a lobe seen at z = A_s/s_w < 5, the sum in `f64`), the filtered lobe's under
    /// the level of detail: the patch's exact V_P (kept callable for the benches and tests).
    #[doc(hidden)]
    pub fn visible_area_blocks(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => finite_or_zero(self.exact_visible_area_blocks(g, w)),
            None => self.filtered.visible_area(w),
        }
    }

    /// Λ_P(w) with [`MixturePatch::visible_area_blocks`] (the benches' lane-kernel column; equal to
    /// [`Ndf::lambda`] in exact masking).
    #[doc(hidden)]
    pub fn lambda_blocks(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_of(
            w,
            |w| self.projected_area(w),
            |w| self.visible_area_blocks(w),
        )
    }

    fn exact_visible_area_blocks(&self, g: &Gathered, w: Vec3) -> f64 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        blocks::dispatch(self.simd, VisibleSum { patch: self, g, w })
    }

    /// V_P(w) by the former scalar path (one [`SlopeGaussian`] per slot, `f64`): the reference of
    /// the benches and tests.
    #[doc(hidden)]
    pub fn visible_area_scalar(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => finite_or_zero(self.exact_visible_area_scalar(g, w)),
            None => self.filtered.visible_area(w),
        }
    }

    /// Λ_P(w) with the former scalar V_P ([`MixturePatch::visible_area_scalar`]) in exact masking:
    /// the reference of the benches.
    #[doc(hidden)]
    pub fn lambda_scalar(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_of(
            w,
            |w| self.projected_area(w),
            |w| self.visible_area_scalar(w),
        )
    }

    /// Exact V_P(w) = Σ W_i V_i(w) in `f64`, one lobe at a time (0 for invalid w).
    fn exact_visible_area_scalar(&self, g: &Gathered, w: Vec3) -> f64 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        g.bufs
            .weights
            .iter()
            .zip(self.slot_lobes(g))
            .map(|(&wi, lobe)| wi as f64 * lobe.visible_area(w) as f64)
            .sum()
    }

    /// The exact visible area V_P(w) = Σ W_i V_i(w) = ∫ ⟨w, m⟩⁺ D_P(m) dm, whatever the masking mode
    /// (the filtered lobe's under the level of detail).
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 12-13 (with V_i in place of the clamped ⟨ω_n̄i, w⟩/(ω_n̄i·ω_g)(1 + Λ_i)).
    pub fn visible_area_exact(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => finite_or_zero(self.exact_visible_area(g, w)),
            None => self.filtered.visible_area(w),
        }
    }

    /// Scarf's bound V⁺(w) = ½ (ā + √(ā² + w_xyᵀ Σ_P w_xy)) ≥ ∫⟨w,m⟩⁺ D_P dm, with ā the signed
    /// projected area and Σ_P the patch's slope covariance: the largest E[(w_z − w_xy·ñ)⁺] over
    /// every slope distribution of that mean and covariance, so masking built on it can only
    /// over-shadow (never create energy). 0 for invalid w. O(1).
    ///
    /// # Reference
    /// \[Scarf1958\]; the per-lobe form is [`SlopeGaussian::visible_area_bound`].
    fn visible_area_bound(&self, g: &Gathered, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let a = self.signed_projected_area(w) as f64;
        let [sxx, sxy, syy] = g.slope_cov;
        let (x, y) = (w.x as f64, w.y as f64);
        let s2 = (sxx * x * x + 2.0 * sxy * x * y + syy * y * y).max(0.0);
        finite_or_zero(0.5 * (a + (a * a + s2).sqrt()))
    }

    /// The signed patch projected area A_s(w) = cos θ − w_xy·μ_P = Σ W_i ∫ (w·m) D_i dm (may be
    /// negative; 0 for invalid w).
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 without the per-lobe clamp.
    pub fn signed_projected_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let mu = self.mean_slope();
        finite_f32(w.z as f64 - (mu.x as f64 * w.x as f64 + mu.y as f64 * w.y as f64))
    }

    /// The paper's patch projected area with clamped per-lobe areas, Σ W_i max(cos θ − w_xy·μ_i, 0)
    /// (\[Chermain2019\] eq. 17 as printed). Not used by the patch (see docs/mixture.md); exposed for
    /// comparison. The filtered lobe's A under the level of detail.
    pub fn paper_projected_area(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => (0..g.bufs.weights.len())
                .map(|s| g.bufs.weights[s] as f64 * self.slot_lobe(g, s).projected_area(w) as f64)
                .sum::<f64>() as f32,
            None => self.filtered.projected_area(w),
        }
    }
}

impl Ndf for MixturePatch<'_> {
    /// D_P(m) = Σ W_i D_i(m) (\[Chermain2019\] eq. 9); see [`MixturePatch::d_with_stats`].
    fn d(&self, m: Vec3) -> f32 {
        self.d_with_stats(m).0
    }

    /// Λ_P(w) = V_P(w)/A_P(w) − 1 (≥ 0); `f32::MAX` when A_P ≤ 0 < w_z (the patch's mean plane faces
    /// away from w), 0 for invalid w.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 15 (exact), §4.2.2 (approximate).
    fn lambda(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_from_areas(self, w)
    }

    /// A_P(w) = max(signed A_P, 0) from the patch mean slope, in both masking modes (exact and
    /// O(1)); the filtered lobe's A under the level of detail.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 (without the per-lobe clamp, docs/mixture.md).
    fn projected_area(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(_) => self.signed_projected_area(w).max(0.0),
            None => self.filtered.projected_area(w),
        }
    }

    /// V_P(w) = A_P (1 + Λ_P): exact Σ W_i V_i(w) ([`MaskingMode::Exact`]), Scarf's upper bound from
    /// the patch's slope mean and covariance ([`MaskingMode::Approximate`]), or the filtered lobe's
    /// V under the level of detail.
    fn visible_area(&self, w: Vec3) -> f32 {
        match (&self.gathered, self.masking) {
            (Some(g), MaskingMode::Exact) => finite_or_zero(self.exact_visible_area(g, w)),
            (Some(g), MaskingMode::Approximate) => self.visible_area_bound(g, w),
            (None, _) => self.filtered.visible_area(w),
        }
    }

    /// m ~ D_P(m) cos θ_m: lobe ∝ W_i with u.x (rescaled), then the lobe's slope Gaussian.
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let Some(g) = &self.gathered else {
            return self.filtered.sample_normal(u);
        };
        let (s, ux) = invert_cdf(&g.bufs.cdf, u.x);
        self.slot_lobe(g, s).sample_normal(Vec2::new(ux, u.y))
    }

    /// m ~ Σ W_i ⟨wo,m⟩⁺ D_i(m) / V_P(wo): lobe ∝ W_i V_i(wo) with u.x (rescaled), then that lobe's
    /// visible normal: [`MixturePatch::sample_visible_blocks`] (V_i by the lobe blocks, as
    /// [`Ndf::pdf_visible`]'s V_P). Invalid wo: [`Ndf::sample_normal`].
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        self.sample_visible_blocks(wo, u)
    }

    /// Σ W_i D_i(m) cos θ_m over **every** gathered lobe (no slope-box truncation): exactly the
    /// density of [`Ndf::sample_normal`]. Differs from `d(m) cos θ_m` by at most the truncated tail
    /// (`slope_tail` of each lobe's mass). O(lobes).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        let Some(g) = &self.gathered else {
            return self.filtered.pdf_normal(m);
        };
        if !(m.z > 0.0 && m.is_finite()) {
            return 0.0;
        }
        let p = self.untruncated_d(g, m) * m.z as f64;
        let p = p as f32;
        if p.is_finite() { p } else { 0.0 }
    }

    /// Σ W_i ⟨wo, m⟩⁺ D_i(m) / V_P(wo) over every gathered lobe, with the exact V_P in every masking
    /// mode: exactly the density of [`Ndf::sample_visible`]. O(lobes).
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        let Some(g) = &self.gathered else {
            return self.filtered.pdf_visible(wo, m);
        };
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        let v = self.exact_visible_area(g, wo);
        if v.is_nan() || v <= 0.0 {
            return 0.0;
        }
        let p = (c as f64 * self.untruncated_d(g, m) / v) as f32;
        if p.is_finite() { p } else { 0.0 }
    }
}

impl MixturePatch<'_> {
    /// Σ W_i D_i(m) over every gathered lobe (no slope box), lanes in `f32`, the sum in `f64`.
    fn untruncated_d(&self, g: &Gathered, m: Vec3) -> f64 {
        let Some(s) = normal_to_slope(m) else {
            return 0.0;
        };
        if !s.is_finite() {
            return 0.0;
        }
        let sum = blocks::dispatch(self.simd, UntruncatedSum { patch: self, g, s });
        let c = 1.0 + s.length_squared() as f64;
        sum * blocks::p22_scale() * c * c
    }

    /// m ~ Σ W_i ⟨wo,m⟩⁺ D_i(m) / V_P(wo): lobe ∝ W_i V_i(wo) with u.x (rescaled), then that lobe's
    /// visible normal. Two passes over the lobe blocks (the total, then the pick: block by block,
    /// then lane by lane in the block that holds the target), no allocation. Invalid wo:
    /// [`Ndf::sample_normal`]. The patch's `sample_visible`; its density is `pdf_visible` (which
    /// divides by the same block V_P) up to the lanes' 1e-6 relative error on each V_i.
    #[doc(hidden)]
    pub fn sample_visible_blocks(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let Some(g) = &self.gathered else {
            return self.filtered.sample_visible(wo, u);
        };
        let total = self.exact_visible_area_blocks(g, wo);
        if !(total > 0.0 && total.is_finite()) {
            return self.sample_normal(u);
        }
        let ux = if u.x.is_nan() {
            0.5
        } else {
            u.x.clamp(0.0, 1.0)
        } as f64;
        let target = ux * total;
        let (k, r) = blocks::dispatch(
            self.simd,
            VisiblePick {
                patch: self,
                g,
                wo,
                target,
            },
        );
        if k == usize::MAX {
            return self.sample_normal(u);
        }
        let r = r.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        self.lv().lobe_at(k).sample_visible(wo, Vec2::new(r, u.y))
    }

    /// The scalar visible sampler (the patch's `sample_visible` before the lobe blocks; kept for the
    /// benches):
    /// m ~ Σ W_i ⟨wo,m⟩⁺ D_i(m) / V_P(wo): lobe ∝ W_i V_i(wo) with u.x (rescaled), then that lobe's
    /// visible normal. Two passes over the lobes (total, then the pick), no allocation. Invalid wo:
    /// [`Ndf::sample_normal`].
    #[doc(hidden)]
    pub fn sample_visible_scalar(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let Some(g) = &self.gathered else {
            return self.filtered.sample_visible(wo, u);
        };
        let total = self.exact_visible_area_scalar(g, wo);
        if !(total > 0.0 && total.is_finite()) {
            return self.sample_normal(u);
        }
        let lobes = self.slot_lobes(g);
        let (s, r) = pick_streaming(
            u.x,
            total,
            lobes
                .iter()
                .enumerate()
                .map(|(s, lobe)| g.bufs.weights[s] as f64 * lobe.visible_area(wo) as f64),
        );
        lobes[s].sample_visible(wo, Vec2::new(r, u.y))
    }
}

/// The per-query block passes, each compiled once per instruction set ([`blocks::dispatch`]).
///
/// [`MixturePatch::sum_p22`]'s loop: Σ over the blocks reached by the walk of Σ_lanes W P22 (slope
/// box applied), without the 1/(2π) factor, and the number of blocks reached.
struct SumP22<'p, 'a, 'g> {
    patch: &'p MixturePatch<'a>,
    g: &'g Gathered<'g>,
    s: Vec2,
}

impl blocks::BlockPass for SumP22<'_, '_, '_> {
    type Out = (f64, usize);
    #[inline(always)]
    fn run<I: blocks::Isa>(self) -> (f64, usize) {
        let (mix, lv, g, s) = (self.patch.mixture, self.patch.lv(), self.g, self.s);
        let k2 = mix.box_k * mix.box_k;
        let bw = &g.bufs.block_weights;
        let mut acc = [0.0f64; LANES];
        let mut blocks_seen = 0usize;
        let mut buf = blocks::LobeBlock::zeroed();
        for r in &g.rects[..g.n_rects] {
            blocks::for_each_block(
                lv.tree,
                r.x,
                r.y,
                s,
                #[inline(always)]
                |bx, by| {
                    blocks_seen += 1;
                    let w = r.weights(bw, bx, by);
                    blocks::p22_lanes::<true>(lv.block(bx, by, &mut buf), w, s, k2, &mut acc);
                },
            );
        }
        (acc.iter().sum::<f64>(), blocks_seen)
    }
}

/// [`MixturePatch::untruncated_d`]'s loop: Σ W P22 over every lane of every block of the patch (no
/// box), without the 1/(2π) factor.
struct UntruncatedSum<'p, 'a, 'g> {
    patch: &'p MixturePatch<'a>,
    g: &'g Gathered<'g>,
    s: Vec2,
}

impl blocks::BlockPass for UntruncatedSum<'_, '_, '_> {
    type Out = f64;
    #[inline(always)]
    fn run<I: blocks::Isa>(self) -> f64 {
        let mut acc = [0.0f64; LANES];
        self.patch.for_each_patch_block(
            self.g,
            #[inline(always)]
            |b, wts, _, _| {
                blocks::p22_lanes::<false>(b, wts, self.s, 0.0, &mut acc);
            },
        );
        acc.iter().sum()
    }
}

/// [`MixturePatch::exact_visible_area_blocks`]'s loop: Σ W V over every block of the patch, for a
/// valid direction (w_z > 0, finite).
struct VisibleSum<'p, 'a, 'g> {
    patch: &'p MixturePatch<'a>,
    g: &'g Gathered<'g>,
    w: Vec3,
}

impl blocks::BlockPass for VisibleSum<'_, '_, '_> {
    type Out = f64;
    #[inline(always)]
    fn run<I: blocks::Isa>(self) -> f64 {
        let mut acc = [0.0f64; LANES];
        self.patch.for_each_patch_block(
            self.g,
            #[inline(always)]
            |b, wts, _, _| {
                blocks::visible_lanes(b, wts, self.w, &mut acc);
            },
        );
        acc.iter().sum()
    }
}

/// [`MixturePatch::sample_visible_blocks`]'s second pass: the lobe whose cumulative W V (blocks in
/// the patch's order, lanes in block order) first exceeds `target`, and u.x rescaled into it;
/// (`usize::MAX`, ½) if no lobe has V > 0, the last lobe with V > 0 if rounding leaves the target
/// unmet.
struct VisiblePick<'p, 'a, 'g> {
    patch: &'p MixturePatch<'a>,
    g: &'g Gathered<'g>,
    wo: Vec3,
    target: f64,
}

impl blocks::BlockPass for VisiblePick<'_, '_, '_> {
    type Out = (usize, f32);
    #[inline(always)]
    fn run<I: blocks::Isa>(self) -> (usize, f32) {
        let (wo, target) = (self.wo, self.target);
        let nx = self.patch.lv().grid[0];
        let lobe = |bx: usize, by: usize, lane: usize| {
            (by * SIDE + lane / SIDE) * nx + bx * SIDE + lane % SIDE
        };
        let mut acc = 0.0f64;
        // (lobe index, rescaled u.x); the last lobe with V > 0 if rounding leaves the target unmet.
        let mut chosen = (usize::MAX, 0.5f32);
        let mut done = false;
        self.patch.for_each_patch_block(
            self.g,
            #[inline(always)]
            |b, wts, bx, by| {
                if done {
                    return;
                }
                let mut v = [0.0f64; LANES];
                blocks::visible_lanes(b, wts, wo, &mut v);
                let sum: f64 = v.iter().sum();
                if sum.is_nan() || sum <= 0.0 {
                    return;
                }
                if acc + sum <= target {
                    if let Some(last) = (0..LANES).rev().find(|&i| v[i] > 0.0) {
                        chosen = (lobe(bx, by, last), 1.0);
                    }
                    acc += sum;
                    return;
                }
                for (lane, &vi) in v.iter().enumerate() {
                    if vi > 0.0 {
                        chosen = (lobe(bx, by, lane), ((target - acc) / vi) as f32);
                        if acc + vi > target {
                            done = true;
                            return;
                        }
                    }
                    acc += vi;
                }
            },
        );
        chosen
    }
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
