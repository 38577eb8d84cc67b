//! `BinMap::load` on arbitrary (optionally re-sealed) bytes: `Ok` or a clear `Err`, never a panic or a
//! huge allocation; a loaded bin map re-saves byte for byte, and its plain and smoothed patches and
//! their BRDFs pass the totality checks.
#![no_main]

use brdf::glint::BinMap;
use brdf::glint::GlintNdf;
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{StoreInput, check_bxdf, check_ndf, check_resave};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = StoreInput::parse(data);
    let bytes = input.bytes();
    if let Ok(map) = BinMap::load(&mut bytes.as_slice()) {
        // A file that loads is re-saved byte for byte, or upgraded to the current version.
        check_resave(
            &bytes,
            &map,
            |m, w| m.save(w),
            |f| BinMap::load(&mut &f[..]),
        );
        let footprint = input.footprint.build();
        for patch in [
            map.patch(&footprint),
            map.patch_with(
                &footprint,
                &brdf::glint::binmap::PatchOptions {
                    smoothing_alpha: 0.1,
                    ..Default::default()
                },
                None,
            ),
        ] {
            check_ndf(&patch, &input.probe);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
        }
    }
});
