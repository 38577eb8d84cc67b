//! Reflection models (BxDFs) built from the NDF and Fresnel layers.
//!
//! Frame: local shading frame, z = geometric normal; `wo` (toward the viewer) and `wi` (toward the light)
//! are unit vectors pointing away from the surface. Reflection needs both strictly above the horizon.
//!
//! Models: [`Lambert`]; the Phong family — [`Phong`] (modified form, normalisations in
//! [`PhongNormalization`], optional Schlick Fresnel) and [`OriginalPhong`] (cos^γ θr / cos θi); the
//! [`BlinnPhongLobe`]; and [`MicrofacetBrdf`], generic over any [`crate::ndf::Ndf`] (centred NDFs,
//! non-centred lobes, glint patches) and any [`crate::fresnel::Fresnel`], with opt-in multiple-scattering
//! energy compensation in [`EnergyCompensated`] (tables: [`AlbedoTable`]) and, for NDFs that estimate
//! their own albedo (glint patches), [`ViewCompensated`]; [`LayeredBrdf`], a microfacet
//! layer over a Lambertian base; [`ClearCoat`], a smooth dielectric coat over any base BxDF (car
//! paint: flakes under a varnish); [`SpecularReflection`], the smooth limit (a delta lobe, see the
//! convention on [`Bxdf`]); and the shading-normal adapters [`NormalMapTilt`] (conventional normal
//! mapping) and [`NormalMapMicrofacet`] (microfacet-based normal mapping), each wrapping any inner
//! [`Bxdf`]. Which are reciprocal and which conserve or normalise energy: docs/bxdf.md.

use crate::ndf::deref_dispatch;
use glam::{Vec2, Vec3};

mod albedo;
mod albedo_anisotropic;
mod albedo_tables;
mod blinn_phong;
mod clear_coat;
mod coat_albedo;
mod compensated;
mod lambert;
mod layered;
mod lobe;
mod microfacet;
mod normal_mapping;
mod phong;
mod specular;
mod view_compensated;

pub use albedo::{
    ALBEDO_ALPHA_MAX, ALBEDO_ALPHA_MIN, ALBEDO_GRID, ALBEDO_MU_EPSILON, AlbedoTable, average_of_row,
};
pub use albedo_anisotropic::{
    ANISO_ALPHA_LOW, ANISO_ALPHA_NODES, ANISO_ALPHA_OFFSET, ANISO_ENTRIES, ANISO_MU_NODES,
    ANISO_PHI_NODES, AnisotropicAlbedo, AnisotropicAlbedoTable, encode_albedo,
};
pub use blinn_phong::{BlinnPhongLobe, BlinnPhongNormalization};
pub use clear_coat::ClearCoat;
#[cfg(feature = "std")]
pub(crate) use clear_coat::inside_view;
pub use coat_albedo::{
    BaseAlbedo, COAT_ALBEDO_DIRECTIONS, COAT_ALBEDO_GRID, MAX_COAT_ETA, MAX_ROUND_TRIP,
    MIN_COAT_ETA, diffuse_external_reflectance, diffuse_internal_reflectance,
};
pub use compensated::{
    EnergyCompensated, TabulatedAlbedo, average_fresnel, multiple_scattering_fresnel,
};
pub use lambert::Lambert;
pub(crate) use lambert::unit_rgb;
pub use layered::{LayeredBrdf, TRANSMISSION_SAMPLES};
pub use microfacet::{Masking, MicrofacetBrdf, Sampling};
pub use normal_mapping::{NormalMapMicrofacet, NormalMapTilt, ShadingNormal};
pub use phong::{
    ARVO_MAX_GAMMA, OriginalPhong, OriginalPhongNormalization, Phong, PhongNormalization,
};
pub use specular::SpecularReflection;
pub use view_compensated::{AlbedoEstimate, ViewCompensated};

/// Which kinds of lobe a sample came from (a small bit set).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LobeFlags(u8);

