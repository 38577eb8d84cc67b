//! An estimate of a glint patch's single-scattering albedo E(wo), the energy its P-BRDF returns
//! toward a view (white Fresnel, height-correlated masking, the renderer's measure): what the
//! opt-in energy compensation of glint patches gives back (`crate::bxdf::ViewCompensated`).
//!
//! A patch made of weighted slope Gaussians D_P = Σ W_i D_i reflects wo through a visible normal
//! drawn from lobe i with probability W_i V_i(wo)/V_P(wo); a sample through m carries the weight
//! G2/G1(wo) = (1 + Λ_P(wo))/(1 + Λ_P(wo) + Λ_P(wi)), 0 where wi = 2⟨wo, m⟩m − wo is below the
//! horizon. So
//!
//! E(wo) = Σ_i (W_i V_i(wo)/V_P(wo)) E_{m ∼ D_wo,i}[g(wi(m))],  g(wi) = (1 + Λo)/(1 + Λo + Λi)⁺,
//!
//! with Λo the patch's own Λ_P(wo) and V_P(wo) = (1 + Λo) A_P(wo) its own visible area (never
//! taken below the lobes' Σ W_i V_i(wo)): where the patch's masking is a conservative bound
//! (Scarf's, above Σ W_i V_i), its visible normals' mass falls short of 1 by that much and so does
//! E. Three approximations make it O(lobes):
//! - a patch of more than [`MERGE_SIDE`]² lobes is first merged onto a [`MERGE_SIDE`]² grid of slope
//!   cells ([`Merged`]): one cheap pass over its lobes, then the per-lobe work on at most
//!   [`MERGE_SIDE`]²;
//! - each lobe's visible average ([`lobe_average`]): g at its mean normal's reflection where the
//!   lobe reflects [`HORIZON_MARGIN`] widths above the horizon (g is flat there), else an 8 × 3
//!   grid of its visible normals (Gauss-Legendre quantiles of the visible slope along the view
//!   through the lobe's own inversion, × Gauss-Hermite across it): g jumps to 0 across such a
//!   lobe, and a wide lobe's loss sits in its tail, which low-order rules in the whitened slope
//!   miss. A lobe carrying at least [`REFINE_SHARE`] of the patch's visible area has the jump
//!   located instead ([`refined_average`]), since the 8-point rule misses up to ~5 % of a step;
//! - Λ_P(wi) at the reflected directions from four slope Gaussians, the lobes pooled on either
//!   side of the pooled mean along the pooled covariance's principal axes ([`Proxy`]), with the
//!   patch's exact projected area: O(1) per direction, exact where every lobe faces wi (V is then
//!   linear in the mean slope), approximate toward wi's horizon.
//!
//! Measured against the renderer's furnace (mean `sample().weight()`) of mixture patches on the
//! four procedural maps: docs/results.md, "Energy compensation of glint patches".

use crate::ndf::{Ndf, SIGMA_MIN_FLOOR, SlopeGaussian};
use glam::{Vec2, Vec3};

/// A lobe whose mean normal reflects wo more than this many lobe widths (2σ, σ its larger slope
/// standard deviation) above the horizon takes g there; others the visible grid.
const HORIZON_MARGIN: f32 = 3.0;

/// The 8-point Gauss-Legendre rule on (0, 1): quantiles of the visible slope along the view.
const GL_NODES: [f32; 8] = [
    0.019_855_07,
    0.101_666_76,
    0.237_233_8,
    0.408_282_68,
    0.591_717_3,
    0.762_766_2,
    0.898_333_24,
    0.980_144_9,
];
const GL_WEIGHTS: [f64; 8] = [
    0.050_614_27,
    0.111_190_52,
    0.156_853_32,
    0.181_341_89,
    0.181_341_89,
    0.156_853_32,
    0.111_190_52,
    0.050_614_27,
];

/// The 3-point Gauss-Hermite rule of the standard normal: the slope across the view.
/// The centre first: Λ at a row's centre stands for the row's (see `lobe_average`).
const GH_NODES: [f64; 3] = [0.0, -1.732_050_807_568_877_2, 1.732_050_807_568_877_2];
const GH_WEIGHTS: [f64; 3] = [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0];

