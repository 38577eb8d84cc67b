//! The Beckmann mixture (Chermain 2019): the model itself. Weights, lobes, D_P against the
//! brute-force and `f64` sums of its lobes, bad input, and (ignored) the measurements against the
//! ground truth. Masking: tests/it/mixture_masking.rs; sampling: tests/it/mixture_sampling.rs; merged
//! levels of detail: tests/it/mixture_levels.rs and tests/it/mixture_lod.rs; compact storage:
//! tests/it/mixture_compact.rs.

use crate::support;

use brdf::glint::mixture::{MaskingMode, MixtureParams, MomentMethod, PatchOptions, SeedKernel};
use brdf::glint::{self, BeckmannMixture, Footprint, GlintNdf, MixturePatch, NormalMap};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use rand::RngExt;
use support::mixture::*;

#[test]
fn weights_sum_to_one_and_cover_the_footprint() {
    let map = glint::bumpy(N, N, 0.25, 4.0, 1).unwrap();
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    for area in [0.0, 1e-6, 1.0, 16.0, 4096.0, 1e9] {
        for c in [Vec2::new(0.5, 0.5), Vec2::new(0.001, 0.999)] {
            let p = exact_patch(&mix, &footprint(area, c));
            let sum: f64 = p.weighted_lobes().map(|(w, _)| w as f64).sum();
            // f32 weights summed in f64: ≤ slots × 2⁻²⁴ relative rounding (≤ 4096 slots → 2.4e-4,
            // in practice ~1e-6).
            assert!((sum - 1.0).abs() < 1e-4, "area {area}: Σ W = {sum}");
            assert!(p.lobe_count() <= mix.memory().lobes.max(1) || area < 1e6);
        }
    }
}

#[test]
fn lobe_spacing_and_moments_of_a_plane() {
    // A constant slope map: every lobe has that mean and σ = σ_ε (zero variance floored).
    let s = Vec2::new(0.3, -0.2);
    let map = NormalMap::from_slopes(8, 8, vec![s; 64]).unwrap();
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    assert_eq!(mix.grid(), (8, 8));
    for k in 0..64 {
        let g = mix.lobe(k % 8, k / 8);
        // Interpolated slope of equal normals = s up to f32 normalisation (1e-6).
        assert!((g.mean() - s).length() < 1e-5);
        let c = g.covariance();
        assert!((c.x_axis.x - 1e-4).abs() < 1e-7 && (c.y_axis.y - 1e-4).abs() < 1e-7);
    }
}

#[test]
fn hierarchy_d_equals_the_brute_force_sum() {
    // D_P through the quadtree = Σ W_i D_i over every gathered lobe (written here), at slopes drawn
    // from the mixture itself and uniformly; differences come only from the 1e-6-mass box truncation
    // and f32 sums.
    let mut rng = support::rng(9);
    let mut max_touched_frac = 0.0f64;
    for (name, map) in maps() {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        for area in AREAS {
            let patch = exact_patch(&mix, &footprint(area, Vec2::new(0.37, 0.61)));
            let lobes: Vec<_> = patch.weighted_lobes().collect();
            for k in 0..200 {
                let m = probe_normal(&patch, &mut rng, k);
                let brute: f64 = lobes.iter().map(|(w, g)| *w as f64 * g.d(m) as f64).sum();
                let (d, touched) = patch.d_with_stats(m);
                // A lobe outside its 5.26σ box contributes ≤ e^{−13.8} ≈ 1e-6 of its peak (times the
                // 1/cos⁴ factor, ≤ 2 here): 1e-5 relative (f32 sums) + 2e-6 Σ W_i peak_i.
                let peak: f64 = lobes
                    .iter()
                    .map(|(w, g)| *w as f64 * g.d(g.mean_normal()) as f64)
                    .sum();
                assert!(
                    (d as f64 - brute).abs() <= 1e-5 * brute + 2e-6 * peak,
                    "{name} {area}: {d} vs {brute}"
                );
                max_touched_frac = max_touched_frac.max(touched as f64 / lobes.len() as f64);
            }
        }
    }
    println!("largest fraction of the footprint's lobes touched by one d(): {max_touched_frac:.3}");
}

