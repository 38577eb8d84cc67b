//! Runnalls' greedy reduction of a Gaussian mixture (\[Runnalls2007\]), as the filtered mixture's
//! build (gmm.rs) applies it to a node's children: the pair whose moment-matched merge has the
//! smallest upper bound of the KL divergence it adds,
//! B(i, j) = ½ [(w_i + w_j) ln det Σ_ij − w_i ln det Σ_i − w_j ln det Σ_j] (eq. 21), is merged until
//! the asked number of components remain. Moment matching keeps the mixture's weight, mean and
//! covariance exact at every merge.

use super::gmm_residual::Comp;

impl Comp {
    fn ln_det(&self) -> f64 {
        (self.cov[0] * self.cov[2] - self.cov[1] * self.cov[1])
            .max(1e-300)
            .ln()
    }

    /// The moment-matched merge of two components.
    fn merge(&self, o: &Comp) -> Comp {
        let w = self.w + o.w;
        if w <= 0.0 {
            return *self;
        }
        let (a, b) = (self.w / w, o.w / w);
        let mean = [
            a * self.mean[0] + b * o.mean[0],
            a * self.mean[1] + b * o.mean[1],
        ];
        let (d0, d1) = (self.mean[0] - o.mean[0], self.mean[1] - o.mean[1]);
        let ab = a * b;
        Comp {
            w,
            mean,
            cov: [
                a * self.cov[0] + b * o.cov[0] + ab * d0 * d0,
                a * self.cov[1] + b * o.cov[1] + ab * d0 * d1,
                a * self.cov[2] + b * o.cov[2] + ab * d1 * d1,
            ],
        }
    }
}

/// The cost of merging components a and b (their ln det given): Runnalls' bound
/// B(a, b) = ½ [(w_a + w_b) ln det Σ_ab − w_a ln det Σ_a − w_b ln det Σ_b].
fn merge_cost(a: &Comp, ld_a: f64, b: &Comp, ld_b: f64) -> f64 {
    let m = a.merge(b);
    0.5 * (m.w * m.ln_det() - a.w * ld_a - b.w * ld_b)
}

/// Most components a reduction caches the pair costs of (a filtered-mixture node's 2 × 2 children
/// hold at most 4 × 4: gmm.rs checks it against its `GMM_LOBES` at compile time); larger inputs
/// take the uncached path.
pub(crate) const MAX_REDUCED: usize = 16;

/// Reduces `comps` (weights summing to 1) to at most `k` components by Runnalls' greedy merging
/// (module docs): the pair of least [`merge_cost`] first, the first such pair in (i, j) order on a
/// tie. The pair costs are computed once and, after a merge, again only for the pairs of the merged
/// component (the others are unchanged), so a node of 16 components takes ~230 logarithms instead
/// of ~2,000; the choices are those of recomputing every cost at every step.
pub(crate) fn reduce(comps: &mut Vec<Comp>, k: usize) {
    comps.retain(|c| c.w > 0.0);
    let n = comps.len();
    if n <= k {
        return;
    }
    if n > MAX_REDUCED {
        return reduce_uncached(comps, k);
    }
    let mut ld = [0.0f64; MAX_REDUCED];
    for (l, c) in ld.iter_mut().zip(comps.iter()) {
        *l = c.ln_det();
    }
    // cost[i][j] for i < j.
    let mut cost = [[0.0f64; MAX_REDUCED]; MAX_REDUCED];
    for i in 0..n {
        for j in (i + 1)..n {
            cost[i][j] = merge_cost(&comps[i], ld[i], &comps[j], ld[j]);
        }
    }
    // The table entry of the pair {p, q}.
    let at = |p: usize, q: usize| if p < q { (p, q) } else { (q, p) };
    while comps.len() > k {
        let len = comps.len();
        let mut best = (f64::INFINITY, 0, 1);
        for (i, row) in cost.iter().enumerate().take(len) {
            for (j, &c) in row.iter().enumerate().take(len).skip(i + 1) {
                if c < best.0 {
                    best = (c, i, j);
                }
            }
        }
        let (_, i, j) = best;
        comps[i] = comps[i].merge(&comps[j]);
        ld[i] = comps[i].ln_det();
        // swap_remove(j): the last component moves to j, with its costs.
        let last = len - 1;
        comps.swap_remove(j);
        if j != last {
            ld[j] = ld[last];
            for q in 0..last {
                if q != j {
                    let (a, b) = at(last, q);
                    let (c, d) = at(j, q);
                    cost[c][d] = cost[a][b];
                }
            }
        }
        for q in 0..last {
            if q != i {
                let (a, b) = at(i, q);
                cost[a][b] = merge_cost(&comps[i], ld[i], &comps[q], ld[q]);
            }
        }
    }
}

