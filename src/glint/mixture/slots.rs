//! The slot rectangle of a gathered patch: the nodes within a footprint's window per axis
//! ([`AxisSlots`], folded onto the grid where the window spans a period) and the rectangles of lobe
//! blocks its weights are laid out in ([`BlockRect`], [`block_rects`]).

use super::blocks::SIDE;
use crate::glint::kernels::lanes::LANES;

/// The slots of one axis of the weight rectangle.
#[derive(Clone, Copy, Debug)]
pub(super) struct AxisSlots {
    /// First unwrapped lobe index (unused when folded).
    start: i64,
    /// Number of slots.
    pub len: usize,
    /// Lobes along this axis.
    pub n: usize,
    /// Folded onto [0, n) (slot = lobe index).
    pub folded: bool,
}

impl AxisSlots {
    /// Lobe indices I with |I + ½ − c| ≤ half, folded if they span a period or more.
    pub(super) fn new(c: f64, half: f64, n: usize) -> AxisSlots {
        let lo = (c - 0.5 - half).ceil();
        let hi = (c - 0.5 + half).floor();
        let len = if hi >= lo { (hi - lo) as usize + 1 } else { 1 };
        let start = if hi >= lo {
            lo as i64
        } else {
            (c - 0.5).round() as i64
        };
        if len >= n {
            AxisSlots {
                start,
                len: n,
                n,
                folded: true,
            }
        } else {
            AxisSlots {
                start,
                len,
                n,
                folded: false,
            }
        }
    }

    /// The slot of unwrapped lobe index I (which must lie in the rectangle).
    #[inline]
    pub(super) fn slot_of_unwrapped(&self, i: i64) -> usize {
        if self.folded {
            i.rem_euclid(self.n as i64) as usize
        } else {
            (i - self.start) as usize
        }
    }

    /// The lobe index of a slot.
    #[inline]
    pub fn lobe_of_slot(&self, s: usize) -> usize {
        if self.folded {
            s
        } else {
            (self.start + s as i64).rem_euclid(self.n as i64) as usize
        }
    }

    /// The unwrapped lobe indices whose weights are summed (the whole ±half range when folded).
    pub(super) fn unwrapped_range(&self, c: f64, half: f64) -> (i64, i64) {
        if self.folded {
            (
                (c - 0.5 - half).ceil() as i64,
                (c - 0.5 + half).floor() as i64,
            )
        } else {
            (self.start, self.start + self.len as i64 - 1)
        }
    }

    /// The number of slots in the first segment of [`AxisSlots::segments`] (all of them for one
    /// segment): the slot at which the second begins.
    #[inline]
    pub fn first_run(&self) -> usize {
        if self.folded {
            return self.n;
        }
        let first = self.start.rem_euclid(self.n as i64) as usize;
        self.len.min(self.n - first)
    }

    /// Segments [lo, hi) of lobe indices with slot = i + off, covering the slots.
    pub(super) fn segments(&self) -> ([(usize, usize, i64); 2], usize) {
        let mut out = [(0, 0, 0); 2];
        if self.folded {
            out[0] = (0, self.n, 0);
            return (out, 1);
        }
        let first = self.start.rem_euclid(self.n as i64) as usize;
        let run = self.len.min(self.n - first);
        out[0] = (first, first + run, -(first as i64));
        if run < self.len {
            out[1] = (0, self.len - run, run as i64);
            (out, 2)
        } else {
            (out, 1)
        }
    }
}

/// One (x segment × y segment) rectangle of a patch's lobes, with its blocks.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct BlockRect {
    /// Lobe ranges [lo, hi) along x and y.
    pub x: (usize, usize),
    pub y: (usize, usize),
    /// First block and the block counts along x and y.
    pub bx0: usize,
    pub by0: usize,
    pub bw: usize,
    pub bh: usize,
    /// Offset of the rectangle's first block in `block_weights`, in lanes.
    pub offset: usize,
}

impl BlockRect {
    /// The lane weights of block (bx, by) (absolute block coordinates, inside the rectangle).
    /// `#[inline(always)]`: called inside the block passes, whose AVX2 copy inlines only what is
    /// forced (simd.rs, `dispatch`).
    #[inline(always)]
    pub fn weights<'w>(&self, bw: &'w [f32], bx: usize, by: usize) -> &'w [f32; LANES] {
        let o = self.offset + ((by - self.by0) * self.bw + (bx - self.bx0)) * LANES;
        bw[o..o + LANES].try_into().expect("16 lanes")
    }
}

/// The lobe blocks of the slot rectangle: one [`BlockRect`] per (x segment × y segment) of the
/// slots (at most 4, disjoint in lobe space, x segments outer), each covering the blocks its lobes
/// touch, and the number of lanes they hold.
pub(super) fn block_rects(axes: &[AxisSlots; 2]) -> ([BlockRect; 4], usize, usize) {
    let (xs, nxs) = axes[0].segments();
    let (ys, nys) = axes[1].segments();
    let mut rects = [BlockRect::default(); 4];
    let mut n = 0;
    let mut total = 0;
    for &(x_lo, x_hi, _) in &xs[..nxs] {
        for &(y_lo, y_hi, _) in &ys[..nys] {
            let (bx0, by0) = (x_lo / SIDE, y_lo / SIDE);
            let (bw, bh) = (x_hi.div_ceil(SIDE) - bx0, y_hi.div_ceil(SIDE) - by0);
            rects[n] = BlockRect {
                x: (x_lo, x_hi),
                y: (y_lo, y_hi),
                bx0,
                by0,
                bw,
                bh,
                offset: total,
            };
            total += bw * bh * LANES;
            n += 1;
        }
    }
    (rects, n, total)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_segments_cover_the_slots_once() {
        for &(c, half, n) in &[
            (0.2, 1.3, 8usize),
            (7.9, 2.0, 8),
            (3.5, 0.1, 8),
            (4.0, 9.0, 8),
            (0.5, 0.0, 1),
        ] {
            let a = AxisSlots::new(c, half, n);
            let (seg, k) = a.segments();
            let mut seen = vec![0; a.len];
            for &(lo, hi, off) in &seg[..k] {
                for i in lo..hi {
                    let s = (i as i64 + off) as usize;
                    assert_eq!(a.lobe_of_slot(s), i, "{c} {half} {n}");
                    seen[s] += 1;
                }
            }
            assert!(seen.iter().all(|&v| v == 1), "{c} {half} {n}: {seen:?}");
            let (lo, hi) = a.unwrapped_range(c, half);
            for i in lo..=hi {
                assert!(a.slot_of_unwrapped(i) < a.len);
            }
        }
    }
}
