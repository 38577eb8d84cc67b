//! Unit tests of the footprint parallelogram: overlaps against products, a slab integration and
//! the clip, the one-edge closed form at its limits, the row bounds against the classification.

use super::*;

#[test]
fn axis_aligned_rectangle_overlaps_are_products() {
    // A rectangle [0.3, 2.8] × [−0.4, 0.7]: the overlap with a texel is the product of the
    // interval overlaps.
    let p = Parallelogram::new([1.55, 0.15], [2.5, 0.0], [0.0, 1.1]).unwrap();
    let ov = |a0: f64, a1: f64, b0: f64| (a1.min(b0 + 1.0) - a0.max(b0)).max(0.0);
    for j in -2..3 {
        for i in -1..4 {
            let expected = ov(0.3, 2.8, i as f64) * ov(-0.4, 0.7, j as f64);
            let got = p.texel_overlap(i as f64, j as f64);
            // f64 rounding of a handful of products: 1e-12.
            assert!(
                (got - expected).abs() < 1e-12,
                "({i}, {j}): {got} vs {expected}"
            );
        }
    }
}

#[test]
fn diamond_in_a_texel() {
    // A square rotated by 45° centred on the texel centre, half-diagonal d: for d ≤ ½ it lies
    // inside (area 2d²); for ½ < d < 1 the four corners sticking out are triangles of area
    // (d − ½)², so the overlap is 2d² − 4(d − ½)².
    for d in [0.2f64, 0.5, 0.6, 0.9] {
        let p = Parallelogram::new([0.5, 0.5], [d, d], [-d, d]).unwrap();
        let expected = if d <= 0.5 {
            2.0 * d * d
        } else {
            2.0 * d * d - 4.0 * (d - 0.5).powi(2)
        };
        let got = p.texel_overlap(0.0, 0.0);
        assert!(
            (got - expected).abs() < 1e-12,
            "d = {d}: {got} vs {expected}"
        );
    }
}

#[test]
fn classification_agrees_with_clipping() {
    let p = Parallelogram::new([0.3, -0.2], [3.1, 1.2], [-0.7, 2.3]).unwrap();
    for j in -4..4 {
        for i in -4..4 {
            let (x, y) = (i as f64, j as f64);
            let area = p.clipped_area(x, y, x + 1.0, y + 1.0);
            match p.classify(x, y, x + 1.0, y + 1.0) {
                Overlap::Outside => assert!(area < 1e-12, "{i} {j}: {area}"),
                Overlap::Inside => assert!((area - 1.0).abs() < 1e-12, "{i} {j}: {area}"),
                Overlap::Partial => assert!(area > -1e-12 && area < 1.0 + 1e-12),
            }
        }
    }
}

/// The vertical extent [y_min, y_max] of the parallelogram's section at abscissa x, if any.
fn section(p: &Parallelogram, x: f64) -> Option<(f64, f64)> {
    let v = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)].map(|(s, t)| p.point(s, t));
    let mut ys = Vec::new();
    for k in 0..4 {
        let (a, b) = (v[k], v[(k + 1) % 4]);
        let (lo, hi) = (a[0].min(b[0]), a[0].max(b[0]));
        if x >= lo && x <= hi && hi > lo {
            ys.push(a[1] + (x - a[0]) / (b[0] - a[0]) * (b[1] - a[1]));
        }
    }
    let lo = ys.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// The overlap area by integrating the section's length inside [y0, y1] over x ∈ [x0, x1]: the
