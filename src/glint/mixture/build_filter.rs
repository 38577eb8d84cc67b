//! Per-lobe slope moments (\[Chermain2019\] eq. 5-6) by a separable filter of a supersampled
//! interpolated map: the fast default of the build ([`super::MomentMethod::Filter`]).
//!
//! The moment integral of lobe i is E_i[f] = ∫∫ f(ñ(x, y)) k_x(x) k_y(y) dx dy / Z, with k the
//! seed kernel (a Gaussian of σ = 0.4247 h per axis, truncated at ±T σ, as in the QMC build), ñ the
//! interpolated map's slope and f one of x̃, ỹ, x̃², ỹ², x̃ỹ. Positions are in texels, the lobe
//! centres at (i + ½) h. The integrand is sampled on a node grid of step 1/S texel (S a multiple of
//! 4, so that the texel centres, where the bilinear interpolation has its kinks, are even nodes) and
//! integrated by a product Simpson rule whose weights are the exact integrals of the quadratic
//! Lagrange basis against the truncated Gaussian (differences of Φ and φ). The weights factor per
//! axis, so the 2D sum is a horizontal pass (node row → per-lobe-column sums) followed by a vertical
//! pass (node rows → lobe rows). Error: O(S⁻⁴) times the fourth derivative of f inside a texel (f is
//! smooth there), and none for f quadratic in each axis between texel centres (tested on an
//! analytic map); measured against a converged QMC reference in docs/results.md ("Fast build").
//!
//! Work is done in bands of lobe rows, in parallel (rayon); a band keeps only the horizontal sums of
//! the node rows one lobe row needs (a ring of ~12 rows × lobe columns × 40 bytes, 1 MB at 2048 lobe
//! columns) and two texel rows of normals, so memory beyond the output is ~1 MB per thread. The
//! result does not depend on the thread count (every node row and every lobe's sums are computed
//! the same way in a fixed order whichever band holds them).

use super::SeedKernel;
use crate::glint::NormalMap;
use crate::ndf::gauss;
use glam::Vec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Nodes per texel along an axis of lobe spacing `h` texels: the multiple of 4 ≥ `supersampling` / min(1, h),
/// so that the node step never exceeds h / `supersampling` (the kernel's σ is 0.42 h) nor
/// 1 / `supersampling` texel (the map's own scale).
pub(super) fn nodes_per_texel(supersampling: u32, h: f64) -> usize {
    let s = (supersampling.max(1) as f64 / h.min(1.0)).ceil() as usize;
    s.div_ceil(4) * 4
}

/// The quadrature of one axis: for each lobe along it, the first node (unwrapped index; node a sits
/// at a / S texels) and `len` normalised weights (zero-padded).
struct AxisWeights {
    /// Nodes per texel S (even).
    s: usize,
    /// First node of each lobe.
    start: Vec<i64>,
    /// Weights, `len` per lobe.
    w: Vec<f64>,
    len: usize,
}

/// The moments [∫ N, ∫ v N, ∫ v² N] of N(v; 0, σ²) over [l, r] (v relative to the kernel centre).
fn gauss_moments(l: f64, r: f64, sigma: f64) -> [f64; 3] {
    if r <= l {
        return [0.0; 3];
    }
    let (zl, zr) = (l / sigma, r / sigma);
    let (pl, pr) = (gauss::std_pdf(zl), gauss::std_pdf(zr));
    let m0 = gauss::std_cdf(zr) - gauss::std_cdf(zl);
    // ∫ z φ = −φ, ∫ z² φ = Φ − z φ.
    [
        m0,
        -sigma * (pr - pl),
        sigma * sigma * (m0 - (zr * pr - zl * pl)),
    ]
}

/// The moments [∫ 1, ∫ v, ∫ v²] over [l, r] (unnormalised: the weights are normalised per lobe).
fn uniform_moments(l: f64, r: f64) -> [f64; 3] {
    if r <= l {
        return [0.0; 3];
    }
    [r - l, 0.5 * (r * r - l * l), (r * r * r - l * l * l) / 3.0]
}

