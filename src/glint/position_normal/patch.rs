//! The patch of a footprint: the closed-form position-normal P-NDF of \[Yan2016\] §5, evaluated
//! through the slope-box quadtree, exact (or moment-bounded) masking terms, and exact samplers.
//!
//! Per-footprint work (done once when the patch is built): the level of detail (the filtered
//! mixture, filtered.rs, where the options serve it: then nothing else), else the footprint's
//! geometry (geometry.rs), the rectangle of elements that can be within `weight_sigmas` of the
//! footprint, their total weight and the P-NDF's first and second slope moments, and the kept
//! elements' weights and lobes (the samplers', masking's and densities'). The exact V(wo) is
//! computed once for the view the patch is prepared for ([`PositionNormalPatch::prepare_view`]).

use super::build::slope_box;
use super::filtered::footprint_in_elements;
use super::geometry::{Geometry, segments};
use super::{PatchOptions, PositionNormalMap, SIGMA_H_PER_SPACING};
use crate::frame::normal_to_slope;
use crate::glint::Footprint;
use crate::glint::GlintScratch;
use crate::glint::kernels::cdf::{invert_cdf, pick_streaming};
use crate::glint::kernels::cut::CutStats;
use crate::glint::kernels::lobe_set::{Few, LobeSet};
use crate::glint::kernels::prepared_view::PreparedView;
use crate::glint::kernels::slope_tree::contains;
use crate::glint::scratch::Lent;
use crate::math::finite_or_zero;
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};

mod form;

/// The per-element lobes of a patch, for the samplers and the untruncated densities; also the
/// position-normal part of [`GlintScratch`] (only its capacity is kept between patches).
#[derive(Clone, Debug, Default)]
pub(crate) struct Slots {
    /// Normalised weights W_i (sum 1).
    weights: Vec<f64>,
    /// Cumulative weights (last = Σ weights).
    cdf: Vec<f64>,
    lobes: Vec<SlopeGaussian>,
    /// Per element of the footprint's rectangle (row-major, unwrapped coordinates), its slot
    /// (index into `weights` and `lobes`), or `u32::MAX` where the element is not kept: so that D,
    /// which walks the elements by slope box, sums the same lobes as the densities.
    index: Vec<u32>,
}