/// P22 of one lobe at slope s in f64 from its public mean and Cholesky factor (L⁻¹ by substitution),
/// whether s lies in the lobe's slope box |s − μ| ≤ k (√Σxx, √Σyy), with the box's margin
/// (|d|/half-width − 1, the smaller of the two axes' in absolute value), and the exponent ½ |z|².
fn p22_f64(g: &brdf::ndf::SlopeGaussian, s: [f64; 2], k: f64) -> (f64, bool, f64, f64) {
    let (mu, l) = (g.mean(), g.cholesky());
    let (l11, l21, l22) = (l.x_axis.x as f64, l.x_axis.y as f64, l.y_axis.y as f64);
    let (dx, dy) = (s[0] - mu.x as f64, s[1] - mu.y as f64);
    let zx = dx / l11;
    let zy = (dy - l21 * zx) / l22;
    let p = (-0.5 * (zx * zx + zy * zy)).exp() / (std::f64::consts::TAU * l11 * l22);
    let (hx, hy) = (k * l11, k * (l21 * l21 + l22 * l22).sqrt());
    let inside = dx.abs() <= hx && dy.abs() <= hy;
    let margin = (dx.abs() / hx - 1.0).abs().min((dy.abs() / hy - 1.0).abs());
    (p, inside, margin, 0.5 * (zx * zx + zy * zy))
}

proptest::proptest! {
    #![proptest_config(support::proptest_config(256))]

    /// D_P by the lobe blocks (f32 lanes, polynomial exp) = Σ W_i P22_i(s) (1 + |s|²)² summed here
    /// in f64 over the patch's public (W_i, lobe_i), with the same slope-box truncation, to 1e-5
    /// relative. Lobes within 1e-4 (relative) of their box's edge may fall either side in f32: their
    /// contributions are added to the allowance, and so is the f32 rounding of each lobe's exponent
    /// (relative 8 ε ½|z|² of its term). Slopes: the patch's own samples (where D_P is
    /// large) and uniform in [−1.2, 1.2]² (tails, empty regions); footprints from sub-texel to
    /// twice the map (folded axes), anisotropic, anywhere (wrapping).
    #[test]
    fn block_d_equals_the_f64_sum_of_the_lobes(
        which in 0usize..5, cx in 0.0f32..1.0, cy in 0.0f32..1.0,
        log_area in -2.0f32..13.0, aspect in 1.0f32..8.0, angle in 0.0f32..3.2,
        own in proptest::bool::ANY, u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let (name, mix) = &block_mixtures()[which];
        let fp = Footprint::anisotropic_texels(
            Vec2::new(cx, cy), log_area.exp2(), aspect, angle, N, N);
        let patch = exact_patch(mix, &fp);
        let m = if own {
            patch.sample_normal(Vec2::new(u0, u1))
        } else {
            brdf::frame::slope_to_normal(Vec2::new(2.4 * u0 - 1.2, 2.4 * u1 - 1.2))
        };
        // The slope the patch evaluates (f32), then the reference in f64 from it.
        let s32 = brdf::frame::normal_to_slope(m).unwrap();
        let s = [s32.x as f64, s32.y as f64];
        let k = mix.box_sigmas() as f64;
        let (mut reference, mut edge) = (0.0f64, 0.0f64);
        for (w, g) in patch.weighted_lobes() {
            let (p, inside, margin, e) = p22_f64(&g, s, k);
            if inside {
                reference += w as f64 * p;
                // The lanes form the exponent e = ½ |z|² in f32: its rounding (a few ulp of e,
                // 8 ε e here) is a relative error of as much in exp(−e), which exceeds 1e-5 in the
                // far tail (e ≳ 10; the 5.26σ box reaches e ≈ 28 at its corners).
                edge += w as f64 * p * 8.0 * f32::EPSILON as f64 * e;
            }
            if margin < 1e-4 {
                edge += w as f64 * p;
            }
        }
        let c = 1.0 + s[0] * s[0] + s[1] * s[1];
        let (reference, edge) = (reference * c * c, edge * c * c);
        let d = patch.d(m) as f64;
        // 1e-5 relative: the f32 lanes (exp2 polynomial < 1e-6, P22 and quadratic form a few ulp
        // each) and the f32 weights; 1e-37: f32's normal range (D below it is flushed).
        proptest::prop_assert!(
            (d - reference).abs() <= 1e-5 * reference + edge + 1e-37,
            "{name}: D {d} vs f64 sum {reference} (edge allowance {edge})"
        );
    }
}

