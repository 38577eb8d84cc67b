//! Glints: normal maps, ray footprints, the ground-truth P-NDF, and the glint NDF models.
//!
//! The data flow (see `docs/glint.md`): a [`NormalMap`] (per-texel slopes, tiled, bilinearly
//! interpolated normals) is turned once into a precomputed glint representation (a [`GlintNdf`]); at
//! each shading point a [`Footprint`] built from the ray differentials selects a patch of the map whose
//! P-NDF D_P(ω_h) (Chermain 2019, eq. 8) is an [`Ndf`] that any microfacet BRDF consumes:
//! `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`.
//!
//! Texel-space conventions (texel (i, j) covers [i, i+1) × [j, j+1) with its sample at the centre,
//! uv = texel coordinate / size, maps tile, texel row 0 is the bottom row of an image file) are
//! documented on [`NormalMap`] and in `docs/glint.md`.

mod footprint;
#[cfg(feature = "image")]
mod image_io;
mod mixture;
mod moments;
mod normal_map;

pub use footprint::{Footprint, MAX_ANISOTROPY, MAX_EXTENT_PERIODS, MIN_WIDTH_TEXELS};
pub use mixture::{
    BeckmannMixture, DEFAULT_KERNEL_SIGMAS, DEFAULT_LOD_LOBES, DEFAULT_MASKING, DEFAULT_SAMPLES,
    DEFAULT_SIGMA_MIN, DEFAULT_SLOPE_TAIL, DEFAULT_SPACING, DEFAULT_WEIGHT_SIGMAS, MaskingMode,
    MixtureMemory, MixtureParams, MixturePatch, PatchOptions,
};
pub use normal_map::{
    MAX_SLOPE, NormalMap, NormalRepair, TangentConvention, moments_mean_covariance,
};

use crate::ndf::Ndf;

/// A precomputed glint representation of one normal map.
///
/// Implemented by the glint models (Beckmann mixture, inverse bin map, position-normal Gaussians).
/// Building the representation is the expensive, once-per-map step; [`GlintNdf::patch`] is the
/// per-shading-point step, and the returned patch answers per-direction queries (`d`, `lambda`,
/// `projected_area`, sampling) cheaply. The patch is an [`Ndf`] in the local frame of the geometric
/// surface (z = ω_g), normalised like every NDF of the crate: ∫ D_P(m) (m·ω_g) dm = 1.
///
/// # Example
///
/// The shape of an implementation (here a toy model whose every patch is the same smooth lobe):
///
/// ```
/// use brdf::glint::{Footprint, GlintNdf, NormalMap};
/// use brdf::ndf::Ndf;
/// use brdf::{Vec2, Vec3};
///
/// struct Patch<'a> { model: &'a Toy, weight_sum: f32 }
/// impl Ndf for Patch<'_> {
///     fn d(&self, m: Vec3) -> f32 { if m.z > 0.0 { self.weight_sum / std::f32::consts::PI } else { 0.0 } }
///     fn lambda(&self, _w: Vec3) -> f32 { 0.0 }
///     fn sample_normal(&self, _u: Vec2) -> Vec3 { Vec3::Z }
///     fn sample_visible(&self, _wo: Vec3, _u: Vec2) -> Vec3 { Vec3::Z }
/// }
/// struct Toy { map: NormalMap }
/// impl GlintNdf for Toy {
///     type Patch<'a> = Patch<'a>;
///     fn patch(&self, footprint: &Footprint) -> Patch<'_> {
///         // Per-footprint work happens here, once, in texel units of the map.
///         let (_centre, _cov) = footprint.gaussian_texels(self.map.width(), self.map.height());
///         Patch { model: self, weight_sum: 1.0 }
///     }
/// }
///
/// let toy = Toy { map: NormalMap::from_slopes(1, 1, vec![Vec2::ZERO]).unwrap() };
/// let f = Footprint::from_differentials(Vec2::new(0.5, 0.5), Vec2::new(0.01, 0.0), Vec2::new(0.0, 0.01));
/// assert!(toy.patch(&f).d(Vec3::Z) > 0.0);
/// ```
///
/// # Reference
/// [Chermain2019] §4 (P-NDF, P-Smith term and patch projected area A_P).
pub trait GlintNdf {
    /// The P-NDF of one footprint; may borrow the representation.
    type Patch<'a>: Ndf
    where
        Self: 'a;

    /// The P-NDF of the surface seen through one ray footprint:
    /// D_P(ω_h) = ∫ δ(ω_n(u) − ω_h) k_P(u) du ([Chermain2019] eq. 8), as approximated by the model.
    fn patch(&self, footprint: &Footprint) -> Self::Patch<'_>;
}
