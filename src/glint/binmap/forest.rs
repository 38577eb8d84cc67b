//! The forest of 2D kd-trees over the inverse bin map's texel lists, packed into one `u32` array,
//! and the area query Σ_k |A ∩ T_k| over one list.
//!
//! # Layout
//!
//! Every list of more than `leaf` texels gets a tree whose root region is the whole map
//! [0, width) × [0, height) (integer texel coordinates). A node with region [x0, x1) × [y0, y1)
//! splits its larger side at the middle (x when x1 − x0 ≥ y1 − y0; mid = x0 + (x1 − x0)/2, texels with
//! i < mid go left): neither the split dimension nor its position is stored. The node's texel list is
//! partitioned stably, so every node's texels are the contiguous range [start, end) of the inverse
//! bin map, and the children's ranges are [start, mid_index) and [mid_index, end).
//!
//! A node with at most `leaf` texels is a leaf and is **not stored**: its range is known from its
//! parent. An internal node is two `u32`, in pre-order: `mid_index` (absolute index into the inverse
//! map where the right child's range starts) and the array index of its right child; its left child,
//! if internal, follows it immediately. A 1 × 1 region holds at most one texel, so recursion stops.
//!
//! # Reference
//! \[Atanasov2020\] §2.3 (forest of 2D kd-trees, implicit splits, contiguous node ranges, one integer
//! list).

use super::clip::{Overlap, Parallelogram};

/// Sentinel for "no tree" (lists of at most `leaf` texels).
pub(crate) const NO_TREE: u32 = u32::MAX;

/// An axis-aligned region of integer texel coordinates [x0, x1) × [y0, y1).
#[derive(Clone, Copy, Debug)]
struct Region {
    x0: u32,
    y0: u32,
    x1: u32,
    y1: u32,
}

impl Region {
    /// The split of the larger side at the middle: (splits along x, mid coordinate).
    #[inline]
    fn split(&self) -> (bool, u32) {
        if self.x1 - self.x0 >= self.y1 - self.y0 {
            (true, self.x0 + (self.x1 - self.x0) / 2)
        } else {
            (false, self.y0 + (self.y1 - self.y0) / 2)
        }
    }

    #[inline]
    fn children(&self) -> (Region, Region) {
        let (along_x, mid) = self.split();
        if along_x {
            (Region { x1: mid, ..*self }, Region { x0: mid, ..*self })
        } else {
            (Region { y1: mid, ..*self }, Region { y0: mid, ..*self })
        }
    }
}

/// Builds the tree of one list in place: reorders `list` (texel indices of a `width`-wide map, the
/// range starting at `offset` of the inverse map) and appends the internal nodes to `nodes`.
/// Returns the root's index, or [`NO_TREE`] if the list is a single leaf.
pub(crate) fn build_tree(
    list: &mut [u32],
    offset: usize,
    width: usize,
    height: usize,
    leaf: usize,
    nodes: &mut Vec<u32>,
) -> u32 {
    if list.len() <= leaf {
        return NO_TREE;
    }
    let root = nodes.len() as u32;
    let region = Region {
        x0: 0,
        y0: 0,
        x1: width as u32,
        y1: height as u32,
    };
    let mut scratch = Vec::with_capacity(list.len());
    build_node(
        list,
        offset,
        width as u32,
        region,
        leaf,
        nodes,
        &mut scratch,
    );
    root
}

