//! The inverse bin map's structure (Atanasov 2020): every sub-texel in exactly one bin list, the
//! forest's node ranges, and exact overlaps of footprints with the texels (Σ = |A|, against interval
//! products and point sampling).
//!
//! Maps are small (16² … 64², some non-square) and some builds use few bins (n = 7 … 15) so that bin
//! lists are long and the trees deep.

use crate::support;

use brdf::Vec2;
use brdf::frame::slope_to_normal;
use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{BinMap, BinMapPatch, Footprint, HemisphereBins, NormalMap};
use proptest::prelude::*;
use rand::RngExt;
use support::binmap::{params, test_maps};
use support::noise_map as noise;

/// The bin of sub-texel k of an s × s subdivision, computed here from the definition (texel-centre
/// normal for s = 1, otherwise the interpolated normal at the sub-texel's n-rooks point: in texel
/// (ti, tj), sub-texel (a, b) takes x = ti + (a + (s − 1 − b + ½)/s)/s, y = tj + (b + (a + ½)/s)/s).
fn expected_bin(map: &NormalMap, bins: &HemisphereBins, s: usize, k: usize) -> usize {
    if s == 1 {
        return bins.bin_of(slope_to_normal(map.slopes()[k])).unwrap();
    }
    let gw = map.width() * s;
    let (i, j) = (k % gw, k / gw);
    let (ti, a, tj, b) = (i / s, i % s, j / s, j % s);
    let sf = s as f32;
    let p = Vec2::new(
        ti as f32 + (a as f32 + ((s - 1 - b) as f32 + 0.5) / sf) / sf,
        tj as f32 + (b as f32 + (a as f32 + 0.5) / sf) / sf,
    );
    bins.bin_of(map.normal_at_texel(p)).unwrap()
}

#[test]
fn every_texel_in_exactly_one_bin_list() {
    for (name, map) in test_maps() {
        for (n, leaf, lookup, sub) in [
            (7, 1, BinLookup::Dense, 1),
            (15, 4, BinLookup::Hash, 2),
            (127, 16, BinLookup::Dense, 1),
            (127, 16, BinLookup::Hash, 3),
        ] {
            let bm = BinMap::build(
                &map,
                BinMapParams {
                    subdivisions: sub,
                    ..params(n, leaf, lookup)
                },
            )
            .unwrap();
            let texels = map.width() * map.height() * sub * sub;
            assert_eq!(bm.grid_size(), (map.width() * sub, map.height() * sub));
            let mut seen = vec![0u32; texels];
            let mut total = 0;
            for bin in 0..bm.bins().len() {
                for &k in bm.texels_of_bin(bin) {
                    seen[k as usize] += 1;
                    assert_eq!(
                        expected_bin(&map, bm.bins(), sub, k as usize),
                        bin,
                        "{name}"
                    );
                    assert_eq!(bm.bin_of_texel(k as usize), Some(bin));
                }
                total += bm.texels_of_bin(bin).len();
            }
            assert_eq!(total, texels, "{name} n={n}");
            assert!(
                seen.iter().all(|&c| c == 1),
                "{name} n={n}: a texel is missing or repeated"
            );
            // The lists tile the inverse map in bin order.
            let mut next = 0;
            for bin in 0..bm.bins().len() {
                if let Some((s, e, _)) = bm.bin_range(bin) {
                    assert_eq!(s, next);
                    next = e;
                }
            }
            assert_eq!(next, texels);
        }
    }
}

