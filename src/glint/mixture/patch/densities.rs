//! The patch's densities ([`Ndf::pdf_normal`], [`Ndf::pdf_visible`] and its per-cosine form)
//! and its few-lobe view: for gathered lobes, D_P itself (the samplers draw each lobe within the
//! slope box D_P counts it in), 0 where D_P is (the density contract), V(wo) prepared for the
//! patch's view.

use super::MixturePatch;
use crate::glint::kernels::lobe_set::Few;
use crate::ndf::Ndf;
use glam::Vec3;

impl MixturePatch<'_> {
    /// The few-lobe patch's V(wo) at the view: a set's value as prepared for its view
    /// ([`LobeSet::prepare_view`](crate::glint::kernels::lobe_set::LobeSet::prepare_view)), else
    /// its pass; a single lobe's directly.
    pub(super) fn few_view_visible_area(&self, wo: Vec3) -> f32 {
        self.few.view_visible_area(wo)
    }

    /// The few-lobe patch's visible-normal density ⟨wo, m⟩⁺ D(m) / V(wo) with D(m) = `d()` and
    /// V(wo) as prepared for a set (the same value its own `pdf_visible` computes); a
    /// single lobe's own density. Without the factor ⟨wo, m⟩ where `over_cos`
    /// ([`Ndf::pdf_visible_over_cos_given_d`]).
    fn few_pdf_visible(&self, wo: Vec3, m: Vec3, d: impl FnOnce() -> f32, over_cos: bool) -> f32 {
        let Few::Set(_) = &self.few else {
            return if over_cos {
                self.few.pdf_visible_over_cos_given_d(wo, m, d())
            } else {
                self.few.pdf_visible(wo, m)
            };
        };
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        let v = self.few_view_visible_area(wo);
        if v.is_nan() || v <= 0.0 {
            return 0.0;
        }
        let p = if over_cos { d() / v } else { c * d() / v };
        if p.is_finite() { p } else { 0.0 }
    }

    /// [`Ndf::pdf_normal`], with `d` giving D_P(m) for the density contract's check.
    #[inline]
    pub(super) fn pdf_normal_with(&self, m: Vec3, d: impl FnOnce() -> f32) -> f32 {
        if self.gathered.is_none() {
            return self.few.pdf_normal(m);
        }
        if !(m.z > 0.0 && m.is_finite()) {
            return 0.0;
        }
        // D_P's own lobes, truncated to their slope boxes as the sampler draws them (0 where D_P
        // is: one density contract for every NDF).
        let p = d() * m.z;
        if p.is_finite() && p > 0.0 { p } else { 0.0 }
    }

    /// [`Ndf::pdf_visible`], with `d` giving D_P(m) for the density contract's check and V_P(wo)
    /// as prepared for the patch's view ([`MixturePatch::prepare_view`]).
    #[inline]
    pub(super) fn pdf_visible_with(&self, wo: Vec3, m: Vec3, d: impl FnOnce() -> f32) -> f32 {
        self.visible_density(wo, m, d, false)
    }

    /// [`Ndf::pdf_visible_over_cos_given_d`], with `d` giving D_P(m) for the density contract's
    /// check.
    #[inline]
    pub(super) fn pdf_visible_over_cos_with(
        &self,
        wo: Vec3,
        m: Vec3,
        d: impl FnOnce() -> f32,
    ) -> f32 {
        self.visible_density(wo, m, d, true)
    }

    /// ⟨wo, m⟩⁺ D_P(m) / V_P(wo) with D_P(m) = `d()` (0 where it is 0), without the factor ⟨wo, m⟩
    /// where `over_cos`: the visible sampler's density, its lobes drawn within their slope boxes.
    #[inline]
    fn visible_density(&self, wo: Vec3, m: Vec3, d: impl FnOnce() -> f32, over_cos: bool) -> f32 {
        let Some(g) = &self.gathered else {
            return self.few_pdf_visible(wo, m, d, over_cos);
        };
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        // D_P's own lobes, truncated to their slope boxes as the sampler draws them (0 where D_P
        // is: one density contract for every NDF).
        let d = d();
        if d.is_nan() || d <= 0.0 {
            return 0.0;
        }
        let v = self.view_exact_visible_area(g, wo);
        if v.is_nan() || v <= 0.0 {
            return 0.0;
        }
        let k = if over_cos { 1.0 } else { c as f64 };
        let p = (k * d as f64 / v) as f32;
        if p.is_finite() { p } else { 0.0 }
    }
}