/// The position-normal P-NDF of one footprint of a [`PositionNormalMap`]: an [`Ndf`].
///
/// For the Gaussian footprint k_P(u) = N(u; c, Σ_P) (texels, [`Footprint::gaussian_texels`], clamped
/// to the query cap), element i contributes the closed-form integral over positions
///
/// ∫ k_P(u) N(u; u_i, σ_h² I) N(ñ; ñ_i + J_i (u − u_i), σ_r² I) du = w_i · N(ñ; μ_i, C_i),
///
/// with w_i = N(u_i; c, Σ_eff), Σ_eff = Σ_P + σ_h² I, μ_i = ñ_i + J_i σ_h² Σ_eff⁻¹ (c − u_i) and
/// C_i = J_i Σ_u J_iᵀ + σ_r² I, Σ_u = (Σ_P⁻¹ + σ_h⁻² I)⁻¹ (completing the square in u). The P-NDF is
/// the slope density P(ñ) = Σ W_i N(ñ; μ_i, C_i) with W_i = w_i / Σ_j w_j (normalised by the total
/// footprint weight of the kept elements), in the crate's convention D_P(m) = P(ñ(m)) / cos⁴θ_m, so
/// ∫ D_P cos θ dω = 1 up to the slope truncation.
///
/// - `d`: the sum over the elements whose slope box contains ñ(m), through the quadtree; elements
///   outside the ellipse of Mahalanobis radius `weight_sigmas` (under Σ_eff) are left out everywhere.
/// - Masking (`lambda`, `projected_area`, `visible_area`): A(w) = max(cos θ − w_xy·μ_P, 0) from the
///   P-NDF's mean slope (exact), V(w) = Σ W_i V_i(w) exactly for patches of at most
///   [`EXACT_MASKING_ELEMENTS`] elements and Scarf's upper bound from the P-NDF's first two slope
///   moments above, Λ = V/A − 1: the mixture's exact construction (\[Chermain2019\] eq. 13-17), so
///   `MicrofacetBrdf` over the patch conserves energy. The published BRDF
///   ([`super::PositionNormalBrdf`]) uses a fixed Beckmann lobe instead.
/// - Samplers: `sample_normal` draws an element ∝ W_i then its slope Gaussian N(μ_i, C_i) (the
///   element's slope marginal under the footprint), exactly `pdf_normal`; `sample_visible` draws an
///   element ∝ W_i V_i(wo) then its visible normal, exactly `pdf_visible`. Both densities sum every
///   kept element (no slope truncation), O(elements in the footprint).
///
/// **Level of detail.** A footprint of at least `filtered_area` elements whose level meets
/// `filtered_tolerance` ([`PatchOptions`](super::PatchOptions)) is served by the filtered mixture
/// instead (src/glint/position_normal/filtered.rs): at most 32 slope Gaussians, every term exact
/// over them (src/glint/kernels/lobe_set.rs), O(1) per query; [`PositionNormalPatch::is_filtered_mixture`]
/// tells which. Elsewhere a footprint of at least `cut_area` elements is served by a cut of the same
/// hierarchy (src/glint/kernels/cut.rs): at most `cut_nodes` nodes of 4 lobes, chosen by their
/// stored residuals; [`PositionNormalPatch::cut`] tells which.
///
/// # Reference
/// \[Yan2016\] §5 (P-NDF of a Gaussian footprint, truncation, hierarchy).
#[derive(Clone, Debug)]
pub struct PositionNormalPatch<'a> {
    map: &'a PositionNormalMap,
    geo: Geometry,
    rect: [[i64; 2]; 2],
    /// Number of kept elements.
    count: usize,
    mean_slope: Vec2,
    moments: [f32; 5],
    moments_lobe: SlopeGaussian,
    /// Every kept element's weight and lobe (masking, samplers, densities), built with the patch in
    /// buffers lent by the caller's scratch if any; empty when a few-lobe set serves.
    /// The elements' lobes; `None` where the filtered mixture serves (no buffers taken).
    slots: Option<Lent<'a, Slots>>,
    /// The filtered mixture or a cut when one serves the footprint ([`Few::None`] for the element
    /// sum).
    few: Few<'a>,
    /// What the cut did, when a cut serves the patch.
    cut: Option<CutStats>,
    /// The filtered mixture's measured TV at the footprint's level, when it serves the patch.
    few_error: f32,
    /// The exact V(wo) at the view the patch was prepared for ([`PositionNormalPatch::prepare_view`];
    /// read by `view_visible_area`, `pdf_visible` and `sample_visible` at that wo).
    view: PreparedView,
}

/// Largest patch (number of elements kept) whose masking terms use the exact V(w) = Σ W_i V_i(w);
/// larger patches use Scarf's moment bound (O(1) per direction instead of O(elements)). 4096: a
/// footprint of 4096 texels at one element per texel.
pub const EXACT_MASKING_ELEMENTS: usize = 4096;

