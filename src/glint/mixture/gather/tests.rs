//! Unit tests of the gather against the footprint's Gaussian summed directly.

use super::*;

/// A level with `grid` nodes whose means and errors are functions of the node index; the
/// gather reads nothing else.
#[derive(Clone, Copy, Debug)]
struct Grid {
    grid: [usize; 2],
    level: usize,
}

impl LevelView for Grid {
    type Scratch = ();
    fn scratch() {}
    fn level(&self) -> usize {
        self.level
    }
    fn grid(&self) -> [usize; 2] {
        self.grid
    }
    fn tree(&self) -> &crate::glint::kernels::slope_tree::SlopeTree {
        unreachable!("the gather reads no tree")
    }
    fn block<'s>(
        &'s self,
        _: usize,
        _: usize,
        _: &'s mut (),
    ) -> &'s super::super::blocks::LobeBlock {
        unreachable!("the gather reads no block")
    }
    fn lobe(&self, _: usize) -> crate::ndf::SlopeGaussian {
        unreachable!("the gather reads no lobe")
    }
    fn mean_cov(&self, k: usize) -> ([f64; 2], [f64; 3]) {
        let k = k as f64;
        ([0.01 * k, 0.5 - 0.003 * k], [0.02 + 0.001 * k, 0.005, 0.03])
    }
    fn error(&self, k: usize, res: usize) -> f32 {
        0.001 * (k + res) as f32
    }
}

/// The gather's weights, mean, covariance and error against the footprint's Gaussian summed
/// directly over every unwrapped node of the ±3σ window (periodic images added per node), on
/// grids smaller and larger than the window, footprints across the grid's edges, folded and
/// unfolded, isotropic and sheared: every slot's weight to 1e-6 relative, the lanes summing to
/// 1 with nothing outside the slots, and every lane mapped back to its node.
#[test]
fn the_gather_is_the_footprint_gaussian_over_its_window() {
    // (grid, footprint centre, covariance, level)
    type Case = ([usize; 2], [f64; 2], [f64; 3], usize);
    let cases: &[Case] = &[
        ([64, 64], [20.3, 31.7], [9.0, 2.0, 4.0], 0),
        ([64, 64], [0.4, 63.2], [30.0, -10.0, 12.0], 0),
        ([37, 23], [36.9, 0.1], [5.0, 0.0, 5.0], 1),
        ([9, 50], [4.5, 10.0], [40.0, 3.0, 2.0], 0),
        ([7, 5], [2.0, 3.0], [200.0, 50.0, 90.0], 1),
        ([1, 13], [0.5, 6.0], [0.3, 0.0, 0.3], 0),
        ([128, 128], [64.0, 64.0], [0.05, 0.01, 0.02], 0),
    ];
    for &(grid, c, cov, level) in cases {
        let lv = Grid { grid, level };
        let det = cov[0] * cov[2] - cov[1] * cov[1];
        let eff = Effective {
            c,
            cov,
            inv: [cov[2] / det, -cov[1] / det, cov[0] / det],
        };
        let second = level == 0;
        let g = gather(3.0, lv, &eff, 1, second, Lent::new(None));
        // The expected weights per node, by direct summation over the window.
        let half = [3.0 * cov[0].sqrt(), 3.0 * cov[2].sqrt()];
        // An empty window keeps the nearest node.
        let range = |a: usize| {
            let (lo, hi) = (
                (c[a] - 0.5 - half[a]).ceil(),
                (c[a] - 0.5 + half[a]).floor(),
            );
            if hi >= lo {
                (lo as i64, hi as i64)
            } else {
                let r = (c[a] - 0.5).round() as i64;
                (r, r)
            }
        };
        let ((i0, i1), (j0, j1)) = (range(0), range(1));
        let mut want = std::collections::HashMap::new();
        let mut total = 0.0;
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (dx, dy) = (i as f64 + 0.5 - c[0], j as f64 + 0.5 - c[1]);
                let q = eff.inv[0] * dx * dx + 2.0 * eff.inv[1] * dx * dy + eff.inv[2] * dy * dy;
                let w = (-0.5 * q).exp();
                let k = j.rem_euclid(grid[1] as i64) as usize * grid[0]
                    + i.rem_euclid(grid[0] as i64) as usize;
                *want.entry(k).or_insert(0.0) += w;
                total += w;
            }
        }
        let (mut mean, mut m2, mut err) = ([0.0; 2], [0.0; 3], 0.0);
        for (&k, w) in want.iter_mut() {
            *w /= total;
            let (mu, cv) = lv.mean_cov(k);
            mean[0] += *w * mu[0];
            mean[1] += *w * mu[1];
            m2[0] += *w * (cv[0] + mu[0] * mu[0]);
            m2[1] += *w * (cv[1] + mu[0] * mu[1]);
            m2[2] += *w * (cv[2] + mu[1] * mu[1]);
            err += *w * lv.error(k, 1) as f64;
        }
        let case = format!("{grid:?} {c:?} {cov:?}");
        assert_eq!(g.slot_count(), want.len(), "{case}");
        let mut seen = std::collections::HashSet::new();
        for s in 0..g.slot_count() {
            let (w, k) = g.slot(s, grid[0]);
            let e = want.get(&k).copied().unwrap_or(0.0);
            assert!(
                ((w as f64) - e).abs() <= 1e-6 * e + 1e-12,
                "{case}: node {k}: {w} {e}"
            );
            assert!(seen.insert(k), "{case}: node {k} twice");
        }
        let bw = &g.bufs.block_weights;
        let sum: f64 = bw.iter().map(|&w| w as f64).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{case}: Σ W = {sum}");
        let last = *g.bufs.block_cdf.last().unwrap();
        assert!((last - sum).abs() < 1e-12, "{case}: {last} {sum}");
        for (lane, &w) in bw.iter().enumerate() {
            if w != 0.0 {
                let k = g.node_of_lane(lane, grid[0]);
                let e = want.get(&k).copied().unwrap_or(0.0);
                assert!(
                    ((w as f64) - e).abs() <= 1e-6 * e,
                    "{case}: lane {lane}: {w} {e}"
                );
            }
        }
        let m = g.mean_slope;
        // The mean is kept in f32.
        for (a, b) in [(m.x, mean[0]), (m.y, mean[1])] {
            assert!(
                (a as f64 - b).abs() <= 1e-6 * b.abs().max(1.0),
                "{case}: {m} {mean:?}"
            );
        }
        if level > 0 {
            assert!(
                (g.lod_error - err).abs() < 1e-9,
                "{case}: {} {err}",
                g.lod_error
            );
        }
        if second {
            let want_cov = [
                m2[0] - mean[0] * mean[0],
                m2[1] - mean[0] * mean[1],
                m2[2] - mean[1] * mean[1],
            ];
            for (a, b) in g.slope_cov.iter().zip(want_cov) {
                assert!(
                    (a - b).abs() < 1e-9,
                    "{case}: {:?} {want_cov:?}",
                    g.slope_cov
                );
            }
        }
    }
}
