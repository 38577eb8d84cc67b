//! Kernels shared by the glint models' builds and patches (crate-private).
//!
//! - albedo.rs: the estimate of a patch's single-scattering albedo E(wo) that the energy
//!   compensation of glint patches gives back.
//! - cdf.rs: inverting a cumulative table, the first step of every glint sampler.
//! - filtered_error.rs: the filtered mixture's measured distance to a model's full P-NDF, per
//!   level (what the models' `filtered_tolerance` is compared with).
//! - gmm.rs: the filtered mixture, a mip chain of few-lobe Gaussian mixtures over a lobe grid;
//!   gmm_residual.rs its nodes' residuals, gmm_store.rs the chain in a model's file.
//! - lanes.rs: lane arithmetic that vectorises (`exp2`, the ramp term of V), for the mixture's
//!   lobe blocks and the lobe sets.
//! - lobe_set.rs: a small weighted set of slope Gaussians, the few-lobe patches' P-NDF.
//! - shared_lobes.rs: a weighted set of slope Gaussians of one shape held inline, a procedural
//!   Beckmann patch's P-NDF.
//! - mip.rs: trilinear addressing of mip chains over a lobe grid.
//! - prefetch.rs: prefetch hints for the memory a footprint's query reads next.
//! - prepared_view.rs: a value a patch computes once for the view it is prepared for (V(wo)).
//! - slope_tree.rs: the implicit quadtree of slope boxes over a regular grid of elements (the
//!   mixture's lobes, the position-normal elements).

pub(crate) mod albedo;
pub(crate) mod cdf;
pub(crate) mod cut;
pub(crate) mod filtered_error;
pub(crate) mod gmm;
pub(crate) mod gmm_reduce;
pub(crate) mod gmm_residual;
pub(crate) mod gmm_store;
pub(crate) mod lanes;
pub(crate) mod lobe_set;
pub(crate) mod mip;
pub(crate) mod prefetch;
pub(crate) mod prepared_view;
pub(crate) mod shared_lobes;
pub(crate) mod slope_tree;
