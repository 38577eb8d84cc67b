//! A cut of the filtered-mixture hierarchy (gmm.rs) for one footprint: the nodes whose few lobes
//! stand for their subtrees, weighted by the footprint's kernel, chosen by their stored residuals
//! (gmm_residual.rs) and bounded in number, in the manner of \[Wu2025\] (start at the level where the
//! footprint covers a few nodes; keep a node's simplified form where its residual, weighted by the
//! footprint's share of it, is within a threshold) and \[Yan2016\] (prune the hierarchy by the
//! footprint).
//!
//! **Kernel.** The footprint's position weights are the Gaussian k_P ∗ k_i of the lobes (centre `c`,
//! covariance `s`, level-0 lobe units, lobe i centred at i + ½). A node of level l spans 2^l × 2^l
//! lobes; its share of the kernel is the moment-matched Gaussian of the sum of its lobes' weights,
//! 4^l N(x_n; c, S + (4^l − 1)/12 I) (exact at level 0), and a split rescales its children's shares
//! to sum to their parent's, so the shares of every cut sum to the same total.
//!
//! **Choice.** Starting from the nodes of the coarsest level on which the kernel's ±`weight_sigmas`
//! box spans at most two nodes per axis (never coarser than needed), a node n of share a_n has the
//! error estimate e_n = a_n (ρ_n + η_n Σ_c |b_c − 1/k|): its residual against its subtree, plus the
//! error of weighting its k children uniformly when the kernel gives them shares b_c (both relative L2,
//! gmm_residual.rs). The node of largest e_n is split into its children while that largest e_n exceeds
//! `tolerance` and the cut has room for the children within `max_nodes` (the cost bound: at most
//! `max_nodes` nodes, each ≤ [`GMM_LOBES`](super::gmm::GMM_LOBES) lobes). A cut that stops at the
//! cap reports its largest e_n, which then exceeds the tolerance.
//!
//! **Periodic maps.** Node positions are unwrapped; a node reads the data of its index wrapped onto
//! its level's grid (exact for power-of-two grids; elsewhere a node at the wrap reads the grid's
//! last, partial node). An axis whose kernel box spans a period or more is folded: one period of
//! nodes, each with the sum of its periodic images' shares (their weights are uniform along an axis
//! spanning three periods or more).
//!
//! Work: O(max_nodes²) to choose (a scan for the largest error per split, `max_nodes` ≤
//! [`MAX_CUT_NODES`]), O(max_nodes) kernel evaluations, no allocation besides `set`'s.

use super::gmm::GmmPyramid;
use super::lobe_set::LobeSet;
use crate::ndf::SlopeGaussian;

/// Largest cut, in nodes.
pub const MAX_CUT_NODES: usize = 64;

/// Default largest cut of the filtered-mixture hierarchy, in nodes, for the mixture and
/// position-normal (module docs): the cost bound of a footprint the cut serves (at least
/// [`PatchOptions::cut_area`](crate::glint::mixture::PatchOptions::cut_area), where the filtered
/// mixture does not serve), at most this many nodes of [`GMM_LOBES`](super::gmm::GMM_LOBES) lobes
/// whatever its size. 0 turns the cut off (the gathered levels or the element sum then serve).
///
/// Measured (docs/results.md, "The cut against the full mixture", 256² maps): at 64 nodes the
/// cut's TV to the full mixture is 0.02-0.11 on the bumpy, brushed and scratched maps and 0.12-0.26
/// on flakes from 1,024 texels up; at 16 nodes up to 3× that.
pub const DEFAULT_CUT_NODES: u32 = 64;

/// Default footprint area, in lobe cells (texels at the default spacing), from which a footprint
/// that the filtered mixture does not serve is served by a cut of the hierarchy instead of the
/// gathered lobes (mixture) or the element sum (position-normal): 4096, the filtered mixture's own
/// threshold, so that the cut bounds the cost exactly where the filtered mixture is refused (flakes,
/// or any map whose measured error refuses it), and leaves the gather below.
///
/// Why not lower: from 1,024 texels the cut makes a path tracer's frame 10× faster at ~30,000
/// texels per pixel, but it moves the orb's image error against the exact P-BRDF at 2,186 texels per
/// pixel (one sample per pixel) by +0.03 to +0.12 over the full mixture (docs/results.md, "The cut
/// against the full mixture"): more than the +0.02 a default may cost. A renderer that prefers the
/// speed sets `cut_area` to 1024.
pub const DEFAULT_CUT_AREA: f32 = 4096.0;

