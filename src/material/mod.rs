//! One run-time material type for every BRDF of the crate, so that a renderer keeps its materials
//! in one `Vec<Material>` and shades every hit the same way:
//!
//! ```
//! use brdf::bxdf::{Bxdf, Lambert};
//! use brdf::fresnel::ConductorFresnel;
//! use brdf::glint::mixture::MixtureParams;
//! use brdf::glint::{BeckmannMixture, Footprint, GlintModel, GlintScratch, ScratchedParams};
//! use brdf::material::{GlintMaterial, Material};
//! use brdf::ndf::Ggx;
//! use brdf::{Vec2, Vec3};
//!
//! let map = brdf::glint::scratched(64, 64, ScratchedParams::default(), 1)?;
//! let glints = GlintModel::from(BeckmannMixture::build(&map, MixtureParams::default())?);
//! let materials = vec![
//!     Material::from(Lambert::new(Vec3::splat(0.5))?),
//!     Material::microfacet(Ggx::isotropic(0.3)?, ConductorFresnel::GOLD),
//!     GlintMaterial::new(glints, ConductorFresnel::SILVER)
//!         .with_uv_scale(Vec2::new(4.0, 2.0))?
//!         .into(),
//! ];
//! let scratch = GlintScratch::default(); // one per render thread
//! // At a hit: its footprint (ray differentials, ray cone), then one BSDF per path vertex.
//! let footprint = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), 8.0, 64, 64);
//! let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
//! for material in &materials {
//!     let bsdf = material.bsdf(&footprint, wo, &scratch);
//!     if let Some(s) = bsdf.sample(wo, 0.5, Vec2::new(0.25, 0.75)) {
//!         assert!(s.weight().is_finite() && s.weight().min_element() >= 0.0);
//!     }
//! }
//! # Ok::<(), brdf::Error>(())
//! ```
//!
//! The variants: the analytic BRDFs ([`Material::Lambert`], the Phong family,
//! [`Material::Microfacet`] over GGX or Beckmann, [`Material::Compensated`] with the energy of
//! multiple scattering given back, [`Material::Layered`]), the smooth limit
//! ([`Material::Mirror`], a delta lobe), glints ([`GlintMaterial`]: any glint model, alone or as a
//! coat over a Lambertian base), normal mapping ([`NormalMappedMaterial`]: any
//! footprint-independent material about a normal map's normals, through microfacet-based or
//! conventional normal mapping) and a smooth clear coat over any of them
//! ([`ClearCoatMaterial`], [`Material::clear_coated`]: car paint is glint flakes over paint under
//! the coat).
//!
//! ## Design
//! [`Material`] is a closed enum dispatched by `match`, not a trait object: its BSDF at a shading
//! point ([`Bsdf`]) lives on the caller's stack, borrows the material and (for glints) buffers
//! from the per-thread [`GlintScratch`], and costs no allocation and no virtual call; a
//! `Box<dyn Bxdf>` per shading point would allocate, and a `&dyn Bxdf` needs the value stored
//! somewhere, which is what the enum is. A renderer with BRDFs of its own wraps `Material` in
//! its own enum. `Material` is `Send + Sync` and cheap to clone: the analytic variants are a few
//! numbers, a glint material holds its model in an `Arc`.
//!
//! Several BSDFs of one scratch can be alive at once (a path's vertices, the layers of a
//! material): each glint patch takes its own buffers from the scratch and gives them back when it
//! drops (tests/alloc.rs: no allocation per shading point once warm).

mod analytic;
mod bsdf;
mod clear_coat;
mod fresnel;
mod glint;
mod normal_mapped;

pub use analytic::AnalyticNdf;
pub use bsdf::Bsdf;
pub use clear_coat::ClearCoatMaterial;
pub use fresnel::AnyFresnel;
pub use glint::GlintMaterial;
pub use normal_mapped::{NormalMappedMaterial, NormalMapping};

