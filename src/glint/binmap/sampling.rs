//! The [`Ndf`] implementation of [`BinMapPatch`] (D, Λ, A and V from the patch's terms) and its
//! samplers with their densities: the normal sampler (a point of the footprint, its sub-texel's bin
//! through 𝓑, a direction in the bin or its smoothing lobe) and the visible-normal sampler over the
//! exact-masking bins (bilinear in the cell's corner values) or smoothing lobes.
//!
//! # Reference
//! \[Atanasov2020\] §2.1 (sampling); \[Pharr2023\] §A.4.2, §A.5 (linear and bilinear sampling).

use super::masking::{ExactMasking, PatchBin, bin_lipschitz_radius};
use super::patch::BinMapPatch;
use crate::glint::kernels::cdf::rehash;
use crate::math::finite_or_zero;
use crate::ndf::Ndf;
use crate::warp::{hemisphere_to_square_equal_area, square_to_gaussian_2d};
use glam::{Vec2, Vec3};

/// The visible-normal sampler's floor on each corner value of a bin that may face wo, as a fraction
/// of the bin's proven radius: it keeps the density positive wherever ⟨wo, m⟩ > 0 (also inside a
/// bin whose four corners are below wo's horizon) at the price of a few draws below it.
const VISIBLE_FLOOR: f32 = 0.05;

impl BinMapPatch<'_> {
    /// The point of A at parameters u ∈ [0, 1)², wrapped into the map, and its sub-texel index.
    fn texel_at(&self, u: Vec2) -> usize {
        let p = self.para.point(u.x as f64 - 0.5, u.y as f64 - 0.5);
        let (w, h) = (self.map.grid_w, self.map.grid_h);
        let i = (p[0].floor() as i64).rem_euclid(w as i64) as usize;
        let j = (p[1].floor() as i64).rem_euclid(h as i64) as usize;
        j * w + i
    }

    /// A direction in the texel's bin (or from its smoothing lobe) from the second pair `v`.
    fn direction_for_bin(&self, bin: usize, v: Vec2) -> Vec3 {
        match self.sigma {
            None => {
                // Rounding of the equal-area map can put a draw on the very edge of the cell into
                // the neighbouring bin (~1e-6 of draws): those take the bin's centre instead.
                let m = self.map.bins.sample_in_bin(bin, v);
                if self.map.bins.bin_of(m) == Some(bin) {
                    m
                } else {
                    self.map.bins.center(bin)
                }
            }
            Some(sigma) => {
                let g = square_to_gaussian_2d(v);
                let c = self.map.center_slope[bin];
                let s = c + g * sigma as f32;
                crate::frame::slope_to_normal(s)
            }
        }
    }
}

/// The visible-normal sampler's corner values of one bin toward `wo`: ⟨wo, corner⟩⁺ + ε (ε =
/// [`VISIBLE_FLOOR`] × the bin's proven radius), or `None` when no direction of the bin faces wo
/// (⟨wo, c_j⟩ + radius ≤ 0).
#[inline]
fn corner_values(b: &PatchBin, wo: Vec3, radius: f32) -> Option<[f32; 4]> {
    if wo.dot(b.facet.center) + radius <= 0.0 {
        return None;
    }
    let eps = VISIBLE_FLOOR * radius;
    Some(b.corners.map(|c| wo.dot(c).max(0.0) + eps))
}

/// The bilinear interpolation of corner values v (00, 10, 01, 11) at t ∈ [0, 1]².
#[inline]
fn bilerp(v: &[f32; 4], t: Vec2) -> f32 {
    let bottom = v[0] + (v[1] - v[0]) * t.x;
    let top = v[2] + (v[3] - v[2]) * t.x;
    bottom + (top - bottom) * t.y
}

/// Inverts the CDF of the linear density ∝ (1 − x) a + x b on [0, 1] (a, b ≥ 0, a + b > 0) at u.
///
/// # Reference
/// \[Pharr2023\] pbrt-v4 §A.4.2 (`SampleLinear`), written from the formula x = u (a + b) /
/// (a + √((1 − u) a² + u b²)).
#[inline]
fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + ((1.0 - u) * a * a + u * b * b).sqrt());
    x.clamp(0.0, 1.0 - f32::EPSILON / 2.0)
}

/// A point of [0, 1]² with density bilerp(v, t) / mean(v): the marginal in y, then x given y
/// (\[Pharr2023\] §A.5, `SampleBilinear`).
#[inline]
fn sample_bilinear(u: Vec2, v: &[f32; 4]) -> Vec2 {
    let y = sample_linear(u.y, v[0] + v[1], v[2] + v[3]);
    let x = sample_linear(u.x, v[0] + (v[2] - v[0]) * y, v[1] + (v[3] - v[1]) * y);
    Vec2::new(x, y)
}

