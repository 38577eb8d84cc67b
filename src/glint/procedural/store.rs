//! Saving and loading a [`ProceduralGlints`] surface (format: docs/format.md, kind 6): its
//! parameters only (the levels are recomputed by the same code as [`ProceduralGlints::new`], so a
//! loaded surface answers every query bit-identically), 40 bytes of payload. The payload is the
//! same in every format version the loaders read.

use super::{ProceduralGlints, ProceduralParams};
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
        format::save(w, Kind::ProceduralGlints, |e| {
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
        let mut d = Decoder::open(r, Kind::ProceduralGlints)?;
        let params = ProceduralParams {
            alpha: Vec2::new(d.get("alpha.x")?, d.get("alpha.y")?),
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
    const KINDS: &'static [Kind] = &[Kind::ProceduralGlints];
    fn save_to(&self, mut w: &mut dyn Write) -> Result<()> {
        self.save(&mut w)
    }
    fn load_from(mut r: &mut dyn Read) -> Result<Self> {
        Self::load(&mut r)
    }
}
