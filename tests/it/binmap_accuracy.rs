//! The inverse bin map against the ground truth: D cos θ integrates to one (plain and smoothed), the
//! distance to the parallelogram-kernel truth on the same bins, its convergence with the sub-texel
//! resolution, exact masses on another grid, and (ignored) the accuracy tables of docs/results.md.

use crate::support;

use brdf::Vec2;
use brdf::frame::slope_to_normal;
use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{
    BinMap, BinMapPatch, Footprint, HemisphereBins, Kernel, binned_pndf, bumpy, tv_distance,
};
use brdf::ndf::Ndf;
use support::binmap::params;

/// ∫ D cos θ dω by the midpoint rule on a k × k grid per bin of the equal-area square
/// (solid angle = 2π × square area), the bin map's D being constant per bin.
fn integral_d_cos(ndf: &impl Ndf, bins: &HemisphereBins, k: usize) -> f64 {
    let n = bins.n() * k;
    let mut s = 0.0;
    for j in 0..n {
        for i in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let w = brdf::warp::square_to_hemisphere_equal_area(u);
            s += ndf.d(w) as f64 * w.z as f64;
        }
    }
    s * std::f64::consts::TAU / (n * n) as f64
}

#[test]
fn d_cos_integrates_to_one() {
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, params(31, 16, BinLookup::Dense)).unwrap();
    for (c, area) in [
        (Vec2::new(0.43, 0.57), 1.0),
        (Vec2::new(0.99, 0.01), 50.0),
        (Vec2::new(0.3, 0.3), 9000.0),
    ] {
        let patch = bm.patch(&Footprint::isotropic_texels(c, area, 64, 64));
        let (i4, i8) = (
            integral_d_cos(&patch, bm.bins(), 4),
            integral_d_cos(&patch, bm.bins(), 8),
        );
        // The midpoint rule is exact for the piecewise-constant D and second order in the smooth
        // cos θ: its error is below 2|I8 − I4| (Richardson), plus f32 rounding of D (1e-6).
        let tol = 2.0 * (i8 - i4).abs() + 1e-5;
        assert!((i8 - 1.0).abs() <= tol, "area {area}: {i8} (I4 = {i4})");
    }
}

#[test]
fn smoothed_d_cos_integrates_to_one() {
    // In slope space D cos θ dω = D cos⁴θ ds = Σ mass_j N(s; c_j, σ²) ds: the trapezoid rule on a
    // grid of step ≤ σ/2 converges exponentially for Gaussians (aliasing error < 1e-10).
    let map = bumpy(32, 32, 0.2, 4.0, 2).unwrap();
    let bm = BinMap::build(&map, params(31, 16, BinLookup::Dense)).unwrap();
    let alpha = 0.15f32;
    let sigma = alpha as f64 / 2f64.sqrt();
    let patch = bm.patch_with(
        &Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 64.0, 32, 32),
        &brdf::glint::binmap::PatchOptions {
            smoothing_alpha: alpha,
            ..Default::default()
        },
        None,
    );
    let step = sigma / 2.0;
    let ext = 2.0;
    let nstep = (2.0 * ext / step) as i64;
    let mut s = 0.0;
    for j in 0..=nstep {
        for i in 0..=nstep {
            let sl = Vec2::new(
                (-ext + i as f64 * step) as f32,
                (-ext + j as f64 * step) as f32,
            );
            let m = slope_to_normal(sl);
            s += patch.d(m) as f64 * (m.z as f64).powi(4);
        }
    }
    s *= step * step;
    // Mass beyond |s| = 2 (the map's slopes are ≤ ~1, plus 5σ): < 1e-6; the truncation of each
    // lobe at 5.26σ: ≤ 1e-6; f32 D: 1e-6.
    assert!((s - 1.0).abs() < 1e-4, "∫ D cos = {s}");
}

#[test]
fn ground_truth_on_the_same_bins() {
    // The reference with the parallelogram kernel, tabulated on the bin map's own bins: the only
    // differences are the reference's interpolated normals (vs texel-centre normals) and its noise.
    // On a smooth map and a large footprint both see the same slope distribution.
    let map = bumpy(64, 64, 0.2, 8.0, 5).unwrap();
    let bm = BinMap::build(&map, params(31, 16, BinLookup::Dense)).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 1024.0, 64, 64);
    let reference = binned_pndf(&map, &fp, Kernel::Parallelogram, bm.bins(), 1_000_000, 3);
    let tv = tv_distance(&bm.patch(&fp), &reference, 16);
    println!("TV {tv:.4}, reference noise {:.4}", reference.tv_error());
    // Measured 0.039 (reference noise 0.0008); interpolation moves mass by about one bin at most
    // on this smooth map. A regression bound of 0.06 (1.5× the measured value), not a physical
    // limit.
    assert!(tv < 0.06, "TV = {tv}");
}

