//! The microfacet BRDF f = F(wo·h) G2 D(h) / (4 A(wo) cos θi), generic over the NDF and the Fresnel
//! term: Torrance-Sparrow / Cook-Torrance for centred NDFs (A = cos θ), Chermain's P-BRDF for glint
//! patches (A = the patch's projected area), in the measure every renderer integrates.
//!
//! ## The renderer's measure
//! Chermain's P-BRDF f_P = F G2 D / (4 A(wo) A(wi)) (eq. 7) is normalised in the patch's own measure:
//! the patch intercepts light from wi in proportion to its projected area A(wi), so the reflected
//! radiance is ∫ L(wi) f_P A(wi) dωi. A renderer computes ∫ L(wi) f(wo, wi) cos θi dωi with the
//! *geometric* cos θi, so the value returned here is f = f_P · A(wi)/cos θi
//! = F G2 D / (4 A(wo) cos θi). For a centred NDF A(wi) = cos θi and the factor is exactly 1 (the
//! analytic BRDFs are bit-identical to Torrance-Sparrow); for a glint patch whose mean normal leans,
//! it is what makes the renderer's white furnace ∫ f cos θi dωi ≤ 1:
//! ∫ f cos θi dωi = ∫ F G2 D(h) / (4 A_o) dωi ≤ ∫ ⟨wo,h⟩⁺ D(h) dh / V_o ≤ 1, using G2 ≤ G1(wo) = A_o/V_o
//! (Λ(wi) ≥ 0) and V_o ≥ ∫⟨wo,m⟩⁺ D dm — so every model only needs a visible area that is exact or
//! an upper bound.
//!
//! Reciprocity: f_P is symmetric; f itself obeys f(wo, wi) cos θi / A(wi) = f(wi, wo) cos θo / A(wo),
//! which for centred NDFs is the usual f(wo, wi) = f(wi, wo). A leaning patch is not a reciprocal
//! BRDF in the geometric measure, and should not be: it is a tilted surface seen through a footprint
//! of the geometric one, and its reciprocal form lives in its own projected-area measure.
//!
//! The masking factor is written with the NDF's visible area V(w) = A(w)(1 + Λ(w)) = ∫⟨w, m⟩ D dm so
//! that no term divides by a projected area that may vanish (non-centred lobes, patches):
//! - separable G2 = G1(wo) G1(wi) with G1 = A/V:   G2 / (A_o A_i) = χ⁺ χ⁺ / (V_o V_i);
//! - height-correlated G2 = 1/(1 + Λ_o + Λ_i), with 1 + Λ = V/A:
//!   1 + Λ_o + Λ_i = (V_o A_i + V_i A_o − A_o A_i) / (A_o A_i), so
//!   G2 / (A_o A_i) = χ⁺ χ⁺ / (V_o A_i + V_i A_o − A_o A_i).
//!
//! The denominator of the second form equals A_o A_i (1 + Λ_o + Λ_i) ≥ 0 and stays positive when one
//! of A_o, A_i vanishes while the corresponding V does not.
//!
//! **Leaning patches.** A glint patch whose mean plane faces away from a direction above the
//! geometric horizon has A ≤ 0 there (Λ = ∞: \[Chermain2019\] eq. 15). The height-correlated form
//! is then taken at its limit A → 0⁺, M = 1/(V_o A_i) (or 1/(V_i A_o)): continuous, symmetric in
//! (wo, wi), and the visible-normal weight below stays F · V_o A_i / (V_o A_i) = F. The form itself,
//! read at A_o < 0, would make the denominator V_o A_i + A_o (V_i − A_i) smaller than V_o A_i, and
//! the weight F · V_o A_i / denominator above F without bound. (Of the crate's NDFs, `SlopeGaussian`
//! (cos θ − w·μ̄) and the bin map's patch with exact masking (w·ā) return a signed A; the others
//! clamp it at 0 themselves.)
//!
//! ## Sample weights
//! With visible-normal sampling the pdf of wi is D_wo(h) / (4 wo·h) with D_wo(h) = ⟨wo, h⟩ D(h) / V_o,
//! so the weight f cos θi / pdf = F · M A_i V_o = F · V_o A_i / (V_o A_i + A_o (V_i − A_i)) ≤ F
//! (height-correlated; F A_i / V_i ≤ F separable): F G2 / G1(wo), whatever h is. The factor
//! ⟨wo, h⟩ of the density and the Jacobian's 1/(4 wo·h) cancel exactly, so the density is formed
//! without either: D(h) / (4 V_o), through [`Ndf::pdf_visible_over_cos_given_d`]. Formed as the
//! quotient of the two, it would underflow at grazing views (⟨wo, h⟩ = 10⁻³⁶ makes ⟨wo, h⟩ D / V_o
//! subnormal while f is 10²⁷), and it would hold in floating point only if both cosines were the
//! same rounded number: at grazing views a micronormal nearly perpendicular to wo reflects wo to
//! wi ≈ −wo, and h rebuilt from wo + wi is off by up to ~6·10⁻⁸ / (2 wo·m) radians, so any two
//! differently rounded cosines disagree by a factor that grows like 1/(wo·m)² (880 at cos θo = 10⁻⁷,
//! 8.8·10¹⁵ at 10⁻²⁰ for Beckmann). An [`Ndf`] of a caller's that keeps the default
//! `pdf_visible_over_cos_given_d` (its `pdf_visible` divided by `wo.dot(m)`) gets the cancellation
//! only if its `pdf_visible` computes ⟨wo, m⟩ as `wo.dot(m)`, as every NDF and patch of the crate
//! does. [`MicrofacetBrdf::eval`] and [`MicrofacetBrdf::pdf`] are 0 where the computed wo·h or wi·h
//! is not positive. The weight is then F · G2/G1(wo) ≤ F up to a few ulps and up to the ratio of
//! the normaliser of the NDF's `pdf_visible` to the `visible_area` its masking uses (1 for the
//! analytic NDFs, ≤ 1 for patches whose masking uses an upper bound of V), for every view down to
//! cos θo = 10⁻³⁰ and every u in [0, 1)² (tests/it/hostile_sampling.rs; measured ≤ 1 + 10⁻⁶ for
//! the analytic NDFs and the mixture, ≤ 1 + 6·10⁻⁶ for the position-normal and smoothed bin-map
//! patches; the unsmoothed bin map's visible sampler, which draws ⟨wo, m⟩ bilinearly in each bin,
//! reaches 1.71 F in bins that wo's horizon cuts).
//!
//! With normal sampling the pdf is D(h) cos θh / (4c), c = ‖wo + wi‖/2, and the weight is
//! F · M A_i c / cos θh ≤ F (wo·h) / (V_o cos θh): not bounded by F (it grows as cos θh → 0, the
//! reason visible-normal sampling is the default), but equal to that expression to rounding.
//!
//! **The density contract:** eval > 0 exactly where pdf > 0. A micronormal density D below
//! `f32::MIN_POSITIVE` (subnormal: too few digits for a weight to be right) is taken as 0 by both
//! `eval` and `pdf` (`sample` → `None`); a positive density below `f32::MIN_POSITIVE` (h near the
//! horizon with normal sampling, or D/V where V is huge) is returned as `f32::MIN_POSITIVE`, one
//! above `f32::MAX` as `f32::MAX`.

