//! A smooth dielectric clear coat over any base BxDF: car paint (metallic flakes in a binder under
//! a varnish), varnished wood, wet or lacquered surfaces.
//!
//! ## The model
//! A flat interface of relative index η = n_coat / n_outside > 1 lies on top of a base BxDF f_b,
//! which sits inside the coat (the coat's thickness is neglected against the footprint, and the
//! coat absorbs nothing). Light reaching the interface splits into
//!
//! - the coat's **mirror reflection** F(θo), a delta lobe at reflect(wo, z) (the convention of
//!   [`super::SpecularReflection`]: drawn by `sample` with [`LobeFlags::SPECULAR`], not in `eval`
//!   or `pdf`), F the unpolarised [`crate::fresnel::dielectric`] reflectance;
//! - the **base seen through the interface**: the light refracts at the macro normal (Snell:
//!   sin θ' = sin θ / η, same azimuth), reflects off the base and refracts out again:
//!
//!   f(wo, wi) = T(θo) T(θi) f_b(wo', wi') / η² · S,   T = 1 − F,
//!
//!   with wo', wi' the refracted directions inside the coat and S the internal-reflection factor
//!   below.
//!
//! **Derivation of one pass** (\[Pharr2023\] §9.5.2, radiance across an interface;
//! \[WeidlichWilkie2007\], the layer under a smooth interface). Radiance divided by n² is invariant along a ray and across an interface, up to the
//! transmitted fraction: light of radiance L(wi) outside becomes η² T(θi) L(wi) inside along wi'.
//! The étendue n² cos θ dω is conserved by refraction, so cos θi' dωi' = cos θi dωi / η². The base
//! reflects L'(wo') = ∫ f_b(wo', wi') η² T(θi) L(wi) cos θi' dωi' = ∫ f_b T(θi) L(wi) cos θi dωi,
//! and the radiance leaving the coat toward wo is L(wo) = T(θo) L'(wo') / η². Hence
//! L(wo) = ∫ [T(θo) T(θi) f_b(wo', wi') / η²] L(wi) cos θi dωi: the bracket is the BRDF of one
//! pass, in the renderer's measure (geometric cos θi).
//!
//! ## Internal reflection
//! The base's light that meets the interface from below is not all transmitted: beyond the
//! critical angle sin θc = 1/η it is totally reflected, and inside the cone a fraction F too. It
//! returns to the base, reflects again, and so on. Let q be the fraction of the light the base
//! reflects that the interface sends back down to it (the round trip): each pass returns q of the
//! previous one, and the geometric series gives S = Σ qᵏ = 1 / (1 − q).
//!
//! For a Lambertian base of albedo ρ the light the base reflects is diffuse whatever lit it, so
//! q = ρ r_i with r_i(η) the interface's hemispherical reflectance for diffuse light from inside
//! ([`diffuse_internal_reflectance`]; 0.596 for η = 1.5); that is the usual closed form
//! 1 / (1 − ρ r_i) of Saunderson's correction (\[Saunderson1942\]), and it is
//! exact: a white base gives E(wo) = F(θo) + T(θo) = 1 (by r_i = 1 − (1 − r_e)/η², the étendue
//! relation between the internal and external diffuse reflectances).
//!
//! For any other base q depends on where the base sends the light. With q = ρ̄_b r_i and ρ̄_b the
//! base's albedo, a glossy base gains energy: a conductor reflects the light that entered near the
//! normal back near the normal, inside the cone, where the interface returns only ~4 % of it, yet
//! the factor counts the diffuse 60 % (measured: E(0°) = 1.08 in red for gold GGX α = 0.3 under
//! η = 1.5, whose own albedo there is 0.835). So q is estimated from the base itself, once, at
//! construction ([`BaseAlbedo::estimate`]): q(wo') = ∫ f_b(wo', wi') F_int(θi') cos θi' dωi'
//! (F_int the interface's reflectance from inside, 1 beyond θc) by the base's own sampler at
//! [`COAT_ALBEDO_DIRECTIONS`] directions wo' across the cone, and q = min over them. Where that is
//! the minimum over the whole cone the model conserves energy for any base that does: light
//! entering at wo' exits at most the base's albedo minus what the interface returns,
//! A(wo') ≤ ρ_b(wo') − q(wo') ≤ 1 − q, so E(wo) = F + T A(wo') / (1 − q) ≤ F + T = 1. It is exact
//! for a Lambertian base (q(wo') = ρ r_i at every wo'), conservative for a glossy one (the light a
//! glossy base sends into total internal reflection from wo' near the critical angle returns less
//! than its own q(wo') in the model, not more); a glint patch of a few facets can have its minimum
//! between the six directions (tests/it/clear_coat.rs measures the furnace over such patches).
//!
//! ## What it leaves out
//! Coat roughness (the interface is flat: its reflection is a delta), interference in thin coats,
//! absorption in the coat, and the angular shape of the light after internal bounces (the series
//! repeats the first pass's shape, with one constant q: the base's own angular albedo enters the
//! first pass only).
//!
//! ## Reciprocity
//! T(θo) T(θi) f_b(wo', wi') / η² · S is symmetric in (wo, wi) when f_b is, since S is one
//! constant: the coat is reciprocal over a reciprocal base (tests/it/clear_coat.rs checks it).

