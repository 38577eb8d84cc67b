//! A small weighted set of slope Gaussians evaluated by brute force: what a glint patch serves
//! when its level of detail is one lobe (the mixture's filtered lobe and sub-texel limit lobe) or
//! the filtered mixture of a large footprint (gmm.rs, for the mixture and position-normal), and a
//! procedural GGX surface's facet lobes (src/glint/procedural/), with the terms of
//! \[Chermain2019\] eq. 9-17 over its lobes:
//!
//! - D(m) = Σ w_i D_i(m) over the lobes whose slope box holds m's slope (their P22 summed at one
//!   slope in `f64`, times the shared Jacobian (1 + |ñ|²)²): the box of the ellipse
//!   holding 1 − [`BOX_TAIL`] of the lobe (k = √(−2 ln tail) standard deviations per axis), so that a
//!   query costs a box test per lobe and a density only where it contributes (as the mixture's
//!   slope boxes at its default tail);
//! - A(w) = max(cos θ − w_xy·μ, 0), μ = Σ w_i μ_i (the signed areas summed, as the mixture's);
//! - V(w) = Σ w_i V_i(w) (exact up to the lanes' 10⁻⁶, O(lobes)): each V_i its signed area alone
//!   where an O(1) bound puts every lobe more than [`FRONT_T`] spreads in front of w, else the ramp
//!   term over [`CHUNK`] lanes ([`lobe_areas`], shared with src/glint/kernels/shared_lobes.rs);
//! - `sample_normal`: a lobe ∝ w_i, then its slope Gaussian; density Σ w_i D_i(m) cos θ_m;
//! - `sample_visible`: a lobe ∝ w_i V_i(wo), then its visible normal; density
//!   Σ w_i ⟨wo, m⟩⁺ D_i(m) / V(wo).
//!
//! A set of one lobe answers every query as that lobe does. A patch holds one lobe inline
//! ([`Few::One`]) or a set lent by the caller's scratch ([`Few::Set`]), so that neither a patch's
//! size nor a shading loop's allocations grow with the set.

use super::lanes::{exp_neg_half, ramp_neg_lanes};
use super::prepared_view::PreparedView;
use crate::glint::scratch::Lent;
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Vec2, Vec3};

/// `v` if finite, else 0.
#[inline]
fn finite_or_zero(v: f32) -> f32 {
    if v.is_finite() { v } else { 0.0 }
}

/// A weighted set of slope Gaussians (module docs).
#[derive(Clone, Debug)]
pub(crate) struct LobeSet {
    n: usize,
    w: Vec<f32>,
    g: Vec<SlopeGaussian>,
    /// Slope boxes [min x, min y, max x, max y] (module docs).
    boxes: Vec<[f32; 4]>,
    /// The mean slope Σ w_i μ_i of the current weights (kept by every change of the set).
    mean: Vec2,
    /// The box of the lobes' means, [min x, min y, max x, max y], and the largest trace of their
    /// covariances: what [`all_in_front`] bounds every lobe's masking terms by.
    mean_box: [f32; 4],
    trace_max: f64,
    /// V(wo) at the view the set was prepared for ([`LobeSet::prepare_view`]); reset by every
    /// change of the set.
    view: PreparedView,
    /// At the prepared view, each lobe's w_i V_i(wo) (the visible sampler's pick weights, whose
    /// sum is V(wo)); empty when no view is prepared.
    view_lobes: Vec<f32>,
}

/// The largest t = |A_s|/s_w at which a lobe wholly behind w takes the lanes' G(−t) (≈ 4·10⁻³⁴ there,
/// within the lanes' stated error); beyond it the lobe's own `f64` V.
const LANE_RAMP_MAX: f64 = 12.0;

/// The least t = A_s/s_w at which a lobe in front of w takes V_i = A_s (the term s_w G(−t)
/// dropped is G(−t)/t < φ(t)/t³ < 10⁻⁹ of it: below `f32` rounding).
pub(crate) const FRONT_T: f64 = 5.5;

/// Lobes per pass of the lane kernel [`ramp_neg_lanes`]: a set holds a
/// few to a few tens of lobes.
const CHUNK: usize = 8;

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

impl Default for LobeSet {
    fn default() -> Self {
        let mut s = LobeSet {
            n: 0,
            w: Vec::new(),
            g: Vec::new(),
            boxes: Vec::new(),
            mean: Vec2::ZERO,
            mean_box: [0.0; 4],
            trace_max: 0.0,
            view: PreparedView::NONE,
            view_lobes: Vec::new(),
        };
        s.clear();
        s
    }
}

