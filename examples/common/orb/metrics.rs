//! Errors of a rendered image against the references (relative RMSE per pixel, with the
//! reference's noise subtracted, on 4 × 4 blocks, and of the total energy), the gap between the two
//! references, and the reference's own noise, over the pixels fully on the sphere.

use super::render::{Image, References};
use super::scene::Scene;

/// Errors of one image against the reference, over the covered pixels, on the mean of the channels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// ‖m − r‖ / ‖r‖ per pixel (includes the reference's own noise).
    pub rel_rmse: f64,
    /// The same with the reference's noise variance subtracted: √max(0, ‖m − r‖² − ‖a − b‖²/4) / ‖r‖
    /// (a, b the two halves: E‖a − b‖²/4 = E‖r − E r‖²).
    pub rel_rmse_denoised: f64,
    /// ‖m − r‖ / ‖r‖ on 4 × 4 pixel block sums (the look at a quarter of the resolution).
    pub rel_rmse_blocks: f64,
    /// (Σ m − Σ r) / Σ r: the relative error of the total energy.
    pub energy: f64,
}

/// The covered-pixel mask of a scene.
pub fn coverage(scene: &Scene) -> Vec<bool> {
    (0..scene.size * scene.size)
        .map(|k| scene.covered(k % scene.size, k / scene.size))
        .collect()
}

/// Errors of `m` against the reference halves `a`, `b` (reference = their mean) over `mask`.
pub fn errors(m: &Image, a: &Image, b: &Image, mask: &[bool]) -> Errors {
    let n = m.size as usize;
    let (mut e2, mut r2, mut noise2, mut sm, mut sr) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let blocks = n.div_ceil(4);
    let mut bm = vec![0.0f64; blocks * blocks];
    let mut br = vec![0.0f64; blocks * blocks];
    for k in (0..n * n).filter(|&k| mask[k]) {
        let (va, vb, vm) = (a.value(k), b.value(k), m.value(k));
        let vr = 0.5 * (va + vb);
        e2 += (vm - vr) * (vm - vr);
        r2 += vr * vr;
        noise2 += 0.25 * (va - vb) * (va - vb);
        sm += vm;
        sr += vr;
        let blk = (k / n / 4) * blocks + (k % n) / 4;
        bm[blk] += vm;
        br[blk] += vr;
    }
    let be2: f64 = bm.iter().zip(&br).map(|(p, q)| (p - q) * (p - q)).sum();
    let br2: f64 = br.iter().map(|q| q * q).sum();
    let safe = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
    Errors {
        rel_rmse: safe(e2, r2).sqrt(),
        rel_rmse_denoised: safe((e2 - noise2).max(0.0), r2).sqrt(),
        rel_rmse_blocks: safe(be2, br2).sqrt(),
        energy: safe(sm - sr, sr),
    }
}

/// The gap between the references, (b) against (a), over `mask`: both see the same positions, so
/// their noises are correlated and [`errors`]' noise subtraction does not apply. With the per-half
/// differences d_k = b_k − a_k: `rel_rmse` = ‖(d_0 + d_1)/2‖ / ‖r_a‖, `rel_rmse_denoised` the same
/// with the noise of the difference ‖d_0 − d_1‖²/4 subtracted (clamped at 0), `energy`
/// = (Σ b − Σ a) / Σ a; the 4 × 4 column is not computed (0).
pub fn gap_errors(refs: &References, mask: &[bool]) -> Errors {
    let (a0, a1) = (&refs.pbrdf.0, &refs.pbrdf.1);
    let (b0, b1) = (&refs.normal_mapped.0, &refs.normal_mapped.1);
    let (mut e2, mut n2, mut r2, mut sa, mut sb) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in (0..a0.pixels.len()).filter(|&k| mask[k]) {
        let (d0, d1) = (b0.value(k) - a0.value(k), b1.value(k) - a1.value(k));
        let ra = 0.5 * (a0.value(k) + a1.value(k));
        e2 += 0.25 * (d0 + d1) * (d0 + d1);
        n2 += 0.25 * (d0 - d1) * (d0 - d1);
        r2 += ra * ra;
        sa += ra;
        sb += 0.5 * (b0.value(k) + b1.value(k));
    }
    let safe = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
    Errors {
        rel_rmse: safe(e2, r2).sqrt(),
        // E‖(d0 + d1)/2‖² = ‖gap‖² + Var, and E‖d0 − d1‖²/4 = Var (independent halves).
        rel_rmse_denoised: safe((e2 - n2).max(0.0), r2).sqrt(),
        rel_rmse_blocks: 0.0,
        energy: safe(sb - sa, sa),
    }
}

/// The reference's own relative noise ‖a − b‖/2 / ‖r‖ over `mask`.
pub fn reference_noise(a: &Image, b: &Image, mask: &[bool]) -> f64 {
    let (mut n2, mut r2) = (0.0, 0.0);
    for k in (0..a.pixels.len()).filter(|&k| mask[k]) {
        let (va, vb) = (a.value(k), b.value(k));
        n2 += 0.25 * (va - vb) * (va - vb);
        r2 += 0.25 * (va + vb) * (va + vb);
    }
    if r2 > 0.0 { (n2 / r2).sqrt() } else { 0.0 }
}
