//! The inverse bin map of \[Atanasov2020\]: a normal map quantised into equal-solid-angle direction
//! bins, the inverse map bin → texels sorted into a forest of 2D kd-trees, and the P-NDF of a
//! parallelogram footprint with constant filtering in texture and half-vector space.
//!
//! - [`BinMap::build`] splits every texel into s × s sub-texels ([`BinMapParams::subdivisions`]),
//!   assigns every sub-texel the bin of the interpolated normal at a point inside it (n-rooks
//!   pattern per texel; the bin map 𝓑; s = 1:
//!   the texel-centre normal, as in the talk), counting-sorts the sub-texels by bin into one array
//!   (the inverse bin map 𝓑⁻¹), builds one kd-tree per list longer than the leaf size L, packed into
//!   one `u32` array, and a lookup bin → list ([`BinLookup`]: dense offsets or a hash table of the
//!   non-empty bins).
//! - [`GlintNdf::patch_with`] turns a [`Footprint`] into a [`BinMapPatch`], an [`Ndf`](crate::ndf::Ndf) whose
//!   D(h) = mass_j / (|H| · c̄_j) for the bin j ∋ h, where mass_j = Σ_k I_{H_j}(t_k) |A ∩ T_k| / |A| is
//!   found through the bin's tree (whole nodes inside A count at once, boundary texels get their exact
//!   clipped area) and c̄_j is the bin's mean cosine. With
//!   [`PatchOptions::smoothing_alpha`] > 0 it spreads every bin's mass with a Beckmann lobe; with a
//!   caller's reusable [`GlintScratch`] it allocates nothing per shading point.
//!
//! The conventions (mean cosine, periodic images, masking lobe, samplers) and the measurements are in
//! docs/binmap.md.

mod clip;
mod facets;
mod footprint_moments;
mod forest;
mod lookup;
mod masking;
mod masking_choice;
mod params;
mod patch;
mod sampling;
mod store;

pub use forest::QueryStats;
pub use lookup::BinLookup;
pub use params::{
    BinMapParams, DEFAULT_BINS_PER_AXIS, DEFAULT_EXACT_MASKING_TEXELS, DEFAULT_LEAF_SIZE,
    DEFAULT_LOOKUP, DEFAULT_MASKING_SIGMA_MIN, DEFAULT_MOMENT_MASKING_TOLERANCE,
    DEFAULT_SMOOTHING_ALPHA, DEFAULT_SUBDIVISIONS, MASKING_FIRST_LEVEL, MAX_SUBDIVISIONS,
    MIN_MOMENT_MASKING_TEXELS, PatchOptions,
};
pub use patch::BinMapPatch;

use crate::error::{Error, Result};
use crate::frame::slope_to_normal;
use crate::glint::surface::MomentPyramid;
use crate::glint::{Footprint, GlintNdf, GlintScratch, HemisphereBins, NormalMap};
use facets::{BinFacet, BinTables, bin_tables};
use forest::{NO_TREE, TreeView};
use glam::{Vec2, Vec3};
use lookup::Table;
use rayon::prelude::*;

/// Bytes held by a [`BinMap`], per part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BinMapMemory {
    /// The bin map 𝓑: one `u16` (B ≤ 65 536 bins) or `u32` per sub-texel.
    pub bin_map: usize,
    /// The inverse bin map 𝓑⁻¹: one `u32` per sub-texel.
    pub inverse: usize,
    /// The packed forest: two `u32` per internal node.
    pub forest: usize,
    /// The bin lookup (dense offsets and roots, or the hash table).
    pub lookup: usize,
    /// Per-bin tables: centre slope and the masking facet (mean direction, whose z is the mean
    /// cosine, centre, radius): 36 bytes per bin.
    pub bin_tables: usize,
    /// The coarse slope-moment mip chain of the masking lobe.
    pub moments: usize,
}

impl BinMapMemory {
    /// The sum of the parts.
    pub fn total(&self) -> usize {
        self.bin_map + self.inverse + self.forest + self.lookup + self.bin_tables + self.moments
    }
}

