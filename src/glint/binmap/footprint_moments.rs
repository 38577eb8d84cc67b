//! The slope moments of the masking lobe of a bin-map patch without a bin list: the chain of the
//! bins' own moments, and its read with the footprint's own shape.
//!
//! - [`chain`] builds the moment mip chain from 𝓑: each sub-texel contributes its bin's share of
//!   D cos θ (uniform in solid angle over the bin, weighted by cos θ; [`bin_moments`]), so the chain
//!   holds the moments of the patches' own D (the map's interpolated slopes would leave out the
//!   bins' quantisation and spread). Kept from level [`MASKING_FIRST_LEVEL`] (2 × 2 texels).
//! - [`footprint_moments`] reads it as the area-weighted mean of the chain's cells over the exact
//!   overlap of each cell with the footprint's parallelogram, at the finest kept level whose cells in
//!   the footprint's bounding box number at most [`MAX_FOOTPRINT_CELLS`].
//!
//! The moments are then the footprint's own except in its boundary cells, whose bins outside the
//! footprint mix in. Scarf's bound of the visible area holds for any distribution of the moments it
//! is given, so the lobe's V(wo) falls below the footprint's own visible area only through those
//! cells: with at most 256 cells of 2 × 2 texels V_bins/V_lobe is at most 1.018 over the procedural
//! maps, seeds 1-3, footprints of 128-8192 texels, and the renderer's furnace exceeds 1 + 3
//! standard errors in 6 of 25,920 cells of that grid (up to 1.0105 ± 0.0031; 64 cells of 4 × 4
//! texels of the map's own slopes: 1.075, and 125 cells up to 1.0143 ± 0.0016; every texel read
//! without a cap: 1.0004). docs/results.md, "Inverse bin map: the masking level of detail".
//!
//! The trilinear lookup at the footprint centre and radius ½√|A| weights a tent around the centre
//! whose extent and shape are not the footprint's (isotropic, one to two cells of a level whose
//! cells are as wide as the footprint): the fallback for a footprint that meets no cell.
//!
//! Cost: at most [`MAX_FOOTPRINT_CELLS`] separating-axis tests and a clip per boundary cell,
//! whatever the footprint's area (docs/results.md).
//!
//! # Reference
//! The moments and the lobe: \[Dupuy2013\] (LEADR moments); Scarf's bound: \[Scarf1958\]; the
//! cell overlaps: clip.rs (\[SutherlandHodgman1974\]).

use super::clip::{Overlap, Parallelogram};
use super::facets::sub_cell;
use super::params::MASKING_FIRST_LEVEL;
use crate::glint::HemisphereBins;
use crate::glint::surface::MomentPyramid;
use rayon::prelude::*;

/// Largest number of cells of the chain in the footprint's bounding box: 256 (a footprint read at
/// about sixteen cells across). With 64, V_bins/V_lobe reached 1.080 (flakes, 1024 texels); with 128,
/// 1.062 (bumpy, 128 texels) and the furnace 1.0143 ± 0.0016 (scratched, 256 texels).
pub(crate) const MAX_FOOTPRINT_CELLS: f64 = 256.0;

/// Sub-cells per axis of the midpoint rule of a bin's second moments ([`bin_moments`]), and of the
/// pole bin's (the concentric map's centre point, where the image's slopes fold): the rule
/// under-counts a bin's spread by at most 0.4 % of a moment (1.6 % at 8, 6.5 % at 4; the pole bin
/// 3.1 % at 8), against 64 × 64 points on 15², 63² and 255² bins. The bins on the horizon ring have
/// unbounded second moments (∫ h_x² / h_z dω diverges there) and take the rule's finite value.
const MOMENT_GRID: usize = 16;
const POLE_MOMENT_GRID: usize = 64;

/// The slope moments [E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ] of each bin's share of the normal distribution
/// D cos θ (uniform in solid angle over the bin, weighted by cos θ), by the midpoint rule on
/// [`MOMENT_GRID`]² sub-cells of its equal-area cell (E s = −m̄_xy / c̄ up to the rule's error).
/// Bins not `used` are skipped (zeros).
pub(super) fn bin_moments(bins: &HemisphereBins, used: &[bool]) -> Vec<[f64; 5]> {
    let pole = bins.bin_of(glam::Vec3::Z);
    (0..bins.len())
        .into_par_iter()
        .map(|b| {
            if !used[b] {
                return [0.0; 5];
            }
            let g = if Some(b) == pole {
                POLE_MOMENT_GRID
            } else {
                MOMENT_GRID
            };
            let mut sum = [0.0f64; 6];
            for k in 0..g * g {
                let m = bins.sample_in_bin(b, sub_cell(k, g));
                let (x, y, z) = (m.x as f64, m.y as f64, (m.z as f64).max(1e-12));
                // Weighted by cos θ = z: s = −(x, y)/z, so s z = −(x, y), s sᵀ z = (x, y)(x, y)ᵀ/z.
                sum[0] -= x;
                sum[1] -= y;
                sum[2] += x * x / z;
                sum[3] += y * y / z;
                sum[4] += x * y / z;
                sum[5] += z;
            }
            let c = sum[5];
            [sum[0] / c, sum[1] / c, sum[2] / c, sum[3] / c, sum[4] / c]
        })
        .collect()
}

