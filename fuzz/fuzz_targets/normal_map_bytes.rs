//! Normal-map decoding from arbitrary bytes (PNG / EXR / anything): `Ok` or a clear `Err`, never a
//! panic; an `Ok` map has finite slopes and total interpolation.
#![no_main]

use brdf::Vec2;
use brdf::glint::{NormalMap, NormalRepair, TangentConvention};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let (flag, bytes) = data.split_first().unwrap_or((&0, &[]));
    let convention = if flag & 1 == 0 {
        TangentConvention::OpenGl
    } else {
        TangentConvention::DirectX
    };
    let repair = if flag & 2 == 0 {
        NormalRepair::Reject
    } else {
        NormalRepair::ClampZ(0.05)
    };
    if let Ok(map) = NormalMap::from_image_bytes(bytes, "fuzz", convention, repair) {
        assert!(map.slopes().iter().all(|s| s.is_finite()));
        let n = map.normal_at(Vec2::new(0.37, 0.61));
        assert!(n.is_finite() && n.z > 0.0, "interpolated normal {n}");
        assert!(
            map.moment_pyramid()
                .filtered(Vec2::new(1.5, 2.5), 3.0)
                .iter()
                .all(|m| m.is_finite())
        );
    }
});