/// [`reduce`] recomputing every pair's cost at every step (no cache).
fn reduce_uncached(comps: &mut Vec<Comp>, k: usize) {
    comps.retain(|c| c.w > 0.0);
    while comps.len() > k {
        let mut best = (f64::INFINITY, 0, 1);
        for i in 0..comps.len() {
            for j in (i + 1)..comps.len() {
                let (a, b) = (&comps[i], &comps[j]);
                let cost = merge_cost(a, a.ln_det(), b, b.ln_det());
                if cost < best.0 {
                    best = (cost, i, j);
                }
            }
        }
        let (_, i, j) = best;
        let m = comps[i].merge(&comps[j]);
        comps[i] = m;
        comps.swap_remove(j);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached reduction makes the choices of recomputing every cost: the same components, bit
    /// for bit, on random nodes of 2 to 16 components reduced to 1 to 4.
    #[test]
    fn cached_reduction_equals_the_uncached() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(3);
        for _ in 0..2000 {
            let n = rng.random_range(2..=16usize);
            let k = rng.random_range(1..=4usize);
            let mut comps: Vec<Comp> = (0..n)
                .map(|_| {
                    let s = rng.random_range(0.005..0.2f64);
                    let r = rng.random_range(-0.5..0.5f64);
                    Comp {
                        w: 1.0 / n as f64,
                        mean: [rng.random_range(-0.4..0.4), rng.random_range(-0.4..0.4)],
                        cov: [s * s, r * s * s * 0.5, s * s * rng.random_range(0.3..3.0)],
                    }
                })
                .collect();
            // Duplicates: ties between pairs.
            if n > 3 && rng.random::<bool>() {
                comps[2] = comps[0];
                comps[3] = comps[1];
            }
            let mut a = comps.clone();
            let mut b = comps;
            reduce(&mut a, k);
            reduce_uncached(&mut b, k);
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(&b) {
                assert_eq!((x.w, x.mean, x.cov), (y.w, y.mean, y.cov));
            }
        }
    }

    /// Reduction keeps the total weight, mean and covariance of the mixture (moment matching is
    /// exact at every merge), and merges the two close components before the far one.
    #[test]
    fn reduction_keeps_the_first_two_moments() {
        let mut c = vec![
            Comp::isotropic(0.25, 0.0, 0.0, 0.01),
            Comp::isotropic(0.25, 0.001, 0.0, 0.01),
            Comp::isotropic(0.25, 0.3, 0.1, 0.02),
            Comp::isotropic(0.25, -0.2, 0.05, 0.01),
        ];
        let moments = |c: &[Comp]| {
            let w: f64 = c.iter().map(|c| c.w).sum();
            let mx: f64 = c.iter().map(|c| c.w * c.mean[0]).sum::<f64>() / w;
            let vxx: f64 = c
                .iter()
                .map(|c| c.w * (c.cov[0] + (c.mean[0] - mx).powi(2)))
                .sum::<f64>()
                / w;
            (w, mx, vxx)
        };
        let before = moments(&c);
        reduce(&mut c, 3);
        let after = moments(&c);
        assert_eq!(c.len(), 3);
        assert!((before.0 - after.0).abs() < 1e-12);
        assert!((before.1 - after.1).abs() < 1e-12);
        assert!((before.2 - after.2).abs() < 1e-12);
        // The far components survive unmerged.
        assert!(c.iter().any(|c| (c.mean[0] - 0.3).abs() < 1e-12));
        assert!(c.iter().any(|c| (c.mean[0] + 0.2).abs() < 1e-12));
        reduce(&mut c, 1);
        let one = moments(&c);
        assert!((before.2 - one.2).abs() < 1e-12);
    }
}