/// Per texel, the mean of its s² sub-texels' bin moments ([`bin_moments`]): level 0 of the masking
/// lobe's chain.
fn texel_bin_moments(
    bins: &HemisphereBins,
    bin_at: &(dyn Fn(usize) -> usize + Sync),
    width: usize,
    height: usize,
    s: usize,
) -> Vec<[f32; 5]> {
    let grid_w = width * s;
    let mut used = vec![false; bins.len()];
    for k in 0..grid_w * height * s {
        used[bin_at(k)] = true;
    }
    let table = bin_moments(bins, &used);
    (0..width * height)
        .into_par_iter()
        .map(|t| {
            let (i, j) = (t % width, t / width);
            let mut acc = [0.0f64; 5];
            for b in 0..s {
                for a in 0..s {
                    let k = (j * s + b) * grid_w + i * s + a;
                    let m = &table[bin_at(k)];
                    for q in 0..5 {
                        acc[q] += m[q];
                    }
                }
            }
            acc.map(|v| (v / (s * s) as f64) as f32)
        })
        .collect()
}

/// The masking lobe's moment chain of a bin map (module docs) of `width × height` texels of s × s
/// sub-texels, `bin_at(k)` the bin of sub-texel k (row major on the (s·width) × (s·height) grid, 𝓑):
/// levels from [`MASKING_FIRST_LEVEL`] of the chain whose level 0 is [`texel_bin_moments`].
pub(super) fn chain(
    bins: &HemisphereBins,
    bin_at: &(dyn Fn(usize) -> usize + Sync),
    width: usize,
    height: usize,
    s: usize,
) -> MomentPyramid {
    let base = texel_bin_moments(bins, bin_at, width, height, s);
    MomentPyramid::build_from_moments(width, height, base, MASKING_FIRST_LEVEL)
}