impl LobeSet {
    /// Empties the set (keeping its capacity).
    pub fn clear(&mut self) {
        self.n = 0;
        self.w.clear();
        self.g.clear();
        self.boxes.clear();
        self.mean = Vec2::ZERO;
        self.mean_box = [
            f32::INFINITY,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NEG_INFINITY,
        ];
        self.trace_max = 0.0;
        self.unprepare();
    }

    /// Forgets the prepared view (every change of the set calls it).
    fn unprepare(&mut self) {
        self.view = PreparedView::NONE;
        self.view_lobes.clear();
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
            self.mean += w * m;
            let b = &mut self.mean_box;
            *b = [b[0].min(m.x), b[1].min(m.y), b[2].max(m.x), b[3].max(m.y)];
            self.trace_max = self.trace_max.max(g.covariance_trace_f64());
            self.n += 1;
            self.unprepare();
        }
    }

    /// Scales the weights to sum to 1 (an empty set stays empty).
    pub fn normalise(&mut self) {
        self.unprepare();
        let sum: f32 = self.weights().iter().sum();
        if sum > 0.0 {
            for w in &mut self.w[..self.n] {
                *w /= sum;
            }
        }
        self.mean = self.iter().map(|(w, g)| w * g.mean()).sum();
    }

    /// Prepares the set for the view direction `wo`: V(wo), an O(lobes) pass, computed here once
    /// and read by the queries at that wo (`view_visible_area`, the visible densities); queries at
    /// any other view compute their own, and every value is the unprepared set's, bit for bit.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.unprepare();
        if self.n > 1 && wo.z > 0.0 && wo.is_finite() {
            let mut lobes = core::mem::take(&mut self.view_lobes);
            let mut v = 0.0f32;
            // The terms and their sum as `visible_area` forms them (`lobe_area_sum`).
            self.for_each_lobe_area(wo, |_, x| {
                lobes.push(x);
                v += x;
            });
            self.view = PreparedView::new(wo, finite_or_zero(v) as f64);
            self.view_lobes = lobes;
        }
    }

    /// The pick weights w_i V_i(wo) at the prepared view, if `wo` is it.
    fn prepared_lobes(&self, wo: Vec3) -> Option<&[f32]> {
        (self.view_lobes.len() == self.n && self.view.is(wo)).then_some(&self.view_lobes[..])
    }

    /// Number of lobes.
    pub fn len(&self) -> usize {
        self.n
    }

    fn weights(&self) -> &[f32] {
        &self.w[..self.n]
    }

    /// (weight, lobe) pairs.
    pub fn iter(&self) -> impl Iterator<Item = (f32, &SlopeGaussian)> + Clone {
        self.weights().iter().copied().zip(&self.g[..self.n])
    }

    /// The mean slope Σ w_i μ_i.
    pub fn mean_slope(&self) -> Vec2 {
        self.mean
    }
}

/// `f(i, w_i V_i(w))` for `n` lobes in order, for a usable w (w_z > 0, finite), from each lobe's
/// `terms(i)` = (w_i, A_s, s_w) (its weight, signed area and spread toward w, in `f64`). Where
/// `in_front` ([`all_in_front`]), V_i is A_s alone (the term dropped is below `f32` rounding).
/// Else V_i = A_s⁺ + s_w G(−|A_s|/s_w) (the two branches of `SlopeGaussian::visible_area` in one
/// form, since G(z) = z + G(−z)), G over [`CHUNK`] lanes ([`ramp_neg_lanes`], relative error
/// < 10⁻⁶); a lobe wholly behind w by more than [`LANE_RAMP_MAX`] of its s_w, where the lanes' G
/// leaves `f32`'s normal range, takes `own_v(i)`, the lobe's own `f64` V.
#[inline]
pub(crate) fn lobe_areas(
    n: usize,
    terms: impl Fn(usize) -> (f32, f64, f64),
    own_v: impl Fn(usize) -> f32,
    in_front: bool,
    mut f: impl FnMut(usize, f32),
) {
    if in_front {
        for i in 0..n {
            let (wi, a, _) = terms(i);
            f(i, wi * a as f32);
        }
        return;
    }
    for base in (0..n).step_by(CHUNK) {
        let len = CHUNK.min(n - base);
        let mut wt = [0.0f32; CHUNK];
        let mut a = [0.0f64; CHUNK];
        let mut sw = [0.0f64; CHUNK];
        let mut t = [0.0f64; CHUNK];
        for k in 0..len {
            let (wk, ak, sk) = terms(base + k);
            (wt[k], a[k], sw[k], t[k]) = (wk, ak, sk, ak.abs() / sk);
        }
        // A lobe wholly in front of w by more than 8 s_w has V = A_s to `f64` resolution
        // (G(−t)/t < 10⁻¹⁷ there): a chunk of such lobes skips the ramp.
        let mut ramp = [0.0f32; CHUNK];
        if (0..len).any(|k| !(a[k] > 0.0 && t[k] > 8.0)) {
            ramp_neg_lanes(&t, &mut ramp);
        }
        for k in 0..len {
            let v = if a[k] < 0.0 && t[k] > LANE_RAMP_MAX {
                own_v(base + k)
            } else {
                finite_or_zero((a[k].max(0.0) + sw[k] * ramp[k] as f64) as f32)
            };
            f(base + k, wt[k] * v);
        }
    }
}