/// The inverse bin map of a normal map, with its kd-tree forest.
///
/// D_A^H(h) = (1/(|H| |A|)) Σ_k I_H(t_k) |A ∩ T_k| (\[Atanasov2020\] §2), the fraction of the
/// footprint A covered by texels whose normal t_k lies in the bin H ∋ h, per unit solid angle; the
/// patches divide it by the bin's mean cosine so that ∫ D cos θ dω = 1 (docs/binmap.md).
///
/// Stored: 𝓑 and 𝓑⁻¹ (2 or 4 + 4 bytes per sub-texel, s² sub-texels per texel), the forest (two
/// `u32` per internal node), the lookup,
/// per-bin mean cosines and centre slopes, and the bins' slope-moment mip chain from level
/// [`MASKING_FIRST_LEVEL`] for the masking lobe (≈ 6.7 bytes per texel). The normal map itself is not
/// kept. See [`BinMap::memory`].
///
/// # Reference
/// \[Atanasov2020\] §2 (bins, D_A^H), §2.1 (sampling through 𝓑), §2.2-2.3 (𝓑⁻¹, hash map, forest).
#[derive(Clone, Debug)]
pub struct BinMap {
    width: usize,
    height: usize,
    bins: HemisphereBins,
    params: BinMapParams,
    /// The sub-texel grid: (s·width) × (s·height) elements, element (I, J) at index J·grid_w + I.
    grid_w: usize,
    grid_h: usize,
    bin_map: BinIndex,
    inverse: Vec<u32>,
    nodes: Vec<u32>,
    table: Table,
    center_slope: Vec<Vec2>,
    /// Per bin: mean direction (its z is the mean cosine c̄_j), centre and radius; sampled only for
    /// non-empty bins (`BinFacet::empty` otherwise).
    facets: Vec<BinFacet>,
    /// The directions of the bins' cell corners, (n + 1)² of them (facets.rs, `corner_grid`).
    corners: Vec<Vec3>,
    moments: MomentPyramid,
    /// The moment-lobe masking's measured error per level (masking_choice.rs), measured by the
    /// build (or read from a file).
    moment_masking_error: Vec<f32>,
}

/// 𝓑, one bin index per sub-texel, in the narrowest integer type that holds every bin.
#[derive(Clone, Debug)]
pub(super) enum BinIndex {
    U16(Vec<u16>),
    U32(Vec<u32>),
}

impl BinIndex {
    fn new(bins: usize, elements: usize) -> BinIndex {
        if bins <= 1 << 16 {
            BinIndex::U16(vec![0; elements])
        } else {
            BinIndex::U32(vec![0; elements])
        }
    }

    #[inline]
    pub(super) fn get(&self, k: usize) -> Option<usize> {
        match self {
            BinIndex::U16(v) => v.get(k).map(|&b| b as usize),
            BinIndex::U32(v) => v.get(k).map(|&b| b as usize),
        }
    }

    /// Asks the CPU for the entries [k0, k1) (a hint; nothing for an empty or out-of-range span).
    #[inline]
    pub(super) fn prefetch(&self, k0: usize, k1: usize) {
        use crate::glint::kernels::prefetch::prefetch;
        match self {
            BinIndex::U16(v) => {
                if let Some(s) = v.get(k0..k1) {
                    prefetch(s);
                }
            }
            BinIndex::U32(v) => {
                if let Some(s) = v.get(k0..k1) {
                    prefetch(s);
                }
            }
        }
    }

    /// Fills row `j` (of width `w`) with `f(I)`, in parallel over rows.
    fn fill(&mut self, w: usize, f: impl Fn(usize, usize) -> usize + Sync) {
        match self {
            BinIndex::U16(v) => v.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
                for (i, b) in row.iter_mut().enumerate() {
                    *b = f(i, j) as u16;
                }
            }),
            BinIndex::U32(v) => v.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
                for (i, b) in row.iter_mut().enumerate() {
                    *b = f(i, j) as u32;
                }
            }),
        }
    }

    fn bytes(&self) -> usize {
        match self {
            BinIndex::U16(v) => 2 * v.len(),
            BinIndex::U32(v) => 4 * v.len(),
        }
    }
}

fn invalid(name: &'static str, value: f64, reason: &'static str) -> Error {
    Error::InvalidParameter {
        name,
        value,
        reason,
    }
}

