//! Saving and loading a [`ProceduralGlints`] surface (format: docs/format.md, kinds 6 and 7): its
//! parameters only (the levels are recomputed by the same code as [`ProceduralGlints::new`], so a
//! loaded surface answers every query bit-identically), 40 bytes of payload. The limit NDF is the
//! kind: 6 for Beckmann (the files every earlier reader reads), 7 for GGX (which a reader that
//! predates it refuses as an unknown kind); the payload is the same for both and in every format
//! version the loaders read.

use super::{ProceduralGlints, ProceduralLimit, ProceduralParams};
use crate::Result;
use crate::glint::io::format::{self, Decoder, Kind, Stored};
use glam::Vec2;
use std::io::{Read, Write};

impl ProceduralGlints {
    /// Writes the surface in the crate's binary format (docs/format.md): its parameters, exactly.
    ///
    /// # Errors
    /// [`crate::Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl Write) -> Result<()> {
        let p = &self.params;
        let kind = match p.limit {
            ProceduralLimit::Beckmann => Kind::ProceduralGlints,
            ProceduralLimit::Ggx => Kind::ProceduralGlintsGgx,
        };
        format::save(w, kind, |e| {
            e.put(p.alpha.x)?;
            e.put(p.alpha.y)?;
            e.put(p.facet_alpha)?;
            e.put(p.density)?;
            e.len(p.resolution[0])?;
            e.len(p.resolution[1])?;
            e.put(p.seed)
        })
    }

    /// Reads a surface written by [`ProceduralGlints::save`].
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`] (foreign bytes), [`crate::Error::CorruptHeader`] (a damaged
    /// header), [`crate::Error::UnsupportedVersion`], [`crate::Error::WrongModelKind`],
    /// [`crate::Error::Truncated`], [`crate::Error::ChecksumMismatch`], [`crate::Error::Stream`];
    /// [`crate::Error::InvalidFile`] for parameters that [`ProceduralGlints::new`] refuses.
    pub fn load(r: &mut impl Read) -> Result<Self> {
        let (mut d, kind) = Decoder::open_any(r, Self::KINDS)?;
        let limit = if kind == Kind::ProceduralGlintsGgx {
            ProceduralLimit::Ggx
        } else {
            ProceduralLimit::Beckmann
        };
        let params = ProceduralParams {
            alpha: Vec2::new(d.get("alpha.x")?, d.get("alpha.y")?),
            limit,
            facet_alpha: d.get("facet_alpha")?,
            density: d.get("density")?,
            resolution: [
                d.len("resolution[0]", u32::MAX as usize)?,
                d.len("resolution[1]", u32::MAX as usize)?,
            ],
            seed: d.get("seed")?,
        };
        d.finish()?;
        ProceduralGlints::new(params)
            .map_err(|e| format::invalid(format!("stored surface refused: {e}")))
    }
}

impl Stored for ProceduralGlints {
    const KINDS: &'static [Kind] = &[Kind::ProceduralGlints, Kind::ProceduralGlintsGgx];
    fn save_to(&self, mut w: &mut dyn Write) -> Result<()> {
        self.save(&mut w)
    }
    fn load_from(mut r: &mut dyn Read) -> Result<Self> {
        Self::load(&mut r)
    }
}
