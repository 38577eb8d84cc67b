//! The masking facets of the bins: per bin H_j, its mean direction (1/|H|) ∫_{H_j} m dω, its
//! centre's image and a bound on |m − c_j|, which the exact masking terms of a footprint read
//! (docs/binmap.md), and the bins' centre slopes; computed once per orbit of the square's eight
//! symmetries.

use crate::frame::normal_to_slope;
use crate::glint::HemisphereBins;
use crate::warp::square_to_hemisphere_equal_area;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// The centre of sub-cell k (row major) of the g × g grid of the unit square: the midpoint rule's
/// points over a bin's equal-area cell (`HemisphereBins::sample_in_bin`).
#[inline]
pub(super) fn sub_cell(k: usize, g: usize) -> Vec2 {
    Vec2::new(
        ((k % g) as f32 + 0.5) / g as f32,
        ((k / g) as f32 + 0.5) / g as f32,
    )
}

/// What the exact masking terms need of one bin H_j (see [`BinMapPatch`](super::BinMapPatch)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct BinFacet {
    /// The bin's mean direction vector (1/|H|) ∫_{H_j} m dω (length < 1; z = the mean cosine c̄_j).
    pub(super) mean: Vec3,
    /// The image c_j of the cell centre (unit).
    pub(super) center: Vec3,
    /// An upper bound r_j of |m − c_j| over the bin, so that ⟨w, m⟩ ≤ ⟨w, c_j⟩ + r_j for unit w.
    pub(super) radius: f32,
}

impl BinFacet {
    /// Sub-cells per axis of the midpoint rule for the mean's x and y (z is exact): the error is
    /// O((1/(8n))²) of the bin's extent, below f32 resolution for n ≥ 15.
    const MEAN_GRID: usize = 8;
    /// Points per cell side probed for the radius (corners, edge points and interior), and the
    /// margin covering the curvature of the cell's image between them (the chord |m − c| is smooth
    /// and maximal on the boundary; 9 points per side leave a relative gap far below 10 %).
    const RADIUS_GRID: usize = 8;
    const RADIUS_MARGIN: f32 = 1.1;

    /// The facet of a bin no texel falls in: only the mean cosine (the mean's z) is set.
    pub(super) fn empty(bins: &HemisphereBins, bin: usize) -> BinFacet {
        BinFacet {
            mean: Vec3::new(0.0, 0.0, bins.mean_cos(bin) as f32),
            center: bins.center(bin),
            radius: 0.0,
        }
    }

    pub(super) fn new(bins: &HemisphereBins, bin: usize) -> BinFacet {
        let center = bins.center(bin);
        let g = Self::MEAN_GRID;
        let mut sum = [0.0f64; 2];
        for k in 0..g * g {
            let m = bins.sample_in_bin(bin, sub_cell(k, g));
            sum[0] += m.x as f64;
            sum[1] += m.y as f64;
        }
        let inv = 1.0 / (g * g) as f64;
        let mean = Vec3::new(
            (sum[0] * inv) as f32,
            (sum[1] * inv) as f32,
            bins.mean_cos(bin) as f32,
        );
        let r = Self::RADIUS_GRID;
        let mut radius = 0.0f32;
        for k in 0..(r + 1) * (r + 1) {
            let u = Vec2::new(
                (k % (r + 1)) as f32 / r as f32,
                (k / (r + 1)) as f32 / r as f32,
            );
            radius = radius.max((bins.sample_in_bin(bin, u) - center).length());
        }
        BinFacet {
            mean,
            center,
            radius: radius * Self::RADIUS_MARGIN,
        }
    }
}

