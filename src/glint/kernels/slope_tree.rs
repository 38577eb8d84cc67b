//! The implicit quadtree of slope boxes shared by the glint models whose elements sit on a regular
//! grid (the Beckmann mixture's lobes, \[Chermain2019\] §5; the position-normal elements, \[Yan2016\]
//! §5, whose 4D hierarchy has its positional half implicit).
//!
//! A node of level l ≥ 1 is the block of 2^l × 2^l elements starting at element (x·2^l, y·2^l)
//! (clipped at the grid's edge); it stores only the union of its elements' slope boxes as
//! [x_min, y_min, x_max, y_max] in `f32` (16 bytes). Level 0 (the elements' own boxes) is not stored:
//! each model recomputes it from its elements at query time.

use glam::Vec2;
use rayon::prelude::*;

/// Whether a slope lies in a box (NaN slopes never do). The four comparisons are combined with `&`
/// (not `&&`): one branch for the caller instead of up to four, whose outcomes a walk cannot predict.
#[inline]
pub(crate) fn contains(b: &[f32; 4], s: Vec2) -> bool {
    (s.x >= b[0]) & (s.y >= b[1]) & (s.x <= b[2]) & (s.y <= b[3])
}

fn union(a: [f32; 4], b: [f32; 4]) -> [f32; 4] {
    [
        a[0].min(b[0]),
        a[1].min(b[1]),
        a[2].max(b[2]),
        a[3].max(b[3]),
    ]
}

/// Sizes of the levels over an `nx × ny` grid: level l has ⌈nx/2^l⌉ × ⌈ny/2^l⌉ nodes, up to 1 × 1.
pub(crate) fn level_sizes(nx: usize, ny: usize) -> Vec<[usize; 2]> {
    let mut sizes = vec![[nx, ny]];
    let (mut w, mut h) = (nx, ny);
    while w > 1 || h > 1 {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        sizes.push([w, h]);
    }
    sizes
}

/// The implicit quadtree of slope boxes. `boxes[l - 1]` holds level l ≥ 1, row major.
#[derive(Clone, Debug)]
pub(crate) struct SlopeTree {
    pub sizes: Vec<[usize; 2]>,
    pub boxes: Vec<Vec<[f32; 4]>>,
}

/// Fills `out` (one row of ⌈pw/2⌉ nodes) with row `y` of the level above a `pw × ph` grid whose
/// boxes `child(k)` gives (k = row · pw + column): each parent is the union of its (up to) 2 × 2
/// children, taken in the order (row 2y: 2x, 2x + 1), (row 2y + 1: 2x, 2x + 1).
///
/// Every way of building a tree goes through this one function, so trees built from stored boxes,
/// from boxes computed on the fly, or band by band are bit-identical (min/max of ±0 depends on the
/// order of the operands, so the order is part of the result).
#[inline]
pub(crate) fn parent_row(
    pw: usize,
    ph: usize,
    y: usize,
    child: impl Fn(usize) -> [f32; 4],
    out: &mut [[f32; 4]],
) {
    let rows = [2 * y, 2 * y + 1];
    for (x, o) in out.iter_mut().enumerate() {
        let mut b = [
            f32::INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NEG_INFINITY,
        ];
        for cy in rows.into_iter().filter(|&cy| cy < ph) {
            b = union(b, child(cy * pw + 2 * x));
            if 2 * x + 1 < pw {
                b = union(b, child(cy * pw + 2 * x + 1));
            }
        }
        *o = b;
    }
}

impl SlopeTree {
    /// Builds the tree from the level-0 boxes (row major over the element grid).
    pub fn build(nx: usize, ny: usize, leaf: &[[f32; 4]]) -> SlopeTree {
        Self::build_with(nx, ny, |k| leaf[k])
    }