/// The default seed kernel resolves by spacing (the cell from one texel up, the Gaussian below), the
/// built mixture names the kernel it used, and the two kernels place their lobes where their docs
/// say: on a map whose slope is linear in x, a lobe's mean x̃ is the slope at its centre.
#[test]
fn seed_kernel_resolves_by_spacing_and_places_the_lobes() {
    assert_eq!(SeedKernel::Auto.resolve(1.0), SeedKernel::Cell);
    assert_eq!(SeedKernel::Auto.resolve(2.0), SeedKernel::Cell);
    assert_eq!(SeedKernel::Auto.resolve(0.5), SeedKernel::Gaussian);
    assert_eq!(SeedKernel::Gaussian.resolve(1.0), SeedKernel::Gaussian);
    assert_eq!(SeedKernel::Cell.resolve(0.25), SeedKernel::Cell);
    // Slope x̃ = a (x − 8) over x in [4, 12] texels (texel i at i + ½), flat in y; lobes away
    // from the ends see a linear field, so their mean is the slope at their centre.
    let (n, a) = (16usize, 0.02f32);
    let slopes = (0..n * n)
        .map(|k| {
            let x = (k % n) as f32 + 0.5;
            Vec2::new(a * (x.clamp(4.0, 12.0) - 8.0), 0.0)
        })
        .collect();
    let map = NormalMap::from_slopes(n, n, slopes).unwrap();
    for (spacing, want) in [(1.0, SeedKernel::Cell), (0.5, SeedKernel::Gaussian)] {
        let params = MixtureParams {
            spacing,
            ..MixtureParams::default()
        };
        assert_eq!(params.seed, SeedKernel::Auto);
        let mix = BeckmannMixture::build(&map, params).unwrap();
        assert_eq!(mix.params().seed, want);
        let h = spacing as f64;
        let lobes = (n as f64 / h) as i64;
        for i in 0..lobes {
            let x = (i as f64 + 0.5) * h + want.origin();
            if !(6.0..=10.0).contains(&x) {
                continue;
            }
            let m = mix.lobe(i, 3).mean();
            // The bilinear blend of unit normals divided by its z is not exactly linear in x̃ (the
            // normals' lengths differ by O(a²)): 1e-5 covers it at a = 0.02 and 4 texels.
            assert!(
                (m.x as f64 - a as f64 * (x - 8.0)).abs() < 1e-5,
                "spacing {spacing}, lobe {i} at {x}: mean {m}"
            );
        }
    }
}

