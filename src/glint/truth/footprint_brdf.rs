//! The two references of a footprint's BRDF: the exact P-BRDF of the interpolated map
//! (\[Chermain2019\] eq. 7 with the true P-NDF, reference (a)) and conventional normal-mapped shading
//! averaged over the footprint (reference (b)), which differ ([`FootprintBrdf`] says by how much), and
//! [`naive_brdf`], normal-mapped shading at one position.
//!
//! # Reference
//! \[Chermain2019\] eq. 7 (P-BRDF), §5.2.2 (naive normal-map reference).

use super::binned::{Kernel, kernel_position};
use crate::glint::{Footprint, NormalMap};
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The two references of a footprint's BRDF at one pair of directions, accumulated over positions.
///
/// Both see the same positions u of the footprint (drawn from its kernel k_P, or given with
/// weights), each carrying the interpolated slope ñ(u) and, as in \[Chermain2019\] §5.2.2, a
/// near-specular facet lobe D_u: the non-centred Beckmann lobe [`SlopeGaussian`] of mean ñ(u) and
/// covariance σ_ε² I in the geometric frame, with projected area A_u(w) = w_z − ñ(u)·w_xy (signed:
/// the tilted facet's area toward w per unit geometric area) and visible area
/// V_u(w) = ∫⟨w, m⟩⁺ D_u(m) dm ([`Ndf::visible_area`]). Values are in the renderer's measure
/// (the radiance is `value · cos θi · F(wo·h) · E`, E the irradiance), without Fresnel: F(wo·h) is
/// the same at every position, since wo and wi are.
///
/// **(a) [`FootprintBrdf::pbrdf`], the exact P-BRDF of the interpolated map** (\[Chermain2019\]
/// eq. 7 with the true P-NDF of the footprint). The P-NDF is D_P = ∫ k_P D_u du (eq. 8, with each
/// position's Dirac widened to the σ_ε lobe); its projected area is A_P(w) = max(0, ∫ k_P A_u du)
/// (eq. 17 for a continuum of facets, clamped as the models clamp it) and its visible area
/// V_P(w) = ∫⟨w, m⟩⁺ D_P dm = ∫ k_P V_u du (the integral over m and the one over u commute). The
/// patch masking is G1(w) = χ⁺(w·h) A_P(w) / V_P(w) (eq. 10-14), so eq. 7 in the renderer's measure
/// (f_P · A_P(wi) / cos θi, the convention of [`crate::bxdf::MicrofacetBrdf`]) is
///
/// f_a = D_P(h) χ⁺(wo·h) χ⁺(wi·h) A_P(wi) / (4 V_P(wo) V_P(wi) cos θi).
///
/// Estimated as a ratio: D_P(h), A_P and V_P are each the k_P-mean of a per-position quantity, so the
/// same positions estimate all three (consistent; its O(1/N) ratio bias is far below the noise).
/// Written as a re-weighting of the naive samples below: position u's term of (b),
/// b_u = D_u(h) χ⁺χ⁺ A_u(wi) / (4 V_u(wo) V_u(wi) cos θi), enters (a) with the weight
/// V_u(wo) V_u(wi) A_P(wi) / (A_u(wi) V_P(wo) V_P(wi)). As σ_ε → 0 each facet sees the whole of its
/// own lobe, V_u → A_u, and the weight becomes (A_u(wo) / A_P(wo)) · G2_P(wo, wi) with
/// G2_P = (A_P(wo)/V_P(wo)) (A_P(wi)/V_P(wi)): the naive sample re-weighted by its facet's share
/// of the patch's projected area toward the viewer, times the patch's masking.
///
/// **(b) [`FootprintBrdf::normal_mapped`], conventional normal-mapped rendering** (what a renderer
/// without glint support shows; \[Chermain2019\] §5.2.2): the k_P-mean of b_u. As σ_ε → 0,
/// b_u cos θi → D_n(h) / (4 ⟨wo, n⟩) with D_n normalised about the facet normal n: each position
/// shaded with its own normal, its own 1/A_u(wo) and no masking by the rest of the patch.
///
/// **(b) does not tend to (a).** Per position, their ratio tends to G1_P(wi) ⟨wo,h⟩ / (h_z V_P(wo))
/// (with A_u(wo) = ⟨wo,h⟩/h_z on the facet that reflects wo into wi), which is 1 when the footprint
/// holds a single facet orientation (then A_P = V_P = A_u) and differs otherwise: the difference is
/// the P-BRDF formulation's own modelling of the patch (masking and normalisation by A_P, V_P),
/// which a per-position shading does not have. tests/it/reference.rs checks both limits.
///
/// Degenerate directions (below the horizon, non-finite, wo = −wi), a non-positive or non-finite
/// σ_ε, or a footprint that sees nothing toward wo or wi give 0 for both.
///
/// # Reference
/// \[Chermain2019\] eq. 7 (P-BRDF), 8 (P-NDF), 10-17 (patch masking and projected area), §5.2.2
/// (naive normal-map reference with σ_ε = 0.01).
#[derive(Clone, Copy, Debug)]
pub struct FootprintBrdf {
    wo: Vec3,
    wi: Vec3,
    wh: Option<Vec3>,
    sigma_eps: f32,
    /// Σ weight.
    weight: f64,
    /// Σ weight · D_u(h) χ⁺χ⁺.
    d: f64,
    /// Σ weight · b_u cos θi (the naive term without the 1/cos θi).
    naive: f64,
    /// Σ weight · A_u(wi) (signed).
    area_i: f64,
    /// Σ weight · V_u(wo), Σ weight · V_u(wi).
    visible_o: f64,
    visible_i: f64,
}

