//! The procedural normal maps (bumpy, brushed, flakes, scratched): the requested statistics (RMS slope,
//! correlation length, anisotropy, flake tilts, groove bounds), determinism whatever the thread count,
//! tiling, bad parameters, and (ignored) the time of 4096² maps.

use brdf::Vec2;
use brdf::glint::{
    BrushedParams, FlakesParams, NormalMap, ScratchedParams, brushed, bumpy, flakes, scratched,
};

/// (√E[x̃²], √E[ỹ²]) over the texels, in f64.
fn rms_xy(map: &NormalMap) -> (f64, f64) {
    let n = map.slopes().len() as f64;
    let (mut a, mut b) = (0.0, 0.0);
    for s in map.slopes() {
        a += (s.x as f64).powi(2);
        b += (s.y as f64).powi(2);
    }
    ((a / n).sqrt(), (b / n).sqrt())
}

#[test]
fn bumpy_has_the_requested_rms_slope() {
    for (w, h, rms, corr, seed) in [
        (256, 256, 0.3f32, 4.0f32, 1u64),
        (384, 200, 0.05, 6.0, 2),
        (256, 256, 1.0, 2.0, 3),
    ] {
        let map = bumpy(w, h, rms, corr, seed).unwrap();
        let (rx, ry) = rms_xy(&map);
        // Combined RMS is exact by construction (f32 rounding only).
        let both = (0.5 * (rx * rx + ry * ry)).sqrt();
        assert!((both / rms as f64 - 1.0).abs() < 1e-4, "{both}");
        // Per axis: the field spans (w/ℓ)(h/ℓ) ≥ 1600 correlation areas, so the relative fluctuation
        // of an axis' mean square is ~ 1/√1600 = 2.5 %, of its RMS half that; 5 % is > 3 σ.
        assert!(
            (rx / rms as f64 - 1.0).abs() < 0.05,
            "{w}×{h}: rms x {rx} vs {rms}"
        );
        assert!(
            (ry / rms as f64 - 1.0).abs() < 0.05,
            "{w}×{h}: rms y {ry} vs {rms}"
        );
        // Mean slope of a periodic height field is 0 (central differences telescope).
        let mean: f64 = map.slopes().iter().map(|s| s.x as f64).sum::<f64>() / (w * h) as f64;
        assert!(mean.abs() < 1e-5, "{mean}");
    }
}

#[test]
fn bumpy_correlation_length_is_honoured() {
    // Height autocorrelation ∝ exp(−r²/ℓ²) means the slope field decorrelates over ~ℓ: the
    // correlation of x̃ between texels ℓ apart along y is exp(−1) ≈ 0.37 for the continuous field
    // (∂²/∂x² of exp(−(x²+y²)/ℓ²) at x = 0 is ∝ exp(−y²/ℓ²)). Allow ±0.1 (sampling of ~64² areas
    // and finite differences).
    let l = 8.0f32;
    let map = bumpy(512, 512, 0.2, l, 9).unwrap();
    let s = map.slopes();
    let (mut c, mut v) = (0.0f64, 0.0f64);
    for j in 0..512usize {
        for i in 0..512usize {
            let a = s[j * 512 + i].x as f64;
            let b = s[((j + l as usize) % 512) * 512 + i].x as f64;
            c += a * b;
            v += a * a;
        }
    }
    let rho = c / v;
    assert!((rho - (-1.0f64).exp()).abs() < 0.1, "ρ(ℓ) = {rho}");
}

#[test]
fn brushed_is_strongly_anisotropic() {
    let p = BrushedParams::default();
    let map = brushed(512, 512, p, 4).unwrap();
    let (rx, ry) = rms_xy(&map);
    assert!((ry / p.rms_slope as f64 - 1.0).abs() < 1e-4, "{ry}");
    // Documented: ratio about 13 with the defaults; require > 8.
    assert!(ry / rx > 8.0, "ratio {}", ry / rx);
}

#[test]
fn flakes_are_piecewise_constant_gaussian_tilts() {
    let p = FlakesParams::default();
    let map = flakes(384, 384, p, 5).unwrap();
    let mut distinct: Vec<[u32; 2]> = map
        .slopes()
        .iter()
        .map(|s| [s.x.to_bits(), s.y.to_bits()])
        .collect();
    distinct.sort_unstable();
    distinct.dedup();
    // 32 × 32 sites; a jittered Voronoi cell is never empty in practice, a few may be.
    assert!(
        distinct.len() > 1000 && distinct.len() <= 1024,
        "{}",
        distinct.len()
    );
    // The sites' slopes are N(0, σ²) per axis: the sample SD of n ≈ 1024 values has a relative
    // standard error 1/√(2n) ≈ 2.2 %; allow 9 % (4 SE).
    let n = distinct.len() as f64;
    let sd = |k: usize| {
        (distinct
            .iter()
            .map(|d| (f32::from_bits(d[k]) as f64).powi(2))
            .sum::<f64>()
            / n)
            .sqrt()
    };
    for k in 0..2 {
        assert!(
            (sd(k) / p.tilt_sigma as f64 - 1.0).abs() < 0.09,
            "axis {k}: {}",
            sd(k)
        );
    }
    // Neighbouring texels mostly share their flake: ~2/12 of horizontal neighbours differ.
    let s = map.slopes();
    let changes = (0..384 * 383).filter(|&k| s[k] != s[k + 1]).count() as f64 / (384.0 * 383.0);
    assert!(changes > 0.05 && changes < 0.3, "{changes}");
}

