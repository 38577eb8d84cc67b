//! The encoder of compact storage (compact.rs): each block's frame (the union of its lobes' slope
//! boxes, widened until every decoded lobe's box fits), the quantised means and binary16 inverse
//! Cholesky factors, and the merge errors of the levels l ≥ 1 raised by the encodings' own total
//! variation (Pinsker's bound on the closed-form Gaussian KL, [`tv_bound`]) before they are rounded
//! up to their one-byte codes. The merged lobes are those of full storage (levels.rs), encoded like
//! level 0.

use super::blocks::{J_SCALE, LANES, SIDE};
use super::compact::{
    CompactBlock, CompactLevel, QMAX, WORDS, assemble, decode_lane, decode_mean, encode_error,
    steps,
};
use super::hierarchy::lobe_box;
use super::levels::build_levels;
use crate::ndf::SlopeGaussian;
use half::f16;
use rayon::prelude::*;

/// J = √(½ log₂ e) L⁻¹ of a lobe in `f64`, rounded once to binary16 bits.
fn encode_j(g: &SlopeGaussian) -> [u16; 3] {
    let l = g.cholesky();
    let (a, b, c) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
    [J_SCALE / a, -J_SCALE * b / (a * c), J_SCALE / c].map(|v| {
        // Finite by MIN_COMPACT_SIGMA (|J| ≤ 0.85 / sigma_min ≤ 42 500); clamped for totality.
        f16::from_f64(v.clamp(-65504.0, 65504.0)).to_bits()
    })
}

/// The code whose decoded mean is nearest to `mu` (ties to the lower code).
fn encode_mean(mu: f32, lo: f32, step: f32) -> u16 {
    if step.is_nan() || step <= 0.0 {
        return 0;
    }
    let t = ((mu - lo) / step).round().clamp(0.0, QMAX) as i64;
    let mut best = (f32::INFINITY, 0u16);
    for q in (t - 1).max(0)..=(t + 1).min(65535) {
        let e = (decode_mean(q as u16, lo, step) - mu).abs();
        if e < best.0 {
            best = (e, q as u16);
        }
    }
    best.1
}

/// An upper bound of the total variation between two slope Gaussians: Pinsker's √(KL/2) with the
/// closed-form KL(b ‖ a), capped at 1, in `f64`.
///
/// # Reference
/// KL of two Gaussians: ½ (tr(Σa⁻¹Σb) + (μa − μb)ᵀ Σa⁻¹ (μa − μb) − 2 + ln(|Σa| / |Σb|)).
fn tv_bound(a: &SlopeGaussian, b: &SlopeGaussian) -> f64 {
    let la = a.cholesky();
    let lb = b.cholesky();
    let (a11, a21, a22) = (la.x_axis.x as f64, la.x_axis.y as f64, la.y_axis.y as f64);
    let (b11, b21, b22) = (lb.x_axis.x as f64, lb.x_axis.y as f64, lb.y_axis.y as f64);
    // M = La⁻¹ Lb (lower triangular): tr(Σa⁻¹ Σb) = |M|²_F.
    let m11 = b11 / a11;
    let m22 = b22 / a22;
    let m21 = (b21 - a21 * m11) / a22;
    let tr = m11 * m11 + m21 * m21 + m22 * m22;
    let d = a.mean() - b.mean();
    let (dx, dy) = (d.x as f64, d.y as f64);
    let zx = dx / a11;
    let zy = (dy - a21 * zx) / a22;
    let ln_det = 2.0 * ((a11 * a22).ln() - (b11 * b22).ln());
    let kl = 0.5 * (tr + zx * zx + zy * zy - 2.0 + ln_det);
    if kl.is_finite() {
        (0.5 * kl.max(0.0)).sqrt().min(1.0)
    } else {
        1.0
    }
}

