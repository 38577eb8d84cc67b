//! The ground truths every glint model is judged by, tabulated on the equal-area
//! [`HemisphereBins`](crate::glint::HemisphereBins) of `surface`.
//!
//! - The Dirac truth (binned.rs): [`binned_pndf`], the P-NDF of the interpolated normal map through a
//!   footprint, binned, and [`tv_distance`] of a model to it.
//! - The σ_ε-convolved truth (convolved.rs): [`convolved_pndf`], the same P-NDF widened by the
//!   material's micro-roughness lobe, and the adaptive per-bin quadrature of a model's D
//!   ([`adaptive_bin_masses`]) that both truths are compared with.
//! - The footprint BRDF references (footprint_brdf.rs): [`FootprintBrdf`] / [`footprint_brdf`], the
//!   exact P-BRDF of the interpolated map (reference (a)) and normal-mapped shading averaged over the
//!   footprint (reference (b)), and [`naive_brdf`] at one position.

mod binned;
mod convolved;
mod footprint_brdf;

pub use binned::{BinnedPndf, Kernel, REFERENCE_BATCHES, binned_pndf, tv_distance};
pub use convolved::{
    BinMasses, DEFAULT_MAX_QUADRATURE, DEFAULT_QUADRATURE_TOLERANCE, JITTERS, adaptive_bin_masses,
    bin_masses, convolved_pndf,
};
pub use footprint_brdf::{FootprintBrdf, footprint_brdf, for_each_footprint_slope, naive_brdf};
