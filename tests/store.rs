//! Saving and loading built glint maps and normal maps (docs/format.md): exact round trips (every query
//! of a loaded model bit-identical to the built one) and a clear `Err` for every class of bad file.
//!
//! The checksum used to forge files with valid checksums is written here from the format's
//! documentation, independently of the crate's code (a mismatch would fail the forged-file tests).

mod support;

use brdf::glint::{
    BeckmannMixture, BinLookup, BinMap, BinMapParams, Footprint, GlintNdf, LobeStorage,
    MaskingMode, MixtureParams, NormalMap, PatchOptions, PositionNormalMap, PositionNormalParams,
};
use brdf::ndf::Ndf;
use brdf::{Error, Vec2, Vec3};

use support::format::reseal;

/// White-noise slopes in [−0.6, 0.6]²: every lobe and element different.
fn map(n: usize) -> NormalMap {
    use rand::RngExt;
    let mut rng = support::rng(n as u64);
    let slopes = (0..n * n)
        .map(|_| Vec2::new(rng.random_range(-0.6..0.6), rng.random_range(-0.6..0.6)))
        .collect();
    NormalMap::from_slopes(n, n, slopes).unwrap()
}

/// Directions for the queries: normal incidence, moderate, grazing, below the horizon.
fn dirs() -> Vec<Vec3> {
    let mut v = Vec::new();
    for th in [0.0, 30.0, 60.0, 85.0, 89.9] {
        for ph in [0.0, 75.0, 200.0] {
            v.push(support::dir(th, ph));
        }
    }
    v.push(Vec3::new(0.3, 0.1, -0.9).normalize());
    v
}

/// Asserts that two patches answer every query with the same bits.
fn assert_same_patch(a: &impl Ndf, b: &impl Ndf, what: &str) {
    let ds = dirs();
    let us = [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.93, 0.07),
    ];
    for &w in &ds {
        assert_eq!(a.d(w).to_bits(), b.d(w).to_bits(), "{what}: d({w})");
        assert_eq!(
            a.lambda(w).to_bits(),
            b.lambda(w).to_bits(),
            "{what}: lambda({w})"
        );
        assert_eq!(
            a.projected_area(w).to_bits(),
            b.projected_area(w).to_bits(),
            "{what}: A({w})"
        );
        for &u in &us {
            let (ma, mb) = (a.sample_visible(w, u), b.sample_visible(w, u));
            assert_eq!(
                ma.to_array().map(f32::to_bits),
                mb.to_array().map(f32::to_bits)
            );
            assert_eq!(a.sample_normal(u), b.sample_normal(u), "{what}");
            for &m in &[ma, Vec3::Z] {
                assert_eq!(
                    a.pdf_visible(w, m).to_bits(),
                    b.pdf_visible(w, m).to_bits(),
                    "{what}: pdf_visible({w}, {m})"
                );
            }
        }
    }
}

/// Footprints from sub-texel to most of the map, isotropic and anisotropic, at several centres.
fn footprints(n: usize) -> Vec<Footprint> {
    let mut f = Vec::new();
    for (k, area) in [0.5f32, 4.0, 64.0, 900.0].into_iter().enumerate() {
        let c = Vec2::new(3.3 + 7.1 * k as f32, 11.7 + 2.9 * k as f32);
        f.push(Footprint::isotropic_texels(c, area, n, n));
        f.push(Footprint::anisotropic_texels(c, area, 4.0, 0.6, n, n));
    }
    f
}

fn saved(save: impl FnOnce(&mut Vec<u8>) -> brdf::Result<()>) -> Vec<u8> {
    let mut v = Vec::new();
    save(&mut v).unwrap();
    v
}

