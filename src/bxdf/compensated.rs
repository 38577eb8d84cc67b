//! Multiple-scattering energy compensation of the microfacet BRDF (Kulla & Conty 2017): the
//! single-scattering lobe plus a cosine-like lobe that gives back the energy masking removes,
//! coloured by the Fresnel term's hemispherical average.
//!
//! f = f_ss + F_ms · f_ms,  f_ms(wo, wi) = (1 − E(μo)) (1 − E(μi)) / (π (1 − E_avg)),
//! F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)),  F_avg = 2 ∫₀¹ F(μ) μ dμ,
//!
//! with E, E_avg the tabulated albedo of the single-scattering BRDF with F = 1 ([`AlbedoTable`] for
//! isotropic NDFs; [`AnisotropicAlbedoTable`] for anisotropic ones, where E depends on wo's azimuth
//! too and f_ms = (1 − E(wo)) (1 − E(wi)) / (π (1 − E_avg)) with E_avg averaged over μ and φ).
//! With F = 1, ∫ f_ms cos θi dωi = 1 − E(wo) exactly (E_avg is the exact average of the table's
//! interpolant), so the white furnace is E_true(wo) + 1 − E_table(wo): 1 up to the table's error.
//! f_ms is a product of the same function of wo and of wi over a constant, so it is symmetric in
//! (wo, wi) and the sum is reciprocal where f_ss is.

use super::albedo::{ALBEDO_ALPHA_MAX, AlbedoTable};
use super::albedo_anisotropic::{AnisotropicAlbedo, AnisotropicAlbedoTable};
use super::lobe::lobe_probability;
use super::microfacet::{Masking, MicrofacetBrdf};
use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::{Error, Result};
use crate::frame::is_upper;
use crate::fresnel::Fresnel;
use crate::ndf::{Beckmann, Ggx, Ndf};
use crate::warp::square_to_cosine_hemisphere;
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// Midpoints of the rule for F_avg = 2 ∫₀¹ F(μ) μ dμ: the midpoint rule's error is below
/// 10⁻⁶ for the crate's Fresnel terms (smooth in μ; Schlick's (1 − μ)⁵ has |(F μ)''| ≤ 20).
const FRESNEL_AVERAGE_POINTS: usize = 1024;

/// Below this 1 − E_avg the BRDF loses nothing worth giving back (α near the NDFs' minimum) and
/// the compensation lobe is 0, so that no quotient of two roundings is formed.
const MIN_LOSS: f32 = 1e-6;

/// An NDF whose single-scattering albedo is tabulated: the tables and the (αx, αy) to read them at.
///
/// Implemented for [`Ggx`] and [`Beckmann`]. Isotropic NDFs (αx = αy) read [`AlbedoTable`], E(μ, α);
/// anisotropic ones read [`AnisotropicAlbedoTable`], E(μ, φ, αx, αy), which follows the azimuth of
/// wo (furnace error measured in docs/results.md).
pub trait TabulatedAlbedo: Ndf {
    /// The family's isotropic table.
    fn albedo_table(&self) -> &'static AlbedoTable;
    /// The family's anisotropic table.
    fn anisotropic_albedo_table(&self) -> &'static AnisotropicAlbedoTable;
    /// (αx, αy), the roughness the tables are read at.
    fn table_alphas(&self) -> (f32, f32);
}

impl TabulatedAlbedo for Ggx {
    fn albedo_table(&self) -> &'static AlbedoTable {
        &AlbedoTable::GGX
    }
    fn anisotropic_albedo_table(&self) -> &'static AnisotropicAlbedoTable {
        &AnisotropicAlbedoTable::GGX
    }
    fn table_alphas(&self) -> (f32, f32) {
        (self.alpha_x(), self.alpha_y())
    }
}

impl TabulatedAlbedo for Beckmann {
    fn albedo_table(&self) -> &'static AlbedoTable {
        &AlbedoTable::BECKMANN
    }
    fn anisotropic_albedo_table(&self) -> &'static AnisotropicAlbedoTable {
        &AnisotropicAlbedoTable::BECKMANN
    }
    fn table_alphas(&self) -> (f32, f32) {
        (self.alpha_x(), self.alpha_y())
    }
}

