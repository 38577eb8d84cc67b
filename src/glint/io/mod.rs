//! Storage of built maps (crate-private, but the format is public: docs/format.md).
//!
//! - format.rs: the checksummed binary file format's encoder and bounded decoder, shared by every
//!   stored type's `save` / `load`.
//! - header.rs: the header (magic, version, [`Kind`](header::Kind) codes, payload length), read
//!   and judged: foreign bytes, a damaged header, an intact file of a version or kind not read.
//! - checksum.rs: the file checksum (and format version 1's, to recognise such files).
//! - multiset.rs: a randomised multiset fingerprint (the bin map's load check of 𝓑 against 𝓑⁻¹).
//!
//! `serde` support (feature `serde`) goes through these bytes too, one layer up, beside the registry
//! (glint/serialize.rs): it names every model, which this layer below the models must not.

pub(crate) mod checksum;
pub(crate) mod format;
pub(crate) mod header;
pub(crate) mod multiset;