use super::{Bxdf, BxdfSample, LobeFlags};
use crate::frame::{half_vector_cos, is_upper, reflect};
use crate::fresnel::Fresnel;
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};

/// Which Smith masking-shadowing function the BRDF uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Masking {
    /// G2 = G1(wo) G1(wi): masking and shadowing treated as independent (\[Walter2007\], eq. 23).
    Separable,
    /// G2 = 1/(1 + Λ(wo) + Λ(wi)): accounts for the correlation of masking and shadowing through the
    /// height of the microfacet (\[Heitz2014\], eq. 99). The default: more accurate than the separable
    /// form for every configuration (the separable form double-counts occlusion), at the same cost.
    #[default]
    HeightCorrelated,
}

/// How [`MicrofacetBrdf::sample`] draws the micronormal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Sampling {
    /// m ~ D(m) cos θ_m (\[Walter2007\], §5.3): ignores `wo`, wastes draws on back-facing normals at
    /// grazing angles.
    Normals,
    /// m ~ D_wo(m) = G1(wo, m) ⟨wo, m⟩ D(m) / A(wo), the normals visible from `wo` (\[Heitz2014b\]):
    /// lower variance, never a back-facing m. The default.
    #[default]
    VisibleNormals,
}

/// The microfacet BRDF f(wo, wi) = F(wo·h) · G2(wo, wi, h) · D(h) / (4 A(wo) cos θi), h = normalize(wo + wi),
/// in the renderer's measure (∫ f cos θi dωi with the geometric cosine; module docs).
///
/// With a centred NDF (A = cos θ) this is the Torrance-Sparrow model (\[TorranceSparrow1967\],
/// \[Walter2007\] eq. 20), called Cook-Torrance with Beckmann's D (\[CookTorrance1982\]); with a glint patch
/// it is the P-BRDF of \[Chermain2019\], eq. 7, times A(wi)/cos θi. Implemented as
/// F · D(h)/4 · M(wo, wi) · A(wi)/cos θi with the masking factor M = G2/(A_o A_i) written through
/// `visible_area` (module docs), so nothing divides by A.
///
/// Reciprocal for centred NDFs when F(wo·h) is (it is: wo·h = wi·h) and the NDF's masking is; for a
/// leaning glint patch f cos θi / A(wi) is (module docs). Single scattering only:
/// the albedo is below 1 for rough surfaces even with F = 1 (energy lost by masking, tabulated in
/// docs/results.md).
///
/// Sampling: draw m ([`Sampling`]), wi = reflect(wo, m), pdf = p_m(h) / (4 wo·h) at the h rebuilt from
/// wi (the Jacobian of reflection, \[Walter2007\] eq. 14; module docs, "Sample weights", for which
/// cosine). `None` when wo·m ≤ 0 or wi is below the horizon; the pdf is then the
/// density of the directions that are produced (it integrates to less than 1 over the hemisphere).
/// The weight f cos θi / pdf is F G2/G1(wo) ≤ F with visible normals at every view (module docs).
///
/// # Reference
/// \[TorranceSparrow1967\]; \[CookTorrance1982\]; \[Walter2007\] eq. 20; \[Heitz2014\] eq. 99;
/// \[Chermain2019\] eq. 7.
///
/// # Degenerate cases
/// `wo`, `wi` not strictly above the horizon, zero-length or non-finite, wo = −wi, wo·h ≤ 0 or wi·h ≤ 0
/// as computed, V or the masking denominator not positive: f = 0, pdf = 0, `sample` → `None`. Values
/// that overflow f32 are returned as 0; a subnormal micronormal density gives pdf 0 (module docs).
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, MicrofacetBrdf};
/// use brdf::fresnel::SchlickFresnel;
/// use brdf::ndf::Ggx;
/// use brdf::{Vec2, Vec3};
///
/// let brdf = MicrofacetBrdf::new(Ggx::isotropic(0.3)?, SchlickFresnel::new(Vec3::splat(0.04))?);
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// if let Some(s) = brdf.sample(wo, 0.5, Vec2::new(0.3, 0.7)) {
///     // With visible-normal sampling the weight f cos θi / pdf is F G2 / G1(wo) <= F.
///     assert!(s.weight().max_element() <= 1.0);
///     assert_eq!(s.f, brdf.eval(wo, s.wi));
/// }
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetBrdf<D, F> {
    ndf: D,
    fresnel: F,
    masking: Masking,
    sampling: Sampling,
}