impl FootprintBrdf {
    /// An empty accumulator for the directions `wo`, `wi` (unit, local frame, z = geometric normal)
    /// and the facets' slope deviation `sigma_eps` (the paper's 0.01).
    pub fn new(wo: Vec3, wi: Vec3, sigma_eps: f32) -> FootprintBrdf {
        let valid = crate::frame::is_upper(wo)
            && crate::frame::is_upper(wi)
            && sigma_eps.is_finite()
            && sigma_eps > 0.0;
        let wh = if valid {
            crate::frame::half_vector(wo, wi)
        } else {
            None
        };
        FootprintBrdf {
            wo,
            wi,
            wh,
            sigma_eps,
            weight: 0.0,
            d: 0.0,
            naive: 0.0,
            area_i: 0.0,
            visible_o: 0.0,
            visible_i: 0.0,
        }
    }

    /// Adds one position of the footprint with slope `slope` (weight 1).
    pub fn add(&mut self, slope: Vec2) {
        self.add_weighted(slope, 1.0);
    }

    /// Adds one position with slope `slope` and kernel weight `weight` (ignored unless finite and
    /// positive). Positions drawn from k_P take weight 1; a quadrature of k_P takes its weights.
    pub fn add_weighted(&mut self, slope: Vec2, weight: f64) {
        let Some(wh) = self.wh else {
            return;
        };
        if !(weight.is_finite() && weight > 0.0 && slope.is_finite()) {
            return;
        }
        self.weight += weight;
        let area = |w: Vec3| w.z as f64 - slope.x as f64 * w.x as f64 - slope.y as f64 * w.y as f64;
        self.area_i += weight * area(self.wi);
        let var = self.sigma_eps * self.sigma_eps;
        let Ok(lobe) = SlopeGaussian::new(slope, Mat2::from_diagonal(Vec2::splat(var))) else {
            return; // a slope outside f32 range: the facet contributes its area only
        };
        let (vo, vi) = (
            lobe.visible_area(self.wo) as f64,
            lobe.visible_area(self.wi) as f64,
        );
        self.visible_o += weight * vo;
        self.visible_i += weight * vi;
        if !(self.wo.dot(wh) > 0.0 && self.wi.dot(wh) > 0.0) {
            return;
        }
        let d = lobe.d(wh) as f64;
        if d > 0.0 && d.is_finite() {
            self.d += weight * d;
            if vo > 0.0 && vi > 0.0 {
                self.naive += weight * d * area(self.wi).max(0.0) / (4.0 * vo * vi);
            }
        }
    }

    /// Adds the positions accumulated by `other` (same directions and σ_ε).
    pub fn merge(&mut self, other: &FootprintBrdf) {
        self.weight += other.weight;
        self.d += other.d;
        self.naive += other.naive;
        self.area_i += other.area_i;
        self.visible_o += other.visible_o;
        self.visible_i += other.visible_i;
    }

    /// Total weight of the positions added.
    pub fn weight(&self) -> f64 {
        self.weight
    }

    /// Reference (a): the P-BRDF of eq. 7 with the footprint's true P-NDF, in the renderer's measure,
    /// without Fresnel (see the type's docs). 0 when degenerate.
    pub fn pbrdf(&self) -> f64 {
        let cos_i = self.wi.z as f64;
        if self.wh.is_none() || self.weight <= 0.0 || cos_i <= 0.0 {
            return 0.0;
        }
        let n = self.weight;
        let (d, ap_i) = (self.d / n, (self.area_i / n).max(0.0));
        let (vp_o, vp_i) = (self.visible_o / n, self.visible_i / n);
        if !(vp_o > 0.0 && vp_i > 0.0) {
            return 0.0;
        }
        let f = d * ap_i / (4.0 * vp_o * vp_i * cos_i);
        if f.is_finite() { f } else { 0.0 }
    }

    /// Reference (b): conventional normal-mapped shading averaged over the footprint, in the
    /// renderer's measure, without Fresnel (see the type's docs). 0 when degenerate.
    pub fn normal_mapped(&self) -> f64 {
        let cos_i = self.wi.z as f64;
        if self.wh.is_none() || self.weight <= 0.0 || cos_i <= 0.0 {
            return 0.0;
        }
        let f = self.naive / self.weight / cos_i;
        if f.is_finite() { f } else { 0.0 }
    }
}

