//! Conventional normal mapping: the inner BxDF evaluated in the frame of the shading normal.

use super::ShadingNormal;
use crate::bxdf::{Bxdf, BxdfSample, LobeFlags};
use crate::frame::is_upper;
use glam::{Vec2, Vec3};

/// Conventional ("tilt the frame") normal mapping of any inner BxDF.
///
/// With n the shading normal and w' = the direction w in the shading frame (z' = n),
///
/// f(wo, wi) = f_inner(wo', wi') · ⟨wi, n⟩ / cos θi,
///
/// so that the renderer's integral ∫ f L cos θi dωi (geometric cosine, the crate's measure) is
/// ∫ f_inner L ⟨wi, n⟩ dωi: the inner BxDF with the *shading* cosine, which is what pbrt-v4 and
/// Mitsuba 3 compute for a normal-mapped surface. f = 0 when wo or wi is at or below the geometric
/// horizon (the surface does not reflect there) or the shading horizon (the inner BxDF does not):
/// the black regions of normal mapping at grazing views, and an energy loss wherever the shading
/// hemisphere pokes below the geometric one. Not reciprocal in general (⟨wi, n⟩/cos θi is not
/// symmetric); energy conserving when the inner BxDF is (∫ f_inner ⟨wi, n⟩ over a part of the
/// shading hemisphere).
///
/// Sampling: the inner sampler in the shading frame, rotated back; `None` when the direction is
/// at or below the geometric horizon. The pdf is the inner pdf (a rotation keeps solid angle), so
/// the weight f cos θi / pdf is the inner weight. A `SPECULAR` inner sample keeps its convention
/// (its `f` is rescaled so that the weight stays the inner weight; `pdf` unchanged).
///
/// # Reference
/// \[Blinn1978\] (shading normals); \[Pharr2023\] §10.5.3 (normal mapping: the BSDF in the shading
/// frame, the shading cosine in the integrator).
///
/// # Degenerate cases
/// Non-finite or below-horizon directions (geometric or shading): 0, pdf 0, `sample` → `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalMapTilt<B> {
    inner: B,
    shading: ShadingNormal,
}

impl<B: Bxdf> NormalMapTilt<B> {
    /// `inner` evaluated about the shading normal `shading`.
    pub fn new(inner: B, shading: ShadingNormal) -> Self {
        NormalMapTilt { inner, shading }
    }

    /// The inner BxDF.
    pub fn inner(&self) -> &B {
        &self.inner
    }

    /// The shading normal and frame.
    pub fn shading(&self) -> &ShadingNormal {
        &self.shading
    }

    /// (wo', wi') in the shading frame when both directions are above both horizons.
    #[inline]
    fn local(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
        if !(is_upper(wo) && is_upper(wi)) {
            return None;
        }
        let (so, si) = (self.shading.to_shading(wo), self.shading.to_shading(wi));
        (so.z > 0.0 && si.z > 0.0).then_some((so, si))
    }
}

/// ⟨wi, n⟩ / cos θi, the shading over the geometric cosine; 0 where it is not finite.
#[inline]
fn cosine_ratio(shading_cos: f32, geometric_cos: f32) -> f32 {
    let r = shading_cos / geometric_cos;
    if r.is_finite() { r } else { 0.0 }
}

/// `v` if finite, else 0.
#[inline]
fn finite_or_zero(v: Vec3) -> Vec3 {
    if v.is_finite() { v } else { Vec3::ZERO }
}

impl<B: Bxdf> Bxdf for NormalMapTilt<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match self.local(wo, wi) {
            Some((so, si)) => finite_or_zero(self.inner.eval(so, si) * cosine_ratio(si.z, wi.z)),
            None => Vec3::ZERO,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match self.local(wo, wi) {
            Some((so, si)) => self.inner.pdf(so, si),
            None => 0.0,
        }
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        match self.local(wo, wi) {
            Some((so, si)) => {
                let (f, p) = self.inner.eval_pdf(so, si);
                (finite_or_zero(f * cosine_ratio(si.z, wi.z)), p)
            }
            None => (Vec3::ZERO, 0.0),
        }
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !is_upper(wo) {
            return None;
        }
        let so = self.shading.to_shading(wo);
        if so.z <= 0.0 {
            return None;
        }
        let s = self.inner.sample(so, uc, u)?;
        let wi = self.shading.to_geometric(s.wi);
        if s.flags.contains(LobeFlags::SPECULAR) {
            // Delta inner lobe: keep its weight f' cos θi' / pdf (module docs of `Bxdf`).
            let f = s.f * cosine_ratio(s.wi.z, wi.z);
            return BxdfSample::checked(wi, f, s.pdf, s.flags);
        }
        // f and pdf at the rotated direction, so that they are exactly `eval` and `pdf` there.
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, s.flags)
    }
}