#[test]
fn normal_map_round_trip_is_exact() {
    let m = map(24);
    let file = saved(|w| m.save(w));
    // 24-byte header + width, height, count (8 each) + 8 bytes per texel + checksum.
    assert_eq!(file.len(), 24 + 24 + 8 * 24 * 24 + 8);
    let back = NormalMap::load_binary(&mut file.as_slice()).unwrap();
    assert_eq!((back.width(), back.height()), (24, 24));
    let bits = |m: &NormalMap| -> Vec<[u32; 2]> {
        m.slopes()
            .iter()
            .map(|s| s.to_array().map(f32::to_bits))
            .collect()
    };
    assert_eq!(bits(&m), bits(&back));
    let p = Vec2::new(0.37, 0.81);
    assert_eq!(m.normal_at(p), back.normal_at(p));
    assert_eq!(
        m.filtered_moments(p * 24.0, 3.0),
        back.filtered_moments(p * 24.0, 3.0)
    );
}

#[test]
fn mixture_round_trip_is_exact() {
    let n = 32;
    let m = map(n);
    for (masking, lod) in [
        (MaskingMode::Exact, f32::INFINITY),
        (MaskingMode::Approximate, 64.0),
    ] {
        let params = MixtureParams {
            samples: 32,
            patch: PatchOptions {
                masking,
                lod_lobes: lod,
                ..PatchOptions::default()
            },
            ..MixtureParams::default()
        };
        let built = BeckmannMixture::build(&m, params).unwrap();
        let file = saved(|w| built.save(w));
        let loaded = BeckmannMixture::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.memory(), built.memory());
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch(f),
                &loaded.patch(f),
                &format!("{masking:?} fp {k}"),
            );
        }
        // Saving the loaded model gives the same bytes.
        assert_eq!(saved(|w| loaded.save(w)), file);
        // The same mixture in format version 2 (no merge errors: recomputed on load) answers the
        // same, so the stored errors are the ones the build computes.
        let old = BeckmannMixture::load(&mut as_version_2(&file).as_slice()).unwrap();
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch(f),
                &old.patch(f),
                &format!("{masking:?} fp {k}, version 2"),
            );
        }
    }
}

/// A full mixture's version-3 file as version 2 wrote it: the payload cut after the lobes (no merge
/// errors), the header's version and payload length set, re-sealed.
fn as_version_2(file: &[u8]) -> Vec<u8> {
    let lobes = u64::from_le_bytes(file[at::LOBE_COUNT..at::LOBES].try_into().unwrap()) as usize;
    let end = at::LOBES + 20 * lobes;
    let mut f = file[..end].to_vec();
    f.extend_from_slice(&[0u8; 8]);
    f[8..12].copy_from_slice(&2u32.to_le_bytes());
    f[16..24].copy_from_slice(&((end - 24) as u64).to_le_bytes());
    reseal(f)
}

/// Compact storage (`LobeStorage::Compact`, model kind 5): the same exactness, on a grid whose
/// levels halve down to 1 × 1 (32²), one that stops halving (24² → 3²) and one with no level-2
/// quadtree node on its coarsest levels (6²).
#[test]
fn compact_mixture_round_trip_is_exact() {
    for (n, masking) in [
        (32, MaskingMode::Exact),
        (24, MaskingMode::Approximate),
        (6, MaskingMode::Exact),
    ] {
        let m = map(n);
        let params = MixtureParams {
            storage: LobeStorage::Compact,
            patch: PatchOptions {
                masking,
                lod_tolerance: 0.5,
                ..PatchOptions::default()
            },
            ..MixtureParams::default()
        };
        let built = BeckmannMixture::build(&m, params).unwrap();
        let file = saved(|w| built.save(w));
        assert_eq!(&file[12..16], &5u32.to_le_bytes());
        let loaded = BeckmannMixture::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params().storage, LobeStorage::Compact);
        assert_eq!(loaded.memory(), built.memory());
        assert_eq!(loaded.level_count(), built.level_count());
        let mut levels = std::collections::BTreeSet::new();
        for (k, f) in footprints(n).iter().enumerate() {
            // The tolerance is not stored in files: both with the build's options.
            let (a, b) = (
                built.patch_with(f, params.patch),
                loaded.patch_with(f, params.patch),
            );
            levels.insert(a.level());
            assert_eq!(a.level(), b.level());
            assert_same_patch(&a, &b, &format!("compact {n}² {masking:?} fp {k}"));
        }
        if n >= 24 {
            assert!(
                levels.len() >= 2,
                "{n}²: the footprints use levels {levels:?}"
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
    }
}

#[test]
fn position_normal_round_trip_is_exact() {
    let n = 24;
    let m = map(n);
    for rate in [1, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            ..PositionNormalParams::default()
        };
        let built = PositionNormalMap::build(&m, params).unwrap();
        let file = saved(|w| built.save(w));
        let loaded = PositionNormalMap::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.memory(), built.memory());
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch(f),
                &loaded.patch(f),
                &format!("rate {rate} fp {k}"),
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
    }
}