/// One lobe of a patch as the estimate reads it: its weight in D_P (not necessarily normalised), its
/// mean slope and its covariance [Σxx, Σxy, Σyy].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Lobe {
    pub weight: f32,
    pub mean: Vec2,
    pub cov: [f32; 3],
    /// The lobe itself where the patch holds it (not rebuilt from the moments).
    pub gaussian: Option<SlopeGaussian>,
}

impl Lobe {
    /// The lobe of weight `weight` and slope Gaussian `g`.
    pub fn of(weight: f32, g: &SlopeGaussian) -> Lobe {
        let c = g.covariance();
        Lobe {
            weight,
            mean: g.mean(),
            cov: [c.x_axis.x, c.x_axis.y, c.y_axis.y],
            gaussian: Some(*g),
        }
    }

    /// The lobe of weight `weight`, mean `mu` and covariance `c` = [Σxx, Σxy, Σyy] in `f64`.
    #[inline]
    pub fn from_mean_cov(weight: f32, mu: [f64; 2], c: [f64; 3]) -> Lobe {
        Lobe {
            weight,
            mean: Vec2::new(mu[0] as f32, mu[1] as f32),
            cov: c.map(|v| v as f32),
            gaussian: None,
        }
    }

    /// The raw moments [E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ].
    fn raw_moments(&self) -> [f32; 5] {
        let (m, [cxx, cxy, cyy]) = (self.mean, self.cov);
        [m.x, m.y, cxx + m.x * m.x, cyy + m.y * m.y, cxy + m.x * m.y]
    }
}

/// Slope moments [E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ] accumulated with their total weight.
#[derive(Clone, Copy, Default)]
struct Moments {
    sum: [f64; 5],
    total: f64,
}

impl Moments {
    fn add(&mut self, l: &Lobe) {
        let (w, [cxx, cxy, cyy]) = (l.weight as f64, l.cov.map(f64::from));
        let (mx, my) = (l.mean.x as f64, l.mean.y as f64);
        self.total += w;
        self.sum[0] += w * mx;
        self.sum[1] += w * my;
        self.sum[2] += w * (cxx + mx * mx);
        self.sum[3] += w * (cyy + my * my);
        self.sum[4] += w * (cxy + mx * my);
    }

    /// The normalised moments, or `None` without positive finite weight.
    fn normalised(&self) -> Option<[f32; 5]> {
        (self.total > 0.0 && self.total.is_finite())
            .then(|| self.sum.map(|v| (v / self.total) as f32))
    }
}

/// What stands for the patch's Λ_P(wi) at the reflected directions: the lobes pooled into (up to)
/// four slope Gaussians, split at the pooled mean along the principal axes of the pooled
/// covariance (so that two or four separated groups of lobes, the facets of a flake patch or the
/// two walls of a scratch, keep their own spread), with the patch's exact projected area.
/// V_proxy(w) = Σ_k W_k V_k(w), Λ = V_proxy/A − 1: O(1) per direction.
struct Proxy {
    mean: Vec2,
    parts: [(f32, SlopeGaussian); 4],
    n: usize,
}

impl Proxy {
    fn new<I: Iterator<Item = (f32, SlopeGaussian)> + Clone>(lobes: I) -> Self {
        let mut all = Moments::default();
        for (w, g) in lobes.clone() {
            all.add(&Lobe::of(w, &g));
        }
        let fallback = SlopeGaussian::from_moments([0.0; 5], SIGMA_MIN_FLOOR);
        let mut proxy = Proxy {
            mean: Vec2::ZERO,
            parts: [(0.0, fallback); 4],
            n: 0,
        };
        let Some(m) = all.normalised() else {
            return proxy;
        };
        proxy.mean = Vec2::new(m[0], m[1]);
        // The principal axis of the pooled covariance [[a, b], [b, c]].
        let (a, b, c) = (m[2] - m[0] * m[0], m[4] - m[0] * m[1], m[3] - m[1] * m[1]);
        let angle = 0.5 * (2.0 * b).atan2(a - c);
        let e1 = Vec2::new(angle.cos(), angle.sin());
        let mut parts = [Moments::default(); 4];
        for (w, g) in lobes {
            let d = g.mean() - proxy.mean;
            let k = usize::from(d.dot(e1) > 0.0) + 2 * usize::from(d.perp_dot(e1) > 0.0);
            parts[k].add(&Lobe::of(w, &g));
        }
        for part in parts {
            if let Some(pm) = part.normalised() {
                let weight = (part.total / all.total) as f32;
                proxy.parts[proxy.n] = (weight, SlopeGaussian::from_moments(pm, SIGMA_MIN_FLOOR));
                proxy.n += 1;
            }
        }
        proxy
    }

