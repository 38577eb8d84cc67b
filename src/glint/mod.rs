//! Glints: normal maps, ray footprints, the ground-truth P-NDF, and the glint NDF models.
//!
//! The data flow (see `docs/glint.md`): a [`NormalMap`] (per-texel slopes, tiled, bilinearly
//! interpolated normals) is turned once into a precomputed glint representation (a [`GlintNdf`]); at
//! each shading point a [`Footprint`] built from the ray differentials selects a patch of the map whose
//! P-NDF D_P(ω_h) (Chermain 2019, eq. 8) is an [`Ndf`] that any microfacet BRDF consumes:
//! `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`.
//!
//! More in `docs/glint.md`; the module layout and the data flow of a query in `docs/architecture.md`.
//!
//! ## Where things are
//!
//! - **Models**, each a public module that owns its build parameters, its per-query options and its
//!   `DEFAULT_*` constants: [`mixture`] (the Beckmann mixture of \[Chermain2019\]), [`binmap`] (the
//!   inverse bin map of \[Atanasov2020\]), [`position_normal`] (the position-normal Gaussians of
//!   \[Yan2016\], the baseline); without a normal map, [`procedural`] (glints from a seed and a
//!   facet density, converging to a Beckmann NDF, in bounded time per footprint: docs/procedural.md).
//!   Their model and patch types are re-exported here, with [`GlintModel`], which holds any of them
//!   at run time.
//! - **Inputs** (re-exported here): [`NormalMap`] and the procedural maps, image decoding,
//!   [`Footprint`].
//! - **Truths** (re-exported here): [`binned_pndf`], [`convolved_pndf`], [`tv_distance`],
//!   [`FootprintBrdf`] and the [`HemisphereBins`] they are tabulated on.
//!
//! ## Which model where
//!
//! The crate's one guide (the same table as the crate docs' and docs/glint.md's, whose "Which model
//! where" adds the per-map tables). "Texels per pixel" is the pixel footprint's area on the map
//! ([`GlintModel::footprint_texels`]).
//!
//! <!-- which-model:begin -->
//! Measured on the orb (docs/results.md, "Error against time"): a metallic sphere under a point
//! light, 128² pixels, 5 maps of 512² (scratched, brushed, bumpy, flakes, fractal) at 5 pixel
//! footprints, every glint model at the material's σ_ε = 0.01 and its default options (the mixture
//! also with its level of detail off, "no LOD"), against naive normal mapping at 1-4,096 samples
//! per pixel. Per footprint and target error (denoised relative RMSE against the exact P-BRDF): the
//! method that first reaches it on each map, with a glint model's equal-error speedup over naive
//! (∞: naive does not get there by 4,096 spp); build times not counted (docs/glint.md, "Which model
//! where", has the per-map tables with builds). Times are wall-clock, ±30 % between runs. Last
//! column: the error of [the mixture](crate::glint::BeckmannMixture) at its defaults, one
//! evaluation per pixel. Generated from docs/data/orb_curves.csv by `python3 tools/orb_which.py
//! --write`.
//!
//! | texels per pixel | first to 0.2 | first to 0.1 | first to 0.05 | mixture's error |
//! |---|---|---|---|---|
//! | 1 | naive: scratched, brushed, bumpy, fractal; mixture (no LOD): flakes (1.2×) | naive: brushed, bumpy, flakes, fractal; mixture: scratched (1.3×) | naive: brushed, bumpy, flakes, fractal; mixture: scratched (2.4×) | 0.02-0.70 |
//! | 9 | naive: brushed, bumpy, fractal; pos.-normal: scratched, flakes (1.2-2.4×) | naive: brushed, bumpy, fractal; mixture (no LOD): scratched, flakes (3.8-5.1×) | naive: scratched, brushed, fractal; mixture (no LOD): flakes (13×); nothing: bumpy | 0.03-0.43 |
//! | 34 | naive: brushed, bumpy, flakes, fractal; mixture (no LOD): scratched (3.8×) | naive: scratched, brushed, flakes, fractal; nothing: bumpy | naive: scratched, brushed; nothing: bumpy, flakes, fractal | 0.12-0.28 |
//! | 2,186 | bin map: scratched, brushed (5.5-39×); mixture: bumpy, fractal (∞×); naive: flakes | mixture: brushed, fractal (4.5-∞×); naive: scratched; pos.-normal: flakes (3.8×); nothing: bumpy | mixture: scratched, flakes (3.2-∞×); nothing: brushed, bumpy, fractal | 0.01-0.10 |
//! | 139,898 | mixture: scratched, brushed, bumpy, fractal (13-∞×); naive: flakes | mixture: scratched, brushed, bumpy, fractal (50-∞×); nothing: flakes | bin map: scratched, brushed (34-∞×); mixture: fractal (∞×); nothing: bumpy, flakes | 0.04-0.27 |
//! <!-- which-model:end -->
//!
//! Cost of one renderer shading point at each footprint (every model at its defaults, against an
//! analytic GGX one): docs/results.md, "Cost and error of a shading point against footprint". Each
//! model chooses its own form per footprint by a measured error: the mixture its sub-texel lobe,
//! gathered lobes, filtered mixture or a cut of its filtered-mixture hierarchy
//! ([`mixture::PatchOptions`]), position-normal its element sum, filtered mixture or the same cut
//! ([`position_normal::PatchOptions`]), the bin map its exact or moment-lobe masking
//! ([`binmap::PatchOptions`]). Those errors are measured by the build and stored in files (a
//! model holds no state filled on first use). The cut (src/glint/kernels/cut.rs) chooses its nodes
//! by residuals stored at build.
//!
//! ## Adding a model
//!
//! 1. A folder `src/glint/<model>/` whose `params.rs` holds its parameters, its per-query options
//!    and their `DEFAULT_*` constants, and whose `mod.rs` (or a `model.rs`) holds the model type
//!    (docs/architecture.md, "Adding a glint model"); the model implements [`GlintNdf`] (its
//!    patch takes its buffers from the scratch's pool of their type with `GlintScratch`'s
//!    crate-private `home::<T>()`, so the scratch needs no field for it) and the crate-private `Stored` trait of `io/format.rs`
//!    (`save` / `load` in the crate's file format).
//! 2. One line per registry: the model's file-format `Kind` code (`io/header.rs`), its line in the
//!    `glint_models!` registry (`model.rs`: the [`GlintModel`] and [`GlintPatch`] variants, the
//!    [`GlintOptions`] field, save/load dispatch), its `serde` line (`serialize.rs`), and
//!    `pub mod` plus the re-export of its model and patch types here.
//! 3. The registry's completeness test (tests/it/glint_registry.rs) lists an example of every
//!    registered model and fails until the new one is there: it saves and loads each through
//!    [`GlintModel`]; tests/serde.rs round-trips each through `serde` and tests/alloc.rs checks
//!    that a patch built in a warm scratch allocates nothing.
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
//!   [`NormalMap::from_heights`]). On a surface, +u and +v are ∂p/∂u and ∂p/∂v: build the shading frame
//!   with [`Frame::from_surface`](crate::frame::Frame::from_surface)`(n, ∂p/∂u, ∂p/∂v)`, whose x and y
//!   follow them for either handedness of the parametrisation (a frame built as y = n × x would
//!   mirror the map on a left-handed one).
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

