//! The slope moments of the masking lobe of a bin-map patch without a bin list, read from the
//! moment mip chain with the footprint's own shape: the area-weighted mean of the chain's cells over
//! the exact overlap of each cell with the footprint's parallelogram, at the finest kept level
//! whose cells in the footprint's bounding box number at most [`MAX_FOOTPRINT_CELLS`].
//!
//! The trilinear lookup at the footprint centre and radius ½√|A| weights a tent around the centre
//! whose extent and shape are not the footprint's (isotropic, one to two cells of a level whose
//! cells are as wide as the footprint). Its first moment then differs from the footprint's, and
//! Scarf's bound of a distribution with other moments is no bound of the footprint's visible area.
//! With the footprint's exact overlaps only the boundary cells mix in slopes from outside it.
//!
//! Cost: at most [`MAX_FOOTPRINT_CELLS`] separating-axis tests and a clip per boundary cell,
//! whatever the footprint's area (1.6-1.8 µs per patch at 16 384 and 65 536 texels against
//! 0.34 µs for the trilinear lookup; docs/results.md).
//!
//! This is an estimate, not a bound: the boundary cells and the chain's finest kept level (4 × 4
//! texels) still mix in slopes from outside the footprint, and the chain holds the map's texel
//! slopes, not the bin map's sub-texel bins, so V can still fall below the footprint's visible
//! area (docs/binmap.md, "Larger footprints").
//!
//! # Reference
//! The moments and the lobe: \[Dupuy2013\] (LEADR moments); the cell overlaps: clip.rs
//! (\[SutherlandHodgman1974\]).

use super::clip::{Overlap, Parallelogram};
use crate::glint::surface::MomentPyramid;

/// Largest number of cells of the chain in the footprint's bounding box: 64 (a footprint read at
/// about eight cells across).
pub(crate) const MAX_FOOTPRINT_CELLS: f64 = 64.0;

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