impl AxisWeights {
    /// Weights of `n` lobes at centres (i + ½)·`spacing` + the seed's origin, `s` nodes per texel
    /// (a multiple of 4): under [`SeedKernel::Gaussian`] a Gaussian of σ `sigma` truncated at ±`t` σ,
    /// under [`SeedKernel::Cell`] the uniform density over the cell of width `spacing`.
    ///
    /// Product Simpson rule with exact kernel weights: the nodes are grouped in pairs of steps
    /// [x₂ₘ, x₂ₘ₊₂] (texel centres, at nodes S k + S/2, are even nodes, so no pair straddles a kink
    /// of the bilinear interpolation; the cells' edges, texel centres at integer 1/h, are even nodes
    /// too), f is replaced on each pair by its quadratic interpolant, and each Lagrange basis
    /// polynomial is integrated exactly against the kernel.
    fn new(n: usize, spacing: f64, seed: SeedKernel, sigma: f64, t: f64, s: usize) -> AxisWeights {
        let step = 1.0 / s as f64;
        let half = match seed {
            SeedKernel::Cell | SeedKernel::Auto => 0.5 * spacing,
            SeedKernel::Gaussian => t * sigma,
        };
        // First and last node (both even) of the pairs that meet the support [c − half, c + half].
        let first = |c: f64| 2 * ((c - half) * s as f64 / 2.0).floor() as i64;
        let last = |c: f64| 2 * ((c + half) * s as f64 / 2.0).ceil() as i64;
        let centre = |i: usize| (i as f64 + 0.5) * spacing + seed.origin();
        let len = (0..n)
            .map(|i| (last(centre(i)) - first(centre(i)) + 1) as usize)
            .max()
            .unwrap_or(1);
        let mut start = Vec::with_capacity(n);
        let mut w = vec![0.0f64; n * len];
        for (i, wi) in w.chunks_mut(len).enumerate() {
            let c = centre(i);
            let a0 = first(c);
            start.push(a0);
            let pairs = ((last(c) - a0) / 2) as usize;
            for m in 0..pairs {
                // Pair nodes relative to the centre: v0, v1 = v0 + step, v2 = v0 + 2 step.
                let v0 = (a0 + 2 * m as i64) as f64 * step - c;
                let (v1, v2) = (v0 + step, v0 + 2.0 * step);
                let (l, r) = (v0.max(-half), v2.min(half));
                let [m0, m1, m2] = match seed {
                    SeedKernel::Cell | SeedKernel::Auto => uniform_moments(l, r),
                    SeedKernel::Gaussian => gauss_moments(l, r, sigma),
                };
                // ∫ (v − p)(v − q) N = m2 − (p + q) m1 + p q m0.
                let quad = |p: f64, q: f64| m2 - (p + q) * m1 + p * q * m0;
                let h2 = step * step;
                wi[2 * m] += quad(v1, v2) / (2.0 * h2);
                wi[2 * m + 1] -= quad(v0, v2) / h2;
                wi[2 * m + 2] += quad(v0, v1) / (2.0 * h2);
            }
            // The basis polynomials sum to 1, so the sum is the kernel's mass (1 − 2Φ(−t) for the
            // truncated Gaussian, the cell's width) up to rounding; dividing by it gives the
            // (truncated) kernel's moments.
            let z: f64 = wi.iter().sum();
            if z > 0.0 {
                wi.iter_mut().for_each(|v| *v /= z);
            }
        }
        AxisWeights { s, start, w, len }
    }

    fn weights(&self, i: usize) -> &[f64] {
        &self.w[i * self.len..(i + 1) * self.len]
    }

