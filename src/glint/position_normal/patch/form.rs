//! The form of a [`PositionNormalPatch`] ([`PatchForm`]): the element sum, the filtered mixture or
//! a cut of its hierarchy.

use super::PositionNormalPatch;
use crate::glint::PatchForm;
use crate::glint::kernels::lobe_set::Few;

impl PositionNormalPatch<'_> {
    /// The form of the patch: the filtered mixture (with its measured TV at this level), a cut of
    /// the hierarchy (its nodes, lobes and largest node error) or the element sum at level 0 (its
    /// elements: the one form whose work grows with the footprint).
    /// [`crate::glint::GlintModel::forms`] reports it across footprint sizes.
    pub fn form(&self) -> PatchForm {
        let lobes = self.few.iter_lobes().count();
        match (&self.few, self.cut) {
            (Few::None, _) => PatchForm::Gathered {
                level: 0,
                lobes: self.count,
            },
            (_, Some(c)) => PatchForm::Cut {
                nodes: c.nodes,
                lobes: c.lobes,
                max_error: c.max_error,
            },
            (_, None) => PatchForm::FilteredMixture {
                lobes,
                error: self.few_error,
            },
        }
    }
}