/// The moments [E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ] of the chain's cells weighted by their exact overlap
/// with `para` (texel units), at the finest kept level whose bounding box of the footprint holds at
/// most [`MAX_FOOTPRINT_CELLS`] cells (the coarsest level for footprints larger than that); `None`
/// for a footprint that meets no cell (never for a valid parallelogram).
pub(crate) fn footprint_moments(
    chain: &MomentPyramid,
    width: usize,
    height: usize,
    para: &Parallelogram,
) -> Option<[f32; 5]> {
    let (lo, hi) = para.bounds();
    let mut level = 0;
    while chain.level(level + 1).is_some() {
        let here = chain.level(level)?;
        let (cx, cy) = (
            width as f64 / here.width as f64,
            height as f64 / here.height as f64,
        );
        let cells = ((hi[0] - lo[0]) / cx + 1.0) * ((hi[1] - lo[1]) / cy + 1.0);
        if cells <= MAX_FOOTPRINT_CELLS {
            break;
        }
        level += 1;
    }
    let l = chain.level(level)?;
    let (kx, ky) = (
        l.width as f64 / width as f64,
        l.height as f64 / height as f64,
    );
    let p = para.scaled(kx, ky)?;
    let (lo, hi) = p.bounds();
    let (i0, i1) = (lo[0].floor() as i64, hi[0].ceil() as i64);
    let (j0, j1) = (lo[1].floor() as i64, hi[1].ceil() as i64);
    let mut sum = [0.0f64; 5];
    let mut total = 0.0f64;
    for j in j0..j1 {
        for i in i0..i1 {
            let (x0, y0) = (i as f64, j as f64);
            let w = match p.classify(x0, y0, x0 + 1.0, y0 + 1.0) {
                Overlap::Outside => continue,
                Overlap::Inside => 1.0,
                Overlap::Partial => p.clipped_area(x0, y0, x0 + 1.0, y0 + 1.0),
            };
            if w <= 0.0 {
                continue;
            }
            let ii = i.rem_euclid(l.width as i64) as usize;
            let jj = j.rem_euclid(l.height as i64) as usize;
            let m = &l.data[jj * l.width + ii];
            for k in 0..5 {
                sum[k] += w * m[k] as f64;
            }
            total += w;
        }
    }
    (total > 0.0).then(|| sum.map(|v| (v / total) as f32))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// The bins' moments against a finer, independent rule: 64 × 64 points of each bin's
    /// equal-area cell, for the pole bin, a bin halfway and one at θ ≈ 49° (the ring touching the horizon diverges).
    #[test]
    fn bin_moments_match_a_finer_quadrature() {
        let bins = HemisphereBins::new(15).unwrap();
        let picks = [
            bins.bin_of(glam::Vec3::Z).unwrap(),
            bins.bin_of(glam::Vec3::new(0.5, 0.3, 0.81).normalize())
                .unwrap(),
            bins.bin_of(glam::Vec3::new(0.75, 0.1, 0.65).normalize())
                .unwrap(),
        ];
        let used: Vec<bool> = (0..bins.len()).map(|b| picks.contains(&b)).collect();
        let table = bin_moments(&bins, &used);
        let g = 64;
        for &b in &picks {
            let mut sum = [0.0f64; 6];
            for k in 0..g * g {
                let m = bins.sample_in_bin(b, sub_cell(k, g));
                let (x, y, z) = (m.x as f64, m.y as f64, m.z as f64);
                let s = [-x / z, -y / z];
                let v = [s[0], s[1], s[0] * s[0], s[1] * s[1], s[0] * s[1]];
                for q in 0..5 {
                    sum[q] += v[q] * z;
                }
                sum[5] += z;
            }
            for q in 0..5 {
                let fine = sum[q] / sum[5];
                let d = (table[b][q] - fine).abs();
                assert!(
                    d <= 5e-3 * fine.abs().max(1e-2),
                    "bin {b} moment {q}: {} vs {fine}",
                    table[b][q]
                );
            }
        }
    }

    /// The chain of a bin map holds at level 1 the mean of each 2 × 2-texel cell's sub-texel bin
    /// moments: a footprint of whole cells reads the mean over its sub-texels of their bins' moments,
    /// summed here directly from 𝓑.
    #[test]
    fn the_chain_holds_the_sub_texels_bin_moments() {
        let n = 32;
        let map = crate::glint::bumpy(n, n, 0.25, 4.0, 2).unwrap();
        let bm = super::super::BinMap::build(&map, super::super::BinMapParams::default()).unwrap();
        let s = bm.params.subdivisions;
        let used = vec![true; bm.bins.len()];
        let table = bin_moments(&bm.bins, &used);
        // The axis-aligned 8 × 8-texel square at texels [8, 16) × [12, 20): whole level-1 cells.
        let p = Parallelogram::new([12.0, 16.0], [8.0, 0.0], [0.0, 8.0]).unwrap();
        let read = footprint_moments(&bm.moments, n, n, &p).unwrap();
        let mut want = [0.0f64; 5];
        let mut count = 0.0;
        for j in 12 * s..20 * s {
            for i in 8 * s..16 * s {
                let b = bm.bin_map.get(j * n * s + i).unwrap();
                for q in 0..5 {
                    want[q] += table[b][q];
                }
                count += 1.0;
            }
        }
        for q in 0..5 {
            let w = want[q] / count;
            assert!(
                (read[q] as f64 - w).abs() <= 1e-5 * w.abs().max(1e-3),
                "{q}: {} vs {w}",
                read[q]
            );
        }
    }

    /// A footprint that covers whole cells of the chosen level reads exactly their mean: an
    /// axis-aligned 8 × 8-texel square on a 32² map is read at level 2 (cells of 4 × 4 texels, 9
    /// cells meet its bounding box), as the mean of its four cells; one shifted by half
    /// a cell weights its nine cells by ¼, ½ and 1 (overlaps of 2 × 2, 2 × 4 and 4 × 4 texels).
    #[test]
    fn cell_aligned_footprints_read_their_cells() {
        let n = 32;
        let slopes: Vec<Vec2> = (0..n * n)
            .map(|k| Vec2::new((k % n) as f32 * 0.01, (k / n) as f32 * -0.02))
            .collect();
        let chain = MomentPyramid::build_from(n, n, &slopes, 2);
        let l = chain.level(0).unwrap();
        let cell = |i: usize, j: usize| l.data[j * l.width + i];
        let mean = |w: &[(usize, usize, f64)]| {
            let t: f64 = w.iter().map(|c| c.2).sum();
            std::array::from_fn::<f64, 5, _>(|k| {
                w.iter()
                    .map(|&(i, j, x)| x * cell(i, j)[k] as f64)
                    .sum::<f64>()
                    / t
            })
        };
        let read = |c: [f64; 2]| {
            let p = Parallelogram::new(c, [8.0, 0.0], [0.0, 8.0]).unwrap();
            footprint_moments(&chain, n, n, &p).unwrap()
        };
        let aligned = read([8.0, 12.0]);
        let want = mean(&[(1, 2, 1.0), (2, 2, 1.0), (1, 3, 1.0), (2, 3, 1.0)]);
        let shifted = read([10.0, 14.0]);
        let mut w = vec![];
        for (j, wy) in [(2usize, 0.5), (3, 1.0), (4, 0.5)] {
            for (i, wx) in [(1usize, 0.5), (2, 1.0), (3, 0.5)] {
                w.push((i, j, wx * wy));
            }
        }
        let want_shifted = mean(&w);
        for k in 0..5 {
            // f32 storage of the result: 1e-6 relative.
            assert!((aligned[k] as f64 - want[k]).abs() <= 1e-6 * want[k].abs() + 1e-9);
            assert!(
                (shifted[k] as f64 - want_shifted[k]).abs() <= 1e-6 * want_shifted[k].abs() + 1e-9
            );
        }
    }
}