/// The compact form of one block of lobes: the words, the frame and, per lane, the TV bound
/// between the lobe and its decoded form (0 for padding lanes).
fn encode_block(
    lobes: &[SlopeGaussian; LANES],
    real: u16,
    box_k: f32,
) -> (CompactBlock, [f32; 4], [f32; LANES]) {
    let mut words = [0u16; WORDS];
    let is_real = |i: usize| real & (1 << i) != 0;
    // J first: it does not depend on the frame.
    for (i, g) in lobes.iter().enumerate() {
        let j = encode_j(g);
        for (c, v) in j.into_iter().enumerate() {
            words[(2 + c) * LANES + i] = v;
        }
    }
    let mut frame = [
        f32::INFINITY,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NEG_INFINITY,
    ];
    for (i, g) in lobes.iter().enumerate().filter(|(i, _)| is_real(*i)) {
        let _ = i;
        let b = lobe_box(g, box_k);
        frame = [
            frame[0].min(b[0]),
            frame[1].min(b[1]),
            frame[2].max(b[2]),
            frame[3].max(b[3]),
        ];
    }
    // Means in the frame; widen until every decoded lane's box lies in it (module docs).
    for round in 0..64 {
        let (sx, sy) = steps(&frame);
        for (i, g) in lobes.iter().enumerate() {
            let mu = g.mean();
            if is_real(i) {
                words[i] = encode_mean(mu.x, frame[0], sx);
                words[LANES + i] = encode_mean(mu.y, frame[1], sy);
            } else {
                words[i] = 0;
                words[LANES + i] = 0;
            }
        }
        let mut u = frame;
        for i in (0..LANES).filter(|&i| is_real(i)) {
            let b = decode_lane(&words, &frame, i).slope_box(box_k);
            u = [
                u[0].min(b[0]),
                u[1].min(b[1]),
                u[2].max(b[2]),
                u[3].max(b[3]),
            ];
        }
        if u == frame {
            break;
        }
        // Grow past the union by a share of the width that rises with the rounds (the means move by
        // at most half a step, ~2⁻¹⁷ of the width, each time the frame changes).
        let grow = 2f32.powi(-14 + round.min(12));
        let (gx, gy) = ((u[2] - u[0]) * grow, (u[3] - u[1]) * grow);
        frame = [u[0] - gx, u[1] - gy, u[2] + gx, u[3] + gy];
    }
    let mut tv = [0.0f32; LANES];
    for i in (0..LANES).filter(|&i| is_real(i)) {
        let d = decode_lane(&words, &frame, i)
            .gaussian()
            .map_or(1.0, |g| tv_bound(&lobes[i], &g));
        // Rounded up to f32.
        tv[i] = (d as f32).max(d as f32 * (1.0 + f32::EPSILON));
    }
    (words, frame, tv)
}

/// A level of `w × h` lobes (`lobe(k)` row major) in compact storage, with the TV bound of each
/// lobe's encoding (row major); the merge errors are left empty. Blocks in parallel.
fn encode_level(
    w: usize,
    h: usize,
    lobe: impl Fn(usize) -> SlopeGaussian + Sync,
    pad: &SlopeGaussian,
    box_k: f32,
) -> (CompactLevel, Vec<f32>) {
    let (bnx, bny) = (w.div_ceil(SIDE), h.div_ceil(SIDE));
    let coded: Vec<(CompactBlock, [f32; 4], [f32; LANES])> = (0..bnx * bny)
        .into_par_iter()
        .map(|b| {
            let (bx, by) = (b % bnx, b / bnx);
            let mut real = 0u16;
            let lobes: [SlopeGaussian; LANES] = std::array::from_fn(|lane| {
                let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
                if x < w && y < h {
                    real |= 1 << lane;
                    lobe(y * w + x)
                } else {
                    *pad
                }
            });
            encode_block(&lobes, real, box_k)
        })
        .collect();
    let mut tv = vec![0.0f32; w * h];
    let mut blocks = Vec::with_capacity(coded.len());
    let mut frames = Vec::with_capacity(coded.len());
    for (b, (words, frame, t)) in coded.into_iter().enumerate() {
        let (bx, by) = (b % bnx, b / bnx);
        for (lane, &v) in t.iter().enumerate() {
            let (x, y) = (bx * SIDE + lane % SIDE, by * SIDE + lane / SIDE);
            if x < w && y < h {
                tv[y * w + x] = v;
            }
        }
        blocks.push(words);
        frames.push(frame);
    }
    (assemble(w, h, blocks, frames, Vec::new()), tv)
}

