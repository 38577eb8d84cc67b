//! The analytic NDFs a material can hold, as one enum implementing [`Ndf`] by dispatch.

use crate::bxdf::{AlbedoTable, AnisotropicAlbedoTable, TabulatedAlbedo};
use crate::ndf::{Beckmann, Ggx, Ndf};
use glam::{Vec2, Vec3};

/// GGX or Beckmann (isotropic or anisotropic), chosen at run time: the NDF of an analytic
/// [`Material`](super::Material). Every method forwards to the model, so values are bit-identical
/// to the model's own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnalyticNdf {
    /// Trowbridge-Reitz / GGX ([`Ggx`]).
    Ggx(Ggx),
    /// Beckmann ([`Beckmann`]).
    Beckmann(Beckmann),
}

impl From<Ggx> for AnalyticNdf {
    fn from(n: Ggx) -> Self {
        AnalyticNdf::Ggx(n)
    }
}

impl From<Beckmann> for AnalyticNdf {
    fn from(n: Beckmann) -> Self {
        AnalyticNdf::Beckmann(n)
    }
}

/// Forwards one `Ndf` method to the variant's model.
macro_rules! forward {
    ($self_:ident, $n:ident => $e:expr) => {
        match $self_ {
            AnalyticNdf::Ggx($n) => $e,
            AnalyticNdf::Beckmann($n) => $e,
        }
    };
}

impl Ndf for AnalyticNdf {
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        forward!(self, n => n.d(m))
    }
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        forward!(self, n => n.lambda(w))
    }
    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        forward!(self, n => n.projected_area(w))
    }
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        forward!(self, n => n.visible_area(w))
    }
    #[inline]
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        forward!(self, n => n.g1(w, m))
    }
    #[inline]
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        forward!(self, n => n.g2(wo, wi, m))
    }
    #[inline]
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        forward!(self, n => n.g2_height_correlated(wo, wi, m))
    }
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        forward!(self, n => n.sample_normal(u))
    }
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f32 {
        forward!(self, n => n.pdf_normal(m))
    }
    #[inline]
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        forward!(self, n => n.sample_visible(wo, u))
    }
    #[inline]
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        forward!(self, n => n.pdf_visible(wo, m))
    }
}

impl TabulatedAlbedo for AnalyticNdf {
    fn albedo_table(&self) -> &'static AlbedoTable {
        forward!(self, n => n.albedo_table())
    }
    fn anisotropic_albedo_table(&self) -> &'static AnisotropicAlbedoTable {
        forward!(self, n => n.anisotropic_albedo_table())
    }
    fn table_alphas(&self) -> (f32, f32) {
        forward!(self, n => n.table_alphas())
    }
}
