//! A model holds what its level of detail reads from the build on: the filtered chains and the
//! measured errors exist before any footprint asks, and no query changes them (no state filled on
//! first use; the same values after a footprint of every size and in a fresh build).

use crate::support;

use brdf::Vec2;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, Footprint, GlintNdf, PositionNormalMap};

/// Footprints from one texel to the whole 128² map.
fn footprints(n: usize) -> Vec<Footprint> {
    [1.0f32, 64.0, 1024.0, 8192.0, 16384.0]
        .iter()
        .map(|&a| Footprint::isotropic_texels(Vec2::new(0.3, 0.6), a, n, n))
        .collect()
}

#[test]
fn the_build_measures_what_the_level_of_detail_reads() {
    let n = 128;
    let map = support::mixture::noise(n, 4);

    let pn = PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
    let (bytes, errors) = (pn.memory(), pn.filtered_mixture_errors().to_vec());
    assert!(bytes.filtered_bytes > 0, "the chain is built with the map");
    assert!(errors.iter().any(|&e| e < 1.0), "{errors:?}");
    for fp in footprints(n) {
        let _ = pn.patch(&fp);
    }
    assert_eq!(pn.memory(), bytes);
    assert_eq!(pn.filtered_mixture_errors(), errors);

    let mix = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let errors = mix.filtered_mixture_errors().to_vec();
    assert!(errors.iter().any(|&e| e < 1.0), "{errors:?}");
    for fp in footprints(n) {
        let _ = mix.patch(&fp);
    }
    assert_eq!(mix.filtered_mixture_errors(), errors);
    let again = BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    assert_eq!(again.filtered_mixture_errors(), errors, "deterministic");

    let bm = BinMap::build(&map, BinMapParams::default()).unwrap();
    let errors = bm.moment_masking_errors().to_vec();
    assert!(errors.iter().any(|&e| e < 1.0), "{errors:?}");
    for fp in footprints(n) {
        let _ = bm.patch(&fp);
    }
    assert_eq!(bm.moment_masking_errors(), errors);
}
