//! The stored residual of a filtered-mixture node (gmm.rs): how far the node's few lobes are from
//! the lobes of its subtree, measured in closed form at build time, and how different its children
//! are from one another. A hierarchy cut (cut.rs) reads both to decide where a node may stand for
//! its subtree.
//!
//! **Measure.** The L2 distance between slope densities, relative to the subtree's own L2 norm:
//! ρ = ‖q − p‖₂ / ‖p‖₂, with q the node's mixture and p the uniform mixture of its subtree's lobes.
//! Under a point light a shading point returns D(h) times smooth factors, so ρ is the relative RMS
//! error of the image of a footprint over the half vectors a moving point light sweeps, weighted
//! toward where the P-NDF is bright (‖p‖₂² = E_p\[p\] is p's mean density under itself). Unlike a total
//! variation on a binned grid it does not blur the glints away: two σ_ε-wide lobes a few σ_ε apart
//! are far apart in L2.
//!
//! **Closed form.** For Gaussians, ∫ N(x; μ_a, Σ_a) N(x; μ_b, Σ_b) dx = N(μ_a − μ_b; 0, Σ_a + Σ_b),
//! so the inner products of mixtures are double sums over their components and
//! ‖q − p‖₂² = ⟨q, q⟩ − 2⟨q, p⟩ + ⟨p, p⟩.
//!
//! **Bound through the levels.** A node's subtree holds up to 4^l lobes, too many to compare with
//! directly, so the distance is measured against its children's mixtures u = Σ_c q_c / n and carried
//! up by the triangle inequality: ‖q − p‖ ≤ ‖q − u‖ + Σ_c ‖q_c − p_c‖ / n, exact at level 1 (whose
//! children are lobes) and an upper bound above.
//!
//! **Heterogeneity.** A cut weighs a node's subtree by the footprint's kernel, not uniformly. With
//! child shares b_c (Σ b_c = 1), Σ_c b_c p_c − Σ_c p_c / n = Σ_c (b_c − 1/n)(p_c − p̄), so the
//! error of the uniform weights is at most Σ_c |b_c − 1/n| · max_c ‖p_c − p̄‖. The node stores
//! η = max_c ‖q_c − u‖₂ / ‖u‖₂ (measured on the children's mixtures) for that term.

/// A Gaussian component: weight, mean and covariance [xx, xy, yy], in `f64`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Comp {
    pub w: f64,
    pub mean: [f64; 2],
    pub cov: [f64; 3],
}

#[cfg(test)]
impl Comp {
    /// The isotropic component of weight `w`, mean (mx, my) and standard deviation `s` (tests).
    pub(crate) fn isotropic(w: f64, mx: f64, my: f64, s: f64) -> Comp {
        Comp {
            w,
            mean: [mx, my],
            cov: [s * s, 0.0, s * s],
        }
    }
}

/// ∫ N(x; μ_a, Σ_a) N(x; μ_b, Σ_b) dx = N(μ_a − μ_b; 0, Σ_a + Σ_b) (weights not applied).
pub(crate) fn overlap(a: &Comp, b: &Comp) -> f64 {
    let s = [
        a.cov[0] + b.cov[0],
        a.cov[1] + b.cov[1],
        a.cov[2] + b.cov[2],
    ];
    let det = (s[0] * s[2] - s[1] * s[1]).max(1e-300);
    let (dx, dy) = (a.mean[0] - b.mean[0], a.mean[1] - b.mean[1]);
    let q = (s[2] * dx * dx - 2.0 * s[1] * dx * dy + s[0] * dy * dy) / det;
    (-0.5 * q).exp() / (std::f64::consts::TAU * det.sqrt())
}

/// ⟨p, q⟩ = Σ_i Σ_j w_i w_j ∫ N_i N_j for two mixtures.
pub(crate) fn inner(p: &[Comp], q: &[Comp]) -> f64 {
    p.iter()
        .map(|a| q.iter().map(|b| a.w * b.w * overlap(a, b)).sum::<f64>())
        .sum()
}

/// ‖p − q‖₂ from the three inner products (clamped at 0 against rounding).
fn distance(pp: f64, pq: f64, qq: f64) -> f64 {
    (pp - 2.0 * pq + qq).max(0.0).sqrt()
}

/// What a node stores (module docs): ρ the relative L2 residual bound, η the children's relative
/// spread, and ‖u‖₂ the norm of the children's mixture (which the parent needs to carry ρ up).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Residual {
    pub rho: f32,
    pub eta: f32,
    pub norm: f32,
}

