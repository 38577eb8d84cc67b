//! Shared pieces of the fuzz targets: arbitrary inputs built from raw bytes, and the totality checks
//! of `tests/it/support/totality.rs` (finite, ≥ 0 where it is a density or a value, a sample only with a
//! positive pdf, never a panic).
//!
//! A failed check panics with the offending input, which libFuzzer records as a crash artefact.

use arbitrary::Arbitrary;
use brdf::glint::{Footprint, NormalMap};
use brdf::ndf::Ndf;
use brdf::{Bxdf, Vec2, Vec3};

/// The checks themselves, shared with the property tests of the crate.
#[path = "../../tests/it/support/totality.rs"]
pub mod totality;

/// A normal map of 1 to 12 texels per side from raw slopes (repeated to fill it; any f32, so NaN,
/// infinities and huge slopes reach the constructor).
#[derive(Arbitrary, Debug)]
pub struct MapInput {
    width: u8,
    height: u8,
    slopes: Vec<(f32, f32)>,
}

impl MapInput {
    /// The map, or `None` where the constructor refused the data (which it must do without panicking).
    pub fn build(&self) -> Option<NormalMap> {
        let (w, h) = (self.width as usize % 12 + 1, self.height as usize % 12 + 1);
        let slopes: Vec<Vec2> = (0..w * h)
            .map(|k| {
                self.slopes
                    .get(k % self.slopes.len().max(1))
                    .map_or(Vec2::ZERO, |&(x, y)| Vec2::new(x, y))
            })
            .collect();
        NormalMap::from_slopes(w, h, slopes).ok()
    }
}

/// A footprint from raw ray differentials (any f32).
#[derive(Arbitrary, Debug)]
pub struct FootprintInput {
    uv: (f32, f32),
    duv_dx: (f32, f32),
    duv_dy: (f32, f32),
}

impl FootprintInput {
    /// The footprint (construction is infallible: degenerate input falls back, documented).
    pub fn build(&self) -> Footprint {
        let v = |(x, y): (f32, f32)| Vec2::new(x, y);
        Footprint::from_differentials(v(self.uv), v(self.duv_dx), v(self.duv_dy))
    }
}

/// Directions and random numbers for one round of queries (any f32: the checks expand them into
/// normalised directions, edge cases and folded random numbers).
#[derive(Arbitrary, Debug)]
pub struct Probe {
    wo: (f32, f32, f32),
    wi: (f32, f32, f32),
    u: (f32, f32),
    uc: f32,
}

impl Probe {
    fn parts(&self) -> (Vec3, Vec3, f32, Vec2) {
        (
            Vec3::new(self.wo.0, self.wo.1, self.wo.2),
            Vec3::new(self.wi.0, self.wi.1, self.wi.2),
            self.uc,
            Vec2::new(self.u.0, self.u.1),
        )
    }
}

/// [`totality::check_ndf`] on the probe.
pub fn check_ndf(ndf: &dyn Ndf, probe: &Probe) {
    let (wo, wi, uc, u) = probe.parts();
    totality::check_ndf(ndf, wo, wi, uc, u);
}

/// [`totality::check_bxdf`] on the probe.
pub fn check_bxdf(bxdf: &dyn Bxdf, probe: &Probe) {
    let (wo, wi, uc, u) = probe.parts();
    totality::check_bxdf(bxdf, wo, wi, uc, u);
}

/// The file checksum of docs/format.md, written from the documentation (not the crate's code), so
/// that the store targets can re-seal a mutated file and reach the loaders' content checks.
pub fn format_checksum(bytes: &[u8]) -> u64 {
    let mix = |h: u64, w: u64| (h ^ w).wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(29);
    let mut lanes = [0u64; 4];
    for (j, lane) in lanes.iter_mut().enumerate() {
        *lane = 0xCBF2_9CE4_8422_2325u64 + j as u64;
    }
    for (k, chunk) in bytes.chunks(8).enumerate() {
        let mut w = [0u8; 8];
        w[..chunk.len()].copy_from_slice(chunk);
        lanes[k % 4] = mix(lanes[k % 4], u64::from_le_bytes(w));
    }
    let mut h = lanes[0];
    for lane in &lanes[1..] {
        h = mix(h, *lane);
    }
    h ^= bytes.len() as u64;
    h ^= h >> 30;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 27;
    h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
    h ^ (h >> 31)
}