pub mod binmap;
mod compensation;
mod form;
mod form_report;
mod io;
mod kernels;
pub mod mixture;
mod model;
pub mod position_normal;
pub mod procedural;
mod scratch;
#[cfg(feature = "serde")]
mod serialize;
mod surface;
mod truth;

pub use binmap::{BinMap, BinMapPatch};
pub use form::PatchForm;
pub use form_report::{FormReport, FormRow};
pub use mixture::{BeckmannMixture, MixturePatch};
pub use model::{GlintModel, GlintOptions, GlintPatch};
pub use position_normal::{PositionNormalBrdf, PositionNormalMap, PositionNormalPatch};
pub use procedural::{ProceduralGlints, ProceduralPatch};
pub use scratch::GlintScratch;
pub use surface::{
    BrushedParams, FlakesParams, Footprint, MAX_ANISOTROPY, MAX_CARVE_WORK_PER_TEXEL,
    MAX_EXTENT_PERIODS, MAX_GENERATED_TEXELS, MAX_SLOPE, MIN_CELL_TEXELS, MIN_WIDTH_TEXELS,
    NormalMap, NormalRepair, RayCone, RayDifferential, ScratchedParams, SlopeMomentPyramid,
    TangentConvention, brushed, bumpy, flakes, moments_mean_covariance, scratched,
};
pub use surface::{
    DEFAULT_LENGTH_TOLERANCE, DEFAULT_MAX_IMAGE_TEXELS, FloatEncoding, HemisphereBins,
    ImageDecoding, ImageOptions, MAX_IMPLAUSIBLE_FRACTION, RAW_EVIDENCE_BELOW,
};
pub use truth::{
    BinMasses, BinnedPndf, DEFAULT_MAX_QUADRATURE, DEFAULT_QUADRATURE_TOLERANCE, FootprintBrdf,
    JITTERS, Kernel, REFERENCE_BATCHES, adaptive_bin_masses, bin_masses, binned_pndf,
    convolved_pndf, footprint_brdf, for_each_footprint_slope, naive_brdf, tv_distance,
};

