//! Glints: normal maps, ray footprints, the ground-truth P-NDF, and the glint NDF models.
//!
//! The data flow (see `docs/glint.md`): a [`NormalMap`] (per-texel slopes, tiled, bilinearly
//! interpolated normals) is turned once into a precomputed glint representation (a [`GlintNdf`]); at
//! each shading point a [`Footprint`] built from the ray differentials selects a patch of the map whose
//! P-NDF D_P(ω_h) (Chermain 2019, eq. 8) is an [`Ndf`] that any microfacet BRDF consumes:
//! `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`.
//!
//! More in `docs/glint.md`.
//!
//! ## Texel space (every glint model relies on this)
//!
//! - A map has `width` × `height` texels (any size ≥ 1 × 1, not necessarily square or a power of two),
//!   stored row major: texel (i, j) is `slopes()[j * width + i]`, column i ∈ [0, width), row j ∈ [0, height).
//! - **Texel units.** Texel (i, j) covers the square [i, i + 1) × [j, j + 1); its sample sits at the
//!   centre (i + ½, j + ½).
//! - **uv.** uv = texel coordinate / (width, height), so uv ∈ [0, 1)² covers the map once; row j = 0 is
//!   v = 0. The map **tiles**: every position p ∈ ℝ² is valid and texel indices wrap (`rem_euclid`).
//! - **Tangent frame.** The slope x̃ is along +u (increasing column), ỹ along +v (increasing row). A
//!   slope ñ = (x̃, ỹ) is the slope of the normal ω_n = normalize(−x̃, −ỹ, 1) (crate convention), so for a
//!   height field h the slope is its gradient (∂h/∂u, ∂h/∂v) in texel units (see
//!   [`NormalMap::from_heights`]).
//! - **Image files.** Files are stored top row first, but texture coordinates conventionally put v = 0
//!   at the *bottom* of the picture (OpenGL, pbrt, Blender). The loader follows that convention: the
//!   **bottom row of the file is texel row 0** (v = 0) and the top row is row `height − 1`, so +v (and the
//!   slope's ỹ) points up in the picture. With [`TangentConvention::OpenGl`] (green = +Y = up) the green
//!   channel is then taken as is; [`TangentConvention::DirectX`] (green = down) flips it. A renderer whose
//!   v = 0 is the *top* of the picture passes (u, 1 − v) and negates the v components of its ray
//!   differentials.
//!
//! ## The reference surface
//!
//! The surface a glint model approximates is the **bilinearly interpolated normal map**: at a texel
//! position p, the four texels whose centres surround p contribute their unit normals with bilinear
//! weights, and the sum is renormalised ([`NormalMap::normal_at_texel`]). It is continuous everywhere,
//! across texel and tile borders, and exact at texel centres. Because every stored normal lies strictly
//! above the horizon, the blend does too, so the interpolated slope is always defined.
//!
//! ## Footprints
//!
//! A [`Footprint`] has two consistent views: the parallelogram {uv + a ∂uv/∂x + b ∂uv/∂y : a, b ∈
//! [−½, ½]} and the Gaussian of the same mean and covariance Σ = (∂uv/∂x ∂uv/∂xᵀ + ∂uv/∂y ∂uv/∂yᵀ)/12,
//! both of area |det| (= 12 √det Σ), read in texel units of a map with documented clamps
//! ([`MIN_WIDTH_TEXELS`], [`MAX_ANISOTROPY`], [`MAX_EXTENT_PERIODS`]).
//!
//! ## Ground truth
//!
//! [`binned_pndf`] estimates the P-NDF of the interpolated map through a footprint on equal-area
//! [`HemisphereBins`], with ∫ D cos θ dω = 1 (D_P(m) = ∫ δ(ω_n(u) − m) k_P(u) du / cos θ_m);
//! [`tv_distance`] compares a model with it; [`naive_brdf`] is normal-mapped shading at one position;
//! [`FootprintBrdf`] / [`footprint_brdf`] give the two references of a footprint's BRDF (the exact
//! P-BRDF of eq. 7 with the true P-NDF, and normal-mapped shading averaged over the footprint).