fn build_node(
    list: &mut [u32],
    offset: usize,
    width: u32,
    region: Region,
    leaf: usize,
    nodes: &mut Vec<u32>,
    scratch: &mut Vec<u32>,
) {
    if list.len() <= leaf {
        return;
    }
    let (along_x, mid) = region.split();
    // Stable partition: texels left of (below) mid first, each side in its previous order.
    let goes_left = |k: u32| {
        if along_x {
            k % width < mid
        } else {
            k / width < mid
        }
    };
    scratch.clear();
    scratch.extend(list.iter().copied().filter(|&k| !goes_left(k)));
    let mut n_left = 0;
    for r in 0..list.len() {
        if goes_left(list[r]) {
            list[n_left] = list[r];
            n_left += 1;
        }
    }
    list[n_left..].copy_from_slice(scratch);
    let at = nodes.len();
    nodes.extend_from_slice(&[(offset + n_left) as u32, 0]);
    let (lr, rr) = region.children();
    let (left, right) = list.split_at_mut(n_left);
    build_node(left, offset, width, lr, leaf, nodes, scratch);
    nodes[at + 1] = nodes.len() as u32;
    build_node(right, offset + n_left, width, rr, leaf, nodes, scratch);
}

/// What the query needs from the map: the inverse bin map, the forest and the sizes.
pub(crate) struct TreeView<'a> {
    pub(crate) inverse: &'a [u32],
    pub(crate) nodes: &'a [u32],
    pub(crate) width: u32,
    pub(crate) height: u32,
    pub(crate) leaf: usize,
}

/// Statistics of one query (for tests and measurements).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryStats {
    /// Internal nodes and leaves visited.
    pub nodes: usize,
    /// Texels tested individually (in partially covered leaves).
    pub texels: usize,
    /// Texels the footprint's boundary crosses (their overlap measured exactly: in closed form where
    /// one edge of the footprint crosses the texel, by polygon clipping where two do).
    pub clipped: usize,
}

impl TreeView<'_> {
    /// Σ_k |P ∩ T_k| over the texels of the range [start, end) (a bin's list), using its tree `root`
    /// when there is one. `P` is in the map's texel coordinates (one periodic image).
    pub(crate) fn area(
        &self,
        p: &Parallelogram,
        start: usize,
        end: usize,
        root: u32,
        stats: &mut QueryStats,
    ) -> f64 {
        let region = Region {
            x0: 0,
            y0: 0,
            x1: self.width,
            y1: self.height,
        };
        self.node_area(p, start, end, root, region, stats)
    }

    fn node_area(
        &self,
        p: &Parallelogram,
        start: usize,
        end: usize,
        node: u32,
        region: Region,
        stats: &mut QueryStats,
    ) -> f64 {
        stats.nodes += 1;
        let class = p.classify(
            region.x0 as f64,
            region.y0 as f64,
            region.x1 as f64,
            region.y1 as f64,
        );
        match class {
            Overlap::Outside => 0.0,
            // Every texel of the node lies inside: its pre-filtered area is its texel count.
            Overlap::Inside => (end - start) as f64,
            Overlap::Partial if end - start > self.leaf && node != NO_TREE => {
                let n = node as usize;
                let (mid, right) = (self.nodes[n] as usize, self.nodes[n + 1]);
                let (lr, rr) = region.children();
                let left_node = if mid - start > self.leaf {
                    node + 2
                } else {
                    NO_TREE
                };
                let right_node = if end - mid > self.leaf {
                    right
                } else {
                    NO_TREE
                };
                self.node_area(p, start, mid, left_node, lr, stats)
                    + self.node_area(p, mid, end, right_node, rr, stats)
            }
            Overlap::Partial => self.leaf_area(p, start, end, stats),
        }
    }

    fn leaf_area(
        &self,
        p: &Parallelogram,
        start: usize,
        end: usize,
        stats: &mut QueryStats,
    ) -> f64 {
        let mut sum = 0.0;
        for &k in &self.inverse[start..end] {
            let (i, j) = ((k % self.width) as f64, (k / self.width) as f64);
            stats.texels += 1;
            sum += match p.classify(i, j, i + 1.0, j + 1.0) {
                Overlap::Outside => 0.0,
                Overlap::Inside => 1.0,
                Overlap::Partial => {
                    stats.clipped += 1;
                    p.overlap_area(i, j, i + 1.0, j + 1.0)
                }
            };
        }
        sum
    }
}
