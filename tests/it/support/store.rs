//! Shared helpers of the store tests (tests/it/store_*.rs): small maps and saved files of every kind,
//! query directions, and the offsets of the fields in a mixture file (docs/format.md).

use super::format::reseal;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{LobeStorage, MixtureParams, SeedKernel};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{BeckmannMixture, BinMap, NormalMap, PositionNormalMap};
use brdf::{Error, Vec3};

/// White-noise slopes in [−0.6, 0.6]² (seed `n`): every lobe and element different.
pub fn map(n: usize) -> NormalMap {
    super::noise_map(n, n, 0.6, n as u64)
}

/// Directions for the queries: normal incidence, moderate, grazing, below the horizon.
pub fn dirs() -> Vec<Vec3> {
    let mut v = Vec::new();
    for th in [0.0, 30.0, 60.0, 85.0, 89.9] {
        for ph in [0.0, 75.0, 200.0] {
            v.push(super::dir(th, ph));
        }
    }
    v.push(Vec3::new(0.3, 0.1, -0.9).normalize());
    v
}

/// The bytes `save` writes.
pub fn saved(save: impl FnOnce(&mut Vec<u8>) -> brdf::Result<()>) -> Vec<u8> {
    let mut v = Vec::new();
    save(&mut v).unwrap();
    v
}

