//! Lobe blocks: the mixture's lobes stored as structure-of-arrays tiles of 4 × 4 lobes, with the
//! coefficients every per-direction query needs precomputed in `f32`, and the branch-free lane
//! kernels (D_P, the exact visible area V_P) that LLVM vectorises.
//!
//! A block is the tile of lobes [4·bx, 4·bx + 4) × [4·by, 4·by + 4) of the lobe grid: exactly a
//! level-2 node of the slope-box quadtree (src/glint/slope_tree.rs), so the tree's level-2 box is
//! the block's box and a D_P query descends the tree only to level 2, then evaluates all 16 lanes of
//! each block whose box contains the slope. Lanes outside the grid (edge tiles) hold a valid padding
//! lobe and get weight 0; lanes outside a footprint get weight 0 from the patch: no per-lobe branch.
//!
//! The kernels work on `[f32; 16]` arrays lane by lane with selects instead of branches, and sum
//! into 16 `f64` lane accumulators (vertical adds only, so the reductions vectorise too; the lanes
//! are added together once per query). The exponential is [`exp2_lanes`], a polynomial of stated
//! error that vectorises (std's `exp` is a library call per lane).

use crate::glint::slope_tree::{SlopeTree, contains};
use crate::ndf::SlopeGaussian;
use glam::{Vec2, Vec3};

/// Lanes per block.
pub(super) const LANES: usize = 16;
/// Block side in lobes (blocks are `SIDE × SIDE` tiles).
pub(super) const SIDE: usize = 4;
/// The quadtree level whose nodes are the blocks (2^2 = [`SIDE`]).
const LEVEL: usize = 2;

/// √(½ log₂ e): the inverse Cholesky factor is stored times this, so that
/// exp(−½ |L⁻¹ d|²) = 2^(−|J d|²) with J = √(½ log₂ e) L⁻¹.
const J_SCALE: f64 = 0.849_321_800_288_019_1;
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
                let mut blk = LobeBlock {
                    mx: [0.0; LANES],
                    my: [0.0; LANES],
                    j11: [0.0; LANES],
                    j21: [0.0; LANES],
                    j22: [0.0; LANES],
                    l11: [0.0; LANES],
                    l21: [0.0; LANES],
                    l22: [0.0; LANES],
                };
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

/// 2^x for x ≤ 0 in `f32`, branch-free (vectorisable); 0 below −126 (the normal range).
///
/// x = n + f with n = round(x) (by the 1.5·2²³ rounding trick, no `floor` call) and f ∈ [−½, ½];
/// 2^f by its degree-7 Taylor polynomial in f·ln 2 (truncation < (½ ln 2)⁸/8! · √2 = 7.4·10⁻⁹
/// relative), 2^n by building the exponent bits. Maximum relative error against `f64` over
/// [−126, 0]: < 1·10⁻⁶ stated (Horner roundings, a few ulp), measured in `tests::exp2_error`.
/// x > 0 is clamped to 0 (the kernels only need x ≤ 0); NaN gives 0.
#[inline(always)]
pub(super) fn exp2_lanes(x: f32) -> f32 {
    const ROUND: f32 = 12_582_912.0; // 1.5 · 2²³: x + ROUND rounds x to an integer in the low bits
    // Taylor coefficients (ln 2)^k / k!.
    const C: [f32; 8] = [
        1.0,
        std::f32::consts::LN_2,
        0.240_226_5,
        0.055_504_11,
        0.009_618_129,
        0.001_333_355_8,
        0.000_154_035_3,
        1.525_273_4e-5,
    ];
    // All-ones if x ≥ −126, else 0 (NaN too): a bit mask, not a branch.
    let keep = ((x >= -126.0) as u32).wrapping_neg();
    let x = x.clamp(-126.0, 0.0);
    let t = x + ROUND;
    let n = t - ROUND;
    let f = x - n;
    let p = C[0]
        + f * (C[1] + f * (C[2] + f * (C[3] + f * (C[4] + f * (C[5] + f * (C[6] + f * C[7]))))));
    // n ∈ [−126, 0]: the bits of t are 0x4B40_0000 + n, so n + 127 ∈ [1, 127] is a normal exponent.
    let e = (t.to_bits() as i32 - 0x4B40_0000 + 127) as u32;
    let r = p * f32::from_bits(e << 23);
    f32::from_bits(r.to_bits() & keep)
}

/// `v` where `keep`, else +0.0, by a bit mask (branch-free; vectorises as an `and`).
#[inline(always)]
fn select(keep: bool, v: f32) -> f32 {
    f32::from_bits(v.to_bits() & (keep as u32).wrapping_neg())
}

/// Σ over the 16 lanes of `w[lane] · P22_lane(s)` into the lane accumulators `acc`, where P22 is
/// taken without its 1/(2π) factor (`× NORM_OF_J` is applied by the caller via [`p22_scale`]).
/// With `BOXED`, a lane contributes only if s lies in its slope box |s − μ| ≤ k (√Σxx, √Σyy)
/// (`k2` = k²), as the scalar walk does.
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
        let (l11, l21, l22) = (b.l11[i], b.l21[i], b.l22[i]);
        // `&`, not `&&`: both tests are evaluated, so the lane loop has no branch.
        let inside = (dx * dx <= k2 * (l11 * l11)) & (dy * dy <= k2 * (l21 * l21 + l22 * l22));
        let v = w[i] * (b.j11[i] * b.j22[i]) * e;
        p[i] = if BOXED { select(inside, v) } else { v };
    }
    for i in 0..LANES {
        acc[i] += p[i] as f64;
    }
}

