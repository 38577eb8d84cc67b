//! The limit NDF of a procedural glint surface ([`LimitNdf`]: Beckmann or GGX) and the patch form
//! that blends GGX into facet lobes ([`GgxBlend`]): D = (1 − b) Σ w_i D_i + b D_GGX, every term of
//! the [`Ndf`] exact over its parts.

use crate::glint::kernels::lobe_set::Few;
use crate::ndf::{Ggx, Ndf, SlopeGaussian, forward_ndf, normal_over_cos, visible_over_cos};
use glam::{Vec2, Vec3};

/// The NDF a [`ProceduralGlints`](super::ProceduralGlints) surface converges to
/// ([`ProceduralGlints::limit`](super::ProceduralGlints::limit)): the mean of its P-NDF over
/// positions at every footprint size and the patch of every large footprint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LimitNdf {
    /// The centred anisotropic Beckmann lobe of roughness α.
    Beckmann(SlopeGaussian),
    /// The anisotropic GGX NDF of roughness α.
    Ggx(Ggx),
}

/// Binds the limit's NDF to `$n` (for [`forward_ndf`]).
macro_rules! to_limit {
    ($s:ident, $n:ident => $e:expr) => {
        match $s {
            LimitNdf::Beckmann($n) => $e,
            LimitNdf::Ggx($n) => $e,
        }
    };
}

forward_ndf!([] LimitNdf, to_limit);

/// A patch's facet lobes blended with GGX: D = (1 − b) D_L + b D_GGX, D_L the lobes' (weights
/// summing to 1), 0 < b < 1.
///
/// - A(w) = cos θ − (1 − b) w_xy·μ_L (clamped at 0): the weighted sum of the parts' signed
///   projected areas, GGX's being cos θ (centred), the lobes' cos θ − w_xy·μ_L (\[Chermain2019\]
///   eq. 17).
/// - V(w) = (1 − b) V_L(w) + b V_GGX(w), V_GGX = cos θ (1 + Λ_GGX) (Smith's identity per part).
/// - `sample_normal` picks GGX with probability b; `sample_visible` picks it with probability
///   b V_GGX(wo) / V(wo), else the lobes' own sampler: densities D cos θ and ⟨wo, m⟩⁺ D / V(wo).
#[derive(Clone, Debug)]
pub(crate) struct GgxBlend<'a> {
    lobes: Few<'a>,
    b: f32,
    ggx: Ggx,
}

impl<'a> GgxBlend<'a> {
    /// The blend of `lobes` (weights summing to 1) with weight 1 − `b` and `ggx` with weight `b`.
    pub fn new(lobes: Few<'a>, b: f32, ggx: Ggx) -> Self {
        GgxBlend { lobes, b, ggx }
    }

    /// The lobes (for a patch's lobe count).
    pub fn lobes(&self) -> &Few<'a> {
        &self.lobes
    }

    /// The lobes, the weight b of GGX and GGX.
    pub fn parts(&self) -> (&Few<'a>, f32, Ggx) {
        (&self.lobes, self.b, self.ggx)
    }

    /// Prepares the lobes for the view `wo` (their V(wo), once: [`Few::prepare_view`]).
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.lobes.prepare_view(wo);
    }

    /// The parts' weighted visible areas toward `w`: ((1 − b) V_L(w), b V_GGX(w)), the lobes' as
    /// prepared where `w` is the prepared view (the same number).
    fn visible_parts(&self, w: Vec3) -> (f32, f32) {
        (
            (1.0 - self.b) * self.lobes.view_visible_area(w),
            self.b * self.ggx.visible_area(w),
        )
    }
}

/// `u` rescaled into [0, 1) after a pick of probability `p` at `u` < `p` (or of 1 − `p` above it).
#[inline]
fn rescale(u: f32, p: f32) -> (bool, f32) {
    let top = 1.0 - f32::EPSILON / 2.0;
    if u < p {
        (true, (u / p).clamp(0.0, top))
    } else {
        (false, ((u - p) / (1.0 - p)).clamp(0.0, top))
    }
}

impl Ndf for GgxBlend<'_> {
    fn d(&self, m: Vec3) -> f32 {
        let d = (1.0 - self.b) * self.lobes.d(m) + self.b * self.ggx.d(m);
        if d.is_finite() { d } else { 0.0 }
    }

    fn lambda(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_from_areas(self, w)
    }

    fn projected_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let mu = (1.0 - self.b) * self.lobes.mean_slope();
        let a = (w.z - w.x * mu.x - w.y * mu.y).max(0.0);
        if a.is_finite() { a } else { 0.0 }
    }

    fn visible_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let (l, g) = self.visible_parts(w);
        let v = l + g;
        if v.is_finite() { v } else { 0.0 }
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        match rescale(u.x, self.b) {
            (true, x) => self.ggx.sample_normal(Vec2::new(x, u.y)),
            (false, x) => self.lobes.sample_normal(Vec2::new(x, u.y)),
        }
    }

    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if !(wo.z > 0.0 && wo.is_finite()) {
            return self.sample_normal(u);
        }
        let (l, g) = self.visible_parts(wo);
        let total = l + g;
        if !(total > 0.0 && total.is_finite()) {
            return self.sample_normal(u);
        }
        match rescale(u.x, g / total) {
            (true, x) => self.ggx.sample_visible(wo, Vec2::new(x, u.y)),
            (false, x) => self.lobes.sample_visible(wo, Vec2::new(x, u.y)),
        }
    }

    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        if !(wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        visible_over_cos(wo, m, d_m, self.visible_area(wo))
    }

    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        normal_over_cos(m, d_m)
    }
}
