//! Storage of built maps (crate-private, but the format is public: docs/format.md).
//!
//! - format.rs: the checksummed binary file format, its header, [`Kind`](format::Kind) codes,
//!   encoder and bounded decoder, shared by every stored type's `save` / `load`.
//! - multiset.rs: a randomised multiset fingerprint (the bin map's load check of 𝓑 against 𝓑⁻¹).
//!
//! `serde` support (feature `serde`) goes through these bytes too, one layer up, beside the registry
//! (glint/serialize.rs): it names every model, which this layer below the models must not.

pub(crate) mod format;
pub(crate) mod multiset;
