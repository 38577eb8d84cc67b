//! Lobe blocks: the mixture's lobes stored as structure-of-arrays tiles of 4 × 4 lobes, with the
//! coefficients every per-direction query needs precomputed in `f32`, and the lane kernels (D_P, the
//! exact visible area V_P) that LLVM vectorises: no branch per lane, at most one per block.
//!
//! A block is the tile of lobes [4·bx, 4·bx + 4) × [4·by, 4·by + 4) of the lobe grid: exactly a
//! level-2 node of the slope-box quadtree (src/glint/slope_tree.rs), so the tree's level-2 box is
//! the block's box and a D_P query descends the tree only to level 2, then evaluates all 16 lanes of
//! each block whose box contains the slope. Lanes outside the grid (edge tiles) hold a valid padding
//! lobe and get weight 0; lanes outside a footprint get weight 0 from the patch: no per-lobe branch.
//!
//! The kernels work on `[f32; 16]` arrays lane by lane with selects instead of branches, and sum
//! into 16 `f64` lane accumulators (vertical adds only, so the reductions vectorise too; the lanes
//! are added together once per query). The exponential and V_P's ramp term are the lane arithmetic
//! of lanes.rs. The loops over blocks that call these kernels are in passes.rs, compiled per
//! storage and per instruction set (simd.rs).

pub(super) use crate::glint::kernels::lanes::LANES;
use crate::glint::kernels::lanes::{exp2_lanes, ramp_neg_lanes, select};
use crate::glint::kernels::slope_tree::{SlopeTree, contains};
use crate::ndf::SlopeGaussian;
use glam::{Vec2, Vec3};

/// Block side in lobes (blocks are `SIDE × SIDE` tiles).
pub(super) const SIDE: usize = 4;
/// The quadtree level whose nodes are the blocks (2^2 = [`SIDE`]).
const LEVEL: usize = 2;

/// √(½ log₂ e): the inverse Cholesky factor is stored times this, so that
/// exp(−½ |L⁻¹ d|²) = 2^(−|J d|²) with J = √(½ log₂ e) L⁻¹.
pub(super) const J_SCALE: f64 = 0.849_321_800_288_019_1;
/// 1/(2π) ÷ (½ log₂ e): P22 = |Σ|^(−½)/(2π) e^(…) = J₁₁ J₂₂ · this · 2^(…).
const NORM_OF_J: f64 = 0.220_635_600_152_652_4;

/// 16 lobes in structure-of-arrays form (aligned to a cache line; 512 bytes).
///
/// Per lane: the mean slope μ, the scaled inverse Cholesky factor J = √(½ log₂ e) L⁻¹ (lower
/// triangular, for P22) and the Cholesky factor L itself (for the slope box and the masking terms),
/// all derived from [`SlopeGaussian::from_moments`] of the stored moments.
#[derive(Clone, Debug)]
#[repr(C, align(64))]
pub(super) struct LobeBlock {
    mx: [f32; LANES],
    my: [f32; LANES],
    j11: [f32; LANES],
    j21: [f32; LANES],
    j22: [f32; LANES],
    l11: [f32; LANES],
    l21: [f32; LANES],
    l22: [f32; LANES],
}

const _: () = assert!(std::mem::size_of::<LobeBlock>() == 512);

impl LobeBlock {
    /// Asks the CPU to bring the block's eight cache lines into its caches (a hint).
    #[inline(always)]
    pub(super) fn prefetch(&self) {
        crate::glint::kernels::prefetch::prefetch(self);
    }

    /// Whether slope `s` lies in lane `lane`'s slope box (`k2` = k²): where [`p22_lanes`] counts
    /// the lane.
    #[inline]
    pub(super) fn in_box(&self, lane: usize, s: Vec2, k2: f32) -> bool {
        let (dx, dy) = (s.x - self.mx[lane], s.y - self.my[lane]);
        in_box(dx, dy, self.l11[lane], self.l21[lane], self.l22[lane], k2)
    }

