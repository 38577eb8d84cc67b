//! An equal-area binning of the upper hemisphere: n × n bins of solid angle 2π/n² each.
//!
//! Bins are the cells of an n × n grid on the unit square, mapped onto the hemisphere by the
//! equal-area map [`square_to_hemisphere_equal_area`] (concentric disk followed by the Lambert
//! azimuthal equal-area projection; solid angle = 2π × square area). Bin `j * n + i` is the image of
//! the cell [i/n, (i+1)/n) × [j/n, (j+1)/n). The pole is the corner shared by the four central cells
//! when n is even, and the centre of the central bin when n is odd. Used by the ground truth
//! ([`binned_pndf`](super::binned_pndf)) and reusable by tabulated models (the inverse bin map uses an
//! odd n).
//!
//! # Reference
//! \[ShirleyChiu1997\] (concentric map); \[Snyder1987\] (Lambert azimuthal equal-area projection);
//! \[Atanasov2020\] §2 (equal-solid-angle direction bins, Fig. 2).

use crate::warp::{hemisphere_to_square_equal_area, square_to_hemisphere_equal_area};
use crate::{Error, Result};
use glam::{Vec2, Vec3};

/// An equal-area n × n binning of the upper hemisphere.
///
/// Bins are the cells of an n × n grid on the unit square mapped onto the hemisphere by
/// [`square_to_hemisphere_equal_area`] (solid angle = 2π × square area): bin `j * n + i` is the image
/// of the cell [i/n, (i+1)/n) × [j/n, (j+1)/n), of solid angle 2π/n². For even n the pole is the
/// corner shared by the four central bins, for odd n the centre of the middle bin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct HemisphereBins {
    n: usize,
}

impl HemisphereBins {
    /// Largest supported resolution per axis (4096² ≈ 1.7·10⁷ bins of 3.7·10⁻⁷ sr).
    pub const MAX_N: usize = 4096;

    /// n × n bins of solid angle 2π/n² each.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `n` unless 1 ≤ n ≤ [`HemisphereBins::MAX_N`].
    pub fn new(n: usize) -> Result<HemisphereBins> {
        if (1..=Self::MAX_N).contains(&n) {
            Ok(HemisphereBins { n })
        } else {
            Err(Error::InvalidParameter {
                name: "n",
                value: n as f64,
                reason: "must be in 1..=4096",
            })
        }
    }

    /// Bins per axis of the square.
    #[inline]
    pub fn n(&self) -> usize {
        self.n
    }

    /// Number of bins, n².
    #[inline]
    pub fn len(&self) -> usize {
        self.n * self.n
    }

    /// Always false (there is at least one bin).
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Solid angle of every bin: ΔΩ = 2π / n² (sr).
    #[inline]
    pub fn solid_angle(&self) -> f64 {
        std::f64::consts::TAU / (self.len() as f64)
    }

    /// The bin containing direction `w` (need not be unit length), or `None` for zero-length,
    /// non-finite or below-horizon (z < 0) directions. Horizon directions (z = 0) belong to the
    /// boundary bins.
    #[inline]
    pub fn bin_of(&self, w: Vec3) -> Option<usize> {
        if !(w.is_finite() && w.z >= 0.0 && w.length_squared() > 0.0) {
            return None;
        }
        let u = hemisphere_to_square_equal_area(w);
        let n = self.n as f32;
        let i = ((u.x * n) as usize).min(self.n - 1);
        let j = ((u.y * n) as usize).min(self.n - 1);
        Some(j * self.n + i)
    }

    /// (column i, row j) of a bin on the square grid; out-of-range bins are clamped to the last.
    #[inline]
    pub fn cell(&self, bin: usize) -> (usize, usize) {
        let bin = bin.min(self.len() - 1);
        (bin % self.n, bin / self.n)
    }

    /// A direction in `bin`, uniformly distributed in solid angle over the bin when `u` is uniform in
    /// [0, 1)²: the equal-area image of the point ((i + u.x)/n, (j + u.y)/n). `u` is clamped into
    /// [0, 1]² by the map; out-of-range bins are clamped to the last.
    #[inline]
    pub fn sample_in_bin(&self, bin: usize, u: Vec2) -> Vec3 {
        let (i, j) = self.cell(bin);
        let n = self.n as f32;
        let u = Vec2::select(u.is_finite_mask(), u, Vec2::splat(0.5)).clamp(Vec2::ZERO, Vec2::ONE);
        square_to_hemisphere_equal_area(Vec2::new((i as f32 + u.x) / n, (j as f32 + u.y) / n))
    }

    /// The image of the centre of the bin's square cell (not its centroid on the sphere).
    #[inline]
    pub fn center(&self, bin: usize) -> Vec3 {
        self.sample_in_bin(bin, Vec2::splat(0.5))
    }

    /// The bin-averaged cosine (1/ΔΩ) ∫_bin cos θ dω, exactly (f64).
    ///
    /// Under the equal-area map z = 1 − r² with r = max(|a|, |b|), (a, b) = 2u − 1 (the concentric
    /// radius), so the average is 1 − the mean of max(a², b²) over the cell: a piecewise cubic in a
    /// after integrating over b in closed form, integrated exactly by Gauss–Legendre on its pieces.
    /// Σ_bins mean_cos · ΔΩ = π (the projected solid angle of the hemisphere).
    pub fn mean_cos(&self, bin: usize) -> f64 {
        let (i, j) = self.cell(bin);
        let n = self.n as f64;
        crate::warp::equal_area_mean_cos(
            i as f64 / n,
            (i + 1) as f64 / n,
            j as f64 / n,
            (j + 1) as f64 / n,
        )
    }
}