use super::coat_albedo::{BaseAlbedo, checked_eta};
#[cfg(doc)]
use super::coat_albedo::{COAT_ALBEDO_DIRECTIONS, MAX_COAT_ETA, diffuse_internal_reflectance};
use super::{Bxdf, BxdfSample, LobeFlags};
use crate::error::Result;
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::is_upper;
use crate::fresnel::dielectric;
use glam::{Vec2, Vec3};

/// Probability bounds of choosing the coat's delta lobe in [`ClearCoat::sample`] (never 0 or 1,
/// so both lobes stay reachable; as [`super::LayeredBrdf`] does).
const MIN_LOBE_PROBABILITY: f32 = 0.05;

/// Transmittance 1 − F of a smooth dielectric interface for light arriving from outside at cos θ
/// = `c` ∈ [0, 1] (η > 1), without cancellation at grazing incidence:
/// 1 − r⊥² = 4 c g / (c + g)², 1 − r∥² = 4 η² c g / (η² c + g)², g = √(η² − 1 + c²), and
/// T = (1 − r⊥² + 1 − r∥²) / 2 (the same r's as [`dielectric`]); T ≈ 2 c (1 + η²)/√(η² − 1) as
/// c → 0, where 1 − F in f32 would round to 0.
#[inline]
fn transmittance(c: f32, eta: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    let e2 = eta * eta;
    let g = ((e2 - 1.0) + c * c).max(0.0).sqrt();
    let (a, b) = (c + g, e2 * c + g);
    let t = 2.0 * c * g * (1.0 / (a * a) + e2 / (b * b));
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The direction inside the coat of an outside direction `w` (upper hemisphere, unit): Snell's
/// law at the macro normal, x and y divided by η, z = √(1 − (x² + y²)/η²) (from x and y, so that
/// it is accurate near the normal too).
#[inline]
fn refract_in(w: Vec3, inv_eta: f32) -> Vec3 {
    let (x, y) = (w.x * inv_eta, w.y * inv_eta);
    Vec3::new(x, y, (1.0 - (x * x + y * y)).max(0.0).sqrt())
}

/// The view inside a coat of index `eta` of the outside view `wo`: the direction at which a
/// [`ClearCoat`] asks its base for every query at `wo`, bit for bit (what a base is prepared for,
/// `Material::bsdf`'s view step).
#[cfg(feature = "std")]
pub(crate) fn inside_view(wo: Vec3, eta: f32) -> Vec3 {
    refract_in(wo, 1.0 / eta)
}

/// The outside direction of a direction `w` inside the coat, or `None` beyond the critical angle
/// (total internal reflection: the light cannot leave).
#[inline]
fn refract_out(w: Vec3, eta: f32) -> Option<Vec3> {
    let (x, y) = (w.x * eta, w.y * eta);
    let z2 = 1.0 - (x * x + y * y);
    (z2 > 0.0 && w.z > 0.0).then(|| Vec3::new(x, y, z2.sqrt()))
}

/// A smooth dielectric clear coat of index η over a base BxDF (module docs): the coat's mirror
/// reflection F(θo) as a delta lobe, plus
/// f(wo, wi) = T(θo) T(θi) f_b(wo', wi') / η² / (1 − q), with wo', wi' refracted into the coat.
///
/// Sampling: the delta lobe with probability p(wo) = clamp(F / (F + T ρ̄), 0.05, 0.95) (ρ̄ the
/// base albedo's channel mean), else the base's sampler at wo', its direction refracted out (a
/// draw beyond the critical angle is trapped: `None`), with density
/// (1 − p) pdf_b(wo', wi') cos θi / (η² cos θi') (the Jacobian dωi'/dωi of Snell's law). `eval`
/// and `pdf` are the non-delta part, consistent with that; a delta lobe of the base stays a
/// delta lobe (`SPECULAR` sample with the discrete probability (1 − p) p_b).
///
/// # Reference
/// \[WeidlichWilkie2007\] (refraction into a layer, f_b at the refracted directions, T at both
/// crossings); \[Pharr2023\] §9.5.2 (the η² of radiance across an interface); \[Saunderson1942\]
/// (the internal-reflection series for a diffuse base).
///
/// # Degenerate cases
/// `wo` or `wi` not strictly above the horizon or non-finite: `eval` and `pdf` 0, `sample`
/// `None`. At cos θ = 10⁻³⁰ the transmittance is ~10⁻²⁹ (computed without cancellation), so
/// `eval` is tiny and positive, never NaN; a positive density below `f32::MIN_POSITIVE` is
/// returned as `f32::MIN_POSITIVE` (the crate's density contract).
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, ClearCoat, Lambert, LobeFlags};
/// use brdf::{Vec2, Vec3};
///
/// let white = ClearCoat::new(Lambert::new(Vec3::ONE)?, 1.5)?;
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// // uc below p(wo): the coat's mirror reflection, weight F(θo) / p.
/// let s = white.sample(wo, 0.01, Vec2::new(0.3, 0.7)).unwrap();
/// assert!(s.flags.contains(LobeFlags::SPECULAR));
/// assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8));
/// // Otherwise the Lambertian base seen through the coat.
/// let s = white.sample(wo, 0.9, Vec2::new(0.3, 0.7)).unwrap();
/// assert!(!s.flags.contains(LobeFlags::SPECULAR));
/// assert!((s.pdf - white.pdf(wo, s.wi)).abs() <= 1e-5 * s.pdf);
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct ClearCoat<B> {
    base: B,
    eta: f32,
    inv_eta: f32,
    base_albedo: BaseAlbedo,
    /// 1 / (1 − q) / η² per channel.
    scale: Vec3,
}

