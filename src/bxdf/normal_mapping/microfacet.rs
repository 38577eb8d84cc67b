//! Microfacet-based normal mapping (\[Schussler2017\]): the shading normal as one facet of a
//! two-facet microsurface whose mean normal is the geometric one.
//!
//! ## The microsurface
//! ω_p = the shading normal (cos θp = ω_p.z, sin θp = ‖(ω_p.x, ω_p.y)‖), ω_t = −(ω_p.x, ω_p.y, 0) /
//! sin θp, the vertical facet facing the lean of ω_p. Per unit geometric area the microsurface has
//! 1/cos θp of facet p and tan θp of facet t; their projected areas toward w are a_p(w) =
//! ⟨w, ω_p⟩⁺ / cos θp and a_t(w) = ⟨w, ω_t⟩⁺ sin θp / cos θp (\[Schussler2017\] §3). With
//! a(w) = ⟨w, ω_p⟩⁺ + ⟨w, ω_t⟩⁺ sin θp:
//! - the probability that a ray from w hits facet p (resp. t) first is λ_p(w) = ⟨w, ω_p⟩⁺ / a(w)
//!   (resp. λ_t(w) = ⟨w, ω_t⟩⁺ sin θp / a(w));
//! - the Smith masking of the microsurface is G1(w) = min(1, cos θ⁺ cos θp / a(w)).
//!
//! ## What `eval` includes
//! Every path of the walk with exactly one scattering event on facet p (the inner BxDF, in p's
//! frame), each with at most one mirror bounce on facet t before and after it (after a t bounce a
//! ray moves away from t, so it meets p or leaves), with f_p(a, b) = f_inner(a', b') ⟨b, ω_p⟩⁺
//! (a', b' in p's frame) and H(w) = w − 2⟨w, ω_t⟩ω_t the mirror on t:
//!
//! f(wo, wi) cos θi = λ_p(wo) f_p(wo, wi) G1(wi)                                      (wo → p → wi)
//!                  + λ_p(wo) f_p(wo, H(wi)) (1 − G1(H(wi))) G1(wi)    if ⟨wi, ω_t⟩ > 0  (wo → p → t → wi)
//!                  + λ_t(wo) f_p(H(wo), wi) G1(wi)                    if ⟨wo, ω_t⟩ > 0  (wo → t → p → wi)
//!                  + λ_t(wo) f_p(H(wo), H(wi)) (1 − G1(H(wi))) G1(wi)  if both > 0      (wo → t → p → t → wi)
//!
//! (\[Schussler2017\] §4 evaluates the first three explicitly; the fourth is the same walk's last
//! single-scattering path.) Each term is a path probability times the inner BxDF, so
//! ∫ f cos θi ≤ λ_p E_inner(wo) + λ_t E_inner(H(wo)) ≤ 1 for an inner albedo E_inner ≤ 1.
//!
//! With a Lambertian inner of albedo ρ these four paths sum to the constant ρ cos θp / π: G1(w) =
//! cos θ cos θp / a(w) exactly (a(w) ≥ cos θ cos θp, so the min never clips), the escape density
//! after p is a(wi) G1(wi) / π = cos θp cos θi / π for every wi, and λ_p + λ_t = 1. So cos θp is
//! the share of a p event's light that leaves the microsurface; the rest meets p again, where a
//! Lambertian facet forgets the incoming direction. The whole walk is then the geometric series
//! ρ cos θp / π · Σ_k (ρ (1 − cos θp))^k = ρ cos θp / (π (1 − ρ (1 − cos θp))): with
//! [`NormalMapMicrofacet::with_multiple_bounces`] (Lambertian inner only) `eval` adds the paths
//! with two or more p events in this closed form, the constant f_ms = ρ² cos θp (1 − cos θp) /
//! (π (1 − ρ (1 − cos θp))), and a white inner reflects exactly 1 at every view. For any other
//! inner the paths with two or more p events are left out and their energy is lost (measured:
//! docs/bxdf.md, "Normal mapping").
//!
//! Reciprocal when the inner BxDF is: G1(w)/cos θ = cos θp / a(w), so the first and fourth terms
//! divided by cos θi are symmetric in (wo, wi) (λ_p(wo) G1(wi) / cos θi = ⟨wo, ω_p⟩ cos θp /
//! (a(wo) a(wi)); λ_t(wo) (1 − G1(H(wi))) ⟨H(wi), ω_p⟩ G1(wi) / cos θi = sin²θp ⟨wo, ω_t⟩
//! ⟨wi, ω_t⟩ cos θp / (a(wo) a(wi))), the second and third exchange under wo ↔ wi, and f_ms is a
//! constant.
//!
//! ## Sampling
//! The paper's walk needs a second random decision after the inner sample (is the sampled
//! direction shadowed?) whose probability depends on that direction, which a single `uc` cannot
//! give exactly. The sampler is instead a mixture of strategies with weights fixed by wo, whose
//! density is exact. With β(v) = min(3/4, max(1 − G1(reflect(v, ω_p)), ½ sin θp)) (the shadowed
//! share of p's mirror direction seen from v, floored so that a t bounce after p is never left
//! unsampled where it contributes) and q the probability of the multiple-bounce lobe (0 without
//! it; ρ̄ (1 − cos θp) with it, ρ̄ the mean of ρ's channels: its share of the energy),
//! - A, probability (1 − q) λ_p(wo)(1 − β(wo)): the inner sample at p, wi = the sampled direction;
//! - B, probability (1 − q) λ_p(wo) β(wo): the inner sample d at p, wi = H(d) (`None` unless d
//!   faces t);
//! - C, probability (1 − q) λ_t(wo)(1 − β(H(wo))): the inner sample at p seen from H(wo);
//! - D, probability (1 − q) λ_t(wo) β(H(wo)): the same, mirrored on t;
//! - M, probability q: a cosine-weighted direction (the multiple-bounce lobe);
//!
//! pdf(wi) = (1 − q) [λ_p (1 − β) p(wo, wi) + λ_p β p(wo, H(wi)) [⟨wi, ω_t⟩ > 0] +
//! λ_t (1 − β_t) p(H(wo), wi) + λ_t β_t p(H(wo), H(wi)) [⟨wi, ω_t⟩ > 0]] + q cos θi / π, with p
//! the inner pdf in p's frame (the mirror H keeps solid angle). The pdf is positive wherever f is.
//! The weight f cos θi / pdf is not bounded by the inner weight w: term by term it is at most
//! w · max(G1(wi)/(1 − β), (1 − G1(H(wi)))/β) / (1 − q) ≤ w · max(4, 2/sin θp) / (1 − q) for the
//! single-scattering terms and ρ² cos θp / (ρ̄ (1 − ρ (1 − cos θp))) for M; its mean is the albedo.