use crate::bxdf::inside_view;
use crate::bxdf::{
    BlinnPhongLobe, ClearCoat, EnergyCompensated, Lambert, LayeredBrdf, MicrofacetBrdf,
    NormalMapMicrofacet, NormalMapTilt, OriginalPhong, Phong, SpecularReflection, ViewCompensated,
};
use crate::error::Result;
use crate::glint::{Footprint, GlintNdf, GlintScratch};
use bsdf::{Coat, Inner, Plain};
use glam::Vec3;

/// Any BRDF of the crate, chosen at run time (module docs): build it with the constructors or
/// `From` the model, get its BSDF at a shading point with [`Material::bsdf`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum Material {
    /// Lambertian diffuse ([`Lambert`]).
    Lambert(Lambert),
    /// The modified Phong model ([`Phong`]).
    Phong(Phong),
    /// The original Phong model ([`OriginalPhong`]).
    OriginalPhong(OriginalPhong),
    /// The Blinn-Phong lobe ([`BlinnPhongLobe`]).
    BlinnPhong(BlinnPhongLobe),
    /// An analytic microfacet BRDF (GGX or Beckmann, any Fresnel term), single scattering.
    Microfacet(MicrofacetBrdf<AnalyticNdf, AnyFresnel>),
    /// An analytic microfacet BRDF with the energy it loses to single scattering given back
    /// ([`EnergyCompensated`], Kulla-Conty): rough metals stay bright and saturated.
    Compensated(EnergyCompensated<AnalyticNdf, AnyFresnel>),
    /// An analytic microfacet layer over a Lambertian base ([`LayeredBrdf`]).
    Layered(LayeredBrdf<AnalyticNdf, AnyFresnel>),
    /// A perfectly smooth reflector, the α → 0 limit of the microfacet BRDF: a delta lobe
    /// ([`SpecularReflection`]; samples flagged `SPECULAR`, `eval` and `pdf` 0).
    Mirror(SpecularReflection<AnyFresnel>),
    /// Glints: a glint model seen through each shading point's footprint ([`GlintMaterial`]).
    Glint(GlintMaterial),
    /// A footprint-independent material shaded about a normal map's normals
    /// ([`NormalMappedMaterial`]).
    NormalMapped(NormalMappedMaterial),
    /// Any other material under a smooth dielectric clear coat ([`ClearCoatMaterial`],
    /// [`crate::bxdf::ClearCoat`]): car paint, varnish.
    ClearCoat(ClearCoatMaterial),
}

impl Material {
    /// The microfacet BRDF of `ndf` ([`crate::ndf::Ggx`] or [`crate::ndf::Beckmann`]) and `fresnel`
    /// (any model of [`crate::fresnel`]), with the default masking and sampling.
    pub fn microfacet(ndf: impl Into<AnalyticNdf>, fresnel: impl Into<AnyFresnel>) -> Material {
        Material::Microfacet(MicrofacetBrdf::new(ndf.into(), fresnel.into()))
    }

    /// [`Material::microfacet`] with multiple-scattering energy compensation
    /// ([`Material::Compensated`]).
    ///
    /// # Errors
    /// Those of [`EnergyCompensated::new`]: αx or αy above 1.
    pub fn microfacet_compensated(
        ndf: impl Into<AnalyticNdf>,
        fresnel: impl Into<AnyFresnel>,
    ) -> Result<Material> {
        let brdf = MicrofacetBrdf::new(ndf.into(), fresnel.into());
        Ok(Material::Compensated(EnergyCompensated::new(brdf)?))
    }

    /// A microfacet layer (`ndf`, `fresnel`) over a Lambertian base of RGB albedo `base`.
    ///
    /// # Errors
    /// [`crate::Error::InvalidParameter`] naming `base` unless every channel is finite and in [0, 1].
    pub fn layered(
        ndf: impl Into<AnalyticNdf>,
        fresnel: impl Into<AnyFresnel>,
        base: Vec3,
    ) -> Result<Material> {
        let specular = MicrofacetBrdf::new(ndf.into(), fresnel.into());
        Ok(Material::Layered(LayeredBrdf::new(specular, base)?))
    }

