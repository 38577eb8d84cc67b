//! The filtered mixture: a mip chain whose every node holds a [`GMM_LOBES`]-lobe slope Gaussian
//! mixture of the lobes below it, so that a large footprint is served in O(1) by a few lobes that
//! keep the P-NDF's shape (the single filtered lobe of \[Chermain2019\] §4.2.2 keeps only its mean
//! and covariance).
//!
//! **Build.** Level 0 is the model's own lobes on a regular grid (one component each, as the
//! model evaluates them: the mixture's lobes with their floored covariance and clamped correlation,
//! the position-normal elements' slope marginals; not stored). A node of level l + 1 takes the components of its
//! (up to) 2 × 2 children, each child's weights divided by the number of children, and reduces them
//! to [`GMM_LOBES`] by greedy pairwise merging (gmm_reduce.rs): the pair whose moment-matched merge has the smallest
//! upper bound of the KL divergence it adds,
//! B(i, j) = ½ [(w_i + w_j) ln det Σ_ij − w_i ln det Σ_i − w_j ln det Σ_j] (\[Runnalls2007\] eq. 21),
//! is merged until [`GMM_LOBES`] components remain. Moment matching keeps the node's mean and
//! covariance exact (those of the single filtered lobe), so the filtered mixture is never further
//! from the lobes it replaces, in its first two moments, than the filtered lobe; its extra lobes
//! keep what one Gaussian cannot hold (a flat surface's peak and its scratches' streaks apart).
//!
//! **Lookup.** As the moment mip chain: trilinear at level log₂ √(footprint area in lobes) and the
//! footprint's centre, a convex combination of up to 8 nodes, each weight multiplying its node's
//! component weights (lobe_set.rs holds the result and evaluates it).
//!
//! **Level 1 is not stored.** A node of level 1 has at most 4 = [`GMM_LOBES`] children, so its
//! reduction merges nothing: its components are its lobes, each of weight 1/(children). The chain
//! keeps level 1's residuals (gmm_residual.rs) and serves its components from the lobes on demand
//! ([`GmmPyramid::push_node`], [`GmmPyramid::records`]), bit for bit the records the build made,
//! which saves 24 of the 36 bytes per lobe the chain would otherwise hold.
//!
//! Cost: ~20 ns of build per lobe (one reduction of ≤ 4 [`GMM_LOBES`] components per node), 96
//! bytes per node of the levels ≥ 2 and 12 of residuals per node of the levels ≥ 1 (≤ 12 bytes per
//! lobe), and O(1) per query.

use super::gmm_reduce::{MAX_REDUCED, reduce};
use super::gmm_residual::{Comp, Residual, node_residual};
use super::lobe_set::LobeSet;
use super::mip::{bilinear_nodes, trilinear_levels};
use super::slope_tree::level_sizes;
use crate::ndf::SlopeGaussian;

/// Components per node of the filtered mixture.
pub const GMM_LOBES: usize = 4;

// A node reduces its 2 × 2 children's components with the reduction's cached pair costs.
const _: () = assert!(4 * GMM_LOBES <= MAX_REDUCED);

/// One stored component: weight (summing to 1 over a node) and raw moments
/// `[E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ]` of its Gaussian.
type Stored = [f32; 6];

/// One node as a file holds it (gmm_store.rs): its [`GMM_LOBES`] components ([`Stored`], weight 0
/// pads) then its residual ρ, η, ‖u‖₂ (gmm_residual.rs).
pub(crate) type NodeRecord = [f32; 6 * GMM_LOBES + 3];

impl Comp {
    fn of_lobe(g: &SlopeGaussian) -> Comp {
        let (m, c) = (g.mean(), g.covariance());
        Comp {
            w: 1.0,
            mean: [m.x as f64, m.y as f64],
            cov: [c.x_axis.x as f64, c.x_axis.y as f64, c.y_axis.y as f64],
        }
    }

