//! The smooth limit: perfect specular reflection off a flat interface, a delta lobe behind the
//! [`Bxdf`] trait, generic over the Fresnel term (a polished conductor with [`ConductorFresnel`],
//! the reflection of a smooth dielectric with [`DielectricFresnel`]).
//!
//! ## The delta-lobe convention
//! A delta lobe reflects all its energy into the single direction wi = reflect(wo, z) = (−wo.x,
//! −wo.y, wo.z). It has no density with respect to solid angle, so, as in pbrt-v4
//! (\[Pharr2023\] §9.1.2, "Specular reflection and transmission"):
//! - `eval(wo, wi)` and `pdf(wo, wi)` are 0 for every given pair of directions (the probability
//!   that a direction chosen by another strategy, a light sample say, is exactly the mirror
//!   direction is 0);
//! - `sample(wo, ..)` returns wi = reflect(wo, z) with `pdf` = 1 (the discrete probability of the
//!   lobe), `f` = F(cos θo) / cos θi and flags `SPECULAR | REFLECTION`, so that
//!   [`BxdfSample::weight`] = f cos θi / pdf = F(cos θo), to rounding (one f32 division and one
//!   f64 product: within 2⁻²³ relative);
//! - a renderer must not combine a `SPECULAR` sample with multiple importance sampling or next-event
//!   estimation: it multiplies the path throughput by `weight()` and follows wi, and it skips light
//!   sampling at this vertex (its `eval` would return 0 anyway, so doing it wastes work but adds no
//!   bias). MIS weights of a `SPECULAR` sample are 1.
//!
//! The sample's `f` and `pdf` are therefore *not* what `eval` and `pdf` return at its wi (they
//! return 0): the agreement promised by [`Bxdf::sample`] holds for every non-`SPECULAR` sample
//! only.
//!
//! ## Energy
//! The weight is F(cos θo) ≤ 1 (every [`Fresnel`] is in [0, 1]), so the lobe conserves energy and
//! reflects exactly F: no masking, no loss. With a dielectric Fresnel only the reflected part is
//! modelled: the transmitted fraction 1 − F enters the material and is not returned by this BxDF
//! (the crate models reflection only); layer it over a base (as [`super::LayeredBrdf`] does for
//! rough coats) or let the renderer's transmission handle it.
//!
//! ## Smooth limit of the microfacet BRDF
//! [`super::MicrofacetBrdf`] with GGX or Beckmann converges to this lobe as α → 0: ∫ f L cos θi dωi
//! → F(cos θo) L(reflect(wo)) for a smooth environment L, with an error O(α²) for Beckmann and
//! O(α² ln(1/α)) for GGX (the second moment of the slope distribution; GGX's is infinite and is
//! cut by the hemisphere). tests/it/specular.rs measures it; docs/bxdf.md, "Delta lobes", has the
//! figures.

use super::{Bxdf, BxdfSample, LobeFlags};
use crate::frame::is_upper;
use crate::fresnel::Fresnel;
#[cfg(doc)]
use crate::fresnel::{ConductorFresnel, DielectricFresnel};
use glam::{Vec2, Vec3};