    /// Λ(w) = V_proxy(w)/A(w) − 1 (`f32::MAX` where A ≤ 0; 0 for an invalid w).
    fn lambda(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let a = w.z - self.mean.dot(Vec2::new(w.x, w.y));
        if a.is_nan() || a <= 0.0 {
            return f32::MAX;
        }
        let v: f32 = self.parts[..self.n]
            .iter()
            .map(|(k, g)| k * visible_area(g, w))
            .sum();
        let l = v / a - 1.0;
        if l.is_finite() { l.max(0.0) } else { f32::MAX }
    }
}

/// The normal of slope s (unnormalised: (−s, 1)).
#[inline]
fn normal_of(s: Vec2) -> Vec3 {
    Vec3::new(-s.x, -s.y, 1.0).normalize_or_zero()
}

/// g at the mirror direction of `wo` about the normal of slope `s`: the weight a visible sample
/// through it carries, (1 + Λo)/(1 + Λo + Λ(wi)) with Λ from `proxy`, 0 below the horizon.
#[inline]
fn weight_through(wo: Vec3, s: Vec2, lambda_o: f32, proxy: &Proxy) -> f32 {
    weight_of_normal(wo, normal_of(s), lambda_o, proxy)
}

/// g at the mirror direction of `wo` about the unit normal `m`.
#[inline]
fn weight_of_normal(wo: Vec3, m: Vec3, lambda_o: f32, proxy: &Proxy) -> f32 {
    let wi = 2.0 * wo.dot(m) * m - wo;
    let li = if wi.z > 0.0 { proxy.lambda(wi) } else { 0.0 };
    g_of(wi, lambda_o, li)
}

/// g = (1 + Λo)/(1 + Λo + Λi) toward `wi`, 0 below the horizon.
#[inline]
fn g_of(wi: Vec3, lambda_o: f32, lambda_i: f32) -> f32 {
    if wi.z.is_nan() || wi.z <= 0.0 {
        return 0.0;
    }
    let g = (1.0 + lambda_o) / (1.0 + lambda_o + lambda_i);
    if g.is_finite() { g } else { 0.0 }
}