impl Ndf for BinMapPatch<'_> {
    /// D(h) = mass_j / (|H| c̄_j) for the bin j ∋ h, or the smoothed Σ_j mass_j D_j(h).
    ///
    /// # Reference
    /// \[Atanasov2020\] §2 (D_A^H), divided by the bin's mean cosine (type docs).
    fn d(&self, m: Vec3) -> f32 {
        finite_or_zero(self.d_f64(m))
    }

    /// Λ(w) = V(w)/A(w) − 1 (exact terms) or the masking lobe's Λ (type docs); `f32::MAX` when
    /// A(w) ≤ 0 < w_z, 0 for invalid w.
    fn lambda(&self, w: Vec3) -> f32 {
        crate::ndf::lambda_from_areas(self, w)
    }

    /// A(w) = max(w · Σ_j mass_j m̄_j / c̄_j, 0) (exact terms) or the masking lobe's
    /// max(cos θ − w_xy·μ, 0).
    fn projected_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        match &self.exact {
            Some(e) => finite_or_zero(w.dot(e.a) as f64),
            None => self.lobe.signed_projected_area(w).max(0.0),
        }
    }

    /// V(w) = Σ_j (mass_j / c̄_j) (1/|H|) ∫_{H_j} ⟨w, m⟩⁺ dω (exact terms, bounded from above for bins
    /// cut by w's horizon) or the masking lobe's V.
    fn visible_area(&self, w: Vec3) -> f32 {
        if !(w.z > 0.0 && w.is_finite()) {
            return 0.0;
        }
        match &self.exact {
            Some(e) => e.visible_area(&self.map.bins, w),
            None => self.moment_bound_visible_area(w),
        }
    }

    /// [`Ndf::visible_area`]`(wo)`, the prepared value at the view the patch was prepared for
    /// ([`BinMapPatch::prepare_view`](super::BinMapPatch::prepare_view)).
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        self.view_area.get_or(wo, || self.visible_area(wo) as f64) as f32
    }

    /// A point of A from `u`, its texel's bin through 𝓑, a direction in the bin (or the bin's
    /// smoothing lobe) from numbers hashed from `u` (type docs).
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let u = Vec2::select(u.is_finite_mask(), u, Vec2::splat(0.5))
            .clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON / 2.0));
        let k = self.texel_at(u);
        let bin = self.map.bin_map.get(k).unwrap_or(0);
        self.direction_for_bin(bin, rehash(u, 0))
    }

    /// The density of [`Ndf::sample_normal`]: mass_j / |H| (unsmoothed) or D(m) cos θ_m (smoothed).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        self.pdf_normal_with(m, None)
    }

    /// [`Ndf::pdf_normal`] with D(m) = `d_m` given: without exact terms the density is formed from
    /// it (D c̄_j = mass_j / |H| unsmoothed, D cos θ_m smoothed), so that D and its density at one
    /// direction cost one forest query (or one window of them), not two.
    fn pdf_normal_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        self.pdf_normal_with(m, Some(d_m))
    }

    /// A normal visible from `wo` (type docs, "Sampling"): for patches with exact masking terms a
    /// bin chosen ∝ s_j ν_j(wo), then a point of its cell with the bilinear density of the corner
    /// values (unsmoothed), or a smoothing lobe chosen ∝ mass_j V_j(wo), then its visible normal
    /// (smoothed); [`Ndf::sample_normal`] for larger footprints or when nothing faces `wo`.
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let u = Vec2::select(u.is_finite_mask(), u, Vec2::splat(0.5))
            .clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON / 2.0));
        match self.visible_total(wo) {
            Some((e, total)) if e.lobes.as_slice().is_empty() => {
                self.sample_visible_bins(e, wo, total, u)
            }
            Some((e, total)) => sample_visible_lobes(e, wo, total, u),
            None => self.sample_normal(u),
        }
    }

    /// The density of [`Ndf::sample_visible`] per unit solid angle of m:
    /// (s_j ν_j / Σ_k s_k ν_k) · bilerp(v_j, t) / (mean(v_j) |H|) for m at cell position t of bin j
    /// (unsmoothed), ⟨wo, m⟩⁺ Σ_j mass_j D_j(m) / Σ_j mass_j V_j(wo) (smoothed), or
    /// [`Ndf::pdf_normal`] where the sampler falls back to it for a valid wo (large footprints,
    /// views nothing faces). 0 for an invalid wo (at or below the horizon, zero, non-finite), as
    /// for every NDF, though the sampler still returns a normal there.
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        self.pdf_visible_with(wo, m, None)
    }

    /// [`Ndf::pdf_visible`] with D_P(m) = `d_m` given (the smoothed support check uses it).
    fn pdf_visible_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        self.pdf_visible_with(wo, m, Some(d_m))
    }
}