    fn stored(&self) -> Stored {
        let [mx, my] = self.mean;
        [
            self.w as f32,
            mx as f32,
            my as f32,
            (self.cov[0] + mx * mx) as f32,
            (self.cov[2] + my * my) as f32,
            (self.cov[1] + mx * my) as f32,
        ]
    }

    /// A stored component as a query serves it: its Gaussian read back with the standard deviations
    /// floored at `sigma_min` (what [`GmmPyramid::push_node`] pushes), with its weight.
    fn served(s: &Stored, sigma_min: f32) -> Comp {
        let g = SlopeGaussian::from_moments([s[1], s[2], s[3], s[4], s[5]], sigma_min);
        Comp {
            w: s[0] as f64,
            ..Comp::of_lobe(&g)
        }
    }

    fn from_stored(s: &Stored) -> Comp {
        let (mx, my) = (s[1] as f64, s[2] as f64);
        Comp {
            w: s[0] as f64,
            mean: [mx, my],
            cov: [
                s[3] as f64 - mx * mx,
                s[5] as f64 - mx * my,
                s[4] as f64 - my * my,
            ],
        }
    }
}

/// The filtered-mixture mip chain (module docs): levels l ≥ 1, [`GMM_LOBES`] components per node,
/// stored from level 2 (level 1's are its lobes).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct GmmPyramid {
    sizes: Vec<[usize; 2]>,
    /// `levels[l - 2]`: level l ≥ 2's nodes, row major, each [`GMM_LOBES`] components (weight 0
    /// pads).
    levels: Vec<Vec<[Stored; GMM_LOBES]>>,
    /// `residuals[l - 1]`: level l's nodes' residuals (gmm_residual.rs), row major.
    residuals: Vec<Vec<Residual>>,
    /// The floor σ_min of every stored component's standard deviations.
    sigma_min: f32,
}

/// The components of node (`x`, `y`) of level 1 over a level-0 grid `[nx, ny]` whose lobe k is
/// `lobe0(k)`: its (up to) 2 × 2 lobes in row order, each of weight 1/(children), as the build's
/// reduction leaves them (it merges nothing at ≤ [`GMM_LOBES`] components), weight 0 pads.
fn level_one_node(
    [nx, ny]: [usize; 2],
    x: usize,
    y: usize,
    lobe0: impl Fn(usize) -> SlopeGaussian,
) -> [Stored; GMM_LOBES] {
    let mut out = [[0.0f32; 6]; GMM_LOBES];
    let (xs, ys) = ((2 * x)..(2 * x + 2).min(nx), (2 * y)..(2 * y + 2).min(ny));
    let n = (xs.len() * ys.len()) as f64;
    let mut i = 0;
    for cy in ys {
        for cx in xs.clone() {
            let mut c = Comp::of_lobe(&lobe0(cy * nx + cx));
            c.w /= n;
            out[i] = c.stored();
            i += 1;
        }
    }
    out
}