/// E_{m ∼ D_wo,i}[g] for one lobe.
///
/// Where g is flat over the lobe (its mean normal reflects wo [`HORIZON_MARGIN`] lobe widths 2σ
/// above the horizon), g there. Elsewhere g jumps to 0 across the lobe, which no low-order rule in
/// the whitened slope integrates (a degree-3 rule misses 0.03-0.09 on a Beckmann lobe of α ≥ 0.2):
/// the 8 × 3 product grid of the lobe's visible normals, 8 Gauss-Legendre quantiles of the visible
/// slope along the view (the lobe's own inversion, so the grid follows D_wo,i into its tail) ×
/// the 3-point Gauss-Hermite rule across it; for a lobe no wider than [`NARROW_SIGMA`] Λ is taken
/// once per row. With `refine` (the lobe carries much of the patch), a grid whose column has nodes
/// on both sides of the horizon is replaced by [`refined_average`], which locates the step.
fn lobe_average(wo: Vec3, lobe: &SlopeGaussian, lambda_o: f32, proxy: &Proxy, refine: bool) -> f32 {
    let l = lobe.cholesky();
    let mu = lobe.mean();
    let sigma = l.x_axis.x.max(l.y_axis.length());
    let m = normal_of(mu);
    let margin = (2.0 * wo.dot(m) * m - wo).z;
    if margin > HORIZON_MARGIN * 2.0 * sigma {
        return weight_through(wo, mu, lambda_o, proxy);
    }
    let (mut sum, mut total) = (0.0f64, 0.0f64);
    let mut row_lambda = 0.0f32;
    let narrow = sigma <= NARROW_SIGMA;
    // Per column across the view: whether some node reflects above the horizon, some below.
    let (mut above, mut below) = ([false; 3], [false; 3]);
    lobe.visible_grid(wo, &GL_NODES, &GH_NODES, |i, j, m| {
        let wi = 2.0 * wo.dot(m) * m - wo;
        above[j] |= wi.z > 0.0;
        below[j] |= wi.z.is_nan() || wi.z <= 0.0;
        if j == 0 || !narrow {
            // Across a narrow lobe's row (the slope across the view) Λ varies far less than along
            // the view: its centre's value serves the row.
            row_lambda = if wi.z > 0.0 {
                proxy.lambda(wi)
            } else {
                f32::MAX
            };
        }
        let w = GL_WEIGHTS[i] * GH_WEIGHTS[j];
        sum += w * g_of(wi, lambda_o, row_lambda) as f64;
        total += w;
    });
    if refine && (0..3).any(|j| above[j] && below[j]) {
        return refined_average(wo, lobe, lambda_o, proxy);
    }
    if total > 0.0 {
        (sum / total) as f32
    } else {
        weight_through(wo, mu, lambda_o, proxy)
    }
}

/// A lobe's visible share of the patch from which it takes [`refined_average`]: the 8-point rule
/// misses up to ~5 % of a lobe whose reflections cross the horizon (g is a step there), which
/// matters only where the lobe carries much of the patch (a flake patch of a few facets).
const REFINE_SHARE: f64 = 0.05;

/// Panels of [`refined_average`] along the view, and the bisection steps that place a horizon
/// crossing inside one (to 2⁻⁸ of a panel).
const PANELS: usize = 8;
const BISECTIONS: usize = 8;

/// The 2-point Gauss-Legendre rule on (0, 1).
const GL2_NODES: [f32; 2] = [0.211_324_87, 0.788_675_1];

/// E_{m ∼ D_wo,i}[g] for a lobe whose reflections cross the horizon, with the crossing resolved:
/// per Gauss-Hermite column across the view, the visible slope's quantile axis (0, 1) along it in
/// [`PANELS`] panels; a panel whose two ends reflect above the horizon takes the 2-point rule, one
/// whose ends straddle it is cut at the crossing (bisection of the reflection's height) and its
/// upper part takes the rule, one wholly below gives 0. g is smooth on each part, so the step that
/// the 8-point rule misses is integrated to the bisection's resolution. About 30 inversions per
/// column instead of 8. Assumes at most one crossing per panel.
fn refined_average(wo: Vec3, lobe: &SlopeGaussian, lambda_o: f32, proxy: &Proxy) -> f32 {
    // The reflection of wo about the visible normal at quantile u along the view and z2 across.
    let reflect = |u: f32, z2: f64| -> Vec3 {
        let mut wi = Vec3::NEG_Z;
        lobe.visible_grid(wo, &[u], &[z2], |_, _, m| wi = 2.0 * wo.dot(m) * m - wo);
        wi
    };
    let g_at = |wi: Vec3| {
        if wi.z > 0.0 {
            g_of(wi, lambda_o, proxy.lambda(wi))
        } else {
            0.0
        }
    };
    let step = 1.0 / PANELS as f32;
    let mut sum = 0.0f64;
    for (&z2, &weight) in GH_NODES.iter().zip(&GH_WEIGHTS) {
        let mut column = 0.0f64;
        let mut lo = (0.0f32, reflect(0.0, z2).z);
        for k in 1..=PANELS {
            let u = k as f32 * step;
            let hi = (u, reflect(u, z2).z);
            let part = match (lo.1 > 0.0, hi.1 > 0.0) {
                (true, true) => Some((lo.0, hi.0)),
                (false, false) => None,
                (lo_up, _) => {
                    // Bisect the crossing: `a` keeps the side of lo, `b` the side of hi.
                    let (mut a, mut b) = (lo.0, hi.0);
                    for _ in 0..BISECTIONS {
                        let c = 0.5 * (a + b);
                        if (reflect(c, z2).z > 0.0) == lo_up {
                            a = c;
                        } else {
                            b = c;
                        }
                    }
                    Some(if lo_up { (lo.0, a) } else { (b, hi.0) })
                }
            };
            if let Some((a, b)) = part {
                let g: f32 = GL2_NODES
                    .iter()
                    .map(|&t| g_at(reflect(a + t * (b - a), z2)))
                    .sum();
                column += 0.5 * (b - a) as f64 * g as f64;
            }
            lo = hi;
        }
        sum += weight * column;
    }
    sum as f32
}

