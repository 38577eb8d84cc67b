//! The patch of a footprint, [`MixturePatch`]: D_P through the slope-box quadtree, the exact and
//! approximate masking terms and the two samplers (\[Chermain2019\] §4-5), on the nodes gathered
//! once per footprint (gather.rs) at one level of detail.
//!
//! The patch reads its storage through a level view ([`PatchLevel`]: full or compact, chosen once
//! when the patch is made); each query selects the storage and the instruction set once, above its
//! loop over blocks, and runs the block pass (passes.rs) compiled for that pair.

use super::blocks;
use super::choice::{SetKind, footprint_patch};
use super::compact::CompactView;
use super::full::FullLevel;
use super::gather::{FootprintLobes, Gathered, SlotBuffers};
use super::model::{BeckmannMixture, Storage};
use super::params::{MaskingMode, PatchOptions};
use super::passes::{SumP22, VisiblePick, VisibleSum};
use super::simd::{self, Simd};
use super::storage::LevelView;
use crate::frame::normal_to_slope;
use crate::glint::Footprint;
use crate::glint::GlintScratch;
use crate::glint::kernels::albedo::Lobe;
use crate::glint::kernels::cdf::{invert_cdf, pick_streaming};
use crate::glint::kernels::cut::CutStats;
use crate::glint::kernels::lobe_set::{Few, LobeSet};
use crate::glint::kernels::prepared_view::PreparedView;
use crate::math::{finite_f32, finite_or_zero};
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Vec2, Vec3};

mod densities;
mod form;

/// The level a patch reads, in the mixture's storage.
#[derive(Clone, Copy, Debug)]
enum PatchLevel<'a> {
    Full(FullLevel<'a>),
    Compact(CompactView<'a>),
}

/// Evaluates `$body` with `$lv` bound to the patch level `$level` ([`PatchLevel`]): one branch, and
/// `$body` compiled once per storage.
macro_rules! with_level {
    ($level:expr, |$lv:ident| $body:expr) => {
        match $level {
            PatchLevel::Full($lv) => $body,
            PatchLevel::Compact($lv) => $body,
        }
    };
}

impl PatchLevel<'_> {
    /// The level l.
    fn level(&self) -> usize {
        with_level!(self, |lv| lv.level())
    }

    /// Node k of the level as a [`SlopeGaussian`].
    fn lobe(&self, k: usize) -> SlopeGaussian {
        with_level!(self, |lv| lv.lobe(k))
    }

    /// The level's node grid.
    fn grid(&self) -> [usize; 2] {
        with_level!(self, |lv| lv.grid())
    }

    /// Node k's mean slope and covariance [Σxx, Σxy, Σyy], from its stored moments.
    fn mean_cov(&self, k: usize) -> ([f64; 2], [f64; 3]) {
        with_level!(self, |lv| lv.mean_cov(k))
    }
}