    /// The mean slope μ of lane `lane`, as D and the masking read it.
    #[inline(always)]
    pub(super) fn mean(&self, lane: usize) -> [f64; 2] {
        [self.mx[lane] as f64, self.my[lane] as f64]
    }

    /// A block of zeros (a decode target: every lane is overwritten before use).
    #[inline]
    pub(super) fn zeroed() -> LobeBlock {
        LobeBlock {
            mx: [0.0; LANES],
            my: [0.0; LANES],
            j11: [0.0; LANES],
            j21: [0.0; LANES],
            j22: [0.0; LANES],
            l11: [0.0; LANES],
            l21: [0.0; LANES],
            l22: [0.0; LANES],
        }
    }

    /// The eight lane arrays, in the order μx, μy, J₁₁, J₂₁, J₂₂, L₁₁, L₂₁, L₂₂ (for the compact
    /// storage's decoder, compact.rs, which writes them).
    #[inline]
    pub(super) fn lanes_mut(&mut self) -> [&mut [f32; LANES]; 8] {
        [
            &mut self.mx,
            &mut self.my,
            &mut self.j11,
            &mut self.j21,
            &mut self.j22,
            &mut self.l11,
            &mut self.l21,
            &mut self.l22,
        ]
    }

    /// The eight lane arrays, read only (same order as [`LobeBlock::lanes_mut`]).
    #[inline]
    pub(super) fn lanes(&self) -> [&[f32; LANES]; 8] {
        [
            &self.mx, &self.my, &self.j11, &self.j21, &self.j22, &self.l11, &self.l21, &self.l22,
        ]
    }

    fn set(&mut self, lane: usize, g: &SlopeGaussian) {
        let mu = g.mean();
        let l = g.cholesky();
        let (l11, l21, l22) = (l.x_axis.x, l.x_axis.y, l.y_axis.y);
        // L⁻¹ = [[1/l11, 0], [−l21/(l11 l22), 1/l22]], formed in f64 from the lobe's f32 factor.
        let (a, b, c) = (l11 as f64, l21 as f64, l22 as f64);
        self.mx[lane] = mu.x;
        self.my[lane] = mu.y;
        self.j11[lane] = (J_SCALE / a) as f32;
        self.j21[lane] = (-J_SCALE * b / (a * c)) as f32;
        self.j22[lane] = (J_SCALE / c) as f32;
        self.l11[lane] = l11;
        self.l21[lane] = l21;
        self.l22[lane] = l22;
    }
}

/// The blocks of a lobe grid, row major over ⌈nx/4⌉ × ⌈ny/4⌉ tiles.
#[derive(Clone, Debug)]
pub(super) struct LobeBlocks {
    /// Blocks per row.
    pub bnx: usize,
    pub blocks: Vec<LobeBlock>,
}

impl LobeBlocks {
    /// The blocks of `lobes` (one [`SlopeGaussian`] per lobe, row major over `nx × ny`); edge lanes
    /// beyond the grid hold `pad`.
    pub fn build(nx: usize, ny: usize, lobes: &[SlopeGaussian], pad: &SlopeGaussian) -> Self {
        use rayon::prelude::*;
        let (bnx, bny) = (nx.div_ceil(SIDE), ny.div_ceil(SIDE));
        let blocks = (0..bnx * bny)
            .into_par_iter()
            .map(|b| {
                let (bx, by) = (b % bnx, b / bnx);
                let mut blk = LobeBlock::zeroed();
                for lane in 0..LANES {
                    let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
                    let g = if x < nx && y < ny {
                        &lobes[y * nx + x]
                    } else {
                        pad
                    };
                    blk.set(lane, g);
                }
                blk
            })
            .collect();
        LobeBlocks { bnx, blocks }
    }

    /// Bytes held by the blocks.
    pub fn bytes(&self) -> usize {
        self.blocks.len() * std::mem::size_of::<LobeBlock>()
    }

