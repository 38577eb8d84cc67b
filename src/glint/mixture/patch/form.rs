//! The form of a [`MixturePatch`] ([`PatchForm`]): which of the mixture's levels of detail serves it.

use super::super::choice::SetKind;
use super::MixturePatch;
use crate::glint::PatchForm;

impl MixturePatch<'_> {
    /// The form of the patch: the sub-texel lobe, the filtered lobe, the filtered mixture (with its
    /// measured TV at this level), a cut of the hierarchy (its nodes, lobes and largest node
    /// error) or the lobes gathered at a level of detail (their number: the one form whose work
    /// grows with the footprint). [`crate::glint::GlintModel::forms`] reports it across footprint
    /// sizes.
    pub fn form(&self) -> PatchForm {
        let lobes = self.few.iter_lobes().count();
        match (self.few_kind, self.cut) {
            (Some(SetKind::SubTexel), _) => PatchForm::SubTexel,
            (Some(SetKind::FilteredLobe), _) => PatchForm::FilteredLobe,
            (Some(SetKind::FilteredMixture), _) => PatchForm::FilteredMixture {
                lobes,
                error: self.few_error,
            },
            (Some(SetKind::Cut), Some(c)) => PatchForm::Cut {
                nodes: c.nodes,
                lobes: c.lobes,
                max_error: c.max_error,
            },
            (Some(SetKind::Cut), None) => PatchForm::Cut {
                nodes: 0,
                lobes,
                max_error: self.few_error,
            },
            (None, _) => PatchForm::Gathered {
                level: self.level(),
                lobes: self.lobe_count(),
            },
        }
    }
}