/// The P-NDF of one footprint of a [`BeckmannMixture`]: an [`Ndf`] with D_P(h) = Σ W_i D_i(h).
///
/// - `d`: \[Chermain2019\] eq. 9 through the slope-box quadtree down to the lobe blocks (4 × 4
///   lobes), then 16 lanes at a time; lobes whose slope box (1 − `slope_tail` of their mass) does
///   not contain h's slope contribute 0 (a masked lane).
/// - Masking, [`MaskingMode::Exact`]: V_P(w) = Σ W_i V_i(w) (V_i = ∫⟨w,m⟩⁺D_i, always ≥ 0), and the
///   **signed** patch projected area A_P(w) = Σ W_i (cos θ − w_xy·μ_i) = cos θ − w_xy·μ_P (μ_P the
///   patch mean slope), clamped at 0; Λ_P = V_P/A_P − 1, G1 = A_P/V_P (eq. 10-17, see
///   docs/mixture.md for why the per-lobe areas are not clamped as in eq. 17).
///   [`MaskingMode::Approximate`]: the same A_P and Scarf's upper bound of V_P from the patch's slope
///   mean and covariance (O(1) per direction; sound: never creates energy, see docs/mixture.md).
/// - Samplers: `sample_normal` draws a lobe ∝ W_i then its slope Gaussian within the lobe's slope
///   box (D_P cos θ); `sample_visible` draws a lobe ∝ W_i V_i(wo) then that lobe's visible normal
///   within its box, density ⟨wo,m⟩⁺ D_P / V_P(wo) = `pdf_visible` (exact V_P in both masking
///   modes), both up to each lobe's mass outside its box (≤ ~10⁻⁶ relative).
/// - Few-lobe forms (one slope Gaussian or a few, evaluated by brute force, O(1) per query):
///   below [`PatchOptions::sub_texel_area`] the sub-texel limit lobe
///   (src/glint/mixture/sub_texel.rs); from [`PatchOptions::filtered_area`] the filtered mixture
///   (src/glint/kernels/gmm.rs) where its measured TV to the full mixture
///   ([`BeckmannMixture::filtered_mixture_errors`]) is within
///   [`PatchOptions::filtered_tolerance`], and beyond the cost cap; compact storage serves the
///   single filtered lobe there. Their masking is exact (V = Σ w_i V_i, V(wo) prepared per view).
/// - Level of detail otherwise: the patch is made of the nodes of one level l of merged lobes
///   (src/glint/mixture/levels.rs; l = 0 is the lobes themselves): the coarsest level whose nodes
///   are no wider than half the footprint's smaller standard deviation and whose bound
///   Σ W_n e_r(n) on the TV to the full mixture at slope resolution r = `lod_resolution` (both
///   P-NDFs blurred by N(0, r² I)) is at most `lod_tolerance`, then moved coarser if the footprint
///   still covers more than `lod_lobes` nodes (the filtered lobe alone if no level is coarse
///   enough). D_P, both masking modes, both samplers and their pdfs all use that one level.
/// - Cost per shading point: a patch prepared for its view ([`MixturePatch::prepare_view`], which
///   `Material::bsdf` calls with the shading point's wo) holds the exact V_P(wo), computed once by
///   that explicit step (nothing is kept lazily: a patch that was not prepared computes V_P(wo) per
///   query), and takes the D_P(h) that `MicrofacetBrdf::eval_pdf` already evaluated
///   ([`Ndf::pdf_visible_given_d`]). A renderer's `eval_pdf` at k directions and one `sample` at the
///   prepared wo then cost k + 1 D_P walks, one V_P(wo) pass, the sampler's pick pass and, with
///   exact masking, k + 1 V_P(wi) passes (the pdfs read D_P from the walk: the samplers draw each
///   lobe within its slope box); every value is the one an
///   unprepared patch returns.
/// - What approximate masking cannot make O(1): the sampler. `sample_visible` picks a lobe
///   ∝ W_i V_i(wo), which needs the exact V_P(wo) (one pass per view, shared with the pdfs) and a
///   pick pass. Picking ∝ W_i instead (O(log lobes) by the
///   weights' CDF) would make the density Σ W_i ⟨wo,m⟩⁺ D_i / V_i(wo), whose pass costs a V_i per
///   lobe at every pdf, and bound the sample weight by F · max_i V_i(wo)/V_P(wo) instead of F
///   (src/bxdf/microfacet.rs, "Sample weights"); [`crate::bxdf::Sampling::Normals`] already is
///   the O(log lobes) sampler, with a weight not bounded by F. docs/mixture.md.
///
/// # Reference
/// \[Chermain2019\] eq. 7-17, §4.2.2, §5.
#[derive(Clone, Debug)]
pub struct MixturePatch<'a> {
    /// The level of detail the patch reads (its lobes, blocks, quadtree), in the mixture's storage.
    level: PatchLevel<'a>,
    /// The mixture's slope-box half-width k, in lobe standard deviations.
    box_k: f32,
    masking: MaskingMode,
    /// The Beckmann lobe of the filtered moments (§4.2.2).
    filtered: SlopeGaussian,
    /// `None` when the level of detail serves the filtered lobe alone.
    gathered: Option<Gathered<'a>>,
    /// What serves the patch when `gathered` is `None` (the filtered lobe, the sub-texel limit
    /// lobe or the filtered mixture) and which it is; empty and `None` otherwise.
    few: Few<'a>,
    few_kind: Option<SetKind>,
    few_error: f32,
    /// What the cut did, when a cut serves the patch.
    cut: Option<CutStats>,
    /// The compiled copy of the block loops the patch runs ([`Simd::detected`]).
    simd: Simd,
    /// The exact V_P at the view the patch was prepared for ([`MixturePatch::prepare_view`]; read by
    /// `pdf_visible`, `sample_visible` and `view_visible_area` at that wo).
    view: PreparedView,
}

