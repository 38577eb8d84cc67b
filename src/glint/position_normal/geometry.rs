//! The per-footprint geometry of a position-normal patch: the footprint in element units (clamped
//! to the query cap), the effective position Gaussian Σ_eff = Σ_P + σ_h² I, the conditional
//! position covariance Σ_u = (Σ_P⁻¹ + σ_h⁻² I)⁻¹, each element's weight and slope lobe under the
//! footprint, and the wrapped element ranges a footprint covers.
//!
//! # Reference
//! \[Yan2016\] §5 (the closed form of footprint × element).

use super::{PositionNormalMap, SIGMA_H_PER_SPACING};
use crate::glint::Footprint;

/// Per-footprint constants, positions in element units (element i has its centre at i + ½).
#[derive(Clone, Copy, Debug)]
pub(super) struct Geometry {
    /// Footprint centre.
    pub c: [f64; 2],
    /// Σ_eff⁻¹ = (Σ_P + σ_h² I)⁻¹ as (xx, xy, yy).
    pub inv_eff: [f64; 3],
    /// K = h σ_h² Σ_eff⁻¹: maps c − u_i (element units) to μ_u − u_i in texels.
    pub k: [f64; 3],
    /// Σ_u in texels²: h² (σ_h² I − σ_h⁴ Σ_eff⁻¹).
    pub sigma_u: [f64; 3],
    /// σ_r².
    pub var_r: f64,
    /// k_w².
    pub kw2: f64,
    /// Half-widths of the rectangle of candidate elements, k_w √Σ_eff,kk.
    pub half: [f64; 2],
    /// Footprint σ after the query cap over σ before, along the major axis (1 if the cap did not bite).
    pub query_scale: f64,
}

/// Symmetric 2 × 2 eigen decomposition: eigenvalues (λ1 ≥ λ2) and the unit eigenvector of λ1.
fn eigen(c: [f64; 3]) -> ([f64; 2], [f64; 2]) {
    let [a, b, d] = c;
    let half_tr = 0.5 * (a + d);
    let r = (0.25 * (a - d) * (a - d) + b * b).sqrt();
    let (l1, l2) = (half_tr + r, half_tr - r);
    let e = if b.abs() > 1e-300 {
        let (x, y) = (l1 - d, b);
        let n = (x * x + y * y).sqrt();
        [x / n, y / n]
    } else if a >= d {
        [1.0, 0.0]
    } else {
        [0.0, 1.0]
    };
    ([l1, l2], e)
}

/// The covariance with eigenvalues clamped to at most `max_var` (same eigenvectors).
fn clamp_covariance(c: [f64; 3], max_var: f64) -> [f64; 3] {
    let ([l1, l2], e) = eigen(c);
    if l1 <= max_var {
        return c;
    }
    let (l1, l2) = (l1.min(max_var), l2.clamp(0.0, max_var));
    let f = [-e[1], e[0]];
    [
        l1 * e[0] * e[0] + l2 * f[0] * f[0],
        l1 * e[0] * e[1] + l2 * f[0] * f[1],
        l1 * e[1] * e[1] + l2 * f[1] * f[1],
    ]
}

impl Geometry {
    /// `max_query_texels` not > 0 (NaN included) acts as 0: the footprint shrinks to its centre.
    pub fn new(map: &PositionNormalMap, footprint: &Footprint, max_query_texels: f32) -> Geometry {
        let p = &map.params;
        let (c, s) = footprint.gaussian_texels(map.width, map.height);
        let cov = [s.x_axis.x as f64, s.y_axis.x as f64, s.y_axis.y as f64];
        let kw = p.weight_sigmas as f64;
        let cap = if max_query_texels > 0.0 {
            max_query_texels as f64 / kw
        } else {
            0.0
        };
        let major = eigen(cov).0[0];
        let cov = clamp_covariance(cov, cap * cap);
        let query_scale = if major > 0.0 {
            (eigen(cov).0[0] / major).sqrt().min(1.0)
        } else {
            1.0
        };
        let h = map.spacing;
        let (h2, sh) = (h * h, SIGMA_H_PER_SPACING);
        let sh2 = sh * sh;
        let (a, b, d) = (cov[0] / h2 + sh2, cov[1] / h2, cov[2] / h2 + sh2);
        let det = a * d - b * b;
        // det ≥ σ_h⁴ > 0: Σ_P is positive semi-definite and σ_h² I is added.
        let inv = [d / det, -b / det, a / det];
        Geometry {
            c: [c.x as f64 / h, c.y as f64 / h],
            inv_eff: inv,
            k: [h * sh2 * inv[0], h * sh2 * inv[1], h * sh2 * inv[2]],
            sigma_u: [
                h2 * (sh2 - sh2 * sh2 * inv[0]).max(0.0),
                -h2 * sh2 * sh2 * inv[1],
                h2 * (sh2 - sh2 * sh2 * inv[2]).max(0.0),
            ],
            var_r: (p.sigma_r as f64).powi(2),
            kw2: kw * kw,
            half: [kw * a.sqrt(), kw * d.sqrt()],
            query_scale,
        }
    }

