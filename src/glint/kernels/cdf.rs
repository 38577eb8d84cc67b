//! Discrete sampling from a cumulative table: the first step of every glint sampler (pick a lobe,
//! element or texel ∝ its weight, then sample inside it); and further uniform numbers derived from
//! the bits of used ones, for a sampler's second step or a redraw.

use glam::Vec2;

/// Inverts an increasing cumulative table (not necessarily normalised) at u ∈ [0, 1): returns the
/// slot k with cdf[k − 1] ≤ u · total < cdf[k] and u rescaled to [0, 1) inside that slot, so that
/// one uniform number serves both steps.
///
/// Total: NaN u → ½; u clamped to [0, 1]; an empty table → slot 0 (callers check emptiness); a
/// zero-width slot → ½.
pub(crate) fn invert_cdf(cdf: &[f64], u: f32) -> (usize, f32) {
    let total = cdf.last().copied().unwrap_or(0.0);
    let u = if u.is_nan() { 0.5 } else { u.clamp(0.0, 1.0) } as f64;
    let target = u * total;
    let s = cdf
        .partition_point(|&c| c <= target)
        .min(cdf.len().saturating_sub(1));
    let lo = if s == 0 { 0.0 } else { cdf[s - 1] };
    let width = cdf.get(s).copied().unwrap_or(0.0) - lo;
    let r = if width > 0.0 {
        (target - lo) / width
    } else {
        0.5
    };
    (s, (r as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0))
}

/// [`invert_cdf`] without the table: picks k ∝ v_k from the weights in order, given their sum
/// `total` (computed beforehand in the same order), stopping at the first k whose running sum passes
/// u · total, and returns u rescaled to [0, 1) inside v_k. For samplers whose weights depend on the
/// direction (W_i V_i(wo)), so that no table is stored. If rounding leaves u · total beyond the last
/// running sum, the last positive weight is taken. NaN u → ½; u clamped to [0, 1]; no positive
/// weight → (0, ½).
pub(crate) fn pick_streaming(
    u: f32,
    total: f64,
    weights: impl IntoIterator<Item = f64>,
) -> (usize, f32) {
    let u = if u.is_nan() { 0.5 } else { u.clamp(0.0, 1.0) } as f64;
    let target = u * total;
    let mut acc = 0.0;
    let mut chosen = (0, 0.5f32);
    for (k, v) in weights.into_iter().enumerate() {
        if v > 0.0 {
            chosen = (k, ((target - acc) / v) as f32);
            if acc + v > target {
                break;
            }
        }
        acc += v;
    }
    (chosen.0, chosen.1.clamp(0.0, 1.0 - f32::EPSILON / 2.0))
}

/// Two further uniform numbers in [0, 1) derived from the bits of `u` and `round` (two steps of
/// the SplitMix64 sequence seeded by the bits, Steele et al. 2014): deterministic in (u, round),
/// independent of u and of the other rounds for every practical purpose.
pub(crate) fn rehash(u: Vec2, round: u64) -> Vec2 {
    const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;
    let seed = (u.x.to_bits() as u64) << 32 | u.y.to_bits() as u64;
    let mut z = seed.wrapping_add(GOLDEN.wrapping_mul(1 + 2 * round));
    let mut next = || {
        z = z.wrapping_add(GOLDEN);
        let mut x = z;
        x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        x ^= x >> 31;
        (x >> 40) as f32 / (1u64 << 24) as f32
    };
    Vec2::new(next(), next())
}

#[cfg(test)]
mod tests {
    use super::{invert_cdf, pick_streaming};

    #[test]
    fn picks_the_slot_and_rescales() {
        let cdf = [1.0, 1.0, 4.0];
        assert_eq!(invert_cdf(&cdf, 0.0), (0, 0.0));
        // u · total = 2 lies in slot 2 ([1, 4)), a third of the way in.
        let (k, r) = invert_cdf(&cdf, 0.5);
        assert_eq!(k, 2);
        assert!((r - 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(invert_cdf(&cdf, f32::NAN).0, 2);
        assert_eq!(invert_cdf(&[], 0.3), (0, 0.5));
    }

    #[test]
    fn streaming_pick_agrees_with_the_table() {
        let v = [1.0, 0.0, 3.0, 2.0];
        let cdf = [1.0, 1.0, 4.0, 6.0];
        for u in [0.0f32, 0.1, 0.2, 0.5, 0.66, 0.9, 1.0] {
            let (a, ra) = invert_cdf(&cdf, u);
            let (b, rb) = pick_streaming(u, 6.0, v);
            assert_eq!(a, b, "{u}");
            assert!((ra - rb).abs() < 1e-6, "{u}: {ra} {rb}");
        }
        assert_eq!(pick_streaming(0.3, 0.0, [0.0, 0.0]), (0, 0.5));
    }
}
