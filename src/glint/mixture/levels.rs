//! Lobe levels of detail: for each level l ≥ 1 of the lobe grid, the merged lobe
//! of every 2^l × 2^l block of lobes, stored exactly as level 0 is (moments, structure-of-arrays
//! blocks, slope-box quadtree), plus a per-node merge error, so that a patch evaluates a level like
//! level 0 (same kernels, same code paths for D_P, the masking sums and the samplers).
//!
//! **Merged lobe.** The node's slope Gaussian G_n is the moment match of its four children as the
//! children are evaluated (floored variances, clamped correlation): mean μ_n = ¼ Σ μ_c and
//! covariance Σ_n = ¼ Σ (Σ_c + (μ_c − μ_n)(μ_c − μ_n)ᵀ), i.e. the average of the children's raw
//! second moments, so it includes the spread of the child means. Merging equal-weight moment
//! matches is associative, so G_n is also the moment match of all 4^l level-0 lobes under n.
//!
//! **Merge error.** e(n) is an upper bound of the total variation distance TV(G_n, M_n) between the
//! merged lobe and the equal-weight mixture M_n of the level-0 lobes under n (TV = ½ ∫|p − q|, in
//! slope space). One merge step: by Pinsker, TV ≤ √(½ KL(M || G)), and by the convexity of KL in its
//! first argument KL(Σ ¼ G_c || G_n) ≤ Σ ¼ KL(G_c || G_n); for the moment-matched G_n the trace and
//! mean terms of the Gaussian KL sum to the dimension, leaving
//!
//! ```text
//! TV(G_n, M) ≤ √(¼ Σ_c ¼ ln(det Σ_n / det Σ_c))                        (Pinsker + convexity)
//! TV(G_n, M) ≤ ½ √χ²(M || G_n),  χ² = Σ_ij ¹⁄₁₆ ∫ G_i G_j / G_n − 1      (Cauchy-Schwarz)
//! e(n) = min(1, min(both) + ¼ Σ_c e(c)),  e = 0 at level 0     (triangle inequality, convexity)
//! ```
//!
//! with M = Σ ¼ G_c the children's mixture. ∫ G_i G_j / G_n is a Gaussian integral in closed form
//! (finite when P_i + P_j − P_n is positive definite, P = Σ⁻¹; otherwise only Pinsker's bound is
//! used). The χ² bound is the tight one for overlapping children (moment matching cancels the first
//! and second order, so it vanishes like the third or fourth power of the means' offset over the
//! child width: measured against quadrature in `tests::merge_bound_holds_against_quadrature`); Pinsker's
//! caps it for well-separated children. Both are upper bounds; docs/mixture.md ("Levels of detail
//! chosen by error") compares the patch-level bound with the measured TV. A patch made of level-l nodes with weights W_n has
//! TV(Σ W_n G_n, Σ W_n M_n) ≤ Σ W_n e(n) (convexity), which is what the patch compares with its
//! tolerance (src/glint/mixture/choice.rs).
//!
//! **At a slope resolution r.** The same bound holds for the lobes convolved with an isotropic
//! Gaussian N(0, r² I) in slope space: convolution adds r² I to every covariance, the convolved
//! merged lobe is still the moment match of the convolved children (the spread term is unchanged),
//! and both the χ² and Pinsker forms above are computed in closed form from those covariances. So
//! e_r(n) (the recursion above with r² I added to every covariance) bounds
//! TV(G_n ∗ N_r, M_n ∗ N_r): the error a viewer sees who blurs the P-NDF by N_r (a light or a
//! histogram bin of about that angular size). The true TV is non-increasing in r (convolution is
//! a Markov kernel: data processing inequality), so a bound stored at r_k ≤ r also bounds the TV
//! at r, and so are both closed forms (χ² and KL obey the same inequality). The levels store e_r
//! for each r of [`LOD_RESOLUTIONS`]; r = 0 is the continuous bound.
//!
//! Levels exist only while the grid divides evenly (nx and ny multiples of 2^l), so every node has
//! exactly four children and a level tiles the map as level 0 does.

use super::blocks::LobeBlocks;
use super::hierarchy::lobe_box;
use super::params::LOD_RESOLUTIONS;
use crate::glint::kernels::slope_tree::SlopeTree;
use crate::ndf::SlopeGaussian;

/// Number of tabulated resolutions.
pub(super) const N_RES: usize = LOD_RESOLUTIONS.len();

