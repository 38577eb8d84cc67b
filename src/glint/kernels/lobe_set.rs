//! A small weighted set of slope Gaussians evaluated by brute force: what a glint patch serves
//! when its level of detail is one lobe (the mixture's filtered lobe and sub-texel limit lobe) or
//! the filtered mixture of a large footprint (gmm.rs, for the mixture and position-normal), with
//! the terms of \[Chermain2019\] eq. 9-17 over its lobes:
//!
//! - D(m) = Σ w_i D_i(m) over the lobes whose slope box holds m's slope: the box of the ellipse
//!   holding 1 − [`BOX_TAIL`] of the lobe (k = √(−2 ln tail) standard deviations per axis), so that a
//!   query costs a box test per lobe and a density only where it contributes (as the mixture's
//!   slope boxes at its default tail);
//! - A(w) = max(cos θ − w_xy·μ, 0), μ = Σ w_i μ_i (the signed areas summed, as the mixture's);
//! - V(w) = Σ w_i V_i(w) (exact, O(lobes));
//! - `sample_normal`: a lobe ∝ w_i, then its slope Gaussian; density Σ w_i D_i(m) cos θ_m;
//! - `sample_visible`: a lobe ∝ w_i V_i(wo), then its visible normal; density
//!   Σ w_i ⟨wo, m⟩⁺ D_i(m) / V(wo).
//!
//! A set of one lobe answers every query as that lobe does. A patch holds one lobe inline
//! ([`Few::One`]) or a set lent by the caller's scratch ([`Few::Set`]), so that neither a patch's
//! size nor a shading loop's allocations grow with the set.

use super::prepared_view::PreparedView;
use crate::glint::scratch::Lent;
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Vec2, Vec3};

/// A weighted set of slope Gaussians (module docs).
#[derive(Clone, Debug, Default)]
pub(crate) struct LobeSet {
    n: usize,
    w: Vec<f32>,
    g: Vec<SlopeGaussian>,
    /// Slope boxes [min x, min y, max x, max y] (module docs).
    boxes: Vec<[f32; 4]>,
    /// Per lobe, √(Σxx + Σyy) ≥ the largest standard deviation of its slope along any direction.
    spread: Vec<f32>,
    /// V(wo) at the view the set was prepared for ([`LobeSet::prepare_view`]); reset by every
    /// change of the set.
    view: PreparedView,
}

/// Mass of a lobe left outside its slope box: 10⁻⁶, the mixture's default slope tail.
pub(crate) const BOX_TAIL: f64 = 1.0e-6;

/// k = √(−2 ln [`BOX_TAIL`]): a slope box's half-width in standard deviations.
fn box_sigmas() -> f32 {
    (-2.0 * BOX_TAIL.ln()).sqrt() as f32
}

/// The half-widths of the slope box of `g` holding 1 − [`BOX_TAIL`] of it: k (√Σxx, √Σyy),
/// k = √(−2 ln tail).
pub(crate) fn box_half_widths(g: &SlopeGaussian) -> Vec2 {
    let k = box_sigmas();
    let c = g.covariance();
    Vec2::new(
        k * c.x_axis.x.max(0.0).sqrt(),
        k * c.y_axis.y.max(0.0).sqrt(),
    )
}

/// What a few-lobe patch holds: one lobe inline, or a set lent by the caller's scratch.
#[derive(Clone, Debug)]
pub(crate) enum Few<'a> {
    /// No lobes (a gathered patch).
    None,
    /// One lobe of weight 1.
    One(SlopeGaussian),
    /// A weighted set.
    Set(Lent<'a, LobeSet>),
}

impl LobeSet {
    /// Empties the set (keeping its capacity).
    pub fn clear(&mut self) {
        self.n = 0;
        self.w.clear();
        self.g.clear();
        self.boxes.clear();
        self.spread.clear();
        self.view = PreparedView::NONE;
    }

    /// Adds a lobe of weight `w` (ignored unless `w` is positive and finite).
    pub fn push(&mut self, w: f32, g: SlopeGaussian) {
        self.push_with_half_widths(w, g, box_half_widths(&g));
    }

    /// Adds a lobe of weight `w` whose slope box (the box of [`BOX_TAIL`], as [`LobeSet::push`]
    /// computes it) is mean ± `half` per axis: for many lobes of one shape, whose half-widths
    /// [`box_half_widths`] computes once.
    pub fn push_with_half_widths(&mut self, w: f32, g: SlopeGaussian, half: Vec2) {
        if w > 0.0 && w.is_finite() {
            let m = g.mean();
            self.w.push(w);
            self.g.push(g);
            self.boxes
                .push([m.x - half.x, m.y - half.y, m.x + half.x, m.y + half.y]);
            self.spread.push(half.length() / box_sigmas());
            self.n += 1;
            self.view = PreparedView::NONE;
        }
    }

