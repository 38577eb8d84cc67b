//! The crate's one error type. Errors happen only at construction and I/O; evaluation never fails.

#[cfg(feature = "std")]
use std::path::PathBuf;

/// Everything that can go wrong when building a model or loading data.
///
/// Evaluation (`d`, `eval`, `pdf`, `sample`, …) never returns an error: degenerate input gives 0 / `None`.
///
/// The variants that hold a `String`, a path or an `io::Error` (files, decoding, texels) exist with
/// the `std` feature only; the analytic core raises none of them.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A scalar parameter is outside its valid range (non-finite, non-positive, …).
    #[error("invalid parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// The parameter's name as it appears in the constructor's signature.
        name: &'static str,
        /// The offending value (as `f64` so that integer parameters fit too).
        value: f64,
        /// What the valid range is.
        reason: &'static str,
    },
    /// A matrix parameter (covariance, …) is invalid: not finite, not symmetric positive definite, ….
    #[error("invalid matrix `{name}` {value:?}: {reason}")]
    InvalidMatrix {
        /// The parameter's name.
        name: &'static str,
        /// The entries, row major.
        value: [f64; 4],
        /// Why it is rejected.
        reason: &'static str,
    },
    /// Map dimensions are unusable (zero-sized, or not matching the data length).
    #[error("invalid map size {width}×{height}: {reason}")]
    InvalidSize {
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// Why it is rejected.
        reason: &'static str,
    },
    #[cfg(feature = "std")]
    /// One texel of a normal map / height field holds unusable data.
    #[error("{source_name}: texel ({x}, {y}): {reason}")]
    InvalidTexel {
        /// Where the data came from (a file path, or a description such as "normals").
        source_name: String,
        /// Texel column.
        x: usize,
        /// Texel row.
        y: usize,
        /// What is wrong with it.
        reason: String,
    },
    #[cfg(feature = "std")]
    /// A file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    #[cfg(feature = "std")]
    /// A file was read but could not be decoded as a usable image.
    #[error("cannot decode image {path}: {reason}")]
    Image {
        /// The file (or a description for in-memory bytes).
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    #[cfg(feature = "std")]
    /// A decoded normal map is implausible as a whole: most of its vectors are far from unit length
    /// or below the horizon (usually a file decoded with the wrong encoding), or the encoding could
    /// not be detected.
    #[error("{source_name}: implausible normal map: {reason}")]
    ImplausibleNormals {
        /// Where the data came from (a file path, or a description).
        source_name: String,
        /// The statistics and the likely cause.
        reason: String,
    },
    /// A stored model's file does not start with the format's magic bytes `BRDFGLNT`.
    #[error("not a brdf glint file: magic bytes {found:?} instead of \"BRDFGLNT\"")]
    BadMagic {
        /// The first 8 bytes found.
        found: [u8; 8],
    },
    /// A stored model's file has a format version this build cannot read.
    #[error(
        "unsupported file format version {found} (this build reads up to version {supported}; \
         the oldest version read depends on the model, docs/format.md)"
    )]
    UnsupportedVersion {
        /// The version in the file.
        found: u32,
        /// The newest version this build reads (the one it writes).
        supported: u32,
    },
    #[cfg(feature = "std")]
    /// A stored model's file header is damaged: a field holds a value that an intact file cannot
    /// have, and nothing vouches for it (docs/format.md, "Damaged or unsupported"). The magic bytes
    /// are at most two bytes off `BRDFGLNT`; or the version or kind is not one this loader reads and
    /// the file's checksum does not match; or the payload length disagrees with the fields the
    /// payload holds and the checksum does not match. An intact file with such a version or kind
    /// (its checksum matches) is [`Error::UnsupportedVersion`] or [`Error::WrongModelKind`] instead.
    #[error("corrupted file header ({field}): {reason}")]
    CorruptHeader {
        /// The header field judged damaged: "magic", "version", "kind" or "payload length".
        field: &'static str,
        /// What was found and why it is taken for damage.
        reason: String,
    },
    #[cfg(feature = "std")]
    /// A stored model's file holds another kind of model than the one asked for.
    #[error("the file holds a {found}, not a {expected}")]
    WrongModelKind {
        /// The type whose loader was called.
        expected: String,
        /// The kind stored in the file.
        found: String,
    },
    /// A stored model's file ended early.
    #[error("truncated file: it ends inside {what}")]
    Truncated {
        /// The field being read when the data ran out.
        what: &'static str,
    },
    /// A stored model's checksum does not match its contents (flipped or altered bytes).
    #[error(
        "checksum mismatch: stored {stored:#018x}, computed {computed:#018x} (the file is corrupt)"
    )]
    ChecksumMismatch {
        /// The checksum at the end of the file.
        stored: u64,
        /// The checksum of the bytes read.
        computed: u64,
    },
    #[cfg(feature = "std")]
    /// A stored model's file is well formed but its contents are inconsistent: lengths that do not
    /// match the parameters, invalid parameters or values, sizes beyond what the file holds.
    #[error("invalid file: {reason}")]
    InvalidFile {
        /// What is wrong.
        reason: String,
    },
    /// A ray footprint's input is not finite (a NaN or infinite uv, derivative, position or
    /// direction: a bug upstream, in the renderer), refused by the checked footprint constructors
    /// (`Footprint::try_from_differentials` and friends); the unchecked ones fall back to a
    /// documented footprint instead.
    #[error("invalid footprint input `{name}` = {value:?}: {reason}")]
    InvalidFootprint {
        /// The argument's name as it appears in the constructor's signature.
        name: &'static str,
        /// Its components (a 2D value has z = 0).
        value: [f32; 3],
        /// What the valid range is.
        reason: &'static str,
    },
    #[cfg(feature = "std")]
    /// Reading or writing a stream failed (other than by ending early).
    #[error("stream error: {source}")]
    Stream {
        /// The underlying error.
        source: std::io::Error,
    },
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = core::result::Result<T, E>;

/// Checks that a scalar parameter is finite and strictly positive.
pub(crate) fn positive(name: &'static str, value: f32) -> Result<f32> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value: value as f64,
            reason: "must be finite and > 0",
        })
    }
}

/// Checks that a scalar parameter is finite and ≥ 0.
pub(crate) fn non_negative(name: &'static str, value: f32) -> Result<f32> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value: value as f64,
            reason: "must be finite and >= 0",
        })
    }
}

/// Checks that a scalar parameter is finite.
#[allow(dead_code)] // not used by every layer yet
pub(crate) fn finite(name: &'static str, value: f32) -> Result<f32> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            name,
            value: value as f64,
            reason: "must be finite",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_parameter() {
        let e = positive("alpha_x", -1.0).unwrap_err();
        assert!(e.to_string().contains("alpha_x"), "{e}");
        assert!(positive("a", f32::NAN).is_err());
        assert!(positive("a", f32::INFINITY).is_err());
        assert!(positive("a", 0.0).is_err());
        assert_eq!(positive("a", 0.5).unwrap(), 0.5);
        assert!(non_negative("a", 0.0).is_ok());
        assert!(non_negative("a", -0.0).is_ok());
        assert!(non_negative("a", -1e-9).is_err());
        assert!(finite("a", f32::NEG_INFINITY).is_err());
    }
}
