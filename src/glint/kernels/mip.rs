//! Mip-chain lookups over a regular grid of lobes (level l's nodes are 2^l × 2^l lobes): the
//! trilinear addressing shared by the mixture's moment chain and compact levels and by the filtered
//! mixture of both glint models (gmm.rs).

/// A trilinear lookup's inputs made total: the position `p` (non-finite → the origin), the lower
/// level l0 = ⌊lod⌋ and the blend t ∈ [0, 1) toward l0 + 1, `lod` clamped to [0, n_levels − 1]
/// (NaN → 0).
pub(crate) fn trilinear_levels(n_levels: usize, p: [f64; 2], lod: f64) -> ([f64; 2], usize, f64) {
    let top = (n_levels - 1) as f64;
    let lod = if lod.is_nan() {
        0.0
    } else {
        lod.clamp(0.0, top)
    };
    let p = if p[0].is_finite() && p[1].is_finite() {
        p
    } else {
        [0.0, 0.0]
    };
    let l0 = lod.floor();
    (p, l0 as usize, lod - l0)
}

/// The four nodes of level `l` (a grid of `size`, nodes 2^l level-0 lobes wide) around `p` (level-0
/// lobe units, lobe i centred at i + ½) and their bilinear weights: (row-major node index, weight)
/// for the offsets (0, 0), (1, 0), (0, 1), (1, 1), indices wrapped onto the grid.
pub(crate) fn bilinear_nodes(p: [f64; 2], l: usize, size: [usize; 2]) -> [(usize, f64); 4] {
    let [w, h] = size;
    let scale = (1u64 << l) as f64;
    let px = p[0] / scale - 0.5;
    let py = p[1] / scale - 0.5;
    let (bx, by) = (px.floor(), py.floor());
    let (fx, fy) = (px - bx, py - by);
    let node = |i: f64, j: f64| {
        let i = (i as i64).rem_euclid(w as i64) as usize;
        let j = (j as i64).rem_euclid(h as i64) as usize;
        j * w + i
    };
    [
        (node(bx, by), (1.0 - fx) * (1.0 - fy)),
        (node(bx + 1.0, by), fx * (1.0 - fy)),
        (node(bx, by + 1.0), (1.0 - fx) * fy),
        (node(bx + 1.0, by + 1.0), fx * fy),
    ]
}
