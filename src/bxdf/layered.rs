//! A specular microfacet layer (analytic or glint) over a Lambertian base: what a renderer needs for
//! coated or flaked paint, glints over a diffuse colour.
//!
//! The light that the specular layer does not reflect at its first bounce reaches the base; the
//! fraction reflected at first bounce toward any direction is
//! R(wo) = ∫ F(wo·m) D_wo(m) dm (D_wo the visible normals from wo), and the specular layer's own
//! albedo E_s(wo) = ∫ F(wo·m) G2/G1(wo) D_wo(m) dm never exceeds it (G2 ≤ G1(wo)). So
//!
//! f(wo, wi) = f_s(wo, wi) + (1 − R̂(wo)) ρ / π
//!
//! has albedo E_s(wo) + ρ (1 − R̂(wo)) ≤ 1 whenever R̂ ≥ E_s, and equal to 1 − (R − E_s) for a white
//! base (R̂ = R): energy lost only by the specular layer's masking, which this single-scattering
//! model does not redistribute. R̂ is R estimated with the layer's own visible-normal sampler on a
//! fixed stratified set of [`TRANSMISSION_SAMPLES`] points: deterministic, exact for a constant F
//! (F = 1 gives R̂ = 1, no base, the glint's own albedo), and for a Fresnel term that varies across
//! the visible normals it carries a quadrature error (bounded in tests/layered.rs by the measured
//! furnace). R̂ is cached per `wo` (a renderer evaluates many `wi` for one `wo`).
//!
//! Not reciprocal: the base term depends on wo only. A reciprocal form (1 − R(wo))(1 − R(wi)) / (1 −
//! R̄) would need R at every wi, i.e. a full visible-normal integral per evaluation, which a glint
//! patch cannot afford; this is the trade made by the albedo-scaling layered models of renderers.

use super::{Bxdf, BxdfSample, LobeFlags, MicrofacetBrdf, lambert::unit_rgb};
use crate::error::Result;
use crate::frame::is_upper;
use crate::fresnel::Fresnel;
use crate::ndf::Ndf;
use crate::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;
use std::sync::Mutex;

/// Number of stratified visible normals (a 4 × 4 grid of cell centres) that estimate the first-bounce
/// reflectance R(wo) of the specular layer.
pub const TRANSMISSION_SAMPLES: usize = 16;

/// Probability bounds of choosing the specular lobe in [`LayeredBrdf::sample`] (never 0 or 1, so
/// both lobes stay reachable and the one-sample mixture pdf stays positive where either lobe is).
const MIN_LOBE_PROBABILITY: f32 = 0.05;

/// A [`MicrofacetBrdf`] specular layer over a Lambertian base of albedo ρ (module docs):
/// f = f_s + (1 − R̂(wo)) ρ/π.
///
/// Sampling: the specular lobe with probability p(wo) = clamp(R̂ / (R̂ + ρ(1 − R̂)), 0.05, 0.95) (channel
/// means), else the cosine hemisphere; pdf = p pdf_s + (1 − p) cos θi/π, and the sample's value is the
/// whole f (one-sample MIS, balance heuristic).
///
/// # Reference
/// The first-bounce transmission argument of albedo-scaling layered models (\[KelemenSzirmayKalos2001\]);
/// the specular layer is \[Walter2007\] / \[Chermain2019\] through [`MicrofacetBrdf`].
///
/// # Example
/// ```
/// use brdf::bxdf::{Bxdf, LayeredBrdf, MicrofacetBrdf};
/// use brdf::fresnel::SchlickFresnel;
/// use brdf::ndf::Ggx;
/// use brdf::{Vec2, Vec3};
///
/// let coat = MicrofacetBrdf::new(Ggx::isotropic(0.2)?, SchlickFresnel::new(Vec3::splat(0.04))?);
/// let paint = LayeredBrdf::new(coat, Vec3::new(0.8, 0.1, 0.1))?;
/// let wo = Vec3::new(0.6, 0.0, 0.8);
/// let s = paint.sample(wo, 0.3, Vec2::new(0.4, 0.6)).unwrap();
/// assert!(s.weight().max_element() <= 1.0 + 1e-3);
/// # Ok::<(), brdf::Error>(())
/// ```
#[derive(Debug)]
pub struct LayeredBrdf<D, F> {
    specular: MicrofacetBrdf<D, F>,
    base: Vec3,
    /// The last (wo, R̂(wo)).
    cache: Mutex<Option<(Vec3, Vec3)>>,
}