    /// Builds the tree from level-0 boxes computed on the fly: `leaf(k)` is the box of element k
    /// (row major), called once per element, rows of level 1 in parallel. The same tree as
    /// [`SlopeTree::build`] over the boxes `leaf` gives, without holding level 0 (16 bytes per
    /// element) in memory.
    pub fn build_with(nx: usize, ny: usize, leaf: impl Fn(usize) -> [f32; 4] + Sync) -> SlopeTree {
        let sizes = level_sizes(nx, ny);
        if sizes.len() < 2 {
            return SlopeTree {
                sizes,
                boxes: Vec::new(),
            };
        }
        let [w, h] = sizes[1];
        let mut level1 = vec![[0.0f32; 4]; w * h];
        level1
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(y, out)| parent_row(nx, ny, y, &leaf, out));
        Self::from_level1(nx, ny, level1)
    }

    /// Builds the levels ≥ 2 above a given level 1 (⌈nx/2⌉ × ⌈ny/2⌉ boxes, row major, as
    /// [`parent_row`] computes it from level 0), rows in parallel.
    pub fn from_level1(nx: usize, ny: usize, level1: Vec<[f32; 4]>) -> SlopeTree {
        let sizes = level_sizes(nx, ny);
        debug_assert!(sizes.len() >= 2 && level1.len() == sizes[1][0] * sizes[1][1]);
        let mut boxes: Vec<Vec<[f32; 4]>> = Vec::with_capacity(sizes.len().saturating_sub(1));
        boxes.push(level1);
        for l in 2..sizes.len() {
            let [pw, ph] = sizes[l - 1];
            let [w, h] = sizes[l];
            let prev = &boxes[l - 2];
            let mut level = vec![[0.0f32; 4]; w * h];
            level
                .par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, out)| parent_row(pw, ph, y, |k| prev[k], out));
            boxes.push(level);
        }
        SlopeTree { sizes, boxes }
    }

    /// A tree that stores its levels from 2 up only: level 2 as given (⌈nx/4⌉ × ⌈ny/4⌉ boxes, row
    /// major), levels ≥ 3 the unions above it ([`parent_row`], rows in parallel); level 1 is left
    /// empty (0 bytes), and so are all levels of a grid with no level 2 (at most 2 × 2 elements).
    ///
    /// For models that test each element's box themselves at level 2 (the mixture's compact lobe
    /// blocks): only [`SlopeTree::for_each_node`] with `stop` ≥ 2 may be called on it (a walk
    /// below level 2 would index the empty level 1).
    pub fn from_level2(nx: usize, ny: usize, level2: Vec<[f32; 4]>) -> SlopeTree {
        let sizes = level_sizes(nx, ny);
        let mut boxes: Vec<Vec<[f32; 4]>> = vec![Vec::new(); sizes.len().saturating_sub(1)];
        if sizes.len() < 3 {
            return SlopeTree { sizes, boxes };
        }
        debug_assert_eq!(level2.len(), sizes[2][0] * sizes[2][1]);
        boxes[1] = level2;
        for l in 3..sizes.len() {
            let [pw, ph] = sizes[l - 1];
            let [w, h] = sizes[l];
            let prev = &boxes[l - 2];
            let mut level = vec![[0.0f32; 4]; w * h];
            level
                .par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, out)| parent_row(pw, ph, y, |k| prev[k], out));
            boxes[l - 1] = level;
        }
        SlopeTree { sizes, boxes }
    }

    /// Index of the top level (its single node is the root); 0 for a 1 × 1 grid.
    #[inline]
    pub fn top(&self) -> usize {
        self.sizes.len() - 1
    }

    /// The box of node (x, y) of level l ≥ 1.
    #[inline]
    pub fn node_box(&self, l: usize, x: usize, y: usize) -> &[f32; 4] {
        &self.boxes[l - 1][y * self.sizes[l][0] + x]
    }

    /// Calls `leaf(x, y)` for every level-0 element (x, y) in the half-open rectangle
    /// [x.0, x.1) × [y.0, y.1) all of whose ancestors' boxes contain the slope `s`, depth first. The
    /// caller tests the element's own box (level 0 is not stored).
    #[inline]
    pub fn for_each_leaf(
        &self,
        x: (usize, usize),
        y: (usize, usize),
        s: Vec2,
        leaf: impl FnMut(usize, usize),
    ) {
        self.for_each_node(0, x, y, s, leaf);
    }

    /// Calls `f(nx, ny)` for every node of level `stop` (≤ [`SlopeTree::top`]) that meets the
    /// level-0 rectangle [x.0, x.1) × [y.0, y.1) and whose boxes — its ancestors' and, for
    /// `stop` ≥ 1, its own — all contain the slope `s`, depth first.
    ///
    /// The walk starts below the root, at the finest level l ≥ max(`stop`, 1) on which the
    /// rectangle spans at most 2 × 2 nodes (pushed in increasing Morton code, so popped in the
    /// order the walk from the root reaches them), so a small footprint skips the levels above it.
    /// Same nodes, same order as the walk from the root: a node's box is the union of its
    /// children's ([`parent_row`]), so an ancestor's box contains the slope whenever a descendant's
    /// does, and the skipped ancestors' tests could only have passed (`for_each_node_from_root`
    /// in the tests checks the sequences match).
    ///
    /// The stack holds at most 3 pending siblings per level plus the start nodes, and a grid of at
    /// most 2³² elements per side has at most 33 levels: 128 entries always suffice. Entries pack
    /// (level, x, y) into a `u64` (6 + 29 + 29 bits; node coordinates < 2²⁹ on every level, i.e.
    /// grids under 2²⁹ elements per side) so that the stack is 1 KiB of plain zeros to set up.
    ///
    /// `#[inline(always)]`: the mixture's lobe-block passes are compiled once more with AVX2
    /// (src/glint/mixture/simd.rs), and only code inlined into them gets that copy.
    #[inline(always)]
    pub fn for_each_node(
        &self,
        stop: usize,
        x: (usize, usize),
        y: (usize, usize),
        s: Vec2,
        mut f: impl FnMut(usize, usize),
    ) {
        const BITS: u32 = 29;
        const MASK: u64 = (1 << BITS) - 1;
        debug_assert!(self.sizes[0][0] < 1 << BITS && self.sizes[0][1] < 1 << BITS);
        let pack = |l: usize, nx: usize, ny: usize| {
            ((l as u64) << (2 * BITS)) | ((nx as u64) << BITS) | ny as u64
        };
        if x.0 >= x.1 || y.0 >= y.1 {
            return;
        }
        let top = self.top();
        let mut stack = [0u64; 128];
        let mut len = 0;
        // The start level: the finest on which the rectangle spans at most 2 nodes per axis, never
        // below `stop` or level 1 (whose test is the one the stored boxes give for level 0).
        let wide =
            |l: usize| ((x.1 - 1) >> l) - (x.0 >> l) > 1 || ((y.1 - 1) >> l) - (y.0 >> l) > 1;
        let mut l0 = stop.max(1).min(top);
        while l0 < top && wide(l0) {
            l0 += 1;
        }
        let [w0, h0] = self.sizes[l0];
        let (xa, xb) = (x.0 >> l0, ((x.1 - 1) >> l0).min(w0.saturating_sub(1)));
        let (ya, yb) = (y.0 >> l0, ((y.1 - 1) >> l0).min(h0.saturating_sub(1)));
        // At most 2 × 2 neighbours, pushed in increasing Morton code (bits interleaved, y's above
        // x's): the axis whose two coordinates differ at the higher bit is the major one, y on a tie
        // (the xor of two consecutive integers is 2^(k+1) − 1, k their highest differing bit).
        if (ya ^ yb) >= (xa ^ xb) {
            for ny in ya..=yb {
                for nx in xa..=xb {
                    stack[len] = pack(l0, nx, ny);
                    len += 1;
                }
            }
        } else {
            for nx in xa..=xb {
                for ny in ya..=yb {
                    stack[len] = pack(l0, nx, ny);
                    len += 1;
                }
            }
        }
        while len > 0 {
            len -= 1;
            let e = stack[len];
            let (l, nx, ny) = (
                (e >> (2 * BITS)) as usize,
                ((e >> BITS) & MASK) as usize,
                (e & MASK) as usize,
            );
            let (bx0, by0) = (nx << l, ny << l);
            let (bx1, by1) = ((nx + 1) << l, (ny + 1) << l);
            if bx1 <= x.0 || bx0 >= x.1 || by1 <= y.0 || by0 >= y.1 {
                continue;
            }
            if l > 0 && !contains(self.node_box(l, nx, ny), s) {
                continue;
            }
            if l == stop {
                f(nx, ny);
                continue;
            }
            let [cw, ch] = self.sizes[l - 1];
            for cy in (2 * ny)..(2 * ny + 2).min(ch) {
                for cx in (2 * nx)..(2 * nx + 2).min(cw) {
                    stack[len] = pack(l - 1, cx, cy);
                    len += 1;
                }
            }
        }
    }

    /// Bytes held by the tree's boxes.
    pub fn bytes(&self) -> usize {
        self.boxes.iter().map(|b| b.len() * 16).sum()
    }
}