#[test]
fn bad_input() {
    let map = glint::bumpy(16, 16, 0.25, 4.0, 1).unwrap();
    for (field, params) in [
        (
            "spacing",
            MixtureParams {
                spacing: 0.0,
                ..Default::default()
            },
        ),
        (
            "spacing",
            MixtureParams {
                spacing: -1.0,
                ..Default::default()
            },
        ),
        (
            "sigma_min",
            MixtureParams {
                sigma_min: 0.0,
                ..Default::default()
            },
        ),
        (
            "sigma_min",
            MixtureParams {
                sigma_min: f32::NAN,
                ..Default::default()
            },
        ),
        (
            "samples",
            MixtureParams {
                samples: 0,
                moments: MomentMethod::Qmc,
                ..Default::default()
            },
        ),
        (
            "slope_tail",
            MixtureParams {
                slope_tail: 1.0,
                ..Default::default()
            },
        ),
    ] {
        let e = BeckmannMixture::build(&map, params).unwrap_err();
        assert!(e.to_string().contains(field), "{e}");
    }
    assert!(NormalMap::from_slopes(0, 0, vec![]).is_err());
    // Totality: any footprint, any direction.
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let fps = [
        Footprint::from_differentials(Vec2::new(0.5, 0.5), Vec2::ZERO, Vec2::ZERO),
        Footprint::from_differentials(Vec2::NAN, Vec2::NAN, Vec2::new(1.0, 0.0)),
        Footprint::from_differentials(
            Vec2::new(0.5, 0.5),
            Vec2::new(1e-9, 0.0),
            Vec2::new(0.0, 1e-9),
        ),
        Footprint::from_differentials(
            Vec2::new(-3.2, 7.9),
            Vec2::new(50.0, 3.0),
            Vec2::new(-2.0, 40.0),
        ),
        Footprint::from_differentials(
            Vec2::new(0.1, 0.2),
            Vec2::new(0.5, 0.0),
            Vec2::new(0.0, 0.001),
        ),
    ];
    let dirs = [
        Vec3::Z,
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::NAN,
        Vec3::ZERO,
        Vec3::new(0.6, 0.0, 0.8),
        Vec3::new(0.999, 0.0, 0.0447),
    ];
    for fp in &fps {
        for masking in [MaskingMode::Exact, MaskingMode::Approximate] {
            for (lod, tol) in [
                (0.0, 0.0),
                (f32::INFINITY, 0.0),
                (f32::INFINITY, 1.0),
                (4.0, 0.1),
            ] {
                let p = mix.patch_with(
                    fp,
                    &PatchOptions {
                        masking,
                        lod_lobes: lod,
                        lod_tolerance: tol,
                        ..PatchOptions::default()
                    },
                    None,
                );
                for &w in &dirs {
                    for v in [
                        p.d(w),
                        p.lambda(w),
                        p.projected_area(w),
                        p.visible_area(w),
                        p.pdf_normal(w),
                    ] {
                        assert!(v.is_finite() && v >= 0.0, "{v} for {w}");
                    }
                    for &m in &dirs {
                        assert!(p.pdf_visible(w, m).is_finite());
                    }
                    for u in [Vec2::ZERO, Vec2::splat(0.999_999_9), Vec2::NAN] {
                        for m in [p.sample_normal(u), p.sample_visible(w, u)] {
                            assert!(
                                m.is_finite() && m.z > 0.0 && (m.length() - 1.0).abs() < 1e-5,
                                "{m}"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// `samples` counts the QMC nodes of [`MomentMethod::Qmc`]: refused at 0 there, accepted (and
/// unused) under the default filter, whose mixture is then bit-identical to one built with any other
/// count.
#[test]
fn samples_are_checked_only_where_used() {
    let map = glint::bumpy(16, 16, 0.25, 4.0, 1).unwrap();
    let qmc = MixtureParams {
        samples: 0,
        moments: MomentMethod::Qmc,
        ..Default::default()
    };
    let e = BeckmannMixture::build(&map, qmc).unwrap_err();
    assert!(e.to_string().contains("samples"), "{e}");
    let zero = MixtureParams {
        samples: 0,
        ..Default::default()
    };
    assert!(matches!(zero.moments, MomentMethod::Filter { .. }));
    let a = BeckmannMixture::build(&map, zero).unwrap();
    let b = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let bits = |m: &BeckmannMixture| {
        m.moments()
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.params().samples, 0);
}

/// TV of a patch to the two ground truths of one footprint (64² bins, Gaussian kernel, same
/// positions): the Dirac truth (`binned_pndf`, the interpolated map itself) and the convolved truth
/// (`convolved_pndf`, each position's normal spread by the material's σ_ε = 0.01 slope Gaussian).
/// The patch's bin masses come from `adaptive_bin_masses` (per-bin midpoint grids refined until
/// the masses change by less than 1e-3 in TV); returns (TV Dirac, TV convolved, finest k, the
/// larger noise floor of the two truths).
fn tv_both_truths(
    patch: &(impl Ndf + Sync),
    truths: &(glint::BinnedPndf, glint::BinnedPndf),
) -> (f64, f64, usize, f64) {
    let (dirac, conv) = truths;
    let q = glint::adaptive_bin_masses(
        patch,
        dirac.bins(),
        glint::DEFAULT_QUADRATURE_TOLERANCE,
        glint::DEFAULT_MAX_QUADRATURE,
    );
    (
        dirac.tv_to_masses(&q.masses).unwrap(),
        conv.tv_to_masses(&q.masses).unwrap(),
        q.k_max,
        dirac.tv_error().max(conv.tv_error()),
    )
}

/// Both truths of `fp` on 64² bins from `samples` positions (seed 17).
fn truths(
    map: &NormalMap,
    fp: &Footprint,
    samples: usize,
) -> (glint::BinnedPndf, glint::BinnedPndf) {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, convolved_pndf};
    let bins = HemisphereBins::new(64).unwrap();
    let sigma = brdf::ndf::DEFAULT_SIGMA_MIN as f64;
    (
        binned_pndf(map, fp, Kernel::Gaussian, &bins, samples, 17),
        convolved_pndf(map, fp, Kernel::Gaussian, &bins, samples, 17, sigma).unwrap(),
    )
}

/// Accuracy against both ground truths and the default sample count (measurements for
/// docs/results.md).
///
/// `cargo test --release --test it -- --ignored mixture::accuracy_table --nocapture`
#[test]
#[ignore]
fn accuracy_table() {
    let n = 256;
    let maps = support::procedural_maps(n);
    println!(
        "| map | footprint (texels) | lobes | TV mixture: Dirac / convolved | TV filtered lobe: \
         Dirac / convolved | quadrature k (mixture, lobe) | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, map) in &maps {
        let mix = BeckmannMixture::build(map, MixtureParams::default()).unwrap();
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let t = truths(map, &fp, 4_000_000);
            let exact = exact_patch(&mix, &fp);
            let lod = mix.patch_with(
                &fp,
                &PatchOptions {
                    masking: MaskingMode::Approximate,
                    lod_lobes: 0.0,
                    lod_tolerance: 0.0,
                    ..PatchOptions::default()
                },
                None,
            );
            let (d, c, k, noise) = tv_both_truths(&exact, &t);
            let (d_lod, c_lod, k_lod, _) = tv_both_truths(&lod, &t);
            println!(
                "| {name} | {area} | {} | {d:.3} / {c:.3} | {d_lod:.3} / {c_lod:.3} | {k}, {k_lod} | {noise:.3} |",
                exact.lobe_count(),
            );
        }
    }
    // Moment convergence: largest error of any lobe's σ (per axis) and mean against 16384 nodes.
    println!("\n| map | samples | max |Δmean| | max |Δσ| / σ_ε |");
    println!("|---|---|---|---|");
    for (name, map) in &maps {
        let small = NormalMap::from_slopes(
            64,
            64,
            (0..64 * 64)
                .map(|k| map.slopes()[(k / 64) * n + k % 64])
                .collect(),
        )
        .unwrap();
        let reference = BeckmannMixture::build(
            &small,
            MixtureParams {
                samples: 16384,
                ..MixtureParams::default()
            },
        )
        .unwrap();
        for samples in [16, 64, 256] {
            let mix = BeckmannMixture::build(
                &small,
                MixtureParams {
                    samples,
                    ..MixtureParams::default()
                },
            )
            .unwrap();
            let (mut dm, mut ds) = (0.0f32, 0.0f32);
            for k in 0..64 * 64 {
                let (a, b) = (mix.lobe(k % 64, k / 64), reference.lobe(k % 64, k / 64));
                dm = dm.max((a.mean() - b.mean()).length());
                let (ca, cb) = (a.covariance(), b.covariance());
                ds = ds.max(
                    (ca.x_axis.x.sqrt() - cb.x_axis.x.sqrt())
                        .abs()
                        .max((ca.y_axis.y.sqrt() - cb.y_axis.y.sqrt()).abs()),
                );
            }
            println!("| {name} | {samples} | {dm:.2e} | {:.3} |", ds / 0.01);
        }
    }
}

/// The level-of-detail measurement behind `DEFAULT_LOD_LOBES`: on 512² procedural maps, for
/// footprints of 1024 to 65 536 texels, the distance of the mixture and of the filtered lobe to the
/// ground truth (64² bins, 4·10⁶ positions, one model evaluation per bin) and the time of one `d`.
///
/// `cargo test --release --test it -- --ignored mixture::lod_table --nocapture`
#[test]
#[ignore]
fn lod_table() {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, tv_distance};
    use std::time::Instant;
    let n = 512;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | TV mixture | TV filtered lobe | d mixture | d filtered lobe |"
    );
    println!("|---|---|---|---|---|---|");
    for (name, map) in &maps {
        let mix = BeckmannMixture::build(map, MixtureParams::default()).unwrap();
        for area in [1024.0f32, 4096.0, 16384.0, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let reference = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let exact = exact_patch(&mix, &fp);
            let filtered = mix.patch_with(
                &fp,
                &PatchOptions {
                    masking: MaskingMode::Approximate,
                    lod_lobes: 0.0,
                    lod_tolerance: 0.0,
                    ..PatchOptions::default()
                },
                None,
            );
            let tv = tv_distance(&exact, &reference, 1);
            let tv_lod = tv_distance(&filtered, &reference, 1);
            // One thread, 512 normals (half from D_P cos, half uniform over the bins' centres).
            let normals: Vec<Vec3> = (0..512)
                .map(|k| {
                    let u = Vec2::new((k as f32 + 0.5) / 512.0, (k as f32 * 0.618_034).fract());
                    if k % 2 == 0 {
                        exact.sample_normal(u)
                    } else {
                        bins.center(k * 7 % bins.len())
                    }
                })
                .collect();
            let time = |p: &MixturePatch| {
                let t = Instant::now();
                let s: f32 = normals.iter().map(|&m| p.d(m)).sum();
                assert!(s.is_finite());
                t.elapsed().as_secs_f64() / normals.len() as f64
            };
            let (t_mix, t_lod) = (time(&exact), time(&filtered));
            println!(
                "| {name} | {area} | {tv:.3} | {tv_lod:.3} | {:.1} µs | {:.3} µs |",
                t_mix * 1e6,
                t_lod * 1e6
            );
        }
    }
}

/// Build time and memory at 2048² (one run; figures in docs/results.md).
///
/// `cargo test --release --test it -- --ignored mixture::build_2048 --nocapture`
#[test]
#[ignore]
fn build_2048() {
    let map = brdf::glint::bumpy(2048, 2048, 0.25, 4.0, 1).unwrap();
    let t = std::time::Instant::now();
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let dt = t.elapsed();
    let m = mix.memory();
    let per = |b: usize| b as f64 / m.lobes as f64;
    println!(
        "build 2048² ({} samples/lobe): {:.2} s; bytes/lobe: lobes {:.1}, hierarchy {:.2}, mip {:.2}",
        mix.params().samples,
        dt.as_secs_f64(),
        per(m.lobe_bytes),
        per(m.hierarchy_bytes),
        per(m.mip_bytes)
    );
    // d() cost and hierarchy efficiency per footprint size.
    let mut rng = support::rng(3);
    for area in [1.0f32, 16.0, 256.0, 4096.0] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), area, 2048, 2048);
        let t = std::time::Instant::now();
        let patch = mix.patch_with(
            &fp,
            &PatchOptions {
                masking: MaskingMode::Exact,
                lod_lobes: f32::INFINITY,
                lod_tolerance: 0.0,
                ..PatchOptions::default()
            },
            None,
        );
        let t_patch = t.elapsed();
        let ms: Vec<Vec3> = (0..2000)
            .map(|_| patch.sample_normal(Vec2::new(rng.random(), rng.random())))
            .collect();
        let t = std::time::Instant::now();
        let mut touched = 0;
        for &m in &ms {
            touched += patch.d_with_stats(m).1;
        }
        let t_d = t.elapsed() / ms.len() as u32;
        let mut contributing = 0;
        for &m in ms.iter().take(200) {
            let d = patch.d(m) as f64;
            contributing += patch
                .weighted_lobes()
                .filter(|(w, g)| *w as f64 * g.d(m) as f64 > 1e-3 * d)
                .count();
        }
        let w = support::dir(60.0, 30.0);
        let t = std::time::Instant::now();
        let mut acc = 0.0;
        for _ in 0..100 {
            acc += patch.lambda(w);
        }
        let t_exact = t.elapsed() / 100;
        let approx = mix.patch_with(
            &fp,
            &PatchOptions {
                masking: MaskingMode::Approximate,
                lod_lobes: f32::INFINITY,
                lod_tolerance: 0.0,
                ..PatchOptions::default()
            },
            None,
        );
        let t = std::time::Instant::now();
        for _ in 0..100 {
            acc += approx.lambda(w);
        }
        let t_approx = t.elapsed() / 100;
        println!(
            "| {area} | {} | {:.1?} | {:.2?} | {:.1} | {:.1} | {:.2?} | {:.2?} |",
            patch.lobe_count(),
            t_patch,
            t_d,
            touched as f64 / ms.len() as f64,
            contributing as f64 / 200.0,
            t_exact,
            t_approx
        );
        assert!(acc.is_finite());
    }
}
