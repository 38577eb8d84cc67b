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
//! are added together once per query). The exponential is [`exp2_lanes`], a polynomial of stated
//! error that vectorises (std's `exp` is a library call per lane); V_P's ramp term G(−t) is
//! [`ramp_neg_lanes`], one fitted exponent and one such exponential (no `erfc` call).

use crate::glint::kernels::slope_tree::{SlopeTree, contains};
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
    // All-ones if x ≥ −126, else 0 (NaN too): a bit mask, not a branch.
    let keep = ((x >= -126.0) as u32).wrapping_neg();
    let x = x.clamp(-126.0, 0.0);
    let t = x + ROUND;
    let n = t - ROUND;
    let f = x - n;
    // n ∈ [−126, 0]: the bits of t are 0x4B40_0000 + n, so n + 127 ∈ [1, 127] is a normal exponent.
    let e = (t.to_bits() as i32 - 0x4B40_0000 + 127) as u32;
    let r = exp2_poly(f) * f32::from_bits(e << 23);
    f32::from_bits(r.to_bits() & keep)
}

/// 2^f for f ∈ [−½, ½]: the degree-7 Taylor polynomial in f·ln 2 (see [`exp2_lanes`]).
#[inline(always)]
fn exp2_poly(f: f32) -> f32 {
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
    C[0] + f * (C[1] + f * (C[2] + f * (C[3] + f * (C[4] + f * (C[5] + f * (C[6] + f * C[7]))))))
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

/// The 16 lanes' G(−t) = φ(t) − t Q(t) = E[(−t − Z)⁺] for t ≥ 0 (Z standard normal), branch-free, in
/// `f32` from `f64` t; 0 where it is below `f32`'s normal range (t ≳ 13.2), for t = ∞ and for NaN.
///
/// G(−t) = φ(t) h(t), h = 1 − t R(t) (R Mills' ratio), is formed as τ² e^{P(τ) − t²/2}/√(2π) with
/// τ = 1/(1 + t/4) ∈ (0, 1] and P a degree-9 polynomial in τ − 0.6 fitted (weighted least squares in
/// the Chebyshev basis, Lawson iterations toward minimax) to ln(h/τ²) over τ ∈ [0.2, 1] (t ∈ [0, 16];
/// h from erfc below t = 3, from Laplace's continued fraction above; `tools/fit_mixture_ramp.py`
/// reproduces the coefficients). Fit error < 9.4·10⁻⁸ in the
/// exponent; the exponent is assembled and range-reduced in `f64` ([`exp2_split`]), so t²/2
/// loses nothing to `f32` at large t. Measured maximum relative error against the `f64` G(−t)
/// (libm's erfc) over t ∈ [0, 13]: see `tests::ramp_neg_lanes_error` (bound 1·10⁻⁶ asserted).
/// One `f32` division (τ), no branch, no library call: the lanes vectorise.
///
/// # Reference
/// docs/slope_gaussian.md (G and V); \[AbramowitzStegun1964\] 26.2.14 (the continued fraction used
/// for the fit's reference values); the τ substitution as in \[Press1992\] §6.2 (`erfcc`).
#[inline(always)]
pub(super) fn ramp_neg_lanes(t: &[f64; LANES], out: &mut [f32; LANES]) {
    const INV_SQRT_2PI: f32 = 0.398_942_3;
    #[allow(clippy::excessive_precision)]
    const P: [f32; 10] = [
        -1.244_708_393_489_749_4,
        3.054_656_480_484_212,
        0.547_764_485_561_222_7,
        -0.928_449_119_805_369_7,
        -0.539_391_164_288_975_5,
        0.744_292_706_170_099_9,
        0.539_760_181_308_597_7,
        -0.793_917_658_569_022,
        -0.409_734_608_149_832_1,
        0.646_252_530_778_816_2,
    ];
    // The work is split into loops of one width each, so that the f32 steps fill whole registers
    // (4 lanes with SSE2) instead of running at the 2 lanes of the f64 steps.
    // t beyond 1e4 (∞, and NaN by `min`'s rule) gives 0 below like any t ≳ 13.2.
    let t: [f64; LANES] = std::array::from_fn(|i| t[i].min(1.0e4));
    let mut tau = [0.0f32; LANES];
    let mut p = [0.0f32; LANES];
    for i in 0..LANES {
        let ti = 1.0 / (1.0 + 0.25 * t[i] as f32);
        let u = ti - 0.6;
        tau[i] = ti;
        p[i] = P[0]
            + u * (P[1]
                + u * (P[2]
                    + u * (P[3]
                        + u * (P[4]
                            + u * (P[5] + u * (P[6] + u * (P[7] + u * (P[8] + u * P[9]))))))));
    }
    let mut f = [0.0f32; LANES];
    let mut scale = [0.0f32; LANES];
    for i in 0..LANES {
        let x = std::f64::consts::LOG2_E * (p[i] as f64 - 0.5 * t[i] * t[i]);
        (f[i], scale[i]) = exp2_split(x);
    }
    for i in 0..LANES {
        out[i] = INV_SQRT_2PI * (tau[i] * tau[i]) * (exp2_poly(f[i]) * scale[i]);
    }
}

/// The range reduction of [`exp2_lanes_wide`]: x ≤ 0 in `f64` → (f, 2ⁿ) with x = n + f, f ∈ [−½, ½]
/// exact in `f32` up to its rounding, 2ⁿ an `f32` power of two; (any, +0) below −126 or for NaN.
#[inline(always)]
fn exp2_split(x: f64) -> (f32, f32) {
    const ROUND: f64 = 6_755_399_441_055_744.0; // 1.5 · 2⁵²
    let keep = ((x >= -126.0) as u32).wrapping_neg();
    // `max` then `min` (not `clamp`): NaN becomes −126, so f stays finite and 2ⁿ is masked to 0.
    #[allow(clippy::manual_clamp)]
    let x = x.max(-126.0).min(0.0);
    let t = x + ROUND;
    let n = t - ROUND;
    let f = (x - n) as f32;
    // The low 32 bits of t's bits are n (two's complement), n ∈ [−126, 0].
    let e = ((t.to_bits() as u32 as i32) + 127) as u32;
    (f, f32::from_bits((e << 23) & keep))
}

/// 2^x for x ≤ 0 given in `f64`, result in `f32`, branch-free; 0 below −126 (what
/// [`ramp_neg_lanes`] computes through [`exp2_split`]; kept for its error test). The integer part is
/// split off in `f64` (1.5·2⁵² rounding trick), so the `f32` polynomial sees f ∈ [−½, ½] exactly
/// and large |x| costs no accuracy (an `f32` argument of size 100 carries 4·10⁻⁶ absolute error).
/// Same polynomial and error as [`exp2_lanes`] (< 1·10⁻⁶ relative). NaN gives 0.
#[cfg(test)]
fn exp2_lanes_wide(x: f64) -> f32 {
    let (f, scale) = exp2_split(x);
    exp2_poly(f) * scale
}

/// Which compiled copy of the per-query block loops a patch runs: the crate's baseline target
/// (SSE2 on x86-64: 4 `f32` lanes per register; whatever the target has elsewhere) or, on x86 CPUs
/// that have it, AVX2 (8 `f32` lanes). The AVX2 copy is the same source compiled with
/// `#[target_feature(enable = "avx2")]` and **without FMA**: Rust never contracts `a * b + c` into a
/// fused multiply-add by itself, every operation stays an IEEE `f32`/`f64` operation in the same
/// order, so the two copies return bit-identical results (tested in tests/mixture_dispatch.rs).
/// Enabling FMA would let the kernels use `mul_add` (one rounding instead of two), which changes bits.
///
/// A value that says AVX2 exists only once `is_x86_feature_detected!("avx2")` returned true (the
/// field is private to this module): that is what makes the `unsafe` call in [`dispatch`] sound.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Simd {
    avx2: bool,
}

