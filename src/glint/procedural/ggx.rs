//! The GGX limit of a procedural glint surface as a Gaussian scale mixture: each lattice cell's
//! variance scale v, its lobe's width and mean spread, and the patch's expected distance to GGX.
//!
//! **The scale mixture.** The anisotropic GGX slope density is a bivariate Student-t with two
//! degrees of freedom, hence a Gaussian scale mixture:
//!
//! ```text
//! P22(s) = 1 / (π αx αy (1 + sx²/αx² + sy²/αy²)²) = ∫ N(s; 0, v diag(αx², αy²)) g(v) dv,
//! ```
//!
//! g = InverseGamma(shape 1, scale 1/2), i.e. v = 1/(2E) with E ~ Exp(1) (\[Heitz2014\] gives
//! GGX's slopes as this Student-t; the mixture is the Student-t's standard one: with q the
//! Mahalanobis norm and w = 1/v ~ Exp(mean 2), ∫ w/(2π αx αy) e^(−q w/2) · e^(−w/2)/2 dw =
//! 1/(4π αx αy) · 4/(1 + q)², checked by quadrature in `tests`). So a cell whose lobe draws v from
//! its hash and its slope statistics from N(0, v α²) per axis has mean NDF GGX, exactly as a
//! Beckmann surface's cells with the fixed v = 1/2.
//!
//! **Lobe widths.** Each lobe applies the per-patch width rule of the Beckmann surface
//! (src/glint/procedural/lattice.rs, `lobe_widths`) with its own σ_i² = v_i α² per axis:
//! 1/β_i² = 1/σ_i² + r (1/σ_f² − 1/σ_i²), τ_i² = σ_i² − β_i², r = min(1, K/n). Where σ_i < σ_f (a
//! cell smoother than one facet, probability exp(−α²/α_f²) per axis) the rule would make β_i > σ_i;
//! the lobe is then N(0, σ_i²) itself (β_i = σ_i, τ_i = 0), so that β_i² + τ_i² = σ_i² for every
//! lobe and the mean over positions stays GGX exactly.
//!
//! **Expected distance.** With w = 1/v ~ Exp(mean 2) and σ̂ = α/√2 (the Beckmann deviation of the
//! same α), e_a = E[1/β_a²] = 1/σ̂_a² + r (1/σ_f² − 1/σ̂_a²) + r e^(−α_a²/α_f²)/σ̂_a² (the last
//! term from the clamp above; the rest is the Beckmann width rule, since E w = 2). The patch's
//! expected squared relative L2 distance to GGX (‖D_GGX‖² = 1/(3π αx αy) in slope space) is
//! (1/K)(3/2 σ̂x σ̂y E[1/(βx βy)] − 1) ≤ (1/K)(3/2 σ̂x σ̂y √(e_x e_y) − 1) (Cauchy-Schwarz; equal
//! for isotropic α). For isotropic α this is (1/K)((1 − r)/2 + r (3/2 (σ̂²/σ_f² + e^(−α²/α_f²)) − 1)):
//! the second term is what the footprint's n facets carry, min(1/K, 1/n)(3/2 σ̂²/σ_f² − 1) (as
//! n facets of roughness σ_f drawn around GGX are from it), the first, (1 − r)/(2K), is the lobes'
//! own: K Gaussians of random widths are not GGX however many facets each stands for. So GGX is
//! blended in twice ([`limit_weight`]): with the weight b_f that brings the patch's expected
//! distance down to the facets' part (G deterministic: E‖(1 − b)L + bG − G‖² = (1 − b)² E‖L − G‖²),
//! and, as for Beckmann, by the tolerance on the facets' part ([`facet_distance`]), so that large
//! footprints are GGX alone (docs/procedural.md, "The GGX limit").

/// Largest variance scale v a cell draws: 10⁵ (v exceeds it with probability 1 − e^(−1/(2·10⁵)) ≈
/// 5·10⁻⁶), so that σ_i = √v α ≤ 633 and a lobe's mean (≤ 5.4 σ_i) stay within the range of a
/// [`SlopeGaussian`](crate::ndf::SlopeGaussian).
pub(super) const MAX_VARIANCE_SCALE: f64 = 1.0e5;