/// Walks one tree from the definition of the layout (root region = map, larger side split at the
/// middle) and checks every node's range; returns the number of internal nodes visited.
#[allow(clippy::too_many_arguments)]
fn walk(
    bm: &BinMap,
    node: Option<usize>,
    start: usize,
    end: usize,
    region: [u32; 4],
    leaf: usize,
    visited: &mut Vec<bool>,
) -> usize {
    let inv = bm.inverse_bin_map();
    let w = bm.grid_size().0 as u32;
    for &k in &inv[start..end] {
        let (i, j) = (k % w, k / w);
        assert!(i >= region[0] && i < region[2] && j >= region[1] && j < region[3]);
    }
    if end - start <= leaf {
        assert!(node.is_none(), "a leaf-sized range has a stored node");
        return 0;
    }
    let node = node.expect("a range longer than L needs a node");
    assert!(!visited[node / 2], "node visited twice");
    visited[node / 2] = true;
    let f = bm.forest();
    let (mid, right) = (f[node] as usize, f[node + 1] as usize);
    assert!(start <= mid && mid <= end);
    let [x0, y0, x1, y1] = region;
    let (lr, rr) = if x1 - x0 >= y1 - y0 {
        let m = x0 + (x1 - x0) / 2;
        ([x0, y0, m, y1], [m, y0, x1, y1])
    } else {
        let m = y0 + (y1 - y0) / 2;
        ([x0, y0, x1, m], [x0, m, x1, y1])
    };
    let left_node = (mid - start > leaf).then_some(node + 2);
    let right_node = (end - mid > leaf).then_some(right);
    1 + walk(bm, left_node, start, mid, lr, leaf, visited)
        + walk(bm, right_node, mid, end, rr, leaf, visited)
}

#[test]
fn forest_node_ranges_are_consistent() {
    for (name, map) in test_maps() {
        for (n, leaf, sub) in [(7, 1, 1), (15, 4, 2), (127, 16, 1)] {
            let p = BinMapParams {
                subdivisions: sub,
                ..params(n, leaf, BinLookup::Dense)
            };
            let bm = BinMap::build(&map, p).unwrap();
            let (gw, gh) = bm.grid_size();
            let mut visited = vec![false; bm.forest().len() / 2];
            let mut internal = 0;
            for bin in 0..bm.bins().len() {
                if let Some((s, e, root)) = bm.bin_range(bin) {
                    assert_eq!(root.is_some(), e - s > leaf, "{name}: tree iff list > L");
                    let region = [0, 0, gw as u32, gh as u32];
                    internal += walk(&bm, root, s, e, region, leaf, &mut visited);
                }
            }
            assert_eq!(internal * 2, bm.forest().len(), "{name} n={n}");
            assert!(visited.iter().all(|&v| v), "{name} n={n}: unreachable node");
        }
    }
}

/// Σ_j Σ_k I_j(t_k)|A ∩ T_k| over all bins.
fn total_overlap(patch: &BinMapPatch, bins: usize) -> f64 {
    (0..bins).map(|b| patch.bin_overlap_with_stats(b).0).sum()
}

proptest! {
    #![proptest_config(support::proptest_config(64))]

    /// Σ overlap areas = |A| for random footprints: sub-texel to twice the map, any aspect (up to
    /// the footprint's clamp) and angle, anywhere (so many cross the border).
    #[test]
    fn overlaps_sum_to_the_footprint_area(
        cx in 0.0f32..1.0, cy in 0.0f32..1.0,
        log_area in -3.0f32..3.6, aspect in 1.0f32..40.0, angle in 0.0f32..6.3,
    ) {
        let map = noise(48, 40, 0.5, 9);
        let bm = BinMap::build(&map, params(9, 4, BinLookup::Hash)).unwrap();
        let fp = Footprint::anisotropic_texels(
            Vec2::new(cx, cy), 10f32.powf(log_area), aspect, angle, 48, 40);
        let area = fp.area_texels(48, 40) as f64;
        let patch = bm.patch(&fp);
        let sum = total_overlap(&patch, bm.bins().len());
        // Independent: |A| from the footprint's own widths. f64 sums of ≤ 10⁴ clipped areas
        // (each exact to ~1e-13 texel²) plus the f32 widths (6e-8 relative): 1e-6 relative.
        prop_assert!((sum - area).abs() <= 1e-6 * area + 1e-9, "{} vs {}", sum, area);
        prop_assert!((patch.area_texels() - area).abs() <= 1e-6 * area);
    }
}