    /// The texel (unwrapped) left of node a and the node's fraction towards the next texel:
    /// node a is at a / S, texel centres at k + ½, so a − S/2 = S k + r gives (k, r / S).
    fn texel_of(&self, a: i64) -> (i64, f64) {
        let s = self.s as i64;
        let q = a - s / 2;
        (q.div_euclid(s), q.rem_euclid(s) as f64 / self.s as f64)
    }
}

/// All lobes' moments, row major over the `nx × ny` lobe grid, by the separable filter (see the
/// module doc): the `seed` kernel (the cell, or a Gaussian of σ = 0.4247 × spacing per axis
/// truncated at ±`t` σ), `supersampling` as in [`nodes_per_texel`]. `progress` gets the fraction
/// of lobe rows done.
pub(super) fn all_moments(
    map: &NormalMap,
    grid: [usize; 2],
    spacing: [f64; 2],
    seed: SeedKernel,
    t: f64,
    supersampling: u32,
    progress: Option<&(dyn Fn(f32) + Sync)>,
) -> Vec<[f32; 5]> {
    let [nx, ny] = grid;
    let sigma = spacing.map(super::params::kernel_sigma);
    let ax = AxisWeights::new(
        nx,
        spacing[0],
        seed,
        sigma[0],
        t,
        nodes_per_texel(supersampling, spacing[0]),
    );
    let ay = AxisWeights::new(
        ny,
        spacing[1],
        seed,
        sigma[1],
        t,
        nodes_per_texel(supersampling, spacing[1]),
    );
    // 4 bands per thread, for load balance; a band re-filters only the kernel's overlap with the
    // previous band (ay.len node rows), so larger bands waste less.
    let band = ny.div_ceil(4 * rayon::current_num_threads()).clamp(1, ny);
    let done = AtomicUsize::new(0);
    let mut out = vec![[0.0f32; 5]; nx * ny];
    out.par_chunks_mut(nx * band)
        .enumerate()
        .for_each(|(k, rows)| {
            let j0 = k * band;
            let rows_here = rows.len() / nx;
            band_moments(map, &ax, &ay, j0..j0 + rows_here, rows);
            if let Some(p) = progress {
                let d = done.fetch_add(rows_here, Ordering::Relaxed) + rows_here;
                p(d as f32 / ny as f32);
            }
        });
    out
}