/// Default error budget of a node of the cut: a node stays in the cut when its share of the
/// footprint's kernel times its relative L2 residual (plus the error of weighting its children
/// uniformly) is at most this (src/glint/kernels/cut.rs, gmm_residual.rs); the node of largest such
/// error is split first, until every node meets it or the cut reaches
/// [`PatchOptions::cut_nodes`](crate::glint::mixture::PatchOptions::cut_nodes).
pub const DEFAULT_CUT_TOLERANCE: f32 = 0.05;

/// The footprint's kernel in level-0 lobe units (module docs).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CutKernel {
    /// Centre (lobe i centred at i + ½).
    pub c: [f64; 2],
    /// Covariance [xx, xy, yy] of k_P ∗ k_i.
    pub s: [f64; 3],
    /// Truncation of the weights, in standard deviations per axis.
    pub weight_sigmas: f64,
}

/// What a cut did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CutStats {
    /// Nodes in the cut.
    pub nodes: usize,
    /// Lobes served (the nodes' components and leaf lobes).
    pub lobes: usize,
    /// The largest error estimate e_n of a node left in the cut.
    pub max_error: f32,
    /// Σ e_n over the cut.
    pub total_error: f32,
    /// The level the cut started from.
    pub start_level: usize,
    /// Nodes split.
    pub splits: usize,
}

/// One node of a cut: level, unwrapped position, share of the kernel and its children's, error.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    l: u8,
    i: i64,
    j: i64,
    mass: f64,
    /// Children's shares (of this node's mass) for (2i, 2j), (2i + 1, 2j), (2i, 2j + 1),
    /// (2i + 1, 2j + 1); 0 for children that do not exist.
    child: [f64; 4],
    err: f64,
}

/// The offsets (a, b) of a node's children (2i + a, 2j + b), in the order of [`Entry::child`].
const CHILDREN: [(i64, i64); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// Children whose share of the whole kernel is below this are left out of a split (their weight is
/// then missing from the cut's total, which `set` renormalises: at most `MIN_SHARE` per child left
/// out).
const MIN_SHARE: f64 = 1e-6;

/// How the weights treat one axis.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Axis {
    /// Unwrapped positions, one image.
    Open,
    /// One period of nodes, summing the images within the box.
    Folded,
    /// One period of nodes, uniform weights.
    Uniform,
}

struct Geometry<'p> {
    pyr: &'p GmmPyramid,
    k: CutKernel,
    /// Box half-widths per axis (lobes).
    half: [f64; 2],
    /// Period per axis (lobes).
    period: [f64; 2],
    axes: [Axis; 2],
}