/// The residual of a node whose mixture is `q` (weights summing to 1) and whose `n` children have
/// the mixtures `children[c]` (weights summing to 1 each) and residuals `child_res[c]` (zero for
/// lobes).
pub(crate) fn node_residual(q: &[Comp], children: &[&[Comp]], child_res: &[Residual]) -> Residual {
    let n = children.len().max(1) as f64;
    // Gram blocks ⟨q_c, q_d⟩ of the children's mixtures.
    let k = children.len();
    let mut gram = [[0.0f64; 4]; 4];
    for c in 0..k {
        for d in c..k {
            let v = inner(children[c], children[d]);
            gram[c][d] = v;
            gram[d][c] = v;
        }
    }
    let uu: f64 = gram[..k]
        .iter()
        .map(|r| r[..k].iter().sum::<f64>())
        .sum::<f64>()
        / (n * n);
    let qu: f64 = children.iter().map(|c| inner(q, c)).sum::<f64>() / n;
    let qq = inner(q, q);
    let norm = uu.max(0.0).sqrt();
    if !(norm > 0.0 && norm.is_finite()) {
        return Residual::default();
    }
    let local = distance(qq, qu, uu);
    let below: f64 = child_res
        .iter()
        .map(|r| r.rho as f64 * r.norm as f64)
        .sum::<f64>()
        / n;
    let eta = (0..k)
        .map(|c| {
            let cu: f64 = gram[c][..k].iter().sum::<f64>() / n;
            distance(gram[c][c], cu, uu)
        })
        .fold(0.0f64, f64::max);
    Residual {
        rho: ((local + below) / norm) as f32,
        eta: (eta / norm) as f32,
        norm: norm as f32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The overlap against a midpoint quadrature of the product of two densities.
    #[test]
    fn overlap_matches_quadrature() {
        let a = Comp {
            w: 1.0,
            mean: [0.01, -0.02],
            cov: [0.0009, 0.0002, 0.0004],
        };
        let b = Comp::isotropic(1.0, 0.03, 0.0, 0.015);
        let pdf = |c: &Comp, x: f64, y: f64| {
            let det = c.cov[0] * c.cov[2] - c.cov[1] * c.cov[1];
            let (dx, dy) = (x - c.mean[0], y - c.mean[1]);
            let q = (c.cov[2] * dx * dx - 2.0 * c.cov[1] * dx * dy + c.cov[0] * dy * dy) / det;
            (-0.5 * q).exp() / (std::f64::consts::TAU * det.sqrt())
        };
        let (n, lo, hi) = (800, -0.2, 0.2);
        let h = (hi - lo) / n as f64;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = (lo + (i as f64 + 0.5) * h, lo + (j as f64 + 0.5) * h);
                sum += pdf(&a, x, y) * pdf(&b, x, y) * h * h;
            }
        }
        let o = overlap(&a, &b);
        assert!((o - sum).abs() < 1e-6 * sum, "{o} vs {sum}");
    }

    /// A node equal to its children's mixture has no residual; identical children have no spread;
    /// a node that merges two far lobes into one has a large residual.
    #[test]
    fn residual_is_zero_exactly_when_nothing_is_lost() {
        let l = [Comp::isotropic(1.0, 0.0, 0.0, 0.01)];
        let r = [Comp::isotropic(1.0, 0.1, 0.0, 0.01)];
        let children: [&[Comp]; 2] = [&l, &r];
        let exact = [
            Comp::isotropic(0.5, 0.0, 0.0, 0.01),
            Comp::isotropic(0.5, 0.1, 0.0, 0.01),
        ];
        let z = [Residual::default(); 2];
        let e = node_residual(&exact, &children, &z);
        assert!(e.rho < 1e-6, "{e:?}");
        assert!(e.eta > 0.9, "two disjoint children: {e:?}");
        // One moment-matched lobe in place of two lobes 10 σ apart.
        let merged = [Comp {
            w: 1.0,
            mean: [0.05, 0.0],
            cov: [0.0001 + 0.0025, 0.0, 0.0001],
        }];
        let m = node_residual(&merged, &children, &z);
        assert!(m.rho > 0.5, "{m:?}");
        let same: [&[Comp]; 2] = [&l, &l];
        let s = node_residual(&l, &same, &z);
        assert!(s.rho < 1e-6 && s.eta < 1e-6, "{s:?}");
    }

    /// The children's residuals are carried up: a node over children that each lose ρ_c loses at
    /// least as much in the bound.
    #[test]
    fn residual_carries_the_childrens() {
        let l = [Comp::isotropic(1.0, 0.0, 0.0, 0.01)];
        let children: [&[Comp]; 2] = [&l, &l];
        let child = Residual {
            rho: 0.3,
            eta: 0.0,
            norm: inner(&l, &l).sqrt() as f32,
        };
        let r = node_residual(&l, &children, &[child, child]);
        assert!((r.rho - 0.3).abs() < 1e-5, "{r:?}");
    }
}