/// The moments of lobe rows `lobe_rows` into `out` (row major, nx per row).
///
/// Node rows are filtered horizontally in increasing order into a ring of `ay.len` rows (the most
/// a lobe row needs; lobe rows need non-decreasing node rows, so a row is overwritten only once no
/// later lobe row needs it), and the two texel rows of normals they interpolate are kept as a pair.
/// Memory: ay.len × nx × 40 bytes plus a few rows of the map.
fn band_moments(
    map: &NormalMap,
    ax: &AxisWeights,
    ay: &AxisWeights,
    lobe_rows: std::ops::Range<usize>,
    out: &mut [[f32; 5]],
) {
    let nx = ax.start.len();
    let width = map.width();
    let a_lo = ax.start[0];
    let a_hi = ax.start[nx - 1] + ax.len as i64 - 1;
    let n_cols = (a_hi - a_lo + 1) as usize;
    // Node columns: left texel (wrapped) and fraction.
    let cols: Vec<(usize, usize, f32)> = (a_lo..=a_hi)
        .map(|a| {
            let (i, f) = ax.texel_of(a);
            let i0 = i.rem_euclid(width as i64) as usize;
            let i1 = if i0 + 1 == width { 0 } else { i0 + 1 };
            (i0, i1, f as f32)
        })
        .collect();
    let texel_row = |j: i64, row: &mut Vec<Vec3>| {
        row.clear();
        row.extend((0..width as i64).map(|i| map.texel_normal(i, j)));
    };
    let ring_len = ay.len;
    let mut ring = vec![[0.0f64; 5]; ring_len * nx];
    let (mut lower, mut upper) = (Vec::with_capacity(width), Vec::with_capacity(width));
    let mut pair_row = i64::MIN;
    let mut blend = vec![Vec3::ZERO; width];
    let mut sx = vec![0.0f64; n_cols];
    let mut sy = vec![0.0f64; n_cols];
    // Next node row to filter.
    let mut next = ay.start[lobe_rows.start];
    let mut acc = vec![[0.0f64; 5]; nx];
    for (j, row) in lobe_rows.zip(out.chunks_mut(nx)) {
        let first = ay.start[j];
        let end = first + ay.len as i64;
        // Horizontal pass for the node rows this lobe row adds.
        while next < end {
            let (t, fy) = ay.texel_of(next);
            if t != pair_row {
                if t == pair_row + 1 {
                    std::mem::swap(&mut lower, &mut upper);
                } else {
                    texel_row(t, &mut lower);
                }
                texel_row(t + 1, &mut upper);
                pair_row = t;
            }
            let fy = fy as f32;
            for ((m, &n0), &n1) in blend.iter_mut().zip(&lower).zip(&upper) {
                *m = n0 * (1.0 - fy) + n1 * fy;
            }
            for ((&(i0, i1, fx), x), y) in cols.iter().zip(&mut sx).zip(&mut sy) {
                let n = blend[i0] * (1.0 - fx) + blend[i1] * fx;
                // n.z > 0: a convex combination of upper-hemisphere unit normals.
                (*x, *y) = ((-n.x / n.z) as f64, (-n.y / n.z) as f64);
            }
            let slot = next.rem_euclid(ring_len as i64) as usize;
            for (i, h) in ring[slot * nx..][..nx].iter_mut().enumerate() {
                let o = (ax.start[i] - a_lo) as usize;
                let mut m = [0.0f64; 5];
                for ((&w, &x), &y) in ax.weights(i).iter().zip(&sx[o..]).zip(&sy[o..]) {
                    let (wx, wy) = (w * x, w * y);
                    m[0] += wx;
                    m[1] += wy;
                    m[2] += wx * x;
                    m[3] += wy * y;
                    m[4] += wx * y;
                }
                *h = m;
            }
            next += 1;
        }
        // Vertical pass: this lobe row from its node rows.
        acc.iter_mut().for_each(|a| *a = [0.0; 5]);
        for (k, &w) in ay.weights(j).iter().enumerate() {
            let slot = (first + k as i64).rem_euclid(ring_len as i64) as usize;
            for (a, hv) in acc.iter_mut().zip(&ring[slot * nx..][..nx]) {
                for c in 0..5 {
                    a[c] += w * hv[c];
                }
            }
        }
        for (m, a) in row.iter_mut().zip(&acc) {
            *m = project(a).map(|v| v as f32);
        }
    }
}

/// The moments with E[x̃²] ≥ E[x̃]² and E[ỹ²] ≥ E[ỹ]². Simpson weights of pairs cut by the kernel's
/// truncation can be slightly negative (< 1 % of the largest), so a lobe over an almost constant
/// region could get a variance of −1e-9 or so; every true second moment is at least the squared
/// mean, and the rest of the crate (the store's range check, the σ floor) relies on it.
fn project(m: &[f64; 5]) -> [f64; 5] {
    [
        m[0],
        m[1],
        m[2].max(m[0] * m[0]),
        m[3].max(m[1] * m[1]),
        m[4],
    ]
}

#[cfg(test)]
mod tests {
    use super::super::params::DEFAULT_SUPERSAMPLING;
    use super::*;

    #[test]
    fn node_counts_are_multiples_of_4_and_scale_with_fine_spacing() {
        assert_eq!(nodes_per_texel(4, 1.0), 4);
        assert_eq!(nodes_per_texel(4, 3.0), 4);
        assert_eq!(nodes_per_texel(2, 1.0), 4);
        assert_eq!(nodes_per_texel(6, 1.0), 8);
        assert_eq!(nodes_per_texel(4, 0.5), 8);
        assert_eq!(nodes_per_texel(4, 0.3), 16);
        assert_eq!(nodes_per_texel(4, 0.125), 32);
    }

