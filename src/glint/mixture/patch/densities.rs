//! The patch's densities ([`Ndf::pdf_normal`], [`Ndf::pdf_visible`] and its per-cosine form)
//! and its few-lobe view: for gathered lobes, D_P itself (the samplers draw each lobe within the
//! slope box D_P counts it in: [`MixturePatch::sample_lobe_in_box`], here), 0 where D_P is (the
//! density contract), V(wo) prepared for the patch's view.

use super::{MixturePatch, PatchLevel};
use crate::frame::normal_to_slope;
use crate::glint::kernels::cdf::rehash;
use crate::glint::kernels::lobe_set::Few;
use crate::glint::mixture::storage::LevelView;
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};

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

    /// Lobe k's visible normal for `wo` (its normal if `None`) **within its slope box**, the box
    /// D_P counts it in ([`blocks::p22_lanes`]): a draw outside the box (probability ≤ ~10⁻⁶, the
    /// lobe's truncated tail) is redrawn with numbers derived from u ([`rehash`]), up to
    /// [`MAX_REDRAWS`] times, then replaced by the lobe's mean normal, which lies in the box. So the
    /// samplers' densities are those of D_P's own truncated lobes, renormalised by each lobe's mass
    /// in its box (1 − ≤ ~10⁻⁶), and the pdfs read them from D_P.
    pub(super) fn sample_lobe_in_box(&self, k: usize, wo: Option<Vec3>, u: Vec2) -> Vec3 {
        let lobe = self.level.lobe(k);
        let draw = |u: Vec2| match wo {
            Some(wo) => lobe.sample_visible(wo, u),
            None => lobe.sample_normal(u),
        };
        let mut m = draw(u);
        for round in 0..MAX_REDRAWS {
            if self.in_lobe_box(k, m) {
                return m;
            }
            m = draw(rehash(u, round));
        }
        if self.in_lobe_box(k, m) {
            m
        } else {
            let mu = lobe.mean();
            Vec3::new(-mu.x, -mu.y, 1.0).normalize()
        }
    }

    /// Whether normal m's slope lies in lobe k's slope box (the test of [`blocks::p22_lanes`]).
    fn in_lobe_box(&self, k: usize, m: Vec3) -> bool {
        let Some(s) = normal_to_slope(m) else {
            return false;
        };
        let k2 = self.box_k * self.box_k;
        match self.level {
            PatchLevel::Full(lv) => lane_in_box(&lv, k, s, k2),
            PatchLevel::Compact(lv) => lane_in_box(&lv, k, s, k2),
        }
    }
}

/// Redraws of a lobe's sample that fell outside its slope box before the lobe's mean stands in
/// ([`MixturePatch::sample_lobe_in_box`]): each redraw fails with probability ≤ ~10⁻⁶.
const MAX_REDRAWS: u64 = 8;

/// Whether slope `s` lies in node k's slope box on level `lv` (its block lane's test).
fn lane_in_box<L: LevelView>(lv: &L, k: usize, s: Vec2, k2: f32) -> bool {
    use super::blocks::SIDE;
    let nx = lv.grid()[0];
    let (x, y) = (k % nx, k / nx);
    let mut scratch = L::scratch();
    lv.block(x / SIDE, y / SIDE, &mut scratch)
        .in_box((y % SIDE) * SIDE + x % SIDE, s, k2)
}