fn check_params(params: &BinMapParams) -> Result<HemisphereBins> {
    let n = params.bins_per_axis;
    if n.is_multiple_of(2) {
        return Err(invalid(
            "bins_per_axis",
            n as f64,
            "must be odd (and in 1..=4096) so that the pole is the centre of a bin",
        ));
    }
    let bins = HemisphereBins::new(n).map_err(|_| {
        invalid(
            "bins_per_axis",
            n as f64,
            "must be odd and in 1..=4096 (at least one bin)",
        )
    })?;
    if params.leaf_size == 0 {
        return Err(invalid("leaf_size", 0.0, "must be at least 1"));
    }
    if !(1..=MAX_SUBDIVISIONS).contains(&params.subdivisions) {
        return Err(invalid(
            "subdivisions",
            params.subdivisions as f64,
            "must be in 1..=16",
        ));
    }
    if !(params.sigma_min.is_finite() && params.sigma_min > 0.0) {
        return Err(invalid(
            "sigma_min",
            params.sigma_min as f64,
            "must be finite and positive",
        ));
    }
    Ok(bins)
}

/// The point, in texel units, whose interpolated normal sub-texel (I, J) of an s × s subdivision
/// carries: with (a, b) = (I mod s, J mod s) its place in texel (⌊I/s⌋, ⌊J/s⌋),
///
/// x = ⌊I/s⌋ + (a + (s − 1 − b + ½)/s)/s,  y = ⌊J/s⌋ + (b + (a + ½)/s)/s.
///
/// Each point lies inside its own sub-texel, and the s² points of a texel fall in s² distinct
/// strata of width 1/s² along x and along y (an n-rooks, "rotated grid" pattern; for s = 2 the
/// points (⅜, ⅛), (⅞, ⅜), (⅛, ⅝), (⅝, ⅞)). The uniform grid of sub-texel centres has only s distinct
/// coordinates per axis, so a map whose normals vary along one axis (brushed, scratched) would be
/// sampled s times per texel across it instead of s²: at s = 2, 255² bins, this pattern halves the TV distance
/// to the ground truth on the brushed map at 256 texels (0.123 → 0.063) for a 1.16× loss on the
/// isotropic bumpy map (docs/results.md, "Inverse bin map (Atanasov 2020)"). s = 1: the texel centre.
fn subtexel_point(i: usize, j: usize, s: usize) -> Vec2 {
    let (a, b) = (i % s, j % s);
    let sf = s as f32;
    Vec2::new(
        (i / s) as f32 + (a as f32 + ((s - 1 - b) as f32 + 0.5) / sf) / sf,
        (j / s) as f32 + (b as f32 + (a as f32 + 0.5) / sf) / sf,
    )
}