#[test]
fn axis_aligned_footprints_match_interval_products() {
    // An axis-aligned rectangle's overlap with texel (i, j) is the product of the interval overlaps;
    // summed over every periodic image here, independently of the bin map's clipping and forest.
    let map = noise(48, 40, 0.5, 9);
    let (w, h) = (48usize, 40usize);
    for (n, leaf) in [(7, 1), (15, 16)] {
        let bm = BinMap::build(&map, params(n, leaf, BinLookup::Dense)).unwrap();
        for (c, sx, sy) in [
            (Vec2::new(0.5, 0.5), 3.3, 2.7),
            (Vec2::new(0.01, 0.98), 7.5, 4.25), // crosses two borders
            (Vec2::new(0.3, 0.6), 61.0, 47.5),  // larger than the map
            (Vec2::new(0.77, 0.2), 0.3, 0.45),  // sub-texel
        ] {
            let fp = Footprint::from_differentials(
                c,
                Vec2::new(sx / w as f32, 0.0),
                Vec2::new(0.0, sy / h as f32),
            );
            let (cc, a, b) = fp.parallelogram_texels(w, h);
            let (cx, cy, ax, by) = (cc.x as f64, cc.y as f64, a.x as f64, b.y as f64);
            let (x0, x1) = (cx - 0.5 * ax, cx + 0.5 * ax);
            let (y0, y1) = (cy - 0.5 * by, cy + 0.5 * by);
            let ov = |lo: f64, hi: f64, t: f64| (hi.min(t + 1.0) - lo.max(t)).max(0.0);
            let mut expected = vec![0.0f64; bm.bins().len()];
            for ti in (x0.floor() as i64)..=(x1.floor() as i64) {
                for tj in (y0.floor() as i64)..=(y1.floor() as i64) {
                    let k = tj.rem_euclid(h as i64) as usize * w + ti.rem_euclid(w as i64) as usize;
                    expected[expected_bin(&map, bm.bins(), 1, k)] +=
                        ov(x0, x1, ti as f64) * ov(y0, y1, tj as f64);
                }
            }
            let patch = bm.patch(&fp);
            for (bin, &e) in expected.iter().enumerate() {
                let got = patch.bin_overlap_with_stats(bin).0;
                // f64 rounding of ≤ 3000 products of interval lengths: 1e-9 texel².
                assert!((got - e).abs() < 1e-9, "n={n} {c} bin {bin}: {got} vs {e}");
            }
        }
    }
}

#[test]
fn rotated_footprint_masses_match_point_sampling() {
    // Bin masses of rotated footprints against an m × m jittered stratification of the
    // parallelogram, each point binned through its texel's normal (computed here).
    // With s = 2 the points are binned through their sub-texel's interpolated normal.
    let map = noise(48, 40, 0.5, 9);
    let (w, h) = (48usize, 40usize);
    let mut rng = support::rng(3);
    for (c, area, aspect, angle, sub) in [
        (Vec2::new(0.5, 0.5), 30.0, 3.0, 0.7, 1),
        (Vec2::new(0.97, 0.03), 400.0, 8.0, 2.1, 1),
        (Vec2::new(0.2, 0.4), 5000.0, 1.5, 0.4, 1),
        (Vec2::new(0.97, 0.03), 400.0, 8.0, 2.1, 2),
    ] {
        let p = BinMapParams {
            subdivisions: sub,
            ..params(9, 4, BinLookup::Dense)
        };
        let bm = BinMap::build(&map, p).unwrap();
        let (gw, gh) = ((w * sub) as i64, (h * sub) as i64);
        let fp = Footprint::anisotropic_texels(c, area, aspect, angle, w, h);
        let (cc, a, b) = fp.parallelogram_texels(w, h);
        let m = 1000;
        let mut counts = vec![0.0f64; bm.bins().len()];
        for r in 0..m {
            for q in 0..m {
                let s = (q as f32 + rng.random::<f32>()) / m as f32 - 0.5;
                let t = (r as f32 + rng.random::<f32>()) / m as f32 - 0.5;
                let p = (cc + s * a + t * b) * sub as f32;
                let k = (p.y.floor() as i64).rem_euclid(gh) as usize * gw as usize
                    + (p.x.floor() as i64).rem_euclid(gw) as usize;
                counts[expected_bin(&map, bm.bins(), sub, k)] += 1.0;
            }
        }
        let patch = bm.patch(&fp);
        let n = (m * m) as f64;
        for (bin, &cnt) in counts.iter().enumerate() {
            let p = cnt / n;
            let got = patch.bin_mass(bin);
            // Jittered stratification has at most the binomial variance p(1 − p)/N: 5 standard
            // errors, plus 1e-6 for f32 point coordinates.
            let tol = 5.0 * (p * (1.0 - p) / n).sqrt() + 1e-6;
            assert!(
                (got - p).abs() <= tol,
                "{c} bin {bin}: {got} vs {p} ± {tol}"
            );
        }
    }
}

