//! `NormalMap::load` on arbitrary (optionally re-sealed) bytes: `Ok` or a clear `Err`, never a
//! panic or a huge allocation; a loaded map has finite slopes and total interpolation.
#![no_main]

use brdf::Vec2;
use brdf::glint::NormalMap;
use brdf_fuzz::{StoreInput, check_resave};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = StoreInput::parse(data);
    let bytes = input.bytes();
    if let Ok(map) = NormalMap::load(&mut bytes.as_slice()) {
        assert!(map.slopes().iter().all(|s| s.is_finite()));
        let n = map.normal_at(Vec2::new(0.37, 0.61));
        assert!(n.is_finite() && n.z > 0.0, "interpolated normal {n}");
        // A file that loads is re-saved byte for byte, or upgraded to the current version.
        check_resave(
            &bytes,
            &map,
            |m, w| m.save(w),
            |f| NormalMap::load(&mut &f[..]),
        );
    }
});