    /// Scales the weights to sum to 1 (an empty set stays empty).
    pub fn normalise(&mut self) {
        self.view = PreparedView::NONE;
        let sum: f32 = self.weights().iter().sum();
        if sum > 0.0 {
            for w in &mut self.w[..self.n] {
                *w /= sum;
            }
        }
    }

    /// Prepares the set for the view direction `wo`: V(wo), an O(lobes) pass, computed here once
    /// and read by the queries at that wo (`view_visible_area`, the visible densities); queries at
    /// any other view compute their own, and every value is the unprepared set's, bit for bit.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view = PreparedView::NONE;
        if self.n > 1 && wo.z > 0.0 && wo.is_finite() {
            self.view = PreparedView::new(wo, self.visible_area(wo) as f64);
        }
    }

    /// Number of lobes.
    pub fn len(&self) -> usize {
        self.n
    }

    fn weights(&self) -> &[f32] {
        &self.w[..self.n]
    }

    /// (weight, lobe) pairs.
    pub fn iter(&self) -> impl Iterator<Item = (f32, &SlopeGaussian)> {
        self.weights().iter().copied().zip(&self.g[..self.n])
    }

    /// The mean slope Σ w_i μ_i.
    pub fn mean_slope(&self) -> Vec2 {
        self.iter().map(|(w, g)| w * g.mean()).sum()
    }

    /// Picks lobe i with probability ∝ `p(i)` (each evaluated once), rescaling `u` into [0, 1) for
    /// the lobe's own draw.
    fn pick(&self, p: impl Fn(usize) -> f32, u: f32) -> Option<(usize, f32)> {
        // The probabilities of the first `STACK` lobes on the stack (a filtered mixture has ≤ 32),
        // the rest evaluated again in the scan.
        const STACK: usize = 32;
        let mut first = [0.0f32; STACK];
        for (i, f) in first.iter_mut().enumerate().take(self.n) {
            *f = p(i);
        }
        let total: f32 = first.iter().sum::<f32>() + (STACK..self.n).map(&p).sum::<f32>();
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let target = u.clamp(0.0, 1.0) * total;
        let mut acc = 0.0;
        let mut last = None;
        for i in 0..self.n {
            let pi = first.get(i).copied().unwrap_or_else(|| p(i));
            if pi <= 0.0 {
                continue;
            }
            last = Some(i);
            if target < acc + pi {
                let r = ((target - acc) / pi).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
                return Some((i, r));
            }
            acc += pi;
        }
        last.map(|i| (i, 1.0 - f32::EPSILON / 2.0))
    }
}

impl LobeSet {
    /// V_i(w) of lobe i, the number `SlopeGaussian::visible_area` returns: where the lobe lies
    /// wholly in front of w (A_s > 8 s_w, checked with the bound s_w ≤ spread · |w_xy|), V_i = A_s
    /// exactly, computed as that function computes it without its per-lobe square root.
    #[inline]
    fn lobe_visible_area(&self, i: usize, w: Vec3, w_xy: f32) -> f32 {
        let m = self.g[i].mean();
        let a_s = w.z as f64 - (m.x as f64 * w.x as f64 + m.y as f64 * w.y as f64);
        if a_s > 8.0 * (self.spread[i] * w_xy) as f64 * (1.0 + 1e-6) {
            crate::math::finite_or_zero(a_s)
        } else {
            self.g[i].visible_area(w)
        }
    }

    /// The lobe itself when the set is one lobe of weight 1 (every query then delegates to it,
    /// bit for bit).
    #[inline]
    fn single(&self) -> Option<&SlopeGaussian> {
        (self.n == 1).then(|| &self.g[0])
    }
}