impl<'a> MixturePatch<'a> {
    /// Gathers the footprint's lobes (gather.rs), with the per-slot buffers lent by `scratch` if
    /// any (given back when the patch drops: no heap allocation once the scratch has grown to the
    /// footprint's size). Total: any footprint works.
    pub(super) fn new(
        mixture: &'a BeckmannMixture,
        footprint: &Footprint,
        options: PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> MixturePatch<'a> {
        let slots = scratch.map(|s| s.home::<SlotBuffers>());
        let sets = scratch.map(|s| s.home::<LobeSet>());
        let (width, height) = mixture.map_size();
        let p = mixture.params();
        let fp = FootprintLobes::new(
            footprint,
            (width, height),
            mixture.spacing_f64(),
            p.seed,
            p.kernel_sigmas,
        );
        let params = [p.weight_sigmas, p.sigma_min];
        // The filtered mixture's measured errors, only where the options read them.
        let errors: &[f32] = if fp.area() >= options.filtered_area as f64
            && options.filtered_tolerance != f32::INFINITY
        {
            mixture.filtered_mixture_errors()
        } else {
            &[]
        };
        // The storage is chosen here, once per patch.
        let (level, filtered, gathered, set, cut) = match mixture.lobe_storage() {
            Storage::Full(s) => {
                let f = footprint_patch(s, &fp, &options, params, errors, slots, sets);
                (
                    PatchLevel::Full(f.level),
                    f.filtered,
                    f.gathered,
                    f.set,
                    f.cut,
                )
            }
            Storage::Compact(s) => {
                let f = footprint_patch(s, &fp, &options, params, errors, slots, sets);
                (
                    PatchLevel::Compact(f.level),
                    f.filtered,
                    f.gathered,
                    f.set,
                    f.cut,
                )
            }
        };
        MixturePatch {
            level,
            box_k: mixture.box_sigmas(),
            masking: options.masking,
            filtered,
            gathered,
            few_kind: set.as_ref().map(|(_, k, _)| *k),
            few_error: set.as_ref().map_or(0.0, |(_, _, e)| *e),
            few: set.map_or(Few::None, |(s, _, _)| s),
            cut,
            simd: Simd::detected(),
            view: PreparedView::NONE,
        }
    }

    /// The masking mode.
    pub fn masking(&self) -> MaskingMode {
        self.masking
    }