/// Sub-texel binning converges to the interpolated surface's P-NDF: the TV distance to the
/// parallelogram-kernel ground truth on the bin map's own bins falls as s grows, towards the
/// reference's noise.
#[test]
fn subtexel_binning_converges_to_the_interpolated_surface() {
    let map = bumpy(32, 32, 0.25, 4.0, 1).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 16.0, 32, 32);
    let mut tvs = vec![];
    for sub in [1usize, 2, 4, 8] {
        let p = BinMapParams {
            subdivisions: sub,
            ..params(31, 16, BinLookup::Dense)
        };
        let bm = BinMap::build(&map, p).unwrap();
        let reference = binned_pndf(&map, &fp, Kernel::Parallelogram, bm.bins(), 1_000_000, 3);
        let tv = tv_distance(&bm.patch(&fp), &reference, 8);
        println!(
            "s = {sub}: TV {tv:.4} (reference noise {:.4})",
            reference.tv_error()
        );
        tvs.push((tv, reference.tv_error()));
    }
    for w in tvs.windows(2) {
        // Each doubling of s must lower the distance by more than the two references' noise.
        assert!(
            w[1].0 < w[0].0 - (w[0].1 + w[1].1),
            "no convergence: {tvs:?}"
        );
    }
    // Measured: 0.570, 0.229, 0.082, 0.028 for s = 1, 2, 4, 8 (noise 0.0005; 0.230, 0.072, 0.024
    // with the sub-texel centres before the n-rooks points): about 3× per doubling. A quarter of s = 1's distance at s = 8 is a regression bound far from that.
    assert!(tvs[3].0 < 0.25 * tvs[0].0, "s = 8 vs s = 1: {tvs:?}");
}

/// TV distance ½ Σ_r |M(r) − mass_ref(r)| on the reference's bins with the bin map's masses M(r)
/// integrated exactly over each reference bin ([`BinMapPatch::masses_on`]): the measure of
/// docs/binmap.md, "Measuring against a ground truth".
fn tv_exact(patch: &BinMapPatch, reference: &brdf::glint::BinnedPndf) -> f64 {
    let m = patch.masses_on(reference.bins()).expect("unsmoothed patch");
    0.5 * m
        .iter()
        .zip(reference.mass())
        .map(|(a, b)| (a - b).abs())
        .sum::<f64>()
}

/// `masses_on` against independent closed forms. (1) Aligned grids: with 15² map bins and a 45²
/// grid every map bin is exactly 3 × 3 grid bins, so grid bin r inside map bin j must receive
/// mass_j · c̄_r |R| / (c̄_j |H|) = mass_j c̄_r / (9 c̄_j), the mean cosines from
/// `HemisphereBins::mean_cos` (exact); f64 rounding only: 1e-12. (2) The map's own grid returns
/// `bin_mass`. (3) On a non-aligned grid (64² against 127² map bins) the masses sum to 1 (f64
/// rounding: 1e-9) and agree with a fine midpoint rule of D cos θ (32 × 32 points per grid bin,
/// ≈ 16 × 16 per map bin): the midpoint rule can only misplace the points along a map bin's
/// boundary, and the measured difference (printed) is far below the regression bound 0.1. A smoothed
/// patch has no piecewise-constant D: `None`.
#[test]
fn exact_masses_on_another_grid() {
    let map = bumpy(32, 32, 0.25, 4.0, 1).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 64.0, 32, 32);
    let bm = BinMap::build(&map, params(15, 16, BinLookup::Dense)).unwrap();
    let patch = bm.patch(&fp);
    let fine = HemisphereBins::new(45).unwrap();
    let m = patch.masses_on(&fine).unwrap();
    let mut checked = 0;
    for (r, &got) in m.iter().enumerate() {
        let (ri, rj) = fine.cell(r);
        let j = (rj / 3) * 15 + ri / 3;
        let want = patch.bin_mass(j) * fine.mean_cos(r) / (9.0 * bm.bins().mean_cos(j));
        assert!((got - want).abs() < 1e-12, "grid bin {r}: {got} vs {want}");
        checked += (want > 0.0) as usize;
    }
    assert!(checked > 9, "only {checked} grid bins with mass");
    let own = patch.masses_on(bm.bins()).unwrap();
    for (j, &got) in own.iter().enumerate() {
        assert!((got - patch.bin_mass(j)).abs() < 1e-12, "own bin {j}");
    }
    assert!(
        bm.patch_with(
            &fp,
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: 0.1,
                ..Default::default()
            },
            None
        )
        .masses_on(&fine)
        .is_none()
    );
    // (3) Non-aligned, at the default 127² bins.
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let patch = bm.patch(&fp);
    let grid = HemisphereBins::new(64).unwrap();
    let m = patch.masses_on(&grid).unwrap();
    let sum: f64 = m.iter().sum();
    assert!((sum - 1.0).abs() < 1e-9, "Σ = {sum}");
    let k = 32;
    let mid: Vec<f64> = (0..grid.len())
        .map(|r| {
            let mut s = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                    let w = grid.sample_in_bin(r, u);
                    s += patch.d(w) as f64 * w.z as f64;
                }
            }
            s * grid.solid_angle() / (k * k) as f64
        })
        .collect();
    let diff = 0.5 * m.iter().zip(&mid).map(|(a, b)| (a - b).abs()).sum::<f64>();
    println!("½ Σ |exact − midpoint 32²| = {diff:.4}");
    assert!(diff < 0.1, "exact vs fine midpoint: {diff}");
}