impl<'a> PositionNormalPatch<'a> {
    /// The P-NDF of `footprint` (see the type's docs) at the level of detail of `options`, with
    /// its buffers lent by `scratch` if any. Total: any footprint works; cost O(1) where the
    /// filtered mixture serves, else O(elements within `weight_sigmas` of the capped footprint). No
    /// allocation with a warmed scratch (the samplers' buffers are built on first use).
    pub(super) fn new(
        map: &'a PositionNormalMap,
        footprint: &Footprint,
        options: &PatchOptions,
        scratch: Option<&'a GlintScratch>,
    ) -> PositionNormalPatch<'a> {
        let (c, area) = footprint_in_elements(map, footprint);
        if area >= options.filtered_area as f64 {
            let mut set: Lent<'a, LobeSet> = Lent::new(scratch.map(|s| s.home()));
            if let Some(error) = map.filtered_mixture(c, area, options, &mut set) {
                return Self::filtered(map, footprint, set, None, error);
            }
        }
        // NaN options compare false: no cut.
        if options.cut_nodes > 0 && area >= options.cut_area as f64 {
            let mut set: Lent<'a, LobeSet> = Lent::new(scratch.map(|s| s.home()));
            let stats = map.cut(footprint, options, &mut set);
            if set.len() > 0 {
                let error = stats.max_error;
                return Self::filtered(map, footprint, set, Some(stats), error);
            }
        }
        Self::build(
            map,
            Geometry::new(map, footprint, options.max_query_texels),
            scratch,
        )
    }

    /// The patch served by the few-lobe `set` (the filtered mixture, or the cut `cut` did): its
    /// moments from the lobes, no elements.
    fn filtered(
        map: &'a PositionNormalMap,
        footprint: &Footprint,
        set: Lent<'a, LobeSet>,
        cut: Option<CutStats>,
        few_error: f32,
    ) -> Self {
        let mut acc = [0.0f64; 5];
        for (w, g) in set.iter() {
            let (m, c) = (g.mean(), g.covariance());
            let (w, mx, my) = (w as f64, m.x as f64, m.y as f64);
            acc[0] += w * mx;
            acc[1] += w * my;
            acc[2] += w * (c.x_axis.x as f64 + mx * mx);
            acc[3] += w * (c.y_axis.y as f64 + my * my);
            acc[4] += w * (c.x_axis.y as f64 + mx * my);
        }
        let moments = acc.map(|v| v as f32);
        PositionNormalPatch {
            map,
            geo: Geometry::new(map, footprint, f32::INFINITY),
            rect: [[0, -1], [0, -1]],
            count: 0,
            mean_slope: Vec2::new(moments[0], moments[1]),
            moments,
            moments_lobe: SlopeGaussian::from_moments(moments, map.params.sigma_r),
            slots: None,
            few: Few::Set(set),
            cut,
            few_error,
            view: PreparedView::NONE,
        }
    }

    /// Prepares the patch for the view direction `wo` (shading frame): the exact V(wo) that the
    /// queries at that wo share (`view_visible_area`, `pdf_visible`, `sample_visible`), computed
    /// here once, an O(elements) pass. Queries at `wo` (the same bits) then read it; queries at any
    /// other view compute their own. Every value is the one the unprepared patch returns, bit for
    /// bit. A second call replaces the first view. `Material::bsdf` prepares its glint patches for
    /// the shading point's wo.
    pub fn prepare_view(&mut self, wo: Vec3) {
        self.view = PreparedView::NONE;
        if wo.z > 0.0 && wo.is_finite() {
            self.view = PreparedView::new(wo, self.exact_visible_area(wo));
        }
    }

    /// Whether the filtered mixture serves the patch (module docs of
    /// src/glint/position_normal/filtered.rs); else a cut of its hierarchy ([`Self::cut`]) or the
    /// element sum.
    pub fn is_filtered_mixture(&self) -> bool {
        self.few_serves() && self.cut.is_none()
    }

    /// What the cut of the filtered-mixture hierarchy did when one serves the patch
    /// ([`PatchOptions::cut_nodes`](super::PatchOptions::cut_nodes), src/glint/kernels/cut.rs).
    pub fn cut(&self) -> Option<CutStats> {
        self.cut
    }

    /// Whether a few-lobe set (the filtered mixture or a cut) serves the patch.
    fn few_serves(&self) -> bool {
        !matches!(self.few, Few::None)
    }

    fn build(
        map: &'a PositionNormalMap,
        geo: Geometry,
        scratch: Option<&'a GlintScratch>,
    ) -> PositionNormalPatch<'a> {
        let rect = [geo.range(0), geo.range(1)];
        let mut total = 0.0f64;
        let mut count = 0usize;
        let mut acc = [0.0f64; 5];
        // One pass: the totals and moments, and every kept element's weight and lobe (normalised
        // below) for the masking terms, the samplers and the densities.
        let mut slots = Lent::new(scratch.map(|s| s.home::<Slots>()));
        let Slots {
            weights,
            cdf,
            lobes,
            index,
        } = &mut *slots;
        weights.clear();
        lobes.clear();
        cdf.clear();
        index.clear();
        let rect_width = (rect[0][1] - rect[0][0] + 1).max(0) as usize;
        let rect_height = (rect[1][1] - rect[1][0] + 1).max(0) as usize;
        index.resize(rect_width * rect_height, u32::MAX);
        let sigma_r = map.params.sigma_r;
        Self::for_each_kept(map, &geo, rect, |at, w, mean, cov| {
            index[at] = weights.len() as u32;
            total += w;
            count += 1;
            acc[0] += w * mean[0];
            acc[1] += w * mean[1];
            acc[2] += w * (cov[0] + mean[0] * mean[0]);
            acc[3] += w * (cov[2] + mean[1] * mean[1]);
            acc[4] += w * (cov[1] + mean[0] * mean[1]);
            weights.push(w);
            lobes.push(lobe_of(mean, cov, sigma_r));
        });
        // total ≥ the nearest element's weight ≥ e^{−1.39} (weight_sigmas ≥ 2 keeps it).
        let inv_total = if total > 0.0 { 1.0 / total } else { 0.0 };
        let mut sum = 0.0;
        for w in weights.iter_mut() {
            *w *= inv_total;
            sum += *w;
            cdf.push(sum);
        }
        let moments = acc.map(|v| (v * inv_total) as f32);
        let moments_lobe = SlopeGaussian::from_moments(moments, map.params.sigma_r);
        PositionNormalPatch {
            map,
            geo,
            rect,
            count,
            mean_slope: Vec2::new(moments[0], moments[1]),
            moments,
            moments_lobe,
            slots: Some(slots),
            few: Few::None,
            cut: None,
            few_error: 0.0,
            view: PreparedView::NONE,
        }
    }

    /// Calls `f(w, mean, cov)` for every kept element of the rectangle, in a fixed order.
    fn for_each_kept(
        map: &PositionNormalMap,
        geo: &Geometry,
        rect: [[i64; 2]; 2],
        mut f: impl FnMut(usize, f64, [f64; 2], [f64; 3]),
    ) {
        let [nx, ny] = map.grid;
        let mut at = 0;
        for j in rect[1][0]..=rect[1][1] {
            let jw = j.rem_euclid(ny as i64) as usize;
            for i in rect[0][0]..=rect[0][1] {
                let here = at;
                at += 1;
                let Some((w, d)) = geo.weight(i, j) else {
                    continue;
                };
                let iw = i.rem_euclid(nx as i64) as usize;
                let (mean, cov) = geo.lobe(&map.elements[jw * nx + iw], d);
                f(here, w, mean, cov);
            }
        }
    }

    /// The level of detail the query cap applied: the footprint's standard deviation along its major
    /// axis after the cap over before (1 when the cap did not bite; `k_w σ ≤ max_query_texels`).
    pub fn query_scale(&self) -> f32 {
        self.geo.query_scale as f32
    }

    /// Number of elements kept in the footprint (inside the weight ellipse); 0 where the filtered
    /// mixture serves.
    pub fn element_count(&self) -> usize {
        self.count
    }

    /// The P-NDF's mean slope Σ W_i μ_i.
    pub fn mean_slope(&self) -> Vec2 {
        self.mean_slope
    }

    /// The P-NDF's slope moments `[E[x̃], E[ỹ], E[x̃²], E[ỹ²], E[x̃ỹ]]` (exact for the kept elements).
    pub fn moments(&self) -> [f32; 5] {
        self.moments
    }

    /// The moments lobe: the non-centred Beckmann lobe with the P-NDF's mean and covariance (variances
    /// floored at σ_r²), whose Smith terms the patch reports.
    pub fn moments_lobe(&self) -> &SlopeGaussian {
        &self.moments_lobe
    }

    /// The normalised weights W_i and slope Gaussians N(μ_i, C_i) of the kept elements, or the
    /// filtered mixture's lobes where it serves.
    pub fn weighted_lobes(&self) -> impl Iterator<Item = (f32, SlopeGaussian)> + Clone + '_ {
        let few = self.few.iter_lobes();
        let slots = (!self.few_serves()).then(|| self.slots());
        few.chain(
            slots
                .into_iter()
                .flat_map(|s| s.weights.iter().zip(&s.lobes).map(|(&w, &l)| (w as f32, l))),
        )
    }

    fn slots(&self) -> &Slots {
        static EMPTY: Slots = Slots {
            weights: Vec::new(),
            cdf: Vec::new(),
            lobes: Vec::new(),
            index: Vec::new(),
        };
        self.slots.as_deref().unwrap_or(&EMPTY)
    }

    /// D_P(m) and the number of elements whose contribution was evaluated.
    ///
    /// # Reference
    /// \[Yan2016\] §5.
    pub fn d_with_stats(&self, m: Vec3) -> (f32, usize) {
        if let Few::Set(set) = &self.few {
            return (set.d(m), set.len());
        }
        let Some(s) = normal_to_slope(m) else {
            return (0.0, 0);
        };
        if !s.is_finite() {
            return (0.0, 0);
        }
        // The slope in `f64` from the `f32` normal (as the densities form it), the `f32` slope
        // only for the slope-box tests of the walk.
        let sd = [-(m.x as f64) / m.z as f64, -(m.y as f64) / m.z as f64];
        let (p, touched) = self.sum_p(s, sd);
        let c = 1.0 + sd[0] * sd[0] + sd[1] * sd[1];
        let d = (p * c * c) as f32;
        (if d.is_finite() { d } else { f32::MAX }, touched)
    }

    /// Σ W_i P22_i(ñ) over the kept elements whose slope box contains ñ (`s` the slope in `f32` for
    /// the box tests, `sd` in `f64` for the lobes), by a depth-first walk of the quadtree restricted
    /// to each (x segment × y segment) of the rectangle; W_i and P22_i are the slot's normalised
    /// weight and `f32` lobe, the terms the densities sum.
    fn sum_p(&self, s: Vec2, sd: [f64; 2]) -> (f64, usize) {
        let map = self.map;
        let tree = &map.tree;
        let [nx, ny] = map.grid;
        let sigma_h = SIGMA_H_PER_SPACING * map.spacing;
        let (rect, slots) = (self.rect, self.slots());
        let width = (rect[0][1] - rect[0][0] + 1).max(0) as usize;
        let mut acc = 0.0f64;
        let mut touched = 0usize;
        for (x_lo, x_hi, x_off) in segments(self.rect[0], nx) {
            for (y_lo, y_hi, y_off) in segments(self.rect[1], ny) {
                // Segments are inclusive; the walk takes half-open ranges.
                tree.for_each_leaf((x_lo, x_hi + 1), (y_lo, y_hi + 1), s, |x, y| {
                    let e = &map.elements[y * nx + x];
                    if !contains(&slope_box(e, sigma_h, &map.params), s) {
                        return;
                    }
                    let (i, j) = (x as i64 + x_off - rect[0][0], y as i64 + y_off - rect[1][0]);
                    let Some(&k) = slots.index.get(j as usize * width + i as usize) else {
                        return;
                    };
                    if k == u32::MAX {
                        return;
                    }
                    touched += 1;
                    let k = k as usize;
                    acc += slots.weights[k] * slots.lobes[k].p22_f64(sd[0], sd[1]);
                });
            }
        }
        (acc, touched)
    }

    /// Σ W_i D_i(m) over every kept element, in `f64`: D_i(m) = P22_i(ñ) (1 + |ñ|²)² with
    /// ñ = −m_xy/m_z, whose Jacobian is common to every element, so each element adds
    /// W_i P22_i(ñ) (one exponential) and the sum is multiplied by the Jacobian once.
    fn untruncated_d(&self, m: Vec3) -> f64 {
        if self.few_serves() {
            return self.few.d(m) as f64;
        }
        if !(m.z > 0.0 && m.is_finite()) {
            return 0.0;
        }
        let (sx, sy) = (-m.x as f64 / m.z as f64, -m.y as f64 / m.z as f64);
        let s = self.slots();
        let sum: f64 = s
            .weights
            .iter()
            .zip(&s.lobes)
            .map(|(&w, lobe)| w * lobe.p22_f64(sx, sy))
            .sum();
        let j = 1.0 + sx * sx + sy * sy;
        sum * j * j
    }

    /// Σ W_i V_i(w) over every kept element (the exact visible area of the P-NDF), in `f64`; over
    /// the filtered mixture's lobes where it serves.
    pub fn visible_area_exact(&self, w: Vec3) -> f32 {
        finite_or_zero(self.exact_visible_area(w))
    }

    /// The exact V(wo) at the view: the prepared value at the prepared wo, else one pass (the same
    /// value as [`Self::exact_visible_area`]).
    fn view_exact_visible_area(&self, wo: Vec3) -> f64 {
        if !(wo.z > 0.0 && wo.is_finite()) {
            return 0.0;
        }
        self.view.get_or(wo, || self.exact_visible_area(wo))
    }

    fn exact_visible_area(&self, w: Vec3) -> f64 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        if self.few_serves() {
            return self.few.visible_area(w) as f64;
        }
        let s = self.slots();
        s.weights
            .iter()
            .zip(&s.lobes)
            .map(|(&wi, lobe)| wi * lobe.visible_area(w) as f64)
            .sum()
    }
}