mod binmap;
mod bins;
mod cdf;
mod footprint;
#[cfg(feature = "image")]
mod image_io;
mod mixture;
mod model;
mod moments;
mod multiset;
mod normal_map;
mod position_normal;
mod procedural;
mod reference;
mod scratch;
#[cfg(feature = "serde")]
mod serde_impl;
mod slope_tree;
mod store;

pub use binmap::{
    BinLookup, BinMap, BinMapMemory, BinMapParams, BinMapPatch, DEFAULT_BINS_PER_AXIS,
    DEFAULT_LEAF_SIZE, DEFAULT_LOOKUP, DEFAULT_MASKING_SIGMA_MIN, DEFAULT_SUBDIVISIONS,
    EXACT_MASKING_TEXELS, MASKING_FIRST_LEVEL, MAX_SUBDIVISIONS, QueryStats,
};
pub use bins::HemisphereBins;
pub use footprint::{Footprint, MAX_ANISOTROPY, MAX_EXTENT_PERIODS, MIN_WIDTH_TEXELS};
#[cfg(feature = "image")]
pub use image_io::{
    DEFAULT_LENGTH_TOLERANCE, FloatEncoding, ImageDecoding, ImageOptions, MAX_IMPLAUSIBLE_FRACTION,
    RAW_EVIDENCE_BELOW,
};
pub use mixture::{
    BeckmannMixture, DEFAULT_KERNEL_SIGMAS, DEFAULT_LOD_LOBES, DEFAULT_LOD_RESOLUTION,
    DEFAULT_LOD_TOLERANCE, DEFAULT_MASKING, DEFAULT_SAMPLES, DEFAULT_SIGMA_MIN, DEFAULT_SLOPE_TAIL,
    DEFAULT_SPACING, DEFAULT_WEIGHT_SIGMAS, LOD_RESOLUTIONS, MAX_TRUNCATION_SIGMAS, MIN_SPACING,
    MaskingMode, MixtureMemory, MixtureParams, MixturePatch, PatchOptions,
};
pub use mixture::{DEFAULT_SUPERSAMPLING, MAX_SUPERSAMPLING, MomentMethod};
pub use mixture::{LobeStorage, MIN_COMPACT_SIGMA};
pub use model::{GlintModel, GlintPatch};
pub use normal_map::{
    MAX_SLOPE, NormalMap, NormalRepair, TangentConvention, moments_mean_covariance,
};
pub use position_normal::{
    DEFAULT_MASKING_ALPHA, EXACT_MASKING_ELEMENTS, PositionNormalBrdf, PositionNormalMap,
    PositionNormalMemory, PositionNormalParams, PositionNormalPatch,
};
pub use procedural::{
    BrushedParams, FlakesParams, ScratchedParams, brushed, bumpy, flakes, scratched,
};
pub use reference::{
    BinMasses, BinnedPndf, DEFAULT_MAX_QUADRATURE, DEFAULT_QUADRATURE_TOLERANCE, FootprintBrdf,
    JITTERS, Kernel, REFERENCE_BATCHES, adaptive_bin_masses, bin_masses, binned_pndf,
    convolved_pndf, footprint_brdf, naive_brdf, tv_distance,
};
pub use scratch::GlintScratch;

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
/// \[Chermain2019\] §4 (P-NDF, P-Smith term and patch projected area A_P).
pub trait GlintNdf {
    /// The P-NDF of one footprint; may borrow the representation.
    type Patch<'a>: Ndf
    where
        Self: 'a;

    /// The P-NDF of the surface seen through one ray footprint:
    /// D_P(ω_h) = ∫ δ(ω_n(u) − ω_h) k_P(u) du (\[Chermain2019\] eq. 8), as approximated by the model.
    /// May allocate the patch's working buffers; see [`GlintNdf::patch_in`].
    fn patch(&self, footprint: &Footprint) -> Self::Patch<'_>;

    /// The same patch, with its working buffers lent by a caller's [`GlintScratch`] (one per render
    /// thread) and given back when the patch drops: once the scratch has grown to the largest
    /// footprint, building and querying a patch performs no heap allocation. Bit-identical results
    /// to [`GlintNdf::patch`]. The default ignores the scratch (for models that need none).
    fn patch_in<'a>(
        &'a self,
        footprint: &Footprint,
        scratch: &'a mut GlintScratch,
    ) -> Self::Patch<'a> {
        let _ = scratch;
        self.patch(footprint)
    }
}