    #[inline]
    pub fn block(&self, bx: usize, by: usize) -> &LobeBlock {
        &self.blocks[by * self.bnx + bx]
    }
}

/// Σ over the 16 lanes of `w[lane] · P22_lane(s)` into the lane accumulators `acc`, where P22 is
/// taken without its 1/(2π) factor (`× NORM_OF_J` is applied by the caller via [`p22_scale`]).
/// With `BOXED`, a lane contributes only if s lies in its slope box |s − μ| ≤ k (√Σxx, √Σyy)
/// (`k2` = k²): the box of `hierarchy::lobe_box`, which the quadtree's boxes contain.
///
/// # Reference
/// \[Chermain2019\] eq. 4 (P22 of each lobe), §5 (the box).
#[inline(always)]
pub(super) fn p22_lanes<const BOXED: bool>(
    b: &LobeBlock,
    w: &[f32; LANES],
    s: Vec2,
    k2: f32,
    acc: &mut [f64; LANES],
) {
    let mut p = [0.0f32; LANES];
    for i in 0..LANES {
        let dx = s.x - b.mx[i];
        let dy = s.y - b.my[i];
        let zx = b.j11[i] * dx;
        let zy = b.j21[i] * dx + b.j22[i] * dy;
        let e = exp2_lanes(-(zx * zx + zy * zy));
        let inside = in_box(dx, dy, b.l11[i], b.l21[i], b.l22[i], k2);
        let v = w[i] * (b.j11[i] * b.j22[i]) * e;
        p[i] = if BOXED { select(inside, v) } else { v };
    }
    for i in 0..LANES {
        acc[i] += p[i] as f64;
    }
}

/// Whether the offset (dx, dy) = s − μ of a slope from a lane's mean lies in the lane's slope box
/// |dx| ≤ k L₁₁, |dy| ≤ k √(L₂₁² + L₂₂²) (`k2` = k²), in `f32`: the one test of [`p22_lanes`] and
/// of the samplers' draws ([`LobeBlock::in_box`]), so that both agree on every slope.
#[inline(always)]
fn in_box(dx: f32, dy: f32, l11: f32, l21: f32, l22: f32, k2: f32) -> bool {
    // `&`, not `&&`: both tests are evaluated, so the lane loop has no branch.
    (dx * dx <= k2 * (l11 * l11)) & (dy * dy <= k2 * (l21 * l21 + l22 * l22))
}

/// The factor that turns the sums of [`p22_lanes`] into P22: 1/(2π) ÷ (½ log₂ e).
#[inline]
pub(super) fn p22_scale() -> f64 {
    NORM_OF_J
}

/// z = A_s/s_w at and beyond which a lane counts as fully visible: V = A_s (1 + G(−z)/z) and
/// G(−z)/z ≤ G(−5)/5 = 1.07·10⁻⁸, so dropping the ramp term changes V by less than that, relatively
/// (one-sided: V errs low).
pub(super) const Z_FULL: f32 = 5.0;

