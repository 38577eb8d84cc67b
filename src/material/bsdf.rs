//! The BSDF of a material at one shading point: a [`Bxdf`](crate::bxdf::Bxdf) that borrows the material (and, for
//! glints, the patch's buffers from the caller's scratch).

use super::{AnalyticNdf, AnyFresnel};
use crate::bxdf::{
    BlinnPhongLobe, ClearCoat, EnergyCompensated, Lambert, LayeredBrdf, MicrofacetBrdf,
    NormalMapMicrofacet, NormalMapTilt, OriginalPhong, Phong, SpecularReflection, ViewCompensated,
    forward_bxdf,
};
use crate::glint::GlintPatch;

/// A material's BRDF at one shading point ([`Material::bsdf`](super::Material::bsdf)): evaluate,
/// sample and take densities through [`Bxdf`](crate::bxdf::Bxdf), in the local shading frame (z = normal, x along
/// ∂p/∂u, y along ∂p/∂v; crate-root conventions). Delta lobes (a mirror) follow the crate's delta
/// convention: `eval` and `pdf` 0, samples flagged `SPECULAR` ([`Bxdf`](crate::bxdf::Bxdf)).
///
/// It borrows the material and, for glint materials, buffers from the caller's
/// [`GlintScratch`](crate::glint::GlintScratch), which it gives back when it drops; any number of
/// `Bsdf`s of one scratch can be alive at once (one per path vertex, say). Building one allocates
/// nothing once the scratch is warm.
#[derive(Debug)]
pub struct Bsdf<'a>(pub(super) Coat<'a>);

/// The BRDF behind a [`Bsdf`]: a material's own, or that under a clear coat (one level: coats do
/// not nest, so the type is not recursive and needs no allocation).
#[derive(Debug)]
pub(super) enum Coat<'a> {
    Bare(Inner<'a>),
    Coated(ClearCoat<Inner<'a>>),
}

/// The BRDF of a material without its clear coat.
#[derive(Debug)]
pub(super) enum Inner<'a> {
    Plain(Plain<'a>),
    Glint(MicrofacetBrdf<GlintPatch<'a>, AnyFresnel>),
    GlintCompensated(ViewCompensated<GlintPatch<'a>, AnyFresnel>),
    GlintCoat(LayeredBrdf<GlintPatch<'a>, AnyFresnel>),
    Tilt(NormalMapTilt<Plain<'a>>),
    NormalMicrofacet(NormalMapMicrofacet<Plain<'a>>),
}

/// The BRDFs that do not depend on the footprint: what a normal-mapped material can wrap.
#[derive(Debug)]
pub(super) enum Plain<'a> {
    Lambert(&'a Lambert),
    Phong(&'a Phong),
    OriginalPhong(&'a OriginalPhong),
    BlinnPhong(&'a BlinnPhongLobe),
    Microfacet(&'a MicrofacetBrdf<AnalyticNdf, AnyFresnel>),
    Compensated(&'a EnergyCompensated<AnalyticNdf, AnyFresnel>),
    /// A copy per shading point, prepared for its view (R̂(wo) computed once:
    /// [`LayeredBrdf::prepare_view`]).
    Layered(LayeredBrdf<AnalyticNdf, AnyFresnel>),
    Mirror(&'a SpecularReflection<AnyFresnel>),
}

/// Forwards one `Bxdf` method to the BRDF behind a [`Plain`].
macro_rules! forward_plain {
    ($self_:expr, $b:ident => $e:expr) => {
        match $self_ {
            Plain::Lambert($b) => $e,
            Plain::Phong($b) => $e,
            Plain::OriginalPhong($b) => $e,
            Plain::BlinnPhong($b) => $e,
            Plain::Microfacet($b) => $e,
            Plain::Compensated($b) => $e,
            Plain::Layered($b) => $e,
            Plain::Mirror($b) => $e,
        }
    };
}

/// Forwards one `Bxdf` method to the BRDF behind an [`Inner`].
macro_rules! forward_inner {
    ($self_:ident, $b:ident => $e:expr) => {
        match $self_ {
            Inner::Plain($b) => $e,
            Inner::Glint($b) => $e,
            Inner::GlintCompensated($b) => $e,
            Inner::GlintCoat($b) => $e,
            Inner::Tilt($b) => $e,
            Inner::NormalMicrofacet($b) => $e,
        }
    };
}

forward_bxdf!(['a] Plain<'a>, forward_plain);

/// Forwards one `Bxdf` method to the BRDF behind a [`Bsdf`].
macro_rules! forward_coat {
    ($self_:ident, $b:ident => $e:expr) => {
        match &$self_.0 {
            Coat::Bare($b) => $e,
            Coat::Coated($b) => $e,
        }
    };
}

forward_bxdf!(['a] Inner<'a>, forward_inner);

forward_bxdf!(['a] Bsdf<'a>, forward_coat);