use super::ShadingNormal;
use crate::bxdf::{Bxdf, BxdfSample, Lambert, LobeFlags};
use crate::frame::{is_upper, reflect};
use crate::warp::square_to_cosine_hemisphere;
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// Microfacet-based normal mapping of any inner BxDF: the shading normal is facet ω_p of a
/// two-facet microsurface completed by a vertical mirror facet ω_t (module docs for the formulas,
/// what `eval` includes and the sampler).
///
/// Energy conserving (furnace ≤ the inner albedo), reciprocal when the inner BxDF is, and never
/// black at grazing views: where ω_p faces away from wo, the view reaches p through the t facet.
/// `eval` holds every path with one scattering event on p; a lossless inner therefore reflects
/// less than 1 (cos θp with a white Lambertian). Over a [`Lambert`] inner,
/// [`NormalMapMicrofacet::with_multiple_bounces`] adds the rest of the walk in closed form, so that
/// a white inner reflects exactly 1.
/// The inner BxDF must have no delta lobe (its `eval` is 0, so the paths through it vanish; its
/// `SPECULAR` samples are dropped): use [`super::NormalMapTilt`] for a mirror.
///
/// # Reference
/// \[Schussler2017\] §3 (the microsurface, λ_p, G1), §4 (the random walk and its single-scattering
/// evaluation).
///
/// # Degenerate cases
/// Non-finite or below-horizon directions: 0, pdf 0, `sample` → `None`. A shading normal equal to
/// the geometric one (sin θp = 0) gives the inner BxDF itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMapMicrofacet<B> {
    inner: B,
    shading: ShadingNormal,
    /// ω_t, horizontal and unit (x axis when sin θp = 0, where it has no area).
    wt: Vec3,
    sin_p: f32,
    cos_p: f32,
    /// f_ms, the paths with two or more p events (zero unless enabled).
    f_ms: Vec3,
    /// q, the probability of sampling the multiple-bounce lobe.
    q_ms: f32,
}

impl<B: Bxdf> NormalMapMicrofacet<B> {
    /// `inner` on facet ω_p = the shading normal of `shading`.
    pub fn new(inner: B, shading: ShadingNormal) -> Self {
        let n = shading.normal();
        let lean = glam::Vec2::new(n.x, n.y);
        let sin_p = lean.length().min(1.0);
        let wt = match (-lean).try_normalize() {
            Some(t) => Vec3::new(t.x, t.y, 0.0),
            None => Vec3::X,
        };
        NormalMapMicrofacet {
            inner,
            shading,
            wt,
            sin_p,
            cos_p: n.z,
            f_ms: Vec3::ZERO,
            q_ms: 0.0,
        }
    }

    /// The inner BxDF.
    pub fn inner(&self) -> &B {
        &self.inner
    }

