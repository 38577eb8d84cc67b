//! Energy compensation from the NDF's own albedo toward the view: for microfacet BRDFs whose NDF
//! has no albedo table (a glint patch's P-NDF changes with every footprint), the energy single
//! scattering loses toward wo is given back as a Lambertian lobe,
//!
//! f = f_ss + F_ms(wo) (1 − E(wo)) / π,  F_ms = F_avg² E(wo) / (1 − F_avg (1 − E(wo))),
//!
//! with E(wo) the NDF's estimate of its single-scattering albedo ([`AlbedoEstimate`]) and F_avg the
//! Fresnel term's hemispherical average. With F = 1, ∫ f_ms cos θi dωi = 1 − E(wo) exactly, so the
//! white furnace is E_true(wo) + 1 − E(wo): 1 up to the estimate's error.
//!
//! Unlike [`EnergyCompensated`](super::EnergyCompensated)'s (1 − E(wo))(1 − E(wi)) / (π (1 − E_avg)),
//! the lobe depends on wo only, so the sum is **not reciprocal**: E_avg would need the NDF's albedo
//! over the whole hemisphere, O(directions × lobes) per glint patch, and a glint patch in the
//! renderer's measure is not reciprocal to begin with (docs/bxdf.md). F_ms is Kulla and Conty's
//! multiple-scattering Fresnel with E_avg replaced by E(wo).

use super::compensated::{average_fresnel, multiple_scattering_fresnel};
use super::lobe::lobe_probability;
use super::microfacet::{Masking, MicrofacetBrdf};
use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::{Error, Result};
use crate::frame::is_upper;
use crate::fresnel::Fresnel;
use crate::ndf::Ndf;
use crate::warp::square_to_cosine_hemisphere;
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// An NDF that can estimate its own single-scattering albedo E(wo) = ∫ f_ss(wo, wi) cos θi dωi of
/// the microfacet BRDF it makes with F = 1 and height-correlated masking (the white furnace a
/// renderer computes, [`MicrofacetBrdf`]'s convention).
///
/// Implemented by every glint patch ([`crate::glint::GlintPatch`] and each model's patch type):
/// O(lobes), the cubature of src/glint/kernels/albedo.rs (error measured in docs/results.md,
/// "Energy compensation of glint patches").
pub trait AlbedoEstimate: Ndf {
    /// E(wo) in [0, 1]; 1 where there is nothing to give back (wo not above the horizon).
    fn albedo_estimate(&self, wo: Vec3) -> f32;
}

/// A microfacet BRDF with the energy its single scattering loses toward the view given back as a
/// Lambertian lobe of albedo F_ms (1 − E(wo)) (module docs): opt-in, not reciprocal.
///
/// E is estimated once, for the view given to [`ViewCompensated::new`] (the shading point's wo:
/// [`crate::material::GlintMaterial::with_energy_compensation`] does this per shading point);
/// queries at another view estimate their own (O(lobes) each), so every value is what the BRDF
/// prepared for that view returns.
///
/// Sampling: the single-scattering sampler with probability p = s / (s + d), s = E(wo) mean(F_avg),
/// d = (1 − E(wo)) mean(F_ms), else the cosine hemisphere; pdf = p pdf_ss + (1 − p) cos θi/π.
/// Samples of the Lambertian lobe carry [`LobeFlags::DIFFUSE`].
///
/// # Reference
/// \[KullaConty2017\] (the compensation lobe's energy, F_avg, F_ms).
///
/// # Degenerate cases
/// As [`MicrofacetBrdf`]: `wo` or `wi` not strictly above the horizon or non-finite → 0, pdf 0,
/// `sample` → `None`.
#[derive(Clone, Debug)]
pub struct ViewCompensated<D, F> {
    brdf: MicrofacetBrdf<D, F>,
    f_avg: Vec3,
    /// The bits of the view E was estimated for, and E there.
    view: ([u32; 3], f32),
}

/// The compensation lobe's value F_ms (1 − E)/π for a Fresnel average `f_avg` and albedo `e`, with
/// F_ms Kulla and Conty's multiple-scattering Fresnel at E_avg = `e` (shared with
/// [`LayeredBrdf::with_energy_compensation`](super::LayeredBrdf::with_energy_compensation)).
#[inline]
pub(super) fn multiple_scattering_lobe(f_avg: Vec3, e: f32) -> Vec3 {
    multiple_scattering_fresnel(f_avg, e) * ((1.0 - e) * FRAC_1_PI)
}

