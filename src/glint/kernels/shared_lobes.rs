//! A weighted set of slope Gaussians of one shape, held inline: what a procedural glint patch of a
//! Beckmann surface serves (its facet lobes share one width per footprint, src/glint/procedural/
//! patch.rs), with the terms of the few-lobe sets (src/glint/kernels/lobe_set.rs, \[Chermain2019\]
//! eq. 9-17) over lobes that differ only in their means:
//!
//! - D(m) = Σ w_i D_i(m) over the lobes whose slope box (the shape's half-widths around each mean)
//!   holds m's slope: the Mahalanobis distance in `f64` through the shared inverse factor, the
//!   exponential inline (`exp_neg_half`), the shared peak and Jacobian applied once;
//! - A(w) = max(cos θ − w_xy·μ, 0), μ = Σ w_i μ_i;
//! - V(w) = Σ w_i V_i(w), by the lobe sets' own pass ([`lobe_areas`]: the signed areas alone where
//!   every lobe is more than `FRONT_T` spreads in front of w, tested exactly since the shared shape
//!   has one spread toward w, else the ramp over lanes);
//! - `sample_normal`: a lobe ∝ w_i, then its slope Gaussian; `sample_visible`: a lobe
//!   ∝ w_i V_i(wo), then its visible normal; their densities Σ w_i D_i cos θ_m and
//!   ⟨wo, m⟩⁺ D / V(wo).
//!
//! One lobe of another shape may close the set (a patch's limit lobe, blended in as the footprint
//! grows): it is the last lobe, with its own factor and slope box.
//!
//! The lobes live in the patch itself (three arrays of [`SharedLobes::CAPACITY`] floats): no
//! scratch buffer is lent, nothing is allocated. A set of one lobe answers every query as that lobe
//! does.

use super::lanes::exp_neg_half;
use super::lobe_set::{
    FRONT_T, box_half_widths, lobe_areas, pdf_normal_of, pdf_visible_of, pick, visible_over_cos_of,
};
use super::prepared_view::PreparedView;
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Vec2, Vec3};

/// A weighted set of slope Gaussians of one shape and different means (module docs).
#[derive(Clone, Debug)]
pub(crate) struct SharedLobes {
    n: usize,
    w: [f32; SharedLobes::CAPACITY],
    mx: [f32; SharedLobes::CAPACITY],
    my: [f32; SharedLobes::CAPACITY],
    /// The lobes' shape: a centred slope Gaussian.
    shape: SlopeGaussian,
    /// The half-widths of every lobe's slope box.
    half: Vec2,
    /// The last lobe when it has its own shape, with its slope box's half-widths (the box of
    /// `LobeSet::push`).
    other: Option<(SlopeGaussian, Vec2)>,
    /// The mean slope Σ w_i μ_i of the current weights.
    mean: Vec2,
    /// V(wo) at the prepared view ([`SharedLobes::prepare_view`]), and each lobe's w_i V_i(wo)
    /// there (the visible sampler's pick weights, whose sum is V(wo)) for a set of at most
    /// [`SharedLobes::PREPARED`] lobes.
    view: PreparedView,
    view_lobes: [f32; SharedLobes::PREPARED],
}

impl SharedLobes {
    /// The most lobes a set holds: a procedural patch's two lattice levels of at most 4 × 4 cells.
    pub const CAPACITY: usize = 32;

    /// The most lobes whose pick weights a prepared set keeps (a patch holds 4-8 lobes, at most 16
    /// over random footprints; a larger set recomputes them per draw): the set stays small enough
    /// that a patch holding it moves as cheaply as any other glint patch.
    pub const PREPARED: usize = 16;

    /// An empty set of lobes of shape `shape` (its mean is ignored) with slope boxes of half-widths
    /// `half` around each mean.
    pub fn new(shape: SlopeGaussian, half: Vec2) -> Self {
        SharedLobes {
            n: 0,
            w: [0.0; Self::CAPACITY],
            mx: [0.0; Self::CAPACITY],
            my: [0.0; Self::CAPACITY],
            shape: shape.with_mean(Vec2::ZERO).unwrap_or(shape),
            half,
            other: None,
            mean: Vec2::ZERO,
            view: PreparedView::NONE,
            view_lobes: [0.0; Self::PREPARED],
        }
    }

