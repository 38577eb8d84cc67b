//! Ground truth: the binned P-NDF of the interpolated normal map through a footprint, the total
//! variation distance of a model to it, and the two references of a footprint's BRDF: the exact
//! P-BRDF of the interpolated map (\[Chermain2019\] eq. 7 with the true P-NDF) and conventional
//! normal-mapped shading averaged over the footprint ([`FootprintBrdf`]), which differ.
//!
//! # The P-NDF, normalised like every NDF of the crate
//!
//! Positions u are weighted by the footprint kernel k_P (geometric area), each carries the interpolated
//! normal ω_n(u). The distribution of ω_n then has density p(m) per unit solid angle, and the P-NDF in
//! the crate's convention (∫ D cos θ dω = 1) is
//!
//! D_P(m) = p(m) / cos θ_m = ∫ δ(ω_n(u) − m) k_P(u) du / cos θ_m,
//!
//! i.e. \[Chermain2019\] eq. 8 with the 1/cos θ that turns "fraction of geometric area" into "microfacet
//! area per unit solid angle", the same convention as the mixture's lobes D_i = P22/cos⁴θ (eq. 2).
//!
//! # Reference
//! \[Chermain2019\] eq. 8 (P-NDF), §5.1.1 (comparison to ground truth), §5.2.2 (naive reference).

use super::bins::HemisphereBins;
use super::footprint::Footprint;
use super::normal_map::NormalMap;
use crate::ndf::{Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Independent batches of [`binned_pndf`]: standard errors come from the spread between them.
///
/// 16 batches give a standard-error estimate with 15 degrees of freedom (its own relative error is
/// about 1/√30 ≈ 18 %), enough for test tolerances of a few standard errors.
pub const REFERENCE_BATCHES: usize = 16;

/// Smallest number of stratum rows per parallel task, and the largest number of tasks per batch. Both
/// are fixed (results do not depend on the thread count); the cap bounds the memory of the per-task
/// histograms to 16 × bins × 16 bytes.
const MIN_ROWS_PER_TASK: usize = 32;
const MAX_TASKS_PER_BATCH: usize = 16;

/// Which footprint kernel weights the positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Kernel {
    /// The Gaussian view of the footprint ([`Footprint::gaussian_texels`]).
    Gaussian,
    /// The uniform parallelogram ([`Footprint::parallelogram_texels`]).
    Parallelogram,
}

/// The reference P-NDF of one footprint, tabulated on equal-area hemisphere bins.
///
/// Per bin b (solid angle ΔΩ):
/// - `mass[b]` = ∫_b D cos θ dω, the fraction of the (kernel-weighted) samples whose normal falls in b;
///   Σ mass = 1 exactly (up to f64 rounding);
/// - `d[b]` = (1/ΔΩ) ∫_b D dω, the bin average of D, estimated without bias by
///   Σ_{samples in b} (1/cos θ_s) / (N ΔΩ);
/// - `cos_theta[b]` = mass / (d ΔΩ): the harmonic mean of the samples' cos θ in the bin (the bin's
///   exact mean cosine [`HemisphereBins::mean_cos`] for empty bins), chosen so that
///   Σ d · cos_theta · ΔΩ = Σ mass = 1 exactly;
/// - standard errors of `d` and `mass` from [`REFERENCE_BATCHES`] independent batches.
#[derive(Clone, Debug)]
pub struct BinnedPndf {
    bins: HemisphereBins,
    d: Vec<f64>,
    cos_theta: Vec<f64>,
    mass: Vec<f64>,
    d_std_error: Vec<f64>,
    mass_std_error: Vec<f64>,
    tv_error: f64,
    samples: usize,
}

impl BinnedPndf {
    /// The binning.
    pub fn bins(&self) -> &HemisphereBins {
        &self.bins
    }

    /// Bin-averaged D per bin.
    pub fn d(&self) -> &[f64] {
        &self.d
    }

    /// The cosine associated with each bin, with Σ d · cos_theta · ΔΩ = 1 (see the type's docs).
    pub fn cos_theta(&self) -> &[f64] {
        &self.cos_theta
    }

    /// ∫_bin D cos θ dω per bin (sums to 1).
    pub fn mass(&self) -> &[f64] {
        &self.mass
    }

    /// Standard error of each bin's `d` (batch spread / √batches).
    pub fn std_error(&self) -> &[f64] {
        &self.d_std_error
    }