impl<D: Ndf, F: Fresnel> MicrofacetBrdf<D, F> {
    /// A microfacet BRDF with height-correlated masking and visible-normal sampling.
    pub fn new(ndf: D, fresnel: F) -> Self {
        MicrofacetBrdf {
            ndf,
            fresnel,
            masking: Masking::default(),
            sampling: Sampling::default(),
        }
    }

    /// The same BRDF with another masking-shadowing form.
    pub fn with_masking(mut self, masking: Masking) -> Self {
        self.masking = masking;
        self
    }

    /// The same BRDF with another micronormal sampler.
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    /// The NDF.
    pub fn ndf(&self) -> &D {
        &self.ndf
    }

    /// The Fresnel term.
    pub fn fresnel(&self) -> &F {
        &self.fresnel
    }

    /// The masking-shadowing form.
    pub fn masking(&self) -> Masking {
        self.masking
    }

    /// The micronormal sampler.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The masking factor M(wo, wi) = G2(wo, wi, h) / (A(wo) A(wi)) for a half vector with
    /// wo·h = wi·h > 0 (the χ⁺ factors are checked by the caller): 1/(V_o V_i) (separable) or
    /// 1/(V_o A_i + V_i A_o − A_o A_i) with A_o, A_i taken at least 0 (height-correlated); 0 when
    /// the denominator is not positive.
    pub fn masking_factor(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.masking_factor_with(wo, wi, self.ndf.projected_area(wi))
    }