    /// Adds a lobe of weight `w` at mean slope `mean`; ignored unless `w` is positive and finite,
    /// the mean within the slope range of a `SlopeGaussian` and the set not full.
    pub fn push(&mut self, w: f32, mean: Vec2) {
        if self.shape.with_mean(mean).is_some() && self.other.is_none() {
            self.push_entry(w, mean);
        }
    }

    /// Closes the set with lobe `g` of its own shape and weight `w` (ignored unless `w` is
    /// positive and finite and the set not full); its slope box holds 1 − `BOX_TAIL` of it, as
    /// `LobeSet::push` makes it. No lobe can be added after it.
    pub fn push_other(&mut self, w: f32, g: SlopeGaussian) {
        if self.other.is_none() && self.push_entry(w, g.mean()) {
            self.other = Some((g, box_half_widths(&g)));
        }
    }

    /// Adds a lobe's weight and mean if `w` is positive and finite and the set not full.
    fn push_entry(&mut self, w: f32, mean: Vec2) -> bool {
        let ok = w > 0.0 && w.is_finite() && self.n < Self::CAPACITY;
        if ok {
            let i = self.n;
            (self.w[i], self.mx[i], self.my[i]) = (w, mean.x, mean.y);
            self.mean += w * mean;
            self.n += 1;
            self.view = PreparedView::NONE;
        }
        ok
    }

    /// The number of lobes of the shared shape (all but the closing one).
    #[inline]
    fn n_shared(&self) -> usize {
        self.n - self.other.is_some() as usize
    }

    /// Scales the weights to sum to 1 (an empty set stays empty).
    pub fn normalise(&mut self) {
        self.view = PreparedView::NONE;
        let sum: f32 = self.w[..self.n].iter().sum();
        if sum > 0.0 {
            for w in &mut self.w[..self.n] {
                *w /= sum;
            }
        }
        self.mean = (0..self.n)
            .map(|i| self.w[i] * Vec2::new(self.mx[i], self.my[i]))
            .sum();
    }

    /// Number of lobes.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Lobe i (i < n): the shape at the i-th mean.
    #[inline]
    fn lobe(&self, i: usize) -> SlopeGaussian {
        if let (Some((g, _)), true) = (self.other, i + 1 == self.n) {
            return g;
        }
        let mean = Vec2::new(self.mx[i], self.my[i]);
        // The mean was checked by `push`.
        self.shape.with_mean(mean).unwrap_or(self.shape)
    }

    /// (weight, lobe) pairs.
    pub fn iter_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        (0..self.n).map(|i| (self.w[i], self.lobe(i)))
    }

    /// The lobe itself when the set is one lobe (every query then delegates to it, bit for bit).
    #[inline]
    fn single(&self) -> Option<SlopeGaussian> {
        (self.n == 1).then(|| self.lobe(0))
    }

    /// `f(i, w_i V_i(w))` for every lobe in order, for a usable w ([`lobe_areas`]).
    // The loops index four arrays in step (an iterator over one of them measured 0.2 % slower in
    // the render example's frame).
    #[allow(clippy::needless_range_loop)]
    fn for_each_lobe_area(&self, w: Vec3, mut f: impl FnMut(usize, f32)) {
        let (wx, wy, wz) = (w.x as f64, w.y as f64, w.z as f64);
        // Every lobe of the shared shape has the same spread toward w; the closing lobe its own.
        let s_shared = self.shape.area_and_spread(w).1;
        let s_other = self.other.map_or(0.0, |(g, _)| g.area_and_spread(w).1);
        let n_shared = self.n_shared();
        // A_s = w_z − μ·w_xy as `SlopeGaussian::area_and_spread` forms it, from the stored means;
        // every lobe more than `FRONT_T` spreads in front of w (exact: one spread for all lobes).
        let mut a = [0.0f64; Self::CAPACITY];
        let mut front = true;
        for i in 0..self.n {
            a[i] = wz - (self.mx[i] as f64 * wx + self.my[i] as f64 * wy);
            let s = if i < n_shared { s_shared } else { s_other };
            front &= a[i] > FRONT_T * s;
        }
        if front {
            for i in 0..self.n {
                f(i, self.w[i] * a[i] as f32);
            }
            return;
        }
        let terms = |i: usize| {
            let s = if i < n_shared { s_shared } else { s_other };
            (self.w[i], a[i], s)
        };
        lobe_areas(self.n, terms, |i| self.lobe(i).visible_area(w), false, f);
    }

    /// V(w) = Σ w_i V_i(w), summed in lobe order from +0 (as the prepared view's).
    fn lobe_area_sum(&self, w: Vec3) -> f32 {
        let mut v = 0.0f32;
        self.for_each_lobe_area(w, |_, x| v += x);
        v
    }

    /// Prepares the set for the view direction `wo`: V(wo), computed once and read by the queries
    /// at that wo (the same bits); every value is the unprepared set's, bit for bit.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view = PreparedView::NONE;
        if self.n > 1 && wo.z > 0.0 && wo.is_finite() {
            // The terms and their sum as `visible_area` forms them (`lobe_area_sum`).
            let mut lobes = [0.0f32; Self::PREPARED];
            let mut v = 0.0f32;
            self.for_each_lobe_area(wo, |i, x| {
                if let Some(l) = lobes.get_mut(i) {
                    *l = x;
                }
                v += x;
            });
            let v = if v.is_finite() { v } else { 0.0 };
            self.view = PreparedView::new(wo, v as f64);
            self.view_lobes = lobes;
        }
    }
}