impl GmmPyramid {
    /// Builds the chain over an `nx × ny` lobe grid whose lobe k (row major) is `lobe0(k)`; the
    /// stored components are read back with their standard deviations floored at `sigma_min`.
    pub fn build(
        nx: usize,
        ny: usize,
        lobe0: impl Fn(usize) -> SlopeGaussian + Sync,
        sigma_min: f32,
    ) -> GmmPyramid {
        use rayon::prelude::*;
        let sizes = level_sizes(nx, ny);
        let mut levels: Vec<Vec<[Stored; GMM_LOBES]>> = Vec::new();
        let mut residuals: Vec<Vec<Residual>> = Vec::new();
        for l in 1..sizes.len() {
            let [pw, ph] = sizes[l - 1];
            let [w, h] = sizes[l];
            let prev = levels.last();
            let prev_res = residuals.last();
            // Node (x, y)'s children as stored (weights divided by their count) and, for the
            // residual, as served with their residuals.
            let node = |x: usize, y: usize| -> ([Stored; GMM_LOBES], Residual) {
                let mut comps = Vec::with_capacity(4 * GMM_LOBES);
                let mut served: Vec<Vec<Comp>> = Vec::with_capacity(4);
                let mut child_res = Vec::with_capacity(4);
                for cy in (2 * y)..(2 * y + 2).min(ph) {
                    for cx in (2 * x)..(2 * x + 2).min(pw) {
                        let k = cy * pw + cx;
                        match (prev, prev_res) {
                            (Some(p), Some(r)) => {
                                comps.extend(p[k].iter().map(Comp::from_stored));
                                served.push(
                                    p[k].iter()
                                        .filter(|c| c[0] > 0.0)
                                        .map(|c| Comp::served(c, sigma_min))
                                        .collect(),
                                );
                                child_res.push(r[k]);
                            }
                            _ => {
                                let c = Comp::of_lobe(&lobe0(k));
                                comps.push(c);
                                served.push(vec![c]);
                                child_res.push(Residual::default());
                            }
                        }
                    }
                }
                let n = served.len() as f64;
                for c in &mut comps {
                    c.w /= n;
                }
                reduce(&mut comps, GMM_LOBES);
                let mut out = [[0.0f32; 6]; GMM_LOBES];
                for (o, c) in out.iter_mut().zip(&comps) {
                    *o = c.stored();
                }
                let q: Vec<Comp> = out
                    .iter()
                    .filter(|c| c[0] > 0.0)
                    .map(|c| Comp::served(c, sigma_min))
                    .collect();
                let children: Vec<&[Comp]> = served.iter().map(Vec::as_slice).collect();
                (out, node_residual(&q, &children, &child_res))
            };
            let (level, res): (Vec<[Stored; GMM_LOBES]>, Vec<Residual>) = (0..w * h)
                .into_par_iter()
                .map(|k| node(k % w, k / w))
                .unzip();
            levels.push(level);
            residuals.push(res);
        }
        // Level 1's components are its lobes (module docs): kept only while level 2 was built.
        if !levels.is_empty() {
            levels.remove(0);
        }
        GmmPyramid {
            sizes,
            levels,
            residuals,
            sigma_min,
        }
    }

    /// Node `k`'s components at level `l` ≥ 1: stored from level 2, level 1's from `lobe0`.
    fn node(
        &self,
        l: usize,
        k: usize,
        lobe0: impl Fn(usize) -> SlopeGaussian,
    ) -> [Stored; GMM_LOBES] {
        if l == 1 {
            let w = self.sizes[1][0];
            level_one_node(self.sizes[0], k % w, k / w, lobe0)
        } else {
            self.levels[l - 2][k]
        }
    }

