//! Forged procedural-glint files (model kind 6, docs/format.md): with valid checksums but
//! parameters their constructor refuses, each an `InvalidFile` naming the parameter.
//!
//! The checksum used to forge the files is written from the format's documentation
//! (`support::format`), independently of the crate's code.

use crate::support::format::reseal;
use crate::support::store::saved;
use brdf::Error;

/// Procedural glints (model kind 6, docs/format.md): every parameter `ProceduralGlints::new`
/// refuses, forged with a valid checksum, is an `InvalidFile` naming it, judged after the checksum
/// (the same bytes unsealed are a checksum error); a resolution beyond 2³² − 1 is refused as it is
/// read; a payload length that disagrees with the 40 bytes of fields is an `InvalidFile`.
/// `GlintModel::load` gives the same errors.
#[test]
fn inconsistent_procedural_parameters_are_errors() {
    use brdf::glint::GlintModel;
    use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};

    let built = ProceduralGlints::new(ProceduralParams {
        seed: 5,
        ..ProceduralParams::default()
    })
    .unwrap();
    let file = saved(|w| built.save(w));
    // Offsets: alpha.x 24, alpha.y 28, facet_alpha 32, density 36 (f32), resolution[0] 40,
    // resolution[1] 48, seed 56 (u64), checksum 64.
    let forged = |fields: &[(usize, &[u8])]| {
        let mut f = file.clone();
        for &(at, bytes) in fields {
            f[at..at + bytes.len()].copy_from_slice(bytes);
        }
        f
    };
    let f32s = |v: f32| v.to_le_bytes();
    let u64s = |v: u64| v.to_le_bytes();
    let refused: Vec<(&str, Vec<u8>, &str)> = vec![
        ("NaN alpha.x", forged(&[(24, &f32s(f32::NAN))]), "alpha.x"),
        (
            "alpha.x below 1e-3",
            forged(&[(24, &f32s(1e-4))]),
            "alpha.x",
        ),
        ("alpha.y above 2", forged(&[(28, &f32s(2.5))]), "alpha.y"),
        (
            "infinite alpha.y",
            forged(&[(28, &f32s(f32::INFINITY))]),
            "alpha.y",
        ),
        (
            "facet_alpha = alpha",
            forged(&[(32, &f32s(0.3))]),
            "facet_alpha",
        ),
        (
            "facet_alpha below 1e-4",
            forged(&[(32, &f32s(5e-5))]),
            "facet_alpha",
        ),
        (
            "negative facet_alpha",
            forged(&[(32, &f32s(-0.02))]),
            "facet_alpha",
        ),
        ("zero density", forged(&[(36, &f32s(0.0))]), "density"),
        ("NaN density", forged(&[(36, &f32s(f32::NAN))]), "density"),
        // Below half a facet per uv side (1024 · √1e-7 ≈ 0.32), and beyond 2²⁴ (1024 · √1e9).
        ("too few facets", forged(&[(36, &f32s(1e-7))]), "density"),
        ("too many facets", forged(&[(36, &f32s(1e9))]), "density"),
        (
            "zero resolution[0]",
            forged(&[(40, &u64s(0))]),
            "resolution[0]",
        ),
        (
            "resolution[1] above 2^20",
            forged(&[(48, &u64s((1 << 20) + 1))]),
            "resolution[1]",
        ),
    ];
    type Load = fn(&[u8]) -> brdf::Result<()>;
    let loads: [(&str, Load); 2] = [
        ("ProceduralGlints", |b| {
            ProceduralGlints::load(&mut &b[..]).map(drop)
        }),
        ("GlintModel", |b| GlintModel::load(&mut &b[..]).map(drop)),
    ];
    for (loader, load) in loads {
        load(&file).unwrap();
        for (name, f, needle) in &refused {
            let e = load(&reseal(f.clone())).unwrap_err();
            let msg = e.to_string();
            assert!(
                matches!(e, Error::InvalidFile { .. })
                    && msg.contains("stored surface refused")
                    && msg.contains(&format!("`{needle}`")),
                "{loader}, {name}: {msg}"
            );
            // Unsealed, the same bytes are a damaged file: the checksum is read first.
            let e = load(f).unwrap_err();
            assert!(
                matches!(e, Error::ChecksumMismatch { .. }),
                "{loader}, {name} unsealed: {e}"
            );
        }
        // A resolution beyond 2³² − 1 is refused as it is read, sealed or not.
        let huge = forged(&[(40, &u64s(1 << 32))]);
        for f in [reseal(huge.clone()), huge] {
            let e = load(&f).unwrap_err();
            assert!(
                matches!(e, Error::InvalidFile { .. })
                    && e.to_string()
                        .contains("resolution[0] = 4294967296 exceeds the limit"),
                "{loader}: {e}"
            );
        }
        // The payload length: 8 bytes more than the fields hold, or 8 bytes fewer (no seed).
        let mut longer = file.clone();
        longer[16..24].copy_from_slice(&48u64.to_le_bytes());
        longer.splice(64..64, [0u8; 8]);
        let e = load(&reseal(longer)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains("payload"),
            "{loader}: {e}"
        );
        let mut shorter = file[..56].to_vec();
        shorter[16..24].copy_from_slice(&32u64.to_le_bytes());
        shorter.extend_from_slice(&[0u8; 8]);
        let e = load(&reseal(shorter)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains("seed needs 8"),
            "{loader}: {e}"
        );
    }
}
