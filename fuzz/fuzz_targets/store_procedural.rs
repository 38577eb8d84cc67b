//! `ProceduralGlints::load` on arbitrary (optionally re-sealed) bytes: `Ok` or a clear `Err`, never a
//! panic; a loaded surface re-saves byte for byte (or, from an older version, as a current file),
//! `GlintModel::load` reads the same surface, and its patches (at the default tolerance and at a
//! loose one) and their BRDFs pass the totality checks.
#![no_main]

use brdf::glint::procedural::{PatchOptions, ProceduralGlints};
use brdf::glint::{GlintModel, GlintNdf};
use brdf::{MicrofacetBrdf, fresnel::NoFresnel};
use brdf_fuzz::{StoreInput, check_bxdf, check_ndf, check_resave};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = StoreInput::parse(data);
    let bytes = input.bytes();
    let loaded = ProceduralGlints::load(&mut bytes.as_slice());
    // The registry's loader reads a kind-6 file exactly as the model's own loader does.
    match (&loaded, GlintModel::load(&mut bytes.as_slice())) {
        (Ok(surface), Ok(GlintModel::Procedural(again))) => {
            assert_eq!(again.params(), surface.params());
        }
        (Ok(_), other) => panic!(
            "ProceduralGlints::load accepted a file that GlintModel::load gave {:?}",
            other.map(|m| m.name())
        ),
        (Err(e), Ok(GlintModel::Procedural(_))) => {
            panic!(
                "GlintModel::load accepted a procedural file that ProceduralGlints::load refused: {e}"
            )
        }
        _ => {}
    }
    if let Ok(surface) = loaded {
        // A file that loads is re-saved byte for byte, or upgraded to the current version.
        check_resave(
            &bytes,
            &surface,
            |m, w| m.save(w),
            |f| ProceduralGlints::load(&mut &f[..]),
        );
        let footprint = input.footprint.build();
        for patch in [
            surface.patch(&footprint),
            surface.patch_with(&footprint, &PatchOptions { tolerance: 0.5 }, None),
        ] {
            check_ndf(&patch, &input.probe);
            check_bxdf(&MicrofacetBrdf::new(&patch, NoFresnel), &input.probe);
        }
    }
});
