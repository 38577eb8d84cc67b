//! Damaged files give a clear `Err` (docs/format.md), never a panic or a huge allocation: every
//! truncation, every flipped byte, header errors that name what is wrong, bad values in later chunks
//! found after the checksum, and sizes beyond the file refused before allocating.

use crate::support;

use brdf::Error;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, NormalMap, PositionNormalMap};
use support::format::{reseal, reseal_v1};
use support::store::{
    as_version_2, at, bin_map_as_version_5, is_flip_error, load_mixture, map, mixture_as_version_3,
    mixture_as_version_4, mixture_as_version_5, position_normal_as_version_3,
    position_normal_as_version_5, saved, small_files, small_mixture_file,
};

#[test]
fn every_truncation_is_an_error() {
    for (kind, file, load) in small_files() {
        for cut in 0..file.len() {
            let e = load(&file[..cut]).unwrap_err();
            assert!(
                matches!(e, Error::Truncated { .. }),
                "{kind}: cut at {cut}: {e}"
            );
        }
    }
}

/// A version-6 file of `kind` (of [`small_files`]) as format `version` (2 to 5) wrote it: no
/// filtered-mixture chain or measured errors; no seed kernel in the mixtures before version 5; in
/// versions 2 and 3 the patch options that the mixtures and the position-normal map stored then (at
/// their defaults), and for a full mixture of version 2 no merge errors.
fn as_version(kind: &str, file: &[u8], version: u32) -> Vec<u8> {
    let mut f = match (kind, version) {
        ("mixture" | "compact mixture", 5) => return mixture_as_version_5(file),
        ("position-normal", 4 | 5) => position_normal_as_version_5(file),
        // The 6² map is too small for any measured masking error: an empty array.
        ("bin map", _) => bin_map_as_version_5(file, 0),
        ("mixture" | "compact mixture", 4) => return mixture_as_version_4(file),
        ("mixture", 2) => return as_version_2(file),
        ("mixture" | "compact mixture", _) => mixture_as_version_3(file, 0, 16384.0),
        ("position-normal", 2 | 3) => position_normal_as_version_3(file, 128.0),
        _ => file.to_vec(),
    };
    f[8..12].copy_from_slice(&version.to_le_bytes());
    reseal(f)
}

#[test]
fn every_flipped_byte_is_an_error() {
    for (kind, file, load) in small_files() {
        assert!(load(&file).is_ok(), "{kind}");
        let own_kind = u32::from_le_bytes(file[12..16].try_into().unwrap());
        // The mixture loader reads both mixture kinds, the procedural loader both procedural
        // kinds (Beckmann and GGX limits); every other loader its own.
        let reads_kind = |code: u32| {
            code == own_kind
                || (kind.contains("mixture") && [2, 5].contains(&code))
                || (kind.contains("procedural") && [6, 7].contains(&code))
        };
        for k in 0..file.len() {
            for mask in [0x01u8, 0x80, 0xFF] {
                let mut f = file.clone();
                f[k] ^= mask;
                let e = load(&f).unwrap_err();
                assert!(
                    is_flip_error(&file, k, mask, &e, reads_kind),
                    "{kind}: byte {k} ^ {mask:#x}: {e}"
                );
            }
        }
    }
}

#[test]
fn header_errors_name_what_is_wrong() {
    let file = small_mixture_file();
    let mut f = file.clone();
    f[..8].copy_from_slice(b"NOTGLINT");
    let e = load_mixture(&f).unwrap_err();
    assert!(e.to_string().contains("BRDFGLNT"), "{e}");
    let mut f = file.clone();
    f[8..12].copy_from_slice(&7u32.to_le_bytes());
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(
        matches!(
            e,
            Error::UnsupportedVersion {
                found: 7,
                supported: 6
            }
        ),
        "{e}"
    );
    // Format versions 2 to 4 are still read for every kind but the bin map (which gained 𝓑 in
    // version 3, and is read from version 3 on; the full mixture gained its merge errors in version
    // 3, recomputed when absent; versions 2 and 3 of the mixtures and the position-normal map store
    // patch options, read and ignored; mixtures before version 5 are Gaussian-seeded); older
    // versions are not.
    for (kind, file, load) in small_files() {
        for version in [2u32, 3, 4, 5] {
            let old = as_version(kind, &file, version);
            let r = load(&old);
            if kind == "bin map" && version == 2 {
                assert!(
                    matches!(
                        r,
                        Err(Error::UnsupportedVersion {
                            found: 2,
                            supported: 6
                        })
                    ),
                    "{kind}: {r:?}"
                );
            } else {
                assert!(r.is_ok(), "{kind} version {version}: {r:?}");
            }
        }
        // Version 1 sealed with version 1's checksum is a version-1 file; sealed with the current
        // one, its version field is not what was written (docs/format.md, "Damaged or
        // unsupported").
        let mut f = file.clone();
        f[8..12].copy_from_slice(&1u32.to_le_bytes());
        assert!(
            matches!(
                load(&reseal_v1(f.clone())),
                Err(Error::UnsupportedVersion { found: 1, .. })
            ),
            "{kind}"
        );
        assert!(
            matches!(
                load(&reseal(f)),
                Err(Error::CorruptHeader {
                    field: "version",
                    ..
                })
            ),
            "{kind}"
        );
    }
    // A mixture file handed to the other loaders.
    let e = PositionNormalMap::load(&mut file.as_slice()).unwrap_err();
    let msg = e.to_string();
    assert!(
        matches!(e, Error::WrongModelKind { .. })
            && msg.contains("BeckmannMixture")
            && msg.contains("PositionNormalMap"),
        "{msg}"
    );
    assert!(matches!(
        NormalMap::load(&mut file.as_slice()),
        Err(Error::WrongModelKind { .. })
    ));
    // A good file with trailing bytes after the checksum: read exactly, the rest left to the caller.
    let mut f = file.clone();
    f.extend_from_slice(b"next");
    let mut r = f.as_slice();
    assert!(BeckmannMixture::load(&mut r).is_ok());
    assert_eq!(r, b"next");
}

