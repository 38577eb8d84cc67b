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
//! Cost: whatever the footprint's area, at most [`MAX_FOOTPRINT_CELLS`] cells, read row by row:
//! each row's cells that meet the footprint and those inside it follow from its edges
//! ([`Parallelogram::row_bounds`]), the cells inside are summed whole, and only the boundary cells
//! at each row's ends are measured ([`Parallelogram::overlap_area`]: one edge's closed form, a
//! clip where two edges cross); docs/results.md.
//!
//! # Reference
//! The moments and the lobe: \[Dupuy2013\] (LEADR moments); Scarf's bound: \[Scarf1958\]; the
//! cell overlaps: clip.rs (\[SutherlandHodgman1974\]).

use super::clip::Parallelogram;
use super::facets::sub_cell;
use super::params::MASKING_FIRST_LEVEL;
use crate::glint::HemisphereBins;
use crate::glint::surface::{MomentLevel, MomentPyramid};
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
    let (level, p) = footprint_level(chain, width, height, para)?;
    overlap_mean(level, &p).map(|m| m.map(|v| v as f32))
}

/// The level [`footprint_moments`] reads and the footprint in its cell units.
fn footprint_level<'c>(
    chain: &'c MomentPyramid,
    width: usize,
    height: usize,
    para: &Parallelogram,
) -> Option<(&'c MomentLevel, Parallelogram)> {
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
    Some((l, para.scaled(kx, ky)?))
}

/// How far (in cells) the analytic row bounds of [`overlap_mean`] are widened toward the
/// boundary cells: far above their rounding (~10⁻¹³ cells at the coordinates of a 2048² map), so
/// that a cell they leave out is outside P and a cell they take whole is inside it, exactly as
/// [`Parallelogram::classify`] would decide.
const ROW_MARGIN: f64 = 1e-7;

/// The mean of the level's cells (wrapped: the map tiles) weighted by their exact overlaps with `p`
/// (cell units), in `f64`; `None` if no cell overlaps. Row by row: the row's cells that may meet P
/// and those that lie inside it come from P's edges ([`Parallelogram::row_bounds`]), so only the
/// few cells at each end of a row are measured ([`Parallelogram::overlap_area`]) and the cells
/// between are taken whole. The cells and their order are those of a separating-axis test and a
/// clip per cell of the bounding box.
fn overlap_mean(l: &MomentLevel, p: &Parallelogram) -> Option<[f64; 5]> {
    let (lo, hi) = p.bounds();
    let (i0, i1) = (lo[0].floor(), hi[0].ceil());
    let (j0, j1) = (lo[1].floor() as i64, hi[1].ceil() as i64);
    let mut sum = [0.0f64; 5];
    let mut total = 0.0f64;
    for j in j0..j1 {
        let (y0, y1) = (j as f64, j as f64 + 1.0);
        let (meet, inside) = p.row_bounds(y0, y1);
        // Cells i with meet₀ − 1 < i < meet₁ meet P; those with inside₀ ≤ i, i + 1 ≤ inside₁ lie in it.
        let a = (meet[0] - ROW_MARGIN).floor().clamp(i0, i1);
        let b = (meet[1] + ROW_MARGIN).ceil().clamp(a, i1);
        let c = (inside[0] + ROW_MARGIN).ceil().clamp(a, b);
        let d = (inside[1] - ROW_MARGIN).floor().clamp(c, b);
        let (a, b, c, d) = (a as i64, b as i64, c as i64, d as i64);
        let row = &l.data[j.rem_euclid(l.height as i64) as usize * l.width..][..l.width];
        let mut ii = a.rem_euclid(l.width as i64) as usize;
        for i in a..b {
            let w = if i >= c && i < d {
                1.0
            } else {
                let x0 = i as f64;
                p.overlap_area(x0, y0, x0 + 1.0, y1)
            };
            if w > 0.0 {
                let m = &row[ii];
                for k in 0..5 {
                    sum[k] += w * m[k] as f64;
                }
                total += w;
            }
            ii += 1;
            if ii == l.width {
                ii = 0;
            }
        }
    }
    (total > 0.0).then(|| sum.map(|v| v / total))
}

#[cfg(test)]
mod tests;
