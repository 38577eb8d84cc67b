//! Every loader gives the same honest answer about a file's header, `GlintModel::load` included
//! (docs/format.md, "Damaged or unsupported"): foreign bytes are "not a brdf glint file", a damaged
//! header field is a corrupted header naming the field, and an intact file of a version or kind this
//! build does not read is unsupported.

use crate::support;

use brdf::Error;
use brdf::glint::procedural::ProceduralGlints;
use brdf::glint::{BeckmannMixture, BinMap, GlintModel, NormalMap, PositionNormalMap};
use support::format::reseal;
use support::store::{is_flip_error, small_files};

type Load = fn(&[u8]) -> brdf::Result<()>;

/// Every loader that reads the file header, by name.
fn loaders() -> [(&'static str, Load); 6] {
    [
        ("GlintModel", |b| GlintModel::load(&mut &b[..]).map(drop)),
        ("BeckmannMixture", |b| {
            BeckmannMixture::load(&mut &b[..]).map(drop)
        }),
        ("BinMap", |b| BinMap::load(&mut &b[..]).map(drop)),
        ("PositionNormalMap", |b| {
            PositionNormalMap::load(&mut &b[..]).map(drop)
        }),
        ("NormalMap", |b| NormalMap::load(&mut &b[..]).map(drop)),
        ("ProceduralGlints", |b| {
            ProceduralGlints::load(&mut &b[..]).map(drop)
        }),
    ]
}

/// A 4 × 4 RGB PNG, encoded by the `image` crate.
#[cfg(feature = "image")]
fn png_bytes() -> Vec<u8> {
    let img = image::RgbImage::from_fn(4, 4, |x, y| {
        image::Rgb([128 + 20 * x as u8, 128 + 20 * y as u8, 255])
    });
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

#[cfg(feature = "image")]
#[test]
fn a_png_is_not_a_glint_file() {
    let png = png_bytes();
    assert!(image::load_from_memory(&png).is_ok(), "a valid PNG");
    for (name, load) in loaders() {
        let e = load(&png).unwrap_err();
        assert!(
            matches!(e, Error::BadMagic { found } if &found == b"\x89PNG\r\n\x1a\n"),
            "{name}: {e}"
        );
        assert!(
            e.to_string().contains("not a brdf glint file"),
            "{name}: {e}"
        );
    }
}

#[test]
fn foreign_bytes_are_not_a_glint_file() {
    let foreign: [&[u8]; 5] = [
        b"# a text file, long enough to hold a whole header\n",
        b"PK\x03\x04\x14\x00\x00\x00\x08\x00 the start of a zip archive",
        &[0u8; 64],
        b"hello",
        // Shares 5 of the magic's 8 bytes: still foreign (docs/format.md).
        b"BRDFGxxx and a header's worth of bytes",
    ];
    for bytes in foreign {
        for (name, load) in loaders() {
            let e = load(bytes).unwrap_err();
            assert!(
                matches!(e, Error::BadMagic { .. }),
                "{name} on {:?}: {e}",
                bytes.escape_ascii().to_string()
            );
        }
    }
}

/// A flipped byte in each header field of each glint model's file, read through
/// `GlintModel::load`: the corrupted header naming the field, except where the flip lands on a
/// version or kind it reads (then the payload's checks or the checksum catch it;
/// `store_corrupt_files::every_flipped_byte_is_an_error` does the same through each model's own
/// loader, over every byte).
#[test]
fn a_damaged_header_field_is_corrupted_through_glint_model() {
    let glint_kind = |code: u32| (2..=7).contains(&code);
    for (kind, file, _) in small_files() {
        if kind == "normal map" {
            continue;
        }
        for k in 0..24 {
            for mask in [0x01u8, 0x02, 0x80, 0xFF] {
                let mut f = file.clone();
                f[k] ^= mask;
                let e = GlintModel::load(&mut f.as_slice()).unwrap_err();
                assert!(
                    is_flip_error(&file, k, mask, &e, glint_kind),
                    "{kind}: byte {k} ^ {mask:#x}: {e}"
                );
            }
        }
    }
}

/// The versions just above 6 (7 is what a flip of bit 0 makes of 6), and far out of range: damaged when the checksum
/// does not match, a real newer version when it does.
#[test]
fn a_newer_version_is_unsupported_only_when_the_checksum_vouches_for_it() {
    for (kind, file, _) in small_files() {
        for version in [7u32, 8, 133, u32::MAX] {
            let mut f = file.clone();
            f[8..12].copy_from_slice(&version.to_le_bytes());
            let sealed = reseal(f.clone());
            for (name, load) in loaders() {
                let damaged = load(&f).unwrap_err();
                assert!(
                    matches!(
                        damaged,
                        Error::CorruptHeader {
                            field: "version",
                            ..
                        }
                    ),
                    "{kind} via {name}, version {version}: {damaged}"
                );
                let newer = load(&sealed).unwrap_err();
                assert!(
                    matches!(newer, Error::UnsupportedVersion { found, supported: 6 } if found == version),
                    "{kind} via {name}, version {version}: {newer}"
                );
                // Cut inside its payload, the newer file cannot be vouched for: truncated.
                let cut = load(&sealed[..sealed.len() - 9]).unwrap_err();
                assert!(
                    matches!(cut, Error::Truncated { .. }),
                    "{kind} via {name}: {cut}"
                );
            }
        }
    }
}

/// A kind code no build has written: an intact file is of a kind this build does not know, a
/// damaged one has a corrupted kind.
#[test]
fn an_unknown_kind_is_wrong_only_when_the_checksum_vouches_for_it() {
    for (kind, file, _) in small_files() {
        let mut f = file.clone();
        f[12..16].copy_from_slice(&9u32.to_le_bytes());
        let sealed = reseal(f.clone());
        for (name, load) in loaders() {
            let e = load(&sealed).unwrap_err();
            assert!(
                matches!(&e, Error::WrongModelKind { found, .. } if found == "unknown kind 9"),
                "{kind} via {name}: {e}"
            );
            let e = load(&f).unwrap_err();
            assert!(
                matches!(e, Error::CorruptHeader { field: "kind", .. }),
                "{kind} via {name}: {e}"
            );
        }
    }
    // An intact normal map is no glint model, and the message says what it is.
    let (_, normal_map, _) = small_files()
        .into_iter()
        .find(|(kind, _, _)| *kind == "normal map")
        .unwrap();
    let e = GlintModel::load(&mut normal_map.as_slice()).unwrap_err();
    assert!(
        matches!(&e, Error::WrongModelKind { found, .. } if found == "NormalMap"),
        "{e}"
    );
}

/// An intact file of a kind a loader does not read is the wrong model, named by its kind (every
/// file of `small_files`, kinds 1 to 6, through every loader); the kinds a loader reads load.
#[test]
fn another_models_file_is_the_wrong_model_kind() {
    // The kinds each loader reads, and the name an error gives each kind (docs/format.md).
    let reads = |loader: &str, code: u32| match loader {
        "GlintModel" => (2..=6).contains(&code),
        "BeckmannMixture" => code == 2 || code == 5,
        "PositionNormalMap" => code == 3,
        "BinMap" => code == 4,
        "NormalMap" => code == 1,
        "ProceduralGlints" => code == 6,
        _ => unreachable!("{loader}"),
    };
    let names = [
        "NormalMap",
        "BeckmannMixture",
        "PositionNormalMap",
        "BinMap",
        "BeckmannMixture (compact)",
        "ProceduralGlints",
    ];
    let mut codes = Vec::new();
    for (kind, file, _) in small_files() {
        let code = u32::from_le_bytes(file[12..16].try_into().unwrap());
        codes.push(code);
        for (name, load) in loaders() {
            let r = load(&file);
            if reads(name, code) {
                assert!(r.is_ok(), "{kind} via {name}: {r:?}");
                continue;
            }
            let e = r.unwrap_err();
            let found_name = names[code as usize - 1];
            let expected_name = if name == "GlintModel" {
                "glint model"
            } else {
                name
            };
            assert!(
                matches!(&e, Error::WrongModelKind { found, expected }
                    if found == found_name && expected == expected_name),
                "{kind} via {name}: {e}"
            );
        }
    }
    codes.sort_unstable();
    assert_eq!(codes, [1, 2, 3, 4, 5, 6], "a small file of every kind");
}