/// The factor that turns the sums of [`p22_lanes`] into P22: 1/(2π) ÷ (½ log₂ e).
#[inline]
pub(super) fn p22_scale() -> f64 {
    NORM_OF_J
}

/// The 16 lanes' `w[lane] · V_lane(ω)`, V = ∫⟨ω, m⟩⁺ D dm the exact visible projected area of each
/// lobe, for a direction with ω_z > 0 (the caller checks).
///
/// V = s_w G(A_s / s_w) with A_s = ω_z − μ·ω_xy, s_w = |Lᵀ ω_xy| and G(z) = z Φ(z) + φ(z), written
/// as V = max(A_s, 0) + s_w G(−t), t = |A_s|/s_w, and G(−t) = φ(t) (1 − t R(t)) with Mills' ratio
/// R = Q/φ = √(π/2) τ e^{P(τ)}, τ = 1/(1 + t/(2√2)), P the exponent of Numerical Recipes' `erfcc`
/// (fractional error < 1.2·10⁻⁷). Where t > 4, 1 − t R loses (t² + 1)× relative accuracy to
/// cancellation; there it is formed as ε R with ε(t) = 1/(t + 2/(t + 3/(t + …))) (Laplace's continued
/// fraction to depth 12 by its forward recurrence). Both forms are computed for every lane and one is
/// selected: no per-lobe branch.
/// s_w = 0 (normal incidence): V = max(A_s, 0).
///
/// # Reference
/// \[Chermain2019\] eq. 12-13 (V_P = Σ W_i V_i); docs/slope_gaussian.md (V of one lobe);
/// \[Press1992\] §6.2 (`erfcc`); \[AbramowitzStegun1964\] 26.2.14 (the continued fraction).
#[inline(always)]
pub(super) fn visible_lanes(b: &LobeBlock, w: &[f32; LANES], d: Vec3, out: &mut [f32; LANES]) {
    const SQRT_HALF_PI: f32 = 1.253_314_1; // √(π/2)
    const INV_SQRT_2PI: f32 = 0.398_942_3;
    const HALF_LOG2E: f32 = 0.721_347_5; // ½ log₂ e
    const T_CF: f32 = 4.0;
    const T_MAX: f32 = 1.0e4;
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    // A_s, s_w and t in f64: V's relative sensitivity to t is ~t·Δt, so t needs more than f32's
    // relative accuracy where A_s cancels (grazing views, tilted lobes).
    let mut t = [0.0f32; LANES];
    let mut sw = [0.0f64; LANES];
    let mut base = [0.0f64; LANES];
    let (wx, wy, wz) = (d.x as f64, d.y as f64, d.z as f64);
    for i in 0..LANES {
        let a = wz - (b.mx[i] as f64 * wx + b.my[i] as f64 * wy);
        let vx = b.l11[i] as f64 * wx + b.l21[i] as f64 * wy;
        let vy = b.l22[i] as f64 * wy;
        let s = (vx * vx + vy * vy).sqrt();
        // s = 0 gives t = ∞ or NaN: `min` maps both to T_MAX, where φ(t) is 0 and so is G.
        t[i] = ((a.abs() / s) as f32).min(T_MAX);
        sw[i] = s;
        base[i] = a.max(0.0);
    }
    // φ(t), Q(t) = φ R and the near form φ (1 − t R), lane by lane.
    let mut q = [0.0f32; LANES];
    let mut near = [0.0f32; LANES];
    for i in 0..LANES {
        let ti = t[i];
        let tau = 1.0 / (1.0 + ti * (0.5 * std::f32::consts::FRAC_1_SQRT_2));
        let mills = SQRT_HALF_PI * tau * exp2_lanes(crate::math::erfc_exponent(tau) * LOG2E);
        let phi = INV_SQRT_2PI * exp2_lanes(-HALF_LOG2E * ti * ti);
        q[i] = phi * mills;
        near[i] = phi * (1.0 - ti * mills).max(0.0);
    }
    // ε(t) = 1/T₁, T₁ = t + 2/(t + 3/(t + … + 13/t)), by the forward recurrence of the convergents
    // (one division), at t clamped to [T_CF, 16] (φ = 0 in f32 beyond 13.3, and 16¹² stays far
    // inside f32's range). The step loop is outside the lane loop, so the lanes vectorise.
    let tc: [f32; LANES] = std::array::from_fn(|i| t[i].clamp(T_CF, 16.0));
    let (mut a0, mut a1) = ([1.0f32; LANES], tc);
    let (mut b0, mut b1) = ([0.0f32; LANES], [1.0f32; LANES]);
    for k in 2..=13 {
        let kf = k as f32;
        for i in 0..LANES {
            let a2 = tc[i] * a1[i] + kf * a0[i];
            let b2 = tc[i] * b1[i] + kf * b0[i];
            (a0[i], a1[i], b0[i], b1[i]) = (a1[i], a2, b1[i], b2);
        }
    }
    // G(−t) = φ (1 − t R) = ε φ R = ε Q beyond T_CF, where 1 − t R cancels.
    let mut g = [0.0f32; LANES];
    for i in 0..LANES {
        let far = (b1[i] / a1[i]) * q[i];
        let ti = t[i];
        g[i] = f32::from_bits(
            select(ti > T_CF, far).to_bits() | select(ti <= T_CF, near[i]).to_bits(),
        );
    }
    for i in 0..LANES {
        out[i] = w[i] * (base[i] + sw[i] * g[i] as f64) as f32;
    }
}

