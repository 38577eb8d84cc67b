//! The inverse bin map's samplers against their densities: the bin-resolution normal and
//! visible-normal samplers (χ² on the bins' own cells) and the smoothed ones (the shared harness).

use crate::support;

use brdf::Vec2;
use brdf::glint::GlintNdf;
use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{BinMap, Footprint, bumpy};
use brdf::ndf::Ndf;
use rand::RngExt;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use support::binmap::params;
use support::chi2::Chi2;

#[test]
fn chi_square_of_the_bin_sampler() {
    // The bin-resolution sampler's density is piecewise constant over the bins, which the
    // harness's (z, φ) cells cut across; so the test runs on the bins themselves: (1) bin counts
    // against N mass_j (mass_j = pdf × |H|), pooled to expected ≥ 5; (2) the position inside the bin
    // cell against uniform on a 10 × 10 grid. 10⁶ draws, significance 0.01 Šidák-corrected over
    // the 2 × 3 tests.
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, params(63, 16, BinLookup::Dense)).unwrap();
    let bins = *bm.bins();
    let alpha = 1.0 - 0.99f64.powf(1.0 / 6.0);
    for (c, area) in [
        (Vec2::new(0.43, 0.57), 16.0),
        (Vec2::new(0.95, 0.02), 300.0),
        (Vec2::new(0.5, 0.5), 4096.0),
    ] {
        let patch = bm.patch(&Footprint::isotropic_texels(c, area, 64, 64));
        let n = 1_000_000usize;
        let mut counts = vec![0.0f64; bins.len()];
        let mut within = vec![0.0f64; 100];
        let mut rng = support::rng(17);
        for _ in 0..n {
            let m = patch.sample_normal(Vec2::new(rng.random(), rng.random()));
            assert!(m.is_finite() && m.z > 0.0);
            let b = bins.bin_of(m).unwrap();
            counts[b] += 1.0;
            let u = brdf::warp::hemisphere_to_square_equal_area(m) * bins.n() as f32;
            let (fx, fy) = (u.x.fract(), u.y.fract());
            within[((fy * 10.0) as usize).min(9) * 10 + ((fx * 10.0) as usize).min(9)] += 1.0;
        }
        let expected: Vec<f64> = (0..bins.len())
            .map(|b| n as f64 * patch.pdf_normal(bins.center(b)) as f64 * bins.solid_angle())
            .collect();
        let p1 = chi2_pvalue(&counts, &expected);
        let p2 = chi2_pvalue(&within, &vec![n as f64 / 100.0; 100]);
        assert!(p1 > alpha, "area {area}: bin counts p = {p1}");
        assert!(p2 > alpha, "area {area}: within-bin p = {p2}");
    }
}

/// Pearson's χ² p-value with cells of expected count < 5 pooled; a draw where nothing is
/// expected fails at once (p = 0).
fn chi2_pvalue(observed: &[f64], expected: &[f64]) -> f64 {
    let (mut stat, mut dof) = (0.0, 0usize);
    let (mut po, mut pe) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e <= 1e-9 {
            if o > 0.0 {
                return 0.0;
            }
            continue;
        }
        if e < 5.0 {
            po += o;
            pe += e;
            continue;
        }
        stat += (o - e) * (o - e) / e;
        dof += 1;
    }
    if pe > 0.0 {
        stat += (po - pe) * (po - pe) / pe;
        dof += 1;
    }
    let dist = ChiSquared::new((dof.max(2) - 1) as f64).unwrap();
    1.0 - dist.cdf(stat)
}

#[test]
fn chi_square_of_the_smoothed_sampler() {
    // Smooth density: the harness applies. 50 × 100 cells (each lobe of σ = 0.07 spans ~10 cells
    // in φ and z) and footprints of ≥ 16 texels; 4·10⁵ draws.
    // 15² bins keep the smoothed pdf's bin window (5.26 σ) small enough for 10⁵ pdf evaluations.
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, params(15, 16, BinLookup::Dense)).unwrap();
    for (k, area) in [16.0f32, 1024.0].into_iter().enumerate() {
        let patch = bm.patch_with(
            &Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, 64, 64),
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: 0.1,
                ..Default::default()
            },
            None,
        );
        let mut chi = Chi2::new(format!("binmap_smoothed_{k}"), 2);
        chi.res_z = 50;
        chi.res_phi = 100;
        chi.samples = 400_000;
        chi.run(
            |_, u| Some(patch.sample_normal(u)),
            |w| patch.pdf_normal(w) as f64,
        )
        .unwrap();
    }
}

