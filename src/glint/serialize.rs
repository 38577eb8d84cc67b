//! `serde` support for built glint maps and normal maps (feature `serde`).
//!
//! Each model serialises as one byte string: its file in the crate's binary format (docs/format.md),
//! header, checksum and all. So a map kept inside a renderer's own asset format (postcard, bincode-like
//! or JSON containers) round-trips exactly like a file — every query of the deserialised model is
//! bit-identical to the saved one's — and deserialising runs the same loader, with every check and
//! error of [`BeckmannMixture::load`] and friends (reported through `serde`'s custom error).
//!
//! Self-describing text formats (JSON) store the bytes as an array of numbers: correct, but ~4× the
//! binary size; use a binary serde format or the files themselves for large maps.

use crate::glint::{
    BeckmannMixture, BinMap, GlintModel, NormalMap, PositionNormalMap, ProceduralGlints,
};
use serde::de::{Deserializer, Error as _, SeqAccess, Visitor};
use serde::ser::{Error as _, Serializer};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Accepts a byte string, or a sequence of bytes (what self-describing formats produce).
struct FileBytes;

impl<'de> Visitor<'de> for FileBytes {
    type Value = Vec<u8>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("the bytes of a brdf glint file (docs/format.md)")
    }

    fn visit_bytes<E: serde::de::Error>(self, v: &[u8]) -> Result<Vec<u8>, E> {
        Ok(v.to_vec())
    }

    fn visit_byte_buf<E: serde::de::Error>(self, v: Vec<u8>) -> Result<Vec<u8>, E> {
        Ok(v)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u8>, A::Error> {
        // The size hint comes from the input: cap the reservation, grow as bytes arrive.
        let mut v = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 16));
        while let Some(b) = seq.next_element::<u8>()? {
            v.push(b);
        }
        Ok(v)
    }
}

macro_rules! serde_via_file {
    ($t:ty, $load:path) => {
        impl Serialize for $t {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let mut bytes = Vec::new();
                self.save(&mut bytes).map_err(S::Error::custom)?;
                s.serialize_bytes(&bytes)
            }
        }

        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let bytes = d.deserialize_byte_buf(FileBytes)?;
                $load(&mut bytes.as_slice()).map_err(D::Error::custom)
            }
        }
    };
}

serde_via_file!(NormalMap, NormalMap::load);
serde_via_file!(BeckmannMixture, BeckmannMixture::load);
serde_via_file!(PositionNormalMap, PositionNormalMap::load);
serde_via_file!(BinMap, BinMap::load);
serde_via_file!(ProceduralGlints, ProceduralGlints::load);
serde_via_file!(GlintModel, GlintModel::load);
