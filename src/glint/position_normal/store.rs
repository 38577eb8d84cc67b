//! Saving and loading a built [`PositionNormalMap`] (format: docs/format.md, kind 3).
//!
//! Stored: the map size, the build parameters (no per-query options), the elements (slope and
//! Jacobian, 24 bytes each) and, since format version 6, the filtered mixture's chain with its
//! residuals and measured errors (kernels/gmm_store.rs, ~36 bytes per element in the file, level 1's
//! components included; older files get them
//! built and measured as a build does). The slope boxes and their hierarchy are rebuilt on load by
//! the same code as the build (O(elements)), so every query of a loaded map is bit-identical to the
//! built one.

use super::{PositionNormalMap, PositionNormalParams};
use crate::Result;
use crate::glint::MAX_SLOPE;
use crate::glint::io::format::{self, Decoder, Kind, Stored};
use crate::glint::kernels::gmm_store::{self, ChainBounds};
use std::io::{Read, Write};

impl PositionNormalMap {
    /// Writes the representation in the crate's binary format (docs/format.md): map size, parameters
    /// and elements, exactly (f32 bits), 24 bytes per element. Writes in 64 KiB blocks.
    ///
    /// # Errors
    /// [`crate::Error::Stream`] if the writer fails.
    pub fn save(&self, w: &mut impl Write) -> Result<()> {
        let p = &self.params;
        format::save(w, Kind::PositionNormalMap, |e| {
            e.len(self.width)?;
            e.len(self.height)?;
            e.len(p.sampling_rate)?;
            e.put(p.sigma_r)?;
            e.put(p.weight_sigmas)?;
            e.put(p.slope_sigmas)?;
            e.array(self.elements.iter().copied())?;
            // The filtered mixture's chain and its measured errors (since version 6).
            gmm_store::save_chain(
                e,
                self.filtered_chain(),
                |k| self.element_marginal(k),
                self.filtered_mixture_errors(),
            )
        })
    }

    /// Reads a representation written by [`PositionNormalMap::save`]. Its patches answer `d`,
    /// `lambda`, `projected_area`, `sample_visible` and `pdf_visible` bit-identically to the saved
    /// one's with the same per-query [`PatchOptions`](super::PatchOptions) (which no file holds: the
    /// footprint cap that files of format versions 2 and 3 stored is read and ignored).
    ///
    /// # Errors
    /// [`crate::Error::BadMagic`] (foreign bytes), [`crate::Error::CorruptHeader`] (a damaged header,
    /// docs/format.md "Damaged or unsupported"), [`crate::Error::UnsupportedVersion`],
    /// [`crate::Error::WrongModelKind`], [`crate::Error::Truncated`],
    /// [`crate::Error::ChecksumMismatch`], [`crate::Error::Stream`]; [`crate::Error::InvalidFile`] for
    /// parameters the builder refuses, a map size out of range, an element count that does not match
    /// the grid, or elements that no build produces (non-finite, slopes beyond 2 · `MAX_SLOPE`,
    /// Jacobian entries beyond 4 · `MAX_SLOPE` · rate).
    pub fn load(r: &mut impl Read) -> Result<Self> {
        let mut d = Decoder::open(r, Kind::PositionNormalMap)?;
        let width = d.len("width", i32::MAX as usize)?;
        let height = d.len("height", i32::MAX as usize)?;
        let params = PositionNormalParams {
            sampling_rate: d.len("sampling_rate", usize::MAX)?,
            sigma_r: d.get("sigma_r")?,
            weight_sigmas: d.get("weight_sigmas")?,
            slope_sigmas: d.get("slope_sigmas")?,
        };
        if d.version() < 4 {
            // Versions 2 and 3 stored the per-query footprint cap; options are per query, so it is
            // read past and dropped.
            let _max_query_texels: f32 = d.get("max_query_texels")?;
        }
        let refused = |e: crate::Error| format::invalid(format!("stored map refused: {e}"));
        params.validate().map_err(refused)?;
        crate::glint::surface::texel_count(width, height, width.saturating_mul(height))
            .map_err(refused)?;
        let [nx, ny] = super::element_grid(width, height, &params).map_err(refused)?;
        // Built elements: interpolated slopes (≤ MAX_SLOPE up to rounding) and central differences of
        // them over 1/rate texels (≤ 2 · MAX_SLOPE · rate); a factor 2 to spare on both.
        let s = 2.0 * MAX_SLOPE;
        let j = 4.0 * MAX_SLOPE * params.sampling_rate as f32;
        let elements =
            d.array_in_range::<6>(
                "elements",
                nx * ny,
                |c| {
                    if c < 2 { (-s, s) } else { (-j, j) }
                },
            )?;
        // Format version 6 holds the filtered mixture's chain and measured errors; older files get
        // them built and measured, as a build does. The chain's components are element marginals
        // N(ñ_i, σ_h² J_i J_iᵀ + σ_r² I) and their moment-matched merges, whose raw second moments
        // average those of the marginals: below s² + 2 (σ_h j)² + σ_r² (σ_h j ≤ 1.7 · MAX_SLOPE for
        // the bounds above); twice that to spare.
        let chain = if d.version() >= 6 {
            let sh_j = 1.7 * MAX_SLOPE;
            let bounds = ChainBounds {
                mean: s,
                second: 2.0 * (s * s + 2.0 * sh_j * sh_j + params.sigma_r * params.sigma_r),
            };
            Some(gmm_store::load_chain(&mut d, nx, ny, bounds)?)
        } else {
            None
        };
        d.finish()?;
        let chain = chain
            .map(|c| c.into_chain(nx, ny, params.sigma_r))
            .transpose()?;
        PositionNormalMap::from_parts(width, height, params, elements, chain).map_err(refused)
    }
}

impl Stored for PositionNormalMap {
    const KINDS: &'static [Kind] = &[Kind::PositionNormalMap];
    fn save_to(&self, mut w: &mut dyn Write) -> Result<()> {
        self.save(&mut w)
    }
    fn load_from(mut r: &mut dyn Read) -> Result<Self> {
        Self::load(&mut r)
    }
}
