//! Storage of built maps (crate-private, but the format is public: docs/format.md).
//!
//! - format.rs: the checksummed binary file format, its header, [`Kind`](format::Kind) codes,
//!   encoder and bounded decoder, shared by every stored type's `save` / `load`.
//! - checksum.rs: the file checksum (and format version 1's, to recognise such files).
//! - header.rs: the header read and judged: foreign bytes, a damaged header, an intact file of a
//!   version or kind not read.
//! - multiset.rs: a randomised multiset fingerprint (the bin map's load check of 𝓑 against 𝓑⁻¹).
//! - serde.rs: `Serialize` / `Deserialize` through the file bytes (feature `serde`).

pub(crate) mod checksum;
pub(crate) mod format;
pub(crate) mod header;
pub(crate) mod multiset;
#[cfg(feature = "serde")]
mod serde;