/// A full mixture of the 6² map (8 QMC samples per lobe; the Gaussian seed kernel, which files of
/// every format version hold, so that [`mixture_as_version_3`] and [`as_version_2`] apply), saved.
pub fn small_mixture_file() -> Vec<u8> {
    let params = MixtureParams {
        samples: 8,
        seed: SeedKernel::Gaussian,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(&map(6), params).unwrap();
    saved(|w| built.save(w))
}

/// A compact mixture of the 6² map (the Gaussian seed kernel, as [`small_mixture_file`]), saved.
pub fn small_compact_file() -> Vec<u8> {
    let params = MixtureParams {
        storage: LobeStorage::Compact,
        seed: SeedKernel::Gaussian,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(&map(6), params).unwrap();
    saved(|w| built.save(w))
}

/// Loads a mixture from bytes.
pub fn load_mixture(bytes: &[u8]) -> brdf::Result<BeckmannMixture> {
    BeckmannMixture::load(&mut &bytes[..])
}

/// A small file of every kind, with its loader.
#[allow(clippy::type_complexity)]
pub fn small_files() -> Vec<(&'static str, Vec<u8>, fn(&[u8]) -> brdf::Result<()>)> {
    let m = map(6);
    let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
    let bm_params = BinMapParams {
        bins_per_axis: 3,
        leaf_size: 2,
        ..BinMapParams::default()
    };
    let bm = BinMap::build(&m, bm_params).unwrap();
    let pg = ProceduralGlints::new(ProceduralParams {
        seed: 5,
        ..ProceduralParams::default()
    })
    .unwrap();
    vec![
        ("mixture", small_mixture_file(), |b| {
            load_mixture(b).map(drop)
        }),
        ("compact mixture", small_compact_file(), |b| {
            load_mixture(b).map(drop)
        }),
        ("normal map", saved(|w| m.save(w)), |b| {
            NormalMap::load(&mut &b[..]).map(drop)
        }),
        ("position-normal", saved(|w| pn.save(w)), |b| {
            PositionNormalMap::load(&mut &b[..]).map(drop)
        }),
        ("bin map", saved(|w| bm.save(w)), |b| {
            BinMap::load(&mut &b[..]).map(drop)
        }),
        ("procedural", saved(|w| pg.save(w)), |b| {
            ProceduralGlints::load(&mut &b[..]).map(drop)
        }),
    ]
}

/// Whether `e` is the documented error (docs/format.md, "What a loader checks" and "Damaged or
/// unsupported") of `file` with byte `k` XOR `mask`, for a loader that reads the kinds `reads_kind`
/// accepts (the file being a current-version file that loader reads).
pub fn is_flip_error(
    file: &[u8],
    k: usize,
    mask: u8,
    e: &Error,
    reads_kind: impl Fn(u32) -> bool,
) -> bool {
    let mut f = file.to_vec();
    f[k] ^= mask;
    let word = |at: usize| u32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    // Damage the loader meets inside the payload: a parameter or count refused before the checksum
    // is read, a field that runs past the declared payload (a damaged count, judged by the
    // checksum: the payload length disagrees), data that run out, or the checksum.
    let payload_error = matches!(
        e,
        Error::InvalidFile { .. }
            | Error::ChecksumMismatch { .. }
            | Error::Truncated { .. }
            | Error::CorruptHeader {
                field: "payload length",
                ..
            }
    );
    match k {
        // One damaged byte of the magic (7 of 8 still right).
        0..8 => matches!(e, Error::CorruptHeader { field: "magic", .. }),
        // A flip that lands on another version this build reads: the payload is read in that
        // version's layout, and its checks or the checksum catch the damage.
        8..12 if (2..=6).contains(&word(8)) => payload_error,
        8..12 => matches!(
            e,
            Error::CorruptHeader {
                field: "version",
                ..
            }
        ),
        // The same for a kind this loader reads.
        12..16 if reads_kind(word(12)) => payload_error,
        12..16 => matches!(e, Error::CorruptHeader { field: "kind", .. }),
        // Too long: every field is read and bytes are left (or the file ends first); too short: a
        // field runs past it. The checksum does not match either way.
        16..24 => matches!(
            e,
            Error::CorruptHeader {
                field: "payload length",
                ..
            }
        ),
        _ => payload_error,
    }
}

/// `file` with `fields` inserted at byte `offset` of the file, the header's version set to `version`
/// and its payload length grown, re-sealed.
fn with_fields(file: &[u8], offset: usize, fields: &[u8], version: u32) -> Vec<u8> {
    let mut f = file[..offset].to_vec();
    f.extend_from_slice(fields);
    f.extend_from_slice(&file[offset..]);
    f[8..12].copy_from_slice(&version.to_le_bytes());
    let payload = u64::from_le_bytes(f[16..24].try_into().unwrap()) + fields.len() as u64;
    f[16..24].copy_from_slice(&payload.to_le_bytes());
    reseal(f)
}

/// Reads the `u64` at byte `at`.
fn u64_at(file: &[u8], at: usize) -> usize {
    u64::from_le_bytes(file[at..at + 8].try_into().unwrap()) as usize
}

/// The end of a filtered-mixture chain written at byte `start` (docs/format.md, "The filtered
/// mixture in a file"): its level count, per level a node count and 108-byte nodes, then the error
/// count and 4-byte errors.
fn chain_end(file: &[u8], start: usize) -> usize {
    let mut at = start + 8;
    for _ in 0..u64_at(file, start) {
        at += 8 + 108 * u64_at(file, at);
    }
    at + 8 + 4 * u64_at(file, at)
}

/// `file` without its bytes [start, end), the header's version set to `version` and its payload
/// length shrunk, re-sealed.
fn without(file: &[u8], start: usize, end: usize, version: u32) -> Vec<u8> {
    let mut f = file[..start].to_vec();
    f.extend_from_slice(&file[end..]);
    f[8..12].copy_from_slice(&version.to_le_bytes());
    let payload = u64_at(&f, 16) - (end - start);
    f[16..24].copy_from_slice(&(payload as u64).to_le_bytes());
    reseal(f)
}

/// A mixture's file (full or compact, format version 6) as version 5 wrote it: a full mixture
/// without the filtered mixture's chain and errors after the merge errors (docs/format.md); a
/// compact one (whose payload did not change) with the version alone set. Re-sealed.
pub fn mixture_as_version_5(file: &[u8]) -> Vec<u8> {
    let word = |at: usize| u32::from_le_bytes(file[at..at + 4].try_into().unwrap());
    if word(8) != 6 {
        return file.to_vec();
    }
    let kind = word(12);
    if kind == 5 {
        let mut f = file.to_vec();
        f[8..12].copy_from_slice(&5u32.to_le_bytes());
        return reseal(f);
    }
    // The merge errors: a level count, then per level a count of records of N_RES = 3 `f32`.
    let mut at = at::LOBES + 20 * u64_at(file, at::LOBE_COUNT);
    let levels = u64_at(file, at);
    at += 8;
    for _ in 0..levels {
        at += 8 + 12 * u64_at(file, at);
    }
    without(file, at, chain_end(file, at), 5)
}

/// A position-normal map's file (format version 6) as version 5 wrote it: without the filtered
/// mixture's chain and errors after the elements, re-sealed.
pub fn position_normal_as_version_5(file: &[u8]) -> Vec<u8> {
    // Header 24, width, height, sampling_rate (u64), three f32, the element count, 24-byte elements.
    let count = 24 + 24 + 12;
    let start = count + 8 + 24 * u64_at(file, count);
    without(file, start, chain_end(file, start), 5)
}

/// A bin map's file (format version 6) as version 5 wrote it: without the `errors` moment-masking
/// errors (and their count) that end its payload, re-sealed.
pub fn bin_map_as_version_5(file: &[u8], errors: usize) -> Vec<u8> {
    let end = file.len() - 8;
    without(file, end - 8 - 4 * errors, end, 5)
}

/// A mixture's file (full or compact, format version 6 or 5, Gaussian seed kernel) as version 4
/// wrote it: without the seed kernel's code after `slope_tail` (docs/format.md), re-sealed.
pub fn mixture_as_version_4(file: &[u8]) -> Vec<u8> {
    let file = &mixture_as_version_5(file)[..];
    assert_eq!(
        &file[at::SEED..at::SEED + 4],
        &0u32.to_le_bytes(),
        "only Gaussian-seeded mixtures have an older form"
    );
    let mut f = file[..at::SEED].to_vec();
    f.extend_from_slice(&file[at::SEED + 4..]);
    f[8..12].copy_from_slice(&4u32.to_le_bytes());
    let payload = u64::from_le_bytes(f[16..24].try_into().unwrap()) - 4;
    f[16..24].copy_from_slice(&payload.to_le_bytes());
    reseal(f)
}

/// A mixture's file (full or compact, format version 6, Gaussian seed kernel) as version 3 wrote
/// it: no seed kernel, and the patch options `masking` (`u32`) and `lod_lobes` (`f32`) stored after
/// `slope_tail` (docs/format.md).
pub fn mixture_as_version_3(file: &[u8], masking: u32, lod_lobes: f32) -> Vec<u8> {
    let mut fields = masking.to_le_bytes().to_vec();
    fields.extend_from_slice(&lod_lobes.to_le_bytes());
    with_fields(&mixture_as_version_4(file), at::SEED, &fields, 3)
}

/// A position-normal map's file (format version 6) as version 3 wrote it: no filtered mixture, and
/// the footprint cap `max_query_texels` (`f32`) stored after `slope_sigmas` (docs/format.md).
pub fn position_normal_as_version_3(file: &[u8], max_query_texels: f32) -> Vec<u8> {
    // Header 24, width, height, sampling_rate (u64), sigma_r, weight_sigmas, slope_sigmas (f32).
    let file = position_normal_as_version_5(file);
    with_fields(&file, 24 + 24 + 12, &max_query_texels.to_le_bytes(), 3)
}

/// A full mixture's file (format version 6, Gaussian seed kernel) as version 2 wrote it: no seed
/// kernel, the default patch options stored after `slope_tail` (masking 0, lod_lobes 16384), the
/// payload cut after the lobes (no merge errors), the header's version and payload length set,
/// re-sealed.
pub fn as_version_2(file: &[u8]) -> Vec<u8> {
    // Offsets in the version-4 layout: lobe count at 68, lobes at 76.
    let file = mixture_as_version_4(file);
    let (count, lobes_at) = (at::SEED, at::SEED + 8);
    let lobes = u64::from_le_bytes(file[count..lobes_at].try_into().unwrap()) as usize;
    let end = lobes_at + 20 * lobes;
    let mut f = file[..end].to_vec();
    f.extend_from_slice(&[0u8; 8]);
    f[16..24].copy_from_slice(&((end - 24) as u64).to_le_bytes());
    let f = reseal(f);
    let mut fields = 0u32.to_le_bytes().to_vec();
    fields.extend_from_slice(&16384.0f32.to_le_bytes());
    with_fields(&f, at::SEED, &fields, 2)
}

/// Offsets in a mixture file of format version 6 (as in version 5; docs/format.md): header 24, width 24, height 32,
/// spacing 40, sigma_min 44, samples 48, kernel_sigmas 56, weight_sigmas 60, slope_tail 64, seed
/// kernel 68, lobe count 72, lobes 80.
pub mod at {
    pub const WIDTH: usize = 24;
    pub const SPACING: usize = 40;
    pub const SEED: usize = 68;
    pub const LOBE_COUNT: usize = 72;
    pub const LOBES: usize = 80;
    /// After the 36 lobes of the 6² map: the level count, then level 1's error count and records.
    pub const LEVELS: usize = LOBES + 36 * 20;
    pub const ERRORS: usize = LEVELS + 16;
}