/// A patch with exact masking terms reads mass_j from the footprint's listed bins: equal to the
/// bin's forest query (the same overlaps summed in another order) for every bin, on footprints from
/// sub-texel to larger than the map, crossing the map's borders, at s = 1 and 2; and the listed
/// masses sum to 1. A patch without them returns the forest query itself, also when it is kept.
#[test]
fn listed_bin_masses_equal_the_forest_queries() {
    use brdf::glint::binmap::PatchOptions;
    let map = noise(48, 40, 0.5, 9);
    let (w, h) = (48usize, 40usize);
    let exact = PatchOptions {
        exact_masking_texels: f32::INFINITY,
        moment_masking_tolerance: 0.0,
        ..PatchOptions::default()
    };
    for sub in [1, 2] {
        let p = BinMapParams {
            subdivisions: sub,
            ..params(9, 4, BinLookup::Dense)
        };
        let bm = BinMap::build(&map, p).unwrap();
        for (c, area, aspect, angle) in [
            (Vec2::new(0.5, 0.5), 0.3, 1.0, 0.0),
            (Vec2::new(0.31, 0.72), 2.5, 2.0, 0.9),
            (Vec2::new(0.97, 0.03), 40.0, 8.0, 2.1),
            (Vec2::new(0.2, 0.4), 3000.0, 1.5, 0.4),
        ] {
            let fp = Footprint::anisotropic_texels(c, area, aspect, angle, w, h);
            let patch = bm.patch_with(&fp, &exact, None);
            let sub_area = patch.area_texels() * (sub * sub) as f64;
            let mut total = 0.0;
            for bin in 0..bm.bins().len() {
                let listed = patch.bin_mass(bin);
                let forest = patch.bin_overlap_with_stats(bin).0 / sub_area;
                total += listed;
                // f64 rounding of up to ~10⁴ overlaps summed in two orders: 1e-12.
                assert!(
                    (listed - forest).abs() < 1e-12,
                    "s={sub} {c} area {area} bin {bin}: {listed} vs {forest}"
                );
            }
            assert!(
                (total - 1.0).abs() < 1e-9,
                "s={sub} {c} area {area}: Σ {total}"
            );
            // Without exact terms (the moment lobe's masking, from 128 texels) every bin's mass is
            // its forest query, the same when asked again (kept) and after another bin.
            if area < 128.0 {
                continue;
            }
            let lobe = PatchOptions {
                exact_masking_texels: 0.0,
                ..exact
            };
            let patch = bm.patch_with(&fp, &lobe, None);
            for bin in 0..bm.bins().len() {
                let forest = patch.bin_overlap_with_stats(bin).0 / sub_area;
                let first = patch.bin_mass(bin);
                let again = patch.bin_mass(bin);
                let other = patch.bin_mass((bin + 1) % bm.bins().len());
                assert!(
                    (first - forest).abs() < 1e-12 && again == first && other >= 0.0,
                    "s={sub} {c} area {area} bin {bin}: {first}, {again} vs {forest}"
                );
            }
        }
    }
}