    #[test]
    fn axis_weights_integrate_quadratics_exactly() {
        // Simpson with exact kernel weights reproduces quadratics, so Σ w = 1, Σ w x = c (the
        // truncated kernel is symmetric) and Σ w (x − c)² = the truncated variance
        // σ² (1 − 2 t φ(t) / (1 − 2 Φ(−t))); all to f64 rounding (~1e-15 per term, ≤ 40 terms,
        // centres up to 10 texels).
        for (h, t) in [(1.0, 3.0), (1.3, 3.0), (0.5, 2.0), (4.0, 5.0)] {
            let sigma = super::super::params::kernel_sigma(h);
            let s = nodes_per_texel(4, h);
            let a = AxisWeights::new(7, h, SeedKernel::Gaussian, sigma, t, s);
            let var = sigma
                * sigma
                * (1.0 - 2.0 * t * gauss::std_pdf(t) / (1.0 - 2.0 * gauss::std_cdf(-t)));
            for i in 0..7 {
                let c = (i as f64 + 0.5) * h;
                let w = a.weights(i);
                let x = |k: usize| (a.start[i] + k as i64) as f64 / s as f64;
                let sum: f64 = w.iter().sum();
                let mean: f64 = w.iter().enumerate().map(|(k, &v)| v * x(k)).sum();
                let m2: f64 = w
                    .iter()
                    .enumerate()
                    .map(|(k, &v)| v * (x(k) - c).powi(2))
                    .sum();
                assert!((sum - 1.0).abs() < 1e-13, "{sum}");
                assert!((mean - c).abs() < 1e-12, "h {h} i {i}: {mean} vs {c}");
                assert!((m2 - var).abs() < 1e-12, "h {h} i {i}: {m2} vs {var}");
                assert_eq!(a.start[i] % 2, 0);
            }
        }
    }

    /// 1D moments [E[T], E[T²]] of the triangle wave T (value (−1)^k at texel centre k + ½, linear
    /// in between) under N(c, σ²) truncated to ±t σ, in closed form: on each linear piece
    /// T = α + β u, ∫ (α + β u)ⁿ N du from ∫ N = Φ, ∫ u N = c Φ − σ φ, ∫ u² N = (c² + σ²) Φ − σ (c + u) φ.
    fn triangle_moments(c: f64, sigma: f64, t: f64) -> [f64; 2] {
        let anti = |u: f64| {
            let z = (u - c) / sigma;
            let (cdf, pdf) = (gauss::std_cdf(z), gauss::std_pdf(z));
            [
                cdf,
                c * cdf - sigma * pdf,
                (c * c + sigma * sigma) * cdf - sigma * (c + u) * pdf,
            ]
        };
        triangle_moments_with(anti, c - t * sigma, c + t * sigma)
    }

    /// [E[T], E[T²]] of the triangle wave under the uniform density on [lo, hi] (a cell).
    fn triangle_moments_cell(lo: f64, hi: f64) -> [f64; 2] {
        triangle_moments_with(|u: f64| [u, 0.5 * u * u, u * u * u / 3.0], lo, hi)
    }

    /// [E[T], E[T²]] over [lo, hi] of a kernel whose antiderivatives of 1, u, u² are `anti`.
    fn triangle_moments_with(anti: impl Fn(f64) -> [f64; 3], lo: f64, hi: f64) -> [f64; 2] {
        let (mut e1, mut e2, mut z) = (0.0, 0.0, 0.0);
        let mut k = (lo - 0.5).floor() as i64;
        while (k as f64) + 0.5 < hi {
            let (l, r) = ((k as f64 + 0.5).max(lo), (k as f64 + 1.5).min(hi));
            let v0 = if k.rem_euclid(2) == 0 { 1.0 } else { -1.0 };
            // T = v0 − 2 v0 (u − k − ½) = α + β u.
            let beta = -2.0 * v0;
            let alpha = v0 - beta * (k as f64 + 0.5);
            let (a, b) = (anti(l), anti(r));
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            z += d[0];
            e1 += alpha * d[0] + beta * d[1];
            e2 += alpha * alpha * d[0] + 2.0 * alpha * beta * d[1] + beta * beta * d[2];
            k += 1;
        }
        [e1 / z, e2 / z]
    }