    /// [`MicrofacetBrdf::masking_factor`] with A(wi) = `ai` already evaluated (`eval` needs it for
    /// the renderer's-measure factor too, and a glint patch's A is not free).
    #[inline]
    fn masking_factor_with(&self, wo: Vec3, wi: Vec3, ai: f32) -> f32 {
        // V at the view through `view_visible_area`: a glint patch may keep it for the queries
        // that follow at the same wo (its pdf, its sampler, the next eval).
        let vo = self.ndf.view_visible_area(wo);
        let vi = self.ndf.visible_area(wi);
        let denom = match self.masking {
            Masking::Separable => vo * vi,
            Masking::HeightCorrelated => {
                // A ≤ 0 (a leaning glint patch whose mean plane faces away from the direction):
                // the form's limit A → 0⁺, M = 1/(V_o A_i) (module docs, "Leaning patches").
                let (ao, ai) = (self.ndf.projected_area(wo).max(0.0), ai.max(0.0));
                vo * ai + vi * ao - ao * ai
            }
        };
        if denom > 0.0 && denom.is_finite() {
            1.0 / denom
        } else {
            0.0
        }
    }

    /// The half vector of a valid reflection configuration, or `None`: both directions strictly
    /// above the horizon and strictly in front of h (wo·h > 0 and wi·h > 0 as computed, so that f,
    /// the pdf and the NDF's χ⁺(wo·m) agree on the support even where h is rounding noise).
    #[inline]
    fn half(wo: Vec3, wi: Vec3) -> Option<Half> {
        if !(is_upper(wo) && is_upper(wi)) {
            return None;
        }
        // c = ‖wo + wi‖/2 rather than wo·h: exact where wi → −wo (frame::half_vector_cos) and
        // symmetric in (wo, wi), so F(c) stays reciprocal to the last bit.
        let (h, c) = half_vector_cos(wo, wi)?;
        (c > 0.0 && wo.dot(h) > 0.0 && wi.dot(h) > 0.0).then_some(Half { h, c })
    }

    /// The renderer's-measure factor A(wi)/cos θi (with `ai` = A(wi)) that turns the patch BRDF f_P (normalised in the
    /// measure A(wi) dωi) into the BRDF a renderer integrates against the geometric cos θi dωi:
    /// exactly 1 for centred NDFs (A = cos θ, and x/x = 1 in IEEE arithmetic), the patch's projected
    /// area over the geometric cosine for leaning glint patches, 0 when the patch's mean plane faces
    /// away from wi (A ≤ 0: it intercepts no light from there).
    #[inline]
    fn measure_factor(wi: Vec3, ai: f32) -> f32 {
        if ai > 0.0 && wi.z > 0.0 {
            ai / wi.z
        } else {
            0.0
        }
    }

    /// f(wo, wi) in the renderer's measure: F · D/4 · M(wo, wi) · A(wi)/cos θi (module docs), with
    /// `d` = D(h) already evaluated.
    #[inline]
    fn eval_at(&self, wo: Vec3, wi: Vec3, hv: &Half, d: f32) -> Vec3 {
        // A subnormal D is taken as 0, here as in the density (`pdf_at`).
        if d.is_nan() || d < f32::MIN_POSITIVE {
            return Vec3::ZERO;
        }
        let ai = self.ndf.projected_area(wi);
        let scale = 0.25 * d * self.masking_factor_with(wo, wi, ai) * Self::measure_factor(wi, ai);
        let v = self.fresnel.eval(hv.c) * scale;
        if v.is_finite() { v } else { Vec3::ZERO }
    }

