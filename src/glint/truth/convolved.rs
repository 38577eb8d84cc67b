//! The second ground truth (the P-NDF convolved with the material's micro-roughness lobe) and the
//! adaptive per-bin quadrature of a model's D that both truths are compared with.
//!
//! # Two truths
//!
//! [`binned_pndf`](super::binned_pndf) tabulates the P-NDF of the interpolated normal map itself:
//! every position contributes a Dirac at its normal (\[Chermain2019\] eq. 8). The paper's material is
//! not that surface: each position reflects through a near-specular lobe of intrinsic roughness
//! σ_ε = 0.01 (§5.2.2), and the glint models carry that roughness in their lobes (the mixture's
//! variance floor `sigma_min`, the position-normal elements' `sigma_r`). [`convolved_pndf`]
//! tabulates the P-NDF of that material:
//!
//! D_σ(m) = ∫ k_P(u) D_{ñ(u), σ_ε}(m) du,
//!
//! with D_{μ, σ} the non-centred Beckmann lobe whose slopes are N(μ, σ² I) (\[Chermain2019\] eq. 2:
//! D = P22(ñ) / cos⁴θ, so that D cos θ dω = P22 dñ). A model that matched the interpolated surface and
//! added exactly σ_ε of roughness would score 0 against it; against the Dirac truth it is charged for
//! the roughness it was asked to add. The two truths answer different questions and the compare
//! example reports both.
//!
//! # Estimator
//!
//! The bins are equal-area cells of the hemisphere ([`HemisphereBins`]); their preimages in slope space
//! are curved, so a Gaussian's mass over a bin has no closed form (erf integrates it exactly only over
//! slope-space rectangles). The estimator therefore integrates the lobe by Monte Carlo: the positions
//! are exactly those of [`binned_pndf`](super::binned_pndf) (same strata, same random stream), and each
//! contributes [`JITTERS`] slopes ñ(u) + σ_ε z, z ~ N(0, I) from a 2 × 2 stratified Box–Muller on an
//! independent stream, each binned like a Dirac sample with weight 1/[`JITTERS`]. This is unbiased for
//! the bin masses of D_σ and is independent of every model under test; its noise is measured by the
//! same [`REFERENCE_BATCHES`](super::REFERENCE_BATCHES) batches as the Dirac truth's.
//!
//! # Reference
//! \[Chermain2019\] eq. 2 (the lobe), eq. 8 (P-NDF), §5.2.2 (σ_ε = 0.01).

use super::binned::{
    BinnedPndf, Kernel, REFERENCE_BATCHES, kernel_position, merge_histograms, summarise,
};
use crate::error::{Error, Result};
use crate::glint::{Footprint, HemisphereBins, NormalMap};
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

/// Slopes drawn per position by [`convolved_pndf`] (a 2 × 2 stratification of the Box–Muller square).
pub const JITTERS: usize = 4;

/// Default tolerance of [`adaptive_bin_masses`]: refinement stops when the bin masses changed by less
/// than this in total variation (½ Σ |Δ mass|), which bounds the change of the TV to any reference.
pub const DEFAULT_QUADRATURE_TOLERANCE: f64 = 1e-3;

/// Default finest grid of [`adaptive_bin_masses`]: 64 × 64 points in a bin.
pub const DEFAULT_MAX_QUADRATURE: usize = 64;

/// Same stratification as `binned_pndf` (kept equal so that σ_ε = 0 reproduces it bit for bit).
const MIN_ROWS_PER_TASK: usize = 32;
const MAX_TASKS_PER_BATCH: usize = 16;

