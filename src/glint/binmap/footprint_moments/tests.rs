//! Unit tests of the masking lobe's moments: the bins' moments, the chain, cell-aligned reads, and
//! the row-wise read against a separating-axis test and a clip per cell.

use super::*;
use glam::Vec2;

/// The bins' moments against a finer, independent rule: 64 × 64 points of each bin's
/// equal-area cell, for the pole bin, a bin halfway and one at θ ≈ 49° (the ring touching the horizon diverges).
#[test]
fn bin_moments_match_a_finer_quadrature() {
    let bins = HemisphereBins::new(15).unwrap();
    let picks = [
        bins.bin_of(glam::Vec3::Z).unwrap(),
        bins.bin_of(glam::Vec3::new(0.5, 0.3, 0.81).normalize())
            .unwrap(),
        bins.bin_of(glam::Vec3::new(0.75, 0.1, 0.65).normalize())
            .unwrap(),
    ];
    let used: Vec<bool> = (0..bins.len()).map(|b| picks.contains(&b)).collect();
    let table = bin_moments(&bins, &used);
    let g = 64;
    for &b in &picks {
        let mut sum = [0.0f64; 6];
        for k in 0..g * g {
            let m = bins.sample_in_bin(b, sub_cell(k, g));
            let (x, y, z) = (m.x as f64, m.y as f64, m.z as f64);
            let s = [-x / z, -y / z];
            let v = [s[0], s[1], s[0] * s[0], s[1] * s[1], s[0] * s[1]];
            for q in 0..5 {
                sum[q] += v[q] * z;
            }
            sum[5] += z;
        }
        for q in 0..5 {
            let fine = sum[q] / sum[5];
            let d = (table[b][q] - fine).abs();
            assert!(
                d <= 5e-3 * fine.abs().max(1e-2),
                "bin {b} moment {q}: {} vs {fine}",
                table[b][q]
            );
        }
    }
}

/// The chain of a bin map holds at level 1 the mean of each 2 × 2-texel cell's sub-texel bin
/// moments: a footprint of whole cells reads the mean over its sub-texels of their bins' moments,
/// summed here directly from 𝓑.
#[test]
fn the_chain_holds_the_sub_texels_bin_moments() {
    let n = 32;
    let map = crate::glint::bumpy(n, n, 0.25, 4.0, 2).unwrap();
    let bm = super::super::BinMap::build(&map, super::super::BinMapParams::default()).unwrap();
    let s = bm.params.subdivisions;
    let used = vec![true; bm.bins.len()];
    let table = bin_moments(&bm.bins, &used);
    // The axis-aligned 8 × 8-texel square at texels [8, 16) × [12, 20): whole level-1 cells.
    let p = Parallelogram::new([12.0, 16.0], [8.0, 0.0], [0.0, 8.0]).unwrap();
    let read = footprint_moments(&bm.moments, n, n, &p).unwrap();
    let mut want = [0.0f64; 5];
    let mut count = 0.0;
    for j in 12 * s..20 * s {
        for i in 8 * s..16 * s {
            let b = bm.bin_map.get(j * n * s + i).unwrap();
            for q in 0..5 {
                want[q] += table[b][q];
            }
            count += 1.0;
        }
    }
    for q in 0..5 {
        let w = want[q] / count;
        assert!(
            (read[q] as f64 - w).abs() <= 1e-5 * w.abs().max(1e-3),
            "{q}: {} vs {w}",
            read[q]
        );
    }
}

/// A footprint that covers whole cells of the chosen level reads exactly their mean: an
/// axis-aligned 8 × 8-texel square on a 32² map is read at level 2 (cells of 4 × 4 texels, 9
/// cells meet its bounding box), as the mean of its four cells; one shifted by half
/// a cell weights its nine cells by ¼, ½ and 1 (overlaps of 2 × 2, 2 × 4 and 4 × 4 texels).
#[test]
fn cell_aligned_footprints_read_their_cells() {
    let n = 32;
    let slopes: Vec<Vec2> = (0..n * n)
        .map(|k| Vec2::new((k % n) as f32 * 0.01, (k / n) as f32 * -0.02))
        .collect();
    let chain = MomentPyramid::build_from(n, n, &slopes, 2);
    let l = chain.level(0).unwrap();
    let cell = |i: usize, j: usize| l.data[j * l.width + i];
    let mean = |w: &[(usize, usize, f64)]| {
        let t: f64 = w.iter().map(|c| c.2).sum();
        std::array::from_fn::<f64, 5, _>(|k| {
            w.iter()
                .map(|&(i, j, x)| x * cell(i, j)[k] as f64)
                .sum::<f64>()
                / t
        })
    };
    let read = |c: [f64; 2]| {
        let p = Parallelogram::new(c, [8.0, 0.0], [0.0, 8.0]).unwrap();
        footprint_moments(&chain, n, n, &p).unwrap()
    };
    let aligned = read([8.0, 12.0]);
    let want = mean(&[(1, 2, 1.0), (2, 2, 1.0), (1, 3, 1.0), (2, 3, 1.0)]);
    let shifted = read([10.0, 14.0]);
    let mut w = vec![];
    for (j, wy) in [(2usize, 0.5), (3, 1.0), (4, 0.5)] {
        for (i, wx) in [(1usize, 0.5), (2, 1.0), (3, 0.5)] {
            w.push((i, j, wx * wy));
        }
    }
    let want_shifted = mean(&w);
    for k in 0..5 {
        // f32 storage of the result: 1e-6 relative.
        assert!((aligned[k] as f64 - want[k]).abs() <= 1e-6 * want[k].abs() + 1e-9);
        assert!((shifted[k] as f64 - want_shifted[k]).abs() <= 1e-6 * want_shifted[k].abs() + 1e-9);
    }
}