    /// `inner` under a smooth dielectric clear coat of relative index `eta`
    /// ([`Material::ClearCoat`]): the coat's mirror reflection, and `inner` seen through the
    /// coat with its internal reflections (docs/bxdf.md, "Clear coat"). Car paint is metallic
    /// glint flakes over a paint base ([`GlintMaterial::over_base`]) under a coat of η = 1.5.
    ///
    /// # Errors
    /// Those of [`ClearCoatMaterial::new`]: `eta` outside (1, 3], or an `inner` that is itself
    /// clear-coated.
    pub fn clear_coated(inner: impl Into<Material>, eta: f32) -> Result<Material> {
        let inner: Material = inner.into();
        Ok(Material::ClearCoat(ClearCoatMaterial::new(inner, eta)?))
    }

    /// A perfectly smooth reflector with Fresnel term `fresnel` (a delta lobe: [`Material::Mirror`]).
    pub fn mirror(fresnel: impl Into<AnyFresnel>) -> Material {
        Material::Mirror(SpecularReflection::new(fresnel.into()))
    }

    /// Whether the material's BSDF depends on the footprint given to [`Material::bsdf`] (glints
    /// use all of it, normal-mapped materials its centre): a renderer may skip computing ray
    /// differentials or cones for the others.
    pub fn uses_footprint(&self) -> bool {
        match self {
            Material::Glint(_) | Material::NormalMapped(_) => true,
            Material::ClearCoat(c) => c.inner().uses_footprint(),
            _ => false,
        }
    }

