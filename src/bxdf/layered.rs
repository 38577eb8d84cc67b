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
//! fixed set of [`TRANSMISSION_SAMPLES`] points, a rank-1 lattice that is both a Latin hypercube and
//! stratified on the 2 × 2 grid: deterministic, exact for a constant F (F = 1 gives R̂ = 1, no base,
//! the glint's own albedo), and for a Fresnel term that varies across the visible normals it carries
//! a quadrature error (bounded in tests/it/layered.rs against a converged estimate, and by the measured
//! furnace). Each point costs one `sample_visible`, which for a glint patch is a pass over its lobes,
//! so the set is as small as keeps the accuracy: a glint patch's visible normals are a mixture of
//! narrow lobes, chosen by the first coordinate, and the four distinct first coordinates pick the
//! same four lobes a 4 × 4 grid picks (the same R̂ on glint patches at a quarter of the passes; on a
//! smooth analytic lobe the quadrature error grows from ~0.007 to ~0.011 RMS up to 75°). A layer
//! prepared for its view ([`LayeredBrdf::prepare_view`], which `Material::bsdf` calls with the shading
//! point's wo) computes R̂(wo) once (a renderer evaluates many `wi` for one `wo`); an unprepared one
//! estimates it per query. Nothing is kept lazily.
//!
//! Not reciprocal: the base term depends on wo only. A reciprocal form (1 − R(wo))(1 − R(wi)) / (1 −
//! R̄) would need R at every wi, i.e. a full visible-normal integral per evaluation, which a glint
//! patch cannot afford; this is the trade made by the albedo-scaling layered models of renderers.

use super::view_compensated::multiple_scattering_lobe;
use super::{AlbedoEstimate, Bxdf, BxdfSample, LobeFlags, MicrofacetBrdf, lambert::unit_rgb};
use crate::error::Result;
use crate::frame::is_upper;
use crate::fresnel::Fresnel;
use crate::ndf::Ndf;
use crate::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use core::f32::consts::FRAC_1_PI;
use glam::{Vec2, Vec3};

/// Number of visible normals that estimate the first-bounce reflectance R(wo) of the specular layer:
/// the points ((k + ½)/N, ((3k mod N) + ½)/N), k < N = 4 (module docs).
pub const TRANSMISSION_SAMPLES: usize = 4;

/// Generator of the rank-1 lattice of [`TRANSMISSION_SAMPLES`] points (coprime to it; 3 makes the four
/// points fall one in each cell of the 2 × 2 grid).
const LATTICE_GENERATOR: usize = 3;

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
#[derive(Clone, Debug)]
pub struct LayeredBrdf<D, F> {
    specular: MicrofacetBrdf<D, F>,
    base: Vec3,
    /// The energy compensation of the specular layer, if any
    /// ([`LayeredBrdf::with_energy_compensation`]).
    compensation: Option<Compensation<D>>,
    /// R̂(wo) and the specular layer's albedo estimate E(wo) (1 without compensation) at the view
    /// the layer was prepared for ([`LayeredBrdf::prepare_view`]): the bits of wo and the values.
    view: Option<([u32; 3], Vec3, f32)>,
}

impl<D> Clone for Compensation<D> {
    fn clone(&self) -> Self {
        Compensation {
            f_avg: self.f_avg,
            albedo: self.albedo,
        }
    }
}

/// The specular layer's energy compensation: the Fresnel average F_avg and the NDF's albedo
/// estimate ([`AlbedoEstimate::albedo_estimate`] of the layer's NDF type).
#[derive(Debug)]
struct Compensation<D> {
    f_avg: Vec3,
    albedo: fn(&D, Vec3) -> f32,
}

impl<D: Ndf, F: Fresnel> LayeredBrdf<D, F> {
    /// The specular layer `specular` over a Lambertian base of RGB albedo `base` (every channel
    /// finite and in [0, 1]; `Error::InvalidParameter` naming `base` otherwise).
    pub fn new(specular: MicrofacetBrdf<D, F>, base: Vec3) -> Result<Self> {
        Ok(LayeredBrdf {
            specular,
            base: unit_rgb("base", base)?,
            compensation: None,
            view: None,
        })
    }