/// Both references of [`FootprintBrdf`] for `footprint` on `map`, from `samples` positions drawn
/// from `kernel` (an m × m jittered stratification of the unit square mapped as [`binned_pndf`](super::binned_pndf)
/// maps it, m = max(1, ⌊√samples⌋); the slope at each position is [`NormalMap::slope_at_texel`]).
///
/// Deterministic for a given `seed`; sequential (call it per pixel from parallel code). Cost:
/// m² slope lookups and non-centred lobe evaluations.
///
/// # Reference
/// \[Chermain2019\] eq. 7-8, §5.2.2.
#[allow(clippy::too_many_arguments)]
pub fn footprint_brdf(
    map: &NormalMap,
    footprint: &Footprint,
    kernel: Kernel,
    wo: Vec3,
    wi: Vec3,
    sigma_eps: f32,
    samples: usize,
    seed: u64,
) -> FootprintBrdf {
    let mut acc = FootprintBrdf::new(wo, wi, sigma_eps);
    if acc.wh.is_none() {
        return acc;
    }
    for_each_footprint_slope(map, footprint, kernel, samples, seed, |slope| {
        acc.add(slope)
    });
    acc
}

/// Calls `visit` with the slope at each of the positions [`footprint_brdf`] uses for the same
/// `footprint`, `kernel`, `samples` and `seed`, in the same order: an m × m jittered
/// stratification of the unit square (m = max(1, ⌊√samples⌋)) mapped by the kernel, the slope at
/// each position being [`NormalMap::slope_at_texel`]. For evaluating another per-position BRDF
/// (a normal-mapped one, say) at exactly the positions of the references.
///
/// # Reference
/// \[Chermain2019\] §5.2.2 (naive sampling of the footprint).
pub fn for_each_footprint_slope(
    map: &NormalMap,
    footprint: &Footprint,
    kernel: Kernel,
    samples: usize,
    seed: u64,
    mut visit: impl FnMut(Vec2),
) {
    let m = (samples as f64).sqrt().floor().max(1.0) as usize;
    let position = kernel_position(map, footprint, kernel);
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    for row in 0..m {
        for col in 0..m {
            let s = (col as f64 + rng.random::<f64>()) / m as f64;
            let t = (row as f64 + rng.random::<f64>()) / m as f64;
            visit(map.slope_at_texel(position(s, t)));
        }
    }
}

/// The BRDF of the interpolated normal map at one position, with a near-specular lobe around the
/// local normal (no Fresnel: multiply by F yourself).
///
/// The lobe is the non-centred Beckmann NDF [`SlopeGaussian`] of mean slope ñ(uv) (the interpolated
/// slope, [`NormalMap::slope_at`]) and covariance σε² I, in the geometric frame, and
///
/// f(wo, wi) = D(ω_h) G2(wo, wi, ω_h) / (4 A(wo) A(wi)) = D(ω_h) χ⁺(wo·ω_h) χ⁺(wi·ω_h) / (4 V(wo) V(wi)),
///
/// with separable Smith masking of the lobe, G1 = A/V and V(w) = ∫⟨w, m⟩⁺ D dm ([`Ndf::visible_area`];
/// written with V so that nothing divides by a vanishing A). This is conventional normal-mapped
/// shading at one position (σε = 0.01 as \[Chermain2019\] §5.2.2). Averaged over a footprint it does
/// **not** tend to the P-BRDF of eq. 7 with the true P-NDF as σε → 0: each position keeps its own
/// 1/A(wo) and no patch masking, so the two agree only where the footprint holds one facet
/// orientation. [`FootprintBrdf`] computes both (its docs give the ratio).
///
/// Total: below-horizon or invalid directions, a non-finite or non-positive `sigma_eps`, or a lobe
/// outside f32 range give 0.
///
/// # Reference
/// \[Chermain2019\] §5.2.2 (naive normal-map reference with σε = 0.01).
pub fn naive_brdf(map: &NormalMap, uv: Vec2, wo: Vec3, wi: Vec3, sigma_eps: f32) -> f32 {
    if !(crate::frame::is_upper(wo) && crate::frame::is_upper(wi)) {
        return 0.0;
    }
    if !(sigma_eps.is_finite() && sigma_eps > 0.0) {
        return 0.0;
    }
    let (Some(wo), Some(wi)) = (wo.try_normalize(), wi.try_normalize()) else {
        return 0.0;
    };
    let Some(wh) = crate::frame::half_vector(wo, wi) else {
        return 0.0;
    };
    let var = sigma_eps * sigma_eps;
    let Ok(lobe) = SlopeGaussian::new(map.slope_at(uv), Mat2::from_diagonal(Vec2::splat(var)))
    else {
        return 0.0;
    };
    if !(wo.dot(wh) > 0.0 && wi.dot(wh) > 0.0) {
        return 0.0;
    }
    let (vo, vi) = (lobe.visible_area(wo), lobe.visible_area(wi));
    if !(vo > 0.0 && vi > 0.0) {
        return 0.0;
    }
    let f = lobe.d(wh) as f64 / (4.0 * vo as f64 * vi as f64);
    if f.is_finite() { f as f32 } else { f32::MAX }
}
