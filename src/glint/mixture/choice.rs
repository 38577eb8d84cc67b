//! Which form serves a footprint of a mixture (\[Chermain2019\] §4.2.2 and the crate's levels of
//! detail, docs/mixture.md "Level of detail"): the sub-texel limit lobe, the filtered mixture where
//! its measured error allows, a cut of the filtered-mixture hierarchy (kernels/cut.rs), the
//! filtered lobe, or the lobes gathered at one level of merged lobes (gather.rs). Chosen once per
//! patch, generic over the storage ([`LobeStore`]).

use super::gather::{
    Effective, FootprintLobes, Gathered, SlotBuffers, gather, level_range, lod_error_of,
};
use super::levels::resolution_index;
use super::params::{MaskingMode, PatchOptions};
use super::storage::{LevelView, LobeStore};
use super::sub_texel;
use crate::glint::kernels::cut::{self, CutKernel, CutStats};
use crate::glint::kernels::filtered_error;
use crate::glint::kernels::lobe_set::{Few, LobeSet};
use crate::glint::scratch::{Home, Lent};
use crate::ndf::SlopeGaussian;

/// What a patch holds of its footprint: the level it reads, the filtered lobe of the footprint
/// (\[Chermain2019\] §4.2.2) and the gathered nodes (`None` when the level of detail serves the
/// filtered lobe alone).
pub(super) struct Footprinted<'a, L> {
    pub level: L,
    pub filtered: SlopeGaussian,
    pub gathered: Option<Gathered<'a>>,
    /// What serves the patch when `gathered` is `None`: the filtered lobe, the sub-texel limit
    /// lobe (sub_texel.rs) or the filtered mixture (gmm.rs), with its error (the filtered
    /// mixture's measured TV to the full mixture, kernels/filtered_error.rs; 1 for the single lobes, which have
    /// none).
    pub set: Option<(Few<'a>, SetKind, f32)>,
    /// What the cut did, when a cut of the hierarchy serves the patch.
    pub cut: Option<CutStats>,
}

impl<'a, L> Footprinted<'a, L> {
    /// A footprint served by a few-lobe set (no gather), read at `level`, with what a cut did.
    fn few(
        level: L,
        filtered: SlopeGaussian,
        set: (Few<'a>, SetKind, f32),
        cut: Option<CutStats>,
    ) -> Self {
        Footprinted {
            level,
            filtered,
            gathered: None,
            set: Some(set),
            cut,
        }
    }
}

/// Which few-lobe patch a [`LobeSet`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SetKind {
    /// The footprint's moment-matched lobe (\[Chermain2019\] §4.2.2).
    FilteredLobe,
    /// The sub-texel limit lobe (sub_texel.rs).
    SubTexel,
    /// The filtered mixture (gmm.rs).
    FilteredMixture,
    /// A cut of the filtered-mixture hierarchy (cut.rs).
    Cut,
}

