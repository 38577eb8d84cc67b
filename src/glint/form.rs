//! Which form of a glint model serves a footprint ([`PatchForm`]): what each model's patch reports
//! with its `form()`, and what the report of form_report.rs collects across footprint sizes.
//!
//! Every glint model chooses per footprint between forms of different cost (docs/glint.md, "Level
//! of detail"): the mixture's sub-texel lobe, gathered lobes, filtered mixture, cut of its hierarchy
//! or filtered lobe; the bin map's exact masking over the footprint's bin list or its moment lobe;
//! position-normal's element sum, filtered mixture or cut; the procedural surface's facet lobes or
//! its limit NDF. Some choices read measured errors of the map (the filtered mixture's TV, the
//! moment lobe's G1 error), so the same options serve different forms on different maps:
//! [`GlintModel::forms`](super::GlintModel::forms) reports them for one model and one set of
//! options. This file imports nothing of the models, which all report through it.

use std::fmt;

/// The form of a glint patch: what its queries evaluate and how their work scales.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum PatchForm {
    /// The mixture's sub-texel limit lobe: one slope Gaussian at the footprint centre's interpolated
    /// slope (footprints below a few texels).
    SubTexel,
    /// One lobe of the footprint's filtered slope moments (\[Chermain2019\] §4.2.2).
    FilteredLobe,
    /// The filtered mixture: a few lobes read from a mip chain, with `error`, the TV to the full
    /// model measured at this footprint's level when the map was built.
    FilteredMixture {
        /// Lobes the patch holds.
        lobes: usize,
        /// The measured TV to the full model at this level.
        error: f32,
    },
    /// A cut of the filtered-mixture hierarchy: at most the options' node cap, whatever the
    /// footprint.
    Cut {
        /// Nodes in the cut.
        nodes: usize,
        /// Lobes the patch holds.
        lobes: usize,
        /// The largest error estimate of a node left in the cut.
        max_error: f32,
    },
    /// Every lobe of the footprint (mixture) or element (position-normal), gathered at one level of
    /// detail: the work of every query grows with the footprint.
    Gathered {
        /// The level of detail read (0: the model's own lobes or elements).
        level: usize,
        /// Lobes or elements the patch holds.
        lobes: usize,
    },
    /// The bin map with exact masking over the footprint's bin list: the list grows with the
    /// footprint.
    BinList {
        /// Bins (or smoothing lobes) listed.
        bins: usize,
    },
    /// The bin map with its moment lobe's masking: D from the forest, no bin list.
    MomentMasking,
    /// The procedural surface's facet lobes (a few tens at most, with the limit lobe when it is
    /// blended in).
    Facets {
        /// Lobes the patch holds.
        lobes: usize,
    },
    /// The procedural surface's limit NDF alone.
    Limit,
}

impl PatchForm {
    /// Whether the work of a query of this form grows with the footprint's area ([`Self::Gathered`]
    /// and [`Self::BinList`]); every other form is bounded whatever the footprint.
    pub fn grows_with_footprint(&self) -> bool {
        matches!(self, PatchForm::Gathered { .. } | PatchForm::BinList { .. })
    }

    /// A short name of the form, for logs and tables.
    pub fn name(&self) -> &'static str {
        match self {
            PatchForm::SubTexel => "sub-texel lobe",
            PatchForm::FilteredLobe => "filtered lobe",
            PatchForm::FilteredMixture { .. } => "filtered mixture",
            PatchForm::Cut { .. } => "cut",
            PatchForm::Gathered { .. } => "gathered",
            PatchForm::BinList { .. } => "bin list",
            PatchForm::MomentMasking => "moment masking",
            PatchForm::Facets { .. } => "facet lobes",
            PatchForm::Limit => "limit NDF",
        }
    }
}

impl fmt::Display for PatchForm {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.name();
        match *self {
            PatchForm::FilteredMixture { lobes, error } => {
                write!(f, "{name} ({lobes} lobes, measured TV {error:.3})")
            }
            PatchForm::Cut {
                nodes,
                lobes,
                max_error,
            } => write!(
                f,
                "{name} ({nodes} nodes, {lobes} lobes, largest node error {max_error:.3})"
            ),
            PatchForm::Gathered { level, lobes } => {
                write!(f, "{name} (level {level}, {lobes} lobes)")
            }
            PatchForm::BinList { bins } => {
                let s = if bins == 1 { "" } else { "s" };
                write!(f, "{name} ({bins} bin{s})")
            }
            PatchForm::Facets { lobes } => write!(f, "{name} ({lobes} lobes)"),
            _ => f.write_str(name),
        }
    }
}