    #[test]
    fn analytic_map_moments_match_the_closed_form() {
        // Slopes (a (−1)^i, b (−1)^j): every texel normal has the same length, so the bilinear blend
        // of unit normals divided by its z is exactly (a T(x), b T(y)) with T the triangle wave, and
        // the moments factor: E[x̃] = a E[T(x)], E[x̃²] = a² E[T(x)²], E[x̃ỹ] = a b E[T(x)] E[T(y)].
        // T is piecewise linear with kinks at texel centres (even nodes), so the Simpson filter
        // integrates T and T² exactly: the tolerance is f32 rounding of the slopes and the stored
        // moments (relative 6e-8, here ≤ 4 · 6e-8 · a²-scale, bounded by 1e-6).
        let (n, a, b) = (12usize, 0.4f32, 0.25f32);
        let slopes = (0..n * n)
            .map(|k| {
                let (i, j) = (k % n, k / n);
                let sx = if i % 2 == 0 { a } else { -a };
                let sy = if j % 2 == 0 { b } else { -b };
                glam::Vec2::new(sx, sy)
            })
            .collect();
        let map = NormalMap::from_slopes(n, n, slopes).unwrap();
        let t = 3.0;
        // Lobe spacings 1 (the default), 1.5 (centres between nodes) and 0.5 (finer grid), both
        // seed kernels (the cell's edges are even nodes at these spacings, so it is exact too).
        for (seed, grid) in [SeedKernel::Gaussian, SeedKernel::Cell]
            .into_iter()
            .flat_map(|k| [[12usize, 12], [8, 8], [24, 12]].map(|g| (k, g)))
        {
            let spacing = grid.map(|g| n as f64 / g as f64);
            let sigma = spacing.map(super::super::params::kernel_sigma);
            let m = all_moments(&map, grid, spacing, seed, t, 4, None);
            let axis = |i: usize, h: f64, sigma: f64| {
                let c = (i as f64 + 0.5) * h + seed.origin();
                match seed {
                    SeedKernel::Gaussian => triangle_moments(c, sigma, t),
                    SeedKernel::Cell | SeedKernel::Auto => {
                        triangle_moments_cell(c - 0.5 * h, c + 0.5 * h)
                    }
                }
            };
            for j in 0..grid[1] {
                for i in 0..grid[0] {
                    let tx = axis(i, spacing[0], sigma[0]);
                    let ty = axis(j, spacing[1], sigma[1]);
                    let (a, b) = (a as f64, b as f64);
                    let want = [
                        a * tx[0],
                        b * ty[0],
                        a * a * tx[1],
                        b * b * ty[1],
                        a * b * tx[0] * ty[0],
                    ];
                    let got = m[j * grid[0] + i];
                    for c in 0..5 {
                        assert!(
                            (got[c] as f64 - want[c]).abs() < 1e-6,
                            "{seed:?} grid {grid:?} lobe ({i}, {j}) moment {c}: {} vs {}",
                            got[c],
                            want[c]
                        );
                    }
                }
            }
        }
    }

