//! The position-normal map's filtered mixture (src/glint/position_normal/filtered.rs): when the
//! options serve it, both samplers against their pdfs, the white furnace in the renderer's
//! measure, its measured error against the element sum's, and its distance to the σ_r-convolved
//! truth against the element sum's.

use crate::support;

use brdf::Vec2;
use brdf::bxdf::MicrofacetBrdf;
use brdf::fresnel::NoFresnel;
use brdf::glint::position_normal::{PatchOptions, PositionNormalParams};
use brdf::glint::{Footprint, GlintNdf, PositionNormalMap};

const N: usize = 128;

fn forced() -> PatchOptions {
    PatchOptions {
        filtered_area: 0.0,
        filtered_tolerance: f32::INFINITY,
        ..PatchOptions::default()
    }
}

fn exact() -> PatchOptions {
    PatchOptions {
        filtered_area: f32::INFINITY,
        max_query_texels: f32::INFINITY,
        cut_nodes: 0,
        ..PatchOptions::default()
    }
}

fn build(map: &brdf::glint::NormalMap) -> PositionNormalMap {
    PositionNormalMap::build(map, PositionNormalParams::default()).unwrap()
}

/// The patch serves the filtered mixture exactly where its options say: at least
/// `filtered_area` and a measured error within `filtered_tolerance` (NaN options never); the
/// measured errors are TVs in [0, 1], 1 below the first measured level; the chain is built (and its
/// memory reported) with the map.
#[test]
fn served_where_the_options_say() {
    let map = support::mixture::noise(N, 4);
    let pn = build(&map);
    assert!(pn.memory().filtered_bytes > 0);
    let errors = pn.filtered_mixture_errors().to_vec();
    println!("measured errors per level: {errors:?}");
    assert!(!errors.is_empty());
    assert!(errors.iter().all(|e| (0.0..=1.0).contains(e)));
    assert_eq!(errors[0], 1.0);
    let fp = |area: f32| Footprint::isotropic_texels(Vec2::new(0.3, 0.6), area, N, N);
    let e4 = errors[4];
    let opts = |area: f32, tol: f32| PatchOptions {
        filtered_area: area,
        filtered_tolerance: tol,
        ..PatchOptions::default()
    };
    let served =
        |area: f32, o: PatchOptions| pn.patch_with(&fp(area), &o, None).is_filtered_mixture();
    // Level 4: footprints of 256 elements.
    assert!(served(256.0, opts(256.0, e4)));
    assert!(!served(256.0, opts(256.0, 0.99 * e4)));
    assert!(!served(256.0, opts(257.0, 1.0)));
    assert!(!served(256.0, opts(f32::NAN, 1.0)));
    assert!(!served(256.0, opts(0.0, f32::NAN)));
    assert!(served(4.0, forced()));
    let p = pn.patch_with(&fp(256.0), &forced(), None);
    assert_eq!(p.element_count(), 0);
    assert_eq!(p.query_scale(), 1.0);
    assert!(p.weighted_lobes().count() > 1);
    // Below the default area the element sum serves.
    assert!(!pn.patch(&fp(1024.0)).is_filtered_mixture());
}

/// Both samplers of a filtered-mixture patch against their pdfs (chi-square; the harness's default
/// cells), on the white-noise map, at two views.
#[test]
fn chi_square_of_the_filtered_mixture() {
    let map = support::mixture::noise(N, 4);
    let pn = build(&map);
    let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.71), 300.0, N, N);
    let patch = pn.patch_with(&fp, &forced(), None);
    assert!(patch.is_filtered_mixture());
    assert!(patch.weighted_lobes().count() > 4);
    support::chi2_few_lobe_samplers(&patch, "position-normal filtered mixture", &[30.0, 75.0]);
}

/// White furnace in the renderer's measure (F = 1): the mean of `sample().weight()` ≤ 1 + 4
/// standard errors and equal to the quadrature of eval · cos θi, on a smooth map at a grazing view
/// and a sparse one at an oblique view; [`furnace_of_the_filtered_mixture_sweep`] takes three views
/// on both.
#[test]
fn furnace_of_the_filtered_mixture() {
    furnace_of_the_filtered_mixture_at(&[(0, 75.0), (1, 45.0)]);
}

/// [`furnace_of_the_filtered_mixture`] at θo 0°, 45° and 75° on both maps: `cargo test --release
/// --test it -- --ignored position_normal_filtered::furnace_of_the_filtered_mixture_sweep`.
#[test]
#[ignore]
fn furnace_of_the_filtered_mixture_sweep() {
    let cases: Vec<(usize, f64)> = (0..2)
        .flat_map(|m| [0.0, 45.0, 75.0].map(|t| (m, t)))
        .collect();
    furnace_of_the_filtered_mixture_at(&cases);
}

/// The furnaces at each (map: 0 the first procedural map, 1 the third; θo in degrees) of `cases`.
fn furnace_of_the_filtered_mixture_at(cases: &[(usize, f64)]) {
    let mut rng = support::rng(8);
    for (i, (name, map)) in support::procedural_maps(N)
        .into_iter()
        .step_by(2)
        .enumerate()
    {
        let pn = build(&map);
        let fp = Footprint::isotropic_texels(Vec2::new(0.52, 0.28), 1024.0, N, N);
        let patch = pn.patch_with(&fp, &forced(), None);
        assert!(patch.is_filtered_mixture());
        let brdf = MicrofacetBrdf::new(&patch, NoFresnel);
        let thetas = cases.iter().filter(|c| c.0 == i).map(|c| c.1);
        support::bxdf::assert_half_vector_furnaces(&brdf, thetas, &mut rng, name);
    }
}

/// At the default area the filtered mixture stays near the element sum it replaces, measured
/// against the σ_r-convolved truth (TV on 63² bins, per map printed): where the default serves it,
/// its TV to the truth is within its measured error of the element sum's.
#[test]
fn within_its_measured_error_of_the_element_sum() {
    use brdf::glint::{HemisphereBins, Kernel, bin_masses, convolved_pndf};
    let n = 256;
    let bins = HemisphereBins::new(63).unwrap();
    let sigma = PositionNormalParams::DEFAULT_SIGMA_R as f64;
    let mut served = 0;
    for (name, map) in support::procedural_maps(n) {
        let pn = build(&map);
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 4096.0, n, n);
        let truth = convolved_pndf(&map, &fp, Kernel::Gaussian, &bins, 400_000, 5, sigma).unwrap();
        let default = pn.patch(&fp);
        let full = pn.patch_with(&fp, &exact(), None);
        let few = pn.patch_with(&fp, &forced(), None);
        let a = truth.tv_to_masses(&bin_masses(&few, &bins, 4)).unwrap();
        let b = truth.tv_to_masses(&bin_masses(&full, &bins, 4)).unwrap();
        let e = pn.filtered_mixture_errors()[6];
        println!(
            "{name}: TV to truth filtered mixture {a:.3}, element sum {b:.3}; measured error {e:.3}; \
             default serves the filtered mixture: {}",
            default.is_filtered_mixture()
        );
        if default.is_filtered_mixture() {
            served += 1;
            assert!(a <= b + e as f64 + 0.02, "{name}: {a} > {b} + {e}");
        }
    }
    assert!(
        served >= 2,
        "the default served the filtered mixture on {served} maps"
    );
}
