//! Shared test helpers: seeded RNGs, hemisphere quadrature, the chi-square harness and physics checks.
//!
//! Each integration test file includes this with `mod support;`; not every file uses every helper.
#![allow(dead_code)]

pub mod chi2;
pub mod quadrature;

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// A seeded, reproducible RNG for tests.
pub fn rng(seed: u64) -> Pcg64Mcg {
    Pcg64Mcg::seed_from_u64(seed)
}

/// A unit direction with polar angle `theta_deg` (degrees) and azimuth `phi_deg` in the local frame.
pub fn dir(theta_deg: f64, phi_deg: f64) -> glam::Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    glam::Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}