/// The format version the crate writes (bytes 8..12 of every file it saves; docs/format.md).
pub const FORMAT_VERSION: u32 = 6;

/// A model loaded from `bytes`, saved again: a file of the current format version must come back
/// byte for byte (trailing bytes after it are not read); an older one the loader accepted (format
/// versions 3 to 5, or 2 for every kind but the bin map) must come back as a current file that
/// loads and saves to itself.
pub fn check_resave<M>(
    bytes: &[u8],
    model: &M,
    save: impl Fn(&M, &mut Vec<u8>) -> brdf::Result<()>,
    load: impl Fn(&[u8]) -> brdf::Result<M>,
) {
    let saved = |m: &M| {
        let mut out = Vec::new();
        save(m, &mut out).unwrap();
        out
    };
    let again = saved(model);
    let version = u32::from_le_bytes(bytes[8..12].try_into().unwrap());
    assert_eq!(
        u32::from_le_bytes(again[8..12].try_into().unwrap()),
        FORMAT_VERSION
    );
    if version == FORMAT_VERSION {
        assert_eq!(&bytes[..again.len()], &again[..]);
    } else {
        assert!(
            (2..FORMAT_VERSION).contains(&version),
            "only versions 2 to 5 are read besides the current one"
        );
        assert_eq!(saved(&load(&again).unwrap()), again);
    }
}

/// Input of the store targets: the bytes of a file (re-sealed with a valid checksum when `reseal`,
/// so that mutations reach the content checks rather than stopping at the checksum), and a footprint
/// and probe to query a loaded model with.
///
/// Layout of the fuzz input: 1 flag byte (bit 0 = reseal), the footprint (24 bytes) and the probe
/// (36 bytes) as `arbitrary` decodes them, then the file bytes as they are (not through
/// `Vec<u8>: Arbitrary`, which interleaves a continuation byte per element).
#[derive(Debug)]
pub struct StoreInput {
    pub reseal: bool,
    pub footprint: FootprintInput,
    pub probe: Probe,
    pub file: Vec<u8>,
}

impl StoreInput {
    /// Splits raw fuzz bytes as described above (missing bytes read as zeros).
    pub fn parse(data: &[u8]) -> StoreInput {
        let mut u = arbitrary::Unstructured::new(data);
        let reseal = u8::arbitrary(&mut u).unwrap_or(0) & 1 == 1;
        let footprint = FootprintInput::arbitrary(&mut u).unwrap_or(FootprintInput {
            uv: (0.0, 0.0),
            duv_dx: (0.0, 0.0),
            duv_dy: (0.0, 0.0),
        });
        let probe = Probe::arbitrary(&mut u).unwrap_or(Probe {
            wo: (0.0, 0.0, 1.0),
            wi: (0.0, 0.0, 1.0),
            u: (0.5, 0.5),
            uc: 0.5,
        });
        let file = u.take_rest().to_vec();
        StoreInput {
            reseal,
            footprint,
            probe,
            file,
        }
    }

    /// The file bytes, re-sealed if asked (files shorter than the checksum are left alone).
    pub fn bytes(&self) -> Vec<u8> {
        let mut f = self.file.clone();
        if self.reseal && f.len() >= 8 {
            let n = f.len() - 8;
            let sum = format_checksum(&f[..n]);
            f[n..].copy_from_slice(&sum.to_le_bytes());
        }
        f
    }
}
