//! The interface of the two forms in which a mixture holds its lobes ([`super::LobeStorage`]):
//! [`LobeStore`], a whole storage (its levels of detail, the filtered moments, its memory), and
//! [`LevelView`], one level of detail as a patch reads it (blocks, lobes, means and covariances,
//! merge errors). Full storage (full.rs) and compact storage (compact.rs) implement both.
//!
//! The mixture holds one of the two (model.rs, `Storage`) and a patch picks it once, when it is made
//! (patch.rs): the patch's per-query loops over blocks (passes.rs) are generic over [`LevelView`],
//! so each is compiled once per storage, with no branch on the storage inside the loops.
//!
//! Both traits are crate-private and implemented only by the two storages (sealed).

use super::blocks::LobeBlock;
use super::params::MixtureMemory;
use crate::glint::kernels::gmm::GmmPyramid;
use crate::glint::kernels::lobe_set::LobeSet;
use crate::glint::kernels::slope_tree::SlopeTree;
use crate::ndf::SlopeGaussian;

/// One level of detail of a storage as a patch reads it: references into the storage, cheap to copy.
/// Node k is row major over [`LevelView::grid`]; at level 0 the nodes are the lobes.
///
/// [`LevelView::block`], [`LevelView::tree`] and [`LevelView::grid`] run inside the block loops,
/// whose AVX2 copy inlines only what is forced (simd.rs): implementations mark them
/// `#[inline(always)]`.
pub(super) trait LevelView: Copy + std::fmt::Debug {
    /// Memory a block is decoded into by [`LevelView::block`]: `()` where the blocks are stored in
    /// the kernels' form.
    type Scratch;

    /// Fresh scratch memory (once per query, outside the loop over blocks).
    fn scratch() -> Self::Scratch;

    /// The level l: a node covers 2^l × 2^l lobes.
    fn level(&self) -> usize;

    /// Nodes along x and y.
    fn grid(&self) -> [usize; 2];

    /// The slope-box quadtree over the level's nodes, held at least from level 2 (the blocks) up.
    fn tree(&self) -> &SlopeTree;

    /// Block (bx, by) in the form the lane kernels read (blocks.rs): the stored block, or the block
    /// decoded into `scratch`.
    fn block<'s>(&'s self, bx: usize, by: usize, scratch: &'s mut Self::Scratch) -> &'s LobeBlock;

    /// Node k as a [`SlopeGaussian`]: exactly the lobe its block lane holds.
    fn lobe(&self, k: usize) -> SlopeGaussian;

    /// Node k's mean slope and covariance [xx, xy, yy] in `f64`, as D evaluates the lobe (floored,
    /// correlation clamped).
    fn mean_cov(&self, k: usize) -> ([f64; 2], [f64; 3]);

    /// Node k's mean slope in `f64`: [`LevelView::mean_cov`]'s mean, bit for bit.
    #[inline]
    fn mean(&self, k: usize) -> [f64; 2] {
        self.mean_cov(k).0
    }

    /// Block (bx, by) where the blocks are stored in the kernels' form (`None` where a block must
    /// be decoded): the gather reads the lobes' means from its lanes (the means D and the exact
    /// masking evaluate, in `f32`), the memory the passes read next.
    #[inline(always)]
    fn stored_block(&self, bx: usize, by: usize) -> Option<&LobeBlock> {
        let _ = (bx, by);
        None
    }

    /// Asks the CPU to load block (bx, by) where the blocks are stored (a hint, no effect on
    /// any value; nothing otherwise).
    #[inline(always)]
    fn prefetch_block(&self, bx: usize, by: usize) {
        let _ = (bx, by);
    }

    /// The merge-error bound of node k valid at the resolution of index `res` in
    /// [`super::LOD_RESOLUTIONS`] (0 at level 0, which is exact).
    fn error(&self, k: usize, res: usize) -> f32;
}

/// A storage of the mixture's lobes: its levels of detail (level 0 = the lobes, levels l ≥ 1 the
/// merged lobes of levels.rs) and what a patch reads besides them.
pub(super) trait LobeStore {
    /// A level as the patch reads it.
    type Level<'a>: LevelView
    where
        Self: 'a;

    /// Number of levels of detail, level 0 included.
    fn level_count(&self) -> usize;

    /// Level l, clamped to the coarsest.
    fn level(&self, l: usize) -> Self::Level<'_>;

    /// The raw filtered moments `[E x̃, E ỹ, E x̃², E ỹ², E x̃ỹ]` of a footprint centred at `p`
    /// (level-0 lobe units) at level of detail `lod` (\[Chermain2019\] §4.2.2): a trilinear lookup,
    /// a convex combination of stored moments.
    fn filtered_moments(&self, p: [f64; 2], lod: f64) -> [f32; 5];

    /// The raw moments of level-0 lobe (i, j), indices wrapped onto the lobe grid (as stored: the
    /// moments themselves, or their compact encoding decoded).
    fn lobe_moments(&self, i: i64, j: i64) -> [f32; 5];

    /// The filtered mixture of a footprint centred at `p` at level of detail `lod` (gmm.rs) into
    /// `set`, or `false` (set untouched) when the storage holds no filtered-mixture chain (then
    /// the filtered lobe serves).
    fn filtered_mixture(&self, p: [f64; 2], lod: f64, set: &mut LobeSet) -> bool;

    /// The filtered-mixture hierarchy a cut descends (gmm.rs, cut.rs), or `None` when the storage
    /// holds none.
    fn hierarchy(&self) -> Option<&GmmPyramid>;

    /// Bytes held.
    fn memory(&self) -> MixtureMemory;
}
