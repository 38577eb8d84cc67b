//! Deterministic hemisphere quadrature of a BRDF's white furnace, with an error estimate: the rule
//! of the integration tests (tests/it/support/quadrature.rs, tests/it/energy_compensation.rs)
//! for the charts, so that a furnace curve is the integral itself and not a Monte Carlo estimate
//! of it.
//!
//! E(wo) = ∫ f(wo, wi) cos θi dωi is integrated over the half vector m (wi = reflect(wo, m),
//! dωi = 4 (wo·m) dωm): composite Gauss–Legendre in θm, with band edges at atan(k α) (k = ½, 2, 6,
//! 20, 60, 200) so that the specular peak (width ~α) and the horizon cut near it get panels of
//! their own size, and the periodic midpoint rule in φm. Every wi above the horizon has its half
//! vector above it too, so lobes that are not specular (a compensation lobe, a base) are covered.
//! The error estimate is |I(2) − I(1)|, the rule against itself at half the resolution in both
//! variables (an over-estimate of the finer rule's error for the smooth integrands charted).

use brdf::Vec3;
use brdf::bxdf::Bxdf;
use std::f64::consts::{FRAC_PI_2, PI};

/// Points per Gauss–Legendre panel.
const GL_N: usize = 8;

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1] (Newton on P_n, f64).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// ∫ over θ ∈ [lo, hi], φ ∈ [0, 2π) of g(ω) dω (RGB), `panels` Gauss–Legendre panels in θ and
/// `n_phi` midpoints in φ.
fn integrate_band(
    g: &dyn Fn(Vec3) -> [f64; 3],
    lo: f64,
    hi: f64,
    panels: usize,
    n_phi: usize,
) -> [f64; 3] {
    let gl = gauss_legendre(GL_N);
    let width = (hi - lo) / panels as f64;
    let dphi = 2.0 * PI / n_phi as f64;
    let mut total = [0.0; 3];
    for p in 0..panels {
        let a = lo + p as f64 * width;
        for &(x, wx) in &gl {
            let theta = a + 0.5 * width * (x + 1.0);
            let (st, ct) = theta.sin_cos();
            let w = dphi * st * wx * 0.5 * width;
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) * dphi;
                let m = Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                let v = g(m);
                for c in 0..3 {
                    total[c] += v[c] * w;
                }
            }
        }
    }
    total
}

/// ∫ f(wo, wi) cos θi dωi (RGB) by the banded half-vector rule at resolution `scale` (panels and φ
/// points multiplied by it), over the stretched variable v of `stretch` = (αx, αy): m = normalize(αx
/// v.x, αy v.y, v.z), dωm = αx αy / |(αx v.x, αy v.y, v.z)|³ dωv, so that an anisotropic lobe is
/// isotropic in v (a plain φ grid misses a lobe 0.05 wide in φm); (1, 1) is the plain rule.
/// `alpha` places the bands (in v).
fn albedo_at(b: &dyn Bxdf, wo: Vec3, alpha: f64, stretch: (f64, f64), scale: usize) -> [f64; 3] {
    let g = |v: Vec3| {
        let s = [stretch.0 * v.x as f64, stretch.1 * v.y as f64, v.z as f64];
        let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        let m = Vec3::new(
            (s[0] / len) as f32,
            (s[1] / len) as f32,
            (s[2] / len) as f32,
        );
        let jacobian = stretch.0 * stretch.1 / (len * len * len);
        let k = wo.dot(m);
        if k <= 0.0 {
            return [0.0; 3];
        }
        let wi = 2.0 * k * m - wo;
        let f = b.eval(wo, wi) * (wi.z.max(0.0) * 4.0 * k);
        [
            f.x as f64 * jacobian,
            f.y as f64 * jacobian,
            f.z as f64 * jacobian,
        ]
    };
    let mut edges = vec![0.0];
    for k in [0.5, 2.0, 6.0, 20.0, 60.0, 200.0] {
        let t = (k * alpha).atan();
        if t < 1.5 {
            edges.push(t);
        }
    }
    edges.push(FRAC_PI_2);
    let mut sum = [0.0; 3];
    for e in edges.windows(2) {
        let v = integrate_band(&g, e[0], e[1], 6 * scale, 96 * scale);
        for c in 0..3 {
            sum[c] += v[c];
        }
    }
    sum
}

/// The rule at resolutions 2 and 1: the finer value and the largest |I(2) − I(1)| over the channels.
fn with_estimate(rule: impl Fn(usize) -> [f64; 3]) -> ([f64; 3], f64) {
    let (fine, coarse) = (rule(2), rule(1));
    let err = (0..3)
        .map(|c| (fine[c] - coarse[c]).abs())
        .fold(0.0, f64::max);
    (fine, err)
}

/// The white furnace E(wo) (RGB) of `b`, whose lobe has roughness `alpha`, and its error estimate
/// (the largest |I(2) − I(1)| over the channels).
pub fn furnace(b: &dyn Bxdf, wo: Vec3, alpha: f64) -> ([f64; 3], f64) {
    with_estimate(|scale| albedo_at(b, wo, alpha, (1.0, 1.0), scale))
}

/// [`furnace`] of a BRDF whose lobe is anisotropic with roughness (αx, αy): the rule over the
/// stretched variable (bands at atan(k), the lobe's width in v).
pub fn furnace_anisotropic(b: &dyn Bxdf, wo: Vec3, alpha_x: f64, alpha_y: f64) -> ([f64; 3], f64) {
    with_estimate(|scale| albedo_at(b, wo, 1.0, (alpha_x, alpha_y), scale))
}

/// [`furnace`] of `b`, an anisotropic single-scattering BRDF `single` (roughness (αx, αy)) plus a
/// lobe smooth in wi (energy compensation): `single` by [`furnace_anisotropic`], the rest (b − single)
/// by the plain rule over wi (24 panels × 192 φ points, halved for the estimate), which the
/// stretched variable leaves under-resolved away from the specular peak.
pub fn furnace_anisotropic_plus_smooth(
    b: &dyn Bxdf,
    single: &dyn Bxdf,
    wo: Vec3,
    alpha_x: f64,
    alpha_y: f64,
) -> ([f64; 3], f64) {
    let (s, es) = furnace_anisotropic(single, wo, alpha_x, alpha_y);
    let lobe = |wi: Vec3| {
        let f = (b.eval(wo, wi) - single.eval(wo, wi)) * wi.z.max(0.0);
        [f.x as f64, f.y as f64, f.z as f64]
    };
    let (l, el) =
        with_estimate(|scale| integrate_band(&lobe, 0.0, FRAC_PI_2, 12 * scale, 96 * scale));
    (std::array::from_fn(|c| s[c] + l[c]), es + el)
}