impl BinMap {
    /// Builds the bin map, the inverse bin map, its forest and lookup from a normal map.
    ///
    /// The map is split into s × s sub-texels (s = `subdivisions`); sub-texel (I, J) of the
    /// (s·width) × (s·height) grid covers [I/s, (I + 1)/s) × [J/s, (J + 1)/s) in texel units and is a
    /// flat facet with the interpolated surface's normal [`NormalMap::normal_at_texel`] at one point
    /// inside it, placed in an n-rooks pattern per texel (x = ⌊I/s⌋ + (a + (s − 1 − b + ½)/s)/s,
    /// y = ⌊J/s⌋ + (b + (a + ½)/s)/s with (a, b) = (I mod s, J mod s); for s = 1 the texel-centre
    /// normal: the talk's piecewise-constant map). 𝓑(k) = the bin of sub-texel k's normal; 𝓑⁻¹ by counting sort
    /// (sub-texels in row-major order within a bin before the trees reorder them); one kd-tree per
    /// list longer than `leaf_size`. Cost O(s² · texels · log), the normals in parallel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `bins_per_axis` (even, 0 or > 4096), `leaf_size` (0),
    /// `subdivisions` (0 or > [`MAX_SUBDIVISIONS`]) or `sigma_min` (non-finite or ≤ 0);
    /// [`Error::InvalidSize`] for maps of 2³² sub-texels or more (indices are `u32`).
    pub fn build(map: &NormalMap, params: BinMapParams) -> Result<BinMap> {
        let bins = check_params(&params)?;
        let (width, height) = (map.width(), map.height());
        let s = params.subdivisions;
        let (grid_w, grid_h) = (width * s, height * s);
        let texels = grid_w
            .checked_mul(grid_h)
            .filter(|&t| t < u32::MAX as usize)
            .ok_or(Error::InvalidSize {
                width,
                height,
                reason: "the bin map needs fewer than 2^32 sub-texels (width · height · s²)",
            })?;
        let nb = bins.len();
        // 𝓑: every interpolated normal is finite with z > 0, so `bin_of` succeeds; the pole bin
        // guards it.
        let pole = bins.bin_of(glam::Vec3::Z).unwrap_or(0);
        let mut bin_map = BinIndex::new(nb, texels);
        bin_map.fill(grid_w, |i, j| {
            let p = subtexel_point(i, j, s);
            let n = if s == 1 {
                // Exactly the stored texel normal (no interpolation round-off).
                slope_to_normal(map.slopes()[j * width + i])
            } else {
                map.normal_at_texel(p)
            };
            bins.bin_of(n).unwrap_or(pole)
        });
        // 𝓑⁻¹ by counting sort.
        let mut offsets = vec![0u32; nb + 1];
        for k in 0..texels {
            offsets[bin_map.get(k).unwrap_or(pole) + 1] += 1;
        }
        for b in 0..nb {
            offsets[b + 1] += offsets[b];
        }
        let mut cursor: Vec<u32> = offsets[..nb].to_vec();
        let mut inverse = vec![0u32; texels];
        for k in 0..texels {
            let b = bin_map.get(k).unwrap_or(pole);
            inverse[cursor[b] as usize] = k as u32;
            cursor[b] += 1;
        }
        // The forest.
        let mut nodes = Vec::new();
        let mut roots = vec![NO_TREE; nb];
        for b in 0..nb {
            let (s, e) = (offsets[b] as usize, offsets[b + 1] as usize);
            if e - s > params.leaf_size {
                roots[b] = forest::build_tree(
                    &mut inverse[s..e],
                    s,
                    grid_w,
                    grid_h,
                    params.leaf_size,
                    &mut nodes,
                );
            }
        }
        let BinTables {
            facets,
            center_slope,
            corners,
        } = bin_tables(&bins, &offsets);
        let table = Table::new(params.lookup, offsets, roots);
        // The masking lobe's moments: the bins' own, only the levels it reads (from
        // MASKING_FIRST_LEVEL).
        let moments =
            footprint_moments::chain(&bins, &|k| bin_map.get(k).unwrap_or(pole), width, height, s);
        Ok(BinMap {
            width,
            height,
            bins,
            params,
            grid_w,
            grid_h,
            bin_map,
            inverse,
            nodes,
            table,
            center_slope,
            facets,
            corners,
            moments,
            moment_masking_error: Vec::new(),
        }
        .measured())
    }

    /// Map width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Map height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The map size (width, height) in texels.
    pub fn map_size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The direction bins.
    pub fn bins(&self) -> &HemisphereBins {
        &self.bins
    }

    /// The build parameters.
    pub fn params(&self) -> &BinMapParams {
        &self.params
    }

    /// The sub-texel resolution s ([`BinMapParams::subdivisions`]).
    pub fn subdivisions(&self) -> usize {
        self.params.subdivisions
    }

    /// The sub-texel grid (s·width, s·height): the elements that 𝓑, 𝓑⁻¹ and the forest index.
    pub fn grid_size(&self) -> (usize, usize) {
        (self.grid_w, self.grid_h)
    }

    /// 𝓑(k): the bin of sub-texel k = J · (s·width) + I (row major on the sub-texel grid; the texel
    /// index when s = 1); `None` out of range.
    pub fn bin_of_texel(&self, k: usize) -> Option<usize> {
        self.bin_map.get(k)
    }

    /// 𝓑⁻¹(j): the sub-texel indices of bin j, in the forest's order (empty for an empty or
    /// out-of-range bin).
    pub fn texels_of_bin(&self, bin: usize) -> &[u32] {
        self.table
            .get(bin)
            .map_or(&[], |e| &self.inverse[e.start as usize..e.end as usize])
    }

    /// The whole inverse bin map: the texel lists of bins 0, 1, … concatenated.
    pub fn inverse_bin_map(&self) -> &[u32] {
        &self.inverse
    }