impl Geometry<'_> {
    /// The wrapped node index of unwrapped (i, j) at level l.
    fn index(&self, l: usize, i: i64, j: i64) -> usize {
        let [w, h] = self.pyr.sizes()[l];
        let x = i.rem_euclid(w as i64) as usize;
        let y = j.rem_euclid(h as i64) as usize;
        y * w + x
    }

    /// Whether child (a, b) of node (i, j) at level l ≥ 1 exists (partial grids halve upward).
    fn child_exists(&self, l: usize, i: i64, j: i64, a: i64, b: i64) -> bool {
        let [w, h] = self.pyr.sizes()[l];
        let [cw, ch] = self.pyr.sizes()[l - 1];
        let x = i.rem_euclid(w as i64) * 2 + a;
        let y = j.rem_euclid(h as i64) * 2 + b;
        (x as usize) < cw && (y as usize) < ch
    }

    /// The kernel's raw share of node (i, j) of level l (module docs), up to a common factor.
    fn raw(&self, l: usize, i: i64, j: i64) -> f64 {
        let side = (1u64 << l) as f64;
        let n2 = side * side;
        let add = (n2 - 1.0) / 12.0;
        let [a, b, d] = [self.k.s[0] + add, self.k.s[1], self.k.s[2] + add];
        let x = [(i as f64 + 0.5) * side, (j as f64 + 0.5) * side];
        let images = |ax: usize| -> (i64, i64) {
            match self.axes[ax] {
                Axis::Folded => {
                    let p = self.period[ax];
                    let lo = ((self.k.c[ax] - self.half[ax] - x[ax]) / p).floor() as i64;
                    let hi = ((self.k.c[ax] + self.half[ax] - x[ax]) / p).ceil() as i64;
                    (lo, hi)
                }
                _ => (0, 0),
            }
        };
        let (ix, iy) = (images(0), images(1));
        match self.axes {
            [Axis::Uniform, Axis::Uniform] => n2,
            [Axis::Uniform, _] => {
                let mut sum = 0.0;
                for ky in iy.0..=iy.1 {
                    let dy = x[1] + ky as f64 * self.period[1] - self.k.c[1];
                    sum += (-0.5 * dy * dy / d).exp();
                }
                n2 * sum / d.sqrt()
            }
            [_, Axis::Uniform] => {
                let mut sum = 0.0;
                for kx in ix.0..=ix.1 {
                    let dx = x[0] + kx as f64 * self.period[0] - self.k.c[0];
                    sum += (-0.5 * dx * dx / a).exp();
                }
                n2 * sum / a.sqrt()
            }
            _ => {
                let det = (a * d - b * b).max(1e-300);
                let mut sum = 0.0;
                for ky in iy.0..=iy.1 {
                    for kx in ix.0..=ix.1 {
                        let dx = x[0] + kx as f64 * self.period[0] - self.k.c[0];
                        let dy = x[1] + ky as f64 * self.period[1] - self.k.c[1];
                        let q = (d * dx * dx - 2.0 * b * dx * dy + a * dy * dy) / det;
                        sum += (-0.5 * q).exp();
                    }
                }
                n2 * sum / det.sqrt()
            }
        }
    }

    /// A node of the cut with share `mass`: its children's shares and its error estimate.
    fn entry(&self, l: usize, i: i64, j: i64, mass: f64) -> Entry {
        let mut e = Entry {
            l: l as u8,
            i,
            j,
            mass,
            ..Entry::default()
        };
        if l == 0 {
            return e;
        }
        let exists = CHILDREN.map(|(a, b)| self.child_exists(l, i, j, a, b));
        let mut total = 0.0;
        let mut count = 0.0;
        for (c, (a, b)) in CHILDREN.into_iter().enumerate() {
            if exists[c] {
                let r = self.raw(l - 1, 2 * i + a, 2 * j + b);
                e.child[c] = r;
                total += r;
                count += 1.0;
            }
        }
        if total > 0.0 && total.is_finite() {
            for c in &mut e.child {
                *c /= total;
            }
        } else {
            // Shares underflowed: uniform over the existing children.
            for (share, &ex) in e.child.iter_mut().zip(&exists) {
                *share = if ex { 1.0 / count } else { 0.0 };
            }
        }
        let spread: f64 = (0..4)
            .filter(|&c| exists[c])
            .map(|c| (e.child[c] - 1.0 / count).abs())
            .sum();
        let r = self.pyr.residual(l, self.index(l, i, j));
        e.err = mass * (r.rho as f64 + r.eta as f64 * spread);
        e
    }
}

