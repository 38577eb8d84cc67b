//! Glints: normal maps, ray footprints, the ground-truth P-NDF, and the glint NDF models.
//!
//! The data flow (see `docs/glint.md`): a [`NormalMap`] (per-texel slopes, tiled, bilinearly
//! interpolated normals) is turned once into a precomputed glint representation; at each shading point
//! a ray footprint selects a patch of the map whose P-NDF D_P(ω_h) (Chermain 2019, eq. 8) is an
//! [`Ndf`](crate::ndf::Ndf) that any microfacet BRDF can consume.
//!
//! Texel-space conventions (texel (i, j) covers [i, i+1) × [j, j+1) with its sample at the centre,
//! uv = texel coordinate / size, maps tile) are documented on [`NormalMap`]'s module and in
//! `docs/glint.md`.

#[cfg(feature = "image")]
mod image_io;
mod moments;
mod normal_map;

pub use normal_map::{
    MAX_SLOPE, NormalMap, NormalRepair, TangentConvention, moments_mean_covariance,
};