impl Simd {
    /// The baseline copy (always available).
    pub const BASELINE: Simd = Simd { avx2: false };

    /// The best copy this CPU runs, detected once per process and cached: AVX2 where the CPU has it,
    /// unless the environment variable `BRDF_SIMD` is `baseline` when first asked (for comparisons
    /// and for ruling the dispatch out when chasing a bug); the baseline elsewhere.
    #[inline]
    pub fn detected() -> Simd {
        use std::sync::atomic::{AtomicU8, Ordering};
        // 0: not yet detected; 1: baseline; 2: AVX2.
        static CACHE: AtomicU8 = AtomicU8::new(0);
        match CACHE.load(Ordering::Relaxed) {
            1 => Simd::BASELINE,
            2 => Simd { avx2: true },
            _ => {
                let forced = std::env::var_os("BRDF_SIMD").is_some_and(|v| v == "baseline");
                let simd = if forced {
                    Simd::BASELINE
                } else {
                    Simd {
                        avx2: avx2_detected(),
                    }
                };
                CACHE.store(if simd.avx2 { 2 } else { 1 }, Ordering::Relaxed);
                simd
            }
        }
    }

    /// The copy's name: `"avx2"` or `"baseline"`.
    pub fn name(self) -> &'static str {
        if self.avx2 { "avx2" } else { "baseline" }
    }
}

