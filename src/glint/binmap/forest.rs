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

use super::clip::{AxisTests, Overlap, Parallelogram};

/// Sentinel for "no tree" (lists of at most `leaf` texels).
pub(crate) const NO_TREE: u32 = u32::MAX;

/// An axis-aligned region of integer texel coordinates [x0, x1) × [y0, y1).
#[derive(Clone, Copy, Debug, Default)]
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
    ///
    /// The walk classifies each node's region by P's separating axes ([`AxisTests`]): a region
    /// outside P adds nothing, one inside adds its texel count, a partly covered one descends to
    /// its children, or is a leaf whose texels are classified one by one, those P's boundary crosses
    /// measured exactly ([`Parallelogram::overlap_area`]). Texels inside P are counted as an
    /// integer.
    pub(crate) fn area(
        &self,
        p: &Parallelogram,
        start: usize,
        end: usize,
        root: u32,
        stats: &mut QueryStats,
    ) -> f64 {
        let walk = Walk {
            view: self,
            p,
            tests: AxisTests::new(p),
        };
        let root = Node {
            start: start as u32,
            end: end as u32,
            // A range of at most a leaf is scanned whatever the table holds for its tree.
            node: if end - start > self.leaf {
                root
            } else {
                NO_TREE
            },
            region: Region {
                x0: 0,
                y0: 0,
                x1: self.width,
                y1: self.height,
            },
        };
        let mut sum = Sum::default();
        if let Some(root) = walk.visit(root, &mut sum, stats) {
            walk.descend(root, &mut sum, stats);
        }
        sum.inside as f64 + sum.partial
    }
}

/// A query's area: the texels inside P (counted) and the overlaps of those P's boundary crosses.
#[derive(Default)]
struct Sum {
    inside: usize,
    partial: f64,
}

/// A node of a walk: the range [start, end) of the inverse map, the internal node's index (or
/// [`NO_TREE`] for a leaf) and the region.
#[derive(Clone, Copy, Default)]
struct Node {
    start: u32,
    end: u32,
    node: u32,
    region: Region,
}

/// Room for the nodes a walk leaves for later (both children of a node partly covered).
const PENDING: usize = 16;

/// One query's walk: the forest, P and its separating-axis tests.
struct Walk<'a> {
    view: &'a TreeView<'a>,
    p: &'a Parallelogram,
    tests: AxisTests,
}

impl Walk<'_> {
    /// Classifies `n`: adds it to `sum` when it is outside P, inside P or a partly covered leaf,
    /// and returns it when it is a partly covered internal node.
    #[inline(always)]
    fn visit(&self, n: Node, sum: &mut Sum, stats: &mut QueryStats) -> Option<Node> {
        stats.nodes += 1;
        let r = n.region;
        match self.tests.rect(r.x0, r.y0, r.x1, r.y1) {
            Overlap::Outside => None,
            // Every texel of the node lies inside: its pre-filtered area is its texel count.
            Overlap::Inside => {
                sum.inside += (n.end - n.start) as usize;
                None
            }
            Overlap::Partial if n.node != NO_TREE => Some(n),
            Overlap::Partial => {
                self.leaf(n.start as usize, n.end as usize, sum, stats);
                None
            }
        }
    }

    /// The subtree of the partly covered internal node `n`, depth first: a loop down the path of
    /// partly covered children, the second child kept on a small stack where both are (rarely: P's
    /// boundary mostly crosses one of the two), and a recursion in the stack's place should it
    /// fill.
    fn descend(&self, mut n: Node, sum: &mut Sum, stats: &mut QueryStats) {
        let (nodes, leaf) = (self.view.nodes, self.view.leaf);
        let internal = |count: u32, node: u32| {
            if count as usize > leaf { node } else { NO_TREE }
        };
        let mut pending = [Node::default(); PENDING];
        let mut len = 0;
        loop {
            let i = n.node as usize;
            let (mid, right) = (nodes[i], nodes[i + 1]);
            let (lr, rr) = n.region.children();
            let left = Node {
                start: n.start,
                end: mid,
                node: internal(mid - n.start, n.node + 2),
                region: lr,
            };
            let right = Node {
                start: mid,
                end: n.end,
                node: internal(n.end - mid, right),
                region: rr,
            };
            n = match (self.visit(left, sum, stats), self.visit(right, sum, stats)) {
                (Some(l), Some(r)) => {
                    match pending.get_mut(len) {
                        Some(slot) => {
                            *slot = r;
                            len += 1;
                        }
                        None => self.descend(r, sum, stats),
                    }
                    l
                }
                (Some(c), None) | (None, Some(c)) => c,
                (None, None) => {
                    if len == 0 {
                        return;
                    }
                    len -= 1;
                    pending[len]
                }
            };
        }
    }

    /// The texels of a partly covered leaf, one by one.
    #[inline(never)]
    fn leaf(&self, start: usize, end: usize, sum: &mut Sum, stats: &mut QueryStats) {
        let width = self.view.width;
        stats.texels += end - start;
        for &k in &self.view.inverse[start..end] {
            let (i, j) = (k % width, k / width);
            match self.tests.texel(i, j) {
                Overlap::Outside => {}
                Overlap::Inside => sum.inside += 1,
                Overlap::Partial => {
                    stats.clipped += 1;
                    let (x, y) = (i as f64, j as f64);
                    sum.partial += self.p.overlap_area(x, y, x + 1.0, y + 1.0);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