/// Whether every lobe of a set is in front of w by more than [`FRONT_T`] of its spread
/// (A_s > t s_w), from bounds that cost O(1): A_s ≥ w_z − max over `mean_box` (the box of the
/// lobes' means, [min x, min y, max x, max y]) of μ·w_xy, and s_w² = |Lᵀ w_xy|² ≤ tr Σ |w_xy|²
/// (Cauchy-Schwarz) with `trace_max` the largest trace. For a usable w.
#[inline]
pub(crate) fn all_in_front(mean_box: &[f32; 4], trace_max: f64, w: Vec3) -> bool {
    let (wx, wy, wz) = (w.x as f64, w.y as f64, w.z as f64);
    let b = mean_box;
    let mx = if wx > 0.0 { b[2] } else { b[0] } as f64;
    let my = if wy > 0.0 { b[3] } else { b[1] } as f64;
    let a_min = wz - (mx * wx + my * wy);
    let s2 = trace_max * (wx * wx + wy * wy);
    // The margin covers the rounding of the bounds against the lobes' own terms.
    a_min > 0.0 && a_min * a_min > FRONT_T * FRONT_T * s2 * (1.0 + 1e-9)
}

/// Picks lobe i with probability ∝ `p[i]`, rescaling `u` into [0, 1) for the lobe's own draw.
pub(crate) fn pick(p: &[f32], u: f32) -> Option<(usize, f32)> {
    let total: f32 = p.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return None;
    }
    let target = u.clamp(0.0, 1.0) * total;
    let mut acc = 0.0;
    let mut last = None;
    for (i, &pi) in p.iter().enumerate() {
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

impl LobeSet {
    /// `f(i, w_i V_i(w))` for every lobe i in order ([`lobe_areas`]).
    fn for_each_lobe_area(&self, w: Vec3, f: impl FnMut(usize, f32)) {
        let front = all_in_front(&self.mean_box, self.trace_max, w);
        let terms = |i: usize| {
            let (a, s) = self.g[i].area_and_spread(w);
            (self.w[i], a, s)
        };
        lobe_areas(self.n, terms, |i| self.g[i].visible_area(w), front, f);
    }

    /// V(w) = Σ w_i V_i(w), summed in lobe order from +0 (the prepared view's sum is formed the
    /// same way, so the two agree bit for bit).
    fn lobe_area_sum(&self, w: Vec3) -> f32 {
        let mut v = 0.0f32;
        self.for_each_lobe_area(w, |_, x| v += x);
        v
    }

    /// The pick weights w_i V_i(wo) (the prepared ones at the prepared view), then `f` of them.
    fn with_pick_weights<R>(&self, wo: Vec3, f: impl FnOnce(&[f32]) -> R) -> R {
        if let Some(p) = self.prepared_lobes(wo) {
            return f(p);
        }
        // An unprepared view: on the stack for sets up to `STACK` lobes (every few-lobe form but a
        // large cut), else one allocation.
        const STACK: usize = 64;
        if self.n <= STACK {
            let mut buf = [0.0f32; STACK];
            self.for_each_lobe_area(wo, |i, x| buf[i] = x);
            f(&buf[..self.n])
        } else {
            let mut buf = vec![0.0f32; self.n];
            self.for_each_lobe_area(wo, |i, x| buf[i] = x);
            f(&buf)
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
        // The slope and the Jacobian (1 + |ñ|²)² once in `f64`, as `SlopeGaussian::d` forms them
        // per lobe; the lobes' P22 (the exponential inline, `exp_neg_half`: < 10⁻⁶ relative, 0
        // past 13 standard deviations) summed in `f64` and rounded once.
        let (sx, sy) = (-(m.x as f64) / m.z as f64, -(m.y as f64) / m.z as f64);
        let mut sum = 0.0f64;
        for i in 0..self.n {
            let b = &self.boxes[i];
            if s.x >= b[0] && s.x <= b[2] && s.y >= b[1] && s.y <= b[3] {
                let (q, peak) = self.g[i].mahalanobis2_and_peak_f64(sx, sy);
                sum += self.w[i] as f64 * peak * exp_neg_half(q) as f64;
            }
        }
        let j = 1.0 + sx * sx + sy * sy;
        // Beyond `f32::MAX` clamped to it, as each lobe's D is.
        (sum * j * j).min(f32::MAX as f64) as f32
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
        finite_or_zero(self.lobe_area_sum(w))
    }

    /// V(wo): the prepared value at the prepared view ([`LobeSet::prepare_view`]), else one pass.
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        self.view.get_or(wo, || self.visible_area(wo) as f64) as f32
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        if let Some(g) = self.single() {
            return g.sample_normal(u);
        }
        match pick(self.weights(), u.x) {
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
        match self.with_pick_weights(wo, |p| pick(p, u.x)) {
            Some((i, ux)) => self.g[i].sample_visible(wo, Vec2::new(ux, u.y)),
            None => self.sample_normal(u),
        }
    }

    fn pdf_normal(&self, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_normal(m);
        }
        pdf_normal_of(m, || self.d(m))
    }

    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_visible(wo, m);
        }
        pdf_visible_of(wo, m, || self.d(m), || self.view_visible_area(wo))
    }

    /// D(m) / V(wo): [`Ndf::pdf_visible`] without its factor ⟨wo, m⟩.
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        if let Some(g) = self.single() {
            return g.pdf_visible_over_cos_given_d(wo, m, d_m);
        }
        visible_over_cos_of(wo, m, d_m, || self.view_visible_area(wo))
    }
}