/// The index of the largest tabulated resolution ≤ r (0 for r below the second one, NaN or
/// negative): the stored bound that is valid at r (module docs).
pub(super) fn resolution_index(r: f32) -> usize {
    LOD_RESOLUTIONS.iter().rposition(|&t| t <= r).unwrap_or(0)
}

/// One level of the lobe grid in full storage: level 0 (the lobes themselves, no merge error) or a
/// level l ≥ 1 of merged lobes (see the module docs).
#[derive(Clone, Debug)]
pub(super) struct LobeLevel {
    /// Nodes along x and y: (nx / 2^l, ny / 2^l).
    pub grid: [usize; 2],
    /// The merged lobes' raw moments `[E[x̃], E[ỹ], E[x̃²], E[ỹ²], E[x̃ỹ]]` (as level 0 stores them).
    pub moments: Vec<[f32; 5]>,
    /// The merged lobes as 4 × 4 structure-of-arrays blocks (blocks.rs).
    pub blocks: LobeBlocks,
    /// The slope-box quadtree over the merged lobes.
    pub tree: SlopeTree,
    /// The merge errors e_r(n) ∈ [0, 1] per node, one vector per resolution r of
    /// [`LOD_RESOLUTIONS`] (see the module docs); empty vectors at level 0 (exact).
    pub error: [Vec<f32>; N_RES],
    /// Whether every raw moment is finite ([`all_finite`], when the level is made): a node's
    /// mean is then its raw moments' own, with no test per node.
    pub finite: bool,
}

/// Whether every value of every moment vector is finite.
pub(super) fn all_finite(moments: &[[f32; 5]]) -> bool {
    moments.iter().flatten().all(|v| v.is_finite())
}

impl LobeLevel {
    /// Bytes held by the level.
    pub fn bytes(&self) -> usize {
        self.moments.len() * 20
            + self.blocks.bytes()
            + self.tree.bytes()
            + self.error.iter().map(|e| e.len() * 4).sum::<usize>()
    }
}

/// The mean and covariance [xx, xy, yy] of a lobe as D evaluates it, in `f64`.
fn mean_cov(g: &SlopeGaussian) -> ([f64; 2], [f64; 3]) {
    let (m, c) = (g.mean(), g.covariance());
    (
        [m.x as f64, m.y as f64],
        [c.x_axis.x as f64, c.x_axis.y as f64, c.y_axis.y as f64],
    )
}

#[inline]
fn det(c: &[f64; 3]) -> f64 {
    c[0] * c[2] - c[1] * c[1]
}

/// ∫ N(x; μ_i, Σ_i) N(x; μ_j, Σ_j) / N(x; μ, Σ) dx in closed form (a Gaussian integral of the
/// precision A = P_i + P_j − P, P = Σ⁻¹), or `None` when A is not positive definite (the integral
/// diverges).
fn chi2_term(
    i: &([f64; 2], [f64; 3]),
    j: &([f64; 2], [f64; 3]),
    g: &([f64; 2], [f64; 3]),
) -> Option<f64> {
    let inv = |c: &[f64; 3]| {
        let d = det(c);
        [c[2] / d, -c[1] / d, c[0] / d]
    };
    let (pi, pj, p) = (inv(&i.1), inv(&j.1), inv(&g.1));
    let a = [
        pi[0] + pj[0] - p[0],
        pi[1] + pj[1] - p[1],
        pi[2] + pj[2] - p[2],
    ];
    let det_a = det(&a);
    if !(a[0] > 0.0 && det_a > 0.0) {
        return None;
    }
    let mul = |m: &[f64; 3], v: &[f64; 2]| [m[0] * v[0] + m[1] * v[1], m[1] * v[0] + m[2] * v[1]];
    let dot = |u: &[f64; 2], v: &[f64; 2]| u[0] * v[0] + u[1] * v[1];
    let (bi, bj, bg) = (mul(&pi, &i.0), mul(&pj, &j.0), mul(&p, &g.0));
    let b = [bi[0] + bj[0] - bg[0], bi[1] + bj[1] - bg[1]];
    let c = dot(&i.0, &bi) + dot(&j.0, &bj) - dot(&g.0, &bg);
    let a_inv_b = mul(&inv(&a), &b);
    let e = 0.5 * (dot(&b, &a_inv_b) - c);
    let v = (det(&g.1) / (det(&i.1) * det(&j.1) * det_a)).sqrt() * e.exp();
    v.is_finite().then_some(v)
}