/// The per-bin tables derived from the bins and the lists' offsets (built, and rebuilt on load): the
/// masking facets, sampled only for the bins some sub-texel falls in (the only ones a footprint's
/// masking sums; the others keep their exact mean cosine), and the bins' centre slopes.
///
/// The facets' sampled parts (the mean's x and y, the radius) are computed once per orbit of the
/// square's eight symmetries (x ↦ −x, y ↦ −y, x ↔ y), which the equal-area map commutes with and
/// which map the cells of the grid and the sample points of [`BinFacet::new`] onto each other, and
/// carried to the orbit's other bins: an eighth of the work, equal to the direct computation up to
/// f32 rounding (`mirrored_facets_match_direct_ones`). The centre and the mean cosine of every bin
/// are its own.
pub(super) fn bin_tables(bins: &HemisphereBins, offsets: &[u32]) -> BinTables {
    let n = bins.n();
    let occupied = |b: usize| offsets[b + 1] > offsets[b];
    // The canonical facet of every orbit that holds an occupied bin, indexed by its canonical bin.
    let canonical: Vec<Option<BinFacet>> = (0..bins.len())
        .into_par_iter()
        .map(|b| {
            let (i, j) = bins.cell(b);
            let is_canonical = 2 * i < n && 2 * j < n && i <= j;
            (is_canonical && orbit(n, i, j).into_iter().any(occupied))
                .then(|| BinFacet::new(bins, b))
        })
        .collect();
    let facets = (0..bins.len())
        .into_par_iter()
        .map(|b| {
            if !occupied(b) {
                return BinFacet::empty(bins, b);
            }
            let (i, j) = bins.cell(b);
            let (ci, flip_x) = fold(n, i);
            let (cj, flip_y) = fold(n, j);
            let swap = ci > cj;
            let c = if swap { ci * n + cj } else { cj * n + ci };
            // Every occupied bin's orbit has its canonical facet.
            let f = canonical[c].unwrap_or_else(|| BinFacet::new(bins, c));
            let (mut x, mut y) = (f.mean.x, f.mean.y);
            if swap {
                (x, y) = (y, x);
            }
            if flip_x {
                x = -x;
            }
            if flip_y {
                y = -y;
            }
            BinFacet {
                mean: Vec3::new(x, y, bins.mean_cos(b) as f32),
                center: bins.center(b),
                radius: f.radius,
            }
        })
        .collect();
    let center_slope = (0..bins.len())
        .map(|b| normal_to_slope(bins.center(b)).unwrap_or(Vec2::ZERO))
        .collect();
    BinTables {
        facets,
        center_slope,
        corners: corner_grid(bins),
    }
}

/// The per-bin tables a bin map derives from its bins and lists ([`bin_tables`]).
pub(super) struct BinTables {
    /// The masking facet of every bin.
    pub facets: Vec<BinFacet>,
    /// The slope of every bin's centre direction.
    pub center_slope: Vec<Vec2>,
    /// The directions of the (n + 1)² corners of the bins' cells, row major ([`corners_of`]).
    pub corners: Vec<Vec3>,
}

/// The equal-area images of the grid points (i/n, j/n), 0 ≤ i, j ≤ n, row major: the corners of
/// every bin's cell, computed with the arithmetic of [`HemisphereBins::sample_in_bin`] at
/// u ∈ {0, 1}², so each is bit for bit the direction that call returns.
fn corner_grid(bins: &HemisphereBins) -> Vec<Vec3> {
    let n = bins.n();
    let nf = n as f32;
    (0..(n + 1) * (n + 1))
        .into_par_iter()
        .map(|k| {
            let (i, j) = (k % (n + 1), k / (n + 1));
            square_to_hemisphere_equal_area(Vec2::new(i as f32 / nf, j as f32 / nf))
        })
        .collect()
}

/// The four corner directions of `bin`'s cell from the grid of [`corner_grid`], in the order
/// (0, 0), (1, 0), (0, 1), (1, 1) of the cell's square coordinates.
#[inline]
pub(super) fn corners_of(corners: &[Vec3], bins: &HemisphereBins, bin: usize) -> [Vec3; 4] {
    let (i, j) = bins.cell(bin);
    let row = bins.n() + 1;
    let k = j * row + i;
    [
        corners[k],
        corners[k + 1],
        corners[k + row],
        corners[k + row + 1],
    ]
}

/// Column (or row) `i` of an n-cell axis folded onto its first half: (the folded index, whether it
/// was mirrored).
fn fold(n: usize, i: usize) -> (usize, bool) {
    if 2 * i < n {
        (i, false)
    } else {
        (n - 1 - i, true)
    }
}