#[test]
fn bin_map_round_trip_is_exact() {
    let n = 48;
    let m = map(n);
    for (bins, leaf, lookup) in [(31, 4, BinLookup::Dense), (15, 1, BinLookup::Hash)] {
        let params = BinMapParams {
            bins_per_axis: bins,
            leaf_size: leaf,
            lookup,
            ..BinMapParams::default()
        };
        let built = BinMap::build(&m, params).unwrap();
        assert!(!built.forest().is_empty(), "the test needs trees");
        let file = saved(|w| built.save(w));
        let loaded = BinMap::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.memory(), built.memory());
        assert_eq!(loaded.inverse_bin_map(), built.inverse_bin_map());
        assert_eq!(loaded.forest(), built.forest());
        // 𝓑 is derived on load, not stored: the same bin for every sub-texel.
        let (gw, gh) = built.grid_size();
        for k in 0..gw * gh {
            assert_eq!(
                loaded.bin_of_texel(k),
                built.bin_of_texel(k),
                "sub-texel {k}"
            );
        }
        for (k, f) in footprints(n).iter().enumerate() {
            let what = format!("{lookup:?} fp {k}");
            assert_same_patch(&built.patch(f), &loaded.patch(f), &what);
            assert_same_patch(
                &built.patch_smoothed(f, 0.1),
                &loaded.patch_smoothed(f, 0.1),
                &what,
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
    }
}

/// Offsets in a bin-map file: width 24, height 32, bins 40, leaf 48, sub-texels 56, lookup 64, σ 68,
/// 𝓑⁻¹ count 72, 𝓑⁻¹ 80.. (one u32 per sub-texel), then offsets (count, data), roots, forest,
/// moments. (𝓑 is not stored: the loader derives it from 𝓑⁻¹ and the offsets.)
#[test]
fn inconsistent_bin_maps_are_errors() {
    let n = 16;
    let params = BinMapParams {
        bins_per_axis: 5,
        leaf_size: 2,
        ..BinMapParams::default()
    };
    let built = BinMap::build(&map(n), params).unwrap();
    let file = saved(|w| built.save(w));
    let sub = built.subdivisions();
    assert_eq!(
        sub, 2,
        "the default sub-texel resolution the layout assumes"
    );
    let texels = (n * sub) * (n * sub);
    // Format version 3: offsets, roots, forest, then 𝓑⁻¹ and 𝓑 (as u16: 25 bins).
    let layout = |file: &[u8]| {
        let offsets_at = 80;
        let roots_at = offsets_at + 4 * 26 + 8;
        let forest_at = roots_at + 4 * 25 + 8;
        let forest_len =
            u64::from_le_bytes(file[forest_at - 8..forest_at].try_into().unwrap()) as usize;
        let inverse_at = forest_at + 4 * forest_len + 8;
        let bin_map_at = inverse_at + 4 * texels + 8;
        (
            offsets_at, roots_at, forest_at, forest_len, inverse_at, bin_map_at,
        )
    };
    let (offsets_at, roots_at, forest_at, forest_len, inverse_at, bin_map_at) = layout(&file);
    assert_eq!(forest_len, built.forest().len(), "layout of the test");
    let u32_at = |f: &[u8], at: usize| u32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    let with = |at: usize, v: u32| {
        let mut f = file.clone();
        f[at..at + 4].copy_from_slice(&v.to_le_bytes());
        reseal(f)
    };
    let with_u16 = |at: usize, v: u16| {
        let mut f = file.clone();
        f[at..at + 2].copy_from_slice(&v.to_le_bytes());
        reseal(f)
    };
    let swap = |a: usize, b: usize| {
        let mut f = file.clone();
        for k in 0..4 {
            f.swap(a + k, b + k);
        }
        reseal(f)
    };
    // Two texels of the same bin list swapped: still a permutation with the right bins, but the
    // forest's split no longer holds (the first tree's root splits x at 8: find a left and a right
    // texel of its list).
    let root_bin = (0..25)
        .find(|&b| built.bin_range(b).is_some_and(|r| r.2.is_some()))
        .unwrap();
    let (s, e, _) = built.bin_range(root_bin).unwrap();
    let mid = built.forest()[0] as usize;
    assert!(s < mid && mid < e);
    // A sub-texel given another bin by 𝓑 than the list that holds it.
    let pair_bin = (0..25).find(|&b| b != root_bin).unwrap();
    let k0 = built.texels_of_bin(root_bin)[0] as usize;
    let disagree =
        format!("is in the list of bin {root_bin} but the bin map gives it bin Some({pair_bin})");
    let not_a_bin = format!("bin map[{k0}] = 25 is not a bin");
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "sub-texel beyond the grid",
            with(inverse_at, texels as u32),
            "outside its leaf's region",
        ),
        (
            "bin map disagreeing with the lists",
            with_u16(bin_map_at + 2 * k0, pair_bin as u16),
            &disagree,
        ),
        (
            "bin map value beyond the bins",
            with_u16(bin_map_at + 2 * k0, 25),
            &not_a_bin,
        ),
        (
            "offsets decreasing",
            with(offsets_at + 4, texels as u32 + 5),
            "must not decrease",
        ),
        (
            "offsets not ending at the sub-texel count",
            with(offsets_at + 4 * 25, texels as u32 - 1),
            "offsets run from",
        ),
        (
            "inverse not a permutation",
            with(inverse_at + 4, u32_at(&file, inverse_at)),
            "inverse",
        ),
        (
            "texel on the wrong side",
            swap(inverse_at + 4 * s, inverse_at + 4 * (e - 1)),
            "wrong side",
        ),
        (
            "root not at the layout's place",
            with(roots_at + 4 * root_bin, 2),
            "roots",
        ),
        (
            "mid outside the range",
            with(forest_at, (e + 1) as u32),
            "outside",
        ),
        ("right link broken", with(forest_at + 4, 0), "right child"),
    ];
    for (name, f, needle) in cases {
        let e = BinMap::load(&mut f.as_slice()).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
    // A sub-texel repeated (in place of another) within a list too short for a tree: its region is
    // the whole map and 𝓑 is untouched, so only the fingerprint of 𝓑 against 𝓑⁻¹ sees it.
    let params = BinMapParams {
        leaf_size: 64,
        ..params
    };
    let built = BinMap::build(&map(n), params).unwrap();
    let mut f = saved(|w| built.save(w));
    let inverse_at = layout(&f).4;
    let b = (0..25)
        .find(|&b| {
            built
                .bin_range(b)
                .is_some_and(|r| r.2.is_none() && r.1 - r.0 >= 2)
        })
        .unwrap();
    let (s, _, _) = built.bin_range(b).unwrap();
    let first = u32_at(&f, inverse_at + 4 * s);
    f[inverse_at + 4 * (s + 1)..inverse_at + 4 * (s + 2)].copy_from_slice(&first.to_le_bytes());
    let e = BinMap::load(&mut reseal(f).as_slice()).unwrap_err();
    assert!(
        e.to_string().contains(&format!(
            "inverse[{}] = {first} is out of range or repeated",
            s + 1
        )),
        "{e}"
    );
}