/// The bits of a direction (the key of the prepared view).
fn key_of(w: Vec3) -> [u32; 3] {
    [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()]
}

impl<D: AlbedoEstimate, F: Fresnel> ViewCompensated<D, F> {
    /// Compensates `brdf`, prepared for the view `wo` (shading frame); computes F_avg from its
    /// Fresnel term (1,024 evaluations: a renderer that makes one per shading point passes the
    /// material's F_avg to [`ViewCompensated::with_fresnel_average`] instead).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `masking` if the BRDF uses [`Masking::Separable`] (the
    /// estimate is of height-correlated masking).
    pub fn new(brdf: MicrofacetBrdf<D, F>, wo: Vec3) -> Result<Self> {
        let f_avg = average_fresnel(brdf.fresnel());
        Self::with_fresnel_average(brdf, f_avg, wo)
    }

    /// [`ViewCompensated::new`] with the Fresnel term's average F_avg = 2 ∫₀¹ F(μ) μ dμ given
    /// ([`average_fresnel`]).
    ///
    /// # Errors
    /// As [`ViewCompensated::new`], and [`Error::InvalidParameter`] naming `f_avg` unless every
    /// channel is finite and in [0, 1].
    pub fn with_fresnel_average(brdf: MicrofacetBrdf<D, F>, f_avg: Vec3, wo: Vec3) -> Result<Self> {
        if brdf.masking() != Masking::HeightCorrelated {
            return Err(Error::InvalidParameter {
                name: "masking",
                value: 0.0,
                reason: "the albedo estimate is of height-correlated masking only",
            });
        }
        let f_avg = super::unit_rgb("f_avg", f_avg)?;
        Ok(Self::from_valid(brdf, f_avg, wo))
    }

    /// [`ViewCompensated::with_fresnel_average`] for arguments the caller has validated.
    pub(crate) fn from_valid(brdf: MicrofacetBrdf<D, F>, f_avg: Vec3, wo: Vec3) -> Self {
        let e = brdf.ndf().albedo_estimate(wo);
        ViewCompensated {
            brdf,
            f_avg,
            view: (key_of(wo), e),
        }
    }

    /// The single-scattering BRDF.
    pub fn single_scattering(&self) -> &MicrofacetBrdf<D, F> {
        &self.brdf
    }

    /// The Fresnel average F_avg.
    pub fn average_fresnel(&self) -> Vec3 {
        self.f_avg
    }

    /// The estimate E(wo) the compensation uses: the prepared one at the prepared view.
    pub fn albedo(&self, wo: Vec3) -> f32 {
        if key_of(wo) == self.view.0 {
            self.view.1
        } else {
            self.brdf.ndf().albedo_estimate(wo)
        }
    }

    /// F_ms (1 − E(wo)) / π, the Lambertian lobe's value, and p, the probability of the
    /// single-scattering sampler, at `wo` (upper).
    fn lobe_and_probability(&self, wo: Vec3) -> (Vec3, f32) {
        let e = self.albedo(wo).clamp(0.0, 1.0);
        let f_ms = multiple_scattering_fresnel(self.f_avg, e);
        let lobe = multiple_scattering_lobe(self.f_avg, e);
        let mean = |v: Vec3| (v.x + v.y + v.z) / 3.0;
        let p = lobe_probability(
            (1.0 - e) * mean(f_ms),
            e * mean(self.f_avg).max(f32::MIN_POSITIVE),
        );
        (lobe, p)
    }
}

impl<D: AlbedoEstimate, F: Fresnel> Bxdf for ViewCompensated<D, F> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.eval_pdf(wo, wi).0
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).1
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !(is_upper(wo) && is_upper(wi)) {
            return (Vec3::ZERO, 0.0);
        }
        let (fs, ps) = self.brdf.eval_pdf(wo, wi);
        let (lobe, p) = self.lobe_and_probability(wo);
        let pdf = p * ps + (1.0 - p) * wi.z * FRAC_1_PI;
        (fs + lobe, pdf)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite() && uc.is_finite()) {
            return None;
        }
        let (_, p) = self.lobe_and_probability(wo);
        let (wi, flags) = if uc < p {
            let s = self.brdf.sample(wo, uc / p, u)?;
            (s.wi, s.flags)
        } else {
            (
                square_to_cosine_hemisphere(u),
                LobeFlags::REFLECTION | LobeFlags::DIFFUSE,
            )
        };
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, flags)
    }
}
