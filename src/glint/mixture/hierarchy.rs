//! The two pyramids over the lobe grid: the implicit quadtree of slope bounding boxes that prunes
//! D_P evaluations (\[Chermain2019\] §5), and the mip chain of lobe moments that gives a footprint's
//! filtered lobe (\[Chermain2019\] §4.2.2; full storage, full.rs).
//!
//! Lobes sit on a regular grid, so positions are implicit: a node of level l ≥ 1 is the block of
//! 2^l × 2^l lobes starting at lobe (x·2^l, y·2^l) (clipped at the grid's edge), and stores only the
//! union of its lobes' slope boxes as [x_min, y_min, x_max, y_max] in `f32` (16 bytes). Level 0 (the
//! lobes' own boxes) is not stored: queries descend to level 2, whose nodes are the lobe blocks
//! (blocks.rs), and test each lane's box there; [`lobe_box`] gives the boxes the tree is built from.

use crate::glint::kernels::mip::{bilinear_nodes, trilinear_levels};
use crate::glint::kernels::slope_tree::level_sizes;
use crate::ndf::SlopeGaussian;

/// The slope box of one lobe: mean ± k (√Σxx, √Σyy), the axis-aligned box of the ellipse
/// (ñ − μ)ᵀ Σ⁻¹ (ñ − μ) ≤ k², which holds a fraction 1 − e^{−k²/2} of the lobe's mass.
#[inline]
pub(super) fn lobe_box(g: &SlopeGaussian, k: f32) -> [f32; 4] {
    let l = g.cholesky();
    let (l11, l21, l22) = (l.x_axis.x, l.x_axis.y, l.y_axis.y);
    let hx = k * l11.abs();
    let hy = k * (l21 * l21 + l22 * l22).sqrt();
    let m = g.mean();
    [m.x - hx, m.y - hy, m.x + hx, m.y + hy]
}

/// The mip chain of lobe moments: level 0 = the lobes, level l + 1 = the average of the (up to)
/// 2 × 2 children of each node, accumulated in `f64`.
#[derive(Clone, Debug)]
pub(super) struct LobePyramid {
    pub sizes: Vec<[usize; 2]>,
    /// `levels[l - 1]` holds level l ≥ 1 (level 0 is the lobe array itself).
    pub levels: Vec<Vec<[f32; 5]>>,
}

impl LobePyramid {
    pub fn build(nx: usize, ny: usize, lobes: &[[f32; 5]]) -> LobePyramid {
        use rayon::prelude::*;
        let sizes = level_sizes(nx, ny);
        let mut levels: Vec<Vec<[f32; 5]>> = Vec::new();
        for l in 1..sizes.len() {
            let [pw, ph] = sizes[l - 1];
            let [w, h] = sizes[l];
            let prev: &[[f32; 5]] = if l == 1 { lobes } else { &levels[l - 2] };
            // Rows in parallel; each node is the same f64 average in the same order whatever the
            // thread count.
            let mut level = vec![[0.0f32; 5]; w * h];
            level.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, out) in row.iter_mut().enumerate() {
                    let mut acc = [0.0f64; 5];
                    let mut n = 0.0;
                    for cy in (2 * y)..(2 * y + 2).min(ph) {
                        for cx in (2 * x)..(2 * x + 2).min(pw) {
                            let m = prev[cy * pw + cx];
                            for k in 0..5 {
                                acc[k] += m[k] as f64;
                            }
                            n += 1.0;
                        }
                    }
                    *out = acc.map(|v| (v / n) as f32);
                }
            });
            levels.push(level);
        }
        LobePyramid { sizes, levels }
    }

    fn level<'a>(&'a self, lobes: &'a [[f32; 5]], l: usize) -> &'a [[f32; 5]] {
        if l == 0 { lobes } else { &self.levels[l - 1] }
    }

    /// Trilinear lookup: level of detail `lod` (clamped to [0, top], NaN → 0), position in lobe
    /// units. A convex combination of lobe moments, so a valid moment set.
    pub fn filtered(&self, lobes: &[[f32; 5]], p: [f64; 2], lod: f64) -> [f32; 5] {
        trilinear(
            self.sizes.len(),
            p,
            lod,
            |l| self.sizes[l],
            |l, k| self.level(lobes, l)[k].map(f64::from),
        )
    }

    /// Bytes held by levels ≥ 1.
    pub fn bytes(&self) -> usize {
        self.levels.iter().map(|l| l.len() * 20).sum()
    }
}

/// Trilinear lookup in a chain of `n_levels` levels of raw moments: bilinear with wrapping in the two
/// levels around `lod` (clamped to [0, n_levels − 1], NaN → 0), blended linearly; the position `p` is
/// in level-0 lobe units (lobe i has its centre at i + ½; non-finite → the origin), level l's nodes
/// are 2^l lobes wide. `size(l)` is level l's grid, `at(l, k)` the raw moments of its node k (row
/// major). Shared by the moment mip chain and compact storage's levels (compact.rs), in `f64`.
pub(super) fn trilinear(
    n_levels: usize,
    p: [f64; 2],
    lod: f64,
    size: impl Fn(usize) -> [usize; 2],
    at: impl Fn(usize, usize) -> [f64; 5],
) -> [f32; 5] {
    let (p, l0, t) = trilinear_levels(n_levels, p, lod);
    let bilinear = |l: usize| -> [f64; 5] {
        let c = bilinear_nodes(p, l, size(l)).map(|(k, wt)| (at(l, k), wt));
        std::array::from_fn(|k| c.iter().map(|(m, wt)| m[k] * wt).sum())
    };
    let a = bilinear(l0);
    let out = if t > 0.0 && l0 + 1 < n_levels {
        let b = bilinear(l0 + 1);
        std::array::from_fn(|k| a[k] * (1.0 - t) + b[k] * t)
    } else {
        a
    };
    out.map(|v| v as f32)
}