/// A lobe set's normal density D(m) cos θ_m from its D (`d`, asked only for m above the horizon);
/// 0 below the horizon, for non-finite m and where it is not finite.
pub(crate) fn pdf_normal_of(m: Vec3, d: impl FnOnce() -> f32) -> f32 {
    if !(m.z > 0.0 && m.is_finite()) {
        return 0.0;
    }
    let p = d() * m.z;
    if p.is_finite() { p } else { 0.0 }
}

/// A lobe set's visible density ⟨wo, m⟩⁺ D(m) / V(wo) from its D (`d`) and V(wo) (`v`), both asked
/// only for valid, facing wo and m; 0 elsewhere and where it is not finite.
pub(crate) fn pdf_visible_of(
    wo: Vec3,
    m: Vec3,
    d: impl FnOnce() -> f32,
    v: impl FnOnce() -> f32,
) -> f32 {
    let c = wo.dot(m);
    if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
        return 0.0;
    }
    let v = v();
    if v.is_nan() || v <= 0.0 {
        return 0.0;
    }
    let p = c * d() / v;
    if p.is_finite() { p } else { 0.0 }
}

/// D(m) / V(wo) of a lobe set given D(m) = `d_m` and its V(wo) (`v`, asked only for finite wo and
/// m): [`pdf_visible_of`] without its factor ⟨wo, m⟩.
pub(crate) fn visible_over_cos_of(wo: Vec3, m: Vec3, d_m: f32, v: impl FnOnce() -> f32) -> f32 {
    if !(wo.is_finite() && m.is_finite()) {
        return 0.0;
    }
    crate::ndf::visible_over_cos(wo, m, d_m, v())
}

impl Few<'_> {
    /// The lobes as (weight, lobe) pairs without allocating (empty for [`Few::None`]).
    pub fn iter_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        let (one, set) = match self {
            Few::None => (None, None),
            Few::One(g) => (Some((1.0, *g)), None),
            Few::Set(s) => (None, Some(&**s)),
        };
        one.into_iter()
            .chain(set.into_iter().flat_map(|s| s.iter().map(|(w, g)| (w, *g))))
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

#[cfg(test)]
mod tests;