/// Adds the 16 lanes' W_lane · V_lane(ω) to the lane accumulators `acc`, V = ∫⟨ω, m⟩⁺ D dm the exact
/// visible projected area of each lobe, for a direction with ω_z > 0 (the caller checks).
///
/// V = s_w G(A_s/s_w) with A_s = ω_z − μ·ω_xy, s_w = |Lᵀ ω_xy| and G(z) = z Φ(z) + φ(z), written as
/// V = max(A_s, 0) + s_w G(−t), t = |A_s|/s_w (two non-negative terms, no cancellation). The first
/// term is added for every lane (A_s in `f64`: it cancels at grazing views on tilted lobes). If every
/// weighted lane of the block has z = A_s/s_w ≥ [`Z_FULL`] (tested in `f32` on A_s > 0 and
/// A_s² ≥ 25 s_w², no square root or division) the block is done: the ramp term is below 1.07·10⁻⁸ V per lane. Else the
/// ramp term is formed for all 16 lanes by [`ramp_neg_lanes`] (t and s_w in `f64`, relative error
/// ≤ 1·10⁻⁶ stated for G(−t)). One branch per block, none per lane; lanes of weight 0 never force
/// the ramp. s_w = 0 (normal incidence): t = ∞ → V = max(A_s, 0).
///
/// Error: per lane |ΔV| ≤ 1.1·10⁻⁸ V (the skip) + 1·10⁻⁶ s_w G(−t) (the ramp) + `f64` roundings,
/// so |ΔV_P| ≤ 1·10⁻⁶ V_P before the caller's `f32` rounding (`visible_lanes_match_f64`).
///
/// # Reference
/// \[Chermain2019\] eq. 12-13 (V_P = Σ W_i V_i); docs/slope_gaussian.md (V of one lobe).
#[inline(always)]
// Lane loops index several arrays in step; indices keep them in one obvious form for the vectoriser.
#[allow(clippy::needless_range_loop)]
pub(super) fn visible_lanes(b: &LobeBlock, w: &[f32; LANES], d: Vec3, acc: &mut [f64; LANES]) {
    const Z2: f32 = Z_FULL * Z_FULL;
    // The skip test in f32 (4 lanes per SSE register): a lane needs the ramp term unless it is
    // weightless or A_s ≥ Z_FULL s_w. A_s's f32 rounding only moves the test's threshold by a
    // relative ~1e-7 · |μ·ω_xy| / A_s, immaterial to the 1.07e-8 bound of the dropped term.
    let mut ramp = 0u32;
    for i in 0..LANES {
        let a = d.z - (b.mx[i] * d.x + b.my[i] * d.y);
        let vx = b.l11[i] * d.x + b.l21[i] * d.y;
        let vy = b.l22[i] * d.y;
        let full = (a > 0.0) & (a * a >= Z2 * (vx * vx + vy * vy));
        ramp |= (!full & (w[i] > 0.0)) as u32;
    }
    // max(A_s, 0) in f64 for every lane (2 lanes per register).
    let (wx, wy, wz) = (d.x as f64, d.y as f64, d.z as f64);
    let mut a = [0.0f64; LANES];
    for i in 0..LANES {
        a[i] = wz - (b.mx[i] as f64 * wx + b.my[i] as f64 * wy);
        acc[i] += w[i] as f64 * a[i].max(0.0);
    }
    if ramp == 0 {
        return;
    }
    let mut s = [0.0f64; LANES];
    let mut t = [0.0f64; LANES];
    for i in 0..LANES {
        let (l11, l21, l22) = (b.l11[i] as f64, b.l21[i] as f64, b.l22[i] as f64);
        let vx = l11 * wx + l21 * wy;
        let vy = l22 * wy;
        s[i] = (vx * vx + vy * vy).sqrt();
        // s = 0 gives t = ∞ or NaN (0/0): G(−t) is 0 for both, and so is s G.
        t[i] = a[i].abs() / s[i];
    }
    let mut g = [0.0f32; LANES];
    ramp_neg_lanes(&t, &mut g);
    for i in 0..LANES {
        acc[i] += w[i] as f64 * (s[i] * g[i] as f64);
    }
}