/// The per-footprint work of a patch of `store` (module docs): below `options.sub_texel_area` the
/// sub-texel limit lobe; from `options.filtered_area`, where the filtered mixture's measured error
/// meets `options.filtered_tolerance`, the filtered mixture (its lobes lent by `sets`); otherwise
/// from `options.cut_area` (when `options.cut_nodes` > 0 and the storage holds the hierarchy) a cut
/// of the filtered-mixture hierarchy (kernels/cut.rs, its lobes lent by `sets`); otherwise the
/// filtered lobe, the level of detail (the coarsest whose weighted merge-error bound meets
/// `options.lod_tolerance`, moved coarser by the cost cap, see [`level_range`]; past the cap the
/// filtered mixture, or the filtered lobe without one) and the gather there, its buffers lent by
/// `slots`.
/// `weight_sigmas` and `sigma_min` are the mixture's parameters,
/// `filtered_error` the filtered mixture's measured error per level (kernels/filtered_error.rs).
pub(super) fn footprint_patch<'a, S: LobeStore>(
    store: &'a S,
    fp: &FootprintLobes,
    options: &PatchOptions,
    [weight_sigmas, sigma_min]: [f32; 2],
    filtered_error: &[f32],
    slots: Option<Home<'a, SlotBuffers>>,
    sets: Option<Home<'a, LobeSet>>,
) -> Footprinted<'a, S::Level<'a>> {
    let area = fp.area();
    if area < options.sub_texel_area as f64 {
        let lobe = sub_texel::limit_lobe(store, fp.c, fp.cov, fp.seed(), sigma_min);
        return Footprinted::few(
            store.level(0),
            lobe,
            (Few::One(lobe), SetKind::SubTexel, 1.0),
            None,
        );
    }
    let lod = 0.5 * area.max(1e-300).log2();
    let filtered = SlopeGaussian::from_moments(store.filtered_moments(fp.c, lod), sigma_min);
    // The filtered mixture where the storage has one (with its measured error at this level),
    // else the filtered lobe.
    let error = filtered_error::error_at(filtered_error, lod);
    let few = |sets: Option<Home<'a, LobeSet>>| {
        let mut set = Lent::new(sets);
        if store.filtered_mixture(fp.c, lod, &mut set) && set.len() > 0 {
            (Few::Set(set), SetKind::FilteredMixture, error)
        } else {
            (Few::One(filtered), SetKind::FilteredLobe, 1.0)
        }
    };
    let tolerance = options.filtered_tolerance;
    if area >= options.filtered_area as f64 && (error <= tolerance || tolerance == f32::INFINITY) {
        return Footprinted::few(store.level(0), filtered, few(sets), None);
    }
    // A cut of the hierarchy where the filtered mixture does not serve and the gather would cost
    // more than the cut (full storage).
    if options.cut_nodes > 0
        && area >= options.cut_area as f64
        && let Some(hierarchy) = store.hierarchy()
    {
        let k2 = fp.seed().0.weight_variance();
        let kernel = CutKernel {
            c: fp.c,
            s: [fp.cov[0] + k2, fp.cov[1], fp.cov[2] + k2],
            weight_sigmas: weight_sigmas as f64,
        };
        let mut set = Lent::new(sets);
        let level0 = store.level(0);
        let stats = cut::cut(
            hierarchy,
            |k| level0.lobe(k),
            kernel,
            options.cut_tolerance,
            options.cut_nodes as usize,
            &mut set,
        );
        let set = (Few::Set(set), SetKind::Cut, stats.max_error);
        return Footprinted::few(store.level(0), filtered, set, Some(stats));
    }
    let res = resolution_index(options.lod_resolution);
    let Some((finest, coarsest)) = level_range(store, fp, area, options) else {
        return Footprinted::few(store.level(0), filtered, few(sets), None);
    };
    let mut bufs = Lent::new(slots);
    // From the finest allowed level up while the next level's Σ W_n e(n) meets the tolerance (an
    // error-only pass: weights, no moments, no block layout), then one gather at the level chosen.
    // The bound grows with the level (a node's e(n) includes the mean of its children's; up to the
    // per-level weight approximation), so this stops where a coarse-to-fine search would; a
    // footprint that merges nothing pays one error pass at level finest + 1 (a quarter of the
    // nodes) instead of a gather per level.
    let mut l = finest;
    while l < coarsest {
        let eff = Effective::at_level(fp, l + 1);
        let e = lod_error_of(weight_sigmas, store.level(l + 1), &eff, res, &mut bufs);
        if e > options.lod_tolerance as f64 {
            break;
        }
        l += 1;
    }
    let level = store.level(l);
    let eff = Effective::at_level(fp, l);
    Footprinted {
        level,
        filtered,
        gathered: Some(gather(
            weight_sigmas,
            level,
            &eff,
            res,
            options.masking == MaskingMode::Approximate,
            bufs,
        )),
        set: None,
        cut: None,
    }
}