/// The variance scale v = 1/(2E) of a cell, E = −ln u ~ Exp(1) from the cell's uniform u ∈ (0, 1)
/// (module docs), at most [`MAX_VARIANCE_SCALE`].
#[inline]
pub(super) fn variance_scale(u: f32) -> f64 {
    let e = -(u as f64).ln();
    (0.5 / e).min(MAX_VARIANCE_SCALE)
}

/// One lobe's width and mean spread per axis, (β², τ²), for variance scale `v`, roughness `alpha`
/// (σ_i² = v α²), facet deviation `sigma_f` and r = min(1, K/n) (module docs): the Beckmann width
/// rule with σ_i, β² at most σ_i², τ² = σ_i² − β².
pub(super) fn scaled_lobe_widths(
    alpha: [f64; 2],
    v: f64,
    sigma_f: f64,
    r: f64,
) -> ([f64; 2], [f64; 2]) {
    let r = r.clamp(0.0, 1.0);
    let s2 = alpha.map(|a| v * a * a);
    let beta2 = s2.map(|s2| {
        let rule = 1.0 / (1.0 / s2 + r * (1.0 / (sigma_f * sigma_f) - 1.0 / s2));
        rule.min(s2)
    });
    let tau2 = [0, 1].map(|a| (s2[a] - beta2[a]).max(0.0));
    (beta2, tau2)
}

/// e_a = E[1/β_a²] over v (module docs) per axis, for Beckmann deviations `sigma` (σ̂ = α/√2),
/// facet deviation `sigma_f` and r.
fn mean_inverse_widths(sigma: [f64; 2], sigma_f: f64, r: f64) -> [f64; 2] {
    let r = r.clamp(0.0, 1.0);
    sigma.map(|s| {
        let clamp = (-(s * s) / (sigma_f * sigma_f)).exp();
        1.0 / (s * s) + r * (1.0 / (sigma_f * sigma_f) - 1.0 / (s * s)) + r * clamp / (s * s)
    })
}

/// The part of a patch's expected relative L2 distance to GGX that its footprint's facets carry
/// (module docs): √(max(0, 3/2 σ̂x σ̂y √(e_x e_y) − 1 − (1 − r)/2) / K), for Beckmann deviations
/// `sigma`, facet deviation `sigma_f`, r = min(1, K/n) and the kernel's effective lobe count `k`.
/// For isotropic α, min(1/K, 1/n)(3/2 (σ̂²/σ_f² + e^(−α²/α_f²)) − 1) under the root.
pub(super) fn facet_distance(sigma: [f64; 2], sigma_f: f64, r: f64, k: f64) -> f64 {
    let r = r.clamp(0.0, 1.0);
    let e = mean_inverse_widths(sigma, sigma_f, r);
    let total = 1.5 * sigma[0] * sigma[1] * (e[0] * e[1]).sqrt() - 1.0;
    ((total - 0.5 * (1.0 - r)).max(0.0) / k.max(1e-300)).sqrt()
}

/// The weight b of GGX in a GGX surface's patch: 1 − (1 − b_f)(1 − `b_tol`), with `b_tol` the
/// tolerance's weight (0 above 2 tol, 1 below tol) and b_f the weight that makes the patch as far
/// from GGX as its footprint's facets are (module docs): (1 − b_f)² (ρ_f² + (1 − r)/(2K)) = ρ_f²,
/// i.e. 1 − b_f = ρ_f / √(ρ_f² + (1 − r)/(2K)), for ρ_f = `facet` ([`facet_distance`]), r and
/// the kernel's effective lobe count `k`. b_f = 0 where r = 1 (a footprint of fewer facets than
/// lobes).
pub(super) fn limit_weight(facet: f64, r: f64, k: f64, b_tol: f32) -> f32 {
    let floor2 = 0.5 * (1.0 - r.clamp(0.0, 1.0)) / k.max(1e-300);
    let total = facet * facet + floor2;
    let keep = if total > 0.0 {
        facet / total.sqrt()
    } else {
        1.0
    };
    (1.0 - keep * (1.0 - b_tol as f64)).clamp(0.0, 1.0) as f32
}

