//! Unit tests of the forest's walk: its area against the exact overlaps summed texel by texel, and
//! its visits against a walk that classifies every node by [`Parallelogram::classify`].

use super::*;

/// xorshift64 in [0, 1).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A walk written directly on [`Parallelogram::classify`] and [`Parallelogram::overlap_area`],
/// recursive, in f64 throughout: the reference for the visits and the area.
fn reference(
    view: &TreeView,
    p: &Parallelogram,
    (start, end, node): (usize, usize, u32),
    r: Region,
    stats: &mut QueryStats,
) -> f64 {
    stats.nodes += 1;
    let (x0, y0, x1, y1) = (r.x0 as f64, r.y0 as f64, r.x1 as f64, r.y1 as f64);
    match p.classify(x0, y0, x1, y1) {
        Overlap::Outside => 0.0,
        Overlap::Inside => (end - start) as f64,
        Overlap::Partial if node != NO_TREE => {
            let n = node as usize;
            let (mid, right) = (view.nodes[n] as usize, view.nodes[n + 1]);
            let (lr, rr) = r.children();
            let left = if mid - start > view.leaf {
                node + 2
            } else {
                NO_TREE
            };
            let right = if end - mid > view.leaf {
                right
            } else {
                NO_TREE
            };
            reference(view, p, (start, mid, left), lr, stats)
                + reference(view, p, (mid, end, right), rr, stats)
        }
        Overlap::Partial => {
            let mut sum = 0.0;
            for &k in &view.inverse[start..end] {
                let (i, j) = ((k % view.width) as f64, (k / view.width) as f64);
                stats.texels += 1;
                sum += match p.classify(i, j, i + 1.0, j + 1.0) {
                    Overlap::Outside => 0.0,
                    Overlap::Inside => 1.0,
                    Overlap::Partial => {
                        stats.clipped += 1;
                        p.overlap_area(i, j, i + 1.0, j + 1.0)
                    }
                };
            }
            sum
        }
    }
}

/// Random footprints over and around a `width` × `height` map: rotated, sheared, thin (to 1:100),
/// from a tenth of a texel to larger than the map, some crossing its border; every fifth one
/// axis-aligned with its edges on integer coordinates (rectangles touching its sides).
fn footprints(rng: &mut Rng, n: usize, width: f64, height: f64) -> Vec<(Parallelogram, bool)> {
    (0..n)
        .filter_map(|k| {
            let c = [
                width * (1.2 * rng.unit() - 0.1),
                height * (1.2 * rng.unit() - 0.1),
            ];
            if k % 5 == 0 {
                let (a, b) = (
                    (1.0 + 20.0 * rng.unit()).round(),
                    (1.0 + 20.0 * rng.unit()).round(),
                );
                let c = [c[0].round() + 0.5 * a, c[1].round() + 0.5 * b];
                return Parallelogram::new(c, [a, 0.0], [0.0, b]).map(|p| (p, true));
            }
            let r = 0.1 * (1500.0f64).powf(rng.unit());
            let ang = std::f64::consts::TAU * rng.unit();
            let q = r * (0.01 + rng.unit());
            let skew = 0.2 + 2.7 * rng.unit();
            let (a, b) = (
                [r * ang.cos(), r * ang.sin()],
                [q * (ang + skew).cos(), q * (ang + skew).sin()],
            );
            Parallelogram::new(c, a, b).map(|p| (p, false))
        })
        .collect()
}

/// Three lists on a 61 × 47 map (sparse, dense, and one of at most a leaf: no tree), packed one
/// after the other as in the inverse map, leaf size 4. On 3000 random footprints the walk's area
/// equals Σ_k |P ∩ T_k| over the list's texels to 1e-9 relative (sums of ≤ 2867 terms ≤ 1 in
/// f64), and the reference walk's to the same tolerance; on the footprints in general position
/// (not touching texel edges) it visits the same nodes and texels and clips the same texels.
#[test]
fn walk_matches_the_exact_sum_and_the_reference_walk() {
    let (width, height, leaf) = (61u32, 47u32, 4);
    let mut rng = Rng(0x0F0E_57C0_5700_0001);
    let mut inverse = Vec::new();
    let mut lists = Vec::new();
    let mut nodes = Vec::new();
    for density in [0.05, 0.6, 0.001] {
        let mut list: Vec<u32> = (0..width * height)
            .filter(|_| rng.unit() < density)
            .collect();
        if density < 0.01 {
            list.truncate(leaf);
        }
        let offset = inverse.len();
        let root = build_tree(
            &mut list,
            offset,
            width as usize,
            height as usize,
            leaf,
            &mut nodes,
        );
        inverse.extend_from_slice(&list);
        lists.push((offset, inverse.len(), root));
    }
    assert!(lists[2].2 == NO_TREE && lists[1].1 - lists[1].0 > 1000);
    let view = TreeView {
        inverse: &inverse,
        nodes: &nodes,
        width,
        height,
        leaf,
    };
    let whole = Region {
        x0: 0,
        y0: 0,
        x1: width,
        y1: height,
    };
    let mut same_visits = 0;
    for (p, on_edges) in footprints(&mut rng, 3000, width as f64, height as f64) {
        for &(start, end, root) in &lists {
            let mut stats = QueryStats::default();
            let got = view.area(&p, start, end, root, &mut stats);
            let exact: f64 = inverse[start..end]
                .iter()
                .map(|&k| {
                    let (i, j) = ((k % width) as f64, (k / width) as f64);
                    p.overlap_area(i, j, i + 1.0, j + 1.0)
                })
                .sum();
            let mut want_stats = QueryStats::default();
            let want = reference(&view, &p, (start, end, root), whole, &mut want_stats);
            let tol = 1e-9 * exact.max(1.0);
            assert!((got - exact).abs() <= tol, "{p:?}: {got} vs Σ {exact}");
            assert!((got - want).abs() <= tol, "{p:?}: {got} vs {want}");
            if !on_edges {
                assert_eq!(stats, want_stats, "{p:?}");
                same_visits += 1;
            }
        }
    }
    assert!(same_visits > 6000, "{same_visits}");
}
