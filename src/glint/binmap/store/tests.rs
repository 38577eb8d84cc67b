//! Unit tests of the bin map's store: the divisor's arithmetic and the load of a legacy moment
//! chain.

use super::Divisor;
use crate::glint::binmap::{BinMap, BinMapParams};
use crate::glint::surface::MomentPyramid;

/// A file whose chain starts at level 2 (the map's own slopes: the format's older layout) loads
/// with the chain a build makes and its errors measured again.
#[test]
fn a_legacy_moment_chain_is_rebuilt_on_load() {
    let map = crate::glint::bumpy(48, 48, 0.25, 4.0, 3).unwrap();
    let built = BinMap::build(&map, BinMapParams::default()).unwrap();
    let mut legacy = built.clone();
    legacy.moments = MomentPyramid::build_from(48, 48, map.slopes(), 2);
    legacy.moment_masking_error = vec![0.5; built.moment_masking_error.len()];
    let mut file = Vec::new();
    legacy.save(&mut file).unwrap();
    let loaded = BinMap::load(&mut file.as_slice()).unwrap();
    let ((lf, ll), (bf, bl)) = (loaded.moments.parts(), built.moments.parts());
    assert_eq!((lf, ll.len()), (bf, bl.len()));
    assert_eq!(lf, 1);
    for (a, b) in ll.iter().zip(bl) {
        assert_eq!(a.data, b.data);
    }
    assert_eq!(
        loaded.moment_masking_errors(),
        built.moment_masking_errors()
    );
    // The current layout loads as saved.
    let mut file = Vec::new();
    built.save(&mut file).unwrap();
    let again = BinMap::load(&mut file.as_slice()).unwrap();
    assert_eq!(again.moments.parts().1[0].data, bl[0].data);
}

#[test]
fn divisor_matches_hardware_division() {
    let ds = [
        1u32,
        2,
        3,
        7,
        255,
        256,
        510,
        4095,
        4096,
        65_537,
        1 << 31,
        u32::MAX - 1,
        u32::MAX,
    ];
    let ns = [
        0u32,
        1,
        2,
        4095,
        4096,
        16_777_215,
        1 << 31,
        u32::MAX - 1,
        u32::MAX,
    ];
    for &d in &ds {
        let v = Divisor::new(d);
        for &n in ns
            .iter()
            .chain(&[d - 1, d, d.wrapping_add(1), d.wrapping_mul(3)])
        {
            assert_eq!(v.rem_div(n), (n % d, n / d), "{n} / {d}");
        }
    }
}