/// The read as a separating-axis test and a clip of every cell of the footprint's bounding box
/// ([`Parallelogram::classify`], [`Parallelogram::clipped_area`]): what [`overlap_mean`] computes
/// with its rows' spans.
fn overlap_mean_per_cell(l: &MomentLevel, p: &Parallelogram) -> Option<[f64; 5]> {
    use super::super::clip::Overlap;
    let (lo, hi) = p.bounds();
    let (i0, i1) = (lo[0].floor() as i64, hi[0].ceil() as i64);
    let (j0, j1) = (lo[1].floor() as i64, hi[1].ceil() as i64);
    let mut sum = [0.0f64; 5];
    let mut total = 0.0f64;
    for j in j0..j1 {
        for i in i0..i1 {
            let (x0, y0) = (i as f64, j as f64);
            let w = match p.classify(x0, y0, x0 + 1.0, y0 + 1.0) {
                Overlap::Outside => continue,
                Overlap::Inside => 1.0,
                Overlap::Partial => p.clipped_area(x0, y0, x0 + 1.0, y0 + 1.0),
            };
            if w <= 0.0 {
                continue;
            }
            let ii = i.rem_euclid(l.width as i64) as usize;
            let jj = j.rem_euclid(l.height as i64) as usize;
            let m = &l.data[jj * l.width + ii];
            for k in 0..5 {
                sum[k] += w * m[k] as f64;
            }
            total += w;
        }
    }
    (total > 0.0).then(|| sum.map(|v| v / total))
}

/// The row-wise read against the per-cell one on 4,000 random parallelograms on a 37 × 29 level of
/// random cells in [−1, 1] (a wrong or missing weight moves the mean by ~1/cells): isotropic, thin
/// (up to 200:1), rotated, sheared, smaller than a cell, larger than the level and wrapping across
/// its edges (centres in [−40, 80]), and axis-aligned ones on whole and half cells (edges along the
/// cells' own). Agreement to 1e-12 (f64 sums of at most a few thousand weights and the overlaps'
/// rounding, ~1e-15 each).
#[test]
fn the_row_spans_read_what_every_cell_reads() {
    let mut z = 0x9E37_79B9_7F4A_7C15u64;
    let mut unit = || {
        z ^= z << 13;
        z ^= z >> 7;
        z ^= z << 17;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    let (w, h) = (37, 29);
    let data: Vec<[f32; 5]> = (0..w * h)
        .map(|_| std::array::from_fn(|_| (2.0 * unit() - 1.0) as f32))
        .collect();
    let l = MomentLevel {
        width: w,
        height: h,
        data,
    };
    let mut read = 0;
    for k in 0..4000 {
        let c = [120.0 * unit() - 40.0, 120.0 * unit() - 40.0];
        let p = match k % 4 {
            // Axis-aligned on whole or half cells.
            0 => {
                let snap = |v: f64| (2.0 * v).round() / 2.0;
                let (a, b) = (snap(0.5 + 30.0 * unit()), snap(0.5 + 30.0 * unit()));
                Parallelogram::new([snap(c[0]), snap(c[1])], [a, 0.0], [0.0, b])
            }
            // Tiny: at most a cell across.
            1 => {
                let (r, ang) = (0.02 + unit(), std::f64::consts::TAU * unit());
                let (q, skew) = (0.02 + unit(), 0.2 + 2.7 * unit());
                Parallelogram::new(
                    c,
                    [r * ang.cos(), r * ang.sin()],
                    [q * (ang + skew).cos(), q * (ang + skew).sin()],
                )
            }
            // Thin: 20-200:1.
            2 => {
                let (r, ang) = (5.0 + 40.0 * unit(), std::f64::consts::TAU * unit());
                let q = r / (20.0 + 180.0 * unit());
                let skew = std::f64::consts::FRAC_PI_2 + 0.6 * (unit() - 0.5);
                Parallelogram::new(
                    c,
                    [r * ang.cos(), r * ang.sin()],
                    [q * (ang + skew).cos(), q * (ang + skew).sin()],
                )
            }
            // General: rotated and sheared, up to larger than the level.
            _ => {
                let (r, ang) = (0.5 + 60.0 * unit(), std::f64::consts::TAU * unit());
                let (q, skew) = (0.5 + 60.0 * unit(), 0.3 + 2.5 * unit());
                Parallelogram::new(
                    c,
                    [r * ang.cos(), r * ang.sin()],
                    [q * (ang + skew).cos(), q * (ang + skew).sin()],
                )
            }
        };
        let Some(p) = p else {
            continue;
        };
        let (got, want) = (overlap_mean(&l, &p), overlap_mean_per_cell(&l, &p));
        assert_eq!(got.is_some(), want.is_some(), "{p:?}");
        let (Some(got), Some(want)) = (got, want) else {
            continue;
        };
        for q in 0..5 {
            assert!(
                (got[q] - want[q]).abs() <= 1e-12,
                "{p:?} moment {q}: {} vs {}",
                got[q],
                want[q]
            );
        }
        read += 1;
    }
    assert!(read > 3900, "{read} parallelograms read");
}
