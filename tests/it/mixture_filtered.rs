//! The mixture's filtered mixture (src/glint/kernels/gmm.rs, filtered_error.rs): when the default
//! options serve it, both samplers against their pdfs, the white furnace in the renderer's
//! measure, its measured error, and its distance to the σ_ε-convolved truth against the single
//! filtered lobe's.

use crate::support;

use brdf::Vec2;
use brdf::bxdf::MicrofacetBrdf;
use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::{LobeStorage, MixtureParams, PatchOptions};
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf};

const N: usize = 128;

fn forced() -> PatchOptions {
    PatchOptions {
        filtered_area: 0.0,
        filtered_tolerance: f32::INFINITY,
        sub_texel_area: 0.0,
        ..PatchOptions::default()
    }
}

/// The patch serves the filtered mixture exactly where its options say: at least
/// `filtered_area` and a measured error within `filtered_tolerance`; never under compact storage;
/// the measured errors are TVs in [0, 1], 1 below the first measured level.
#[test]
fn served_where_the_options_say() {
    let map = support::mixture::noise(N, 4);
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let errors = mix.filtered_mixture_errors().to_vec();
    println!("measured errors per level: {errors:?}");
    assert!(!errors.is_empty());
    assert!(errors.iter().all(|e| (0.0..=1.0).contains(e)));
    assert_eq!(errors[0], 1.0);
    let fp = |area: f32| Footprint::isotropic_texels(Vec2::new(0.3, 0.6), area, N, N);
    // Level 4 (256 texels): measured.
    let e4 = errors[4];
    let opts = |area: f32, tol: f32| PatchOptions {
        filtered_area: area,
        filtered_tolerance: tol,
        ..PatchOptions::default()
    };
    assert!(
        mix.patch_with(&fp(256.0), &opts(256.0, e4), None)
            .is_filtered_mixture()
    );
    assert!(
        !mix.patch_with(&fp(256.0), &opts(256.0, 0.99 * e4), None)
            .is_filtered_mixture()
    );
    assert!(
        !mix.patch_with(&fp(256.0), &opts(257.0, 1.0), None)
            .is_filtered_mixture()
    );
    assert!(
        mix.patch_with(&fp(256.0), &forced(), None)
            .is_filtered_mixture()
    );
    let compact = BeckmannMixture::build(
        &map,
        MixtureParams {
            storage: LobeStorage::Compact,
            ..MixtureParams::default()
        },
    )
    .unwrap();
    assert!(compact.filtered_mixture_errors().is_empty());
    let p = compact.patch_with(&fp(256.0), &forced(), None);
    assert!(!p.is_filtered_mixture() && p.is_filtered_lobe());
}

/// Both samplers of a filtered-mixture patch against their pdfs (chi-square; the harness's default
/// cells), on the white-noise map, at two views.
#[test]
fn chi_square_of_the_filtered_mixture() {
    let map = support::mixture::noise(N, 4);
    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let fp = Footprint::isotropic_texels(Vec2::new(0.37, 0.71), 300.0, N, N);
    let patch = mix.patch_with(&fp, &forced(), None);
    assert!(patch.is_filtered_mixture());
    assert!(
        patch.few_lobes().count() > 4,
        "{}",
        patch.few_lobes().count()
    );
    support::chi2_few_lobe_samplers(&patch, "filtered mixture", &[30.0, 75.0]);
}

/// White furnace in the renderer's measure (F = 1): the mean of `sample().weight()` ≤ 1 + 4
/// standard errors and equal to the quadrature of eval · cos θi, on a smooth map at a grazing view
/// and a sparse one at an oblique view; [`furnace_of_the_filtered_mixture_sweep`] takes three views
/// on both.
#[test]
fn furnace_of_the_filtered_mixture() {
    furnace_of_the_filtered_mixture_at(&[(0, 75.0), (1, 45.0)]);
}

/// [`furnace_of_the_filtered_mixture`] at θo 0°, 45° and 75° on both maps:
/// `cargo test --release --test it -- --ignored mixture_filtered::furnace_of_the_filtered_mixture_sweep`.
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
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        let fp = Footprint::isotropic_texels(Vec2::new(0.52, 0.28), 1024.0, N, N);
        let patch = mix.patch_with(&fp, &forced(), None);
        assert!(patch.is_filtered_mixture());
        let brdf = MicrofacetBrdf::new(&patch, NoFresnel);
        let thetas = cases.iter().filter(|c| c.0 == i).map(|c| c.1);
        support::bxdf::assert_half_vector_furnaces(&brdf, thetas, &mut rng, name);
    }
}

/// At large footprints the filtered mixture is closer to the σ_ε-convolved truth than the single
/// filtered lobe it generalises (TV on 63² bins, summed over the four procedural maps; per map
/// printed).
#[test]
fn closer_to_the_truth_than_the_filtered_lobe() {
    use brdf::glint::{HemisphereBins, Kernel, bin_masses, convolved_pndf};
    let n = 256;
    let bins = HemisphereBins::new(63).unwrap();
    let sigma = brdf::ndf::DEFAULT_SIGMA_MIN as f64;
    // Compact storage has no filtered mixture: past the cost cap it serves the filtered lobe.
    let lobe = PatchOptions {
        lod_lobes: 0.0,
        sub_texel_area: 0.0,
        ..PatchOptions::default()
    };
    let compact = MixtureParams {
        storage: LobeStorage::Compact,
        ..MixtureParams::default()
    };
    let (mut sum_mix, mut sum_lobe) = (0.0, 0.0);
    for (name, map) in support::procedural_maps(n) {
        let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
        let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), 4096.0, n, n);
        let truth = convolved_pndf(&map, &fp, Kernel::Gaussian, &bins, 400_000, 5, sigma).unwrap();
        let few = mix.patch_with(&fp, &forced(), None);
        let single = BeckmannMixture::build(&map, compact).unwrap();
        let one = single.patch_with(&fp, &lobe, None);
        assert!(few.is_filtered_mixture() && one.is_filtered_lobe());
        let a = truth.tv_to_masses(&bin_masses(&few, &bins, 4)).unwrap();
        let b = truth.tv_to_masses(&bin_masses(&one, &bins, 4)).unwrap();
        println!("{name}: TV filtered mixture {a:.3}, filtered lobe {b:.3}");
        sum_mix += a;
        sum_lobe += b;
    }
    assert!(sum_mix < sum_lobe, "{sum_mix} ≥ {sum_lobe}");
}