/// The element lobe as a [`SlopeGaussian`]; the moments fallback (variances floored at σ_r²) if the
/// covariance leaves the `f32` range.
fn lobe_of(mean: [f64; 2], cov: [f64; 3], sigma_r: f32) -> SlopeGaussian {
    let m = Vec2::new(mean[0] as f32, mean[1] as f32);
    let c = Mat2::from_cols(
        Vec2::new(cov[0] as f32, cov[1] as f32),
        Vec2::new(cov[1] as f32, cov[2] as f32),
    );
    SlopeGaussian::new(m, c).unwrap_or_else(|_| {
        SlopeGaussian::from_moments(
            [
                m.x,
                m.y,
                (cov[0] + mean[0] * mean[0]) as f32,
                (cov[2] + mean[1] * mean[1]) as f32,
                (cov[1] + mean[0] * mean[1]) as f32,
            ],
            sigma_r,
        )
    })
}

impl Ndf for PositionNormalPatch<'_> {
    /// D_P(m) = Σ W_i N(ñ(m); μ_i, C_i) / cos⁴θ_m (\[Yan2016\] §5); see [`PositionNormalPatch::d_with_stats`].
    fn d(&self, m: Vec3) -> f32 {
        self.d_with_stats(m).0
    }

    /// Λ = V/A − 1 with V from [`Ndf::visible_area`] (exact, or Scarf's bound for large patches) and A
    /// from the P-NDF's mean slope; 0 for invalid w, `f32::MAX` where A(w) = 0 < w_z.
    fn lambda(&self, w: Vec3) -> f32 {
        if self.few_serves() {
            return self.few.lambda(w);
        }
        crate::ndf::lambda_from_areas(self, w)
    }

    /// A(w) of the moments lobe: max(cos θ − w_xy·μ_P, 0) with μ_P the P-NDF's mean slope.
    fn projected_area(&self, w: Vec3) -> f32 {
        if self.few_serves() {
            return self.few.projected_area(w);
        }
        self.moments_lobe.projected_area(w)
    }

    /// V(w) = ∫⟨w, m⟩⁺ D_P dm: exact ([`PositionNormalPatch::visible_area_exact`], O(elements)) for
    /// patches of at most [`EXACT_MASKING_ELEMENTS`] elements; above, Scarf's bound from the P-NDF's
    /// first two slope moments ([`SlopeGaussian::visible_area_bound`], O(1)), which is ≥ the exact V.
    /// Either way masking never under-shadows and `MicrofacetBrdf` over the patch never gains energy.
    /// The moments lobe's own Gaussian V, used before, could fall below the exact V of a multi-modal
    /// patch (white furnace up to 1.42 at grazing angles on the bumpy map, docs/robustness.md).
    fn visible_area(&self, w: Vec3) -> f32 {
        if self.count <= EXACT_MASKING_ELEMENTS {
            self.visible_area_exact(w)
        } else {
            self.moments_lobe.visible_area_bound(w)
        }
    }

    /// [`Ndf::visible_area`]`(wo)`, the exact V as prepared for the patch's view
    /// ([`PositionNormalPatch::prepare_view`]) at that wo.
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        if self.count <= EXACT_MASKING_ELEMENTS {
            finite_or_zero(self.view_exact_visible_area(wo))
        } else {
            self.moments_lobe.visible_area_bound(wo)
        }
    }

    /// m ~ D_P(m) cos θ_m (untruncated): element ∝ W_i with u.x (rescaled), then its slope Gaussian.
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        if self.few_serves() {
            return self.few.sample_normal(u);
        }
        let s = self.slots();
        if s.lobes.is_empty() {
            return self.moments_lobe.sample_normal(u);
        }
        let (k, ux) = invert_cdf(&s.cdf, u.x);
        s.lobes[k].sample_normal(Vec2::new(ux, u.y))
    }

    /// Σ W_i D_i(m) cos θ_m over every kept element where D_P(m) > 0, else 0: the density of
    /// [`Ndf::sample_normal`] on the support of D_P. The sampler draws each element's whole
    /// Gaussian, D_P leaves out an element beyond its slope box (`slope_sigmas`), so a draw outside
    /// every box (at most 4 Q(k) of the mass for k = `slope_sigmas`, 1.3·10⁻⁴ at the default) has
    /// pdf 0, where D_P is 0 too, and `MicrofacetBrdf::sample` returns `None` for it. Inside the
    /// support the value differs from `d(m) cos θ_m` by at most the truncated tails. O(elements).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        if self.few_serves() {
            return self.few.pdf_normal(m);
        }
        if !(m.z > 0.0 && m.is_finite() && self.d(m) > 0.0) {
            return 0.0;
        }
        let p = self.untruncated_d(m) * m.z as f64;
        let p = p as f32;
        if p.is_finite() { p } else { 0.0 }
    }

    /// m ~ Σ W_i ⟨wo, m⟩⁺ D_i(m) / Σ W_i V_i(wo): element ∝ W_i V_i(wo), then its visible normal.
    /// Invalid wo: [`Ndf::sample_normal`].
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if self.few_serves() {
            return self.few.sample_visible(wo, u);
        }
        let s = self.slots();
        let total = self.view_exact_visible_area(wo);
        if !(total > 0.0 && total.is_finite()) {
            return self.sample_normal(u);
        }
        let (k, r) = pick_streaming(
            u.x,
            total,
            s.lobes
                .iter()
                .enumerate()
                .map(|(k, lobe)| s.weights[k] * lobe.visible_area(wo) as f64),
        );
        s.lobes[k].sample_visible(wo, Vec2::new(r, u.y))
    }

    /// ⟨wo, m⟩ Σ W_i D_i(m) / Σ W_i V_i(wo) over every kept element where D_P(m) > 0, else 0: the
    /// density of [`Ndf::sample_visible`] on the support of D_P (draws outside it as in
    /// [`Ndf::pdf_normal`]). 0 for invalid wo. O(elements).
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        self.pdf_visible_with(wo, m, || self.d(m), false)
    }

    /// [`Ndf::pdf_visible`] with D_P(m) = `d_m` given (the support check uses it).
    fn pdf_visible_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        self.pdf_visible_with(wo, m, || d_m, false)
    }

    /// [`Ndf::pdf_visible_given_d`] without its factor ⟨wo, m⟩ (no underflow at grazing views).
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        self.pdf_visible_with(wo, m, || d_m, true)
    }
}

impl PositionNormalPatch<'_> {
    /// [`Ndf::pdf_visible`], with `d` giving D_P(m) for the support check; without the factor
    /// ⟨wo, m⟩ where `over_cos` ([`Ndf::pdf_visible_over_cos_given_d`]).
    #[inline]
    fn pdf_visible_with(&self, wo: Vec3, m: Vec3, d: impl FnOnce() -> f32, over_cos: bool) -> f32 {
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0 && m.z > 0.0 && wo.is_finite() && m.is_finite()) {
            return 0.0;
        }
        if d() <= 0.0 {
            return 0.0;
        }
        let v = self.view_exact_visible_area(wo);
        if v.is_nan() || v <= 0.0 {
            return 0.0;
        }
        let k = if over_cos { 1.0 } else { c as f64 };
        let p = (k * self.untruncated_d(m) / v) as f32;
        if p.is_finite() { p } else { 0.0 }
    }
}