/// The estimate of E(wo) (module docs) of the patch D_P = Σ W_i D_i made of `lobes` (weights need
/// not be normalised; [`Lobe::of`] makes one of a slope Gaussian), whose own Λ_P(wo) is `lambda_o`;
/// `frame`, a slope Gaussian of about the patch's moments, lets a patch of many lobes be merged in
/// one pass ([`Merged`]); `extra` adds parts that are not slope
/// Gaussians as (weighted visible area W_j V_j(wo), their albedo e_j). In [0, 1]; 1 for a view
/// no lobe is visible from (no energy to give back).
pub(crate) fn lobes_albedo<I>(
    wo: Vec3,
    lambda_o: f32,
    lobes: I,
    frame: Option<&SlopeGaussian>,
    extra: &[(f32, f32)],
) -> f32
where
    I: Iterator<Item = Lobe> + Clone,
{
    if !(wo.z > 0.0 && wo.is_finite()) {
        return 1.0;
    }
    let lambda_o = if lambda_o.is_finite() {
        lambda_o.max(0.0)
    } else {
        f32::MAX
    };
    let merged = Merged::new(lobes, frame);
    let proxy = Proxy::new(merged.lobes());
    // The lobes' weighted visible areas W_i V_i(wo) first: a lobe's share of them decides its rule.
    let mut v = [0.0f64; MERGE_SIDE * MERGE_SIDE];
    for (vi, (w, lobe)) in v.iter_mut().zip(merged.lobes()) {
        *vi = (w as f64 * visible_area(&lobe, wo) as f64).max(0.0);
    }
    let lobes_v: f64 = v[..merged.n].iter().sum();
    let extra_v: f64 = extra.iter().map(|&(ve, _)| (ve as f64).max(0.0)).sum();
    let mut num = 0.0f64;
    for (&vi, (_, lobe)) in v.iter().zip(merged.lobes()) {
        if vi > 0.0 {
            let refine = vi >= REFINE_SHARE * (lobes_v + extra_v);
            num += vi * lobe_average(wo, &lobe, lambda_o, &proxy, refine) as f64;
        }
    }
    for &(ve, e) in extra {
        if ve > 0.0 {
            num += ve as f64 * e.clamp(0.0, 1.0) as f64;
        }
    }
    // The patch's own V_P(wo) = (1 + Λo) A_P(wo) normalises its visible normals; where it exceeds
    // the lobes' (a conservative masking bound, such as Scarf's), part of D_wo's mass is lost to
    // that bound and E is lower by V_lobes/V_P.
    let mut den = lobes_v + extra_v;
    if extra.is_empty() {
        let total: f64 = merged.lobes().map(|(w, _)| w as f64).sum();
        let a = wo.z as f64 - proxy.mean.dot(Vec2::new(wo.x, wo.y)) as f64;
        let v_patch = (1.0 + lambda_o as f64) * a * total;
        if v_patch.is_finite() && v_patch > den {
            den = v_patch;
        }
    }
    if den > 0.0 && (num / den).is_finite() {
        ((num / den) as f32).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Lobes no wider than this (larger slope standard deviation) take Λ once per row of the visible
/// grid.
const NARROW_SIGMA: f32 = 0.05;

/// Side of the slope grid that merges the lobes of a patch with more than `MERGE_SIDE²` of them.
const MERGE_SIDE: usize = 12;

/// The lobes the estimate runs over: a patch's own when it has at most [`MERGE_SIDE`]² of them,
/// else its lobes pooled per cell of a [`MERGE_SIDE`]² grid over the pooled mean ± 3 pooled
/// standard deviations (outer lobes in the edge cells): O(lobes) cheap additions, then the
/// estimate's per-lobe work on at most 64 lobes. A cell's weighted visible area is its pooled
/// lobe's, exact wherever its lobes face wo (V = A there, linear in the mean slope); its visible
/// normals those of its pooled lobe, as wide as its lobes and the spread of their means.
struct Merged {
    lobes: [(f32, SlopeGaussian); MERGE_SIDE * MERGE_SIDE],
    n: usize,
}

impl Merged {
    /// `frame`, if given, places the grid (its mean ± 3 standard deviations per axis) in the one
    /// pass over `lobes`; without it a first pass pools the lobes' moments.
    fn new<I: Iterator<Item = Lobe> + Clone>(lobes: I, frame: Option<&SlopeGaussian>) -> Self {
        let unit = SlopeGaussian::from_moments([0.0; 5], SIGMA_MIN_FLOOR);
        let mut merged = Merged {
            lobes: [(0.0, unit); MERGE_SIDE * MERGE_SIDE],
            n: 0,
        };
        let (mean, var) = match frame {
            Some(f) => {
                let c = f.covariance();
                (f.mean(), Vec2::new(c.x_axis.x, c.y_axis.y))
            }
            None => {
                let mut all = Moments::default();
                for l in lobes.clone() {
                    all.add(&l);
                }
                let Some(m) = all.normalised() else {
                    return merged;
                };
                (
                    Vec2::new(m[0], m[1]),
                    Vec2::new(m[2] - m[0] * m[0], m[3] - m[1] * m[1]),
                )
            }
        };
        let sd = var
            .max(Vec2::splat(SIGMA_MIN_FLOOR * SIGMA_MIN_FLOOR))
            .powf(0.5);
        let lo = mean - 3.0 * sd;
        let scale = MERGE_SIDE as f32 / (6.0 * sd);
        let mut cells = [Moments::default(); MERGE_SIDE * MERGE_SIDE];
        let last = (MERGE_SIDE - 1) as f32;
        let mut count = 0usize;
        for l in lobes {
            if count < merged.lobes.len() {
                let g = l.gaussian.unwrap_or_else(|| {
                    SlopeGaussian::from_moments(l.raw_moments(), SIGMA_MIN_FLOOR)
                });
                merged.lobes[count] = (l.weight, g);
            }
            count += 1;
            let c = ((l.mean - lo) * scale).clamp(Vec2::ZERO, Vec2::splat(last));
            cells[c.y as usize * MERGE_SIDE + c.x as usize].add(&l);
        }
        if count <= merged.lobes.len() {
            merged.n = count;
            return merged;
        }
        for cell in &cells {
            if let Some(cm) = cell.normalised() {
                merged.lobes[merged.n] = (
                    cell.total as f32,
                    SlopeGaussian::from_moments(cm, SIGMA_MIN_FLOOR),
                );
                merged.n += 1;
            }
        }
        merged
    }

    fn lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        self.lobes[..self.n].iter().copied()
    }
}

/// V(w) of a lobe, without the tail term where the lobe faces w by more than [`FACING_SPREADS`]
/// of its spread toward w (the term is then below 10⁻⁵ of the spread: V = A_s).
fn visible_area(g: &SlopeGaussian, w: Vec3) -> f32 {
    let (a_s, s_w) = g.area_and_spread(w);
    if a_s > FACING_SPREADS * s_w {
        a_s as f32
    } else {
        g.visible_area(w)
    }
}

/// See [`visible_area`].
const FACING_SPREADS: f64 = 4.0;

#[cfg(test)]
mod tests;