    /// The shading normal (facet ω_p) and its frame.
    pub fn shading(&self) -> &ShadingNormal {
        &self.shading
    }

    /// The tangent facet ω_t (horizontal, unit).
    pub fn tangent_facet(&self) -> Vec3 {
        self.wt
    }

    /// f_ms, the constant value of the paths with two or more scattering events on p that `eval`
    /// adds (zero unless [`NormalMapMicrofacet::with_multiple_bounces`] enabled it).
    pub fn multiple_bounces(&self) -> Vec3 {
        self.f_ms
    }

    /// a(w) = ⟨w, ω_p⟩⁺ + ⟨w, ω_t⟩⁺ sin θp with its two parts.
    #[inline]
    fn areas(&self, w: Vec3) -> (f32, f32) {
        let ap = w.dot(self.shading.normal()).max(0.0);
        let at = w.dot(self.wt).max(0.0) * self.sin_p;
        (ap, at)
    }

    /// (λ_p(w), λ_t(w)): the probabilities that a ray from `w` meets facet p, resp. t, first;
    /// (0, 0) when it meets neither.
    pub fn facet_probabilities(&self, w: Vec3) -> (f32, f32) {
        let (ap, at) = self.areas(w);
        let a = ap + at;
        if a > 0.0 && a.is_finite() {
            (ap / a, at / a)
        } else {
            (0.0, 0.0)
        }
    }

    /// The microsurface's masking G1(w) = min(1, cos θ⁺ cos θp / a(w)); 0 below the horizon.
    pub fn g1(&self, w: Vec3) -> f32 {
        let (ap, at) = self.areas(w);
        let a = ap + at;
        let g = w.z.max(0.0) * self.cos_p / a;
        if g.is_finite() { g.min(1.0) } else { 0.0 }
    }

    /// H(w): the mirror image of the propagation direction `w` on facet t (z is kept exactly).
    #[inline]
    fn mirror_t(&self, w: Vec3) -> Vec3 {
        w - 2.0 * w.dot(self.wt) * self.wt
    }

    /// (f_p(a, b) = f_inner(a', b') ⟨b, ω_p⟩⁺, p_inner(a', b')) with a', b' in p's frame.
    #[inline]
    fn on_p(&self, a: Vec3, b: Vec3) -> (Vec3, f32) {
        let (sa, sb) = (self.shading.to_shading(a), self.shading.to_shading(b));
        if !(sa.z > 0.0 && sb.z > 0.0) {
            return (Vec3::ZERO, 0.0);
        }
        let (f, p) = self.inner.eval_pdf(sa, sb);
        (f * sb.z, p)
    }

    /// β(v), the share of the mirrored strategy among the samples started on facet p from `v`
    /// (module docs).
    #[inline]
    fn beta(&self, v: Vec3) -> f32 {
        let d0 = reflect(v, self.shading.normal());
        let shadowed = if d0.dot(self.wt) < 0.0 {
            1.0 - self.g1(d0)
        } else {
            0.0
        };
        shadowed.max(0.5 * self.sin_p).min(0.75)
    }

    /// The paths that scatter once on p from `v` (= wo, or H(wo) after a t bounce), weighted by
    /// `lambda`, the probability of reaching p that way: (f cos θi, pdf) of the two strategies
    /// that start there (module docs). `h_wi` is H(wi) when wi faces t.
    #[inline]
    fn via_p(&self, v: Vec3, lambda: f32, wi: Vec3, g1_i: f32, h_wi: Option<Vec3>) -> (Vec3, f32) {
        let beta = self.beta(v);
        let (fp, pp) = self.on_p(v, wi);
        let (mut f, mut pdf) = (fp * (lambda * g1_i), lambda * (1.0 - beta) * pp);
        if let Some(d) = h_wi {
            let (fd, pd) = self.on_p(v, d);
            f += fd * (lambda * (1.0 - self.g1(d)) * g1_i);
            pdf += lambda * beta * pd;
        }
        (f, pdf)
    }

    /// f(wo, wi) and pdf(wo, wi) together (module docs).
    fn terms(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !(is_upper(wo) && is_upper(wi)) {
            return (Vec3::ZERO, 0.0);
        }
        let (lp, lt) = self.facet_probabilities(wo);
        let g1_i = self.g1(wi);
        let h_wi = (wi.dot(self.wt) > 0.0).then(|| self.mirror_t(wi));
        let (mut f, mut pdf) = (Vec3::ZERO, 0.0f32);
        if lp > 0.0 {
            let (fa, pa) = self.via_p(wo, lp, wi, g1_i, h_wi);
            f += fa;
            pdf += pa;
        }
        if lt > 0.0 {
            let (fc, pc) = self.via_p(self.mirror_t(wo), lt, wi, g1_i, h_wi);
            f += fc;
            pdf += pc;
        }
        let f = f / wi.z;
        let f = if f.is_finite() { f } else { Vec3::ZERO };
        let pdf = (1.0 - self.q_ms) * pdf + self.q_ms * wi.z * FRAC_1_PI;
        let pdf = if pdf.is_finite() && pdf > 0.0 {
            pdf
        } else {
            0.0
        };
        (f + self.f_ms, pdf)
    }