/// The directional albedo E(wo) and E_avg the compensation reads: the isotropic table at α, or the
/// anisotropic table's slice at (αx, αy) (2.2 kB; with `std` boxed so that isotropic materials stay
/// small, without it inline, for there is no heap).
#[cfg_attr(not(feature = "std"), allow(clippy::large_enum_variant))]
#[derive(Clone, Debug)]
enum Albedo {
    Isotropic(&'static AlbedoTable, f32),
    Anisotropic(SliceStorage),
}

/// Where the anisotropic slice lives: on the heap with `std`, inline without it (the `no_std` core
/// does not allocate; the BRDF is then 2.2 kB larger).
#[cfg(feature = "std")]
type SliceStorage = Box<AnisotropicAlbedo>;
#[cfg(not(feature = "std"))]
type SliceStorage = AnisotropicAlbedo;

impl Albedo {
    #[inline]
    fn albedo(&self, w: Vec3) -> f32 {
        match self {
            Albedo::Isotropic(table, alpha) => table.albedo(w.z, *alpha),
            Albedo::Anisotropic(slice) => slice.albedo(w),
        }
    }

    fn average(&self) -> f32 {
        match self {
            Albedo::Isotropic(table, alpha) => table.average_albedo(*alpha),
            Albedo::Anisotropic(slice) => slice.average(),
        }
    }
}

/// The cosine-weighted hemispherical average F_avg = 2 ∫₀¹ F(μ) μ dμ of a Fresnel term, per channel,
/// by the midpoint rule on 1024 points (error < 10⁻⁶ for smooth F), clamped to [0, 1].
///
/// # Reference
/// \[KullaConty2017\], the Fresnel section of multiple scattering (F_avg).
pub fn average_fresnel(fresnel: &impl Fresnel) -> Vec3 {
    let n = FRESNEL_AVERAGE_POINTS;
    let mut sum = [0.0f64; 3];
    for k in 0..n {
        let mu = (k as f64 + 0.5) / n as f64;
        let f = fresnel.eval(mu as f32);
        for (s, c) in sum.iter_mut().zip([f.x, f.y, f.z]) {
            *s += c as f64 * mu;
        }
    }
    let avg = |s: f64| ((2.0 * s / n as f64) as f32).clamp(0.0, 1.0);
    Vec3::new(avg(sum[0]), avg(sum[1]), avg(sum[2]))
}

/// The colour of the multiple-scattering lobe, F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)):
/// the energy of the light that leaves after two or more bounces, each bounce keeping F_avg and
/// escaping with probability E_avg (a geometric series), relative to the white case (F_ms = 1 at
/// F_avg = 1).
///
/// # Reference
/// \[KullaConty2017\], the multiple-scattering Fresnel term.
pub fn multiple_scattering_fresnel(f_avg: Vec3, e_avg: f32) -> Vec3 {
    let denom = Vec3::ONE - f_avg * (1.0 - e_avg);
    let v = f_avg * f_avg * e_avg / denom.max(Vec3::splat(f32::MIN_POSITIVE));
    if v.is_finite() {
        v.clamp(Vec3::ZERO, Vec3::ONE)
    } else {
        Vec3::ZERO
    }
}

/// A microfacet BRDF with Kulla-Conty multiple-scattering energy compensation:
/// f = f_ss + F_ms (1 − E(wo)) (1 − E(wi)) / (π (1 − E_avg)) (module docs).
///
/// Anisotropic NDFs read the anisotropic table's slice at (αx, αy), built in `new` (a 2.2 kB
/// slice, boxed with the `std` feature and inline without it; the type is `Clone`, not `Copy`);
/// isotropic ones read the isotropic table.
///
/// Opt-in: [`MicrofacetBrdf`] stays the single-scattering model that matches pbrt-v4 and Mitsuba 3;
/// wrap it to give back the energy its masking removes (white furnace 1 within 0.5 % for
/// α ∈ [0.01, 1], θo ≤ 85°, isotropic; the anisotropic error is measured in docs/results.md).
///
/// Sampling: a mixture of the single-scattering sampler (probability p) and the cosine-weighted
/// hemisphere (1 − p), p = s / (s + d) with s = E(wo) · mean(F_avg) and d = (1 − E(wo)) · mean(F_ms),
/// the two lobes' approximate albedos; `pdf` is p · pdf_ss + (1 − p) cos θi / π. Samples of the
/// compensation lobe carry [`LobeFlags::DIFFUSE`].
///
/// # Reference
/// \[KullaConty2017\] (energy compensation, F_avg, F_ms).
///
/// # Degenerate cases
/// As [`MicrofacetBrdf`]: `wo` or `wi` not strictly above the horizon or non-finite → 0, pdf 0,
/// `sample` → `None`. Table lookups are clamped (μ to [0, 1], α to the tables' range).
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, EnergyCompensated, MicrofacetBrdf};
/// use brdf::fresnel::NoFresnel;
/// use brdf::ndf::Ggx;
/// use brdf::{Vec2, Vec3};
///
/// let brdf = EnergyCompensated::new(MicrofacetBrdf::new(Ggx::isotropic(0.8)?, NoFresnel))?;
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// // The compensation lobe gives back what single scattering loses at this view.
/// assert!(brdf.albedo(wo) < 1.0 && brdf.multiple_scattering_fresnel() == Vec3::ONE);
/// if let Some(s) = brdf.sample(wo, 0.9, Vec2::new(0.3, 0.7)) {
///     assert_eq!((s.f, s.pdf), brdf.eval_pdf(wo, s.wi));
/// }
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct EnergyCompensated<D, F> {
    brdf: MicrofacetBrdf<D, F>,
    albedo: Albedo,
    e_avg: f32,
    f_avg: Vec3,
    f_ms: Vec3,
    /// F_ms / (π (1 − E_avg)), 0 when 1 − E_avg < [`MIN_LOSS`].
    scale: Vec3,
}

