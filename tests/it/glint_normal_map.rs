//! Normal maps: the interpolated normal against an independent f64 bilinear blend (exact at texel
//! centres, continuous across texel and tile borders, total on non-finite positions), the
//! constructors (from heights, bad input), and the slope-moment mip chain.
//!
//! Expected values come from independent formulas written here, never from the code under test.
//! Each tolerance says where it comes from.

use crate::support;

use brdf::glint::{NormalMap, NormalRepair};
use brdf::{Error, Vec2, Vec3};
use rand::RngExt;
use support::noise_map as random_map;

/// The interpolated normal written independently in f64: bilinear blend of the four unit normals
/// whose sample centres (i + ½, j + ½) surround p, renormalised.
fn reference_normal(map: &NormalMap, p: [f64; 2]) -> [f64; 3] {
    let (w, h) = (map.width() as i64, map.height() as i64);
    let unit = |i: i64, j: i64| -> [f64; 3] {
        let s = map.slopes()[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
        let (x, y) = (-(s.x as f64), -(s.y as f64));
        let l = (x * x + y * y + 1.0).sqrt();
        [x / l, y / l, 1.0 / l]
    };
    let (qx, qy) = (p[0] - 0.5, p[1] - 0.5);
    let (i, j) = (qx.floor() as i64, qy.floor() as i64);
    let (fx, fy) = (qx - qx.floor(), qy - qy.floor());
    let mut b = [0.0; 3];
    for (di, dj, wgt) in [
        (0, 0, (1.0 - fx) * (1.0 - fy)),
        (1, 0, fx * (1.0 - fy)),
        (0, 1, (1.0 - fx) * fy),
        (1, 1, fx * fy),
    ] {
        let n = unit(i + di, j + dj);
        for k in 0..3 {
            b[k] += wgt * n[k];
        }
    }
    let l = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    [b[0] / l, b[1] / l, b[2] / l]
}

fn dist3(a: Vec3, b: [f64; 3]) -> f64 {
    ((a.x as f64 - b[0]).powi(2) + (a.y as f64 - b[1]).powi(2) + (a.z as f64 - b[2]).powi(2)).sqrt()
}

// ---------------------------------------------------------------------------------------------
// Normal maps: interpolation
// ---------------------------------------------------------------------------------------------

#[test]
fn interpolation_matches_an_independent_bilinear_blend() {
    let map = random_map(5, 3, 1.0, 1);
    let mut rng = support::rng(2);
    for _ in 0..2000 {
        // Positions over several tiles, negative ones included.
        let p = [
            rng.random_range(-12.0..12.0f64) as f32 as f64,
            rng.random_range(-7.0..7.0f64) as f32 as f64,
        ];
        let n = map.normal_at_texel(Vec2::new(p[0] as f32, p[1] as f32));
        // f32 arithmetic on O(1) values through a handful of operations: 1e-5 is ~100 ulps.
        assert!(dist3(n, reference_normal(&map, p)) < 1e-5, "at {p:?}");
        assert!((n.length() - 1.0).abs() < 1e-6);
        // uv and texel-space views agree.
        let uv = Vec2::new(p[0] as f32 / 5.0, p[1] as f32 / 3.0);
        assert!((map.normal_at(uv) - n).length() < 1e-5);
        // The slope is the slope of the normal.
        let s = map.slope_at_texel(Vec2::new(p[0] as f32, p[1] as f32));
        assert!((s - Vec2::new(-n.x / n.z, -n.y / n.z)).length() < 1e-4 * (1.0 + s.length()));
    }
}

#[test]
fn interpolation_is_exact_at_texel_centres() {
    let map = random_map(4, 7, 2.0, 3);
    for j in 0..7i64 {
        for i in 0..4i64 {
            let s = map.slope_at_texel(Vec2::new(i as f32 + 0.5, j as f32 + 0.5));
            let t = map.texel_slope(i, j);
            // Slope → normal → slope in f32: a few ulps of slopes of magnitude ≤ 2.9.
            assert!((s - t).length() < 2e-6 * (1.0 + t.length()), "{s} vs {t}");
            // Also at the same centre one tile away in each direction.
            let s2 = map.slope_at_texel(Vec2::new(i as f32 + 0.5 - 4.0, j as f32 + 0.5 + 7.0));
            assert!((s2 - t).length() < 2e-6 * (1.0 + t.length()));
        }
    }
}

#[test]
fn interpolation_is_continuous_across_texel_and_tile_borders() {
    let map = random_map(3, 2, 1.0, 4);
    let eps = 1e-3f32;
    // The normal field is Lipschitz: a step δ changes the blend by ≤ 2δ·max|n_a − n_b| ≤ 4δ and the
    // renormalisation by at most a factor 1/min|blend| ≤ 1/min z ≈ 1.7 (slopes ≤ √2 per texel): 7·2ε.
    let bound = 7.0 * 2.0 * eps;
    // The largest jump between two neighbouring texel normals, to show the bound is meaningful.
    let mut jump = 0.0f32;
    for j in 0..2 {
        for i in 0..3 {
            jump = jump.max((map.texel_normal(i, j) - map.texel_normal(i + 1, j)).length());
        }
    }
    assert!(jump > 10.0 * bound, "test map too smooth: {jump}");
    let mut rng = support::rng(5);
    for _ in 0..500 {
        let y = rng.random_range(0.0..2.0f32);
        // Vertical texel borders x = 0, 1, 2, 3 (x = 0 and 3 are tile borders) and the sample-centre lines.
        for x in [0.0f32, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
            let a = map.normal_at_texel(Vec2::new(x - eps, y));
            let b = map.normal_at_texel(Vec2::new(x + eps, y));
            assert!((a - b).length() < bound, "x = {x}, y = {y}: {a} vs {b}");
        }
        let x = rng.random_range(0.0..3.0f32);
        for y in [0.0f32, 1.0, 2.0] {
            let a = map.normal_at_texel(Vec2::new(x, y - eps));
            let b = map.normal_at_texel(Vec2::new(x, y + eps));
            assert!((a - b).length() < bound, "x = {x}, y = {y}");
        }
    }
    // Tiling: one tile away gives the same normal (up to the f32 rounding of p + size).
    for _ in 0..100 {
        let p = Vec2::new(rng.random_range(0.0..3.0f32), rng.random_range(0.0..2.0f32));
        let a = map.normal_at_texel(p);
        let b = map.normal_at_texel(p + Vec2::new(3.0, -2.0));
        assert!((a - b).length() < 1e-5);
    }
}

#[test]
fn non_finite_positions_do_not_produce_nan() {
    let map = random_map(2, 2, 1.0, 6);
    for p in [
        Vec2::new(f32::NAN, 0.3),
        Vec2::new(f32::INFINITY, f32::NEG_INFINITY),
        Vec2::new(1e30, -1e30),
    ] {
        assert!(map.normal_at_texel(p).is_finite());
        assert!(map.slope_at_texel(p).is_finite());
        assert!(map.normal_at(p).is_finite());
    }
}

#[test]
fn single_texel_map_is_flat() {
    let s = Vec2::new(0.3, -0.2);
    let map = NormalMap::from_slopes(1, 1, vec![s]).unwrap();
    for p in [Vec2::ZERO, Vec2::new(0.37, 0.91), Vec2::new(-5.2, 8.1)] {
        assert!((map.slope_at(p) - s).length() < 1e-6);
    }
}

// ---------------------------------------------------------------------------------------------
// Normal maps: constructors
// ---------------------------------------------------------------------------------------------

#[test]
fn from_heights_gives_the_gradient_of_a_tilted_plane() {
    // h = a x + b y (texel units). Central differences are exact on a plane away from the wrap seam.
    let (a, b, scale) = (0.3f32, -0.7f32, 2.0f32);
    let (w, h) = (8, 6);
    let heights: Vec<f32> = (0..w * h)
        .map(|k| a * (k % w) as f32 + b * (k / w) as f32)
        .collect();
    let map = NormalMap::from_heights(w, h, &heights, scale).unwrap();
    for j in 1..h as i64 - 1 {
        for i in 1..w as i64 - 1 {
            // The surface z = scale·h: its tangent vectors (1, 0, scale·a) and (0, 1, scale·b) must be
            // orthogonal to the normal (plane geometry, independent of the slope convention).
            let n = map.texel_normal(i, j);
            let tx = Vec3::new(1.0, 0.0, scale * a);
            let ty = Vec3::new(0.0, 1.0, scale * b);
            // Heights up to ~5 lose ~1e-6 in f32 differences: 1e-5 on O(1) dot products.
            assert!(n.dot(tx).abs() < 1e-5 && n.dot(ty).abs() < 1e-5, "{n}");
            assert!(n.z > 0.0);
            // The slope is the scaled gradient.
            let s = map.texel_slope(i, j);
            assert!((s - Vec2::new(scale * a, scale * b)).length() < 1e-5, "{s}");
        }
    }
    // The normal leans away from the uphill direction: uphill along +x means n.x < 0.
    assert!(map.texel_normal(3, 3).x < 0.0 && map.texel_normal(3, 3).y > 0.0);
    // Wrapping: on a periodic field h = sin(2π i / w) texel 0 uses h(w − 1) and h(1).
    let per: Vec<f32> = (0..w * h)
        .map(|k| (2.0 * std::f32::consts::PI * (k % w) as f32 / w as f32).sin())
        .collect();
    let map = NormalMap::from_heights(w, h, &per, 1.0).unwrap();
    let expected = 0.5 * ((2.0 * std::f64::consts::PI / w as f64).sin() * 2.0);
    assert!((map.texel_slope(0, 2).x as f64 - expected).abs() < 1e-6);
    assert_eq!(map.texel_slope(0, 2).y, 0.0);
}

#[test]
fn constructors_reject_bad_input() {
    assert!(matches!(
        NormalMap::from_heights(2, 2, &[0.0; 3], 1.0),
        Err(Error::InvalidSize { .. })
    ));
    assert!(matches!(
        NormalMap::from_heights(2, 2, &[0.0, 1.0, f32::NAN, 0.0], 1.0),
        Err(Error::InvalidTexel { x: 0, y: 1, .. })
    ));
    assert!(NormalMap::from_heights(2, 2, &[0.0; 4], f32::INFINITY).is_err());
    // A huge height step gives a slope above MAX_SLOPE.
    assert!(NormalMap::from_heights(3, 1, &[0.0, 0.0, 1e6], 1.0).is_err());
    assert!(NormalMap::from_slopes(1, 1, vec![Vec2::new(2e4, 0.0)]).is_err());
    assert!(matches!(
        NormalMap::from_normals(
            2,
            1,
            &[Vec3::Z, Vec3::new(0.0, 0.0, -1.0)],
            NormalRepair::Reject
        ),
        Err(Error::InvalidTexel { x: 1, y: 0, .. })
    ));
    assert!(
        NormalMap::from_normals(
            1,
            1,
            &[Vec3::new(0.0, f32::NAN, 1.0)],
            NormalRepair::ClampZ(0.1)
        )
        .is_err()
    );
    assert!(NormalMap::from_normals(0, 0, &[], NormalRepair::Reject).is_err());
}

// ---------------------------------------------------------------------------------------------
// Normal maps: slope-moment mip chain
// ---------------------------------------------------------------------------------------------

#[test]
fn moment_levels_preserve_the_map_average() {
    for (w, h) in [(8, 8), (5, 3), (7, 1), (1, 6)] {
        let map = random_map(w, h, 1.5, 20 + w as u64);
        // Independent f64 average of the five moments over all texels.
        let mut mean = [0.0f64; 5];
        for s in map.slopes() {
            let (x, y) = (s.x as f64, s.y as f64);
            for (m, v) in mean.iter_mut().zip([x, y, x * x, y * y, x * y]) {
                *m += v / (w * h) as f64;
            }
        }
        let pyramid = map.moment_pyramid();
        assert_eq!(pyramid.levels(), map.levels());
        let l0 = pyramid.level(0).unwrap();
        assert_eq!(l0.len(), w * h);
        let s = map.slopes()[1 % (w * h)];
        assert_eq!(l0[1 % (w * h)], [s.x, s.y, s.x * s.x, s.y * s.y, s.x * s.y]);
        assert_eq!(map.level_size(map.levels() - 1), Some((1, 1)));
        assert_eq!(map.level_size(map.levels()), None);
        assert_eq!(pyramid.level(map.levels()), None);
        for l in 0..map.levels() {
            let (lw, lh) = map.level_size(l).unwrap();
            let data = pyramid.level(l).unwrap();
            assert_eq!(data.len(), lw * lh);
            // Every level is an area-weighted average, so its texel average is the map average
            // (f32 storage of O(1) values: 1e-5).
            for k in 0..5 {
                let avg: f64 = data.iter().map(|m| m[k] as f64).sum::<f64>() / (lw * lh) as f64;
                assert!((avg - mean[k]).abs() < 1e-5, "{w}×{h} level {l} moment {k}");
            }
            // Second moments dominate squared means (a convex combination of point masses).
            for m in data {
                assert!(m[2] >= m[0] * m[0] - 1e-5 && m[3] >= m[1] * m[1] - 1e-5);
            }
        }
    }
}

#[test]
fn filtered_moments_levels_and_interpolation() {
    let map = random_map(8, 8, 1.0, 30).moment_pyramid();
    let l0 = map.level(0).unwrap();
    // At a texel centre with a one-texel region: the texel itself.
    let m = map.filtered(Vec2::new(3.5, 2.5), 0.5);
    for k in 0..5 {
        assert!((m[k] - l0[2 * 8 + 3][k]).abs() < 1e-6);
    }
    // Halfway between two level-0 centres: their average.
    let m = map.filtered(Vec2::new(4.0, 2.5), 0.25);
    for k in 0..5 {
        let want = 0.5 * (l0[2 * 8 + 3][k] + l0[2 * 8 + 4][k]);
        assert!((m[k] - want).abs() < 1e-6);
    }
    // A region as large as the map: the 1×1 level, i.e. the map average, anywhere.
    let top = map.level(map.levels() - 1).unwrap()[0];
    for c in [Vec2::ZERO, Vec2::new(3.3, 7.9), Vec2::new(-100.0, 40.0)] {
        let m = map.filtered(c, 1e6);
        for k in 0..5 {
            assert!((m[k] - top[k]).abs() < 1e-6);
        }
    }
    // Radius 1 (λ = 1): exactly level 1 at a level-1 texel centre (level-1 texel (1, 1) is centred at
    // level-0 position (3, 3)), which is the 2×2 box of level-0 texels (2..4)².
    let m = map.filtered(Vec2::new(3.0, 3.0), 1.0);
    for k in 0..5 {
        let want: f32 = [(2, 2), (3, 2), (2, 3), (3, 3)]
            .iter()
            .map(|&(i, j)| l0[j * 8 + i][k])
            .sum::<f32>()
            / 4.0;
        assert!((m[k] - want).abs() < 1e-6, "{k}");
    }
    // Degenerate arguments stay finite.
    for r in [f32::NAN, -1.0, 0.0, f32::INFINITY] {
        assert!(
            map.filtered(Vec2::new(f32::NAN, 1.0), r)
                .iter()
                .all(|v| v.is_finite())
        );
    }
}

// ---------------------------------------------------------------------------------------------
// The explicit pyramid against independent computations
// ---------------------------------------------------------------------------------------------

/// A map whose slopes are multiples of 2⁻⁶ in [−2, 2]: the products x̃², ỹ², x̃ỹ are multiples of
/// 2⁻¹² of magnitude at most 4, so the mean of any 2^k of them is a multiple of 2^−(12+k) of
/// magnitude at most 4, 15 + k significant bits: exact in `f32` for k ≤ 9 (blocks of up to 512
/// texels), whatever the order of the sums.
fn dyadic_map(w: usize, h: usize, seed: u64) -> NormalMap {
    let mut rng = support::rng(seed);
    let slopes = (0..w * h)
        .map(|_| {
            let mut q = || rng.random_range(-128i32..=128) as f32 / 64.0;
            Vec2::new(q(), q())
        })
        .collect();
    NormalMap::from_slopes(w, h, slopes).unwrap()
}

/// The five moments of a slope, in f64 from the f32 slope.
fn texel_moments(s: Vec2) -> [f64; 5] {
    let (x, y) = (s.x as f64, s.y as f64);
    [x, y, x * x, y * y, x * y]
}

/// Level `l` of a power-of-two map as plain f64 box averages of level-0 texels: level texel (i, j)
/// averages the bx × by block of level-0 texels at (i bx, j by), bx = W / w_l, by = H / h_l.
fn box_level(map: &NormalMap, l: usize) -> Vec<[f64; 5]> {
    let (w, h) = (map.width(), map.height());
    let (lw, lh) = map.level_size(l).unwrap();
    assert!(w % lw == 0 && h % lh == 0, "{w}×{h} level {l}");
    let (bx, by) = (w / lw, h / lh);
    let mut out = vec![[0.0; 5]; lw * lh];
    for (t, o) in out.iter_mut().enumerate() {
        let (i, j) = (t % lw, t / lw);
        for y in j * by..(j + 1) * by {
            for x in i * bx..(i + 1) * bx {
                let m = texel_moments(map.texel_slope(x as i64, y as i64));
                for k in 0..5 {
                    o[k] += m[k] / (bx * by) as f64;
                }
            }
        }
    }
    out
}

/// The trilinear lookup written independently in f64 over `levels` (f64 level values):
/// λ = clamp(log₂(2r), 0, L − 1), bilinear between level texel centres with wrapping, linear in λ.
fn reference_filtered(map: &NormalMap, levels: &[Vec<[f64; 5]>], c: Vec2, r: f32) -> [f64; 5] {
    let top = (levels.len() - 1) as f64;
    let lod = if r > 0.0 {
        (2.0 * r as f64).log2().clamp(0.0, top)
    } else {
        0.0
    };
    let at_level = |l: usize| -> [f64; 5] {
        let (lw, lh) = map.level_size(l).unwrap();
        let px = c.x as f64 * lw as f64 / map.width() as f64 - 0.5;
        let py = c.y as f64 * lh as f64 / map.height() as f64 - 0.5;
        let (fx, fy) = (px - px.floor(), py - py.floor());
        let mut out = [0.0; 5];
        for (di, dj, wgt) in [
            (0, 0, (1.0 - fx) * (1.0 - fy)),
            (1, 0, fx * (1.0 - fy)),
            (0, 1, (1.0 - fx) * fy),
            (1, 1, fx * fy),
        ] {
            let i = (px.floor() as i64 + di).rem_euclid(lw as i64) as usize;
            let j = (py.floor() as i64 + dj).rem_euclid(lh as i64) as usize;
            for k in 0..5 {
                out[k] += wgt * levels[l][j * lw + i][k];
            }
        }
        out
    };
    let l0 = lod.floor();
    let (a, b) = (at_level(l0 as usize), at_level(lod.ceil() as usize));
    std::array::from_fn(|k| a[k] + (lod - l0) * (b[k] - a[k]))
}

/// Centres (wrapping, off-centre, negative) and radii (λ below 0, integer, fractional, above the
/// top) for the lookups.
fn lookups() -> Vec<(Vec2, f32)> {
    let centres = [
        Vec2::new(3.0, 5.0),
        Vec2::new(0.2, 7.7),
        Vec2::new(-13.4, 2.6),
        Vec2::new(41.3, -9.1),
    ];
    let radii = [0.1, 0.5, 0.8, 1.0, 1.3, 2.0, 3.7, 6.0, 11.0, 1e5];
    centres
        .iter()
        .flat_map(|&c| radii.iter().map(move |&r| (c, r)))
        .collect()
}

/// Power-of-two maps: every level equals the f64 box average of its block of level-0 texels bit
/// for bit (dyadic slopes make every such mean exact in f32, see [`dyadic_map`]), and `filtered`
/// equals the f64 trilinear lookup over those averages to 1e-6 of the moments' scale (4: the f32
/// rounding of the result and of λ, computed in f32 by the pyramid).
#[test]
fn moment_pyramid_matches_box_averages_on_power_of_two_maps() {
    for (w, h) in [(16, 16), (32, 8), (4, 16)] {
        let map = dyadic_map(w, h, 40 + w as u64 + h as u64);
        let pyramid = map.moment_pyramid();
        assert_eq!(pyramid.levels(), map.levels());
        let levels: Vec<Vec<[f64; 5]>> = (0..map.levels()).map(|l| box_level(&map, l)).collect();
        for (l, want) in levels.iter().enumerate() {
            let got = pyramid.level(l).unwrap();
            assert_eq!(got.len(), want.len(), "{w}×{h} level {l}");
            for (t, (g, e)) in got.iter().zip(want).enumerate() {
                assert_eq!(*g, e.map(|v| v as f32), "{w}×{h} level {l} texel {t}");
            }
        }
        assert!(pyramid.level(map.levels()).is_none());
        for (c, r) in lookups() {
            let got = pyramid.filtered(c, r);
            let want = reference_filtered(&map, &levels, c, r);
            for k in 0..5 {
                assert!(
                    (got[k] as f64 - want[k]).abs() <= 4e-6,
                    "{w}×{h} at {c} r {r} moment {k}: {} vs {}",
                    got[k],
                    want[k]
                );
            }
        }
    }
}

/// Odd sizes: level 1 is the f64 area-weighted average over the exact overlap of its uv rectangle
/// with the level-0 texels (to f32 rounding of values below 4: 1e-6); at every level and for
/// `filtered`, the result is a convex combination of level-0 texels with weights ≥ 0 summing to 1,
/// read through linearity: the moments of a map whose slope x̃ is 1 on one texel t and 0 elsewhere
/// are the weights of t (E\[x̃\] = E\[x̃²\] = weight).
#[test]
fn moment_pyramid_is_a_convex_combination_on_odd_maps() {
    for (w, h) in [(5, 3), (7, 5), (9, 1), (3, 6)] {
        let map = random_map(w, h, 1.2, 50 + w as u64);
        let pyramid = map.moment_pyramid();
        // Level 1 by exact overlaps.
        let (lw, lh) = map.level_size(1).unwrap_or((1, 1));
        let overlap =
            |a0: f64, a1: f64, k: usize| (a1.min(k as f64 + 1.0) - a0.max(k as f64)).max(0.0);
        if map.levels() > 1 {
            let got = pyramid.level(1).unwrap();
            let (sx, sy) = (w as f64 / lw as f64, h as f64 / lh as f64);
            for j in 0..lh {
                for i in 0..lw {
                    let mut want = [0.0f64; 5];
                    for y in 0..h {
                        for x in 0..w {
                            let a = overlap(i as f64 * sx, (i + 1) as f64 * sx, x)
                                * overlap(j as f64 * sy, (j + 1) as f64 * sy, y);
                            let m = texel_moments(map.texel_slope(x as i64, y as i64));
                            for k in 0..5 {
                                want[k] += a / (sx * sy) * m[k];
                            }
                        }
                    }
                    for k in 0..5 {
                        let g = got[j * lw + i][k] as f64;
                        assert!(
                            (g - want[k]).abs() < 1e-6,
                            "{w}×{h} ({i}, {j}) {k}: {g} vs {}",
                            want[k]
                        );
                    }
                }
            }
        }
        // Convex weights, from impulse maps: level texel weights and lookup weights per input texel.
        let texels = w * h;
        let mut level_sums: Vec<Vec<f64>> = (0..map.levels())
            .map(|l| vec![0.0; map.level_size(l).map_or(0, |(a, b)| a * b)])
            .collect();
        let mut lookup_sums = vec![0.0f64; lookups().len()];
        for t in 0..texels {
            let mut slopes = vec![Vec2::ZERO; texels];
            slopes[t] = Vec2::new(1.0, 0.0);
            let p = NormalMap::from_slopes(w, h, slopes)
                .unwrap()
                .moment_pyramid();
            for (l, sums) in level_sums.iter_mut().enumerate() {
                for (s, m) in sums.iter_mut().zip(p.level(l).unwrap()) {
                    assert!(
                        (0.0..=1.0).contains(&m[0]) && m[0] == m[2],
                        "{w}×{h} level {l}: {m:?}"
                    );
                    assert!(m[1] == 0.0 && m[3] == 0.0 && m[4] == 0.0);
                    *s += m[0] as f64;
                }
            }
            for (s, &(c, r)) in lookup_sums.iter_mut().zip(&lookups()) {
                let m = p.filtered(c, r);
                assert!(
                    (0.0..=1.0).contains(&m[0]) && m[0] == m[2],
                    "{w}×{h} at {c} r {r}: {m:?}"
                );
                *s += m[0] as f64;
            }
        }
        for sums in level_sums.iter().chain([&lookup_sums]) {
            for s in sums {
                // One f32 rounding per weight: texels × 2⁻²⁴.
                assert!(
                    (s - 1.0).abs() < texels as f64 * 1.2e-7,
                    "{w}×{h}: weights sum to {s}"
                );
            }
        }
    }
}