    /// The strategy `uc` picks, with `uc` rescaled into [0, 1) for the inner sampler:
    /// 0 = A, 1 = B, 2 = C, 3 = D, 4 = M (module docs).
    #[inline]
    fn choose(&self, wo: Vec3, uc: f32) -> Option<(u8, f32)> {
        let (lp, lt) = self.facet_probabilities(wo);
        if lp + lt <= 0.0 || !uc.is_finite() {
            return None;
        }
        let below_one = |x: f32| x.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let uc = below_one(uc);
        if uc < self.q_ms {
            return Some((4, uc));
        }
        let uc = below_one((uc - self.q_ms) / (1.0 - self.q_ms));
        let (bp, bt) = (self.beta(wo), self.beta(self.mirror_t(wo)));
        let weights = [lp * (1.0 - bp), lp * bp, lt * (1.0 - bt), lt * bt];
        // The last strategy with a weight takes what rounding leaves above the weights' sum.
        let last = weights.iter().rposition(|&w| w > 0.0)?;
        let mut start = 0.0;
        for (k, w) in weights.into_iter().enumerate() {
            if w > 0.0 && (uc < start + w || k == last) {
                return Some((k as u8, below_one((uc - start) / w)));
            }
            start += w;
        }
        None
    }
}

impl NormalMapMicrofacet<Lambert> {
    /// Adds the paths of the walk with two or more scattering events on p, in closed form for a
    /// Lambertian inner of albedo ρ: the constant f_ms = ρ² cos θp (1 − cos θp) / (π (1 − ρ (1 −
    /// cos θp))), so that the whole BRDF is ρ cos θp / (π (1 − ρ (1 − cos θp))) and a white inner
    /// reflects exactly 1 at every view (module docs for the derivation). The sampler draws the
    /// added lobe (cosine-weighted) with probability ρ̄ (1 − cos θp), ρ̄ the mean of ρ's channels.
    /// Reciprocal (f_ms is a constant).
    ///
    /// # Reference
    /// \[Schussler2017\] §4 (the random walk on the two facets), summed for a Lambertian facet.
    pub fn with_multiple_bounces(self) -> Self {
        let rho = self.inner.albedo();
        let (c, lost) = (self.cos_p, 1.0 - self.cos_p);
        // 1 − ρ (1 − c) ≥ c > 0 for ρ ≤ 1, formed as (1 − ρ) + ρ c to keep its digits.
        let denom = (Vec3::ONE - rho) + rho * c;
        let f_ms = rho * rho * (c * lost * FRAC_1_PI) / denom;
        // q = 1 (a shading normal within f32 rounding of the horizon) samples the lobe alone; the
        // pdf stays positive wherever f is (it holds q cos θi / π).
        let q_ms = (rho.element_sum() / 3.0 * lost).clamp(0.0, 1.0);
        let ok = f_ms.is_finite() && f_ms.min_element() >= 0.0;
        NormalMapMicrofacet {
            f_ms: if ok { f_ms } else { Vec3::ZERO },
            q_ms: if ok { q_ms } else { 0.0 },
            ..self
        }
    }
}

impl<B: Bxdf> Bxdf for NormalMapMicrofacet<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.terms(wo, wi).0
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.terms(wo, wi).1
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        self.terms(wo, wi)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite()) {
            return None;
        }
        let (strategy, uc) = self.choose(wo, uc)?;
        let (wi, flags) = if strategy == 4 {
            (
                square_to_cosine_hemisphere(u),
                LobeFlags::REFLECTION | LobeFlags::DIFFUSE,
            )
        } else {
            let from = if strategy >= 2 { self.mirror_t(wo) } else { wo };
            let so = self.shading.to_shading(from);
            if so.z <= 0.0 {
                return None;
            }
            let s = self.inner.sample(so, uc, u)?;
            if s.flags.contains(LobeFlags::SPECULAR) {
                return None;
            }
            let d = self.shading.to_geometric(s.wi);
            if strategy == 1 || strategy == 3 {
                if d.dot(self.wt) >= 0.0 {
                    return None;
                }
                (self.mirror_t(d), s.flags)
            } else {
                (d, s.flags)
            }
        };
        let (f, pdf) = self.terms(wo, wi);
        BxdfSample::checked(wi, f, pdf, flags)
    }
}