    /// Level l ≥ 1's nodes as records (row major): what a file stores of the chain. `lobe0(k)` is
    /// the level-0 lobe k as at the build (level 1's components are its lobes).
    pub fn records<'a>(
        &'a self,
        l: usize,
        lobe0: impl Fn(usize) -> SlopeGaussian + Copy + 'a,
    ) -> impl ExactSizeIterator<Item = NodeRecord> + 'a {
        self.residuals[l - 1].iter().enumerate().map(move |(k, r)| {
            let mut out = [0.0f32; 6 * GMM_LOBES + 3];
            out[..6 * GMM_LOBES].copy_from_slice(self.node(l, k, lobe0).as_flattened());
            out[6 * GMM_LOBES..].copy_from_slice(&[r.rho, r.eta, r.norm]);
            out
        })
    }

    /// The chain over an `nx × ny` lobe grid from its levels' records (`levels[l - 1]`: level l's
    /// nodes, row major, as [`GmmPyramid::records`] gives them), read back with standard deviations
    /// floored at `sigma_min`: the chain [`GmmPyramid::build`] made, bit for bit, when the records
    /// are the ones it wrote. Level 1's components are checked as every level's and then dropped
    /// (the chain serves them from the lobes, module docs); its residuals are kept.
    ///
    /// # Errors
    /// A reason if the level count or a level's node count does not match the grid, or a node's
    /// weights are negative or do not sum to 1 (within 10⁻³: they are written as `f32` from an `f64`
    /// sum of 1). The components' moments and the residuals are the caller's to bound (the loader
    /// checks their ranges as it reads).
    pub fn from_records(
        nx: usize,
        ny: usize,
        records: Vec<Vec<NodeRecord>>,
        sigma_min: f32,
    ) -> std::result::Result<GmmPyramid, String> {
        let sizes = level_sizes(nx, ny);
        if records.len() + 1 != sizes.len() {
            return Err(format!(
                "{} filtered-mixture levels but the grid {nx}×{ny} has {} above the lobes",
                records.len(),
                sizes.len() - 1
            ));
        }
        let mut levels = Vec::with_capacity(records.len());
        let mut residuals = Vec::with_capacity(records.len());
        for (l, level) in records.into_iter().enumerate() {
            let [w, h] = sizes[l + 1];
            if level.len() != w * h {
                return Err(format!(
                    "filtered-mixture level {} holds {} nodes but its grid {w}×{h} needs {}",
                    l + 1,
                    level.len(),
                    w * h
                ));
            }
            let mut nodes = Vec::with_capacity(level.len());
            let mut res = Vec::with_capacity(level.len());
            for (k, r) in level.iter().enumerate() {
                let node: [Stored; GMM_LOBES] =
                    std::array::from_fn(|c| std::array::from_fn(|i| r[6 * c + i]));
                let sum: f64 = node.iter().map(|c| c[0] as f64).sum();
                if node.iter().any(|c| c[0].is_nan() || c[0] < 0.0) || (sum - 1.0).abs() > 1e-3 {
                    return Err(format!(
                        "filtered-mixture node {k} of level {}: weights sum to {sum}, not 1",
                        l + 1
                    ));
                }
                nodes.push(node);
                let t = &r[6 * GMM_LOBES..];
                res.push(Residual {
                    rho: t[0],
                    eta: t[1],
                    norm: t[2],
                });
            }
            if l > 0 {
                levels.push(nodes);
            }
            residuals.push(res);
        }
        Ok(GmmPyramid {
            sizes,
            levels,
            residuals,
            sigma_min,
        })
    }

    /// A chain of no levels (a placeholder while its model is assembled).
    pub fn empty() -> GmmPyramid {
        GmmPyramid {
            sizes: Vec::new(),
            levels: Vec::new(),
            residuals: Vec::new(),
            sigma_min: 0.0,
        }
    }

    /// Levels of the chain, level 0 (the lobes) included.
    pub fn levels(&self) -> usize {
        self.sizes.len()
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        let nodes: usize = self.levels.iter().map(Vec::len).sum();
        let residuals: usize = self.residuals.iter().map(Vec::len).sum();
        nodes * std::mem::size_of::<[Stored; GMM_LOBES]>()
            + residuals * std::mem::size_of::<Residual>()
    }

    /// The grid of every level, level 0 (the lobes) first.
    pub fn sizes(&self) -> &[[usize; 2]] {
        &self.sizes
    }

    /// The residual of node `k` of level `l` ≥ 1 (gmm_residual.rs; zero at level 0, whose nodes are
    /// the lobes themselves).
    pub fn residual(&self, l: usize, k: usize) -> Residual {
        if l == 0 {
            return Residual::default();
        }
        self.residuals[l - 1][k]
    }

    /// Pushes node `k` of level `l` ≥ 1 into `set`, its components' weights times `w` (as
    /// [`GmmPyramid::lookup`] serves them); `lobe0(k)` is the level-0 lobe k as at the build.
    pub fn push_node(
        &self,
        l: usize,
        k: usize,
        w: f64,
        lobe0: impl Fn(usize) -> SlopeGaussian,
        set: &mut LobeSet,
    ) {
        for c in &self.node(l, k, lobe0) {
            if c[0] > 0.0 {
                let g = SlopeGaussian::from_moments([c[1], c[2], c[3], c[4], c[5]], self.sigma_min);
                set.push((w * c[0] as f64) as f32, g);
            }
        }
    }

    /// The filtered mixture of a footprint centred at `p` (level-0 lobe units, lobe i centred at
    /// i + ½) at level of detail `lod` (clamped to [0, top], NaN → 0), into `set`: trilinear over
    /// the nodes (mip.rs), `lobe0(k)` the level-0 lobes as at the build; at most 8 nodes ×
    /// [`GMM_LOBES`] lobes.
    pub fn lookup(
        &self,
        lobe0: impl Fn(usize) -> SlopeGaussian,
        p: [f64; 2],
        lod: f64,
        set: &mut LobeSet,
    ) {
        let (p, l0, t) = trilinear_levels(self.sizes.len(), p, lod);
        set.clear();
        let mut add_level = |l: usize, wl: f64| {
            if wl <= 0.0 {
                return;
            }
            for (k, wb) in bilinear_nodes(p, l, self.sizes[l]) {
                let wn = wl * wb;
                if wn <= 0.0 {
                    continue;
                }
                if l == 0 {
                    set.push(wn as f32, lobe0(k));
                } else {
                    self.push_node(l, k, wn, &lobe0, set);
                }
            }
        };
        add_level(l0, 1.0 - t);
        if l0 + 1 < self.sizes.len() {
            add_level(l0 + 1, t);
        }
        set.normalise();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Level 1 is served from the lobes: every level-1 record holds the node's (up to) 2 × 2 lobes
    /// in row order, each of weight 1/(children), as mean and raw second moments, then zero pads,
    /// on an odd grid (edge nodes of 1 and 2 children); and `push_node` serves those lobes.
    #[test]
    fn level_one_is_its_lobes() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
        let (nx, ny) = (5, 3);
        let lobes: Vec<SlopeGaussian> = (0..nx * ny)
            .map(|_| {
                let m = [
                    rng.random_range(-0.5..0.5f32),
                    rng.random_range(-0.5..0.5f32),
                ];
                let (sx, sy) = (
                    rng.random_range(0.01..0.2f32),
                    rng.random_range(0.01..0.2f32),
                );
                let r = rng.random_range(-0.8..0.8f32);
                let (mxx, myy) = (sx * sx + m[0] * m[0], sy * sy + m[1] * m[1]);
                SlopeGaussian::from_moments(
                    [m[0], m[1], mxx, myy, r * sx * sy + m[0] * m[1]],
                    0.005,
                )
            })
            .collect();
        let pyr = GmmPyramid::build(nx, ny, |k| lobes[k], 0.005);
        assert_eq!(pyr.sizes()[1], [3, 2]);
        for (k, rec) in pyr.records(1, |k| lobes[k]).enumerate() {
            let (x, y) = (k % 3, k / 3);
            let kids: Vec<usize> = (2 * y..(2 * y + 2).min(ny))
                .flat_map(|cy| (2 * x..(2 * x + 2).min(nx)).map(move |cx| cy * nx + cx))
                .collect();
            for c in 0..GMM_LOBES {
                let got = &rec[6 * c..6 * c + 6];
                let Some(&kid) = kids.get(c) else {
                    assert_eq!(got, &[0.0; 6], "node {k}: pad {c}");
                    continue;
                };
                let (m, s) = (lobes[kid].mean(), lobes[kid].covariance());
                let m = [m.x as f64, m.y as f64];
                let want = [
                    1.0 / kids.len() as f64,
                    m[0],
                    m[1],
                    s.x_axis.x as f64 + m[0] * m[0],
                    s.y_axis.y as f64 + m[1] * m[1],
                    s.x_axis.y as f64 + m[0] * m[1],
                ];
                for (g, w) in got.iter().zip(want) {
                    assert!(
                        (*g as f64 - w).abs() <= 1e-6 * w.abs().max(1e-3),
                        "node {k}: {got:?}"
                    );
                }
            }
            let mut set = LobeSet::default();
            pyr.push_node(1, k, 1.0, |k| lobes[k], &mut set);
            assert_eq!(set.len(), kids.len());
        }
    }
}
