//! The patch's per-query loops over lobe blocks: D_P's walk ([`SumP22`]), the exact visible area
//! V_P ([`VisibleSum`]) and the visible sampler's pick ([`VisiblePick`]). Each is a [`BlockPass`], generic over the storage's level view
//! ([`LevelView`]) and compiled once per storage and per instruction set (`simd::dispatch`): the
//! storage and the instruction set are chosen above the loop, once per query, never per block.

use super::blocks::{self, LobeBlock, SIDE};
use super::gather::Gathered;
use super::simd::{BlockPass, Isa};
use super::storage::LevelView;
use crate::glint::kernels::lanes::LANES;
use glam::{Vec2, Vec3};

/// Calls `f(block, lane weights, bx, by)` for every lobe block of the patch, rectangle by rectangle,
/// blocks row major.
#[inline(always)]
fn for_each_patch_block<L: LevelView>(
    lv: &L,
    g: &Gathered,
    mut f: impl FnMut(&LobeBlock, &[f32; LANES], usize, usize),
) {
    let bw = &g.bufs.block_weights;
    let mut scratch = L::scratch();
    for r in &g.rects[..g.n_rects] {
        for by in r.by0..r.by0 + r.bh {
            for bx in r.bx0..r.bx0 + r.bw {
                f(
                    lv.block(bx, by, &mut scratch),
                    r.weights(bw, bx, by),
                    bx,
                    by,
                );
            }
        }
    }
}

/// D_P's loop: Σ over the blocks reached by the walk (the quadtree down to the blocks whose boxes
/// hold `s`, [`blocks::for_each_block`]) of Σ_lanes W P22 (slope box applied), without the 1/(2π)
/// factor, and the number of blocks reached.
pub(super) struct SumP22<'g, L> {
    pub lv: L,
    pub g: &'g Gathered<'g>,
    pub s: Vec2,
    /// The squared slope-box half-width k² in lobe standard deviations.
    pub k2: f32,
}

impl<L: LevelView> BlockPass for SumP22<'_, L> {
    type Out = (f64, usize);
    #[inline(always)]
    fn run<I: Isa>(self) -> (f64, usize) {
        let Self { lv, g, s, k2 } = self;
        let bw = &g.bufs.block_weights;
        let mut acc = [0.0f64; LANES];
        let mut blocks_seen = 0usize;
        let mut scratch = L::scratch();
        for r in &g.rects[..g.n_rects] {
            blocks::for_each_block(
                lv.tree(),
                r.x,
                r.y,
                s,
                #[inline(always)]
                |bx, by| {
                    blocks_seen += 1;
                    let w = r.weights(bw, bx, by);
                    blocks::p22_lanes::<true>(lv.block(bx, by, &mut scratch), w, s, k2, &mut acc);
                },
            );
        }
        (acc.iter().sum::<f64>(), blocks_seen)
    }
}

/// The exact V_P's loop: Σ W V over every block of the patch, for a valid direction (w_z > 0,
/// finite).
pub(super) struct VisibleSum<'g, L> {
    pub lv: L,
    pub g: &'g Gathered<'g>,
    pub w: Vec3,
}

impl<L: LevelView> BlockPass for VisibleSum<'_, L> {
    type Out = f64;
    #[inline(always)]
    fn run<I: Isa>(self) -> f64 {
        let mut acc = [0.0f64; LANES];
        for_each_patch_block(
            &self.lv,
            self.g,
            #[inline(always)]
            |b, wts, _, _| {
                blocks::visible_lanes(b, wts, self.w, &mut acc);
            },
        );
        acc.iter().sum()
    }
}

/// The visible sampler's second pass: the node whose cumulative W V (blocks in the patch's order,
/// lanes in block order) first exceeds `target`, and u.x rescaled into it; (`usize::MAX`, ½) if no
/// node has V > 0, the last node with V > 0 if rounding leaves the target unmet.
pub(super) struct VisiblePick<'g, L> {
    pub lv: L,
    pub g: &'g Gathered<'g>,
    pub wo: Vec3,
    pub target: f64,
}

impl<L: LevelView> BlockPass for VisiblePick<'_, L> {
    type Out = (usize, f32);
    #[inline(always)]
    fn run<I: Isa>(self) -> (usize, f32) {
        let (wo, target) = (self.wo, self.target);
        let nx = self.lv.grid()[0];
        let lobe = |bx: usize, by: usize, lane: usize| {
            (by * SIDE + lane / SIDE) * nx + bx * SIDE + lane % SIDE
        };
        let mut acc = 0.0f64;
        // (lobe index, rescaled u.x); the last lobe with V > 0 if rounding leaves the target unmet.
        let mut chosen = (usize::MAX, 0.5f32);
        let mut done = false;
        for_each_patch_block(
            &self.lv,
            self.g,
            #[inline(always)]
            |b, wts, bx, by| {
                if done {
                    return;
                }
                let mut v = [0.0f64; LANES];
                blocks::visible_lanes(b, wts, wo, &mut v);
                let sum: f64 = v.iter().sum();
                if sum.is_nan() || sum <= 0.0 {
                    return;
                }
                if acc + sum <= target {
                    if let Some(last) = (0..LANES).rev().find(|&i| v[i] > 0.0) {
                        chosen = (lobe(bx, by, last), 1.0);
                    }
                    acc += sum;
                    return;
                }
                for (lane, &vi) in v.iter().enumerate() {
                    if vi > 0.0 {
                        chosen = (lobe(bx, by, lane), ((target - acc) / vi) as f32);
                        if acc + vi > target {
                            done = true;
                            return;
                        }
                    }
                    acc += vi;
                }
            },
        );
        chosen
    }
}