impl Ndf for SharedLobes {
    fn d(&self, m: Vec3) -> f32 {
        if let Some(g) = self.single() {
            return g.d(m);
        }
        let Some(s) = crate::frame::normal_to_slope(m) else {
            return 0.0;
        };
        // The slope and the Jacobian (1 + |ñ|²)² in `f64`, as `SlopeGaussian::d` forms them; each
        // lobe's exponent through the shared factor, its exponential inline (< 10⁻⁶ relative).
        let (sx, sy) = (-(m.x as f64) / m.z as f64, -(m.y as f64) / m.z as f64);
        let (lo, hi) = (s - self.half, s + self.half);
        let peak = self.shape.mahalanobis2_and_peak_f64(0.0, 0.0).1;
        let mut sum = 0.0f64;
        for i in 0..self.n_shared() {
            let (mx, my) = (self.mx[i], self.my[i]);
            // s within [μ − half, μ + half], tested as μ within [s − half, s + half].
            if mx >= lo.x && mx <= hi.x && my >= lo.y && my <= hi.y {
                let (q, _) = self
                    .shape
                    .mahalanobis2_and_peak_f64(sx - mx as f64, sy - my as f64);
                sum += self.w[i] as f64 * exp_neg_half(q) as f64;
            }
        }
        let mut d = peak * sum;
        if let Some((g, h)) = &self.other {
            let (m, i) = (g.mean(), self.n - 1);
            if (s.x - m.x).abs() <= h.x && (s.y - m.y).abs() <= h.y {
                let (q, p) = g.mahalanobis2_and_peak_f64(sx, sy);
                d += self.w[i] as f64 * p * exp_neg_half(q) as f64;
            }
        }
        let j = 1.0 + sx * sx + sy * sy;
        // Beyond `f32::MAX` clamped to it, as each lobe's D is.
        (d * j * j).min(f32::MAX as f64) as f32
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
        let mu = self.mean;
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
        let v = self.lobe_area_sum(w);
        if v.is_finite() { v } else { 0.0 }
    }