fn small_mixture_file() -> Vec<u8> {
    let params = MixtureParams {
        samples: 8,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(&map(6), params).unwrap();
    saved(|w| built.save(w))
}

fn small_compact_file() -> Vec<u8> {
    let params = MixtureParams {
        storage: LobeStorage::Compact,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(&map(6), params).unwrap();
    saved(|w| built.save(w))
}

fn load_mixture(bytes: &[u8]) -> brdf::Result<BeckmannMixture> {
    BeckmannMixture::load(&mut &bytes[..])
}

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

/// A small file of every kind, with its loader.
#[allow(clippy::type_complexity)]
fn small_files() -> Vec<(&'static str, Vec<u8>, fn(&[u8]) -> brdf::Result<()>)> {
    let m = map(6);
    let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
    let bm_params = BinMapParams {
        bins_per_axis: 3,
        leaf_size: 2,
        ..BinMapParams::default()
    };
    let bm = BinMap::build(&m, bm_params).unwrap();
    vec![
        ("mixture", small_mixture_file(), |b| {
            load_mixture(b).map(drop)
        }),
        ("compact mixture", small_compact_file(), |b| {
            load_mixture(b).map(drop)
        }),
        ("normal map", saved(|w| m.save(w)), |b| {
            NormalMap::load_binary(&mut &b[..]).map(drop)
        }),
        ("position-normal", saved(|w| pn.save(w)), |b| {
            PositionNormalMap::load(&mut &b[..]).map(drop)
        }),
        ("bin map", saved(|w| bm.save(w)), |b| {
            BinMap::load(&mut &b[..]).map(drop)
        }),
    ]
}

#[test]
fn every_flipped_byte_is_an_error() {
    for (kind, file, load) in small_files() {
        assert!(load(&file).is_ok(), "{kind}");
        for k in 0..file.len() {
            for mask in [0x01u8, 0x80, 0xFF] {
                let mut f = file.clone();
                f[k] ^= mask;
                let e = load(&f).unwrap_err();
                let expected = match k {
                    0..8 => matches!(e, Error::BadMagic { .. }),
                    // A flip to version 2 (from 3, bit 0 of byte 8) is a version still read for
                    // every kind but the bin map: the checksum, which covers the header, refuses it.
                    // (A full mixture read as version 2 stops short of its merge errors first.)
                    8..12 => {
                        matches!(e, Error::UnsupportedVersion { .. })
                            || (k == 8
                                && f[8] == 2
                                && kind != "bin map"
                                && matches!(
                                    e,
                                    Error::ChecksumMismatch { .. } | Error::InvalidFile { .. }
                                ))
                    }
                    12..16 => matches!(e, Error::WrongModelKind { .. }),
                    // The payload length: too long leaves bytes over or runs out; too short cuts a
                    // field.
                    16..24 => matches!(e, Error::InvalidFile { .. } | Error::Truncated { .. }),
                    // Parameters and counts may be refused before the checksum is read (or, for a
                    // count, run out of data); data are caught by the checksum.
                    _ => matches!(
                        e,
                        Error::InvalidFile { .. }
                            | Error::ChecksumMismatch { .. }
                            | Error::Truncated { .. }
                    ),
                };
                assert!(expected, "{kind}: byte {k} ^ {mask:#x}: {e}");
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
    f[8..12].copy_from_slice(&4u32.to_le_bytes());
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(
        matches!(
            e,
            Error::UnsupportedVersion {
                found: 4,
                supported: 3
            }
        ),
        "{e}"
    );
    // Format version 2 is still read for every kind but the bin map (which gained 𝓑 in version 3;
    // the full mixture gained its merge errors, recomputed when absent); older versions are not.
    for (kind, file, load) in small_files() {
        let v2 = if kind == "mixture" {
            as_version_2(&file)
        } else {
            let mut f = file.clone();
            f[8..12].copy_from_slice(&2u32.to_le_bytes());
            reseal(f)
        };
        let r = load(&v2);
        if kind == "bin map" {
            assert!(
                matches!(
                    r,
                    Err(Error::UnsupportedVersion {
                        found: 2,
                        supported: 3
                    })
                ),
                "{kind}: {r:?}"
            );
        } else {
            assert!(r.is_ok(), "{kind}: {r:?}");
        }
        let mut f = file.clone();
        f[8..12].copy_from_slice(&1u32.to_le_bytes());
        assert!(
            matches!(
                load(&reseal(f)),
                Err(Error::UnsupportedVersion { found: 1, .. })
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
        NormalMap::load_binary(&mut file.as_slice()),
        Err(Error::WrongModelKind { .. })
    ));
    // A good file with trailing bytes after the checksum: read exactly, the rest left to the caller.
    let mut f = file.clone();
    f.extend_from_slice(b"next");
    let mut r = f.as_slice();
    assert!(BeckmannMixture::load(&mut r).is_ok());
    assert_eq!(r, b"next");
}

/// Offsets in the compact mixture file of a 6² map (docs/format.md, kind 5; lobe grid 6², levels of
/// detail 6² and 3²): the parameters as kind 2 up to 76, level count 76; level 0: frame count 84,
/// 4 frames 92..156, block count 156, 4 blocks 164..804, error count 804 (0); level 1: frame count
/// 812, 1 frame 820..836, block count 836, 1 block 844..1004, error count 1004, 9 codes 1012..1021.
mod compact_at {
    pub const LEVELS: usize = 76;
    pub const FRAME0: usize = 92;
    pub const BLOCK0: usize = 164;
    pub const ERROR_COUNT1: usize = 1004;
    pub const END: usize = 1021;
}

/// Compact files whose checksums are valid but whose contents no build writes: each an
/// `InvalidFile` naming what is wrong (before any model is made).
#[test]
fn inconsistent_compact_contents_are_errors() {
    let file = small_compact_file();
    assert_eq!(
        file.len(),
        compact_at::END + 8,
        "the layout the offsets assume"
    );
    let f32_at = |f: &[u8], at: usize| f32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    let with = |at: usize, bytes: &[u8]| {
        let mut f = file.clone();
        f[at..at + bytes.len()].copy_from_slice(bytes);
        reseal(f)
    };
    let (lo, hi) = (
        f32_at(&file, compact_at::FRAME0),
        f32_at(&file, compact_at::FRAME0 + 8),
    );
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "level count",
            with(compact_at::LEVELS, &3u64.to_le_bytes()),
            "levels = 3",
        ),
        (
            "error count",
            with(compact_at::ERROR_COUNT1, &8u64.to_le_bytes()),
            "errors holds 8",
        ),
        // J₁₁ of lane 0 (words 32.. of the block) = +0 or +∞ in binary16.
        (
            "J zero",
            with(compact_at::BLOCK0 + 64, &0u16.to_le_bytes()),
            "J =",
        ),
        (
            "J infinite",
            with(compact_at::BLOCK0 + 64, &0x7C00u16.to_le_bytes()),
            "J =",
        ),
        (
            "frame reversed",
            with(compact_at::FRAME0, &(hi + 1.0).to_le_bytes()),
            "lo > hi",
        ),
        (
            "frame shrunk",
            with(compact_at::FRAME0, &(0.5 * (lo + hi)).to_le_bytes()),
            "outside its block's box",
        ),
        (
            "frame huge",
            with(compact_at::FRAME0, &(-1e30f32).to_le_bytes()),
            "frames",
        ),
    ];
    for (name, f, needle) in cases {
        let e = load_mixture(&f).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
}

/// Every single-byte change of a small compact file, re-sealed (so the checksum passes): the loader
/// returns an error or a mixture whose queries are total (finite, non-negative `d` and pdfs, unit
/// upper-hemisphere samples) — never a panic. A changed mean code or binary16 J that stays valid is a
/// legitimate different model; everything else must be refused.
#[test]
fn resealed_compact_byte_changes_load_to_total_models_or_errors() {
    let file = small_compact_file();
    let (mut ok, mut refused) = (0, 0);
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 9.0, 6, 6);
    for k in 24..file.len() - 8 {
        let mut f = file.clone();
        f[k] ^= 0x5A;
        let Ok(mix) = load_mixture(&reseal(f)) else {
            refused += 1;
            continue;
        };
        ok += 1;
        let p = mix.patch(&fp);
        for w in dirs() {
            let d = p.d(w);
            assert!(d.is_finite() && d >= 0.0, "byte {k}: d({w}) = {d}");
            let l = p.lambda(w);
            assert!(l.is_finite() && l >= 0.0, "byte {k}: lambda({w}) = {l}");
            let m = p.sample_visible(w, Vec2::new(0.3, 0.8));
            assert!(
                m.is_finite() && (m.length() - 1.0).abs() < 1e-3 && m.z >= 0.0,
                "byte {k}: sample {m}"
            );
            let q = p.pdf_visible(w, m);
            assert!(q.is_finite() && q >= 0.0, "byte {k}: pdf {q}");
        }
    }
    println!("{ok} changed files loaded (all total), {refused} refused");
    assert!(ok > 0 && refused > 0);
}

/// Offsets in a mixture file (docs/format.md): header 24, width 24, height 32, spacing 40,
/// sigma_min 44, samples 48, kernel_sigmas 56, weight_sigmas 60, slope_tail 64, masking 68,
/// lod_lobes 72, lobe count 76, lobes 84.
mod at {
    pub const WIDTH: usize = 24;
    pub const SPACING: usize = 40;
    pub const MASKING: usize = 68;
    pub const LOBE_COUNT: usize = 76;
    pub const LOBES: usize = 84;
    /// After the 36 lobes of the 6² map: the level count, then level 1's error count and records.
    pub const LEVELS: usize = LOBES + 36 * 20;
    pub const ERRORS: usize = LEVELS + 16;
}

#[test]
fn inconsistent_contents_with_valid_checksums_are_errors() {
    let file = small_mixture_file();
    let set =
        |f: &mut Vec<u8>, at: usize, bytes: &[u8]| f[at..at + bytes.len()].copy_from_slice(bytes);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "lobe count off by one",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBE_COUNT, &35u64.to_le_bytes());
                f
            },
            "lobes",
        ),
        (
            "width changes the grid",
            {
                let mut f = file.clone();
                set(&mut f, at::WIDTH, &7u64.to_le_bytes());
                f
            },
            "lobes",
        ),
        (
            "zero width",
            {
                let mut f = file.clone();
                set(&mut f, at::WIDTH, &0u64.to_le_bytes());
                f
            },
            "map size",
        ),
        (
            "spacing below MIN_SPACING",
            {
                let mut f = file.clone();
                set(&mut f, at::SPACING, &0.01f32.to_le_bytes());
                f
            },
            "spacing",
        ),
        (
            "unknown masking mode",
            {
                let mut f = file.clone();
                set(&mut f, at::MASKING, &7u32.to_le_bytes());
                f
            },
            "masking",
        ),
        (
            "NaN moment",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES + 8, &f32::NAN.to_le_bytes());
                f
            },
            "lobes[0][2]",
        ),
        (
            "negative second moment",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES + 20 * 3 + 12, &(-1.0f32).to_le_bytes());
                f
            },
            "lobes[3][3]",
        ),
        (
            "huge mean",
            {
                let mut f = file.clone();
                set(&mut f, at::LOBES, &1e30f32.to_le_bytes());
                f
            },
            "lobes[0][0]",
        ),
        // Version 3: one level of merge errors (6² lobes → 3² nodes) after the 36 lobes.
        (
            "level count",
            {
                let mut f = file.clone();
                set(&mut f, at::LEVELS, &2u64.to_le_bytes());
                f
            },
            "levels = 2 but the lobe grid 6×6 has 1",
        ),
        (
            "merge error above 1",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS + 12 * 4 + 8, &1.5f32.to_le_bytes());
                f
            },
            "merge errors[4][2]",
        ),
        (
            "NaN merge error",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS, &f32::NAN.to_le_bytes());
                f
            },
            "merge errors[0][0]",
        ),
        (
            "negative merge error",
            {
                let mut f = file.clone();
                set(&mut f, at::ERRORS + 12 * 8 + 4, &(-1e-3f32).to_le_bytes());
                f
            },
            "merge errors[8][1]",
        ),
    ];
    for (name, f, needle) in cases {
        let e = load_mixture(&reseal(f)).unwrap_err();
        assert!(
            matches!(e, Error::InvalidFile { .. }) && e.to_string().contains(needle),
            "{name}: {e}"
        );
    }
    // The payload length declaring more than the fields hold.
    let mut f = file.clone();
    let declared = u64::from_le_bytes(f[16..24].try_into().unwrap());
    f[16..24].copy_from_slice(&(declared + 8).to_le_bytes());
    let n = f.len() - 8;
    f.splice(n..n, [0u8; 8]);
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(
        matches!(e, Error::InvalidFile { .. }) && e.to_string().contains("payload"),
        "{e}"
    );
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
    // The position-normal elements end the payload; the lobes start it (the merge errors follow).
    let pn_start = pn_file.len() - 8 - count * 24;
    let cases: [Case; 2] = [
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
            pn_file,
            pn_start,
            24,
            3000,
            4,
            1e30,
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
    let e = NormalMap::load_binary(&mut &reseal(nm)[..]).unwrap_err();
    assert!(e.to_string().contains("width"), "{e}");
}