/// Every level of detail of the lobes `moments` (nx × ny, row major) in compact storage: level 0
/// encoded from the full lobes, levels l ≥ 1 from the merged lobes of full storage
/// ([`build_levels`]) with their merge errors raised by the encodings' TV bounds (module docs).
/// `box_k` is the slope-box half-width in lobe standard deviations.
pub(super) fn build(
    nx: usize,
    ny: usize,
    moments: &[[f32; 5]],
    sigma_min: f32,
    box_k: f32,
) -> Vec<CompactLevel> {
    let pad = SlopeGaussian::from_moments([0.0; 5], sigma_min);
    let full_levels = build_levels(nx, ny, moments, sigma_min, box_k, &pad, None);
    let (l0, mut qmax) = encode_level(
        nx,
        ny,
        |k| SlopeGaussian::from_moments(moments[k], sigma_min),
        &pad,
        box_k,
    );
    let mut out = vec![l0];
    let mut pw = nx;
    for lv in full_levels {
        let [w, h] = lv.grid;
        // The largest level-0 encoding TV under each node.
        let q0: Vec<f32> = (0..w * h)
            .into_par_iter()
            .map(|k| {
                let (x, y) = (k % w, k / w);
                [(0, 0), (1, 0), (0, 1), (1, 1)]
                    .iter()
                    .map(|(dx, dy)| qmax[(2 * y + dy) * pw + 2 * x + dx])
                    .fold(0.0f32, f32::max)
            })
            .collect();
        let (mut cl, q) = encode_level(
            w,
            h,
            |k| SlopeGaussian::from_moments(lv.moments[k], sigma_min),
            &pad,
            box_k,
        );
        cl.error = (0..w * h)
            .into_par_iter()
            .map(|k| encode_error(lv.error[0][k] as f64 + q[k] as f64 + q0[k] as f64))
            .collect();
        out.push(cl);
        qmax = q0;
        pw = w;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::mixture::blocks::LobeBlock;
    use crate::glint::mixture::compact::{decode_block, inside};

    /// Lobes of every kind: small and large means, narrow (σ_min) and wide, correlated to the
    /// clamp, in blocks of 16.
    fn test_lobes(seed: u64) -> Vec<SlopeGaussian> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..16 * 64)
            .map(|k| {
                let scale = [0.01f32, 0.3, 3.0, 40.0][k % 4];
                let (mx, my) = (scale * (2.0 * next() - 1.0), scale * (2.0 * next() - 1.0));
                let sig = [0.0f32, 0.005, 0.05, 0.5][(k / 4) % 4];
                let (sx, sy, r) = (sig * next(), sig * next(), 2.0 * next() - 1.0);
                let r = if k % 7 == 0 { r.signum() } else { r };
                SlopeGaussian::from_moments(
                    [
                        mx,
                        my,
                        mx * mx + sx * sx,
                        my * my + sy * sy,
                        mx * my + r * sx * sy,
                    ],
                    0.01,
                )
            })
            .collect()
    }

    /// Decode error bounds against the `f64` values of the full lobe: each mean within half a
    /// quantisation step plus the decode's two `f32` roundings (½ ulp of q·step and of the sum);
    /// each J entry within a relative 2⁻¹¹ (binary16 rounding) of J_SCALE L⁻¹ formed in `f64`;
    /// every decoded box inside the frame; the block decoder equal to the lane decoder bit for bit;
    /// L · (J / J_SCALE) = I to `f32` rounding.
    #[test]
    fn decode_error_bounds() {
        let box_k = 5.26f32;
        let (mut worst_mu, mut worst_j) = (0.0f64, 0.0f64);
        for (c, chunk) in test_lobes(7).chunks(LANES).enumerate() {
            let lobes: [SlopeGaussian; LANES] = std::array::from_fn(|i| chunk[i]);
            let real = if c.is_multiple_of(3) { 0x7fff } else { 0xffff };
            let (words, frame, tv) = encode_block(&lobes, real, box_k);
            let (sx, sy) = steps(&frame);
            let mut blk = LobeBlock::zeroed();
            decode_block(&words, &frame, &mut blk);
            let lanes = blk.lanes();
            for (i, g) in lobes.iter().enumerate() {
                let d = decode_lane(&words, &frame, i);
                let from_block: Vec<u32> = lanes.iter().map(|a| a[i].to_bits()).collect();
                let from_lane: Vec<u32> = [
                    d.mean.x, d.mean.y, d.j[0], d.j[1], d.j[2], d.l[0], d.l[1], d.l[2],
                ]
                .iter()
                .map(|v| v.to_bits())
                .collect();
                assert_eq!(from_block, from_lane, "lane {i}");
                if real & (1 << i) == 0 {
                    continue;
                }
                assert!(inside(&d.slope_box(box_k), &frame), "{d:?} {frame:?}");
                let mu = g.mean();
                let ulp = |v: f32| f32::EPSILON as f64 * v.abs().max(f32::MIN_POSITIVE) as f64;
                for (got, want, step, lo) in [
                    (d.mean.x, mu.x, sx, frame[0]),
                    (d.mean.y, mu.y, sy, frame[1]),
                ] {
                    let bound =
                        0.5 * step as f64 + ulp(lo.abs().max(got.abs())) + ulp(step * 65535.0);
                    let e = (got as f64 - want as f64).abs();
                    assert!(e <= bound, "mean {got} vs {want}: {e:e} > {bound:e}");
                    worst_mu = worst_mu.max(e / (0.5 * step as f64));
                }
                let l = g.cholesky();
                let (a, b, c) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
                let want = [J_SCALE / a, -J_SCALE * b / (a * c), J_SCALE / c];
                for (got, want) in d.j.iter().zip(want) {
                    let e = (*got as f64 - want).abs();
                    let bound = 2f64.powi(-11) * want.abs() + 2f64.powi(-25);
                    assert!(e <= bound, "J {got} vs {want}");
                    if want.abs() > 1e-3 {
                        worst_j = worst_j.max(e / want.abs());
                    }
                }
                // L J / s = I.
                let [l11, l21, l22] = d.l.map(f64::from);
                let [j11, j21, j22] = d.j.map(f64::from);
                let s = J_SCALE;
                assert!((l11 * j11 / s - 1.0).abs() < 1e-6);
                assert!((l22 * j22 / s - 1.0).abs() < 1e-6);
                assert!(
                    (l21 * j11 + l22 * j21).abs() / s
                        < 1e-6 * (l21.abs() * j11 + l22 * j21.abs()) / s + 1e-12
                );
                // The TV bound of the encoding: in [0, 1] (its size depends on the spread of the
                // block's means against each lobe's width: these test blocks mix scales at random).
                assert!((0.0..=1.0).contains(&tv[i]), "{}", tv[i]);
            }
        }
        println!(
            "mean error / half step ≤ {worst_mu:.3}, J relative ≤ {worst_j:e} (2^-11 = {:e})",
            2f64.powi(-11)
        );
        assert!(worst_mu > 0.2, "the test lobes exercise the quantisation");
    }

    #[test]
    fn tv_bound_is_zero_for_equal_and_grows() {
        let a =
            SlopeGaussian::from_moments([0.1, -0.2, 0.01 + 0.01, 0.04 + 0.02, -0.02 + 0.001], 0.01);
        assert!(tv_bound(&a, &a) < 1e-7);
        let b = SlopeGaussian::from_moments(
            [0.11, -0.2, 0.0121 + 0.01, 0.04 + 0.02, -0.022 + 0.001],
            0.01,
        );
        let t = tv_bound(&a, &b);
        assert!(t > 0.01 && t < 0.2, "{t}");
    }
}
