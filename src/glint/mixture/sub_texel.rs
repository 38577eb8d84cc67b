//! The sub-texel limit of a mixture patch: one slope Gaussian for footprints smaller than the seed
//! kernels, where the mixture's lobes are too wide.
//!
//! **Why.** Each level-0 lobe G_i is the moment match of the map's slopes under its seed kernel k_i
//! ([`SeedKernel`](super::SeedKernel): the cell, of per-axis variance σ_k² = 1/12 lobe spacings², or
//! the paper's Gaussian, σ_k = 0.42 lobe spacings truncated at ±`kernel_sigmas` σ_k, σ_k² below
//! that truncated kernel's variance), so it carries the slope variation of a whole texel. The
//! P-NDF the mixture approximates, D_P(m) = ∫ k_P(x) N(ñ(m); s(x), σ_ε² I) dx (s the
//! interpolated slope field, σ_ε the material's intrinsic roughness), tends instead to the single
//! slope s(c) at the footprint's centre, spread by σ_ε, as the footprint k_P = N(c, Σ_P) shrinks.
//!
//! **The limit lobe.** For a slope field linear across the footprint and its neighbouring kernels,
//! s(x) = s(c) + J (x − c), the truth is exactly the Gaussian N(s(c), J Σ_P Jᵀ + σ_ε² I), and a lobe
//! under an isotropic kernel has covariance Σ_i = σ_k² J Jᵀ. So from the four lobes around c (the
//! bilinear weights w_k of the lobe lattice):
//!
//! ```text
//! μ = Σ_k w_k (μ_k − ½ σ_k² ∇²μ_k)             (s(c))
//! Σ = (√det Σ_P / σ_k²) Σ_k w_k Σ_k + σ_ε² I   (J Σ_P Jᵀ for an isotropic footprint)
//! ```
//!
//! with Σ_k the lobes' covariances from their raw moments (unfloored: a flat lobe adds nothing, so a
//! flat map gives σ_ε exactly) and ∇²μ_k the lattice Laplacian of the lobe means: the means are the
//! slope field smoothed by the seed kernel, s ∗ k_i, and s ≈ s̃ − ½ σ_k² ∇²s̃ undoes that
//! smoothing to first order (it lowered the TV to the convolved truth at 0.25-1 texel on three of
//! the four procedural maps, docs/results.md). The lobe reads twenty stored lobes. An anisotropic footprint enters through its area (√det Σ_P): the
//! map's Jacobian is not stored, only J Jᵀ, so the lobe is scaled isotropically. The lobe is served
//! like the filtered lobe (D, masking and samplers of one Gaussian): O(1) per query.
//!
//! Where it wins: docs/results.md, "Sub-texel footprints"; the switch is
//! [`PatchOptions::sub_texel_area`](super::PatchOptions::sub_texel_area).

use super::SeedKernel;
use super::storage::LobeStore;
use crate::ndf::SlopeGaussian;

/// The raw moments `[E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ]` of the sub-texel limit lobe (module docs) of a
/// footprint centred at `c` with covariance `cov` = [xx, xy, yy] (both in level-0 lobe units), for
/// lobes seeded by `seed` (resolved; truncated at ±`kernel_sigmas` σ if Gaussian) and a material of
/// intrinsic roughness `sigma_min`.
pub(super) fn limit_moments<S: LobeStore>(
    store: &S,
    c: [f64; 2],
    cov: [f64; 3],
    (seed, kernel_sigmas): (SeedKernel, f32),
    sigma_min: f32,
) -> [f32; 5] {
    let sk2 = seed.moment_variance(kernel_sigmas);
    let c = if c[0].is_finite() && c[1].is_finite() {
        c
    } else {
        [0.0, 0.0]
    };
    // Lobe k sits at k + ½; the four around c and their bilinear weights.
    let (px, py) = (c[0] - 0.5, c[1] - 0.5);
    let (bx, by) = (px.floor(), py.floor());
    let (fx, fy) = (px - bx, py - by);
    let corners = [
        (bx, by, (1.0 - fx) * (1.0 - fy)),
        (bx + 1.0, by, fx * (1.0 - fy)),
        (bx, by + 1.0, (1.0 - fx) * fy),
        (bx + 1.0, by + 1.0, fx * fy),
    ];
    let mut mean = [0.0f64; 2];
    let mut spread = [0.0f64; 3];
    // The stored moments of lobe (x, y), wrapping as the lattice does.
    let at = |x: f64, y: f64| store.lobe_moments(x as i64, y as i64).map(f64::from);
    // The lobe means are the slope field smoothed by the seed kernel, s̃ = s ∗ k (k of variance
    // σ_k² per axis); one step of deconvolution, s ≈ s̃ − ½ σ_k² ∇² s̃ (the second-order term of
    // any even kernel), with the lattice Laplacian of the means.
    let h = 0.5 * sk2;
    for (x, y, w) in corners {
        let m = at(x, y);
        let n = [
            at(x + 1.0, y),
            at(x - 1.0, y),
            at(x, y + 1.0),
            at(x, y - 1.0),
        ];
        let lx: f64 = n.iter().map(|v| v[0]).sum::<f64>() - 4.0 * m[0];
        let ly: f64 = n.iter().map(|v| v[1]).sum::<f64>() - 4.0 * m[1];
        let (mx, my) = (m[0] - h * lx, m[1] - h * ly);
        mean[0] += w * mx;
        mean[1] += w * my;
        spread[0] += w * (m[2] - m[0] * m[0]).max(0.0);
        spread[2] += w * (m[3] - m[1] * m[1]).max(0.0);
        spread[1] += w * (m[4] - m[0] * m[1]);
    }
    let area = (cov[0] * cov[2] - cov[1] * cov[1]).max(0.0).sqrt();
    let scale = if area.is_finite() { area / sk2 } else { 0.0 };
    let e2 = (sigma_min as f64).powi(2);
    let var = [
        scale * spread[0] + e2,
        scale * spread[1],
        scale * spread[2] + e2,
    ];
    [
        mean[0] as f32,
        mean[1] as f32,
        (var[0] + mean[0] * mean[0]) as f32,
        (var[2] + mean[1] * mean[1]) as f32,
        (var[1] + mean[0] * mean[1]) as f32,
    ]
}

/// The sub-texel limit lobe (module docs) as the patch evaluates it (floored at `sigma_min`, as
/// every lobe).
pub(super) fn limit_lobe<S: LobeStore>(
    store: &S,
    c: [f64; 2],
    cov: [f64; 3],
    seed: (SeedKernel, f32),
    sigma_min: f32,
) -> SlopeGaussian {
    let m = limit_moments(store, c, cov, seed, sigma_min);
    SlopeGaussian::from_moments(m, sigma_min)
}
