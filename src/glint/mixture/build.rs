//! Per-lobe slope moments of the interpolated normal map under the seed kernels k_i (the cell or
//! the Gaussian, [`SeedKernel`]), integrated by quasi-Monte Carlo (\[Chermain2019\] eq. 5-6).
//!
//! Every lobe sees the same kernel shape, so the quadrature nodes are computed once: an R2
//! low-discrepancy point set (Roberts 2018, the additive recurrence with the plastic number) in
//! [0, 1)², mapped linearly onto the cell or through the inverse cdf of a Gaussian truncated at ±T σ
//! per axis. Each node then has weight 1/N, and E_i[f] ≈ (1/N) Σ_k f(ñ(u_i + d_k)), accumulated in
//! `f64`.

use super::params::kernel_sigma;
use super::{MixtureParams, SeedKernel};
use crate::glint::NormalMap;
use crate::glint::kernels::filtered_error::r2;
use crate::ndf::gauss;
use glam::Vec2;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The N quadrature offsets (texel units) of a Gaussian kernel of per-axis standard deviations
/// `sigma`, truncated at ±`t` σ per axis.
pub(super) fn qmc_offsets(n: usize, sigma: [f64; 2], t: f64) -> Vec<Vec2> {
    let p_lo = gauss::std_cdf(-t);
    let span = 1.0 - 2.0 * p_lo;
    (0..n)
        .map(|k| {
            let r = r2(k);
            let z = r.map(|ri| gauss::inv_std_cdf(p_lo + ri * span));
            Vec2::new((z[0] * sigma[0]) as f32, (z[1] * sigma[1]) as f32)
        })
        .collect()
}

/// The N quadrature offsets (texel units) of the uniform density over a cell of `spacing` texels
/// per axis: the R2 points of [`qmc_offsets`], mapped linearly onto [−h/2, h/2).
pub(super) fn cell_offsets(n: usize, spacing: [f64; 2]) -> Vec<Vec2> {
    (0..n)
        .map(|k| {
            let r = r2(k).map(|v| v - 0.5);
            Vec2::new((r[0] * spacing[0]) as f32, (r[1] * spacing[1]) as f32)
        })
        .collect()
}

/// The five moments [E[x̃], E[ỹ], E[x̃²], E[ỹ²], E[x̃ỹ]] of the interpolated map's slopes around
/// `centre` (texel units) for the given offsets.
pub(super) fn lobe_moments(map: &NormalMap, centre: Vec2, offsets: &[Vec2]) -> [f32; 5] {
    let mut acc = [0.0f64; 5];
    for d in offsets {
        let s = map.slope_at_texel(centre + *d);
        let (x, y) = (s.x as f64, s.y as f64);
        acc[0] += x;
        acc[1] += y;
        acc[2] += x * x;
        acc[3] += y * y;
        acc[4] += x * y;
    }
    let inv = 1.0 / offsets.len().max(1) as f64;
    acc.map(|v| (v * inv) as f32)
}

/// All lobes' moments, row major over the `nx × ny` lobe grid, parallel over rows (deterministic:
/// every lobe is computed independently with the same nodes). `progress` gets the fraction of rows
/// done (calls may come from several threads, values are non-decreasing per thread).
pub(super) fn all_moments(
    map: &NormalMap,
    params: &MixtureParams,
    grid: [usize; 2],
    spacing: [f64; 2],
    progress: Option<&(dyn Fn(f32) + Sync)>,
) -> Vec<[f32; 5]> {
    let [nx, ny] = grid;
    let offsets = match params.seed {
        SeedKernel::Gaussian => qmc_offsets(
            params.samples,
            spacing.map(kernel_sigma),
            params.kernel_sigmas as f64,
        ),
        SeedKernel::Cell | SeedKernel::Auto => cell_offsets(params.samples, spacing),
    };
    let o = params.seed.origin();
    let done = AtomicUsize::new(0);
    let mut out = vec![[0.0f32; 5]; nx * ny];
    out.par_chunks_mut(nx).enumerate().for_each(|(j, row)| {
        let y = ((j as f64 + 0.5) * spacing[1] + o) as f32;
        for (i, m) in row.iter_mut().enumerate() {
            let x = ((i as f64 + 0.5) * spacing[0] + o) as f32;
            *m = lobe_moments(map, Vec2::new(x, y), &offsets);
        }
        if let Some(p) = progress {
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            p(d as f32 / ny as f32);
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernel_sigma_halves_the_peak_at_the_midpoint() {
        let s = kernel_sigma(1.0);
        // exp(−(½)²/(2σ²)) = ½ by definition; f64 rounding only.
        assert!(((-0.25 / (2.0 * s * s)).exp() - 0.5).abs() < 1e-15);
    }

    #[test]
    fn cell_offsets_have_the_cells_moments() {
        // Uniform on [−h/2, h/2): mean 0, variance h²/12; R2 points are equidistributed, so 4096
        // of them reproduce both to ~1/N (bound 1e-3, relative for the variance).
        let h = [1.0, 0.5];
        let o = cell_offsets(4096, h);
        let n = o.len() as f64;
        for (axis, &hk) in h.iter().enumerate() {
            let v: Vec<f64> = o.iter().map(|d| d[axis] as f64).collect();
            let m = v.iter().sum::<f64>() / n;
            let var = v.iter().map(|x| x * x).sum::<f64>() / n - m * m;
            assert!(m.abs() < 1e-3 * hk, "axis {axis}: mean {m}");
            assert!(
                (var / (hk * hk / 12.0) - 1.0).abs() < 1e-3,
                "axis {axis}: var {var}"
            );
            assert!(
                v.iter().all(|x| x.abs() <= 0.5 * hk),
                "axis {axis}: outside the cell"
            );
        }
    }

    #[test]
    fn offsets_have_the_truncated_gaussian_moments() {
        // Variance of a standard normal truncated at ±3: 1 − 2·3 φ(3)/(1 − 2Φ(−3)) = 0.97333.
        let t = 3.0;
        let expected = 1.0 - 2.0 * t * gauss::std_pdf(t) / (1.0 - 2.0 * gauss::std_cdf(-t));
        let o = qmc_offsets(4096, [1.0, 2.0], t);
        let n = o.len() as f64;
        let mx: f64 = o.iter().map(|d| d.x as f64).sum::<f64>() / n;
        let vx: f64 = o.iter().map(|d| (d.x as f64).powi(2)).sum::<f64>() / n;
        let vy: f64 = o.iter().map(|d| (d.y as f64).powi(2)).sum::<f64>() / n / 4.0;
        // R2 + smooth inverse cdf: QMC error ~ (log N)²/N ≈ 2e-3 at N = 4096 for this integrand.
        assert!(mx.abs() < 2e-3, "{mx}");
        assert!((vx - expected).abs() < 5e-3, "{vx} vs {expected}");
        assert!((vy - expected).abs() < 5e-3, "{vy} vs {expected}");
        assert!(
            o.iter()
                .all(|d| d.x.abs() <= 3.0 + 1e-5 && d.y.abs() <= 6.0 + 1e-5)
        );
    }
}
