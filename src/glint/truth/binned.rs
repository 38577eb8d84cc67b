//! The Dirac ground truth: the binned P-NDF of the interpolated normal map through a footprint, and
//! the total variation distance of a model to it. The position sampler of the footprint kernel here
//! is shared with the σ_ε-convolved truth (convolved.rs) and the footprint BRDF references
//! (footprint_brdf.rs).
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

use crate::glint::surface::HemisphereBins;
use crate::glint::{Footprint, NormalMap};
use crate::ndf::Ndf;
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
pub(super) fn cholesky(cov: Mat2) -> [f64; 3] {
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
pub(super) fn kernel_position(
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
pub(super) fn merge_histograms(hists: &[Vec<(u64, f64)>], nb: usize) -> (Vec<u64>, Vec<f64>) {
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
pub(super) fn summarise(
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