impl<B: Bxdf> ClearCoat<B> {
    /// A coat of index `eta` (in (1, [`MAX_COAT_ETA`]]) over `base`, the base's albedo and round
    /// trip estimated from its sampler ([`BaseAlbedo::estimate`], 1,536 `sample` calls).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming `eta` outside (1, 3].
    pub fn new(base: B, eta: f32) -> Result<Self> {
        let eta = checked_eta(eta)?;
        let base_albedo = BaseAlbedo::estimate(&base, eta);
        Ok(Self::from_valid(base, eta, base_albedo))
    }

    /// A coat of index `eta` over `base` with given [`BaseAlbedo`] values (computed once for a
    /// base that a renderer rebuilds per shading point, e.g. a glint patch:
    /// [`crate::material::Material::clear_coated`] does this).
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming `eta` outside (1, 3].
    pub fn with_base_albedo(base: B, eta: f32, base_albedo: BaseAlbedo) -> Result<Self> {
        Ok(Self::from_valid(base, checked_eta(eta)?, base_albedo))
    }

    /// [`ClearCoat::with_base_albedo`] for an `eta` already checked.
    pub(crate) fn from_valid(base: B, eta: f32, base_albedo: BaseAlbedo) -> Self {
        let scale = (Vec3::ONE - base_albedo.round_trip()).recip() / (eta * eta);
        ClearCoat {
            base,
            eta,
            inv_eta: 1.0 / eta,
            base_albedo,
            scale,
        }
    }

    /// The base BxDF.
    pub fn base(&self) -> &B {
        &self.base
    }

    /// The coat's relative index η.
    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// The base's albedo and round trip the coat uses.
    pub fn base_albedo(&self) -> BaseAlbedo {
        self.base_albedo
    }

    /// The coat's mirror reflectance F(θo), the weight of its delta lobe's direction; 0 for a
    /// `wo` not strictly above the horizon.
    pub fn coat_reflectance(&self, wo: Vec3) -> f32 {
        if is_upper(wo) {
            dielectric(wo.z.min(1.0), self.eta)
        } else {
            0.0
        }
    }

    /// The probability of sampling the delta lobe at `wo` (above the horizon).
    fn coat_probability(&self, wo: Vec3) -> f32 {
        let f = dielectric(wo.z.min(1.0), self.eta);
        let base = transmittance(wo.z, self.eta) * self.base_albedo.albedo().element_sum() / 3.0;
        let p = if f + base > 0.0 { f / (f + base) } else { 1.0 };
        p.clamp(MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY)
    }

    /// T(θo) T(θi) / η² / (1 − q): the factor of f_b in `eval`.
    #[inline]
    fn factor(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        self.scale * (transmittance(wo.z, self.eta) * transmittance(wi.z, self.eta))
    }

    /// The density of the non-delta part at `wi`, from the base's density `pdf_b` at (wo', wi'):
    /// (1 − p) pdf_b cos θi / (η² cos θi'), formed in `f64`; a positive density below
    /// `f32::MIN_POSITIVE` is returned as that.
    #[inline]
    fn density(&self, wo: Vec3, wi: Vec3, wi_in: Vec3, pdf_b: f32) -> f32 {
        if !(pdf_b > 0.0 && wi_in.z > 0.0) {
            return 0.0;
        }
        let p = 1.0 - self.coat_probability(wo) as f64;
        let d =
            p * pdf_b as f64 * wi.z as f64 / (self.eta as f64 * self.eta as f64 * wi_in.z as f64);
        if d.is_finite() {
            (d as f32).max(f32::MIN_POSITIVE)
        } else {
            0.0
        }
    }
}