/// Perfect specular reflection: a delta lobe at wi = reflect(wo, z) with weight F(cos θo).
///
/// `eval` and `pdf` are 0 for every pair of directions; `sample` returns the mirror direction with
/// `pdf` = 1, `f` = F(cos θo)/cos θi and flags `SPECULAR | REFLECTION`, so that `weight()` =
/// F(cos θo) (module docs: the delta-lobe convention, and what a renderer must do with it).
///
/// # Reference
/// \[Pharr2023\] §9.1.2 (the convention for specular BxDFs); \[BornWolf1999\] §1.5 (the law of
/// reflection and the Fresnel reflectance).
///
/// # Degenerate cases
/// `wo` not strictly above the horizon, zero-length or non-finite, or `u` non-finite: `sample`
/// returns `None`. A view so grazing that F/cos θi overflows f32 (cos θo below ~3·10⁻³⁹, subnormal)
/// also returns `None`.
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, LobeFlags, SpecularReflection};
/// use brdf::fresnel::{ConductorFresnel, Fresnel};
/// use brdf::{Vec2, Vec3};
///
/// let mirror = SpecularReflection::new(ConductorFresnel::SILVER);
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// let s = mirror.sample(wo, 0.5, Vec2::new(0.3, 0.7)).unwrap();
/// assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8));
/// assert!(s.flags.contains(LobeFlags::SPECULAR));
/// let f = ConductorFresnel::SILVER.eval(0.8);
/// assert!((s.weight() - f).abs().max_element() < 1e-6);
/// // A delta has no density: eval and pdf are 0 even at the mirror direction.
/// assert_eq!(mirror.eval(wo, s.wi), Vec3::ZERO);
/// assert_eq!(mirror.pdf(wo, s.wi), 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularReflection<F> {
    fresnel: F,
}

impl<F: Fresnel> SpecularReflection<F> {
    /// A smooth reflector with Fresnel term `fresnel` (a valid [`Fresnel`] value is already checked
    /// by its own constructor, so this one cannot fail).
    pub fn new(fresnel: F) -> Self {
        SpecularReflection { fresnel }
    }

    /// The Fresnel term.
    pub fn fresnel(&self) -> &F {
        &self.fresnel
    }

    /// The reflectance F(cos θo) the lobe returns toward reflect(wo, z), i.e. the weight of its
    /// sample; 0 for a `wo` not strictly above the horizon or non-finite.
    pub fn reflectance(&self, wo: Vec3) -> Vec3 {
        if is_upper(wo) {
            self.fresnel.eval(wo.z.min(1.0))
        } else {
            Vec3::ZERO
        }
    }
}

impl<F: Fresnel> Bxdf for SpecularReflection<F> {
    /// 0: a delta lobe has no value for a given pair of directions (module docs).
    fn eval(&self, _wo: Vec3, _wi: Vec3) -> Vec3 {
        Vec3::ZERO
    }

    /// 0: a delta lobe has no density per unit solid angle (module docs).
    fn pdf(&self, _wo: Vec3, _wi: Vec3) -> f32 {
        0.0
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite()) {
            return None;
        }
        // Negating x and y is exact: wi.z = wo.z bit for bit, so f cos θi / pdf = F to rounding.
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        let f = self.reflectance(wo) / wi.z;
        BxdfSample::checked(wi, f, 1.0, LobeFlags::SPECULAR | LobeFlags::REFLECTION)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::{ConductorFresnel, DielectricFresnel};

    #[test]
    fn weight_is_fresnel() {
        let m = SpecularReflection::new(ConductorFresnel::GOLD);
        for c in [1.0f32, 0.5, 1e-3, 1e-20, 1e-30] {
            let s = (1.0 - c * c).sqrt();
            let wo = Vec3::new(s * 0.6, s * 0.8, c);
            let smp = m.sample(wo, 0.1, Vec2::new(0.2, 0.9)).unwrap();
            let f = ConductorFresnel::GOLD.eval(c);
            // One f32 division and one f64 product rounded to f32: 2 ulps.
            assert!(
                ((smp.weight() - f).abs() - f * 2.0 * f32::EPSILON).max_element() <= 0.0,
                "{c}: {} vs {f}",
                smp.weight()
            );
            assert_eq!(smp.pdf, 1.0);
        }
    }

    #[test]
    fn dielectric_reflects_its_fresnel_fraction() {
        let m = SpecularReflection::new(DielectricFresnel::new(1.5).unwrap());
        let s = m.sample(Vec3::Z, 0.5, Vec2::ZERO).unwrap();
        assert!((s.weight().x - 0.04).abs() < 1e-6);
    }
}