/// Calls `f(bx, by)` for every block that meets the lobe rectangle [x.0, x.1) × [y.0, y.1) and
/// whose quadtree ancestors' boxes (down to the block's own, level 2) all contain the slope `s`, in
/// the depth-first order of [`SlopeTree::for_each_node`] at level 2 (so the lane sums, and D_P's
/// bits, do not depend on how the blocks are found). Grids of at most 2 × 2 lobes (no level-2 node)
/// have one block, always called.
///
/// The walk stops one level above the blocks (level 3): for each level-3 node reached, its up to
/// 2 × 2 child blocks are tested at once, without a branch (inside the rectangle and the grid, box
/// holds `s`), into a 4-bit mask whose set bits are then visited from the highest down (the order
/// the walk pops them in). This saves the most numerous node visits of the walk (a stack pop,
/// range test and unpredictable box branch per block) by a few comparisons per four blocks.
#[inline(always)]
pub(super) fn for_each_block(
    tree: &SlopeTree,
    x: (usize, usize),
    y: (usize, usize),
    s: Vec2,
    mut f: impl FnMut(usize, usize),
) {
    let top = tree.top();
    if top < LEVEL {
        f(0, 0);
        return;
    }
    if top == LEVEL || x.0 >= x.1 || y.0 >= y.1 {
        tree.for_each_node(LEVEL, x, y, s, f);
        return;
    }
    let [w2, h2] = tree.sizes[LEVEL];
    let boxes = &tree.boxes[LEVEL - 1];
    // Blocks meeting the rectangle (a block spans lobes [4 b, 4 b + 4)), clipped to the grid.
    let (bx0, bx1) = (x.0 >> LEVEL, ((x.1 - 1) >> LEVEL).min(w2 - 1));
    let (by0, by1) = (y.0 >> LEVEL, ((y.1 - 1) >> LEVEL).min(h2 - 1));
    tree.for_each_node(
        LEVEL + 1,
        x,
        y,
        s,
        #[inline(always)]
        |px, py| {
            let mut mask = 0u32;
            for k in 0..4 {
                let (bx, by) = (2 * px + (k & 1), 2 * py + (k >> 1));
                let inside = (bx >= bx0) & (bx <= bx1) & (by >= by0) & (by <= by1);
                // Clamped index: read a valid box even for a child outside the grid (masked out).
                let b = &boxes[by.min(h2 - 1) * w2 + bx.min(w2 - 1)];
                mask |= ((inside & contains(b, s)) as u32) << k;
            }
            while mask != 0 {
                let k = 31 - mask.leading_zeros() as usize;
                mask &= !(1 << k);
                f(2 * px + (k & 1), 2 * py + (k >> 1));
            }
        },
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`for_each_block`] (the walk to level 3, then each node's 2 × 2 blocks by a mask) reaches
    /// the same blocks in the same order as the plain walk to level 2, on grids of odd sizes, random
    /// boxes, rectangles from one lobe to the whole grid, slopes inside and outside the boxes: the
    /// lane sums are accumulated in this order, so D_P's bits depend on it.
    #[test]
    fn block_walk_matches_the_walk_to_level_2() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(15);
        let mut calls = 0usize;
        for (nx, ny) in [
            (3, 3),
            (4, 4),
            (7, 6),
            (5, 9),
            (16, 16),
            (31, 17),
            (64, 64),
            (100, 37),
        ] {
            let leaf: Vec<[f32; 4]> = (0..nx * ny)
                .map(|_| {
                    let (cx, cy): (f32, f32) =
                        (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let (hx, hy): (f32, f32) =
                        (rng.random_range(0.0..0.2), rng.random_range(0.0..0.2));
                    [cx - hx, cy - hy, cx + hx, cy + hy]
                })
                .collect();
            let tree = SlopeTree::build(nx, ny, &leaf);
            for _ in 0..400 {
                let (x0, y0) = (rng.random_range(0..nx), rng.random_range(0..ny));
                let x1 = rng.random_range(x0 + 1..=nx);
                let y1 = rng.random_range(y0 + 1..=ny);
                let s = Vec2::new(rng.random_range(-1.2..1.2), rng.random_range(-1.2..1.2));
                let (mut got, mut want) = (Vec::new(), Vec::new());
                for_each_block(&tree, (x0, x1), (y0, y1), s, |a, b| got.push((a, b)));
                if tree.top() < LEVEL {
                    want.push((0, 0));
                } else {
                    tree.for_each_node(LEVEL, (x0, x1), (y0, y1), s, |a, b| want.push((a, b)));
                }
                assert_eq!(got, want, "{nx}×{ny} x {x0}..{x1} y {y0}..{y1} {s:?}");
                calls += want.len();
            }
        }
        assert!(calls > 5_000, "{calls}");
    }

    #[test]
    fn block_constants() {
        let half_log2e = 0.5 * std::f64::consts::LOG2_E;
        assert!((J_SCALE * J_SCALE - half_log2e).abs() < 1e-15);
        assert!((NORM_OF_J - 1.0 / (std::f64::consts::TAU * half_log2e)).abs() < 1e-15);
    }

    /// V of one lobe in `f64` from its public mean and Cholesky factor: max(A, 0) + s G(−|A|/s).
    fn visible_f64(g: &SlopeGaussian, d: Vec3) -> f64 {
        let (mu, l) = (g.mean(), g.cholesky());
        let (wx, wy, wz) = (d.x as f64, d.y as f64, d.z as f64);
        let a = wz - (mu.x as f64 * wx + mu.y as f64 * wy);
        let vx = l.x_axis.x as f64 * wx + l.x_axis.y as f64 * wy;
        let vy = l.y_axis.y as f64 * wy;
        let s = (vx * vx + vy * vy).sqrt();
        if s == 0.0 {
            return a.max(0.0);
        }
        a.max(0.0) + s * crate::ndf::gauss::ramp_neg(a.abs() / s)
    }

    /// V of one lobe by the lane kernel against the `f64` V, over views from normal incidence to
    /// 89.9° and lobes tilted toward and away from the view; each lane alone (the other lanes' weights
    /// 0, so that the block's skip decision is the lane's own) and all 16 together.
    #[test]
    fn visible_lanes_match_f64() {
        let mut worst = 0.0f64;
        let mut at = String::new();
        let mut lobes = Vec::new();
        for &(mx, my) in &[(0.0, 0.0), (0.8, -0.3), (-2.0, 1.0), (5.0, 0.0)] {
            for &(sx, sy, rho) in &[
                (0.01, 0.01, 0.0),
                (0.2, 0.05, 0.7),
                (0.5, 0.5, -0.9),
                (0.05, 0.3, 0.99),
            ] {
                let m = [
                    mx,
                    my,
                    mx * mx + sx * sx,
                    my * my + sy * sy,
                    mx * my + rho * sx * sy,
                ];
                lobes.push(SlopeGaussian::from_moments(m, 0.01));
            }
        }
        for chunk in lobes.chunks(LANES) {
            let blocks = LobeBlocks::build(SIDE, SIDE, chunk, &chunk[0]);
            let b = &blocks.blocks[0];
            for ti in 0..60 {
                for pi in 0..12 {
                    let th = (89.9f32 * ti as f32 / 59.0).to_radians();
                    let ph = std::f32::consts::TAU * pi as f32 / 12.0;
                    let d = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    let mut all = [0.0f64; LANES];
                    visible_lanes(b, &[1.0; LANES], d, &mut all);
                    for (lane, g) in chunk.iter().enumerate() {
                        let mut w = [0.0f32; LANES];
                        w[lane] = 1.0;
                        let mut one = [0.0f64; LANES];
                        visible_lanes(b, &w, d, &mut one);
                        let want = visible_f64(g, d);
                        for got in [one[lane], all[lane]] {
                            if want > 1e-30 {
                                let e = (got - want).abs() / want;
                                if e > worst {
                                    worst = e;
                                    at = format!("{g:?} {d:?} want {want:e} got {got:e}");
                                }
                            } else {
                                assert!(got.abs() <= 1e-30, "{g:?} {d:?}: {got:e}");
                            }
                        }
                    }
                }
            }
        }
        println!("visible_lanes: max relative error {worst:e} at {at}");
        assert!(worst < 1e-6, "{worst:e} at {at}");
    }
}