use crate::ndf::Ndf;

/// A precomputed glint representation of one normal map.
///
/// Implemented by the glint models (Beckmann mixture, inverse bin map, position-normal Gaussians)
/// and by [`GlintModel`], which holds any of them. Building the representation is the expensive,
/// once-per-map step; [`GlintNdf::patch_with`] is the per-shading-point step, and the returned patch
/// answers per-direction queries (`d`, `lambda`, `projected_area`, sampling) cheaply. The patch is an
/// [`Ndf`] in the local frame of the geometric surface (z = ω_g), normalised like every NDF of the
/// crate: ∫ D_P(m) (m·ω_g) dm = 1.
///
/// Every query goes through one path, [`GlintNdf::patch_with`]: the footprint, the per-query
/// [`Options`](GlintNdf::Options) (level of detail, masking, smoothing; each model's own type, with
/// its `DEFAULT_*` constants in the model's module), and optionally a per-thread [`GlintScratch`]
/// that lends the patch its buffers. [`GlintNdf::patch`] and [`GlintNdf::patch_in`] are the same with
/// `Self::Options::default()`.
///
/// **Options are per query, never part of a model.** A model holds only what its build made, and
/// its file (`save` / `load`) stores no options, so a patch depends on the model, the footprint and
/// the options passed, and on nothing else: a loaded model with the same options gives bit-identical
/// patches, and [`GlintNdf::patch`] always means the documented defaults. A renderer that wants
/// other options keeps them with its material and passes them to every query. There is no
/// accessor for "the model's options": a model has none to report, and a `patch` whose meaning
/// depended on how the model was built or loaded is the hidden state this design rules out.
///
/// # Example
///
/// The shape of an implementation (here a toy model whose every patch is the same smooth lobe):
///
/// ```
/// use brdf::glint::{Footprint, GlintNdf, GlintScratch, NormalMap};
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
///     type Options = ();
///     fn patch_with<'a>(
///         &'a self,
///         footprint: &Footprint,
///         _options: &(),
///         _scratch: Option<&'a GlintScratch>,
///     ) -> Patch<'a> {
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

    /// Per-query options of the patches (level of detail, masking, smoothing); `Default` gives the
    /// model's documented `DEFAULT_*` values.
    type Options: Clone + Default + std::fmt::Debug;

    /// The P-NDF of the surface seen through one ray footprint:
    /// D_P(ω_h) = ∫ δ(ω_n(u) − ω_h) k_P(u) du (\[Chermain2019\] eq. 8), as approximated by the model
    /// with `options`. With a `scratch` (one per render thread), the patch takes its working
    /// buffers from it and gives them back when it drops; several patches of one scratch can be
    /// alive at once. Once the scratch has grown to the largest need it serves (the largest
    /// footprint's, or under a coarse level of detail possibly a smaller footprint's, which gathers
    /// more lobes; and the most live patches), building and querying a patch performs no heap
    /// allocation (tests/alloc.rs).
    /// Without one, the patch allocates its own. Results are bit-identical either way.
    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &Self::Options,
        scratch: Option<&'a GlintScratch>,
    ) -> Self::Patch<'a>;

    /// [`GlintNdf::patch_with`] with the default options (`Self::Options::default()`), allocating.
    fn patch(&self, footprint: &Footprint) -> Self::Patch<'_> {
        self.patch_with(footprint, &Self::Options::default(), None)
    }

    /// [`GlintNdf::patch_with`] with the default options (`Self::Options::default()`) and the
    /// buffers of a caller's [`GlintScratch`].
    fn patch_in<'a>(&'a self, footprint: &Footprint, scratch: &'a GlintScratch) -> Self::Patch<'a> {
        self.patch_with(footprint, &Self::Options::default(), Some(scratch))
    }
}