/// `f` with non-finite or negative channels set to 0.
#[inline]
fn finite_non_negative(f: Vec3) -> Vec3 {
    Vec3::select(f.is_finite_mask(), f.max(Vec3::ZERO), Vec3::ZERO)
}

impl<B: Bxdf> Bxdf for ClearCoat<B> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !(is_upper(wo) && is_upper(wi)) {
            return Vec3::ZERO;
        }
        let (wo_in, wi_in) = (refract_in(wo, self.inv_eta), refract_in(wi, self.inv_eta));
        finite_non_negative(self.base.eval(wo_in, wi_in) * self.factor(wo, wi))
    }

    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if !(is_upper(wo) && is_upper(wi)) {
            return 0.0;
        }
        let (wo_in, wi_in) = (refract_in(wo, self.inv_eta), refract_in(wi, self.inv_eta));
        self.density(wo, wi, wi_in, self.base.pdf(wo_in, wi_in))
    }

    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        if !(is_upper(wo) && is_upper(wi)) {
            return (Vec3::ZERO, 0.0);
        }
        let (wo_in, wi_in) = (refract_in(wo, self.inv_eta), refract_in(wi, self.inv_eta));
        let (f_b, pdf_b) = self.base.eval_pdf(wo_in, wi_in);
        let f = finite_non_negative(f_b * self.factor(wo, wi));
        (f, self.density(wo, wi, wi_in, pdf_b))
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && uc.is_finite() && u.is_finite()) {
            return None;
        }
        let p = self.coat_probability(wo);
        if uc < p {
            // The coat's mirror: weight F(θo) / p (the delta-lobe convention).
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let f = self.coat_reflectance(wo) / wi.z;
            return BxdfSample::checked(
                wi,
                Vec3::splat(f),
                p,
                LobeFlags::SPECULAR | LobeFlags::REFLECTION,
            );
        }
        let uc = ((uc - p) / (1.0 - p)).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let wo_in = refract_in(wo, self.inv_eta);
        let s = self.base.sample(wo_in, uc, u)?;
        let wi = refract_out(s.wi, self.eta)?;
        let factor = self.factor(wo, wi);
        if s.flags.contains(LobeFlags::SPECULAR) {
            // A delta lobe of the base stays one: weight T T w_b / (1 − q) / (1 − p), i.e. f =
            // T T f_b cos θi' / ((1 − q) cos θi) and the discrete probability (1 − p) p_b.
            let f = s.f * factor * (self.eta * self.eta * s.wi.z / wi.z);
            return BxdfSample::checked(wi, f, (1.0 - p) * s.pdf, s.flags);
        }
        let f = finite_non_negative(s.f * factor);
        BxdfSample::checked(wi, f, self.density(wo, wi, s.wi, s.pdf), s.flags)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transmittance_is_one_minus_fresnel() {
        for eta in [1.01f32, 1.33, 1.5, 2.0, 3.0] {
            for c in [1.0f32, 0.9, 0.5, 0.2, 0.05, 0.01] {
                let t = transmittance(c, eta);
                let f = dielectric(c, eta);
                assert!((t + f - 1.0).abs() < 2e-6, "η={eta} c={c}: {t} + {f}");
            }
            // Grazing: linear in c, positive where 1 − F rounds to 0.
            let g = (eta * eta - 1.0).sqrt();
            let t = transmittance(1e-30, eta);
            let lim = 2e-30 * (1.0 + eta * eta) / g;
            assert!((t / lim - 1.0).abs() < 1e-5, "η={eta}: {t} vs {lim}");
        }
    }

    #[test]
    fn refraction_round_trips_inside_the_cone() {
        let eta = 1.5;
        for (x, y) in [(0.0f32, 0.0f32), (0.3, 0.4), (-0.7, 0.1), (0.0, -0.99)] {
            let z = (1.0 - x * x - y * y).sqrt();
            let w = Vec3::new(x, y, z);
            let w_in = refract_in(w, 1.0 / eta);
            assert!((w_in.length() - 1.0).abs() < 1e-6);
            assert!(w_in.x * w_in.x + w_in.y * w_in.y <= 1.0 / (eta * eta) + 1e-6);
            let back = refract_out(w_in, eta).unwrap();
            assert!((back - w).abs().max_element() < 1e-5, "{w} → {back}");
        }
        // Beyond the critical angle nothing leaves.
        assert!(refract_out(Vec3::new(0.8, 0.0, 0.6), eta).is_none());
    }
}