impl LobeFlags {
    /// No lobe.
    pub const NONE: LobeFlags = LobeFlags(0);
    /// Reflection (the only transport this crate models today).
    pub const REFLECTION: LobeFlags = LobeFlags(1);
    /// A diffuse lobe (Lambert and the diffuse part of Phong).
    pub const DIFFUSE: LobeFlags = LobeFlags(2);
    /// A glossy lobe (Phong specular, rough microfacets, glint patches).
    pub const GLOSSY: LobeFlags = LobeFlags(4);
    /// A delta lobe (perfect mirror, [`SpecularReflection`]): the sample's `pdf` is the discrete
    /// probability of the lobe, not a density, and `eval` / `pdf` return 0 at its direction. A
    /// renderer multiplies the throughput by `weight()` and uses neither MIS nor next-event
    /// estimation for it (the delta-lobe convention on [`Bxdf`]).
    pub const SPECULAR: LobeFlags = LobeFlags(8);

    /// Whether every flag of `other` is set in `self`.
    #[inline]
    pub const fn contains(self, other: LobeFlags) -> bool {
        self.0 & other.0 == other.0
    }

    /// The raw bits.
    #[inline]
    pub const fn bits(self) -> u8 {
        self.0
    }
}

impl core::ops::BitOr for LobeFlags {
    type Output = LobeFlags;
    #[inline]
    fn bitor(self, rhs: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 | rhs.0)
    }
}

impl core::ops::BitOrAssign for LobeFlags {
    #[inline]
    fn bitor_assign(&mut self, rhs: LobeFlags) {
        self.0 |= rhs.0;
    }
}

/// One sampled direction with its BRDF value and density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BxdfSample {
    /// The sampled direction (unit, away from the surface, local frame).
    pub wi: Vec3,
    /// f(wo, wi), without the cosine; agrees with [`Bxdf::eval`] (for a `SPECULAR` sample: F / cos θi,
    /// see the delta-lobe convention on [`Bxdf`]).
    pub f: Vec3,
    /// Density of `wi` per unit solid angle; finite, > 0, agrees with [`Bxdf::pdf`] (for a `SPECULAR`
    /// sample: the discrete probability of the lobe).
    pub pdf: f32,
    /// The lobe the sample came from.
    pub flags: LobeFlags,
}

impl BxdfSample {
    /// A sample, if it is usable: a finite positive `pdf`, a finite `f`, a finite upper-hemisphere
    /// `wi` and a finite weight f · cos θi / pdf; otherwise `None`.
    ///
    /// Every sampler of the crate finishes through this check, so that `Some` always means a sample a
    /// renderer can use as it is. The weight test matters only at the numerical edge: a pdf near
    /// f32's smallest normal (cos θo ~ 10⁻⁴⁰) can make f · cos θi / pdf overflow.
    #[inline]
    pub fn checked(wi: Vec3, f: Vec3, pdf: f32, flags: LobeFlags) -> Option<BxdfSample> {
        let usable = pdf > 0.0
            && pdf.is_finite()
            && f.is_finite()
            && wi.is_finite()
            && wi.z > 0.0
            && weight_of(f, wi, pdf).is_finite();
        usable.then_some(BxdfSample { wi, f, pdf, flags })
    }

    /// The Monte Carlo weight f · cos θ_i / pdf, formed in `f64` so that it is correctly rounded
    /// even where cos θi / pdf alone would leave f32's normal range (cos θi ~ 10⁻²³ at grazing
    /// views, where that quotient is subnormal and loses most of its digits).
    #[inline]
    pub fn weight(&self) -> Vec3 {
        weight_of(self.f, self.wi, self.pdf)
    }
}

/// f · max(cos θi, 0) / pdf per channel, in `f64`, rounded once to `f32`.
#[inline]
fn weight_of(f: Vec3, wi: Vec3, pdf: f32) -> Vec3 {
    let s = wi.z.max(0.0) as f64 / pdf as f64;
    Vec3::new(
        (f.x as f64 * s) as f32,
        (f.y as f64 * s) as f32,
        (f.z as f64 * s) as f32,
    )
}