    /// [`LayeredBrdf::new`] for a `base` already checked by `unit_rgb` (`Material`'s glint coats).
    #[cfg(feature = "std")]
    pub(crate) fn with_valid_base(specular: MicrofacetBrdf<D, F>, base: Vec3) -> Self {
        LayeredBrdf {
            specular,
            base,
            compensation: None,
            view: None,
        }
    }

    /// The same layer with the specular layer's single-scattering loss given back
    /// ([`crate::bxdf::ViewCompensated`]'s lobe F_ms (1 − E(wo))/π beside the base term, E the
    /// NDF's own estimate), for a Fresnel term of hemispherical average `f_avg`
    /// ([`crate::bxdf::average_fresnel`]; channels clamped to [0, 1]). The albedo is then
    /// E_s + F_ms (1 − E) + ρ (1 − R̂): 1 for F = 1 up to the estimate's error, at most
    /// 1 − (1 − E)(F − F_ms) ≤ 1 otherwise (docs/bxdf.md).
    ///
    /// Call [`LayeredBrdf::prepare_view`] at the shading point's wo before querying it, as
    /// `Material::bsdf` does: an unprepared compensated layer estimates E(wo) again at every `eval`,
    /// `pdf` and `sample`, a pass over the patch's lobes each time (a chi-square run of a glint coat
    /// ran 5× longer that way).
    pub fn with_energy_compensation(mut self, f_avg: Vec3) -> Self
    where
        D: AlbedoEstimate,
    {
        let f_avg = Vec3::select(
            f_avg.is_finite_mask(),
            f_avg.clamp(Vec3::ZERO, Vec3::ONE),
            Vec3::ONE,
        );
        self.compensation = Some(Compensation {
            f_avg,
            albedo: <D as AlbedoEstimate>::albedo_estimate,
        });
        self.view = None;
        self
    }

    /// Whether the specular layer's single-scattering loss is given back
    /// ([`LayeredBrdf::with_energy_compensation`]).
    pub fn is_compensated(&self) -> bool {
        self.compensation.is_some()
    }

    /// The specular layer.
    pub fn specular(&self) -> &MicrofacetBrdf<D, F> {
        &self.specular
    }

    /// The base albedo ρ.
    pub fn base(&self) -> Vec3 {
        self.base
    }