    /// Largest |Δσ| (either axis, in units of σ_ε = 0.01, σ floored at σ_ε as the lobes are) and
    /// largest |Δmean| of `test` against `reference` over the lobes `ks`.
    fn errors(test: &[[f32; 5]], reference: &[[f32; 5]], ks: &[usize]) -> (f64, f64) {
        use crate::ndf::SlopeGaussian;
        let (mut dm, mut ds) = (0.0f64, 0.0f64);
        for (&k, r) in ks.iter().zip(reference) {
            let (a, b) = (
                SlopeGaussian::from_moments(test[k], 0.01),
                SlopeGaussian::from_moments(*r, 0.01),
            );
            dm = dm.max((a.mean() - b.mean()).length() as f64);
            let (ca, cb) = (a.covariance(), b.covariance());
            let dx = (ca.x_axis.x.sqrt() - cb.x_axis.x.sqrt()).abs();
            let dy = (ca.y_axis.y.sqrt() - cb.y_axis.y.sqrt()).abs();
            ds = ds.max(dx.max(dy) as f64 / 0.01);
        }
        (dm, ds)
    }

    /// The four procedural maps of the crate's tables at n².
    fn maps(n: usize) -> Vec<(&'static str, NormalMap)> {
        use crate::glint::{BrushedParams, FlakesParams, ScratchedParams};
        use crate::glint::{brushed, bumpy, flakes, scratched};
        vec![
            ("bumpy", bumpy(n, n, 0.25, 4.0, 1).unwrap()),
            (
                "brushed",
                brushed(n, n, BrushedParams::default(), 2).unwrap(),
            ),
            (
                "scratched",
                scratched(n, n, ScratchedParams::default(), 3).unwrap(),
            ),
            ("flakes", flakes(n, n, FlakesParams::default(), 4).unwrap()),
        ]
    }

    /// Per map: the errors of QMC-256 then of the filter at each of `supersampling`, against
    /// 65 536-node QMC on every `stride`-th lobe of an n² map at spacing 1.
    fn accuracy(
        n: usize,
        stride: usize,
        supersampling: &[u32],
    ) -> Vec<(&'static str, Vec<(f64, f64)>)> {
        use super::super::build::{lobe_moments, qmc_offsets};
        use super::super::params::kernel_sigma;
        let t = 3.0;
        let sigma = kernel_sigma(1.0);
        let fine = qmc_offsets(65536, [sigma; 2], t);
        let coarse = qmc_offsets(256, [sigma; 2], t);
        let ks: Vec<usize> = (0..n * n).step_by(stride).collect();
        let centre = |k: usize| glam::Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
        maps(n)
            .into_iter()
            .map(|(name, map)| {
                let reference: Vec<[f32; 5]> = ks
                    .par_iter()
                    .map(|&k| lobe_moments(&map, centre(k), &fine))
                    .collect();
                let qmc: Vec<[f32; 5]> = (0..n * n)
                    .map(|k| lobe_moments(&map, centre(k), &coarse))
                    .collect();
                let mut e = vec![errors(&qmc, &reference, &ks)];
                for &s in supersampling {
                    let filt =
                        all_moments(&map, [n, n], [1.0; 2], SeedKernel::Gaussian, t, s, None);
                    e.push(errors(&filt, &reference, &ks));
                }
                (name, e)
            })
            .collect()
    }

    #[test]
    fn filter_is_at_least_as_accurate_as_256_node_qmc() {
        // Reference: 65 536 R2 nodes per lobe, whose own error is ≤ 1/256 of the 256-node error
        // if QMC converges as (log N)²/N and ≤ 1/16 of it even at the Monte Carlo rate 1/√N; the
        // filter at supersampling 16 (an independent quadrature) agrees with it to < 0.05 σ_ε,
        // which bounds the reference's error from the other side. 1 lobe in 7 of 48² maps.
        for (name, e) in accuracy(48, 7, &[DEFAULT_SUPERSAMPLING, 16]) {
            let (qmc, filt, fine) = (e[0], e[1], e[2]);
            eprintln!(
                "{name}: max |Δmean|, |Δσ|/σ_ε: QMC 256 {:.2e} {:.3}; filter ×4 {:.2e} {:.3}; ×16 {:.2e} {:.3}",
                qmc.0, qmc.1, filt.0, filt.1, fine.0, fine.1
            );
            assert!(
                filt.1 <= qmc.1,
                "{name}: filter σ error {} > QMC's {}",
                filt.1,
                qmc.1
            );
            assert!(
                filt.0 <= qmc.0,
                "{name}: filter mean error {} > QMC's {}",
                filt.0,
                qmc.0
            );
            assert!(fine.1 < 0.05, "{name}: {}", fine.1);
        }
    }

