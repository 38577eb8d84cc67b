//! Kernels shared by the glint models' builds and patches (crate-private).
//!
//! - cdf.rs: inverting a cumulative table, the first step of every glint sampler.
//! - slope_tree.rs: the implicit quadtree of slope boxes over a regular grid of elements (the
//!   mixture's lobes, the position-normal elements).

pub(crate) mod cdf;
pub(crate) mod slope_tree;
