//! `GlintNdf::prepare` builds and measures what each model otherwise defers to its first large
//! footprint, and what it measures is what first use would (deterministic), through the registry.

use crate::support;

use brdf::Vec2;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, PositionNormalMap};

#[test]
fn prepare_measures_what_first_use_would() {
    let n = 128;
    let map = support::mixture::noise(n, 4);
    let pn = || PositionNormalMap::build(&map, PositionNormalParams::default()).unwrap();
    let mix = || BeckmannMixture::build(&map, MixtureParams::default()).unwrap();
    let bm = || BinMap::build(&map, BinMapParams::default()).unwrap();

    // Position-normal: nothing built before, the chain and the errors after.
    let prepared = GlintModel::from(pn());
    let GlintModel::PositionNormal(p) = &prepared else {
        unreachable!()
    };
    assert_eq!(p.memory().filtered_bytes, 0);
    prepared.prepare();
    assert!(p.memory().filtered_bytes > 0);
    let first_use = pn();
    let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), 8192.0, n, n);
    let _ = first_use.patch(&fp);
    assert_eq!(
        p.filtered_mixture_errors(),
        first_use.filtered_mixture_errors()
    );

    // The mixture and the bin map: the same errors as a fresh model's.
    let prepared = GlintModel::from(mix());
    prepared.prepare();
    let GlintModel::Mixture(m) = &prepared else {
        unreachable!()
    };
    assert_eq!(m.filtered_mixture_errors(), mix().filtered_mixture_errors());
    let prepared = GlintModel::from(bm());
    prepared.prepare();
    let GlintModel::BinMap(b) = &prepared else {
        unreachable!()
    };
    assert_eq!(b.moment_masking_errors(), bm().moment_masking_errors());
    assert!(b.moment_masking_errors().iter().any(|&e| e < 1.0));
}