/// Writes the seed files of the store fuzz targets (small valid files of each kind):
/// `cargo test --test store write_fuzz_seeds -- --ignored`.
#[test]
#[ignore]
fn write_fuzz_seeds() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    let write = |dir: &str, name: &str, bytes: Vec<u8>| {
        let d = root.join(dir);
        std::fs::create_dir_all(&d).unwrap();
        // The store targets read a flag byte, a footprint and a probe before the file: prefix zeros.
        let mut input = vec![0u8; 1 + 6 * 4 + 9 * 4];
        input.extend(bytes);
        std::fs::write(d.join(name), input).unwrap();
    };
    for n in [1usize, 3] {
        let m = map(n);
        write("store_normal_map", &format!("map{n}"), saved(|w| m.save(w)));
        let params = MixtureParams {
            samples: 4,
            ..MixtureParams::default()
        };
        let mx = BeckmannMixture::build(&m, params).unwrap();
        write(
            "store_mixture",
            &format!("mixture{n}"),
            saved(|w| mx.save(w)),
        );
        // Compact storage (model kind 5): 1², 3² (no level-2 node: the single block's own frame)
        // and 8² (frames from the quadtree's level 2).
        for k in [n, n + 5] {
            let cm = BeckmannMixture::build(
                &map(k),
                MixtureParams {
                    storage: LobeStorage::Compact,
                    ..params
                },
            )
            .unwrap();
            write(
                "store_mixture",
                &format!("compact{k}"),
                saved(|w| cm.save(w)),
            );
        }
        let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
        write(
            "store_position_normal",
            &format!("pn{n}"),
            saved(|w| pn.save(w)),
        );
        for (bins, leaf) in [(3, 1), (7, 2)] {
            let params = BinMapParams {
                bins_per_axis: bins,
                leaf_size: leaf,
                ..BinMapParams::default()
            };
            let bm = BinMap::build(&map(n + 3), params).unwrap();
            write(
                "store_binmap",
                &format!("bm{n}_{bins}"),
                saved(|w| bm.save(w)),
            );
        }
    }
}