/// The one-step bound of TV(G_n ∗ N_r, Σ ¼ G_c ∗ N_r) for children and merged lobe as (mean,
/// covariance), r² = `r2`: the smaller of Pinsker's √(¼ Σ ¼ ln(det Σ_n / det Σ_c)) and
/// ½ √χ²(Σ ¼ G_c || G_n), every covariance plus r² I (module docs).
fn one_step_bound(mc: &[([f64; 2], [f64; 3]); 4], g: &([f64; 2], [f64; 3]), r2: f64) -> f64 {
    let widen = |(m, c): &([f64; 2], [f64; 3])| (*m, [c[0] + r2, c[1], c[2] + r2]);
    let mc = mc.each_ref().map(widen);
    let g = widen(g);
    let ln_det_n = det(&g.1).ln();
    let kl: f64 = mc
        .iter()
        .map(|(_, c)| 0.25 * 0.5 * (ln_det_n - det(c).ln()))
        .sum();
    // KL ≥ 0 in exact arithmetic; rounding (identical children) may leave −1e-16. A non-finite KL
    // (degenerate child) counts as the largest TV, 1.
    let pinsker = if kl.is_finite() {
        (0.5 * kl.max(0.0)).sqrt()
    } else {
        1.0
    };
    let mut chi2 = -1.0;
    for i in &mc {
        for j in &mc {
            match chi2_term(i, j, &g) {
                Some(v) => chi2 += v / 16.0,
                None => chi2 = f64::INFINITY,
            }
        }
    }
    let by_chi2 = if chi2.is_finite() {
        0.5 * chi2.max(0.0).sqrt()
    } else {
        1.0
    };
    pinsker.min(by_chi2).min(1.0)
}

/// Merges four child lobes: the moment-matched moments and, per resolution r of
/// [`LOD_RESOLUTIONS`], the one-step bound of TV(G_n ∗ N_r, Σ ¼ G_c ∗ N_r) ([`one_step_bound`]).
fn merge(children: [&SlopeGaussian; 4]) -> ([f32; 5], [f64; N_RES]) {
    let mc = children.map(mean_cov);
    let (raw, g) = merged_moments(&mc);
    let bounds = LOD_RESOLUTIONS.map(|r| one_step_bound(&mc, &g, r as f64 * r as f64));
    (raw, bounds)
}

/// The moment-matched merge of four children given as (mean, covariance): the raw moments (as
/// stored, f32) and the merged (mean, covariance) in f64.
#[allow(clippy::type_complexity)]
fn merged_moments(mc: &[([f64; 2], [f64; 3]); 4]) -> ([f32; 5], ([f64; 2], [f64; 3])) {
    let mut raw = [0.0f64; 5];
    for (mu, c) in mc {
        raw[0] += 0.25 * mu[0];
        raw[1] += 0.25 * mu[1];
        raw[2] += 0.25 * (c[0] + mu[0] * mu[0]);
        raw[3] += 0.25 * (c[2] + mu[1] * mu[1]);
        raw[4] += 0.25 * (c[1] + mu[0] * mu[1]);
    }
    let mean = [raw[0], raw[1]];
    // The covariance from central sums (not raw[2] − raw[0]², which cancels for large means).
    let mut cov = [0.0f64; 3];
    for (mu, c) in mc {
        let (dx, dy) = (mu[0] - mean[0], mu[1] - mean[1]);
        cov[0] += 0.25 * (c[0] + dx * dx);
        cov[1] += 0.25 * (c[1] + dx * dy);
        cov[2] += 0.25 * (c[2] + dy * dy);
    }
    (raw.map(|v| v as f32), (mean, cov))
}

/// The node grids of the levels l ≥ 1 of an `nx × ny` lobe grid: halved while both sides are even
/// (and the grid holds at least 4 lobes), as [`build_levels`] makes them.
pub(super) fn level_grids(nx: usize, ny: usize) -> Vec<[usize; 2]> {
    let mut out = Vec::new();
    let (mut pw, mut ph) = (nx, ny);
    while pw % 2 == 0 && ph % 2 == 0 && pw * ph >= 4 {
        (pw, ph) = (pw / 2, ph / 2);
        out.push([pw, ph]);
    }
    out
}