    /// Standard error of each bin's `mass`.
    pub fn mass_std_error(&self) -> &[f64] {
        &self.mass_std_error
    }

    /// Estimated total-variation error of this estimate against the exact binned P-NDF:
    /// ½ Σ_b √(2/π) σ_mass,b, the expected ½ Σ |error| if the bins' errors were independent and
    /// Gaussian (E|X| = √(2/π) σ). A noise floor: model-vs-reference distances below a few times this
    /// are not resolved.
    pub fn tv_error(&self) -> f64 {
        self.tv_error
    }

    /// Number of positions actually sampled (`REFERENCE_BATCHES` × m², see [`binned_pndf`]).
    pub fn samples(&self) -> usize {
        self.samples
    }

    /// D of the bin containing `w` (0 below the horizon or for invalid `w`).
    pub fn d_at(&self, w: Vec3) -> f64 {
        self.bins.bin_of(w).map_or(0.0, |b| self.d[b])
    }

    /// Total variation ½ Σ |mass − mass'| between two references on the same bins; `None` if the
    /// binnings differ.
    pub fn tv_to(&self, other: &BinnedPndf) -> Option<f64> {
        (self.bins == other.bins).then(|| {
            0.5 * self
                .mass
                .iter()
                .zip(&other.mass)
                .map(|(a, b)| (a - b).abs())
                .sum::<f64>()
        })
    }
}

/// Per-task histogram: (count, Σ 1/cos θ) per bin.
type Hist = Vec<(u64, f64)>;

/// Lower Cholesky factor of a 2 × 2 covariance, in f64 (clamped: the footprint's clamps keep Σ
/// positive definite, this only guards rounding).
fn cholesky(cov: Mat2) -> [f64; 3] {
    let (sxx, sxy, syy) = (
        cov.col(0).x as f64,
        cov.col(1).x as f64,
        cov.col(1).y as f64,
    );
    let l11 = sxx.max(0.0).sqrt();
    let l21 = if l11 > 0.0 { sxy / l11 } else { 0.0 };
    let l22 = (syy - l21 * l21).max(0.0).sqrt();
    [l11, l21, l22]
}

/// The position of the stratum point (s, t) ∈ [0, 1)² under `kernel`, in texel units of `map`
/// wrapped into the map: c + (s − ½) a + (t − ½) b for the parallelogram, c + L (Box–Muller of
/// (s, t)) for the Gaussian (L the Cholesky factor of Σ; Box–Muller keeps strata compact). A
/// uniformly distributed (s, t) gives positions distributed as k_P.
fn kernel_position(
    map: &NormalMap,
    footprint: &Footprint,
    kernel: Kernel,
) -> Box<dyn Fn(f64, f64) -> Vec2 + Sync> {
    let (w, h) = (map.width(), map.height());
    let (wf, hf) = (w as f64, h as f64);
    match kernel {
        Kernel::Parallelogram => {
            let (c, a, b) = footprint.parallelogram_texels(w, h);
            let (c, a, b) = (
                c.to_array().map(f64::from),
                a.to_array().map(f64::from),
                b.to_array().map(f64::from),
            );
            Box::new(move |s: f64, t: f64| {
                let (s, t) = (s - 0.5, t - 0.5);
                let x = c[0] + s * a[0] + t * b[0];
                let y = c[1] + s * a[1] + t * b[1];
                Vec2::new(x.rem_euclid(wf) as f32, y.rem_euclid(hf) as f32)
            })
        }
        Kernel::Gaussian => {
            let (c, cov) = footprint.gaussian_texels(w, h);
            let c = c.to_array().map(f64::from);
            let l = cholesky(cov);
            Box::new(move |s: f64, t: f64| {
                let r = (-2.0 * (-s).ln_1p()).sqrt();
                let (sn, cs) = (std::f64::consts::TAU * t).sin_cos();
                let (z1, z2) = (r * cs, r * sn);
                let x = c[0] + l[0] * z1;
                let y = c[1] + l[1] * z1 + l[2] * z2;
                Vec2::new(x.rem_euclid(wf) as f32, y.rem_euclid(hf) as f32)
            })
        }
    }
}