/// The same distance for the footprint's n facets alone (r = 1, K = n): the bound a patch's
/// [`facet_distance`] does not exceed for isotropic α, known before any lobe is gathered.
pub(super) fn footprint_distance(sigma: [f64; 2], sigma_f: f64, n: f64) -> f64 {
    facet_distance(sigma, sigma_f, 1.0, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scale mixture of the module docs, numerically: ∫ N(s; 0, v α²) g(v) dv against
    /// P22(s) at a few slopes (the midpoint rule in E = 1/(2v), over E (1 + q) ∈ (0, 60) in
    /// 4·10⁵ steps), relative error below 10⁻⁴.
    #[test]
    fn gaussian_scale_mixture_is_ggx() {
        let (ax, ay) = (0.3f64, 0.15f64);
        for s in [
            [0.0, 0.0],
            [0.1, -0.05],
            [0.5, 0.2],
            [2.0, -1.0],
            [8.0, 3.0],
        ] {
            let q = s[0] * s[0] / (ax * ax) + s[1] * s[1] / (ay * ay);
            let exact = 1.0 / (std::f64::consts::PI * ax * ay * (1.0 + q) * (1.0 + q));
            // E = x / (1 + q): the integrand's scale in x is 1 whatever q.
            let (n, top) = (400_000, 60.0);
            let h = top / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                let e = (i as f64 + 0.5) * h / (1.0 + q);
                let v = 0.5 / e;
                let gauss = (-0.5 * q / v).exp() / (2.0 * std::f64::consts::PI * v * ax * ay);
                sum += gauss * (-e).exp() * h / (1.0 + q);
            }
            assert!((sum / exact - 1.0).abs() < 1e-4, "{s:?}: {sum} vs {exact}");
        }
    }

    /// Every lobe keeps β² + τ² = σ_i² (the exact mean), β² ≤ σ_i² and β ≥ the facet width where
    /// σ_i ≥ σ_f.
    #[test]
    fn widths_keep_the_lobe_variance() {
        for v in [1e-4, 0.01, 0.5, 3.0, 1e5] {
            for r in [0.0, 0.3, 1.0] {
                let alpha = [0.3, 0.1];
                let (b, t) = scaled_lobe_widths(alpha, v, 0.02, r);
                for a in 0..2 {
                    let s2 = v * alpha[a] * alpha[a];
                    assert!((b[a] + t[a] - s2).abs() <= 1e-12 * s2.max(1.0), "{v} {r}");
                    assert!(b[a] <= s2 && b[a] > 0.0);
                }
            }
        }
    }

    /// The floor's weight: the blend (1 − b_f)² (ρ_f² + (1 − r)/(2K)) = ρ_f², none where r = 1,
    /// the tolerance's weight on top.
    #[test]
    fn limit_weight_brings_the_distance_to_the_facets() {
        let (f, r, k) = (0.2, 0.1, 12.0);
        let b = limit_weight(f, r, k, 0.0) as f64;
        let d2 = (1.0 - b).powi(2) * (f * f + 0.5 * (1.0 - r) / k);
        assert!((d2 / (f * f) - 1.0).abs() < 1e-6, "{b} {d2}");
        assert_eq!(limit_weight(f, 1.0, k, 0.0), 0.0);
        assert_eq!(limit_weight(f, 1.0, k, 0.25), 0.25);
        assert_eq!(limit_weight(f, r, k, 1.0), 1.0);
    }

    /// For isotropic α the facet distance is min(1/K, 1/n)(3/2 (ratio + e) − 1) (module docs).
    #[test]
    fn facet_distance_isotropic_closed_form() {
        let (s, sf) = (0.3 / 2f64.sqrt(), 0.02 / 2f64.sqrt());
        let c = 1.5 * (s * s / (sf * sf) + (-(s * s) / (sf * sf)).exp()) - 1.0;
        for (k, n) in [(10.0f64, 1000.0f64), (20.0, 5.0)] {
            let r = (k / n).min(1.0);
            let got = facet_distance([s, s], sf, r, k);
            let want = (c * (1.0 / k).min(1.0 / n)).sqrt();
            assert!((got / want - 1.0).abs() < 1e-12, "{got} {want}");
        }
    }
}