/// χ² of the bin-resolution visible-normal sampler at θo up to 89°, in the equal-area square
/// (the map is measure preserving: density per unit square area = 2π × pdf per steradian): cells
/// are g × g sub-cells of every bin, aligned with the bins. Inside a bin the pdf is bilinear in the
/// cell coordinates, so its mean over an aligned sub-cell is its value at the sub-cell's centre:
/// the expected counts are exact (N |H|/g² pdf(centre)). Pooled to expected ≥ 5; a draw where the
/// pdf is 0 fails. 3·10⁵ draws per view (~300 per occupied cell at 64 texels), significance 0.01
/// Šidák-corrected over the family. Checked to fail when the pdf ignores the bilinear factor
/// (uniform within the bin).
#[test]
fn chi_square_of_the_visible_sampler() {
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let views = [
        (0.0, 0.0),
        (60.0, 210.0),
        (85.0, 210.0),
        (89.0, 210.0),
        (89.0, 30.0),
    ];
    let cases = [(63usize, 64.0f32, 1usize), (15, 16.0, 2)];
    let alpha = 1.0 - 0.99f64.powf(1.0 / (views.len() * cases.len()) as f64);
    for (n, area, sub) in cases {
        let p = BinMapParams {
            subdivisions: sub,
            ..params(n, 16, BinLookup::Dense)
        };
        let bm = BinMap::build(&map, p).unwrap();
        let bins = *bm.bins();
        let patch = bm.patch(&Footprint::isotropic_texels(
            Vec2::new(0.37, 0.61),
            area,
            64,
            64,
        ));
        let g = 4usize;
        let side = n * g;
        for (theta, phi) in views {
            let wo = support::dir(theta, phi);
            let draws = 300_000usize;
            let mut counts = vec![0.0f64; side * side];
            let mut rng = support::rng(23);
            for _ in 0..draws {
                let m = patch.sample_visible(wo, Vec2::new(rng.random(), rng.random()));
                assert!(m.is_finite() && m.z > 0.0, "{m}");
                let u = brdf::warp::hemisphere_to_square_equal_area(m) * side as f32;
                let (i, j) = ((u.x as usize).min(side - 1), (u.y as usize).min(side - 1));
                counts[j * side + i] += 1.0;
            }
            let cell = bins.solid_angle() / (g * g) as f64;
            let expected: Vec<f64> = (0..side * side)
                .map(|c| {
                    let (i, j) = (c % side, c / side);
                    let u = Vec2::new(
                        (i as f32 + 0.5) / side as f32,
                        (j as f32 + 0.5) / side as f32,
                    );
                    let m = brdf::warp::square_to_hemisphere_equal_area(u);
                    draws as f64 * cell * patch.pdf_visible(wo, m) as f64
                })
                .collect();
            let total: f64 = expected.iter().sum::<f64>() / draws as f64;
            // The pdf integrates to 1 (f32 pdf values summed over ≤ 10⁵ cells: 1e-4).
            assert!(
                (total - 1.0).abs() < 1e-4,
                "n={n} θo={theta}: ∫ pdf = {total}"
            );
            let p = chi2_pvalue(&counts, &expected);
            assert!(p > alpha, "n={n} θo={theta} φ={phi}: p = {p}");
        }
    }
}

#[test]
fn chi_square_of_the_smoothed_visible_sampler() {
    // Smooth density (a mixture of visible slope Gaussians): the shared harness, 50 × 100 cells,
    // 4·10⁵ draws, θo up to 89°. 15² bins keep the number of lobes small.
    let map = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let bm = BinMap::build(&map, params(15, 16, BinLookup::Dense)).unwrap();
    let patch = bm.patch_with(
        &Footprint::isotropic_texels(Vec2::new(0.37, 0.61), 16.0, 64, 64),
        &brdf::glint::binmap::PatchOptions {
            smoothing_alpha: 0.1,
            ..Default::default()
        },
        None,
    );
    let views = [(30.0, 210.0), (85.0, 210.0), (89.0, 210.0)];
    for (k, (theta, phi)) in views.into_iter().enumerate() {
        let wo = support::dir(theta, phi);
        let mut chi = Chi2::new(format!("binmap_smoothed_visible_{k}"), views.len());
        chi.res_z = 50;
        chi.res_phi = 100;
        chi.samples = 400_000;
        chi.run(
            |_, u| Some(patch.sample_visible(wo, u)),
            |w| patch.pdf_visible(wo, w) as f64,
        )
        .unwrap();
    }
}
