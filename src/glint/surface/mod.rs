//! What every glint model is built from and queried with: the normal map (its slopes, its
//! bilinearly interpolated surface and the mip chain of its slope moments), the procedural maps, the
//! image decoder, the ray footprint, and the equal-area bins of the hemisphere (the bin map's bins,
//! and the grid the truths are tabulated on).
//!
//! - bins.rs: [`HemisphereBins`], an equal-area binning of the hemisphere.
//! - normal_map.rs: [`NormalMap`], the tiled grid of per-texel slopes and the interpolated surface.
//! - moments.rs: [`SlopeMomentPyramid`], the mip chain of slope moments of a map
//!   ([`NormalMap::moment_pyramid`]), and the crate's chain the bin map keeps.
//! - procedural.rs: the seeded generators [`scratched`], [`brushed`], [`bumpy`], [`flakes`].
//! - pixels.rs: decoding normal maps from 8-bit, 16-bit or float pixel slices (always available).
//! - image_io.rs: decoding PNG / EXR normal-map files into those pixels (feature `image`).
//! - footprint.rs: [`Footprint`], a ray footprint as a parallelogram and a Gaussian.
//! - ray_differential.rs: [`RayDifferential`], a camera ray's offset rays and the tangent-plane
//!   step from them to ∂p/∂x, ∂p/∂y and the footprint.
//! - ray_cone.rs: [`RayCone`], footprints for secondary rays (width and spread propagated through
//!   bounces, one rule for every lobe).

mod bins;
mod footprint;
#[cfg(feature = "image")]
mod image_io;
mod moments;
mod normal_map;
mod pixels;
mod procedural;
mod ray_cone;
mod ray_differential;

pub use bins::HemisphereBins;
pub use footprint::{Footprint, MAX_ANISOTROPY, MAX_EXTENT_PERIODS, MIN_WIDTH_TEXELS};
pub use moments::SlopeMomentPyramid;
pub(crate) use moments::{MomentLevel, MomentPyramid};
pub(crate) use normal_map::texel_count;
pub use normal_map::{
    MAX_SLOPE, NormalMap, NormalRepair, TangentConvention, moments_mean_covariance,
};
pub use pixels::{
    DEFAULT_LENGTH_TOLERANCE, DEFAULT_MAX_IMAGE_TEXELS, FloatEncoding, ImageDecoding, ImageOptions,
    MAX_IMPLAUSIBLE_FRACTION, RAW_EVIDENCE_BELOW,
};
pub use procedural::{
    BrushedParams, FlakesParams, MAX_CARVE_WORK_PER_TEXEL, MAX_GENERATED_TEXELS, MIN_CELL_TEXELS,
    ScratchedParams, brushed, bumpy, flakes, scratched,
};
pub use ray_cone::RayCone;
pub use ray_differential::RayDifferential;
