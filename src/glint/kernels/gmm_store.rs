//! The filtered-mixture chain (gmm.rs) and its measured errors (filtered_error.rs) in a model's file
//! (docs/format.md, "The filtered mixture in a file"): a loader reads them instead of re-deriving
//! them (the Runnalls reductions, the residuals and the error measurement are most of a build's
//! derived work), so a loaded model answers bit-identically to the built one.
//!
//! Layout, after the model's own payload: the level count L (`u64`, the chain's levels above the
//! lobes), then per level l = 1..=L an array of its nodes (row major), each
//! [`NodeRecord`] = [`GMM_LOBES`] × (weight, E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ) then ρ, η, ‖u‖₂ (`f32`);
//! then the measured errors: their count (0 when the map is too small for any to be measured, else
//! one per level of the chain, level 0 included), then one `f32` each.

use super::gmm::{GMM_LOBES, GmmPyramid, NodeRecord};
use super::slope_tree::level_sizes;
use crate::Result;
use crate::glint::io::format::{self, Decoder, Encoder};
use crate::ndf::SlopeGaussian;

/// What a loader accepts of a stored chain's components: means within ±`mean`, raw second moments
/// E x̃², E ỹ² in [0, `second`] and E x̃ỹ in ±`second` (each model's bound from what its build can
/// produce, with room to spare).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChainBounds {
    pub mean: f32,
    pub second: f32,
}

/// A chain and its errors as read, before [`StoredChain::into_chain`] checks what the ranges
/// cannot (node counts, weight sums); called after the decoder's `finish`, so that a damaged file
/// is reported as damaged first.
pub(crate) struct StoredChain {
    records: Vec<Vec<NodeRecord>>,
    pub errors: Vec<f32>,
}

/// Writes `chain` and its measured `errors` (one per level of the chain); `lobe0(k)` is the
/// level-0 lobe k as at the build (the chain serves level 1 from its lobes).
pub(crate) fn save_chain(
    e: &mut Encoder<'_>,
    chain: &GmmPyramid,
    lobe0: impl Fn(usize) -> SlopeGaussian + Copy,
    errors: &[f32],
) -> Result<()> {
    e.len(chain.levels() - 1)?;
    for l in 1..chain.levels() {
        e.array(chain.records(l, lobe0))?;
    }
    e.array(errors.iter().map(|&v| [v]))
}

/// Reads what [`save_chain`] wrote for an `nx × ny` lobe grid, every value checked against
/// `bounds` (weights in [0, 1], residuals finite and ≥ 0) as it is read; the errors are checked by
/// [`StoredChain::into_chain`].
///
/// # Errors
/// [`crate::Error::InvalidFile`] for a level count or node count that does not match the grid
/// (checked before anything is allocated); the decoder's errors.
pub(crate) fn load_chain(
    d: &mut Decoder<'_>,
    nx: usize,
    ny: usize,
    bounds: ChainBounds,
) -> Result<StoredChain> {
    let sizes = level_sizes(nx, ny);
    let n = d.len("filtered-mixture levels", usize::MAX)?;
    if n.checked_add(1) != Some(sizes.len()) {
        return Err(format::invalid(format!(
            "filtered-mixture levels = {n} but the grid {nx}×{ny} has {} above the lobes",
            sizes.len() - 1
        )));
    }
    let (m, s) = (bounds.mean, bounds.second);
    let mut records = Vec::with_capacity(n);
    for &[w, h] in &sizes[1..] {
        records.push(d.array_in_range::<{ 6 * GMM_LOBES + 3 }>(
            "filtered-mixture nodes",
            w * h,
            |c| {
                if c >= 6 * GMM_LOBES {
                    return (0.0, f32::MAX);
                }
                match c % 6 {
                    0 => (0.0, 1.0),
                    1 | 2 => (-m, m),
                    3 | 4 => (0.0, s),
                    _ => (-s, s),
                }
            },
        )?);
    }
    let errors = d.array_up_to::<f32, 1>("filtered-mixture errors", sizes.len())?;
    Ok(StoredChain {
        records,
        errors: errors.into_iter().map(|[v]| v).collect(),
    })
}

impl StoredChain {
    /// The chain, its node counts and weights checked ([`GmmPyramid::from_records`]).
    ///
    /// # Errors
    /// [`crate::Error::InvalidFile`] naming what does not match.
    pub fn into_chain(
        self,
        nx: usize,
        ny: usize,
        sigma_min: f32,
    ) -> Result<(GmmPyramid, Vec<f32>)> {
        let levels = level_sizes(nx, ny).len();
        if !(self.errors.is_empty() || self.errors.len() == levels) {
            return Err(format::invalid(format!(
                "{} filtered-mixture errors for a chain of {levels} levels (0 or one per level)",
                self.errors.len()
            )));
        }
        // Errors are total variations.
        if let Some(e) = self.errors.iter().find(|e| !(0.0..=1.0).contains(*e)) {
            return Err(format::invalid(format!(
                "filtered-mixture error {e} is not a total variation in [0, 1]"
            )));
        }
        let chain =
            GmmPyramid::from_records(nx, ny, self.records, sigma_min).map_err(format::invalid)?;
        Ok((chain, self.errors))
    }
}