impl Ndf for LobeSet {
    fn d(&self, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.d(m);
        }
        let Some(s) = crate::frame::normal_to_slope(m) else {
            return 0.0;
        };
        let mut sum = 0.0;
        for i in 0..self.n {
            let b = &self.boxes[i];
            if s.x >= b[0] && s.x <= b[2] && s.y >= b[1] && s.y <= b[3] {
                sum += self.w[i] * self.g[i].d(m);
            }
        }
        sum
    }

    fn lambda(&self, w: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.lambda(w);
        }
        crate::ndf::lambda_from_areas(self, w)
    }

    fn projected_area(&self, w: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.projected_area(w);
        }
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let mu = self.mean_slope();
        // A huge non-unit w overflows the products: 0, as for invalid w (the values of every
        // finite result are unchanged).
        let a = (w.z - w.x * mu.x - w.y * mu.y).max(0.0);
        if a.is_finite() { a } else { 0.0 }
    }

    fn visible_area(&self, w: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.visible_area(w);
        }
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        let w_xy = Vec2::new(w.x, w.y).length();
        let v: f32 = (0..self.n)
            .map(|i| self.w[i] * self.lobe_visible_area(i, w, w_xy))
            .sum();
        if v.is_finite() { v } else { 0.0 }
    }

    /// V(wo): the prepared value at the prepared view ([`LobeSet::prepare_view`]), else one pass.
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        self.view.get_or(wo, || self.visible_area(wo) as f64) as f32
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        if let Some(g) = self.single() {
            return g.sample_normal(u);
        }
        match self.pick(|i| self.w[i], u.x) {
            Some((i, ux)) => self.g[i].sample_normal(Vec2::new(ux, u.y)),
            None => Vec3::Z,
        }
    }

    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if let Some(g) = self.single() {
            return g.sample_visible(wo, u);
        }
        if !(wo.z > 0.0 && wo.is_finite()) {
            return self.sample_normal(u);
        }
        let w_xy = Vec2::new(wo.x, wo.y).length();
        match self.pick(|i| self.w[i] * self.lobe_visible_area(i, wo, w_xy), u.x) {
            Some((i, ux)) => self.g[i].sample_visible(wo, Vec2::new(ux, u.y)),
            None => self.sample_normal(u),
        }
    }

    fn pdf_normal(&self, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_normal(m);
        }
        if !(m.z > 0.0 && m.is_finite()) {
            return 0.0;
        }
        let p = self.d(m) * m.z;
        if p.is_finite() { p } else { 0.0 }
    }

    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_visible(wo, m);
        }
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        let v = self.view_visible_area(wo);
        if v.is_nan() || v <= 0.0 {
            return 0.0;
        }
        let p = c * self.d(m) / v;
        if p.is_finite() { p } else { 0.0 }
    }

    /// D(m) / V(wo): [`Ndf::pdf_visible`] without its factor ⟨wo, m⟩.
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_visible_over_cos_given_d(wo, m, d_m);
        }
        if !(wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        crate::ndf::visible_over_cos(wo, m, d_m, self.view_visible_area(wo))
    }
}

impl Few<'_> {
    /// The lobes as (weight, lobe) pairs (empty for [`Few::None`]).
    pub fn lobes(&self) -> Vec<(f32, SlopeGaussian)> {
        match self {
            Few::None => Vec::new(),
            Few::One(g) => vec![(1.0, *g)],
            Few::Set(s) => s.iter().map(|(w, g)| (w, *g)).collect(),
        }
    }

    /// Prepares a set for the view `wo` ([`LobeSet::prepare_view`]); one lobe needs nothing.
    pub fn prepare_view(&mut self, wo: Vec3) {
        if let Few::Set(s) = self {
            s.prepare_view(wo);
        }
    }

    /// The mean slope Σ w_i μ_i (zero for [`Few::None`]).
    pub fn mean_slope(&self) -> Vec2 {
        match self {
            Few::None => Vec2::ZERO,
            Few::One(g) => g.mean(),
            Few::Set(s) => s.mean_slope(),
        }
    }
}

/// Runs `$body` with `$n` bound to the lobe or the set (a [`Few::None`] answers `$none`).
macro_rules! with_few {
    ($few:expr, $none:expr, |$n:ident| $body:expr) => {
        match $few {
            Few::None => $none,
            Few::One($n) => $body,
            Few::Set(s) => {
                let $n: &LobeSet = s;
                $body
            }
        }
    };
}

impl Ndf for Few<'_> {
    fn d(&self, m: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.d(m))
    }

    fn lambda(&self, w: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.lambda(w))
    }

    fn projected_area(&self, w: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.projected_area(w))
    }

    fn visible_area(&self, w: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.visible_area(w))
    }

    fn view_visible_area(&self, wo: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.view_visible_area(wo))
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        with_few!(self, Vec3::Z, |n| n.sample_normal(u))
    }

    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        with_few!(self, Vec3::Z, |n| n.sample_visible(wo, u))
    }

    fn pdf_normal(&self, m: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.pdf_normal(m))
    }

    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        with_few!(self, 0.0, |n| n.pdf_visible(wo, m))
    }

    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        with_few!(self, 0.0, |n| n.pdf_visible_over_cos_given_d(wo, m, d_m))
    }
}