/// The levels l ≥ 1 of a lobe grid of `nx × ny` lobes (`lobes` row major, as D evaluates them),
/// while both sides divide by 2^l; each level's nodes merged from the previous level's lobes, in
/// parallel over node rows. `box_k` is the slope-box half-width in standard deviations and `pad`
/// the padding lobe of the blocks (as for level 0).
///
/// # Reference
/// Moment matching of \[Chermain2019\] §4.2.2 (there for a single filtered lobe); the error bound is
/// Pinsker's inequality with the convexity of KL (module docs).
///
/// `stored` holds the merge errors of every level (as [`LobeLevel::error`], one entry per level of
/// [`level_grids`]) when they come from a file: the merged moments are then recomputed (cheap, and
/// exactly as the build merges them) but the error bounds, most of the cost of a build's levels,
/// are taken as stored.
pub(super) fn build_levels(
    nx: usize,
    ny: usize,
    lobes: &[[f32; 5]],
    sigma_min: f32,
    box_k: f32,
    pad: &SlopeGaussian,
    stored: Option<Vec<[Vec<f32>; N_RES]>>,
) -> Vec<LobeLevel> {
    use rayon::prelude::*;
    let mut out: Vec<LobeLevel> = Vec::new();
    let mut prev_lobes: Vec<SlopeGaussian> = Vec::new();
    let mut stored = stored.map(|v| v.into_iter());
    let (mut pw, mut ph) = (nx, ny);
    while pw % 2 == 0 && ph % 2 == 0 && pw * ph >= 4 {
        let (w, h) = (pw / 2, ph / 2);
        let given: Option<[Vec<f32>; N_RES]> = stored.as_mut().and_then(|it| it.next());
        // Level 0's lobes are made from their moments where needed (as the blocks are), so that
        // no whole-grid array of Gaussians is held; coarser levels keep the previous level's.
        let first = out.is_empty();
        let child = |i: usize| {
            if first {
                SlopeGaussian::from_moments(lobes[i], sigma_min)
            } else {
                prev_lobes[i]
            }
        };
        let prev_err: Option<&[Vec<f32>; N_RES]> = out.last().map(|l| &l.error);
        let children = |k: usize| {
            let (x, y) = (k % w, k / w);
            let idx = [
                2 * y * pw + 2 * x,
                2 * y * pw + 2 * x + 1,
                (2 * y + 1) * pw + 2 * x,
                (2 * y + 1) * pw + 2 * x + 1,
            ];
            (idx, idx.map(child))
        };
        let (moments, error): (Vec<[f32; 5]>, [Vec<f32>; N_RES]) = match given {
            Some(error) => {
                let moments = (0..w * h)
                    .into_par_iter()
                    .map(|k| merged_moments(&children(k).1.map(|c| mean_cov(&c))).0)
                    .collect();
                (moments, error)
            }
            None => {
                let merged: Vec<([f32; 5], [f32; N_RES])> = (0..w * h)
                    .into_par_iter()
                    .map(|k| {
                        let (idx, c) = children(k);
                        let (m, tv) = merge([&c[0], &c[1], &c[2], &c[3]]);
                        let e = std::array::from_fn(|r| {
                            let below: f64 = prev_err.map_or(0.0, |pe| {
                                idx.iter().map(|&i| 0.25 * pe[r][i] as f64).sum()
                            });
                            (tv[r] + below).min(1.0) as f32
                        });
                        (m, e)
                    })
                    .collect();
                let moments = merged.iter().map(|p| p.0).collect();
                let error = std::array::from_fn(|r| merged.iter().map(|p| p.1[r]).collect());
                (moments, error)
            }
        };
        let gaussians: Vec<SlopeGaussian> = moments
            .par_iter()
            .map(|m| SlopeGaussian::from_moments(*m, sigma_min))
            .collect();
        let leaf: Vec<[f32; 4]> = gaussians.par_iter().map(|g| lobe_box(g, box_k)).collect();
        let tree = SlopeTree::build(w, h, &leaf);
        let blocks = LobeBlocks::build(w, h, &gaussians, pad);
        out.push(LobeLevel {
            grid: [w, h],
            finite: all_finite(&moments),
            moments,
            blocks,
            tree,
            error,
        });
        prev_lobes = gaussians;
        (pw, ph) = (w, h);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lobe(mx: f32, my: f32, s: f32) -> SlopeGaussian {
        SlopeGaussian::from_moments([mx, my, mx * mx + s * s, my * my + s * s, mx * my], 0.01)
    }

    /// Identical children merge into themselves with error 0.
    #[test]
    fn identical_children_merge_exactly() {
        let g = lobe(0.3, -0.2, 0.05);
        let (m, tv) = merge([&g, &g, &g, &g]);
        let back = SlopeGaussian::from_moments(m, 0.01);
        assert!((back.mean() - g.mean()).length() < 1e-6);
        assert!((back.covariance().x_axis.x - 0.0025).abs() < 1e-7);
        assert!(tv.iter().all(|&t| t < 1e-6), "{tv:?}");
    }

    /// TV between the equal-weight mixture of `children` and `g` by the midpoint rule on
    /// [−h, h]², n² cells.
    fn tv_midpoint(children: &[SlopeGaussian; 4], g: &SlopeGaussian, h: f64, n: usize) -> f64 {
        let dx = 2.0 * h / n as f64;
        let mut tv = 0.0;
        for i in 0..n {
            for j in 0..n {
                let p = glam::Vec2::new(
                    (-h + (i as f64 + 0.5) * dx) as f32,
                    (-h + (j as f64 + 0.5) * dx) as f32,
                );
                let mix: f64 = children.iter().map(|l| 0.25 * l.p22(p) as f64).sum();
                tv += 0.5 * (mix - g.p22(p) as f64).abs() * dx * dx;
            }
        }
        tv
    }

    /// The one-step bound against a numerical TV (midpoint rule) of children at offsets ±d of
    /// width s, equal or unequal widths: the bound must hold (it is a theorem; this checks the
    /// algebra) and be within 2× of the TV for overlapping children (d ≤ 2 s; the χ² form; measured
    /// 1.1-1.7×, printed), so that it is not vacuous; the
    /// merged mean and covariance must be the moment match written out by hand.
    #[test]
    fn merge_bound_holds_against_quadrature() {
        for &(d, s, mixed) in &[
            (0.01f32, 0.05f32, false),
            (0.05, 0.05, false),
            (0.1, 0.05, false),
            (0.3, 0.05, false),
            (0.05, 0.05, true),
            (0.1, 0.05, true),
        ] {
            let c = if mixed {
                [
                    lobe(-d, 0.0, s),
                    lobe(d, 0.0, 1.5 * s),
                    lobe(0.0, d, s),
                    lobe(0.0, -d, 0.7 * s),
                ]
            } else {
                [
                    lobe(-d, 0.0, s),
                    lobe(d, 0.0, s),
                    lobe(-d, 0.0, s),
                    lobe(d, 0.0, s),
                ]
            };
            let (m, bounds) = merge([&c[0], &c[1], &c[2], &c[3]]);
            let bound = bounds[0];
            let g = SlopeGaussian::from_moments(m, 0.01);
            if !mixed {
                let var_x = (s * s + d * d) as f64;
                assert!((g.covariance().x_axis.x as f64 - var_x).abs() < 1e-6 * var_x.max(1e-3));
                assert!(g.mean().length() < 1e-7);
            }
            // TV by the midpoint rule on ±(d + 12 s)², 1000² cells.
            let tv = tv_midpoint(&c, &g, (d + 12.0 * s) as f64, 1000);
            println!("d/s {} mixed {mixed}: TV {tv:.5}, bound {bound:.5}", d / s);
            assert!(tv <= bound + 1e-4, "d {d} s {s}: TV {tv} > bound {bound}");
            if d <= 2.0 * s && tv > 1e-3 {
                assert!(bound <= 2.0 * tv, "d {d} s {s}: bound {bound} ≫ TV {tv}");
            }
            // At each resolution r > 0: the children and the merged lobe convolved with N(0, r² I)
            // (r² added to the variances), TV by the midpoint rule (400² cells on ±(d + 10 σ_max)²,
            // σ_max = 1.5 s + r), against the stored bound (+1e-4 as above); and the bounds are
            // non-increasing in r (module docs).
            for k in 1..N_RES {
                let r = LOD_RESOLUTIONS[k];
                assert!(bounds[k] <= bounds[k - 1], "{bounds:?}");
                let widen = |g: &SlopeGaussian| {
                    let (m, c) = (g.mean(), g.covariance());
                    SlopeGaussian::new(m, c + glam::Mat2::from_diagonal(glam::Vec2::splat(r * r)))
                        .unwrap()
                };
                let (cw, gw) = (c.each_ref().map(widen), widen(&g));
                let tv_r = tv_midpoint(&cw, &gw, (d + 10.0 * (1.5 * s + r)) as f64, 400);
                println!("  r {r}: TV {tv_r:.5}, bound {:.5}", bounds[k]);
                assert!(
                    tv_r <= bounds[k] + 1e-4,
                    "d {d} s {s} r {r}: TV {tv_r} > bound {}",
                    bounds[k]
                );
            }
        }
    }
}
