//! Saving and loading a built [`BeckmannMixture`] (format: docs/format.md, kind 2).
//!
//! Stored: the map size, the build parameters and the lobes' moments (20 bytes per lobe). The slope
//! boxes, their hierarchy and the moment mip chain are rebuilt on load by the same code as the build
//! (O(lobes), parallel): this keeps files at 20 bytes per lobe and every query of a loaded mixture
//! bit-identical to the built one.

use super::{BeckmannMixture, MaskingMode, MixtureParams, PatchOptions};
use crate::Result;
use crate::glint::MAX_SLOPE;
use crate::glint::store::{self, Decoder, Kind};
use std::io::{Read, Write};

/// Bound on stored mean slopes: 2 · [`MAX_SLOPE`]. Built moments average slopes of at most
/// `MAX_SLOPE` (interpolated slopes may exceed it by rounding only), so every built file passes with
/// a factor 2 to spare; the bound keeps squares and products finite in f32.
const MEAN_BOUND: f32 = 2.0 * MAX_SLOPE;

impl BeckmannMixture {
    /// Writes the mixture in the crate's binary format (docs/format.md): map size, parameters and
    /// moments, exactly (f32 bits), about 20 bytes per lobe. Writes in 64 KiB blocks.
    ///
    /// # Errors
    /// [`crate::Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl Write) -> Result<()> {
        let p = &self.params;
        store::save(w, Kind::BeckmannMixture, |e| {
            e.len(self.width)?;
            e.len(self.height)?;
            e.put(p.spacing)?;
            e.put(p.sigma_min)?;
            e.len(p.samples)?;
            e.put(p.kernel_sigmas)?;
            e.put(p.weight_sigmas)?;
            e.put(p.slope_tail)?;
            e.put(match p.patch.masking {
                MaskingMode::Exact => 0u32,
                MaskingMode::Approximate => 1u32,
            })?;
            e.put(p.patch.lod_lobes)?;
            e.array(self.lobes.iter().copied())
        })
    }

    /// Reads a mixture written by [`BeckmannMixture::save`]. Its patches answer `d`, `lambda`,
    /// `projected_area`, `sample_visible` and `pdf_visible` bit-identically to the saved mixture's.
    ///
    /// Cost: one pass over the file plus the O(lobes) hierarchy and mip chain (parallel); no moment
    /// integration. Memory is allocated only as data arrive (in 64 KiB steps), whatever the header
    /// claims.
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`], [`crate::Error::UnsupportedVersion`],
    /// [`crate::Error::WrongModelKind`], [`crate::Error::Truncated`],
    /// [`crate::Error::ChecksumMismatch`], [`crate::Error::Stream`]; [`crate::Error::InvalidFile`] for
    /// parameters the builder refuses, a map size out of range, a lobe count that does not match the
    /// grid the size and spacing give, or moments that no built mixture holds (non-finite, means
    /// beyond 2 · `MAX_SLOPE`, second moments beyond its square or negative).
    pub fn load(r: &mut impl Read) -> Result<Self> {
        let mut d = Decoder::open(r, Kind::BeckmannMixture)?;
        let width = d.len("width", i32::MAX as usize)?;
        let height = d.len("height", i32::MAX as usize)?;
        let spacing = d.get("spacing")?;
        let sigma_min = d.get("sigma_min")?;
        let samples = d.len("samples", usize::MAX)?;
        let kernel_sigmas = d.get("kernel_sigmas")?;
        let weight_sigmas = d.get("weight_sigmas")?;
        let slope_tail = d.get("slope_tail")?;
        let masking = match d.get::<u32>("masking")? {
            0 => MaskingMode::Exact,
            1 => MaskingMode::Approximate,
            m => {
                return Err(store::invalid(format!(
                    "masking mode {m} (0 or 1 expected)"
                )));
            }
        };
        let lod_lobes = d.get("lod_lobes")?;
        let params = MixtureParams {
            spacing,
            sigma_min,
            samples,
            kernel_sigmas,
            weight_sigmas,
            slope_tail,
            // The level-of-detail tolerance is not stored (the format is unchanged): the default.
            patch: PatchOptions {
                masking,
                lod_lobes,
                ..PatchOptions::default()
            },
            ..MixtureParams::default()
        };
        let refused = |e: crate::Error| store::invalid(format!("stored mixture refused: {e}"));
        params.validate().map_err(refused)?;
        crate::glint::normal_map::texel_count(width, height, width.saturating_mul(height))
            .map_err(refused)?;
        let ([nx, ny], _) = super::lobe_grid(width, height, &params).map_err(refused)?;
        let lobes = d.array::<f32, 5>("lobes", nx * ny)?;
        d.finish()?;
        let m2 = MEAN_BOUND * MEAN_BOUND;
        store::check_range(&lobes, "lobes", |c| match c {
            0 | 1 => (-MEAN_BOUND, MEAN_BOUND),
            2 | 3 => (0.0, m2),
            _ => (-m2, m2),
        })?;
        BeckmannMixture::from_parts(width, height, params, lobes).map_err(refused)
    }
}