/// Accuracy against the ground truth, beside the Beckmann mixture's table (same maps, footprints,
/// reference bins). Command:
/// `cargo test --release --test it -- --ignored binmap_accuracy::accuracy_table --nocapture`
#[test]
#[ignore]
fn accuracy_table() {
    let n = 256;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | TV bins, Gaussian ref. | TV bins, parallelogram ref. | TV α = 0.02, parallelogram ref. | TV mask lobe, Gaussian ref. | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, map) in &maps {
        let bm = BinMap::build(map, BinMapParams::default()).unwrap();
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let gauss = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let para = binned_pndf(map, &fp, Kernel::Parallelogram, &bins, 4_000_000, 17);
            let patch = bm.patch(&fp);
            let smooth = bm.patch_with(
                &fp,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: 0.02,
                    ..Default::default()
                },
                None,
            );
            // 8 × 8 midpoints per reference bin: each 64²-bin covers ~4 of the bin map's 127² bins.
            let sub = 64;
            println!(
                "| {name} | {area} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |",
                tv_distance(&patch, &gauss, sub),
                tv_distance(&patch, &para, sub),
                tv_distance(&smooth, &para, sub),
                tv_distance(patch.masking_lobe(), &gauss, sub),
                gauss.tv_error().max(para.tv_error()),
            );
        }
    }
}

/// Accuracy against memory for the sub-texel resolution s = 1, 2, 4 (docs/results.md, "Sub-texel
/// binning"): TV against the parallelogram-kernel ground truth (256² procedural maps, 64² reference
/// bins, 4·10⁶ positions, the accuracy table's settings) and bytes per texel at 1024² (bumpy).
/// Command: `cargo test --test it -- --ignored binmap_accuracy::subtexel_table --nocapture`
#[test]
#[ignore]
fn subtexel_table() {
    let n = 256;
    let maps = support::procedural_maps(n);
    let ref_bins = HemisphereBins::new(64).unwrap();
    // (s, bins per axis): the sub-texel sweep at the default 127² bins, then s = 1, 2 at 255².
    let configs = [(1usize, 127usize), (2, 127), (4, 127), (1, 255), (2, 255)];
    let models: Vec<Vec<BinMap>> = maps
        .iter()
        .map(|(_, map)| {
            configs
                .iter()
                .map(|&(s, n)| {
                    let p = BinMapParams {
                        subdivisions: s,
                        bins_per_axis: n,
                        ..BinMapParams::default()
                    };
                    BinMap::build(map, p).unwrap()
                })
                .collect()
        })
        .collect();
    println!(
        "| map | footprint (texels) | s = 1 | s = 2 | s = 4 | s = 1, 255² | s = 2, 255² | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for ((name, map), bms) in maps.iter().zip(&models) {
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let para = binned_pndf(map, &fp, Kernel::Parallelogram, &ref_bins, 4_000_000, 17);
            let tvs: Vec<String> = bms
                .iter()
                .map(|bm| format!("{:.3}", tv_distance(&bm.patch(&fp), &para, 64)))
                .collect();
            println!(
                "| {name} | {area} | {} | {:.3} |",
                tvs.join(" | "),
                para.tv_error()
            );
        }
    }
    let big = bumpy(1024, 1024, 0.25, 4.0, 1).unwrap();
    println!("| s | bins | 𝓑 | 𝓑⁻¹ | forest | other | total (B/texel) | build (s) |");
    println!("|---|---|---|---|---|---|---|---|");
    for (s, n) in configs {
        let t = std::time::Instant::now();
        let bm = BinMap::build(
            &big,
            BinMapParams {
                subdivisions: s,
                bins_per_axis: n,
                ..BinMapParams::default()
            },
        )
        .unwrap();
        let dt = t.elapsed().as_secs_f64();
        let m = bm.memory();
        let tex = (1024 * 1024) as f64;
        println!(
            "| {s} | {n}² | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {dt:.2} |",
            m.bin_map as f64 / tex,
            m.inverse as f64 / tex,
            m.forest as f64 / tex,
            (m.lookup + m.bin_tables + m.moments) as f64 / tex,
            m.total() as f64 / tex
        );
    }
}