impl BinMapPatch<'_> {
    /// [`Ndf::pdf_normal`], with D(m) = `d_m` when the caller has it (`None`: evaluated here where
    /// needed). With exact terms the unsmoothed density reads the listed bins' mass (exact, cheap);
    /// without them it is formed from D: mass_j / |H| = D c̄_j for the bin j ∋ m (to `f32` rounding
    /// of D), D cos θ_m smoothed.
    fn pdf_normal_with(&self, m: Vec3, d_m: Option<f32>) -> f32 {
        if !(m.is_finite() && m.z > 0.0) {
            return 0.0;
        }
        let Some(m) = m.try_normalize() else {
            return 0.0;
        };
        let d_m = d_m.filter(|_| self.exact.is_none());
        match self.sigma {
            None => self.map.bins.bin_of(m).map_or(0.0, |b| match d_m {
                Some(d) => finite_or_zero(d as f64 * self.map.facets[b].mean.z as f64),
                None => finite_or_zero(self.bin_mass(b) / self.map.bins.solid_angle()),
            }),
            Some(_) => {
                let d = d_m.map_or_else(|| self.d_f64(m), f64::from);
                finite_or_zero(d * m.z as f64)
            }
        }
    }

    /// [`Ndf::pdf_visible`], with D_P(m) = `d_m` when the caller has it (the smoothed density's
    /// support check, and the normal density where the sampler falls back to it).
    #[inline]
    fn pdf_visible_with(&self, wo: Vec3, m: Vec3, d_m: Option<f32>) -> f32 {
        if !(wo.is_finite() && wo.z > 0.0) {
            return 0.0;
        }
        match self.visible_total(wo) {
            Some((e, total)) if e.lobes.as_slice().is_empty() => {
                self.pdf_visible_bins(e, wo, total, m)
            }
            // The smoothed D leaves out each lobe beyond its truncation radius (SMOOTH_TAIL), the
            // lobes' own samplers do not: where D is 0 the density is 0 too (a draw there, at most
            // 10⁻⁶ of a lobe's mass, gets pdf 0 and `MicrofacetBrdf::sample` returns `None`).
            Some((e, total)) if d_m.unwrap_or_else(|| self.d(m)) > 0.0 => {
                pdf_visible_lobes(e, wo, total, m)
            }
            Some(_) => 0.0,
            None => self.pdf_normal_with(m, d_m),
        }
    }
}