    /// The range [start, end) of bin j's list in [`BinMap::inverse_bin_map`] and its tree root in
    /// [`BinMap::forest`] (`None` for lists of at most L texels); `None` for an empty bin.
    pub fn bin_range(&self, bin: usize) -> Option<(usize, usize, Option<usize>)> {
        self.table.get(bin).map(|e| {
            (
                e.start as usize,
                e.end as usize,
                (e.root != NO_TREE).then_some(e.root as usize),
            )
        })
    }

    /// The packed forest topology (see the layout in docs/binmap.md): per internal node, in pre-order,
    /// the index in the inverse map where its right child's range starts and the array index of its
    /// right child; a left child that is internal follows its parent.
    pub fn forest(&self) -> &[u32] {
        &self.nodes
    }

    /// Mean cosine c̄_j = (1/|H|) ∫_{H_j} cos θ dω of bin j (f32; 0 out of range).
    pub fn mean_cos(&self, bin: usize) -> f32 {
        self.facets.get(bin).map_or(0.0, |f| f.mean.z)
    }

    /// Bytes held, per part.
    pub fn memory(&self) -> BinMapMemory {
        BinMapMemory {
            bin_map: self.bin_map.bytes(),
            inverse: 4 * self.inverse.len(),
            forest: 4 * self.nodes.len(),
            lookup: self.table.bytes(),
            bin_tables: 8 * self.center_slope.len()
                + std::mem::size_of::<BinFacet>() * self.facets.len()
                + std::mem::size_of::<Vec3>() * self.corners.len(),
            moments: self.moments.bytes(),
        }
    }

    fn tree_view(&self) -> TreeView<'_> {
        TreeView {
            inverse: &self.inverse,
            nodes: &self.nodes,
            width: self.grid_w as u32,
            height: self.grid_h as u32,
            leaf: self.params.leaf_size,
        }
    }
}

impl GlintNdf for BinMap {
    type Patch<'a> = BinMapPatch<'a>;
    type Options = PatchOptions;

    /// The patch of a footprint ([`BinMapPatch`]): the bin-resolution P-NDF, or with
    /// [`PatchOptions::smoothing_alpha`] > 0 every bin's mass spread by a Beckmann lobe; its
    /// masking from its own bins or the moment lobe as the options choose (masking_choice.rs).
    fn patch_with<'a>(
        &'a self,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> BinMapPatch<'a> {
        let alpha = options.smoothing_alpha;
        let alpha = (alpha.is_finite() && alpha > 0.0)
            .then(|| alpha.clamp(crate::ndf::MIN_ALPHA, crate::ndf::MAX_ALPHA));
        BinMapPatch::new(self, footprint, alpha, options, scratch)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sub-texel points: each inside its own sub-texel, and per texel s² distinct strata of width
    /// 1/s² on each axis (exact small rationals: compared after scaling by s² and flooring).
    #[test]
    fn subtexel_points_are_n_rooks_inside_their_subtexels() {
        for s in 1..=MAX_SUBDIVISIONS {
            for (ti, tj) in [(0usize, 0usize), (3, 5)] {
                let (mut xs, mut ys) = (vec![false; s * s], vec![false; s * s]);
                for b in 0..s {
                    for a in 0..s {
                        let (i, j) = (ti * s + a, tj * s + b);
                        let p = subtexel_point(i, j, s);
                        let (x, y) = (p.x as f64 * s as f64, p.y as f64 * s as f64);
                        assert!(x > i as f64 && x < (i + 1) as f64, "s={s} ({i},{j}) x {x}");
                        assert!(y > j as f64 && y < (j + 1) as f64, "s={s} ({i},{j}) y {y}");
                        let sx = ((p.x as f64 - ti as f64) * (s * s) as f64).floor() as usize;
                        let sy = ((p.y as f64 - tj as f64) * (s * s) as f64).floor() as usize;
                        assert!(!xs[sx] && !ys[sy], "s={s}: stratum repeated");
                        xs[sx] = true;
                        ys[sy] = true;
                    }
                }
            }
        }
        assert_eq!(subtexel_point(0, 0, 2), Vec2::new(0.375, 0.125));
        assert_eq!(subtexel_point(1, 1, 2), Vec2::new(0.625, 0.875));
        assert_eq!(subtexel_point(4, 2, 1), Vec2::new(4.5, 2.5));
    }
}