/// Values are checked chunk by chunk while they are read (64 KiB chunks: 3276 lobes, 2730
/// position-normal elements): a bad value far into a later chunk is found and named by its index in
/// the whole array, and only after the checksum (a damaged file is a checksum error first).
#[test]
fn values_in_later_chunks_are_checked_after_the_checksum() {
    let m = map(64);
    let mixture = BeckmannMixture::build(&m, MixtureParams::default()).unwrap();
    let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
    type Load = fn(&[u8]) -> brdf::Result<()>;
    /// Name in the error, file, offset of the array's first record, record bytes, record index,
    /// component, bad value, loader.
    type Case = (&'static str, Vec<u8>, usize, usize, usize, usize, f32, Load);
    let count = 64 * 64;
    let pn_file = saved(|w| pn.save(w));
    // The position-normal elements follow the header (24), the size and rate (3 u64), three f32
    // and their count; then the filtered mixture: its level count, level 1's node count and its
    // 32² nodes of 108 bytes (a 64 KiB chunk holds 606). The lobes start the mixture's payload.
    let pn_start = 24 + 24 + 12 + 8;
    let chain_nodes = pn_start + count * 24 + 16;
    let cases: [Case; 3] = [
        (
            "lobes[4000][2]",
            saved(|w| mixture.save(w)),
            at::LOBES,
            20,
            4000,
            2,
            -1.0,
            |f| load_mixture(f).map(|_| ()),
        ),
        (
            "elements[3000][4]",
            pn_file.clone(),
            pn_start,
            24,
            3000,
            4,
            1e30,
            |f| PositionNormalMap::load(&mut &f[..]).map(|_| ()),
        ),
        (
            "filtered-mixture nodes[900][0]",
            pn_file.clone(),
            chain_nodes,
            108,
            900,
            0,
            2.0,
            |f| PositionNormalMap::load(&mut &f[..]).map(|_| ()),
        ),
    ];
    for (needle, file, start, record, index, component, value, load) in cases {
        let mut f = file.clone();
        let at = start + index * record + 4 * component;
        f[at..at + 4].copy_from_slice(&value.to_le_bytes());
        let e = load(&f).unwrap_err();
        assert!(matches!(e, Error::ChecksumMismatch { .. }), "{needle}: {e}");
        let e = load(&reseal(f)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{needle}: {e}"
        );
        load(&file).unwrap();
    }
}

#[test]
fn sizes_beyond_the_file_are_refused_before_allocating() {
    // A 40000² map (1.6·10⁹ lobes, 32 GB) declared in a file of a few hundred bytes: refused from the
    // declared payload length before any allocation (the allocation-bound test is tests/store_limits.rs).
    let mut f = small_mixture_file();
    f[at::WIDTH..at::WIDTH + 8].copy_from_slice(&40000u64.to_le_bytes());
    f[at::WIDTH + 8..at::WIDTH + 16].copy_from_slice(&40000u64.to_le_bytes());
    f[at::LOBE_COUNT..at::LOBE_COUNT + 8].copy_from_slice(&1_600_000_000u64.to_le_bytes());
    let e = load_mixture(&reseal(f.clone())).unwrap_err();
    assert!(e.to_string().contains("declares only"), "{e}");
    // The same with a payload length that claims it all: the data run out (Truncated).
    f[16..24].copy_from_slice(&(60 + 32_000_000_000u64).to_le_bytes());
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(matches!(e, Error::Truncated { what: "lobes" }), "{e}");
    // A normal map of 2^31 × 2^31 texels: beyond the size limit.
    let mut nm = saved(|w| map(2).save(w));
    nm[24..32].copy_from_slice(&(1u64 << 31).to_le_bytes());
    let e = NormalMap::load(&mut &reseal(nm)[..]).unwrap_err();
    assert!(e.to_string().contains("width"), "{e}");
}