/// The cut of `pyr` (module docs) for the footprint `kernel`, into `set` (normalised): leaves are
/// `lobe0(k)`, nodes their [`GmmPyramid::push_node`] components. A non-finite or degenerate kernel
/// gives the coarsest node alone.
pub(crate) fn cut(
    pyr: &GmmPyramid,
    lobe0: impl Fn(usize) -> SlopeGaussian,
    kernel: CutKernel,
    tolerance: f32,
    max_nodes: usize,
    set: &mut LobeSet,
) -> CutStats {
    set.clear();
    let sizes = pyr.sizes();
    let top = sizes.len() - 1;
    let max_nodes = max_nodes.clamp(1, MAX_CUT_NODES);
    let [sxx, _, syy] = kernel.s;
    let ok = kernel
        .c
        .iter()
        .chain(kernel.s.iter())
        .all(|v| v.is_finite())
        && sxx > 0.0
        && syy > 0.0;
    let ws = if kernel.weight_sigmas.is_finite() && kernel.weight_sigmas > 0.0 {
        kernel.weight_sigmas
    } else {
        3.0
    };
    let half = if ok {
        [ws * sxx.sqrt(), ws * syy.sqrt()]
    } else {
        [f64::INFINITY; 2]
    };
    let period = [sizes[0][0] as f64, sizes[0][1] as f64];
    let axis = |ax: usize| {
        if 2.0 * half[ax] >= 3.0 * period[ax] {
            Axis::Uniform
        } else if 2.0 * half[ax] >= period[ax] {
            Axis::Folded
        } else {
            Axis::Open
        }
    };
    let geo = Geometry {
        pyr,
        k: CutKernel {
            c: if ok { kernel.c } else { [0.0; 2] },
            s: if ok { kernel.s } else { [1.0, 0.0, 1.0] },
            weight_sigmas: ws,
        },
        half,
        period,
        axes: [axis(0), axis(1)],
    };
    // The coarsest level on which the box spans at most two nodes per axis.
    let reach = half[0].max(half[1]);
    let start = if reach.is_finite() {
        (reach.max(1.0).log2().ceil() as usize).min(top)
    } else {
        top
    };
    let mut entries = [Entry::default(); MAX_CUT_NODES];
    let mut n = 0usize;
    let range = |ax: usize, l: usize| -> (i64, i64) {
        let side = (1u64 << l) as f64;
        match geo.axes[ax] {
            Axis::Open => (
                ((geo.k.c[ax] - half[ax]) / side).floor() as i64,
                ((geo.k.c[ax] + half[ax]) / side).floor() as i64,
            ),
            _ => (0, sizes[l][ax] as i64 - 1),
        }
    };
    let (rx, ry) = (range(0, start), range(1, start));
    let mut total = 0.0;
    'fill: for j in ry.0..=ry.1 {
        for i in rx.0..=rx.1 {
            if n == MAX_CUT_NODES {
                break 'fill;
            }
            let r = geo.raw(start, i, j);
            entries[n] = Entry {
                l: start as u8,
                i,
                j,
                mass: r,
                ..Entry::default()
            };
            total += r;
            n += 1;
        }
    }
    for e in &mut entries[..n] {
        let mass = if total > 0.0 && total.is_finite() {
            e.mass / total
        } else {
            1.0 / n as f64
        };
        *e = geo.entry(start, e.i, e.j, mass);
    }
    let mut splits = 0;
    // NaN or non-positive tolerances split until the cap.
    let tolerance = if tolerance > 0.0 {
        tolerance as f64
    } else {
        0.0
    };
    while let Some((worst, err)) = entries[..n]
        .iter()
        .enumerate()
        .filter(|(_, e)| e.l > 0)
        .map(|(k, e)| (k, e.err))
        .max_by(|a, b| a.1.total_cmp(&b.1))
    {
        if err <= tolerance {
            break;
        }
        let e = entries[worst];
        let kids = e.child.iter().filter(|&&b| e.mass * b >= MIN_SHARE).count();
        if kids == 0 {
            // Every child below the share floor: the node stays, as it is.
            entries[worst].err = 0.0;
            continue;
        }
        if n - 1 + kids > max_nodes {
            break;
        }
        entries[worst] = entries[n - 1];
        n -= 1;
        let l = e.l as usize;
        for (c, (a, b)) in CHILDREN.into_iter().enumerate() {
            if e.mass * e.child[c] >= MIN_SHARE {
                entries[n] = geo.entry(l - 1, 2 * e.i + a, 2 * e.j + b, e.mass * e.child[c]);
                n += 1;
            }
        }
        splits += 1;
    }
    let mut stats = CutStats {
        nodes: n,
        start_level: start,
        splits,
        ..CutStats::default()
    };
    for e in &entries[..n] {
        let l = e.l as usize;
        let k = geo.index(l, e.i, e.j);
        if l == 0 {
            set.push(e.mass as f32, lobe0(k));
        } else {
            pyr.push_node(l, k, e.mass, &lobe0, set);
        }
        stats.max_error = stats.max_error.max(e.err as f32);
        stats.total_error += e.err as f32;
    }
    set.normalise();
    stats.lobes = set.len();
    stats
}
