//! `PositionNormalMap::load` on arbitrary (optionally re-sealed) bytes: `Ok` or a clear `Err`, never a
//! panic or a huge allocation; a loaded map's patch, `MicrofacetBrdf` over it and the published BRDF
//! pass the totality checks.
#![no_main]

use brdf::glint::{GlintNdf, PositionNormalBrdf, PositionNormalMap};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{StoreInput, check_bxdf, check_ndf, check_resave};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = StoreInput::parse(data);
    let bytes = input.bytes();
    if let Ok(map) = PositionNormalMap::load(&mut bytes.as_slice()) {
        // A file that loads is re-saved byte for byte, or upgraded to the current version.
        check_resave(
            &bytes,
            &map,
            |m, w| m.save(w),
            |f| PositionNormalMap::load(&mut &f[..]),
        );
        let patch = map.patch(&input.footprint.build());
        check_ndf(&patch, &input.probe);
        check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
        check_bxdf(&PositionNormalBrdf::new(&patch, NoFresnel), &input.probe);
    }
});
