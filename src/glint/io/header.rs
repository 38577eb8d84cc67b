//! The 24-byte header of a stored file, read and judged before any payload: foreign bytes, a
//! damaged header, an intact file this loader does not read, or a header to go on with.
//!
//! A header value a loader cannot use has two explanations: the file is intact and says so (a newer
//! version, another model's kind), or the header is damaged. The file's checksum (docs/format.md)
//! covers the header, so it tells them apart: the loader reads the rest of the file as the header
//! declares it (payload, then checksum, in bounded chunks, nothing kept) and believes the header only
//! if the checksum matches ([`Seal::Intact`]). The magic is the exception: foreign bytes carry no
//! checksum, so it is judged by how far it is from `BRDFGLNT` ([`MIN_MAGIC_MATCH`]). The rules, as
//! docs/format.md ("Damaged or unsupported") states them:
//!
//! | header | checksum | error |
//! |---|---|---|
//! | magic with fewer than [`MIN_MAGIC_MATCH`] bytes of `BRDFGLNT` | not read | [`Error::BadMagic`] |
//! | magic with [`MIN_MAGIC_MATCH`] to 7 bytes of `BRDFGLNT` | not read | [`Error::CorruptHeader`] |
//! | version not read, kind not expected | matches | [`Error::UnsupportedVersion`], [`Error::WrongModelKind`] |
//! | version not read, kind not expected | does not match | [`Error::CorruptHeader`] |
//! | any | the file ends before it | [`Error::Truncated`] |
//!
//! A version-1 file is confirmed with the checksum of version 1 ([`ChecksumV1`]), every other
//! version with the current one: the format keeps the header and the checksum in every version.

use super::checksum::{Checksum, ChecksumV1, FileHash};
use crate::{Error, Result};
use std::io::Read;

/// The first 8 bytes of every file.
pub(crate) const MAGIC: [u8; 8] = *b"BRDFGLNT";

/// The format version written. Version 6 adds the filtered mixture's chain (with its residuals) and
/// measured errors to the full mixture's and the position-normal map's payloads, and the moment
/// masking's measured errors to the bin map's, so that a loader reads what a build measured. Version 5 adds the mixture's seed kernel (files of older versions
/// hold Gaussian-seeded mixtures). Version 4 holds no per-query options (the mixture's masking mode and
/// cost cap, the position-normal map's footprint cap: read and ignored in older files, since options
/// are per query); version 3 added 𝓑 to the bin map's payload and the levels' merge errors to the
/// full mixture's; version 2 files of every kind but the bin map are still read ([`OLDEST_READ`]; a
/// version-2 full mixture gets its merge errors recomputed).
pub(crate) const VERSION: u32 = 6;

/// The oldest format version read (for every kind but the bin map, whose loader needs version 3).
pub(crate) const OLDEST_READ: u32 = 2;

/// Bytes of the header (magic, version, kind, payload length).
pub(crate) const HEADER_BYTES: usize = 24;

/// Bytes of the rest of a file read at once when its checksum is consulted (not kept).
const CONFIRM_CHUNK_BYTES: usize = 1 << 16;

/// The model stored in a file: the format's registry of kind codes (one line per stored type; the
/// codes are part of the format, docs/format.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// [`crate::glint::NormalMap`].
    NormalMap = 1,
    /// [`crate::glint::BeckmannMixture`].
    BeckmannMixture = 2,
    /// [`crate::glint::PositionNormalMap`].
    PositionNormalMap = 3,
    /// [`crate::glint::BinMap`].
    BinMap = 4,
    /// [`crate::glint::BeckmannMixture`] in compact storage
    /// ([`crate::glint::mixture::LobeStorage::Compact`]).
    BeckmannMixtureCompact = 5,
    /// [`crate::glint::ProceduralGlints`] of the Beckmann limit.
    ProceduralGlints = 6,
    /// [`crate::glint::ProceduralGlints`] of the GGX limit (the payload of kind 6).
    ProceduralGlintsGgx = 7,
}