    /// The BRDF of a footprint-independent material (`None` for glint and normal-mapped ones).
    fn plain(&self) -> Option<Plain<'_>> {
        Some(match self {
            Material::Lambert(b) => Plain::Lambert(b),
            Material::Phong(b) => Plain::Phong(b),
            Material::OriginalPhong(b) => Plain::OriginalPhong(b),
            Material::BlinnPhong(b) => Plain::BlinnPhong(b),
            Material::Microfacet(b) => Plain::Microfacet(b),
            Material::Compensated(b) => Plain::Compensated(b),
            Material::Layered(b) => Plain::Layered(b.clone()),
            Material::Mirror(b) => Plain::Mirror(b),
            Material::Glint(_) | Material::NormalMapped(_) | Material::ClearCoat(_) => {
                return None;
            }
        })
    }

    /// The material's BRDF at a shading point whose ray footprint on the surface is `footprint`
    /// (surface uv; ignored unless [`Material::uses_footprint`]), prepared for the view direction
    /// `wo` (shading frame, toward the viewer: the `wo` the renderer then passes to `eval_pdf` and
    /// `sample`). Glint patches take their buffers from `scratch` (one per render thread) and give
    /// them back when the [`Bsdf`] drops. Total: any footprint and any `wo` work.
    ///
    /// The view step: what every query at `wo` shares is computed here, once (a glint patch's
    /// exact V(wo), a pass over its lobes; a layered material's first-bounce reflectance R̂(wo),
    /// a few visible-normal draws). Queries at another view stay exact and compute their own;
    /// nothing is kept lazily.
    pub fn bsdf<'a>(
        &'a self,
        footprint: &Footprint,
        wo: Vec3,
        scratch: &'a GlintScratch,
    ) -> Bsdf<'a> {
        Bsdf(match self {
            Material::ClearCoat(c) => {
                // The coat asks its base at the view refracted into it: the base is prepared there.
                let view = inside_view(wo, c.eta());
                let inner = c.inner().uncoated_bsdf(footprint, view, scratch);
                // η was validated by `ClearCoatMaterial::new`.
                Coat::Coated(ClearCoat::from_valid(inner, c.eta(), c.base_albedo()))
            }
            uncoated => Coat::Bare(uncoated.uncoated_bsdf(footprint, wo, scratch)),
        })
    }

    /// The BRDF of a material that is not clear-coated (a clear-coated one gives its inner
    /// material's; coats do not nest, `ClearCoatMaterial::new` rejects it), prepared for the view
    /// `wo`.
    fn uncoated_bsdf<'a>(
        &'a self,
        footprint: &Footprint,
        wo: Vec3,
        scratch: &'a GlintScratch,
    ) -> Inner<'a> {
        match self {
            Material::ClearCoat(c) => c.inner().uncoated_bsdf(footprint, wo, scratch),
            Material::Glint(g) => {
                let fp = g.map_footprint(footprint);
                let mut patch = g.model().patch_with(&fp, g.options(), Some(scratch));
                patch.prepare_view(wo);
                let layer = MicrofacetBrdf::new(patch, g.fresnel());
                match (g.base(), g.energy_compensation()) {
                    (None, None) => Inner::Glint(layer),
                    // F_avg was computed by `average_fresnel` (in [0, 1]); masking is the default
                    // height-correlated form.
                    (None, Some(f_avg)) => {
                        Inner::GlintCompensated(ViewCompensated::from_valid(layer, f_avg, wo))
                    }
                    // Validated by `GlintMaterial::over_base`.
                    (Some(base), compensation) => {
                        let mut coat = LayeredBrdf::with_valid_base(layer, base);
                        if let Some(f_avg) = compensation {
                            coat = coat.with_energy_compensation(f_avg);
                        }
                        coat.prepare_view(wo);
                        Inner::GlintCoat(coat)
                    }
                }
            }
            Material::NormalMapped(nm) => {
                // The base is footprint-independent (checked by `NormalMappedMaterial::new`).
                let base = nm.base().plain().unwrap_or(Plain::Lambert(&Lambert::BLACK));
                match (nm.shading_normal(footprint), nm.mapping()) {
                    (None, _) => Inner::Plain(base),
                    (Some(n), NormalMapping::Microfacet) => {
                        Inner::NormalMicrofacet(NormalMapMicrofacet::new(base, n))
                    }
                    (Some(n), NormalMapping::Tilt) => Inner::Tilt(NormalMapTilt::new(base, n)),
                }
            }
            Material::Layered(b) => {
                let mut layered = b.clone();
                layered.prepare_view(wo);
                Inner::Plain(Plain::Layered(layered))
            }
            // Every other material is footprint-independent (`plain` is `Some`).
            plain => Inner::Plain(plain.plain().unwrap_or(Plain::Lambert(&Lambert::BLACK))),
        }
    }
}

/// `From` each BRDF a [`Material`] variant holds.
macro_rules! material_from {
    ($($variant:ident($ty:ty)),+ $(,)?) => {
        $(
            impl From<$ty> for Material {
                fn from(b: $ty) -> Material {
                    Material::$variant(b)
                }
            }
        )+
    };
}

material_from! {
    Mirror(SpecularReflection<AnyFresnel>),
    NormalMapped(NormalMappedMaterial),
    Lambert(Lambert),
    Phong(Phong),
    OriginalPhong(OriginalPhong),
    BlinnPhong(BlinnPhongLobe),
    Microfacet(MicrofacetBrdf<AnalyticNdf, AnyFresnel>),
    Compensated(EnergyCompensated<AnalyticNdf, AnyFresnel>),
    Layered(LayeredBrdf<AnalyticNdf, AnyFresnel>),
    Glint(GlintMaterial),
    ClearCoat(ClearCoatMaterial),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A renderer shares its materials between threads and copies them cheaply.
    #[test]
    fn materials_are_send_sync_and_clone() {
        fn shared<T: Send + Sync + Clone>() {}
        fn per_thread<T: Send + Sync>() {}
        shared::<Material>();
        per_thread::<GlintScratch>();
    }
}
