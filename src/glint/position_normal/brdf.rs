//! The position-normal BRDF as \[Yan2016\] publishes it: f = F G D_P / (4 cos θo cos θi), with G the
//! Smith term of a fixed, footprint-independent Beckmann lobe. Kept as its own type so that its
//! known energy error (\[Chermain2019\] §1, Fig. 3) is reproduced and measured, not hidden.

use crate::bxdf::{Bxdf, BxdfSample, LobeFlags};
use crate::error::Result;
use crate::frame::{half_vector_cos, is_upper, reflect};
use crate::fresnel::Fresnel;
use crate::ndf::{Beckmann, Ndf};
use glam::{Vec2, Vec3};

/// Default α of the Beckmann lobe whose separable Smith term masks the published BRDF: 0.1 (the
/// default `alpha` of the authors' released Mitsuba 2 adaptation, whose masking lobe is independent
/// of the footprint and of the normal map).
pub const DEFAULT_MASKING_ALPHA: f32 = 0.1;

/// The BRDF of \[Yan2016\]: f(wo, wi) = F(wo·h) G(wo, wi, h) D_P(h) / (4 cos θo cos θi).
///
/// D_P is any NDF (normally a [`super::PositionNormalPatch`]); G = G1(wo, h) G1(wi, h) is the
/// separable Smith term of an isotropic Beckmann lobe of fixed α ([`DEFAULT_MASKING_ALPHA`]), and the
/// normalisation is the geometric cos θo cos θi, not the patch's projected area. Neither depends on the
/// footprint, so the BRDF neither conserves nor normalises energy: where the patch's mean normal is
/// tilted, its white-furnace albedo can exceed 1 (\[Chermain2019\] Fig. 3; tabulated in
/// docs/results.md). For an energy-consistent alternative use
/// `MicrofacetBrdf::new(patch, fresnel)`.
///
/// Sampling as published: m ~ D_P(m) cos θm ([`Ndf::sample_normal`]: footprint position → element →
/// slope), wi = reflect(wo, m), pdf = p_m(m) / (4 |wo·m|).
///
/// # Reference
/// \[Yan2016\] §3 (BRDF), §6 (sampling); \[Walter2007\] eq. 14 (reflection Jacobian).
///
/// # Degenerate cases
/// wo, wi not strictly above the horizon, zero-length or non-finite, wo·h ≤ 0: f = 0, pdf = 0,
/// `sample` → `None`. Values that overflow `f32` are returned as 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionNormalBrdf<D, F> {
    ndf: D,
    fresnel: F,
    masking: Beckmann,
}

impl<D: Ndf, F: Fresnel> PositionNormalBrdf<D, F> {
    /// The published BRDF with the default masking lobe α = [`DEFAULT_MASKING_ALPHA`].
    pub fn new(ndf: D, fresnel: F) -> Self {
        PositionNormalBrdf {
            ndf,
            fresnel,
            // α = 0.1 is a valid Beckmann roughness; the fallback is never taken.
            masking: Beckmann::isotropic(DEFAULT_MASKING_ALPHA).unwrap_or_else(|_| unreachable!()),
        }
    }

    /// The same BRDF with the masking lobe of roughness `alpha`.
    ///
    /// # Errors
    /// As [`Beckmann::isotropic`] (`alpha` non-finite or not positive).
    pub fn with_masking_alpha(mut self, alpha: f32) -> Result<Self> {
        self.masking = Beckmann::isotropic(alpha)?;
        Ok(self)
    }

    /// The NDF.
    pub fn ndf(&self) -> &D {
        &self.ndf
    }

    /// The Beckmann lobe whose Smith term masks the BRDF.
    pub fn masking_lobe(&self) -> &Beckmann {
        &self.masking
    }

    #[inline]
    fn half(wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        if !(is_upper(wo) && is_upper(wi)) {
            return None;
        }
        // c = ‖wo + wi‖/2 rather than wo·h: exact where wi → −wo (frame::half_vector_cos) and
        // symmetric in (wo, wi), so F(c) and the Jacobian 1/(4c) stay reciprocal to the last bit.
        let (h, c) = half_vector_cos(wo, wi)?;
        (c > 0.0).then_some((h, c))
    }

    #[inline]
    fn eval_at(&self, wo: Vec3, wi: Vec3, h: Vec3, c: f32) -> Vec3 {
        let d = self.ndf.d(h);
        if d.is_nan() || d <= 0.0 {
            return Vec3::ZERO;
        }
        let g = self.masking.g2(wo, wi, h);
        let v = self.fresnel.eval(c) * (d * g / (4.0 * wo.z * wi.z));
        if v.is_finite() { v } else { Vec3::ZERO }
    }

    #[inline]
    fn pdf_at(&self, h: Vec3, c: f32) -> f32 {
        let p = self.ndf.pdf_normal(h) / (4.0 * c);
        if p.is_finite() && p > 0.0 { p } else { 0.0 }
    }
}

impl<D: Ndf, F: Fresnel> Bxdf for PositionNormalBrdf<D, F> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match Self::half(wo, wi) {
            Some((h, c)) => self.eval_at(wo, wi, h, c),
            None => Vec3::ZERO,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match Self::half(wo, wi) {
            Some((h, c)) => self.pdf_at(h, c),
            None => 0.0,
        }
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        match Self::half(wo, wi) {
            Some((h, c)) => (self.eval_at(wo, wi, h, c), self.pdf_at(h, c)),
            None => (Vec3::ZERO, 0.0),
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite()) {
            return None;
        }
        let m = self.ndf.sample_normal(u);
        if !(m.is_finite() && m.z > 0.0 && wo.dot(m) > 0.0) {
            return None;
        }
        let wi = reflect(wo, m);
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, LobeFlags::REFLECTION | LobeFlags::GLOSSY)
    }
}
