//! # brdf
//!
//! BRDF math and glint normal distribution functions for renderers: Fresnel, analytic NDFs, classic
//! and microfacet BRDFs, and glints (the sparkle of scratched, brushed and flaky metal) from a
//! high-definition normal map through one of three glint models, or without a map from procedural
//! glints ([`glint::procedural`]).
//!
//! ## Quick start
//!
//! ```
//! use brdf::ndf::Ndf;
//! use brdf::{Vec2, Vec3};
//!
//! # fn main() -> Result<(), brdf::Error> {
//! // Directions live in the local shading frame: z is the surface normal, vectors point away from it.
//! let wo = Vec3::new(0.6, 0.0, 0.8);
//! let ndf = brdf::ndf::Ggx::new(0.3, 0.1)?; // anisotropic GGX, α_x = 0.3, α_y = 0.1
//! let m = ndf.sample_visible(wo, Vec2::new(0.25, 0.75));
//! let density = ndf.pdf_visible(wo, m);
//! assert!(density > 0.0 && density.is_finite());
//! // Bad input is rejected at construction, with the parameter named:
//! assert!(brdf::ndf::Ggx::isotropic(f32::NAN).is_err());
//! # Ok(())
//! # }
//! ```
//!
//! ## Glints in a renderer
//!
//! A glint material is a normal map made into a glint model once; then, at every shading point, a
//! footprint (from the hit's uv, ∂p/∂u, ∂p/∂v and ray differentials ∂p/∂x, ∂p/∂y, which
//! [`glint::RayDifferential`] gets from a camera ray's offset rays, or a [`glint::RayCone`] for
//! secondary rays, with one rule at every bounce) and a BRDF that the renderer integrates as it
//! integrates any BRDF, with the geometric cosine:
//!
//! ```
//! use brdf::bxdf::{Bxdf, MicrofacetBrdf};
//! use brdf::frame::Frame;
//! use brdf::fresnel::ConductorFresnel;
//! use brdf::glint::{BeckmannMixture, Footprint, GlintModel, GlintNdf, GlintScratch};
//! use brdf::glint::mixture::MixtureParams;
//! use brdf::{Vec2, Vec3};
//!
//! # fn main() -> Result<(), brdf::Error> {
//! # let (n, uv, dpdu, dpdv) = (Vec3::Z, Vec2::new(0.3, 0.6), Vec3::new(6.0, 0.0, 0.0), Vec3::new(0.0, 6.0, 0.0));
//! # let (dpdx, dpdy) = (Vec3::new(0.2, 0.0, 0.0), Vec3::new(0.0, 0.2, 0.0));
//! # let (to_eye, to_light) = (Vec3::new(0.3, 0.1, 0.95).normalize(), Vec3::new(-0.3, -0.1, 0.95).normalize());
//! # let light = Vec3::splat(10.0);
//! // Once per material: a normal map (`NormalMap::from_image_file` reads a PNG) made into a glint model.
//! let map = brdf::glint::scratched(64, 64, Default::default(), 1)?;
//! let model = GlintModel::from(BeckmannMixture::build(&map, MixtureParams::default())?);
//! let scratch = GlintScratch::default(); // one per render thread
//! // Per shading point: n, uv, ∂p/∂u, ∂p/∂v and the ray differentials ∂p/∂x, ∂p/∂y (world space).
//! let footprint = Footprint::from_surface_differentials(uv, dpdu, dpdv, dpdx, dpdy);
//! let brdf = MicrofacetBrdf::new(model.patch_in(&footprint, &scratch), ConductorFresnel::GOLD);
//! // Then as any BRDF, in the local frame (x along ∂p/∂u, y along +∂p/∂v), cos θi = wi.z:
//! let frame = Frame::from_surface(n, dpdu, dpdv);
//! let (wo, wi) = (frame.to_local(to_eye), frame.to_local(to_light));
//! let direct = brdf.eval(wo, wi) * wi.z * light;
//! let bounce = brdf.sample(wo, 0.5, Vec2::new(0.3, 0.7)).map(|s| (frame.to_world(s.wi), s.weight()));
//! # assert!(direct.is_finite() && direct.min_element() >= 0.0);
//! # assert!(bounce.is_none_or(|(_, w)| w.is_finite()));
//! # Ok(())
//! # }
//! ```
//!
//! A renderer that mixes analytic, layered, normal-mapped and glint materials keeps them in one
//! `Vec<`[`Material`]`>` and shades every hit with `material.bsdf(&footprint, wo, &scratch)` (module
//! [`material`]). The `render` example is a small path tracer built this way (`cargo run --release
//! --example render`).
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
//! - **Files.** `save(writer)` / `load(reader)` is the crate's binary format, on every glint model,
//!   on [`glint::GlintModel`] (which loads whichever model a file holds) and on
//!   [`glint::NormalMap`]; images decode with `NormalMap::from_image_file` / `from_image_bytes`
//!   (feature `image`) or, always, from pixel slices with [`glint::NormalMap::from_pixels_u8`] and
//!   its `u16` / `f32` forms.
//!
//! ## Which model when
//!
//! - **No normal map** (smooth to rough metal, plastic): [`Material::microfacet`] over [`Ggx`] or
//!   [`Beckmann`] ([`Material::microfacet_compensated`] to keep the energy of multiple scattering),
//!   [`Material::layered`] for a rough coat over a diffuse base, [`Material::clear_coated`] for a
//!   smooth varnish over any material (car paint: glint flakes over paint under the coat),
//!   [`Material::mirror`] for the smooth limit: closed forms.
//! - **A normal map, no glints** (the look is smooth): [`material::NormalMappedMaterial`]
//!   (microfacet-based normal mapping), one map lookup per shading point.
//! - **Glints**: a glint model of the map, at its defaults. Each chooses its own form per footprint
//!   from measured errors (no setting by hand): the mixture ([`glint::BeckmannMixture`], exact
//!   masking by default) a sub-texel lobe below 2 texels, its gathered lobes (merged levels within
//!   a TV budget of 0.01, and a cost cap) and its filtered mixture from 4,096 texels where that
//!   stays within 0.15 TV of the full mixture, and where it does not, from 4,096 texels a cut of at most 64
//!   nodes of its filtered-mixture hierarchy, whose cost does not grow with the footprint
//!   ([`glint::mixture::PatchOptions`]); the bin map
//!   ([`glint::BinMap`]) its exact or moment-lobe masking; position-normal
//!   ([`glint::PositionNormalMap`]) its element sum or filtered mixture. Which is first to a given
//!   error depends on the pixel's footprint on the map (texels per pixel), as below.
//! - **Memory** (docs/results.md, "Memory per model"): the mixture holds 99 B/texel at the
//!   defaults (at 512²-2048²: lobes, lobe blocks, quadtree, the moment and filtered-mixture mip
//!   chains, levels of detail), 15.4 B/texel with `LobeStorage::Compact` (1.4-1.8× the query time);
//!   the bin map 29.2 B/texel at 2048², position-normal 41 (29.3 of elements and quadtree, 12 of
//!   its filtered mixture's chain).
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
//! Any of them as one run-time type: [`Material`] (module [`material`]).
//!
//! ## Features and `no_std`
//!
//! - `std` (default): the standard library, the glint layer ([`glint`]), [`material`] and
//!   [`LayeredBrdf`].
//! - `image` (default, implies `std`): `NormalMap::from_image_file` / `from_image_bytes` (PNG, EXR).
//! - `serde` (implies `std`): serde for built glint models and normal maps, as their file bytes.
//!
//! With `default-features = false` the crate is `#![no_std]` and allocates nothing: the analytic
//! core, [`frame`], [`warp`], [`fresnel`], [`ndf`] (Beckmann, GGX, Blinn-Phong, [`SlopeGaussian`],
//! masking, samplers, Phong lobe integrals) and [`bxdf`] (Lambert, the Phong family,
//! [`MicrofacetBrdf`], [`bxdf::EnergyCompensated`] with its static tables, [`LayeredBrdf`],
//! [`SpecularReflection`], the normal-mapping adapters), for GPU shaders (rust-gpu) and other
//! `no_std` code. Its float functions (`sqrt`, `exp`, `ln`, …) are then `libm`'s instead of std's
//! (glam's through its `nostd-libm` feature), which may change results in the last bits; no feature
//! needs naming. Not in the core, for they need std or a heap: [`glint`] (maps, parallel builds,
//! files, `Vec`-backed models), [`material`], `Fresnel` for `Box<T>`, and the [`Error`] variants of files and decoding (they hold a `String`, a path or an
//! `io::Error`).

#![cfg_attr(not(feature = "std"), no_std)]
// The docs describe the whole crate; without `std` their links to the glint layer and `material`
// have no target (CI checks every link in the default build).
#![cfg_attr(not(feature = "std"), allow(rustdoc::broken_intra_doc_links))]

pub mod bxdf;
mod error;
#[cfg(any(not(feature = "std"), test))]
mod float;
pub mod frame;
pub mod fresnel;
#[cfg(feature = "std")]
pub mod glint;
#[cfg(feature = "std")]
pub mod material;
mod math;
pub mod ndf;
pub mod warp;

pub use bxdf::LayeredBrdf;
pub use bxdf::{
    BlinnPhongLobe, Bxdf, BxdfSample, Lambert, MicrofacetBrdf, NormalMapMicrofacet, NormalMapTilt,
    OriginalPhong, Phong, PhongNormalization, ShadingNormal, SpecularReflection,
};
pub use error::{Error, Result};
pub use fresnel::Fresnel;
pub use glam::{Mat2, Vec2, Vec3};
#[cfg(feature = "std")]
pub use material::{Bsdf, GlintMaterial, Material};
pub use ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};

/// The README's examples, compiled and run as doctests so that the quick start stays true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
