//! A Fresnel term chosen at run time: the crate's Fresnel models behind one `Copy` enum, so that a
//! [`Material`](super::Material) holds any of them without a type parameter or a heap allocation.

use crate::fresnel::{ConductorFresnel, DielectricFresnel, Fresnel, NoFresnel, SchlickFresnel};
use glam::Vec3;

/// Any Fresnel model of [`crate::fresnel`], dispatched by a `match` (no allocation, no virtual
/// call). Build it with `From` from the model (`ConductorFresnel::GOLD.into()`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnyFresnel {
    /// F = 1 ([`NoFresnel`]): white furnace tests, or a BRDF whose colour is elsewhere.
    None(NoFresnel),
    /// Schlick's approximation ([`SchlickFresnel`]).
    Schlick(SchlickFresnel),
    /// The exact dielectric reflectance ([`DielectricFresnel`]).
    Dielectric(DielectricFresnel),
    /// The exact conductor reflectance ([`ConductorFresnel`]).
    Conductor(ConductorFresnel),
}

impl Fresnel for AnyFresnel {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        match self {
            AnyFresnel::None(f) => f.eval(cos_theta),
            AnyFresnel::Schlick(f) => f.eval(cos_theta),
            AnyFresnel::Dielectric(f) => f.eval(cos_theta),
            AnyFresnel::Conductor(f) => f.eval(cos_theta),
        }
    }
}

impl From<NoFresnel> for AnyFresnel {
    fn from(f: NoFresnel) -> Self {
        AnyFresnel::None(f)
    }
}

impl From<SchlickFresnel> for AnyFresnel {
    fn from(f: SchlickFresnel) -> Self {
        AnyFresnel::Schlick(f)
    }
}

impl From<DielectricFresnel> for AnyFresnel {
    fn from(f: DielectricFresnel) -> Self {
        AnyFresnel::Dielectric(f)
    }
}

impl From<ConductorFresnel> for AnyFresnel {
    fn from(f: ConductorFresnel) -> Self {
        AnyFresnel::Conductor(f)
    }
}