    /// The density of `sample` at the wi of `hv`: p_m(h) / (4 wo·h), the Jacobian of reflection
    /// (\[Walter2007\] eq. 14), with `d` = D(h) already evaluated. Formed from the NDF's density
    /// per unit cosine, so that no factor is rounded away before it cancels (module docs, "Sample
    /// weights"): for visible normals p_m / ⟨wo, h⟩ = D(h)/V(wo)
    /// ([`Ndf::pdf_visible_over_cos_given_d`]) and the density is that over 4; for normals drawn
    /// from D cos θ it is D(h) · cos θh / (4c), c = ‖wo + wi‖/2
    /// ([`Ndf::pdf_normal_over_cos_given_d`]).
    ///
    /// A micronormal density D below `f32::MIN_POSITIVE` (subnormal: fewer than 23 significant
    /// bits, none at all near 10⁻⁴⁵) is taken as 0, here and in `eval_at`. A positive density
    /// below `f32::MIN_POSITIVE` (a normal density at h near the horizon, or D/V where V is huge)
    /// is returned as `f32::MIN_POSITIVE` and one above `f32::MAX` as `f32::MAX`: the BRDF is
    /// positive exactly where its density is (the density contract, docs/bxdf.md), and directions
    /// with a density that small are drawn with probability below 10⁻³⁸.
    #[inline]
    fn pdf_at(&self, wo: Vec3, hv: &Half, d: f32) -> f32 {
        if d.is_nan() || d < f32::MIN_POSITIVE {
            return 0.0;
        }
        let (per_cos, factor) = match self.sampling {
            Sampling::Normals => (
                self.ndf.pdf_normal_over_cos_given_d(hv.h, d),
                hv.h.z / (4.0 * hv.c),
            ),
            Sampling::VisibleNormals => (self.ndf.pdf_visible_over_cos_given_d(wo, hv.h, d), 0.25),
        };
        if !(per_cos > 0.0 && factor > 0.0) {
            return 0.0;
        }
        (per_cos * factor).clamp(f32::MIN_POSITIVE, f32::MAX)
    }
}

/// The half vector h = (wo + wi)/‖wo + wi‖ of a reflection configuration with
/// c = ‖wo + wi‖/2 (accurate, symmetric: Fresnel and the normal sampler's Jacobian).
struct Half {
    h: Vec3,
    c: f32,
}

impl<D: Ndf, F: Fresnel> Bxdf for MicrofacetBrdf<D, F> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        match Self::half(wo, wi) {
            Some(hv) => self.eval_at(wo, wi, &hv, self.ndf.d(hv.h)),
            None => Vec3::ZERO,
        }
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        match Self::half(wo, wi) {
            Some(hv) => self.pdf_at(wo, &hv, self.ndf.d(hv.h)),
            None => 0.0,
        }
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        match Self::half(wo, wi) {
            Some(hv) => {
                // D(h) once for both: the NDF's density may need it again (its contract check).
                let d = self.ndf.d(hv.h);
                (self.eval_at(wo, wi, &hv, d), self.pdf_at(wo, &hv, d))
            }
            None => (Vec3::ZERO, 0.0),
        }
    }

    fn sample(&self, wo: Vec3, _uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite()) {
            return None;
        }
        let m = match self.sampling {
            Sampling::Normals => self.ndf.sample_normal(u),
            Sampling::VisibleNormals => self.ndf.sample_visible(wo, u),
        };
        if !(m.is_finite() && m.z > 0.0 && wo.dot(m) > 0.0) {
            return None;
        }
        let wi = reflect(wo, m);
        // f and pdf are evaluated at the drawn wi (through its recomputed half vector, equal to m up to
        // rounding), so that they agree exactly with `eval` and `pdf`.
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, LobeFlags::REFLECTION | LobeFlags::GLOSSY)
    }
}