    /// Prepares the layer for the view direction `wo`: R̂(wo) ([`TRANSMISSION_SAMPLES`] visible
    /// normals of the specular layer) computed here once and read by every query at that wo (the
    /// same bits); queries at any other view estimate their own, and every value is the
    /// unprepared layer's, bit for bit. A second call replaces the first view. Prepare the specular
    /// layer's NDF for `wo` first where it has a view step of its own (a glint patch's
    /// `prepare_view`), as `Material::bsdf` does.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view = None;
        if is_upper(wo) {
            self.view = Some((
                key_of(wo),
                self.estimate_reflectance(wo),
                self.estimate_albedo(wo),
            ));
        }
    }

    /// E(wo) of the compensated specular layer's NDF (1 without compensation: nothing to give
    /// back).
    fn estimate_albedo(&self, wo: Vec3) -> f32 {
        self.compensation
            .as_ref()
            .map_or(1.0, |c| (c.albedo)(self.specular.ndf(), wo).clamp(0.0, 1.0))
    }

    /// R̂(wo) and E(wo) (upper `wo`): the prepared values at the prepared view.
    fn view_terms(&self, wo: Vec3) -> (Vec3, f32) {
        match self.view {
            Some((k, r, e)) if k == key_of(wo) => (r, e),
            _ => (self.estimate_reflectance(wo), self.estimate_albedo(wo)),
        }
    }

    /// The value of the compensation lobe, F_ms (1 − E)/π (0 without compensation).
    fn multiple_scattering_value(&self, e: f32) -> Vec3 {
        self.compensation
            .as_ref()
            .map_or(Vec3::ZERO, |c| multiple_scattering_lobe(c.f_avg, e))
    }

    /// R̂(wo): the specular layer's first-bounce reflectance ∫ F(wo·m) D_wo(m) dm, estimated on
    /// [`TRANSMISSION_SAMPLES`] lattice-stratified visible normals (module docs); the prepared value
    /// at the prepared view ([`LayeredBrdf::prepare_view`]). In [0, 1] per channel; 1 for invalid `wo`
    /// (nothing transmitted).
    pub fn first_bounce_reflectance(&self, wo: Vec3) -> Vec3 {
        if !is_upper(wo) {
            return Vec3::ONE;
        }
        match self.view {
            Some((k, r, _)) if k == key_of(wo) => r,
            _ => self.estimate_reflectance(wo),
        }
    }

    fn estimate_reflectance(&self, wo: Vec3) -> Vec3 {
        let ndf = self.specular.ndf();
        let mut sum = Vec3::ZERO;
        for u in transmission_points() {
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

    /// The probability of sampling the specular lobe, with `diffuse` the cosine-shaped terms' value
    /// (the base's and the compensation lobe's).
    fn specular_probability(&self, r: Vec3, diffuse: Vec3) -> f32 {
        let spec = r.element_sum() / 3.0;
        let diffuse = diffuse.element_sum() / 3.0 * core::f32::consts::PI;
        if diffuse <= 0.0 {
            return 1.0;
        }
        (spec / (spec + diffuse)).clamp(MIN_LOBE_PROBABILITY, 1.0 - MIN_LOBE_PROBABILITY)
    }
}

/// The key of a direction: its components' bits.
fn key_of(w: Vec3) -> [u32; 3] {
    [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()]
}

/// The [`TRANSMISSION_SAMPLES`] points of the R̂ quadrature in [0, 1)²: the rank-1 lattice
/// ((k + ½)/N, ((g k mod N) + ½)/N) of generator g = [`LATTICE_GENERATOR`].
fn transmission_points() -> impl Iterator<Item = Vec2> {
    const N: usize = TRANSMISSION_SAMPLES;
    (0..N).map(|k| {
        Vec2::new(
            (k as f32 + 0.5) / N as f32,
            ((k * LATTICE_GENERATOR % N) as f32 + 0.5) / N as f32,
        )
    })
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
        let (r, e) = self.view_terms(wo);
        let diffuse = self.base_value(r) + self.multiple_scattering_value(e);
        let p = self.specular_probability(r, diffuse);
        let (fs, ps) = self.specular.eval_pdf(wo, wi);
        let f = fs + diffuse;
        let pdf = p * ps + (1.0 - p) * pdf_cosine_hemisphere(wi);
        (f, pdf)
    }

    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample> {
        if !(is_upper(wo) && u.is_finite() && uc.is_finite()) {
            return None;
        }
        let (r, e) = self.view_terms(wo);
        let diffuse = self.base_value(r) + self.multiple_scattering_value(e);
        let p = self.specular_probability(r, diffuse);
        if uc < p {
            // `MicrofacetBrdf::sample` returns its own `eval_pdf` at the drawn wi: the layered f and
            // pdf follow from it exactly as `eval_pdf` forms them, without evaluating the coat again.
            let s = self.specular.sample(wo, uc / p, u)?;
            let f = s.f + diffuse;
            let pdf = p * s.pdf + (1.0 - p) * pdf_cosine_hemisphere(s.wi);
            return BxdfSample::checked(s.wi, f, pdf, s.flags);
        }
        let wi = square_to_cosine_hemisphere(u);
        let flags = LobeFlags::REFLECTION | LobeFlags::DIFFUSE;
        let (f, pdf) = self.eval_pdf(wo, wi);
        BxdfSample::checked(wi, f, pdf, flags)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The R̂ points are a Latin hypercube (one per row and per column of the N × N grid) and fall
    /// one in each cell of the 2 × 2 grid.
    #[test]
    fn transmission_points_are_latin_and_quadrant_stratified() {
        const N: usize = TRANSMISSION_SAMPLES;
        let cells: Vec<(usize, usize)> = transmission_points()
            .map(|u| ((u.x * N as f32) as usize, (u.y * N as f32) as usize))
            .collect();
        assert_eq!(cells.len(), N);
        for k in 0..N {
            assert_eq!(cells.iter().filter(|c| c.0 == k).count(), 1, "column {k}");
            assert_eq!(cells.iter().filter(|c| c.1 == k).count(), 1, "row {k}");
        }
        for q in 0..4 {
            let inside = |c: &&(usize, usize)| (c.0 * 2 / N, c.1 * 2 / N) == (q % 2, q / 2);
            assert_eq!(cells.iter().filter(inside).count(), N / 4, "quadrant {q}");
        }
    }
}
