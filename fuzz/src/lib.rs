//! Shared pieces of the fuzz targets: arbitrary inputs built from raw bytes, and the totality checks
//! of `tests/support/totality.rs` (finite, ≥ 0 where it is a density or a value, a sample only with a
//! positive pdf, never a panic).
//!
//! A failed check panics with the offending input, which libFuzzer records as a crash artefact.

use arbitrary::Arbitrary;
use brdf::glint::{Footprint, NormalMap};
use brdf::ndf::Ndf;
use brdf::{Bxdf, Vec2, Vec3};

/// The checks themselves, shared with the property tests of the crate.
#[path = "../../tests/support/totality.rs"]
pub mod totality;

/// A normal map of 1 to 12 texels per side from raw slopes (repeated to fill it; any f32, so NaN,
/// infinities and huge slopes reach the constructor).
#[derive(Arbitrary, Debug)]
pub struct MapInput {
    width: u8,
    height: u8,
    slopes: Vec<(f32, f32)>,
}

impl MapInput {
    /// The map, or `None` where the constructor refused the data (which it must do without panicking).
    pub fn build(&self) -> Option<NormalMap> {
        let (w, h) = (self.width as usize % 12 + 1, self.height as usize % 12 + 1);
        let slopes: Vec<Vec2> = (0..w * h)
            .map(|k| {
                self.slopes
                    .get(k % self.slopes.len().max(1))
                    .map_or(Vec2::ZERO, |&(x, y)| Vec2::new(x, y))
            })
            .collect();
        NormalMap::from_slopes(w, h, slopes).ok()
    }
}

/// A footprint from raw ray differentials (any f32).
#[derive(Arbitrary, Debug)]
pub struct FootprintInput {
    uv: (f32, f32),
    duv_dx: (f32, f32),
    duv_dy: (f32, f32),
}

impl FootprintInput {
    /// The footprint (construction is infallible: degenerate input falls back, documented).
    pub fn build(&self) -> Footprint {
        let v = |(x, y): (f32, f32)| Vec2::new(x, y);
        Footprint::from_differentials(v(self.uv), v(self.duv_dx), v(self.duv_dy))
    }
}

/// Directions and random numbers for one round of queries (any f32: the checks expand them into
/// normalised directions, edge cases and folded random numbers).
#[derive(Arbitrary, Debug)]
pub struct Probe {
    wo: (f32, f32, f32),
    wi: (f32, f32, f32),
    u: (f32, f32),
    uc: f32,
}

impl Probe {
    fn parts(&self) -> (Vec3, Vec3, f32, Vec2) {
        (
            Vec3::new(self.wo.0, self.wo.1, self.wo.2),
            Vec3::new(self.wi.0, self.wi.1, self.wi.2),
            self.uc,
            Vec2::new(self.u.0, self.u.1),
        )
    }
}

/// [`totality::check_ndf`] on the probe.
pub fn check_ndf(ndf: &dyn Ndf, probe: &Probe) {
    let (wo, wi, uc, u) = probe.parts();
    totality::check_ndf(ndf, wo, wi, uc, u);
}

/// [`totality::check_bxdf`] on the probe.
pub fn check_bxdf(bxdf: &dyn Bxdf, probe: &Probe) {
    let (wo, wi, uc, u) = probe.parts();
    totality::check_bxdf(bxdf, wo, wi, uc, u);
}