    /// The table of docs/results.md ("Fast build"): every lobe of 64² maps.
    /// `cargo test --lib -- --ignored moment_accuracy_table --nocapture`
    #[test]
    #[ignore]
    fn moment_accuracy_table() {
        println!("| map | method | max |Δmean| | max |Δσ| / σ_ε |");
        println!("|---|---|---|---|");
        let ss = [4u32, 8, 16];
        for (name, e) in accuracy(64, 1, &ss) {
            println!("| {name} | QMC 256 | {:.2e} | {:.3} |", e[0].0, e[0].1);
            for (s, f) in ss.iter().zip(&e[1..]) {
                println!("| {name} | filter ×{s} | {:.2e} | {:.3} |", f.0, f.1);
            }
        }
    }

    /// Whole builds (moments, boxes, hierarchy, mip chain) with the filter and with 256-node QMC,
    /// alternated (QMC, filter, per round; BRDF_ROUNDS rounds, default 1) on the four procedural maps
    /// at 2048², with their ratio.
    /// `cargo test --lib -- --ignored build_timing_2048 --nocapture` (the test profile is opt-level 3).
    #[test]
    #[ignore]
    fn build_timing_2048() {
        use super::super::{BeckmannMixture, MixtureParams, MomentMethod};
        use std::time::Instant;
        let time = |map: &NormalMap, moments| {
            let p = MixtureParams {
                moments,
                ..MixtureParams::default()
            };
            let t = Instant::now();
            let m = BeckmannMixture::build(map, p).unwrap();
            std::hint::black_box(m.moments()[0]);
            t.elapsed().as_secs_f64()
        };
        println!("| map | QMC 256 (s) | filter ×4 (s) | ratio |");
        println!("|---|---|---|---|");
        for (name, map) in maps(2048) {
            let (mut q, mut f) = (0.0, 0.0);
            for _ in 0..2 {
                q += time(&map, MomentMethod::Qmc);
                f += time(&map, MomentMethod::default());
            }
            println!(
                "| {name} | {:.2} | {:.2} | {:.1} |",
                q / 2.0,
                f / 2.0,
                q / f
            );
        }
    }

    /// Peak resident memory (VmHWM) of one process that makes the bumpy 2048² map and builds it with
    /// the method named by the environment variable BRDF_BUILD_METHOD ("filter" or "qmc"): run once
    /// per method, as separate processes, e.g.
    /// `BRDF_BUILD_METHOD=qmc cargo test --lib -- --ignored build_peak_memory_2048 --nocapture`.
    #[test]
    #[ignore]
    fn build_peak_memory_2048() {
        use super::super::{BeckmannMixture, MixtureParams, MomentMethod};
        let method = std::env::var("BRDF_BUILD_METHOD").unwrap_or_else(|_| "filter".into());
        let moments = match method.as_str() {
            "qmc" => MomentMethod::Qmc,
            _ => MomentMethod::default(),
        };
        let map = crate::glint::bumpy(2048, 2048, 0.25, 4.0, 1).unwrap();
        let p = MixtureParams {
            moments,
            ..MixtureParams::default()
        };
        let m = BeckmannMixture::build(&map, p).unwrap();
        std::hint::black_box(m.moments()[0]);
        let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
        let hwm = status
            .lines()
            .find(|l| l.starts_with("VmHWM"))
            .unwrap_or("VmHWM: ?");
        println!("{method}: {hwm}");
    }
}