impl BinMapPatch<'_> {
    /// The exact-masking data and the visible sampler's normalisation Σ_j s_j ν_j(wo) (unsmoothed)
    /// or Σ_j mass_j V_j(wo) (smoothed), when the patch has exact terms, `wo` is a valid upper
    /// direction and the total is positive; `None` otherwise (the samplers fall back to
    /// [`Ndf::sample_normal`]).
    fn visible_total(&self, wo: Vec3) -> Option<(&ExactMasking<'_>, f64)> {
        let e = self.exact.as_ref()?;
        if !(wo.is_finite() && wo.z > 0.0) {
            return None;
        }
        let total = self
            .view_total
            .get_or(wo, || self.visible_total_pass(e, wo));
        (total > 0.0 && total.is_finite()).then_some((e, total))
    }

    /// The pass behind [`Self::visible_total`]: Σ_j s_j ν_j(wo) over the listed bins (unsmoothed)
    /// or Σ_j mass_j V_j(wo) over the smoothing lobes, for a valid upper `wo`.
    pub(super) fn visible_total_pass(&self, e: &ExactMasking<'_>, wo: Vec3) -> f64 {
        if e.lobes.as_slice().is_empty() {
            let radius = bin_lipschitz_radius(&self.map.bins);
            e.bins
                .as_slice()
                .iter()
                .map(|b| bin_visible_weight(b, wo, radius))
                .sum::<f64>()
        } else {
            e.lobes
                .as_slice()
                .iter()
                .map(|(m, lobe)| *m as f64 * lobe.visible_area(wo) as f64)
                .sum::<f64>()
        }
    }

    fn sample_visible_bins(&self, e: &ExactMasking<'_>, wo: Vec3, total: f64, u: Vec2) -> Vec3 {
        let bins = &self.map.bins;
        let radius = bin_lipschitz_radius(bins);
        let target = u.x as f64 * total;
        let mut cum = 0.0;
        let mut chosen = None;
        for b in e.bins.as_slice() {
            let w = bin_visible_weight(b, wo, radius);
            if w <= 0.0 {
                continue;
            }
            chosen = Some((b, cum, w));
            if cum + w > target {
                break;
            }
            cum += w;
        }
        let Some((b, before, w)) = chosen else {
            return self.sample_normal(u);
        };
        let Some(v) = corner_values(b, wo, radius) else {
            return self.sample_normal(u);
        };
        let ux = (((target - before) / w) as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let t = sample_bilinear(Vec2::new(ux, u.y), &v);
        let bin = b.bin as usize;
        let m = bins.sample_in_bin(bin, t);
        // As in `direction_for_bin`: a draw that rounding puts in the neighbouring bin takes the
        // bin's centre.
        if bins.bin_of(m) == Some(bin) {
            m
        } else {
            bins.center(bin)
        }
    }

    fn pdf_visible_bins(&self, e: &ExactMasking<'_>, wo: Vec3, total: f64, m: Vec3) -> f32 {
        if !(m.is_finite() && m.z > 0.0) {
            return 0.0;
        }
        let Some(m) = m.try_normalize() else {
            return 0.0;
        };
        let bins = &self.map.bins;
        let Some(bin) = bins.bin_of(m) else {
            return 0.0;
        };
        let list = e.bins.as_slice();
        let Ok(k) = list.binary_search_by_key(&(bin as u32), |b| b.bin) else {
            return 0.0;
        };
        let b = &list[k];
        let radius = bin_lipschitz_radius(bins);
        let Some(v) = corner_values(b, wo, radius) else {
            return 0.0;
        };
        let n = bins.n() as f32;
        let (i, j) = bins.cell(bin);
        let t = (hemisphere_to_square_equal_area(m) * n - Vec2::new(i as f32, j as f32))
            .clamp(Vec2::ZERO, Vec2::ONE);
        let sum_v = (v[0] + v[1] + v[2] + v[3]) as f64;
        let density = 4.0 * bilerp(&v, t) as f64 / sum_v;
        let choose = bin_visible_weight(b, wo, radius) / total;
        finite_or_zero(choose * density / bins.solid_angle())
    }
}

/// The visible sampler's weight of one bin: s_j ν_j(wo), ν_j = the mean of its corner values (0
/// when no direction of the bin faces wo).
#[inline]
fn bin_visible_weight(b: &PatchBin, wo: Vec3, radius: f32) -> f64 {
    corner_values(b, wo, radius).map_or(0.0, |v| {
        b.scale as f64 * 0.25 * (v[0] + v[1] + v[2] + v[3]) as f64
    })
}

/// The smoothed patch's visible sampler: lobe j with probability mass_j V_j(wo) / total, then its
/// own visible normal (density ⟨wo, m⟩⁺ D_j(m) / V_j(wo)).
fn sample_visible_lobes(e: &ExactMasking<'_>, wo: Vec3, total: f64, u: Vec2) -> Vec3 {
    let target = u.x as f64 * total;
    let mut cum = 0.0;
    let mut chosen = None;
    for (m, lobe) in e.lobes.as_slice() {
        let w = *m as f64 * lobe.visible_area(wo) as f64;
        if w <= 0.0 {
            continue;
        }
        chosen = Some((lobe, cum, w));
        if cum + w > target {
            break;
        }
        cum += w;
    }
    match chosen {
        Some((lobe, before, w)) => {
            let ux = (((target - before) / w) as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
            lobe.sample_visible(wo, Vec2::new(ux, u.y))
        }
        None => Vec3::Z,
    }
}

/// The density of [`sample_visible_lobes`]: Σ_j (mass_j V_j / total) ⟨wo, m⟩⁺ D_j(m) / V_j =
/// ⟨wo, m⟩⁺ Σ_j mass_j D_j(m) / total.
fn pdf_visible_lobes(e: &ExactMasking<'_>, wo: Vec3, total: f64, m: Vec3) -> f32 {
    let c = wo.dot(m);
    if !(m.is_finite() && m.z > 0.0 && c > 0.0) {
        return 0.0;
    }
    let d: f64 = e
        .lobes
        .as_slice()
        .iter()
        .map(|(mass, lobe)| *mass as f64 * lobe.d(m) as f64)
        .sum();
    finite_or_zero(c as f64 * d / total)
}
