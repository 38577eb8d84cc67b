//! Shared helpers of the inverse bin map tests (tests/it/binmap_*.rs): build parameters with one element
//! per texel and the small test maps.

use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::{FlakesParams, NormalMap, ScratchedParams, bumpy, flakes, scratched};

/// Parameters with one element per texel (s = 1), so that element indices are texel indices.
pub fn params(n: usize, leaf: usize, lookup: BinLookup) -> BinMapParams {
    BinMapParams {
        bins_per_axis: n,
        leaf_size: leaf,
        lookup,
        subdivisions: 1,
        ..BinMapParams::default()
    }
}

/// The four test maps: bumpy, flakes and scratched at 64², white noise at 48 × 40.
pub fn test_maps() -> Vec<(&'static str, NormalMap)> {
    vec![
        ("bumpy", bumpy(64, 64, 0.25, 4.0, 1).unwrap()),
        (
            "flakes",
            flakes(64, 64, FlakesParams::default(), 4).unwrap(),
        ),
        (
            "scratched",
            scratched(64, 64, ScratchedParams::default(), 3).unwrap(),
        ),
        ("noise 48×40", super::noise_map(48, 40, 0.5, 9)),
    ]
}