impl Kind {
    pub(crate) fn name(code: u32) -> String {
        match code {
            1 => "NormalMap".into(),
            2 => "BeckmannMixture".into(),
            3 => "PositionNormalMap".into(),
            4 => "BinMap".into(),
            5 => "BeckmannMixture (compact)".into(),
            6 => "ProceduralGlints".into(),
            7 => "ProceduralGlints (GGX)".into(),
            c => format!("unknown kind {c}"),
        }
    }
}

/// Fewest bytes of a file's first 8 equal to `BRDFGLNT` (at the same places) for the file to be
/// taken for a brdf file with a damaged magic rather than for foreign bytes.
///
/// 6 of 8: one or two damaged bytes of the magic give [`Error::CorruptHeader`], while foreign bytes
/// (a PNG, a text file) share at most a byte or two with it by chance: bytes drawn uniformly match
/// 6 of 8 given ones with probability C(8, 6) · 256⁻⁶ ≈ 10⁻¹³.
pub(crate) const MIN_MAGIC_MATCH: usize = 6;

/// A header a loader accepted.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Header {
    /// The header's bytes, as read.
    pub(crate) bytes: [u8; HEADER_BYTES],
    /// The format version ([`OLDEST_READ`] ..= [`VERSION`]).
    pub(crate) version: u32,
    /// The model kind, one of the kinds the loader expected.
    pub(crate) kind: Kind,
    /// The declared payload length in bytes.
    pub(crate) payload: u64,
}

/// What the rest of a file says about its header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Seal {
    /// The stored checksum matches the bytes: the file is as it was written.
    Intact,
    /// The stored checksum does not match.
    Broken,
    /// The file ends inside the named part before its checksum could be read.
    EndsEarly(&'static str),
}

impl Seal {
    /// The error of a header value the loader cannot use: `intact` if the checksum vouches for the
    /// file, else a damaged `field` (with `reason`), or the truncation.
    pub(crate) fn judge(
        self,
        intact: Error,
        field: &'static str,
        reason: impl FnOnce() -> String,
    ) -> Error {
        match self {
            Seal::Intact => intact,
            Seal::Broken => Error::CorruptHeader {
                field,
                reason: reason(),
            },
            Seal::EndsEarly(what) => Error::Truncated { what },
        }
    }
}

/// Reads a header and judges it (module docs): the header of a file of one of the `expected` kinds
/// (not empty) at a version this build reads. `expected_name` names the expected type in
/// [`Error::WrongModelKind`]. Reads exactly the header from `r`, unless the header is refused after
/// its checksum was consulted: then the whole file (32 + P bytes, as a loader does).
///
/// # Errors
/// [`Error::BadMagic`], [`Error::CorruptHeader`], [`Error::UnsupportedVersion`],
/// [`Error::WrongModelKind`], [`Error::Truncated`], [`Error::Stream`].
pub(crate) fn read_header(
    r: &mut dyn Read,
    expected: &[Kind],
    expected_name: &str,
) -> Result<Header> {
    let mut bytes = [0u8; HEADER_BYTES];
    let n = read_up_to(r, &mut bytes)?;
    judge_magic(&bytes[..n.min(MAGIC.len())])?;
    if n < HEADER_BYTES {
        return Err(Error::Truncated { what: "the header" });
    }
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    let (version, code) = (word(8), word(12));
    let payload = u64::from(word(16)) | (u64::from(word(20)) << 32);
    if !(OLDEST_READ..=VERSION).contains(&version) {
        let seal = if version == 1 {
            confirm(r, hashed(ChecksumV1::new(), &bytes), payload)?
        } else {
            confirm(r, hashed(Checksum::new(), &bytes), payload)?
        };
        let intact = Error::UnsupportedVersion {
            found: version,
            supported: VERSION,
        };
        return Err(seal.judge(intact, "version", || {
            format!(
                "version {version} is not one this build reads ({OLDEST_READ} to {VERSION}) and \
                 the file's checksum does not match"
            )
        }));
    }
    let Some(&kind) = expected.iter().find(|&&k| k as u32 == code) else {
        let seal = confirm(r, hashed(Checksum::new(), &bytes), payload)?;
        let intact = Error::WrongModelKind {
            expected: expected_name.into(),
            found: Kind::name(code),
        };
        return Err(seal.judge(intact, "kind", || {
            format!(
                "kind {code} ({}) is not a {expected_name} and the file's checksum does not match",
                Kind::name(code)
            )
        }));
    };
    Ok(Header {
        bytes,
        version,
        kind,
        payload,
    })
}