    /// Prepares the patch for the view direction `wo` (shading frame): the exact V_P(wo) that the
    /// queries at that wo share (`view_visible_area`, `pdf_visible`, `sample_visible`, the
    /// densities `MicrofacetBrdf` forms), computed here once, an O(lobes) pass. Queries at `wo` (the
    /// same bits) then read it; queries at any other view compute their own. Every value is the
    /// one the unprepared patch returns, bit for bit. A second call replaces the first view.
    /// `Material::bsdf` prepares its glint patches for the shading point's wo.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view = PreparedView::NONE;
        // A few-lobe set keeps its own (its queries read it through `few_view_visible_area`).
        self.few.prepare_view(wo);
        if let (Some(g), MaskingMode::Exact) = (&self.gathered, self.masking)
            && wo.z > 0.0
            && wo.is_finite()
        {
            self.view = PreparedView::new(wo, self.exact_visible_area(g, wo));
        }
    }

    /// Whether the level of detail replaced the mixture by the single filtered lobe (the
    /// footprint's moment-matched lobe: compact storage above the cost cap or
    /// [`PatchOptions::filtered_area`], or an empty filtered mixture).
    pub fn is_filtered_lobe(&self) -> bool {
        self.few_kind == Some(SetKind::FilteredLobe)
    }

    /// Whether the patch is the filtered mixture: [`super::GMM_LOBES`] lobes per node of a mip
    /// chain read trilinearly (src/glint/kernels/gmm.rs), for footprints of at least
    /// [`PatchOptions::filtered_area`] (or beyond the cost cap), full storage.
    pub fn is_filtered_mixture(&self) -> bool {
        self.few_kind == Some(SetKind::FilteredMixture)
    }

    /// What the cut of the filtered-mixture hierarchy did when one serves the patch
    /// ([`PatchOptions::cut_nodes`]; src/glint/kernels/cut.rs): its nodes, lobes, largest and
    /// summed node error, start level and splits. `None` for the other forms.
    pub fn cut(&self) -> Option<CutStats> {
        self.cut
    }

    /// Whether the patch is the sub-texel limit lobe: one slope Gaussian at the interpolated slope
    /// of the footprint's centre, for footprints below [`PatchOptions::sub_texel_area`]
    /// (src/glint/mixture/sub_texel.rs).
    pub fn is_sub_texel(&self) -> bool {
        self.few_kind == Some(SetKind::SubTexel)
    }

    /// The lobes of the patch when it is one of the few-lobe forms (filtered lobe, sub-texel lobe,
    /// filtered mixture, cut): (weight, lobe) pairs, weights summing to 1; empty otherwise.
    pub fn few_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        self.few.iter_lobes()
    }

    /// The level of detail l the patch reads: its lobes are the merged lobes of 2^l × 2^l blocks of
    /// the mixture's lobes (0: the lobes themselves; also 0 under the filtered lobe).
    pub fn level(&self) -> usize {
        self.level.level()
    }

    /// The level of detail's error bound Σ W_n e_r(n): an upper bound of the TV between this
    /// patch's slope density and that of the level-0 lobes its nodes replace, each node's weight
    /// W_n spread evenly over its lobes, both blurred by an isotropic Gaussian of std r in slope
    /// space, r the largest of [`super::LOD_RESOLUTIONS`] not above `PatchOptions::lod_resolution`
    /// (0 at level 0; under the filtered mixture its measured TV to the full mixture instead,
    /// [`BeckmannMixture::filtered_mixture_errors`]; under a cut its largest node error e_n,
    /// [`MixturePatch::cut`]; 1 under the filtered lobe and the sub-texel lobe, which have none). The difference between that
    /// even spread and the full mixture's own weights is not bounded (measured 0.0005-0.013 in TV,
    /// docs/mixture.md). See src/glint/mixture/levels.rs.
    pub fn lod_error(&self) -> f32 {
        self.gathered
            .as_ref()
            .map_or(self.few_error, |g| g.lod_error as f32)
    }

    /// The Beckmann lobe of the footprint's filtered moments (\[Chermain2019\] §4.2.2): their
    /// trilinear lookup at level log₂(√(footprint area in lobes)), in the moment mip chain (full
    /// storage) or in the levels of detail (compact storage).
    pub fn filtered_lobe(&self) -> &SlopeGaussian {
        &self.filtered
    }

    /// Number of lobe slots (weights) the patch holds (0 for the filtered lobe).
    pub fn lobe_count(&self) -> usize {
        self.gathered.as_ref().map_or(0, Gathered::slot_count)
    }

    /// The patch mean slope μ_P = Σ W_i μ_i (the filtered lobe's mean under the level of detail).
    pub fn mean_slope(&self) -> Vec2 {
        self.gathered
            .as_ref()
            .map_or_else(|| self.few.mean_slope(), |g| g.mean_slope)
    }

    /// The normalised weights W_i and their lobes, for tests and tools: (W, lobe) per slot.
    pub fn weighted_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        let g = self.gathered.as_ref();
        let nx = self.level.grid()[0];
        let n = g.map_or(0, Gathered::slot_count);
        (0..n).filter_map(move |s| {
            g.map(|g| {
                let (w, k) = g.slot(s, nx);
                (w, self.level.lobe(k))
            })
        })
    }

    /// The patch's lobes (few-lobe form or gathered slots) as the albedo estimate reads them
    /// (src/glint/kernels/albedo.rs): the gathered slots from their stored moments, without
    /// forming their slope Gaussians.
    pub(crate) fn albedo_lobes(&self) -> impl Iterator<Item = Lobe> + Clone + '_ {
        let nx = self.level.grid()[0];
        let slots = self.gathered.as_ref().into_iter().flat_map(move |g| {
            (0..g.slot_count()).map(move |s| {
                let (w, k) = g.slot(s, nx);
                let (mu, c) = self.level.mean_cov(k);
                Lobe::from_mean_cov(w, mu, c)
            })
        });
        self.few
            .iter_lobes()
            .map(|(w, l)| Lobe::of(w, &l))
            .chain(slots)
    }

    /// D_P(m) and the number of lobes whose D_i was evaluated: 16 per lobe block whose box (and
    /// whose ancestors' boxes) contain m's slope.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 9, §5.
    pub fn d_with_stats(&self, m: Vec3) -> (f32, usize) {
        let Some(g) = &self.gathered else {
            return (self.few.d(m), 0);
        };
        let Some(s) = normal_to_slope(m) else {
            return (0.0, 0);
        };
        if !s.is_finite() {
            return (0.0, 0);
        }
        let (p22, touched) = self.sum_p22(g, s);
        let c = 1.0 + s.length_squared() as f64;
        let d = (p22 * c * c) as f32;
        (if d.is_finite() { d } else { f32::MAX }, touched)
    }

    /// Σ W_i P22_i(s) over the lobes whose slope box contains s: a depth-first walk of the quadtree
    /// down to the lobe blocks (level 2) restricted to each lobe rectangle of the footprint, then
    /// the 16 lanes of each block reached at once ([`blocks::p22_lanes`]); and the lanes evaluated.
    fn sum_p22(&self, g: &Gathered, s: Vec2) -> (f64, usize) {
        let k2 = self.box_k * self.box_k;
        let (sum, blocks_seen) = with_level!(self.level, |lv| simd::dispatch(
            self.simd,
            SumP22 { lv, g, s, k2 }
        ));
        (sum * blocks::p22_scale(), blocks_seen * blocks::LANES)
    }

    /// Exact V_P(w) = Σ W_i V_i(w) (0 for invalid w) by the lobe blocks ([`blocks::visible_lanes`]:
    /// the ramp term G(−t) in lanes only in blocks that hold a lobe seen at z = A_s/s_w < 5, the sum
    /// in `f64`; relative error ≤ 1e-6, docs/mixture.md "Lobe blocks").
    fn exact_visible_area(&self, g: &Gathered, w: Vec3) -> f64 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        with_level!(self.level, |lv| simd::dispatch(
            self.simd,
            VisibleSum { lv, g, w }
        ))
    }

    /// [`MixturePatch::exact_visible_area`] at a view direction: the prepared value if `wo` is the
    /// view the patch was prepared for ([`MixturePatch::prepare_view`]), else one pass.
    fn view_exact_visible_area(&self, g: &Gathered, wo: Vec3) -> f64 {
        if !(wo.z > 0.0 && wo.is_finite()) {
            return 0.0;
        }
        self.view.get_or(wo, || self.exact_visible_area(g, wo))
    }

    /// The exact visible area V_P(w) = Σ W_i V_i(w) = ∫ ⟨w, m⟩⁺ D_P(m) dm, whatever the masking mode
    /// (the filtered lobe's under the level of detail).
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 12-13 (with V_i in place of the clamped ⟨ω_n̄i, w⟩/(ω_n̄i·ω_g)(1 + Λ_i)).
    pub fn visible_area_exact(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => finite_or_zero(self.exact_visible_area(g, w)),
            None => self.few.visible_area(w),
        }
    }

    /// Scarf's bound V⁺(w) = ½ (ā + √(ā² + w_xyᵀ Σ_P w_xy)) ≥ ∫⟨w,m⟩⁺ D_P dm, with ā the signed
    /// projected area and Σ_P the patch's slope covariance: the largest E[(w_z − w_xy·ñ)⁺] over
    /// every slope distribution of that mean and covariance, so masking built on it can only
    /// over-shadow (never create energy). 0 for invalid w. O(1).
    ///
    /// # Reference
    /// \[Scarf1958\]; the per-lobe form is [`SlopeGaussian::visible_area_bound`].
    fn visible_area_bound(&self, g: &Gathered, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let a = self.signed_projected_area(w) as f64;
        let [sxx, sxy, syy] = g.slope_cov;
        let (x, y) = (w.x as f64, w.y as f64);
        let s2 = (sxx * x * x + 2.0 * sxy * x * y + syy * y * y).max(0.0);
        finite_or_zero(0.5 * (a + (a * a + s2).sqrt()))
    }

    /// The signed patch projected area A_s(w) = cos θ − w_xy·μ_P = Σ W_i ∫ (w·m) D_i dm (may be
    /// negative; 0 for invalid w).
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 without the per-lobe clamp.
    pub fn signed_projected_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let mu = self.mean_slope();
        finite_f32(w.z as f64 - (mu.x as f64 * w.x as f64 + mu.y as f64 * w.y as f64))
    }

    /// The paper's patch projected area with clamped per-lobe areas, Σ W_i max(cos θ − w_xy·μ_i, 0)
    /// (\[Chermain2019\] eq. 17 as printed). Not used by the patch (see docs/mixture.md); exposed for
    /// comparison. The filtered lobe's A under the level of detail.
    pub fn paper_projected_area(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(g) => {
                let nx = self.level.grid()[0];
                (0..g.slot_count())
                    .map(|s| {
                        let (wi, k) = g.slot(s, nx);
                        wi as f64 * self.level.lobe(k).projected_area(w) as f64
                    })
                    .sum::<f64>() as f32
            }
            None => self.few.projected_area(w),
        }
    }

    /// m ~ Σ W_i ⟨wo,m⟩⁺ D_i(m) / V_P(wo) on the gathered lobes: lobe ∝ W_i V_i(wo) with u.x
    /// (rescaled), then that lobe's visible normal. Two passes over the lobe blocks (the total
    /// [`VisibleSum`], then the pick [`VisiblePick`]: block by block, then lane by lane in the block
    /// that holds the target), no allocation. Invalid wo or V_P: [`Ndf::sample_normal`]. Its density
    /// is `pdf_visible` (which divides by the same block V_P) up to the lanes' 1e-6 relative error on
    /// each V_i.
    fn sample_visible_gathered(&self, g: &Gathered, wo: Vec3, u: Vec2) -> Vec3 {
        let total = self.view_exact_visible_area(g, wo);
        if !(total > 0.0 && total.is_finite()) {
            return self.sample_normal(u);
        }
        let ux = if u.x.is_nan() {
            0.5
        } else {
            u.x.clamp(0.0, 1.0)
        } as f64;
        let target = ux * total;
        let (k, r) = with_level!(self.level, |lv| simd::dispatch(
            self.simd,
            VisiblePick { lv, g, wo, target }
        ));
        if k == usize::MAX {
            return self.sample_normal(u);
        }
        let r = r.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        self.sample_lobe_in_box(k, Some(wo), Vec2::new(r, u.y))
    }

    /// This patch running its block loops in the baseline copy (`baseline`) or in the copy the CPU
    /// supports (AVX2 where detected): results are bit-identical either way (dispatch_tests.rs).
    #[cfg(test)]
    pub(super) fn with_simd(mut self, baseline: bool) -> Self {
        self.simd = if baseline {
            Simd::BASELINE
        } else {
            Simd::detected()
        };
        self
    }

    /// The copy of the block loops the patch runs: `"avx2"` or `"baseline"`.
    #[cfg(test)]
    pub(super) fn simd_name(&self) -> &'static str {
        self.simd.name()
    }
}