/// Whether the CPU runs AVX2 (never on other architectures).
fn avx2_detected() -> bool {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        std::arch::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        false
    }
}

/// Marker of the instruction set a [`BlockPass`] is instantiated for. The type parameter only makes
/// the compiler emit one copy of the pass (and of the closures inside it) per instruction set, so
/// that the AVX2 copy, inlined whole into its `#[target_feature]` wrapper, shares no code with the
/// baseline copy.
pub(super) trait Isa {}
/// The baseline instruction set.
pub(super) enum BaselineIsa {}
/// AVX2 (without FMA).
#[cfg_attr(
    not(any(target_arch = "x86", target_arch = "x86_64")),
    allow(dead_code)
)]
pub(super) enum Avx2Isa {}
impl Isa for BaselineIsa {}
impl Isa for Avx2Isa {}

/// One per-query loop over lobe blocks (the walk and the lane kernels), written once and compiled
/// per instruction set. `run` must be `#[inline(always)]` and call only `#[inline]`/`#[inline(always)]`
/// code in its hot loop: a function compiled without AVX2 does not inline into one with it the
/// other way round, but the baseline-compiled walk would otherwise be called from the AVX2 copy.
pub(super) trait BlockPass {
    type Out;
    fn run<I: Isa>(self) -> Self::Out;
}

/// Runs `pass` in the copy `simd` selects. The choice sits above the loop over blocks (one branch per
/// query, not per block): a `#[target_feature]` function is not inlined into a caller without the
/// feature, so a kernel dispatched per block would cost a call per block.
#[inline(always)]
pub(super) fn dispatch<P: BlockPass>(simd: Simd, pass: P) -> P::Out {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    if simd.avx2 {
        // SAFETY: `simd.avx2` is true only in a `Simd` made by `Simd::detected`, after
        // `is_x86_feature_detected!("avx2")` returned true on this CPU (the field is private).
        return unsafe { run_avx2(pass) };
    }
    let _ = simd;
    pass.run::<BaselineIsa>()
}

/// `pass` compiled with AVX2 enabled (no FMA: bit-identical to the baseline, see [`Simd`]).
#[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
#[target_feature(enable = "avx2")]
fn run_avx2<P: BlockPass>(pass: P) -> P::Out {
    pass.run::<Avx2Isa>()
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
/// the walk pops them in). This replaces the most numerous node visits of the walk (a stack pop,
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

    /// [`ramp_neg_lanes`] at one t (in every lane).
    fn ramp_neg_one(t: f64) -> f32 {
        let mut out = [0.0f32; LANES];
        ramp_neg_lanes(&[t; LANES], &mut out);
        out[7]
    }

    /// G(−t) by the lanes against the `f64` G(−t) (libm's erfc, Laplace's continued fraction
    /// beyond t = 5), relative, over t ∈ [0, 13] (G(−13) ≈ 3·10⁻⁴¹·… is at `f32`'s normal limit).
    #[test]
    fn ramp_neg_lanes_error() {
        let mut worst = (0.0f64, 0.0f64);
        let n = 400_000;
        for k in 0..=n {
            let t = 13.0 * k as f64 / n as f64;
            let want = crate::ndf::gauss::ramp_neg(t);
            let got = ramp_neg_one(t) as f64;
            // Below 2^-120 the f32 result is subnormal or flushed: not part of the stated bound.
            if want > 2f64.powi(-120) {
                let e = (got - want).abs() / want;
                if e > worst.0 {
                    worst = (e, t);
                }
            }
        }
        println!(
            "ramp_neg_lanes: max relative error {:e} at t = {}",
            worst.0, worst.1
        );
        assert!(
            worst.0 < 1e-6,
            "max relative error {:e} at t = {}",
            worst.0,
            worst.1
        );
        assert_eq!(ramp_neg_one(1.0e4), 0.0);
        assert_eq!(ramp_neg_one(f64::INFINITY), 0.0);
        assert_eq!(ramp_neg_one(f64::NAN), 0.0);
    }

    #[test]
    fn exp2_wide_error() {
        let mut worst = 0.0f64;
        let n = 1_000_000;
        for k in 0..=n {
            let x = -126.0 * k as f64 / n as f64;
            let want = x.exp2();
            worst = worst.max((exp2_lanes_wide(x) as f64 - want).abs() / want);
        }
        println!("exp2_lanes_wide: max relative error {worst:e}");
        assert!(worst < 1e-6, "max relative error {worst:e}");
        assert_eq!(exp2_lanes_wide(-126.5), 0.0);
        assert_eq!(exp2_lanes_wide(f64::NAN), 0.0);
        assert_eq!(exp2_lanes_wide(0.0), 1.0);
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