    /// The unwrapped element index range [lo, hi] of one axis.
    pub fn range(&self, axis: usize) -> [i64; 2] {
        let (c, half) = (self.c[axis], self.half[axis]);
        let lo = (c - 0.5 - half).ceil();
        let hi = (c - 0.5 + half).floor();
        if hi >= lo {
            [lo as i64, hi as i64]
        } else {
            let n = (c - 0.5).round() as i64;
            [n, n]
        }
    }

    /// The position weight of unwrapped element (i, j): exp(−½ dᵀ Σ_eff⁻¹ d), d = c − u_i, or
    /// `None` outside the truncation ellipse. Also returns d.
    #[inline]
    pub fn weight(&self, i: i64, j: i64) -> Option<(f64, [f64; 2])> {
        let d = [self.c[0] - (i as f64 + 0.5), self.c[1] - (j as f64 + 0.5)];
        let q = self.inv_eff[0] * d[0] * d[0]
            + 2.0 * self.inv_eff[1] * d[0] * d[1]
            + self.inv_eff[2] * d[1] * d[1];
        (q <= self.kw2).then(|| ((-0.5 * q).exp(), d))
    }

    /// The element's slope Gaussian under the footprint: mean ñ_i + J K d and covariance
    /// J Σ_u Jᵀ + σ_r² I (as (xx, xy, yy)).
    #[inline]
    pub fn lobe(&self, e: &[f32; 6], d: [f64; 2]) -> ([f64; 2], [f64; 3]) {
        let [sx, sy, jxu, jxv, jyu, jyv] = e.map(f64::from);
        let du = [
            self.k[0] * d[0] + self.k[1] * d[1],
            self.k[1] * d[0] + self.k[2] * d[1],
        ];
        let mean = [
            sx + jxu * du[0] + jxv * du[1],
            sy + jyu * du[0] + jyv * du[1],
        ];
        let [u0, u1, u2] = self.sigma_u;
        // Rows of J Σ_u.
        let (ax, ay) = (jxu * u0 + jxv * u1, jxu * u1 + jxv * u2);
        let (bx, by) = (jyu * u0 + jyv * u1, jyu * u1 + jyv * u2);
        let cov = [
            ax * jxu + ay * jxv + self.var_r,
            ax * jyu + ay * jyv,
            bx * jyu + by * jyv + self.var_r,
        ];
        (mean, cov)
    }
}

/// Segments of one axis: wrapped index ranges [lo, hi] (inclusive) with the offset that unwraps them.
pub(super) fn segments(range: [i64; 2], n: usize) -> impl Iterator<Item = (usize, usize, i64)> {
    let n = n as i64;
    let [lo, hi] = range;
    (lo.div_euclid(n)..=hi.div_euclid(n)).map(move |k| {
        let a = (lo - k * n).max(0);
        let b = (hi - k * n).min(n - 1);
        (a as usize, b as usize, k * n)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_cover_the_range_once() {
        for &(lo, hi, n) in &[
            (-3i64, 4i64, 4usize),
            (0, 3, 4),
            (5, 5, 4),
            (-9, 9, 3),
            (2, 2, 1),
        ] {
            let mut seen = Vec::new();
            for (a, b, off) in segments([lo, hi], n) {
                assert!(a <= b && b < n);
                for w in a..=b {
                    seen.push(w as i64 + off);
                }
            }
            assert_eq!(seen, (lo..=hi).collect::<Vec<_>>(), "{lo} {hi} {n}");
        }
    }

    #[test]
    fn clamp_keeps_small_and_shrinks_large() {
        let c = [4.0, 1.0, 2.0];
        assert_eq!(clamp_covariance(c, 10.0), c);
        let ([l1, l2], _) = eigen(clamp_covariance([100.0, 0.0, 1.0], 9.0));
        assert!((l1 - 9.0).abs() < 1e-12 && (l2 - 1.0).abs() < 1e-12);
    }
}