/// Calls `f(bx, by)` for every block that meets the lobe rectangle [x.0, x.1) × [y.0, y.1) and
/// whose quadtree ancestors' boxes (down to the block's own, level 2) all contain the slope `s`,
/// depth first. Grids of at most 2 × 2 lobes (no level-2 node) have one block, always called.
///
/// The stack holds at most 3 pending siblings per level plus one; ≤ 33 levels: 128 entries suffice.
#[inline]
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
    let mut stack = [(0u8, 0u32, 0u32); 128];
    let mut len = 1;
    stack[0] = (top as u8, 0, 0);
    while len > 0 {
        len -= 1;
        let (l, nx, ny) = stack[len];
        let (l, nx, ny) = (l as usize, nx as usize, ny as usize);
        let (bx0, by0) = (nx << l, ny << l);
        let (bx1, by1) = ((nx + 1) << l, (ny + 1) << l);
        if bx1 <= x.0 || bx0 >= x.1 || by1 <= y.0 || by0 >= y.1 {
            continue;
        }
        if !contains(tree.node_box(l, nx, ny), s) {
            continue;
        }
        if l == LEVEL {
            f(nx, ny);
            continue;
        }
        let [cw, ch] = tree.sizes[l - 1];
        for cy in (2 * ny)..(2 * ny + 2).min(ch) {
            for cx in (2 * nx)..(2 * nx + 2).min(cw) {
                stack[len] = ((l - 1) as u8, cx as u32, cy as u32);
                len += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp2_error() {
        // Dense grid over [−126, 0] plus the integers and half-integers (the reduction's edges).
        let mut worst = 0.0f64;
        let n = 2_000_000;
        for k in 0..=n {
            let x = -126.0 * k as f64 / n as f64;
            let x32 = x as f32;
            let want = (x32 as f64).exp2();
            let got = exp2_lanes(x32) as f64;
            worst = worst.max((got - want).abs() / want);
        }
        for k in 0..=252 {
            let x = -0.5 * k as f32;
            let want = (x as f64).exp2();
            worst = worst.max((exp2_lanes(x) as f64 - want).abs() / want);
        }
        println!("exp2_lanes: max relative error {worst:e}");
        assert!(worst < 1e-6, "max relative error {worst:e}");
        assert_eq!(exp2_lanes(-127.0), 0.0);
        assert_eq!(exp2_lanes(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp2_lanes(f32::NAN), 0.0);
        assert_eq!(exp2_lanes(0.0), 1.0);
    }

    #[test]
    fn block_constants() {
        let half_log2e = 0.5 * std::f64::consts::LOG2_E;
        assert!((J_SCALE * J_SCALE - half_log2e).abs() < 1e-15);
        assert!((NORM_OF_J - 1.0 / (std::f64::consts::TAU * half_log2e)).abs() < 1e-15);
    }

    /// V of one lobe by the lane kernel against [`SlopeGaussian`]'s `f64` V (libm erfc), over
    /// views from normal incidence to 89.9° and lobes tilted toward and away from the view.
    #[test]
    fn visible_lanes_match_the_scalar_lobe() {
        use crate::ndf::Ndf;
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
        let w = [1.0f32; LANES];
        for chunk in lobes.chunks(LANES) {
            let blocks = LobeBlocks::build(SIDE, SIDE, chunk, &chunk[0]);
            let b = &blocks.blocks[0];
            for ti in 0..60 {
                for pi in 0..12 {
                    let th = (89.9f32 * ti as f32 / 59.0).to_radians();
                    let ph = std::f32::consts::TAU * pi as f32 / 12.0;
                    let d = Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos());
                    let mut out = [0.0f32; LANES];
                    visible_lanes(b, &w, d, &mut out);
                    for (lane, g) in chunk.iter().enumerate() {
                        let want = g.visible_area(d) as f64;
                        let got = out[lane] as f64;
                        if want > 1e-30 {
                            let e = (got - want).abs() / want;
                            if e > worst {
                                worst = e;
                                at = format!(
                                    "{g:?} {d:?} want {want:e} got {got:e} a {}",
                                    g.signed_projected_area(d)
                                );
                            }
                        }
                    }
                }
            }
        }
        println!("visible_lanes: max relative error {worst:e} at {at}");
        assert!(worst < 1e-5, "{worst:e}");
    }
}
