//! Saving and loading built glint maps and normal maps (docs/format.md): exact round trips (every query
//! of a loaded model bit-identical to the built one) and a clear `Err` for every class of bad file.
//!
//! The checksum used to forge files with valid checksums is written here from the format's
//! documentation, independently of the crate's code (a mismatch would fail the forged-file tests).

mod support;

use brdf::glint::{
    BeckmannMixture, Footprint, GlintNdf, MaskingMode, MixtureParams, NormalMap, PatchOptions,
    PositionNormalMap, PositionNormalParams,
};
use brdf::ndf::Ndf;
use brdf::{Error, Vec2, Vec3};

/// The documented checksum (docs/format.md).
fn doc_checksum(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xCBF2_9CE4_8422_2325;
    for chunk in bytes.chunks(8) {
        let mut w = [0u8; 8];
        w[..chunk.len()].copy_from_slice(chunk);
        h = (h ^ u64::from_le_bytes(w))
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(29);
    }
    h ^= bytes.len() as u64;
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// Replaces the last 8 bytes of a file by the checksum of the others.
fn reseal(mut file: Vec<u8>) -> Vec<u8> {
    let n = file.len() - 8;
    let sum = doc_checksum(&file[..n]);
    file[n..].copy_from_slice(&sum.to_le_bytes());
    file
}

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

fn small_mixture_file() -> Vec<u8> {
    let params = MixtureParams {
        samples: 8,
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
    let file = small_mixture_file();
    for cut in 0..file.len() {
        let e = load_mixture(&file[..cut]).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "cut at {cut}: {e}");
    }
    let nm = saved(|w| map(5).save(w));
    for cut in 0..nm.len() {
        let e = NormalMap::load_binary(&mut &nm[..cut]).unwrap_err();
        assert!(matches!(e, Error::Truncated { .. }), "cut at {cut}: {e}");
    }
}

#[test]
fn every_flipped_byte_is_an_error() {
    let file = small_mixture_file();
    for k in 0..file.len() {
        for mask in [0x01u8, 0x80, 0xFF] {
            let mut f = file.clone();
            f[k] ^= mask;
            let e = load_mixture(&f).unwrap_err();
            let expected = match k {
                0..8 => matches!(e, Error::BadMagic { .. }),
                8..12 => matches!(e, Error::UnsupportedVersion { .. }),
                12..16 => matches!(e, Error::WrongModelKind { .. }),
                // The payload length: too long leaves bytes over or runs out; too short cuts a field.
                16..24 => matches!(e, Error::InvalidFile { .. } | Error::Truncated { .. }),
                // Parameters may be refused before the checksum is read; data are caught by it.
                _ => matches!(
                    e,
                    Error::InvalidFile { .. } | Error::ChecksumMismatch { .. }
                ),
            };
            assert!(expected, "byte {k} ^ {mask:#x}: {e}");
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
    f[8..12].copy_from_slice(&2u32.to_le_bytes());
    let e = load_mixture(&reseal(f)).unwrap_err();
    assert!(
        matches!(
            e,
            Error::UnsupportedVersion {
                found: 2,
                supported: 1
            }
        ),
        "{e}"
    );
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

/// Offsets in a mixture file (docs/format.md): header 24, width 24, height 32, spacing 40,
/// sigma_min 44, samples 48, kernel_sigmas 56, weight_sigmas 60, slope_tail 64, masking 68,
/// lod_lobes 72, lobe count 76, lobes 84.
mod at {
    pub const WIDTH: usize = 24;
    pub const SPACING: usize = 40;
    pub const MASKING: usize = 68;
    pub const LOBE_COUNT: usize = 76;
    pub const LOBES: usize = 84;
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