#[test]
fn scratches_are_bounded_grooves() {
    let p = ScratchedParams {
        base_rms_slope: 0.0,
        ..ScratchedParams::default()
    };
    let map = scratched(256, 256, p, 6).unwrap();
    let mut max = 0.0f32;
    let mut nonzero = 0usize;
    for s in map.slopes() {
        max = max.max(s.x.abs()).max(s.y.abs());
        nonzero += (s.length() > 0.0) as usize;
    }
    // The height is a minimum of profiles with |h'| ≤ max_slope, so it is max_slope-Lipschitz and
    // so is every central difference (+ f32 rounding).
    assert!(
        max <= p.max_slope * (1.0 + 1e-4) && max > 0.3 * p.max_slope,
        "{max}"
    );
    // 40 scratches of mean length 87 texels and width ~3 (+2 texels of differences)
    // cover roughly 40·90·5/65536 ≈ 27 % of the map; overlaps reduce it. Allow 8–40 %.
    let frac = nonzero as f64 / 65536.0;
    assert!(frac > 0.08 && frac < 0.4, "{frac}");
    // No scratches and no base: flat.
    let flat = scratched(
        64,
        64,
        ScratchedParams {
            density: 0.0,
            base_rms_slope: 0.0,
            ..p
        },
        7,
    )
    .unwrap();
    assert!(flat.slopes().iter().all(|s| *s == Vec2::ZERO));
    // With the default base the map is rough everywhere.
    let rough = scratched(128, 128, ScratchedParams::default(), 8).unwrap();
    assert!(rough.slopes().iter().filter(|s| s.length() == 0.0).count() < 10);
}

#[test]
fn generators_are_deterministic_whatever_the_thread_count() {
    let run = || {
        vec![
            bumpy(96, 80, 0.2, 3.0, 11).unwrap(),
            brushed(96, 80, BrushedParams::default(), 11).unwrap(),
            scratched(96, 80, ScratchedParams::default(), 11).unwrap(),
            flakes(96, 80, FlakesParams::default(), 11).unwrap(),
        ]
    };
    let a = run();
    let b = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    let c = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap()
        .install(run);
    for ((x, y), z) in a.iter().zip(&b).zip(&c) {
        assert_eq!(x.slopes(), y.slopes());
        assert_eq!(x.slopes(), z.slopes());
    }
    // Different seeds differ.
    assert_ne!(
        bumpy(32, 32, 0.2, 3.0, 1).unwrap().slopes(),
        bumpy(32, 32, 0.2, 3.0, 2).unwrap().slopes()
    );
}

#[test]
fn generators_tile() {
    // Across the tile border the slopes are as continuous as inside: compare the mean jump between
    // columns 0 and w−1 with the mean jump between interior neighbours (same statistics ⇒ ratio ≈ 1).
    let map = bumpy(128, 128, 0.2, 6.0, 12).unwrap();
    let s = map.slopes();
    let jump = |i0: usize, i1: usize| -> f64 {
        (0..128)
            .map(|j| (s[j * 128 + i0] - s[j * 128 + i1]).length() as f64)
            .sum::<f64>()
            / 128.0
    };
    let border = jump(127, 0);
    let inner = (1..127).map(|i| jump(i - 1, i)).sum::<f64>() / 126.0;
    assert!(border < 2.0 * inner, "border {border} vs inner {inner}");
}

#[test]
fn generators_reject_bad_parameters() {
    assert!(bumpy(64, 64, 0.0, 4.0, 1).is_err());
    assert!(bumpy(64, 64, f32::NAN, 4.0, 1).is_err());
    assert!(bumpy(64, 64, 0.2, 100.0, 1).is_err());
    assert!(bumpy(0, 64, 0.2, 4.0, 1).is_err());
    assert!(bumpy(1, 1, 0.2, 1.0, 1).is_err());
    assert!(
        brushed(
            64,
            64,
            BrushedParams {
                width_texels: -1.0,
                ..Default::default()
            },
            1
        )
        .is_err()
    );
    assert!(
        scratched(
            64,
            64,
            ScratchedParams {
                curved_fraction: 2.0,
                ..Default::default()
            },
            1
        )
        .is_err()
    );
    assert!(
        scratched(
            64,
            64,
            ScratchedParams {
                length_texels: (50.0, 20.0),
                ..Default::default()
            },
            1
        )
        .is_err()
    );
    assert!(
        flakes(
            64,
            64,
            FlakesParams {
                cell_texels: 0.0,
                ..Default::default()
            },
            1
        )
        .is_err()
    );
    assert!(
        flakes(
            64,
            64,
            FlakesParams {
                tilt_sigma: f32::INFINITY,
                ..Default::default()
            },
            1
        )
        .is_err()
    );
}

/// 4096² of each generator in seconds (run: `cargo test --release --test it -- --ignored
/// glint_procedural::big_maps --nocapture`); the timed figures are in benches/glint.rs.
#[test]
#[ignore]
fn big_maps() {
    let t = std::time::Instant::now();
    bumpy(4096, 4096, 0.2, 8.0, 1).unwrap();
    println!("bumpy 4096²: {:?}", t.elapsed());
    let t = std::time::Instant::now();
    brushed(4096, 4096, BrushedParams::default(), 1).unwrap();
    println!("brushed 4096²: {:?}", t.elapsed());
    let t = std::time::Instant::now();
    scratched(4096, 4096, ScratchedParams::default(), 1).unwrap();
    println!("scratched 4096²: {:?}", t.elapsed());
    let t = std::time::Instant::now();
    flakes(4096, 4096, FlakesParams::default(), 1).unwrap();
    println!("flakes 4096²: {:?}", t.elapsed());
}