/// length is linear between the breakpoints (the vertices' abscissas and those where an edge
/// crosses y0 or y1), so the trapezoid rule on each piece is exact.
fn slab_area(p: &Parallelogram, [x0, y0, x1, y1]: [f64; 4]) -> f64 {
    let v = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)].map(|(s, t)| p.point(s, t));
    let mut xs = vec![x0, x1];
    for k in 0..4 {
        let (a, b) = (v[k], v[(k + 1) % 4]);
        xs.push(a[0]);
        for y in [y0, y1] {
            if (a[1] - y) * (b[1] - y) < 0.0 {
                xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
            }
        }
    }
    let mut xs: Vec<f64> = xs.into_iter().filter(|&x| x >= x0 && x <= x1).collect();
    xs.sort_by(f64::total_cmp);
    let len = |x: f64| section(p, x).map_or(0.0, |(lo, hi)| (hi.min(y1) - lo.max(y0)).max(0.0));
    xs.windows(2)
        .map(|w| 0.5 * (w[1] - w[0]) * (len(w[0]) + len(w[1])))
        .sum()
}

/// The clipped area against the slab integration, on random parallelograms (thin, rotated,
/// larger and smaller than a texel) and every texel around them: equal to 1e-9 texel².
#[test]
fn clipped_area_matches_slab_integration() {
    let mut z = 0x2545_F491_4F6C_DD1Du64;
    let mut unit = || {
        z ^= z << 13;
        z ^= z >> 7;
        z ^= z << 17;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..200 {
        let c = [4.0 * unit() - 2.0, 4.0 * unit() - 2.0];
        let (r, ang) = (0.2 + 3.0 * unit(), std::f64::consts::TAU * unit());
        let a = [r * ang.cos(), r * ang.sin()];
        let (q, skew) = (0.05 + 2.0 * unit(), 0.3 + 2.5 * unit());
        let b = [q * (ang + skew).cos(), q * (ang + skew).sin()];
        let Some(p) = Parallelogram::new(c, a, b) else {
            continue;
        };
        let (lo, hi) = p.bounds();
        for j in (lo[1].floor() as i64 - 1)..=(hi[1].ceil() as i64) {
            for i in (lo[0].floor() as i64 - 1)..=(hi[0].ceil() as i64) {
                let (x, y) = (i as f64, j as f64);
                let got = p.clipped_area(x, y, x + 1.0, y + 1.0);
                let want = slab_area(&p, [x, y, x + 1.0, y + 1.0]);
                assert!(
                    (got - want).abs() < 1e-9,
                    "{c:?} {a:?} {b:?} ({i}, {j}): {got} vs {want}"
                );
            }
        }
    }
}

/// Random parallelograms for the tests below: rotated, sheared, thin (to 1:100) and smaller and
/// larger than a texel, with a few axis-aligned ones on half texels (edges along texel edges).
fn random_parallelograms(n: usize) -> Vec<Parallelogram> {
    let mut z = 0x0DDB_1A5E_5BAD_5EEDu64;
    let mut unit = || {
        z ^= z << 13;
        z ^= z >> 7;
        z ^= z << 17;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .filter_map(|k| {
            let c = [8.0 * unit() - 4.0, 8.0 * unit() - 4.0];
            if k % 5 == 0 {
                let snap = |v: f64| (2.0 * v).round() / 2.0;
                let (a, b) = (snap(0.5 + 4.0 * unit()), snap(0.5 + 4.0 * unit()));
                return Parallelogram::new([snap(c[0]), snap(c[1])], [a, 0.0], [0.0, b]);
            }
            let (r, ang) = (0.1 + 5.0 * unit(), std::f64::consts::TAU * unit());
            let q = r * (0.01 + unit());
            let skew = 0.2 + 2.7 * unit();
            Parallelogram::new(
                c,
                [r * ang.cos(), r * ang.sin()],
                [q * (ang + skew).cos(), q * (ang + skew).sin()],
            )
        })
        .collect()
}

/// The overlap with one edge's closed form (or the clip where two edges cross) against the clip
/// alone, on unit texels and on 0.5 × 2 and 3 × 1.5 rectangles around 500 random
/// parallelograms: equal to 1e-12 texel² (rounding of a few operations on coordinates ≤ 10).
#[test]
fn overlap_area_matches_the_clip() {
    for p in random_parallelograms(500) {
        let (lo, hi) = p.bounds();
        for (w, h) in [(1.0, 1.0), (0.5, 2.0), (3.0, 1.5)] {
            let (mut y, mut n) = (lo[1] - h, 0);
            while y <= hi[1] {
                let mut x = lo[0] - w;
                while x <= hi[0] {
                    let (x0, y0) = (x.floor(), y.floor());
                    let got = p.overlap_area(x0, y0, x0 + w, y0 + h);
                    let want = match p.classify(x0, y0, x0 + w, y0 + h) {
                        Overlap::Outside => 0.0,
                        Overlap::Inside => w * h,
                        Overlap::Partial => p.clipped_area(x0, y0, x0 + w, y0 + h),
                    };
                    assert!(
                        (got - want).abs() < 1e-12,
                        "{p:?} [{x0}, {y0}] {w} × {h}: {got} vs {want}"
                    );
                    x += w;
                    n += 1;
                }
                y += h;
            }
            assert!(n > 0);
        }
    }
}

/// The one-edge fraction at its limits: axis-aligned lines (v = 0, and v at 1e-15 of u), the
/// diagonal, and lines missing the square.
#[test]
fn half_plane_fraction_at_its_limits() {
    for e in [-0.5, 0.0, 0.25, 0.7, 1.0, 1.5] {
        let want = f64::clamp(e, 0.0, 1.0);
        assert_eq!(half_plane_fraction(1.0, 0.0, e), want);
        assert_eq!(half_plane_fraction(0.0, 1.0, e), want);
        assert!((half_plane_fraction(1.0, 1e-15, e) - want).abs() < 1e-14);
    }
    // u = v = 1: the triangle ξ + η ≤ e has e²/2 for e ≤ 1, 1 − (2 − e)²/2 above.
    for e in [0.3f64, 1.0, 1.6] {
        let want = if e <= 1.0 {
            0.5 * e * e
        } else {
            1.0 - 0.5 * (2.0 - e).powi(2)
        };
        assert!((half_plane_fraction(1.0, 1.0, e) - want).abs() < 1e-15);
    }
    assert_eq!(half_plane_fraction(2.0, 1.0, -0.1), 0.0);
    assert_eq!(half_plane_fraction(2.0, 1.0, 3.1), 1.0);
}

/// The row bounds against the separating-axis test of every texel of each row of 500 random
/// parallelograms: a texel the test keeps lies within the meeting bounds, a texel within the
/// inside bounds is inside (1e-9 texel of slack for the bounds' rounding).
#[test]
fn row_bounds_agree_with_the_classification() {
    let eps = 1e-9;
    for p in random_parallelograms(500) {
        let (lo, hi) = p.bounds();
        for j in (lo[1].floor() as i64)..(hi[1].ceil() as i64) {
            let (y0, y1) = (j as f64, j as f64 + 1.0);
            let (meet, inside) = p.row_bounds(y0, y1);
            for i in (lo[0].floor() as i64 - 1)..=(hi[0].ceil() as i64) {
                let x = i as f64;
                let class = p.classify(x, y0, x + 1.0, y1);
                if class != Overlap::Outside {
                    assert!(
                        meet[0] - 1.0 - eps < x && x < meet[1] + eps,
                        "{p:?} ({i}, {j})"
                    );
                }
                if inside[0] + eps <= x && x + 1.0 <= inside[1] - eps {
                    assert_eq!(class, Overlap::Inside, "{p:?} ({i}, {j})");
                }
            }
        }
    }
}

#[test]
fn degenerate_edges_are_rejected() {
    assert!(Parallelogram::new([0.0, 0.0], [1.0, 1.0], [2.0, 2.0]).is_none());
    assert!(Parallelogram::new([0.0, 0.0], [f64::NAN, 1.0], [0.0, 1.0]).is_none());
    assert!(Parallelogram::new([0.0, 0.0], [0.0, 0.0], [0.0, 1.0]).is_none());
}

/// A classification against the exact area: `Outside` only with area 0 and `Inside` only with the
/// whole rectangle, to `tol` texel² (the rounding of the coordinates of a rectangle touching P).
fn agrees_with_area(class: Overlap, area: f64, whole: f64, tol: f64) -> bool {
    match class {
        Overlap::Outside => area <= tol,
        Overlap::Inside => area >= whole - tol,
        Overlap::Partial => true,
    }
}

/// The walk's tests against [`Parallelogram::classify`] on the random parallelograms (rotated,
/// thin, smaller than a texel) at three scales up to 100 texels, moved onto integer coordinates
/// ≥ 0 and to the edge of the first row and column (a periodic image cut by the map's border),
/// for unit texels and for integer rectangles from 1 × 1 to a few times the parallelogram's size
/// around it. Where the two decide differently, the rectangle touches P's boundary: the exact area
/// must then agree with both decisions to 1e-9 of the rectangle's area (the coordinates are
/// ≤ 2000; the tests' rounding is ~1e-13 texels there).
#[test]
fn axis_tests_agree_with_classify() {
    let mut z = 0x5EED_F0E5_7000_0001u64;
    let mut next = |n: u32| {
        z ^= z << 13;
        z ^= z >> 7;
        z ^= z << 17;
        ((z >> 33) % n as u64) as u32
    };
    let (mut differ, mut rects) = (0, 0);
    for (k, p0) in random_parallelograms(1500).into_iter().enumerate() {
        let scale = [1.0, 7.5, 25.0][k % 3];
        let Some(p) = p0.scaled(scale, scale) else {
            continue;
        };
        let (lo, hi) = p.bounds();
        let shift = if k % 7 == 0 {
            [-lo[0] - 0.5 * (hi[0] - lo[0]), -lo[1]]
        } else {
            [1000.0 + 0.37 * k as f64 - lo[0], 900.0 - lo[1]]
        };
        let p = p.translated(shift);
        let tests = AxisTests::new(&p);
        let (lo, hi) = p.bounds();
        let (span_x, span_y) = (
            (hi[0] - lo[0]).ceil() as u32 + 2,
            (hi[1] - lo[1]).ceil() as u32 + 2,
        );
        let (bx, by) = (
            (lo[0].floor() - 1.0).max(0.0) as u32,
            (lo[1].floor() - 1.0).max(0.0) as u32,
        );
        for _ in 0..60 {
            let (i, j) = (bx + next(span_x + 1), by + next(span_y + 1));
            let (x, y) = (i as f64, j as f64);
            let (old, new) = (p.classify(x, y, x + 1.0, y + 1.0), tests.texel(i, j));
            if old != new {
                differ += 1;
                let area = p.overlap_area(x, y, x + 1.0, y + 1.0);
                assert!(
                    agrees_with_area(old, area, 1.0, 1e-9)
                        && agrees_with_area(new, area, 1.0, 1e-9),
                    "{p:?} texel ({i}, {j}): {old:?} vs {new:?}, area {area}"
                );
            }
            let (w, h) = (1 + next(2 * span_x), 1 + next(2 * span_y));
            let (x0, y0) = (bx + next(span_x + 1), by + next(span_y + 1));
            let (x1, y1) = (x0 + w, y0 + h);
            let (fx0, fy0, fx1, fy1) = (x0 as f64, y0 as f64, x1 as f64, y1 as f64);
            let (old, new) = (p.classify(fx0, fy0, fx1, fy1), tests.rect(x0, y0, x1, y1));
            rects += 1;
            if old != new {
                differ += 1;
                let (area, whole) = (p.overlap_area(fx0, fy0, fx1, fy1), (w * h) as f64);
                assert!(
                    agrees_with_area(old, area, whole, 1e-9 * whole)
                        && agrees_with_area(new, area, whole, 1e-9 * whole),
                    "{p:?} [{x0}, {x1}] × [{y0}, {y1}]: {old:?} vs {new:?}, area {area}"
                );
            }
        }
    }
    assert!(rects > 50_000, "{rects} rectangles");
    // Decisions differ only on rectangles touching P, which random parallelograms rarely do.
    assert!(differ < rects / 100, "{differ} of {rects} decisions differ");
}