impl<D: Clone, F: Clone> Clone for LayeredBrdf<D, F> {
    fn clone(&self) -> Self {
        LayeredBrdf {
            specular: self.specular.clone(),
            base: self.base,
            cache: Mutex::new(None),
        }
    }
}

impl<D: Ndf, F: Fresnel> LayeredBrdf<D, F> {
    /// The specular layer `specular` over a Lambertian base of RGB albedo `base` (every channel
    /// finite and in [0, 1]; `Error::InvalidParameter` naming `base` otherwise).
    pub fn new(specular: MicrofacetBrdf<D, F>, base: Vec3) -> Result<Self> {
        Ok(LayeredBrdf {
            specular,
            base: unit_rgb("base", base)?,
            cache: Mutex::new(None),
        })
    }

    /// [`LayeredBrdf::new`] for a `base` already checked by `unit_rgb`.
    pub(crate) fn with_valid_base(specular: MicrofacetBrdf<D, F>, base: Vec3) -> Self {
        LayeredBrdf {
            specular,
            base,
            cache: Mutex::new(None),
        }
    }

    /// The specular layer.
    pub fn specular(&self) -> &MicrofacetBrdf<D, F> {
        &self.specular
    }

    /// The base albedo ρ.
    pub fn base(&self) -> Vec3 {
        self.base
    }

    /// R̂(wo): the specular layer's first-bounce reflectance ∫ F(wo·m) D_wo(m) dm, estimated on
    /// [`TRANSMISSION_SAMPLES`] stratified visible normals (module docs). In [0, 1] per channel; 1 for
    /// invalid `wo` (nothing transmitted).
    pub fn first_bounce_reflectance(&self, wo: Vec3) -> Vec3 {
        if !is_upper(wo) {
            return Vec3::ONE;
        }
        let cached = match self.cache.lock() {
            Ok(g) => *g,
            Err(p) => *p.into_inner(),
        };
        if let Some((w, r)) = cached
            && w == wo
        {
            return r;
        }
        let r = self.estimate_reflectance(wo);
        if let Ok(mut g) = self.cache.lock() {
            *g = Some((wo, r));
        }
        r
    }

    fn estimate_reflectance(&self, wo: Vec3) -> Vec3 {
        const K: usize = 4;
        debug_assert_eq!(K * K, TRANSMISSION_SAMPLES);
        let ndf = self.specular.ndf();
        let mut sum = Vec3::ZERO;
        for j in 0..K {
            for i in 0..K {
                let u = Vec2::new((i as f32 + 0.5) / K as f32, (j as f32 + 0.5) / K as f32);
                let m = ndf.sample_visible(wo, u);
                let c = wo.dot(m);
                // A sampler that fails (non-finite or back-facing m) counts as reflected: the base
                // then receives less, never more, than it should.
                let f = if m.is_finite() && c > 0.0 {
                    self.specular.fresnel().eval(c)
                } else {
                    Vec3::ONE
                };
                sum += f;
            }
        }
        let r = sum / TRANSMISSION_SAMPLES as f32;
        Vec3::select(
            r.is_finite_mask(),
            r.clamp(Vec3::ZERO, Vec3::ONE),
            Vec3::ONE,
        )
    }

    /// The base term (1 − R̂(wo)) ρ/π.
    #[inline]
    fn base_value(&self, r: Vec3) -> Vec3 {
        (Vec3::ONE - r) * self.base * FRAC_1_PI
    }

    /// The probability of sampling the specular lobe.
    fn specular_probability(&self, r: Vec3) -> f32 {
        let spec = r.element_sum() / 3.0;
        let diffuse = self.base_value(r).element_sum() / 3.0 * std::f32::consts::PI;
        if diffuse <= 0.0 {
            return 1.0;
        }
        (spec / (spec + diffuse)).clamp(MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY)
    }
}

impl<D: Ndf, F: Fresnel> Bxdf for LayeredBrdf<D, F> {
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
        let r = self.first_bounce_reflectance(wo);
        let p = self.specular_probability(r);
        let (fs, ps) = self.specular.eval_pdf(wo, wi);
        let f = fs + self.base_value(r);
        let pdf = p * ps + (1.0 - p) * pdf_cosine_hemisphere(wi);
        (f, pdf)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite() && uc.is_finite()) {
            return None;
        }
        let r = self.first_bounce_reflectance(wo);
        let p = self.specular_probability(r);
        let (wi, flags) = if uc < p {
            let s = self.specular.sample(wo, uc / p, u)?;
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