impl<D: TabulatedAlbedo, F: Fresnel> EnergyCompensated<D, F> {
    /// Compensates `brdf`; computes F_avg from its Fresnel term and reads E_avg once.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `masking` if the BRDF uses [`Masking::Separable`] (the
    /// tables are for height-correlated masking), or `alpha_x` / `alpha_y` if either exceeds
    /// [`ALBEDO_ALPHA_MAX`] = 1 (the tables' range; α below the tables' minimum cannot occur for
    /// isotropic NDFs, which clamp α to the same minimum; anisotropic α below
    /// [`ANISO_ALPHA_LOW`](super::ANISO_ALPHA_LOW) reads that node).
    pub fn new(brdf: MicrofacetBrdf<D, F>) -> Result<Self> {
        if brdf.masking() != Masking::HeightCorrelated {
            return Err(Error::InvalidParameter {
                name: "masking",
                value: 0.0,
                reason: "energy compensation is tabulated for height-correlated masking only",
            });
        }
        let (alpha_x, alpha_y) = brdf.ndf().table_alphas();
        for (name, alpha) in [("alpha_x", alpha_x), ("alpha_y", alpha_y)] {
            if !(alpha.is_finite() && alpha <= ALBEDO_ALPHA_MAX) {
                return Err(Error::InvalidParameter {
                    name,
                    value: alpha as f64,
                    reason: "energy compensation needs alpha <= 1 (the albedo tables' range)",
                });
            }
        }
        let albedo = if alpha_x == alpha_y {
            Albedo::Isotropic(brdf.ndf().albedo_table(), alpha_x)
        } else {
            Albedo::Anisotropic(SliceStorage::from(
                brdf.ndf()
                    .anisotropic_albedo_table()
                    .slice(alpha_x, alpha_y),
            ))
        };
        let e_avg = albedo.average();
        let f_avg = average_fresnel(brdf.fresnel());
        let f_ms = multiple_scattering_fresnel(f_avg, e_avg);
        let loss = 1.0 - e_avg;
        let scale = if loss >= MIN_LOSS {
            f_ms * (FRAC_1_PI / loss)
        } else {
            Vec3::ZERO
        };
        Ok(EnergyCompensated {
            brdf,
            albedo,
            e_avg,
            f_avg,
            f_ms,
            scale,
        })
    }
}

impl<D: Ndf, F: Fresnel> EnergyCompensated<D, F> {
    /// The single-scattering BRDF.
    pub fn single_scattering(&self) -> &MicrofacetBrdf<D, F> {
        &self.brdf
    }

    /// Whether the anisotropic table is read (αx ≠ αy).
    pub fn is_anisotropic(&self) -> bool {
        matches!(self.albedo, Albedo::Anisotropic(_))
    }

    /// E_avg: the cosine-weighted hemispherical average of [`albedo`](Self::albedo).
    pub fn average_albedo(&self) -> f32 {
        self.e_avg
    }

    /// E(w): the tabulated single-scattering albedo with F = 1 toward `w` (local frame; isotropic
    /// NDFs read only μ = w.z).
    pub fn albedo(&self, w: Vec3) -> f32 {
        self.albedo.albedo(w)
    }

