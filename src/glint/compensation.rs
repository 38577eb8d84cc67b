//! Every glint patch estimates its single-scattering albedo E(wo) ([`AlbedoEstimate`]), so that
//! `crate::bxdf::ViewCompensated` can give back the energy its masking removes: the estimate of
//! src/glint/kernels/albedo.rs over the patch's own slope Gaussians, with the patch's own Λ(wo).
//! O(lobes in the patch) per view. `GlintPatch` forwards to its model's (the registry,
//! src/glint/model.rs).

use super::kernels::albedo::{Lobe, lobes_albedo};
use super::{BinMapPatch, MixturePatch, PositionNormalPatch, ProceduralPatch};
use crate::bxdf::{ALBEDO_ALPHA_MAX, AlbedoEstimate, AlbedoTable};
use crate::ndf::Ndf;
use glam::Vec3;

/// The lobes of the few-lobe form or of the gathered slots.
impl AlbedoEstimate for MixturePatch<'_> {
    fn albedo_estimate(&self, wo: Vec3) -> f32 {
        lobes_albedo(
            wo,
            self.lambda(wo),
            self.albedo_lobes(),
            Some(self.filtered_lobe()),
            &[],
        )
    }
}

/// The kept elements, or the filtered mixture's lobes where it serves.
impl AlbedoEstimate for PositionNormalPatch<'_> {
    fn albedo_estimate(&self, wo: Vec3) -> f32 {
        let lobes = self.weighted_lobes().map(|(w, g)| Lobe::of(w, &g));
        lobes_albedo(wo, self.lambda(wo), lobes, Some(self.moments_lobe()), &[])
    }
}

/// The footprint's bins (or the smoothed patch's lobes, or the masking lobe).
impl AlbedoEstimate for BinMapPatch<'_> {
    fn albedo_estimate(&self, wo: Vec3) -> f32 {
        let lobes = self.albedo_lobes().map(|(w, g)| Lobe::of(w, &g));
        lobes_albedo(wo, self.lambda(wo), lobes, Some(self.masking_lobe()), &[])
    }
}

/// The facet lobes (a Beckmann surface's limit lobe among them); a GGX part enters with the
/// tabulated albedo of GGX at √(αx αy), weighted by its visible area b V_GGX(wo).
impl AlbedoEstimate for ProceduralPatch<'_> {
    fn albedo_estimate(&self, wo: Vec3) -> f32 {
        let (lobes, ggx) = self.albedo_parts();
        let extra = ggx.map(|(b, g)| {
            let alpha = (g.alpha_x() * g.alpha_y()).sqrt().min(ALBEDO_ALPHA_MAX);
            (b * g.visible_area(wo), AlbedoTable::GGX.albedo(wo.z, alpha))
        });
        let lobes = lobes.map(|(w, g)| Lobe::of(w, &g));
        lobes_albedo(wo, self.lambda(wo), lobes, None, extra.as_slice())
    }
}