/// The quadtree's levels 1, 2, … by the straightforward loop over whole levels (each node the
/// union of its up to 2 × 2 children, in [`union`]'s order): the reference of the tests of
/// `build_with` here and of the mixture loader's banded derivation.
#[cfg(test)]
pub(crate) fn reference_levels(nx: usize, ny: usize, leaf: Vec<[f32; 4]>) -> Vec<Vec<[f32; 4]>> {
    let sizes = level_sizes(nx, ny);
    let mut out = Vec::new();
    let mut level = leaf;
    for l in 1..sizes.len() {
        let ([pw, ph], [w, h]) = (sizes[l - 1], sizes[l]);
        let mut up = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut b = [f32::INFINITY, f32::INFINITY, -f32::INFINITY, -f32::INFINITY];
                for cy in [2 * y, 2 * y + 1].into_iter().filter(|&c| c < ph) {
                    for cx in [2 * x, 2 * x + 1].into_iter().filter(|&c| c < pw) {
                        b = union(b, level[cy * pw + cx]);
                    }
                }
                up.push(b);
            }
        }
        out.push(up.clone());
        level = up;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain walk: from the root, every level's box tested. The reference of `walk_matches_the_walk_from_the_root`.
    fn for_each_node_from_root(
        tree: &SlopeTree,
        stop: usize,
        x: (usize, usize),
        y: (usize, usize),
        s: Vec2,
        mut f: impl FnMut(usize, usize),
    ) {
        let mut stack = vec![(tree.top(), 0usize, 0usize)];
        while let Some((l, nx, ny)) = stack.pop() {
            let (bx0, by0) = (nx << l, ny << l);
            let (bx1, by1) = ((nx + 1) << l, (ny + 1) << l);
            if bx1 <= x.0 || bx0 >= x.1 || by1 <= y.0 || by0 >= y.1 {
                continue;
            }
            if l > 0 && !contains(tree.node_box(l, nx, ny), s) {
                continue;
            }
            if l == stop {
                f(nx, ny);
                continue;
            }
            let [cw, ch] = tree.sizes[l - 1];
            for cy in (2 * ny)..(2 * ny + 2).min(ch) {
                for cx in (2 * nx)..(2 * nx + 2).min(cw) {
                    stack.push((l - 1, cx, cy));
                }
            }
        }
    }

    /// [`SlopeTree::for_each_node`] (started at the finest level where the rectangle spans 2 × 2
    /// nodes) calls `f` for the same nodes in the same order as the walk from the root, for every
    /// stop level, on grids of odd sizes, random boxes (some NaN, some ±0), rectangles from one
    /// element to the whole grid and slopes inside and outside the boxes. The sequences, not just
    /// the sets: the mixture sums its blocks in this order, so its D_P bits depend on it.
    #[test]
    fn walk_matches_the_walk_from_the_root() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let mut calls = 0usize;
        for (nx, ny) in [
            (1, 1),
            (2, 3),
            (7, 5),
            (16, 16),
            (33, 10),
            (64, 64),
            (100, 37),
        ] {
            let leaf: Vec<[f32; 4]> = (0..nx * ny)
                .map(|k| {
                    let (cx, cy): (f32, f32) =
                        (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let (hx, hy): (f32, f32) =
                        (rng.random_range(0.0..0.3), rng.random_range(0.0..0.3));
                    if k % 97 == 5 {
                        [f32::NAN, cy - hy, cx + hx, cy + hy]
                    } else if k % 89 == 3 {
                        [-0.0, -0.0, 0.0, 0.0]
                    } else {
                        [cx - hx, cy - hy, cx + hx, cy + hy]
                    }
                })
                .collect();
            let tree = SlopeTree::build(nx, ny, &leaf);
            for _ in 0..300 {
                let (x0, y0) = (rng.random_range(0..nx), rng.random_range(0..ny));
                let x1 = rng.random_range(x0 + 1..=nx);
                let y1 = rng.random_range(y0 + 1..=ny);
                let s = Vec2::new(rng.random_range(-1.2..1.2), rng.random_range(-1.2..1.2));
                for stop in 0..=tree.top() {
                    let (mut got, mut want) = (Vec::new(), Vec::new());
                    tree.for_each_node(stop, (x0, x1), (y0, y1), s, |a, b| got.push((a, b)));
                    for_each_node_from_root(&tree, stop, (x0, x1), (y0, y1), s, |a, b| {
                        want.push((a, b))
                    });
                    assert_eq!(
                        got, want,
                        "{nx}×{ny} stop {stop} x {x0}..{x1} y {y0}..{y1} {s:?}"
                    );
                    calls += want.len();
                }
            }
        }
        assert!(calls > 10_000, "{calls}");
    }

    /// `build_with` (boxes computed on the fly, level 1 by rows in parallel) equals, bit for bit,
    /// the quadtree built by the straightforward loop over whole levels, including the order of the
    /// min/max of ±0 bounds, on grids with odd sizes.
    #[test]
    fn build_with_matches_the_straightforward_tree() {
        for (nx, ny) in [(1, 1), (2, 1), (1, 9), (7, 5), (16, 16), (33, 10)] {
            let leaf: Vec<[f32; 4]> = (0..nx * ny)
                .map(|k| {
                    let z: f32 = if k % 3 == 0 { -0.0 } else { 0.0 };
                    let v = ((k * 37 % 11) as f32 - 5.0) * 0.1;
                    [z.min(v), -z, z.max(v + 0.5), z]
                })
                .collect();
            let tree = SlopeTree::build_with(nx, ny, |k| leaf[k]);
            let sizes = level_sizes(nx, ny);
            assert_eq!(tree.sizes, sizes);
            assert_eq!(tree.boxes.len(), sizes.len() - 1);
            let want = reference_levels(nx, ny, leaf);
            let bits = |v: &[[f32; 4]]| v.iter().flatten().map(|f| f.to_bits()).collect::<Vec<_>>();
            for (l, up) in want.iter().enumerate() {
                assert_eq!(bits(&tree.boxes[l]), bits(up), "{nx}×{ny} level {}", l + 1);
            }
        }
    }
}
