//! Shared by the slope Gaussian tests (tests/it/slope_gaussian_*.rs): a lobe from its mean slope, slope
//! standard deviations and correlation.

use brdf::ndf::SlopeGaussian;
use glam::{Mat2, Vec2};

/// A lobe with mean slope `mean`, slope standard deviations (σx, σy) and correlation ρ.
pub fn lobe(mean: (f32, f32), sx: f32, sy: f32, rho: f32) -> SlopeGaussian {
    let c = rho * sx * sy;
    SlopeGaussian::new(
        Vec2::new(mean.0, mean.1),
        Mat2::from_cols_array(&[sx * sx, c, c, sy * sy]),
    )
    .expect("valid test lobe")
}
