//! The analytic NDFs a material can hold, as one enum implementing [`Ndf`](crate::ndf::Ndf) by dispatch.

use crate::bxdf::{AlbedoTable, AnisotropicAlbedoTable, TabulatedAlbedo};
use crate::ndf::{Beckmann, Ggx, forward_ndf};

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

forward_ndf!([] AnalyticNdf, forward);

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
