//! # brdf
//!
//! BRDF math and glint normal distribution functions for renderers.
//!
//! ## Conventions
//!
//! - **Frame.** Everything is evaluated in the local shading frame: z is the geometric normal
//!   ω_g = (0, 0, 1), x is the tangent along which `alpha_x` acts. `wo` (toward the viewer) and `wi`
//!   (toward the light, or sampled) are unit vectors pointing *away* from the surface. Reflection needs
//!   both strictly above the horizon; otherwise values and pdfs are 0. Use [`frame::Frame`] to move
//!   directions between world space and the local frame.
//! - **Handedness.** At a surface hit the local x runs along ∂p/∂u and y along +∂p/∂v, the axes of a
//!   normal map's slopes and of a [`glint::Footprint`]: build the frame with
//!   [`frame::Frame::from_surface`]`(n, ∂p/∂u, ∂p/∂v)`, which keeps that true for left-handed
//!   parametrisations too (a frame of determinant −1; BRDFs only see local coordinates). A frame
//!   built as y = n × x would mirror brushed or scratched maps there.
//! - **Slopes.** A normal ω_n = (x, y, z) has slope ñ = (−x/z, −y/z); the inverse is
//!   normalize(−x̃, −ỹ, 1).
//! - **NDF normalisation.** ∫ D(m) (m·ω_g) dm = 1 over the hemisphere, for every NDF.
//! - **Projected area.** `projected_area(w)` = A(w), the microsurface's projected area toward `w` per
//!   unit geometric area (cos θ for centred NDFs). Smith: ∫ ⟨w, m⟩ D(m) dm = A(w) (1 + Λ(w)).
//! - **Microfacet BRDF.** f = F · G2 · D(h) / (4 A(wo) cos θi): Chermain's P-BRDF
//!   F G2 D / (4 A(wo) A(wi)) times A(wi)/cos θi, which is 1 for centred NDFs.
//! - **The renderer's measure.** `Bxdf::eval` returns f (RGB, no cosine) such that the reflected
//!   radiance is ∫ f(wo, wi) L(wi) cos θi dωi with the *geometric* cos θi, for every BRDF of the crate,
//!   glint patches included: integrate it as any BRDF (or use `BxdfSample::weight()`). `pdf` is per
//!   unit solid angle of `wi`.
//! - **Randomness.** Samplers take their random numbers as arguments (`uc: f32`, `u: Vec2`); the
//!   warps from [0, 1)² to disks, hemispheres and cones are in [`warp`].
//! - **Fresnel.** `eta` = n_inside / n_outside; a negative cosine means light arriving from inside
//!   (see [`fresnel`]).
//! - **Roughness.** α is exposed directly. Beckmann α = √2·σ (σ = RMS slope per axis).
//! - **Precision.** Public API in `f32`; builders and reference integrators accumulate in `f64`.
//! - **Errors.** Constructors validate and return [`Result`]; evaluation never fails, never panics and
//!   never returns NaN or infinity.

pub mod bxdf;
mod error;
pub mod frame;
pub mod fresnel;
pub mod glint;
mod math;
pub mod ndf;
pub mod warp;

pub use bxdf::{
    BlinnPhongLobe, Bxdf, BxdfSample, Lambert, LayeredBrdf, MicrofacetBrdf, OriginalPhong, Phong,
    PhongNormalization,
};
pub use error::{Error, Result};
pub use fresnel::Fresnel;
pub use glam::{Mat2, Vec2, Vec3};
pub use ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};

/// The README's examples, compiled and run as doctests so that the quick start stays true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