/// The ground-truth P-NDF of the interpolated map seen through `footprint`, convolved with the
/// isotropic slope Gaussian of standard deviation `sigma_eps` per axis, binned.
///
/// D_σ(m) = ∫ k_P(u) D_{ñ(u), σ_ε}(m) du (module docs), with k_P the Gaussian or parallelogram view
/// of the footprint in texel units of `map`, and D_{μ, σ} the non-centred Beckmann lobe of mean slope μ
/// and covariance σ² I (\[Chermain2019\] eq. 2). Positions are sampled exactly like
/// [`binned_pndf`](super::binned_pndf) with the same `samples` and `seed`; each contributes
/// [`JITTERS`] jittered slopes (module docs). The returned [`BinnedPndf`] has the same meaning and
/// error estimates as the Dirac truth's; [`BinnedPndf::samples`] counts the binned slopes.
///
/// `sigma_eps = 0` is the Dirac truth itself: the result equals `binned_pndf`'s (the positions'
/// normals are binned directly). Use σ_ε = 0.01 ([`crate::ndf::DEFAULT_SIGMA_MIN`]), the paper's
/// material and the mixture's default floor.
///
/// Cost: O(samples) normal lookups plus O([`JITTERS`] · samples) bin lookups.
///
/// # Errors
/// [`Error::InvalidParameter`] naming `sigma_eps` unless it is finite and in [0, 1] (a slope
/// standard deviation of 1 is a 45° RMS tilt: far beyond a micro-roughness).
///
/// # Reference
/// \[Chermain2019\] eq. 2, eq. 8, §5.2.2.
pub fn convolved_pndf(
    map: &NormalMap,
    footprint: &Footprint,
    kernel: Kernel,
    bins: &HemisphereBins,
    samples: usize,
    seed: u64,
    sigma_eps: f64,
) -> Result<BinnedPndf> {
    if !(sigma_eps.is_finite() && (0.0..=1.0).contains(&sigma_eps)) {
        return Err(Error::InvalidParameter {
            name: "sigma_eps",
            value: sigma_eps,
            reason: "must be finite and in [0, 1]",
        });
    }
    let batches = REFERENCE_BATCHES;
    let m = ((samples / batches) as f64).sqrt().floor().max(1.0) as usize;
    let position = kernel_position(map, footprint, kernel);
    let jitters = if sigma_eps > 0.0 { JITTERS } else { 1 };
    let nb = bins.len();
    let rows_per_task = MIN_ROWS_PER_TASK.max(m.div_ceil(MAX_TASKS_PER_BATCH));
    let tasks = m.div_ceil(rows_per_task);
    let mut batch_counts: Vec<Vec<u64>> = Vec::with_capacity(batches);
    let mut batch_inv: Vec<Vec<f64>> = Vec::with_capacity(batches);
    for batch in 0..batches {
        let hists: Vec<Vec<(u64, f64)>> = (0..tasks)
            .into_par_iter()
            .map(|task| {
                let mut hist = vec![(0u64, 0.0f64); nb];
                let rows = task * rows_per_task..((task + 1) * rows_per_task).min(m);
                for row in rows {
                    // The stream of binned_pndf (positions), and an independent one (jitter).
                    let key = seed
                        ^ (batch as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                        ^ (row as u64).wrapping_mul(0xD1B5_4A32_D192_ED03);
                    let mut rng = Pcg64Mcg::seed_from_u64(key);
                    let mut jitter_rng = Pcg64Mcg::seed_from_u64(key ^ 0xA076_1D64_78BD_642F);
                    for col in 0..m {
                        let s = (col as f64 + rng.random::<f64>()) / m as f64;
                        let t = (row as f64 + rng.random::<f64>()) / m as f64;
                        let n = map.normal_at_texel(position(s, t));
                        if sigma_eps == 0.0 {
                            if let Some(bin) = bins.bin_of(n) {
                                hist[bin].0 += 1;
                                hist[bin].1 += 1.0 / n.z as f64;
                            }
                            continue;
                        }
                        let (sx, sy) = (-(n.x as f64) / n.z as f64, -(n.y as f64) / n.z as f64);
                        for j in 0..JITTERS {
                            let a = ((j % 2) as f64 + jitter_rng.random::<f64>()) / 2.0;
                            let b = ((j / 2) as f64 + jitter_rng.random::<f64>()) / 2.0;
                            let (z1, z2) = box_muller(a, b);
                            let (x, y) = (sx + sigma_eps * z1, sy + sigma_eps * z2);
                            // 1 / cos θ of the slope (x, y) is √(1 + x² + y²).
                            let inv_cos = (1.0 + x * x + y * y).sqrt();
                            let w = Vec3::new((-x / inv_cos) as f32, (-y / inv_cos) as f32, {
                                (1.0 / inv_cos) as f32
                            });
                            if let Some(bin) = bins.bin_of(w) {
                                hist[bin].0 += 1;
                                hist[bin].1 += inv_cos;
                            }
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
    Ok(summarise(bins, &batch_counts, &batch_inv, m * m * jitters))
}

/// Two independent standard normals from (s, t) ∈ [0, 1)² (Box–Muller; s = 0 is finite).
fn box_muller(s: f64, t: f64) -> (f64, f64) {
    let r = (-2.0 * (-s).ln_1p()).sqrt();
    let (sn, cs) = (std::f64::consts::TAU * t).sin_cos();
    (r * cs, r * sn)
}

/// A model's bin masses M(b) = ∫_b D cos θ dω with a k × k midpoint grid on each bin's square cell
/// (mapped through the equal-area map): M(b) ≈ ΔΩ/k² Σ D(ω) cos θ. The rule of
/// [`tv_distance`](super::tv_distance), returned per bin so that one evaluation serves several
/// references. Deterministic (parallel over bins).
pub fn bin_masses<M: Ndf + Sync + ?Sized>(model: &M, bins: &HemisphereBins, k: usize) -> Vec<f64> {
    (0..bins.len())
        .into_par_iter()
        .map(|b| bin_mass(model, bins, b, k))
        .collect()
}

/// One bin's k × k midpoint mass (see [`bin_masses`]).
fn bin_mass<M: Ndf + Sync + ?Sized>(model: &M, bins: &HemisphereBins, b: usize, k: usize) -> f64 {
    let k = k.max(1);
    let mut s = 0.0f64;
    for j in 0..k {
        for i in 0..k {
            let u = Vec2::new((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
            let w = bins.sample_in_bin(b, u);
            s += model.d(w) as f64 * w.z as f64;
        }
    }
    s * bins.solid_angle() / (k * k) as f64
}

/// A model's bin masses from [`adaptive_bin_masses`], with the quadrature that produced them.
#[derive(Clone, Debug)]
pub struct BinMasses {
    /// ∫_b D cos θ dω per bin.
    pub masses: Vec<f64>,
    /// The finest grid used in any bin (k of k × k).
    pub k_max: usize,
    /// Number of bins refined beyond 4 × 4.
    pub refined_bins: usize,
    /// ½ Σ_b |last change of bin b| at the end: the estimated change of the TV to any reference had the
    /// refinement gone one step further.
    pub change: f64,
    /// Whether `change` < the tolerance (false: stopped at `max_k`).
    pub converged: bool,
}

/// A model's bin masses with per-bin midpoint grids refined 2 × 2 → 4 × 4 → 8 × 8 … until the masses
/// change by less than `tolerance` in total variation.
///
/// Every bin is integrated with 2 × 2 and 4 × 4 points ([`bin_masses`]'s rule); bin b's change δ_b is
/// the difference of its last two estimates. While ½ Σ_b δ_b ≥ `tolerance` and k < `max_k`, the grid
/// doubles in the bins whose δ_b ≥ `tolerance` / bins (the others, together, can move the total by less
/// than ½ `tolerance` if their changes keep shrinking). Since |TV(M, R) − TV(M', R)| ≤ ½ Σ |M − M'| for
/// any reference R, the result's TV to every truth on these bins is stable to about `tolerance`.
///
/// A caveat of any such rule: a feature narrower than the 4 × 4 spacing that falls between the points
/// of both grids is missed by both. At 64² bins the 4 × 4 spacing is ~0.01 in slope near the pole,
/// the width σ_ε of the narrowest lobes of the models compared.
///
/// `tolerance` ≤ 0 or non-finite refines to `max_k`; `max_k` is raised to at least 4.
pub fn adaptive_bin_masses<M: Ndf + Sync + ?Sized>(
    model: &M,
    bins: &HemisphereBins,
    tolerance: f64,
    max_k: usize,
) -> BinMasses {
    let max_k = max_k.max(4);
    let coarse = bin_masses(model, bins, 2);
    let mut masses = bin_masses(model, bins, 4);
    let mut delta: Vec<f64> = masses
        .iter()
        .zip(&coarse)
        .map(|(a, b)| (a - b).abs())
        .collect();
    let mut k = 4;
    let mut k_max = 4;
    let mut refined = vec![false; bins.len()];
    let threshold = if tolerance > 0.0 && tolerance.is_finite() {
        tolerance / bins.len() as f64
    } else {
        0.0
    };
    let change = |delta: &[f64]| 0.5 * delta.iter().sum::<f64>();
    // `tolerance` may be NaN (then refine to `max_k`): written so that NaN keeps refining.
    while change(&delta).partial_cmp(&tolerance) != Some(std::cmp::Ordering::Less) && k < max_k {
        k = (2 * k).min(max_k);
        let active: Vec<usize> = (0..bins.len()).filter(|&b| delta[b] >= threshold).collect();
        if active.is_empty() {
            break;
        }
        let finer: Vec<f64> = active
            .par_iter()
            .map(|&b| bin_mass(model, bins, b, k))
            .collect();
        for (&b, m) in active.iter().zip(finer) {
            delta[b] = (m - masses[b]).abs();
            masses[b] = m;
            refined[b] = true;
        }
        k_max = k;
    }
    let c = change(&delta);
    BinMasses {
        masses,
        k_max,
        refined_bins: refined.iter().filter(|&&r| r).count(),
        change: c,
        converged: c < tolerance,
    }
}

impl BinnedPndf {
    /// Total variation ½ Σ_b |M(b) − mass(b)| between a model's bin masses (e.g. from
    /// [`adaptive_bin_masses`] on the same bins) and this reference; `None` if the lengths differ.
    pub fn tv_to_masses(&self, masses: &[f64]) -> Option<f64> {
        (masses.len() == self.mass().len()).then(|| {
            0.5 * masses
                .iter()
                .zip(self.mass())
                .map(|(a, b)| (a - b).abs())
                .sum::<f64>()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::glint::{binned_pndf, bumpy};

    fn constant_map(slope: Vec2) -> NormalMap {
        NormalMap::from_slopes(8, 8, vec![slope; 64]).unwrap()
    }

    fn fp(area: f32, n: usize) -> Footprint {
        Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n)
    }

    /// Chebyshev ring of a bin around the pole for even n: ring 1 holds the four bins touching the
    /// pole, ring r the bins whose cell's farthest coordinate from the square's centre is r cells.
    fn ring(bins: &HemisphereBins, b: usize) -> usize {
        let (i, j) = bins.cell(b);
        let h = (bins.n() / 2) as i64;
        let r = |c: usize| {
            if (c as i64) < h {
                h - c as i64
            } else {
                c as i64 - h + 1
            }
        };
        r(i).max(r(j)) as usize
    }

    /// A map of one constant slope 0 makes the convolved truth the lobe D_{0, σ} itself, whose mass in
    /// a cone θ ≤ θ_r is the Rayleigh CDF 1 − exp(−tan²θ_r / (2σ²)) (|ñ| of an isotropic 2D Gaussian).
    /// For even n the union of rings 1..r of the equal-area bins is exactly the cap z ≥ 1 − (2r/n)²
    /// (concentric radius max(|a|, |b|) ≤ 2r/n, Lambert z = 1 − r²), so each ring's mass is a
    /// difference of two CDF values, and the four bins of ring 1 (the four quadrants of the cap) each
    /// hold a quarter of it. Tolerance: 5 binomial standard errors √(p(1 − p)/N) of each ring mass.
    #[test]
    fn single_slope_matches_the_closed_form() {
        let map = constant_map(Vec2::ZERO);
        let n = 32;
        let bins = HemisphereBins::new(n).unwrap();
        let sigma = 0.1;
        let r = convolved_pndf(
            &map,
            &fp(4.0, 8),
            Kernel::Gaussian,
            &bins,
            160_000,
            3,
            sigma,
        )
        .unwrap();
        let total = r.samples() as f64;
        assert_eq!(total as usize, REFERENCE_BATCHES * 100 * 100 * JITTERS);
        let cdf = |ring: usize| {
            let rr = 2.0 * ring as f64 / n as f64;
            let z = 1.0 - rr * rr;
            let tan2 = (1.0 - z * z) / (z * z);
            1.0 - (-tan2 / (2.0 * sigma * sigma)).exp()
        };
        let mut checked = 0;
        for k in 1..=n / 2 {
            let got: f64 = (0..bins.len())
                .filter(|&b| ring(&bins, b) == k)
                .map(|b| r.mass()[b])
                .sum();
            let p = cdf(k) - cdf(k - 1);
            let se = (p * (1.0 - p) / total).sqrt();
            assert!(
                (got - p).abs() <= 5.0 * se + 1e-12,
                "ring {k}: {got} vs {p} (se {se})"
            );
            if p > 1e-3 {
                checked += 1;
            }
        }
        assert!(checked >= 3, "the lobe must spread over several rings");
        let p1 = cdf(1) / 4.0;
        let se = (p1 * (1.0 - p1) / total).sqrt();
        for b in (0..bins.len()).filter(|&b| ring(&bins, b) == 1) {
            assert!(
                (r.mass()[b] - p1).abs() <= 5.0 * se,
                "{} vs {p1}",
                r.mass()[b]
            );
        }
    }

    /// The lobe of a tilted constant slope is centred on that slope's normal (sign conventions): the
    /// mass-weighted mean slope of the bins' centres is within a bin width of ñ.
    #[test]
    fn single_tilted_slope_is_centred_on_its_normal() {
        let s0 = Vec2::new(0.3, -0.2);
        let map = constant_map(s0);
        let bins = HemisphereBins::new(64).unwrap();
        let r =
            convolved_pndf(&map, &fp(4.0, 8), Kernel::Gaussian, &bins, 16_000, 5, 0.01).unwrap();
        let mut mean = Vec2::ZERO;
        for (b, m) in r.mass().iter().enumerate() {
            let c = bins.center(b);
            mean += Vec2::new(-c.x / c.z, -c.y / c.z) * *m as f32;
        }
        // Bins near θ = 20° span ~0.05 in slope at n = 64.
        assert!((mean - s0).length() < 0.05, "{mean} vs {s0}");
    }

    /// Normalisation. Every slope is binned (samples() counts all of them: nothing lost), Σ mass = 1,
    /// and the bin-averaged D integrates to 1 against the cosine: Σ_b d_b ΔΩ cos(b) lies between
    /// Σ_b mass_b cos(b)/z_max(b) and Σ_b mass_b cos(b)/z_min(b), with cos(b) the bin's exact mean
    /// cosine and z_min/z_max the range of cos θ over the bin (d_b ΔΩ is the bin's mean of 1/cos θ over
    /// its samples times its mass). A wrong weight of the jittered samples (e.g. 1/N instead of
    /// 1/(J N)) breaks the bracket by a factor J.
    #[test]
    fn convolved_truth_integrates_to_one() {
        let n = 128;
        let map = bumpy(n, n, 0.25, 4.0, 1).unwrap();
        let bins = HemisphereBins::new(32).unwrap();
        let r =
            convolved_pndf(&map, &fp(64.0, n), Kernel::Gaussian, &bins, 64_000, 9, 0.01).unwrap();
        assert_eq!(r.samples(), REFERENCE_BATCHES * 63 * 63 * JITTERS);
        let total: f64 = r.mass().iter().sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        let nn = bins.n() as f64;
        let (mut lo, mut hi, mut got) = (0.0, 0.0, 0.0);
        for b in 0..bins.len() {
            let (i, j) = bins.cell(b);
            // Concentric radius max(|a|, |b|) over the cell, a = 2u − 1: z = 1 − r².
            let range = |c: usize| {
                let (a0, a1) = (2.0 * c as f64 / nn - 1.0, 2.0 * (c + 1) as f64 / nn - 1.0);
                let min = if a0 < 0.0 && a1 > 0.0 {
                    0.0
                } else {
                    a0.abs().min(a1.abs())
                };
                (min, a0.abs().max(a1.abs()))
            };
            let ((ri0, ri1), (rj0, rj1)) = (range(i), range(j));
            let (r_min, r_max) = (ri0.max(rj0), ri1.max(rj1));
            let (z_min, z_max) = ((1.0 - r_max * r_max).max(1e-12), 1.0 - r_min * r_min);
            let c = bins.mean_cos(b);
            lo += r.mass()[b] * c / z_max;
            hi += r.mass()[b] * c / z_min;
            got += r.d()[b] * bins.solid_angle() * c;
        }
        // 1e-9: f64 rounding of sums of ~10⁷ terms.
        assert!(lo - 1e-9 <= got && got <= hi + 1e-9, "{lo} ≤ {got} ≤ {hi}");
        assert!((got - 1.0).abs() < 0.02, "{got}");
    }

    /// σ_ε = 0 is the Dirac truth (same positions, bit for bit), and the convolved truth tends to it
    /// as σ_ε → 0: the TV is at most the fraction of slopes that cross a bin edge, which shrinks in
    /// proportion to σ_ε (a bumpy map has no mass concentrated on bin edges).
    #[test]
    fn converges_to_the_dirac_truth() {
        let n = 128;
        let map = bumpy(n, n, 0.25, 4.0, 1).unwrap();
        let bins = HemisphereBins::new(64).unwrap();
        let f = fp(256.0, n);
        let dirac = binned_pndf(&map, &f, Kernel::Gaussian, &bins, 64_000, 11);
        let conv =
            |s: f64| convolved_pndf(&map, &f, Kernel::Gaussian, &bins, 64_000, 11, s).unwrap();
        let zero = conv(0.0);
        assert_eq!(zero.mass(), dirac.mass());
        assert_eq!(zero.d(), dirac.d());
        let tv: Vec<f64> = [1e-2, 1e-3, 1e-4, 1e-5]
            .iter()
            .map(|&s| conv(s).tv_to(&dirac).unwrap())
            .collect();
        for w in tv.windows(2) {
            // Each step divides σ_ε by 10: the TV must fall by well over half.
            assert!(w[1] < 0.5 * w[0], "{tv:?}");
        }
        assert!(tv[3] < 1e-3, "{tv:?}");
    }

    #[test]
    fn bad_sigma_is_an_error() {
        let map = constant_map(Vec2::ZERO);
        let bins = HemisphereBins::new(8).unwrap();
        for s in [-1e-3, f64::NAN, f64::INFINITY, 2.0] {
            let r = convolved_pndf(&map, &fp(1.0, 8), Kernel::Gaussian, &bins, 100, 1, s);
            assert!(matches!(
                r,
                Err(Error::InvalidParameter {
                    name: "sigma_eps",
                    ..
                })
            ));
        }
    }

    /// A lobe much narrower than a bin and straddling bin edges: 2 × 2 points under-read or over-read
    /// it, the adaptive rule converges to the bins' exact masses (each the lobe's mass over the bin,
    /// summing to 1 within the lobe's negligible tails) and reports the grid it needed.
    #[test]
    fn adaptive_quadrature_converges_on_a_spiky_lobe() {
        use crate::ndf::SlopeGaussian;
        let bins = HemisphereBins::new(16).unwrap();
        let lobe = SlopeGaussian::new(
            Vec2::new(0.02, 0.0),
            glam::Mat2::from_diagonal(Vec2::splat(1e-4)),
        )
        .unwrap();
        let fixed = bin_masses(&lobe, &bins, 2);
        let a = adaptive_bin_masses(&lobe, &bins, 1e-3, 64);
        assert!(a.converged && a.k_max >= 8, "{a:?}");
        let total: f64 = a.masses.iter().sum();
        assert!((total - 1.0).abs() < 2e-3, "{total}");
        let fine = bin_masses(&lobe, &bins, 64);
        let err = |m: &[f64]| 0.5 * m.iter().zip(&fine).map(|(x, y)| (x - y).abs()).sum::<f64>();
        assert!(err(&a.masses) < 2e-3, "{}", err(&a.masses));
        assert!(
            err(&fixed) > 10.0 * err(&a.masses),
            "{} {}",
            err(&fixed),
            err(&a.masses)
        );
    }
}