impl Ndf for MixturePatch<'_> {
    /// D_P(m) = Σ W_i D_i(m) (\[Chermain2019\] eq. 9); see [`MixturePatch::d_with_stats`].
    fn d(&self, m: Vec3) -> f32 {
        self.d_with_stats(m).0
    }

    /// Λ_P(w) = V_P(w)/A_P(w) − 1 (≥ 0); `f32::MAX` when A_P ≤ 0 < w_z (the patch's mean plane faces
    /// away from w), 0 for invalid w.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 15 (exact), §4.2.2 (approximate).
    fn lambda(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_from_areas(self, w)
    }

    /// A_P(w) = max(signed A_P, 0) from the patch mean slope, in both masking modes (exact and
    /// O(1)); the filtered lobe's A under the level of detail.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 (without the per-lobe clamp, docs/mixture.md).
    fn projected_area(&self, w: Vec3) -> f32 {
        match &self.gathered {
            Some(_) => self.signed_projected_area(w).max(0.0),
            None => self.few.projected_area(w),
        }
    }

    /// V_P(w) = A_P (1 + Λ_P): exact Σ W_i V_i(w) ([`MaskingMode::Exact`], by the lobe blocks),
    /// Scarf's upper bound from the patch's slope mean and covariance
    /// ([`MaskingMode::Approximate`]), or the filtered lobe's V under the level of detail.
    fn visible_area(&self, w: Vec3) -> f32 {
        match (&self.gathered, self.masking) {
            (Some(g), MaskingMode::Exact) => finite_or_zero(self.exact_visible_area(g, w)),
            (Some(g), MaskingMode::Approximate) => self.visible_area_bound(g, w),
            (None, _) => self.few.visible_area(w),
        }
    }

    /// m ~ D_P(m) cos θ_m: lobe ∝ W_i with u.x (rescaled), then the lobe's slope Gaussian.
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let Some(g) = &self.gathered else {
            return self.few.sample_normal(u);
        };
        // The block by its cdf, then the lane in it by the rescaled u.x.
        let (b, ub) = invert_cdf(&g.bufs.block_cdf, u.x);
        let lanes = &g.bufs.block_weights[b * blocks::LANES..(b + 1) * blocks::LANES];
        let total: f64 = lanes.iter().map(|&w| w as f64).sum();
        let (lane, ux) = pick_streaming(ub, total, lanes.iter().map(|&w| w as f64));
        let k = g.node_of_lane(b * blocks::LANES + lane, self.level.grid()[0]);
        self.sample_lobe_in_box(k, None, Vec2::new(ux, u.y))
    }

    /// m ~ Σ W_i ⟨wo,m⟩⁺ D_i(m) / V_P(wo): lobe ∝ W_i V_i(wo) with u.x (rescaled), then that lobe's
    /// visible normal (V_i by the lobe blocks, as [`Ndf::pdf_visible`]'s V_P; the filtered lobe's
    /// sampler under the level of detail). Invalid wo: [`Ndf::sample_normal`].
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        match &self.gathered {
            Some(g) => self.sample_visible_gathered(g, wo, u),
            None => self.few.sample_visible(wo, u),
        }
    }

    /// D_P(m) cos θ_m: the density of [`Ndf::sample_normal`], whose lobes are drawn within the slope
    /// boxes D_P counts them in (up to each lobe's mass outside its box, ≤ ~10⁻⁶ relative); 0 where
    /// D_P is. One D_P walk (none when D_P is given).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        self.pdf_normal_with(m, || self.d(m))
    }

    /// [`Ndf::pdf_normal`] with D_P(m) = `d_m` given (the contract's check uses it).
    fn pdf_normal_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        self.pdf_normal_with(m, || d_m)
    }

    /// ⟨wo, m⟩⁺ D_P(m) / V_P(wo), with the exact V_P in every masking mode: the density of
    /// [`Ndf::sample_visible`] (its lobes drawn within their slope boxes, up to each lobe's mass
    /// outside its box, ≤ ~10⁻⁶ relative); 0 where D_P is. One D_P walk (none when D_P is given)
    /// and V_P(wo) (the prepared view's, else one pass).
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        self.pdf_visible_with(wo, m, || self.d(m))
    }

    /// [`Ndf::pdf_visible`] with D_P(m) = `d_m` given (the contract's check uses it).
    fn pdf_visible_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        self.pdf_visible_with(wo, m, || d_m)
    }

    /// [`Ndf::pdf_visible_given_d`] without its factor ⟨wo, m⟩ (no underflow at grazing views).
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        self.pdf_visible_over_cos_with(wo, m, || d_m)
    }

    /// [`Ndf::visible_area`] at the view: the exact V_P prepared for `wo` if the patch was
    /// prepared for it ([`MaskingMode::Exact`]; [`MixturePatch::prepare_view`]); Scarf's bound, O(1),
    /// is never prepared ([`MaskingMode::Approximate`]).
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        match (&self.gathered, self.masking) {
            (Some(g), MaskingMode::Exact) => finite_or_zero(self.view_exact_visible_area(g, wo)),
            (Some(_), MaskingMode::Approximate) => self.visible_area(wo),
            (None, _) => self.few_view_visible_area(wo),
        }
    }
}