/// The (up to eight distinct) bins that the square's symmetries map cell (i, j) to.
fn orbit(n: usize, i: usize, j: usize) -> [usize; 8] {
    let (mi, mj) = (n - 1 - i, n - 1 - j);
    [
        j * n + i,
        j * n + mi,
        mj * n + i,
        mj * n + mi,
        i * n + j,
        i * n + mj,
        mi * n + j,
        mi * n + mj,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// The facets carried across the square's symmetries equal the ones each bin would get on its
    /// own (up to f32 rounding of the sampled sums), for every bin of odd and even grids, with only
    /// some bins occupied; unoccupied bins keep the empty facet.
    #[test]
    fn mirrored_facets_match_direct_ones() {
        for n in [1usize, 2, 7, 15, 64, 255] {
            let bins = HemisphereBins::new(n).unwrap();
            // Occupy every third bin (offsets of lists of length 0 or 1).
            let mut offsets = vec![0u32];
            for b in 0..bins.len() {
                offsets.push(offsets[b] + u32::from(b % 3 == 0));
            }
            let facets = bin_tables(&bins, &offsets).facets;
            for (b, f) in facets.iter().enumerate() {
                let want = if b % 3 == 0 {
                    BinFacet::new(&bins, b)
                } else {
                    BinFacet::empty(&bins, b)
                };
                assert_eq!(f.center, want.center, "n={n} bin {b}");
                assert_eq!(f.mean.z, want.mean.z, "n={n} bin {b}");
                // Each sampled direction carries f32 rounding of a few 10⁻⁸; the mean of 64 and the
                // largest chord (a bound with a 10 % margin) are compared at 5·10⁻⁷.
                let tol = 5e-7;
                assert!(
                    (f.mean.x - want.mean.x).abs() <= tol && (f.mean.y - want.mean.y).abs() <= tol,
                    "n={n} bin {b}: {:?} vs {:?}",
                    f.mean,
                    want.mean
                );
                assert!(
                    (f.radius - want.radius).abs() <= tol,
                    "n={n} bin {b}: radius {} vs {}",
                    f.radius,
                    want.radius
                );
            }
        }
    }

    /// The tabulated facets against directions drawn uniformly in random bins: every draw lies within
    /// the radius of its bin's centre, and the mean of the draws matches the tabulated mean direction
    /// (z exact; x, y to the midpoint rule), within 4 standard errors of the sample mean + 1e-5.
    #[test]
    fn facets_bound_and_average_their_bins() {
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
        for n in [1usize, 3, 15, 127] {
            let bins = HemisphereBins::new(n).unwrap();
            for _ in 0..20 {
                let bin = rng.random_range(0..bins.len());
                let f = BinFacet::new(&bins, bin);
                let draws = 4000;
                let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
                for _ in 0..draws {
                    let m = bins.sample_in_bin(bin, Vec2::new(rng.random(), rng.random()));
                    assert!((m - f.center).length() <= f.radius, "n={n} bin={bin}");
                    for (i, c) in m.to_array().into_iter().enumerate() {
                        sum[i] += c as f64;
                        sum2[i] += (c as f64) * (c as f64);
                    }
                }
                for i in 0..3 {
                    let mean = sum[i] / draws as f64;
                    let se =
                        ((sum2[i] / draws as f64 - mean * mean).max(0.0) / draws as f64).sqrt();
                    let tab = f.mean.to_array()[i] as f64;
                    assert!(
                        (mean - tab).abs() <= 4.0 * se + 1e-5,
                        "n={n} bin={bin} axis {i}: sampled {mean} vs tabulated {tab} (se {se})"
                    );
                }
            }
        }
    }

    /// The corner grid gives every bin's corners bit for bit as `sample_in_bin` computes them.
    #[test]
    fn corner_grid_is_sample_in_bin_at_the_corners() {
        for n in [1, 15, 255] {
            let bins = HemisphereBins::new(n).expect("odd n");
            let grid = corner_grid(&bins);
            for b in 0..bins.len() {
                let want = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                    .map(|(x, y)| bins.sample_in_bin(b, Vec2::new(x, y)));
                let got = corners_of(&grid, &bins, b);
                for (g, w) in got.iter().zip(&want) {
                    assert_eq!(
                        g.to_array().map(f32::to_bits),
                        w.to_array().map(f32::to_bits)
                    );
                }
            }
        }
    }
}