/// The measure and the model (docs/results.md, "Inverse bin map (Atanasov 2020)"): TV against the
/// parallelogram-kernel ground truth (256² procedural maps, footprints at uv (0.43, 0.57), 64²
/// reference bins, 4·10⁶ positions), with the midpoint rule of `tv_distance` (8 × 8 points per
/// reference bin, the measure of the tables before) and with the exact overlaps (`masses_on`), for
/// bin counts and sub-texel resolutions; then bytes per texel at 1024² and 2048² (bumpy).
/// Command: `cargo test --test it -- --ignored binmap_accuracy::exact_measure_table --nocapture`
#[test]
#[ignore]
fn exact_measure_table() {
    let n = 256;
    let maps = support::procedural_maps(n);
    let ref_bins = HemisphereBins::new(64).unwrap();
    let configs = [
        (1usize, 127usize),
        (2, 127),
        (4, 127),
        (1, 255),
        (2, 191),
        (2, 255),
        (3, 255),
        (2, 383),
    ];
    let header: Vec<String> = configs
        .iter()
        .map(|(s, b)| format!("s = {s}, {b}²"))
        .collect();
    println!(
        "| map | footprint (texels) | {} | reference noise |",
        header.join(" | ")
    );
    println!("|---|---|{}---|", "---|".repeat(configs.len()));
    for (name, map) in &maps {
        let bms: Vec<BinMap> = configs
            .iter()
            .map(|&(s, b)| {
                let p = BinMapParams {
                    subdivisions: s,
                    bins_per_axis: b,
                    ..BinMapParams::default()
                };
                BinMap::build(map, p).unwrap()
            })
            .collect();
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let para = binned_pndf(map, &fp, Kernel::Parallelogram, &ref_bins, 4_000_000, 17);
            let tvs: Vec<String> = bms
                .iter()
                .map(|bm| {
                    let p = bm.patch(&fp);
                    format!(
                        "{:.3} / {:.3}",
                        tv_distance(&p, &para, 64),
                        tv_exact(&p, &para)
                    )
                })
                .collect();
            println!(
                "| {name} | {area} | {} | {:.3} |",
                tvs.join(" | "),
                para.tv_error()
            );
        }
    }
    for side in [1024usize, 2048] {
        let big = bumpy(side, side, 0.25, 4.0, 1).unwrap();
        println!("| s | bins | 𝓑 | 𝓑⁻¹ | forest | other | total (B/texel) at {side}² |");
        println!("|---|---|---|---|---|---|---|");
        for (s, b) in configs {
            let bm = BinMap::build(
                &big,
                BinMapParams {
                    subdivisions: s,
                    bins_per_axis: b,
                    ..BinMapParams::default()
                },
            )
            .unwrap();
            let m = bm.memory();
            let tex = (side * side) as f64;
            println!(
                "| {s} | {b}² | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |",
                m.bin_map as f64 / tex,
                m.inverse as f64 / tex,
                m.forest as f64 / tex,
                (m.lookup + m.bin_tables + m.moments) as f64 / tex,
                m.total() as f64 / tex
            );
        }
    }
}
