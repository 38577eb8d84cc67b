//! `BeckmannMixture::load` on arbitrary (optionally re-sealed) bytes: `Ok` or a clear `Err`, never a
//! panic or a huge allocation; a loaded mixture's patch and P-BRDF pass the totality checks.
#![no_main]

use brdf::glint::{BeckmannMixture, GlintNdf};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{StoreInput, check_bxdf, check_ndf, check_resave};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = StoreInput::parse(data);
    let bytes = input.bytes();
    if let Ok(mixture) = BeckmannMixture::load(&mut bytes.as_slice()) {
        // A file that loads is re-saved byte for byte, or upgraded to the current version.
        check_resave(
            &bytes,
            &mixture,
            |m, w| m.save(w),
            |f| BeckmannMixture::load(&mut &f[..]),
        );
        let patch = mixture.patch(&input.footprint.build());
        check_ndf(&patch, &input.probe);
        check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
    }
});