    /// V(wo): the prepared value at the prepared view, else one pass.
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        self.view.get_or(wo, || self.visible_area(wo) as f64) as f32
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        if let Some(g) = self.single() {
            return g.sample_normal(u);
        }
        match pick(&self.w[..self.n], u.x) {
            Some((i, ux)) => self.lobe(i).sample_normal(Vec2::new(ux, u.y)),
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
        // The pick weights w_i V_i(wo), the terms of V(wo): the prepared ones at the prepared view,
        // else on the stack.
        let mut p = [0.0f32; Self::CAPACITY];
        let p = if self.view.is(wo) && self.n <= Self::PREPARED {
            &self.view_lobes[..]
        } else {
            self.for_each_lobe_area(wo, |i, x| p[i] = x);
            &p[..]
        };
        match pick(&p[..self.n], u.x) {
            Some((i, ux)) => self.lobe(i).sample_visible(wo, Vec2::new(ux, u.y)),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::kernels::lobe_set::LobeSet;
    use glam::Mat2;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    }

    /// The same lobes as a shared-shape set and as a general lobe set.
    fn sets(closed: bool) -> (SharedLobes, LobeSet) {
        let shape = SlopeGaussian::new(
            Vec2::ZERO,
            Mat2::from_diagonal(Vec2::new(0.03 * 0.03, 0.05 * 0.05)),
        )
        .unwrap();
        let half = box_half_widths(&shape);
        let mut shared = SharedLobes::new(shape, half);
        let mut general = LobeSet::default();
        for k in 0..11 {
            let mean = Vec2::new(
                0.07 * (k as f32 - 5.0),
                0.4 * (((k * 7) % 11) as f32 / 11.0 - 0.5),
            );
            let w = 0.2 + 0.1 * ((k * 3) % 5) as f32;
            shared.push(w, mean);
            general.push_with_half_widths(w, shape.with_mean(mean).unwrap(), half);
        }
        if closed {
            let limit = SlopeGaussian::beckmann(0.3, 0.2).unwrap();
            shared.push_other(0.4, limit);
            general.push(0.4, limit);
        }
        shared.normalise();
        general.normalise();
        (shared, general)
    }

    /// Every term of the shared-shape set is the general lobe set's over the same lobes (with and
    /// without a closing lobe of its own shape): D to 10⁻⁶, V and the densities to 10⁻⁶ (the same
    /// pass), at views up to 89.5°; the samplers draw the same normals.
    #[test]
    fn terms_are_the_lobe_sets() {
        for closed in [false, true] {
            terms_match(closed);
        }
    }

    fn terms_match(closed: bool) {
        let (shared, general) = sets(closed);
        assert_eq!(shared.len(), 11 + closed as usize);
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * b.abs().max(1e-30);
        for (t, p) in [
            (0.0, 0.0),
            (30.0, 10.0),
            (60.0, 100.0),
            (80.0, 190.0),
            (89.5, 300.0),
        ] {
            let wo = dir(t, p);
            assert!(close(shared.visible_area(wo), general.visible_area(wo)));
            assert!(close(shared.projected_area(wo), general.projected_area(wo)));
            for k in 0..300 {
                let m = dir(40.0 * (k as f32 / 300.0), 37.0 * k as f32);
                assert!(
                    close(shared.d(m), general.d(m)),
                    "D at {m}: {} against {}",
                    shared.d(m),
                    general.d(m)
                );
                assert!(close(shared.pdf_visible(wo, m), general.pdf_visible(wo, m)));
            }
            for k in 0..64 {
                let u = Vec2::new((k as f32 + 0.5) / 64.0, (k * 29 % 64) as f32 / 64.0);
                assert_eq!(shared.sample_visible(wo, u), general.sample_visible(wo, u));
                assert_eq!(shared.sample_normal(u), general.sample_normal(u));
            }
        }
    }

    /// A prepared set answers as the unprepared one, bit for bit, at the prepared view and at
    /// another; a change of the set forgets the view.
    #[test]
    fn prepared_set_answers_as_the_unprepared_one() {
        let (plain, _) = sets(true);
        let mut prepared = plain.clone();
        let wo = dir(70.0, 40.0);
        prepared.prepare_view(wo);
        for w in [wo, dir(20.0, 250.0)] {
            assert_eq!(prepared.view_visible_area(w), plain.view_visible_area(w));
            for k in 0..64 {
                let u = Vec2::new((k as f32 + 0.5) / 64.0, (k * 29 % 64) as f32 / 64.0);
                let m = plain.sample_visible(w, u);
                assert_eq!(prepared.sample_visible(w, u), m);
                assert_eq!(prepared.pdf_visible(w, m), plain.pdf_visible(w, m));
            }
        }
        let mut open = sets(false).0;
        open.prepare_view(wo);
        open.push(0.1, Vec2::new(0.2, 0.0));
        assert!(!open.view.is(wo));
        // A closed set takes no more lobes.
        prepared.push(0.1, Vec2::new(0.2, 0.0));
        assert_eq!(prepared.len(), 12);
    }

    /// A full set refuses more lobes; weights that are not positive and finite, and means out of
    /// range, are ignored.
    #[test]
    fn push_keeps_the_set_valid() {
        let shape = SlopeGaussian::beckmann(0.1, 0.1).unwrap();
        let mut s = SharedLobes::new(shape, box_half_widths(&shape));
        for w in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            s.push(w, Vec2::ZERO);
        }
        s.push(1.0, Vec2::splat(1e30));
        assert_eq!(s.len(), 0);
        for _ in 0..SharedLobes::CAPACITY + 5 {
            s.push(1.0, Vec2::ZERO);
        }
        assert_eq!(s.len(), SharedLobes::CAPACITY);
    }
}