/// A BRDF in the local shading frame.
///
/// `eval` returns f (RGB, no cosine); `pdf` is per unit solid angle of `wi`. Below-horizon, degenerate
/// or non-finite directions give 0 and pdf 0, and `sample` returns `None` instead of a zero-weight sample.
///
/// # Delta lobes
/// A lobe that reflects into a single direction ([`SpecularReflection`]) has no value or density
/// per unit solid angle. Its `eval` and `pdf` are 0 for every pair of directions; its `sample`
/// returns that direction with [`LobeFlags::SPECULAR`] set, `pdf` = the discrete probability of
/// choosing the lobe (1 for a lone lobe) and `f` = F / cos θi, so that [`BxdfSample::weight`] is
/// the reflectance F. For such a sample, and only for it, `f` and `pdf` are not those of `eval` and
/// `pdf` at its `wi`. A path tracer with MIS handles it as pbrt-v4 does: it multiplies the
/// throughput by `weight()`, gives the sample an MIS weight of 1, and does no next-event estimation
/// at the vertex (a light sample would find `eval` = 0 there anyway).
pub trait Bxdf {
    /// f(wo, wi), without the cosine factor.
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3;

    /// Density (per unit solid angle of `wi`) with which [`Bxdf::sample`] draws `wi`.
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32;

    /// Draws `wi` given `wo`, using `uc` for the lobe choice and `u` for the direction.
    /// `Some` guarantees a finite positive pdf that agrees with [`Bxdf::pdf`] and an `f` that agrees
    /// with [`Bxdf::eval`], except for a [`LobeFlags::SPECULAR`] sample (the delta-lobe convention
    /// above).
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<BxdfSample>;

    /// Both [`Bxdf::eval`] and [`Bxdf::pdf`], sharing work where a model can.
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> (Vec3, f32) {
        (self.eval(wo, wi), self.pdf(wo, wi))
    }
}

/// Implements every method of [`Bxdf`] for a type that hands each call to a BRDF it holds:
/// `$dispatch!` is a macro of the form `($s:ident, $b:ident => $e:expr)` that binds the inner BRDF of
/// `$s` to `$b` and evaluates `$e` (a `match` over an enum's variants, or a dereference). Written
/// once, so every forwarding type forwards every method, the default `eval_pdf` included; the unit
/// test `forward_bxdf_names_every_method_of_the_trait` fails when the trait gains a method this list
/// lacks. `[$generics]` are the impl's generic parameters, possibly empty.
macro_rules! forward_bxdf {
    ([$($generics:tt)*] $ty:ty, $dispatch:ident) => {
        impl<$($generics)*> $crate::bxdf::Bxdf for $ty {
            #[inline]
            fn eval(&self, wo: glam::Vec3, wi: glam::Vec3) -> glam::Vec3 {
                $dispatch!(self, b => b.eval(wo, wi))
            }
            #[inline]
            fn pdf(&self, wo: glam::Vec3, wi: glam::Vec3) -> f32 {
                $dispatch!(self, b => b.pdf(wo, wi))
            }
            #[inline]
            fn sample(
                &self,
                wo: glam::Vec3,
                uc: f32,
                u: glam::Vec2,
            ) -> Option<$crate::bxdf::BxdfSample> {
                $dispatch!(self, b => b.sample(wo, uc, u))
            }
            #[inline]
            fn eval_pdf(&self, wo: glam::Vec3, wi: glam::Vec3) -> (glam::Vec3, f32) {
                $dispatch!(self, b => b.eval_pdf(wo, wi))
            }
        }
    };
}
#[cfg(feature = "std")]
pub(crate) use forward_bxdf;

// A reference to a BRDF is a BRDF.
forward_bxdf!([T: Bxdf + ?Sized] &T, deref_dispatch);

#[cfg(test)]
mod forwarding_tests {
    use crate::ndf::forwarding_tests::{block, fn_names};

    #[test]
    fn forward_bxdf_names_every_method_of_the_trait() {
        let src = include_str!("mod.rs");
        let methods = fn_names(block(src, "pub trait Bxdf {"));
        let forwarded = fn_names(block(src, "macro_rules! forward_bxdf {"));
        assert!(methods.len() >= 4, "{methods:?}");
        assert_eq!(methods, forwarded);
    }
}