    /// F_avg of the Fresnel term.
    pub fn average_fresnel(&self) -> Vec3 {
        self.f_avg
    }

    /// F_ms, the colour of the compensation lobe.
    pub fn multiple_scattering_fresnel(&self) -> Vec3 {
        self.f_ms
    }

    /// The compensation lobe F_ms f_ms(wo, wi) for directions already checked to be upper.
    #[inline]
    fn lobe(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let lo = 1.0 - self.albedo(wo);
        let li = 1.0 - self.albedo(wi);
        self.scale * (lo.max(0.0) * li.max(0.0))
    }

    /// The probability of drawing from the single-scattering sampler at `wo` (upper).
    #[inline]
    fn specular_probability(&self, wo: Vec3) -> f32 {
        let e = self.albedo(wo);
        let mean = |v: Vec3| (v.x + v.y + v.z) / 3.0;
        let d = if self.scale == Vec3::ZERO {
            0.0
        } else {
            (1.0 - e).max(0.0) * mean(self.f_ms)
        };
        lobe_probability(d, e * mean(self.f_avg).max(f32::MIN_POSITIVE))
    }
}

impl<D: Ndf, F: Fresnel> Bxdf for EnergyCompensated<D, F> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !(is_upper(wo) && is_upper(wi)) {
            return Vec3::ZERO;
        }
        self.brdf.eval(wo, wi) + self.lobe(wo, wi)
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(wo, wi).1
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !(is_upper(wo) && is_upper(wi)) {
            return (Vec3::ZERO, 0.0);
        }
        let (fs, ps) = self.brdf.eval_pdf(wo, wi);
        let p = self.specular_probability(wo);
        let pdf = p * ps + (1.0 - p) * wi.z * FRAC_1_PI;
        (fs + self.lobe(wo, wi), pdf)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite() && uc.is_finite()) {
            return None;
        }
        let p = self.specular_probability(wo);
        let (wi, flags) = if uc < p {
            let s = self.brdf.sample(wo, uc, u)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fresnel::{ConductorFresnel, NoFresnel, SchlickFresnel};

    #[test]
    fn white_fresnel_averages_to_one() {
        assert_eq!(average_fresnel(&NoFresnel), Vec3::ONE);
        assert_eq!(multiple_scattering_fresnel(Vec3::ONE, 0.7), Vec3::ONE);
    }

    #[test]
    fn schlick_average_matches_its_closed_form() {
        // 2 ∫ (f0 + (1 − f0)(1 − μ)⁵) μ dμ = f0 + (1 − f0) · 2 B(2, 6) = f0 + (1 − f0) / 21.
        let f0 = 0.3;
        let avg = average_fresnel(&SchlickFresnel::new(Vec3::splat(f0)).unwrap());
        assert!((avg.x - (f0 + (1.0 - f0) / 21.0)).abs() < 1e-6, "{avg}");
    }

    #[test]
    fn coloured_metal_gains_saturated_energy() {
        let f_avg = average_fresnel(&ConductorFresnel::GOLD);
        let f_ms = multiple_scattering_fresnel(f_avg, 0.6);
        // Each extra bounce multiplies by F_avg < 1, so F_ms / F_avg is largest where F_avg is.
        assert!(f_ms.x / f_avg.x > f_ms.z / f_avg.z, "{f_avg} {f_ms}");
        assert!(f_ms.max_element() <= 1.0 && f_ms.min_element() >= 0.0);
    }

    #[test]
    fn bad_input_is_an_error() {
        let sep = MicrofacetBrdf::new(Ggx::isotropic(0.5).unwrap(), NoFresnel)
            .with_masking(Masking::Separable);
        assert!(EnergyCompensated::new(sep).is_err());
        let rough = MicrofacetBrdf::new(Ggx::new(1.0, 1.5).unwrap(), NoFresnel);
        assert!(EnergyCompensated::new(rough).is_err());
        let beyond = MicrofacetBrdf::new(Beckmann::new(0.5, 1.3).unwrap(), NoFresnel);
        assert!(EnergyCompensated::new(beyond).is_err());
        let ok = MicrofacetBrdf::new(Beckmann::new(0.5, 1.0).unwrap(), NoFresnel);
        assert!(EnergyCompensated::new(ok).is_ok());
    }
}