/// The ground-truth P-NDF of the interpolated normal map seen through `footprint`, binned.
///
/// D_P(m) = ∫ δ(ω_n(u) − m) k_P(u) du / cos θ_m (module docs; \[Chermain2019\] eq. 8), with k_P the
/// Gaussian or parallelogram view of the footprint in texel units of `map` (clamps included).
///
/// Sampling: [`REFERENCE_BATCHES`] independent batches, each an m × m jittered stratification of the
/// unit square, m = max(1, ⌊√(samples / batches)⌋) (so the count is rounded down to batches · m²).
/// A stratum point (s, t) becomes a position c + (s − ½) a + (t − ½) b for the parallelogram, or
/// c + L (Box–Muller of (s, t)) for the Gaussian (L the Cholesky factor of Σ; Box–Muller keeps
/// the strata compact). Every position is importance-sampled from k_P, so all weights are 1/N. Each
/// position's interpolated normal ([`NormalMap::normal_at_texel`]) is binned, accumulating counts and
/// Σ 1/cos θ in f64 (see [`BinnedPndf`] for the estimators and error estimates).
///
/// Deterministic: random numbers come from one PCG stream per (seed, batch, stratum row); rows are
/// split into fixed tasks run in parallel and reduced in order.
///
/// Cost: O(samples) normal lookups (~4 normalisations each) plus O(batches · bins); memory
/// O(16 · bins) for the per-task histograms.
///
/// # Reference
/// \[Chermain2019\] eq. 8, §5.1.1.
pub fn binned_pndf(
    map: &NormalMap,
    footprint: &Footprint,
    kernel: Kernel,
    bins: &HemisphereBins,
    samples: usize,
    seed: u64,
) -> BinnedPndf {
    let batches = REFERENCE_BATCHES;
    let m = ((samples / batches) as f64).sqrt().floor().max(1.0) as usize;
    let position = kernel_position(map, footprint, kernel);
    let nb = bins.len();
    let rows_per_task = MIN_ROWS_PER_TASK.max(m.div_ceil(MAX_TASKS_PER_BATCH));
    let tasks = m.div_ceil(rows_per_task);
    let mut batch_counts: Vec<Vec<u64>> = Vec::with_capacity(batches);
    let mut batch_inv: Vec<Vec<f64>> = Vec::with_capacity(batches);
    for batch in 0..batches {
        let hists: Vec<Hist> = (0..tasks)
            .into_par_iter()
            .map(|task| {
                let mut hist: Hist = vec![(0, 0.0); nb];
                let rows = task * rows_per_task..((task + 1) * rows_per_task).min(m);
                for row in rows {
                    let mut rng = Pcg64Mcg::seed_from_u64(
                        seed ^ (batch as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                            ^ (row as u64).wrapping_mul(0xD1B5_4A32_D192_ED03),
                    );
                    for col in 0..m {
                        let s = (col as f64 + rng.random::<f64>()) / m as f64;
                        let t = (row as f64 + rng.random::<f64>()) / m as f64;
                        let n = map.normal_at_texel(position(s, t));
                        if let Some(bin) = bins.bin_of(n) {
                            hist[bin].0 += 1;
                            hist[bin].1 += 1.0 / n.z as f64;
                        }
                    }
                }
                hist
            })
            .collect();
        let (counts, inv) = merge_histograms(&hists, nb);
        batch_counts.push(counts);
        batch_inv.push(inv);
    }
    summarise(bins, &batch_counts, &batch_inv, m * m)
}

/// The sum of per-thread histograms of one batch: (sample count, Σ 1/cos θ) per bin, as two arrays.
fn merge_histograms(hists: &[Vec<(u64, f64)>], nb: usize) -> (Vec<u64>, Vec<f64>) {
    let mut counts = vec![0u64; nb];
    let mut inv = vec![0.0f64; nb];
    for hist in hists {
        for (k, (c, s)) in hist.iter().enumerate() {
            counts[k] += c;
            inv[k] += s;
        }
    }
    (counts, inv)
}

/// Estimates and batch standard errors from per-batch histograms of `per_batch` samples each.
fn summarise(
    bins: &HemisphereBins,
    counts: &[Vec<u64>],
    inv: &[Vec<f64>],
    per_batch: usize,
) -> BinnedPndf {
    let nb = bins.len();
    let batches = counts.len() as f64;
    let dw = bins.solid_angle();
    let pb = per_batch as f64;
    let mut d = vec![0.0; nb];
    let mut mass = vec![0.0; nb];
    let mut cos_theta = vec![0.0; nb];
    let mut d_se = vec![0.0; nb];
    let mut mass_se = vec![0.0; nb];
    let mut tv_error = 0.0;
    let total_count: u64 = counts.iter().flatten().sum();
    for b in 0..nb {
        let dm: Vec<f64> = inv.iter().map(|v| v[b] / (pb * dw)).collect();
        let mm: Vec<f64> = counts.iter().map(|c| c[b] as f64 / pb).collect();
        let mean = |x: &[f64]| x.iter().sum::<f64>() / batches;
        let se = |x: &[f64], mu: f64| {
            if batches > 1.0 {
                (x.iter().map(|v| (v - mu).powi(2)).sum::<f64>() / (batches - 1.0) / batches).sqrt()
            } else {
                0.0
            }
        };
        d[b] = mean(&dm);
        let count: u64 = counts.iter().map(|c| c[b]).sum();
        mass[b] = if total_count > 0 {
            count as f64 / total_count as f64
        } else {
            0.0
        };
        d_se[b] = se(&dm, d[b]);
        mass_se[b] = se(&mm, mean(&mm));
        cos_theta[b] = if d[b] > 0.0 {
            mass[b] / (d[b] * dw)
        } else {
            bins.mean_cos(b)
        };
        tv_error += 0.5 * (2.0 / std::f64::consts::PI).sqrt() * mass_se[b];
    }
    BinnedPndf {
        bins: *bins,
        d,
        cos_theta,
        mass,
        d_std_error: d_se,
        mass_std_error: mass_se,
        tv_error,
        samples: total_count as usize,
    }
}

/// Total variation distance between a model NDF and a reference, on the reference's bins:
/// ½ Σ_b |M_model(b) − mass_ref(b)|, with the model's bin mass M_model(b) = ∫_b D_model cos θ dω.
///
/// This is ½ Σ |D_model − D_ref| cos θ ΔΩ with the model *averaged* over each bin rather than
/// point-sampled: M_model(b) is estimated with a k × k midpoint grid on the bin's square cell mapped
/// through the equal-area map (k = ⌈√sub_samples_per_bin⌉, at least 1), i.e. ΔΩ/k² Σ D(ω) cos θ.
/// In [0, 1] for normalised densities (0: identical bin masses; 1: disjoint supports); binning can
/// only lower a distance, so it is a lower bound of the continuous total variation. A model that
/// is not normalised contributes its missing or excess mass. Compare with
/// [`BinnedPndf::tv_error`], the reference's own noise floor.
///
/// Deterministic (parallel over bins, summed in order), hence the `Sync` bound. Cost: bins × k²
/// evaluations of `d`.
pub fn tv_distance(
    model: &(impl Ndf + Sync),
    reference: &BinnedPndf,
    sub_samples_per_bin: usize,
) -> f64 {
    let bins = reference.bins();
    let k = (sub_samples_per_bin.max(1) as f64).sqrt().ceil() as usize;
    let dw = bins.solid_angle();
    let masses: Vec<f64> = (0..bins.len())
        .into_par_iter()
        .map(|b| {
            let mut s = 0.0f64;
            for j in 0..k {
                for i in 0..k {
                    let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
                    let w = bins.sample_in_bin(b, u);
                    s += model.d(w) as f64 * w.z as f64;
                }
            }
            s * dw / (k * k) as f64
        })
        .collect();
    0.5 * masses
        .iter()
        .zip(reference.mass())
        .map(|(a, b)| (a - b).abs())
        .sum::<f64>()
}

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
/// which a per-position shading does not have. tests/reference.rs checks both limits.
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
/// from `kernel` (an m × m jittered stratification of the unit square mapped as [`binned_pndf`]
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
    let m = (samples as f64).sqrt().floor().max(1.0) as usize;
    let position = kernel_position(map, footprint, kernel);
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    for row in 0..m {
        for col in 0..m {
            let s = (col as f64 + rng.random::<f64>()) / m as f64;
            let t = (row as f64 + rng.random::<f64>()) / m as f64;
            acc.add(map.slope_at_texel(position(s, t)));
        }
    }
    acc
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

// Issue #14, item 4: the σ_ε-convolved ground truth and the adaptive per-bin quadrature live in
// their own file (a child module, so that they share this module's private estimator helpers).
#[path = "truth.rs"]
mod truth;
pub use truth::{
    BinMasses, DEFAULT_MAX_QUADRATURE, DEFAULT_QUADRATURE_TOLERANCE, JITTERS, adaptive_bin_masses,
    bin_masses, convolved_pndf,
};