/// The magic judged on the bytes present (fewer than 8 in a short file): all equal to `BRDFGLNT`'s
/// (a short file is then truncated, which the caller reports), else a damaged magic if at least
/// [`MIN_MAGIC_MATCH`] are, else foreign bytes.
fn judge_magic(present: &[u8]) -> Result<()> {
    let matching = present.iter().zip(&MAGIC).filter(|(a, b)| a == b).count();
    if matching == present.len() {
        return Ok(());
    }
    if matching >= MIN_MAGIC_MATCH {
        return Err(Error::CorruptHeader {
            field: "magic",
            reason: format!(
                "the magic bytes \"{}\" are {} bytes off \"BRDFGLNT\"",
                present.escape_ascii(),
                MAGIC.len() - matching
            ),
        });
    }
    let mut found = [0u8; 8];
    found[..present.len()].copy_from_slice(present);
    Err(Error::BadMagic { found })
}

/// `sum` after `bytes`.
fn hashed<H: FileHash>(mut sum: H, bytes: &[u8]) -> H {
    sum.update(bytes);
    sum
}

/// Reads the rest of a file, `remaining` payload bytes and then the stored checksum, into `sum`
/// (which has taken every byte before them), in chunks of at most 64 KiB that are not kept: whether
/// the checksum matches. Reads exactly `remaining` + 8 bytes, or up to the end of a shorter file.
///
/// # Errors
/// [`Error::Stream`] (the end of the data is [`Seal::EndsEarly`], not an error).
pub(crate) fn confirm(r: &mut dyn Read, mut sum: impl FileHash, remaining: u64) -> Result<Seal> {
    let mut left = remaining;
    let mut buf = vec![
        0u8;
        usize::try_from(left)
            .map_or(CONFIRM_CHUNK_BYTES, |l| l.min(CONFIRM_CHUNK_BYTES))
    ];
    while left > 0 {
        let k = usize::try_from(left).map_or(buf.len(), |l| l.min(buf.len()));
        if read_up_to(r, &mut buf[..k])? < k {
            return Ok(Seal::EndsEarly("the payload"));
        }
        sum.update(&buf[..k]);
        left -= k as u64;
    }
    let mut stored = [0u8; 8];
    if read_up_to(r, &mut stored)? < stored.len() {
        return Ok(Seal::EndsEarly("the checksum"));
    }
    Ok(if u64::from_le_bytes(stored) == sum.finish() {
        Seal::Intact
    } else {
        Seal::Broken
    })
}

/// Reads until `buf` is full or the data end: the number of bytes read.
fn read_up_to(r: &mut dyn Read, buf: &mut [u8]) -> Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match r.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(source) => return Err(Error::Stream { source }),
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magic_is_judged_by_its_distance() {
        assert!(judge_magic(b"BRDFGLNT").is_ok());
        assert!(
            judge_magic(b"BRD").is_ok(),
            "a prefix: the caller reports the truncation"
        );
        assert!(matches!(
            judge_magic(b"BRDFGLNX"),
            Err(Error::CorruptHeader { field: "magic", .. })
        ));
        assert!(matches!(
            judge_magic(b"XRDFGLNX"),
            Err(Error::CorruptHeader { field: "magic", .. })
        ));
        assert!(matches!(
            judge_magic(b"XXDFGLNX"),
            Err(Error::BadMagic { .. })
        ));
        assert!(matches!(
            judge_magic(b"\x89PNG\r\n\x1a\n"),
            Err(Error::BadMagic { .. })
        ));
        assert!(matches!(judge_magic(b"PK"), Err(Error::BadMagic { .. })));
    }
}
