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
//! The paper's explicit evaluation: every path with one scattering event on facet p (the inner
//! BxDF, in p's frame) and at most one mirror bounce on facet t, with f_p(a, b) = f_inner(a', b')
//! ⟨b, ω_p⟩⁺ (a', b' in p's frame) and H(w) = w − 2⟨w, ω_t⟩ω_t the mirror on t:
//!
//! f(wo, wi) cos θi = λ_p(wo) f_p(wo, wi) G1(wi)                                   (wo → p → wi)
//!                  + λ_p(wo) f_p(wo, H(wi)) (1 − G1(H(wi))) G1(wi)  if ⟨wi, ω_t⟩ > 0   (wo → p → t → wi)
//!                  + λ_t(wo) f_p(H(wo), wi) G1(wi)                  if ⟨wo, ω_t⟩ > 0   (wo → t → p → wi)
//!
//! (\[Schussler2017\] §4, the three single-scattering paths). The full model is a random walk on
//! the two facets; the paths it continues after these (a ray that the microsurface shadows again
//! after its t bounce, or after p when it came from t) are left out, so the furnace with a lossless
//! inner BxDF is 1 minus their probability (measured: docs/bxdf.md, "Normal mapping"). Each term is
//! a path probability times the inner BxDF, so ∫ f cos θi ≤ λ_p E_inner(wo) + λ_t E_inner(H(wo))
//! ≤ 1 for an inner albedo E_inner ≤ 1. Reciprocal when the inner BxDF is: the first term is
//! symmetric in (wo, wi) (λ_p(wo) G1(wi) / cos θi = ⟨wo, ω_p⟩ cos θp / (a(wo) a(wi)) ⟨·⟩), and the
//! second and third exchange under wo ↔ wi.
//!
//! ## Sampling
//! The paper's walk needs a second random decision after the inner sample (is the sampled
//! direction shadowed?) whose probability depends on that direction, which a single `uc` cannot
//! give exactly. The sampler is instead a mixture of three strategies with weights fixed by wo,
//! whose density is exact: with β = min(3/4, max(1 − G1(reflect(wo, ω_p)), ½ sin θp)) (the
//! shadowed share of p's mirror direction, floored so that the t bounce is never left unsampled
//! where it contributes),
//! - A, probability λ_p(wo)(1 − β): the inner sample at p, wi = the sampled direction;
//! - B, probability λ_p(wo) β: the inner sample d at p, wi = H(d) (`None` unless d faces t);
//! - C, probability λ_t(wo): the inner sample at p seen from H(wo);
//!
//! pdf(wi) = λ_p(1 − β) p(wo, wi) + λ_p β p(wo, H(wi)) [⟨wi, ω_t⟩ > 0] + λ_t p(H(wo), wi), with p
//! the inner pdf in p's frame (the mirror H keeps solid angle). The pdf is positive wherever f is.
//! The weight f cos θi / pdf is not bounded by the inner weight w: term by term (f is the sum of
//! three terms, the pdf of three matching ones) it is at most w · max(G1(wi)/(1 − β),
//! (1 − G1(H(wi)))/β, G1(wi)) ≤ w · max(4, 2/sin θp); its mean is the albedo.

use super::ShadingNormal;
use crate::bxdf::{Bxdf, BxdfSample, LobeFlags};
use crate::frame::{is_upper, reflect};
use glam::{Vec2, Vec3};

/// Microfacet-based normal mapping of any inner BxDF: the shading normal is facet ω_p of a
/// two-facet microsurface completed by a vertical mirror facet ω_t (module docs for the formulas,
/// what `eval` includes and the sampler).
///
/// Energy conserving (furnace ≤ the inner albedo), reciprocal when the inner BxDF is, and never
/// black at grazing views: where ω_p faces away from wo, the view reaches p through the t facet.
/// The inner BxDF must have no delta lobe (its `eval` is 0, so the paths through it vanish; its
/// `SPECULAR` samples are dropped): use [`super::NormalMapTilt`] for a mirror.
///
/// # Reference
/// \[Schussler2017\] §3 (the microsurface, λ_p, G1), §4 (the single-scattering evaluation).
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

    /// β, the share of strategy B among the samples started on facet p (module docs).
    #[inline]
    fn beta(&self, wo: Vec3) -> f32 {
        let d0 = reflect(wo, self.shading.normal());
        let shadowed = if d0.dot(self.wt) < 0.0 {
            1.0 - self.g1(d0)
        } else {
            0.0
        };
        shadowed.max(0.5 * self.sin_p).min(0.75)
    }

    /// f(wo, wi) and pdf(wo, wi) together (module docs).
    fn terms(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !(is_upper(wo) && is_upper(wi)) {
            return (Vec3::ZERO, 0.0);
        }
        let (lp, lt) = self.facet_probabilities(wo);
        let beta = self.beta(wo);
        let g1_i = self.g1(wi);
        let (mut f, mut pdf) = (Vec3::ZERO, 0.0f32);
        if lp > 0.0 {
            let (fp, pp) = self.on_p(wo, wi);
            f += fp * (lp * g1_i);
            pdf += lp * (1.0 - beta) * pp;
            if wi.dot(self.wt) > 0.0 {
                let d = self.mirror_t(wi);
                let (fd, pd) = self.on_p(wo, d);
                f += fd * (lp * (1.0 - self.g1(d)) * g1_i);
                pdf += lp * beta * pd;
            }
        }
        if lt > 0.0 {
            let (fo, po) = self.on_p(self.mirror_t(wo), wi);
            f += fo * (lt * g1_i);
            pdf += lt * po;
        }
        let f = f / wi.z;
        let f = if f.is_finite() { f } else { Vec3::ZERO };
        let pdf = if pdf.is_finite() && pdf > 0.0 {
            pdf
        } else {
            0.0
        };
        (f, pdf)
    }

    /// The strategy `uc` picks, with `uc` rescaled into [0, 1) for the inner sampler:
    /// 0 = A, 1 = B, 2 = C (module docs).
    #[inline]
    fn choose(&self, wo: Vec3, uc: f32) -> Option<(u8, f32)> {
        let (lp, lt) = self.facet_probabilities(wo);
        if lp + lt <= 0.0 || !uc.is_finite() {
            return None;
        }
        let beta = self.beta(wo);
        let (pa, pb) = (lp * (1.0 - beta), lp * beta);
        let below_one = |x: f32| x.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let uc = below_one(uc);
        if uc < pa {
            Some((0, below_one(uc / pa)))
        } else if uc < pa + pb {
            Some((1, below_one((uc - pa) / pb)))
        } else if lt > 0.0 {
            Some((2, below_one((uc - pa - pb) / lt)))
        } else {
            None
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
        let from = if strategy == 2 { self.mirror_t(wo) } else { wo };
        let so = self.shading.to_shading(from);
        if so.z <= 0.0 {
            return None;
        }
        let s = self.inner.sample(so, uc, u)?;
        if s.flags.contains(LobeFlags::SPECULAR) {
            return None;
        }
        let d = self.shading.to_geometric(s.wi);
        let wi = if strategy == 1 {
            if d.dot(self.wt) >= 0.0 {
                return None;
            }
            self.mirror_t(d)
        } else {
            d
        };
        let (f, pdf) = self.terms(wo, wi);
        BxdfSample::checked(wi, f, pdf, s.flags)
    }
}
