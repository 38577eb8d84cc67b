//! Bad input to the inverse bin map: invalid build parameters are refused, and degenerate footprints,
//! directions and random numbers give finite values and unit upper-hemisphere samples.

use crate::support;

use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{BinMap, Footprint, GlintNdf, bumpy};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use support::binmap::params;

#[test]
fn bad_input_is_total() {
    let map = bumpy(16, 16, 0.25, 4.0, 1).unwrap();
    for (n, leaf, sigma) in [
        (0, 16, 0.01),
        (8, 16, 0.01),
        (4097, 16, 0.01),
        (7, 0, 0.01),
        (7, 16, f32::NAN),
        (7, 16, 0.0),
    ] {
        let p = BinMapParams {
            bins_per_axis: n,
            leaf_size: leaf,
            sigma_min: sigma,
            ..BinMapParams::default()
        };
        assert!(BinMap::build(&map, p).is_err(), "{n} {leaf} {sigma}");
    }
    for sub in [0, 17] {
        let p = BinMapParams {
            subdivisions: sub,
            ..BinMapParams::default()
        };
        assert!(BinMap::build(&map, p).is_err(), "subdivisions {sub}");
    }
    let bm = BinMap::build(&map, params(1, 16, BinLookup::Hash)).unwrap();
    assert_eq!(bm.texels_of_bin(0).len(), 256);
    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let footprints = [
        Footprint::from_differentials(Vec2::new(f32::NAN, 0.5), Vec2::ZERO, Vec2::ZERO),
        Footprint::from_differentials(Vec2::new(0.5, 0.5), Vec2::new(f32::INFINITY, 0.0), Vec2::Y),
        Footprint::from_differentials(
            Vec2::new(0.5, 0.5),
            Vec2::new(1e6, 0.0),
            Vec2::new(0.0, 1e6),
        ),
        Footprint::from_differentials(
            Vec2::new(0.5, 0.5),
            Vec2::new(1.0, 1.0),
            Vec2::new(2.0, 2.0),
        ),
    ];
    let dirs = [
        Vec3::Z,
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 1e-30),
        support::dir(30.0, 20.0),
    ];
    for fp in &footprints {
        for patch in [
            bm.patch(fp),
            bm.patch_with(
                fp,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: 0.2,
                    ..Default::default()
                },
                None,
            ),
            bm.patch_with(
                fp,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: f32::NAN,
                    ..Default::default()
                },
                None,
            ),
        ] {
            let s: f64 = (0..bm.bins().len()).map(|b| patch.bin_mass(b)).sum();
            // Masses of a clamped footprint still sum to 1 (f64 sums: 1e-9).
            assert!((s - 1.0).abs() < 1e-9, "{fp:?}: Σ mass = {s}");
            for &m in &dirs {
                for v in [
                    patch.d(m),
                    patch.lambda(m),
                    patch.projected_area(m),
                    patch.visible_area(m),
                    patch.pdf_normal(m),
                    patch.pdf_visible(Vec3::Z, m),
                ] {
                    assert!(v.is_finite() && v >= 0.0, "{fp:?} {m}: {v}");
                }
            }
            for u in [
                Vec2::ZERO,
                Vec2::ONE,
                Vec2::splat(f32::NAN),
                Vec2::new(0.3, 0.9),
            ] {
                let m = patch.sample_normal(u);
                assert!(
                    m.is_finite() && m.z > 0.0 && (m.length() - 1.0).abs() < 1e-4,
                    "{m}"
                );
                for &wo in &dirs {
                    let m = patch.sample_visible(wo, u);
                    assert!(
                        m.is_finite() && m.z > 0.0 && (m.length() - 1.0).abs() < 1e-4,
                        "{wo} {u}: {m}"
                    );
                    let p = patch.pdf_visible(wo, m);
                    assert!(p.is_finite() && p >= 0.0, "{wo} {m}: {p}");
                }
            }
        }
    }
    // The trait object path.
    let p = GlintNdf::patch(&bm, &footprints[0]);
    assert!(p.d(Vec3::Z).is_finite());
}
