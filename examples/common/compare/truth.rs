//! The two ground truths of a footprint (the Dirac truth of the interpolated map and the convolved
//! truth with the material's micro-roughness) and a model's total variation to them.

use super::Settings;
use crate::common::Res;
use brdf::Vec3;
use brdf::glint::{
    BinnedPndf, Footprint, HemisphereBins, Kernel, NormalMap, adaptive_bin_masses, binned_pndf,
    convolved_pndf,
};
use brdf::ndf::Ndf;

/// σ_ε of the convolved truth: the scene's material (\[Chermain2019\] §5.2.2), the σ every method
/// is given ([`crate::common::material::SIGMA_EPS`]); one truth for all keeps the comparison about
/// the surface, not each model's roughness.
pub const SIGMA_EPS: f64 = crate::common::material::SIGMA_EPS as f64;

/// TV of a model to both truths on one binning, each truth's noise floor (`tv_error`), and the
/// quadrature used (means over the footprint centres; `k` the finest grid, `change` the largest
/// final change).
#[derive(Clone, Copy, Debug, Default)]
pub struct TwoTruths {
    pub dirac: f64,
    pub convolved: f64,
    pub noise_dirac: f64,
    pub noise_convolved: f64,
    pub k: usize,
    pub change: f64,
}

/// The Dirac and the convolved truth of one footprint on one binning.
pub struct Truths {
    pub bins: HemisphereBins,
    pub dirac: BinnedPndf,
    pub convolved: BinnedPndf,
}

impl Truths {
    /// Both truths from the same positions (`samples`, `seed`); σ_ε = [`SIGMA_EPS`].
    pub(super) fn new(
        map: &NormalMap,
        fp: &Footprint,
        n_bins: usize,
        samples: usize,
        seed: u64,
    ) -> Res<Self> {
        let bins = HemisphereBins::new(n_bins)?;
        let dirac = binned_pndf(map, fp, Kernel::Gaussian, &bins, samples, seed);
        let convolved = convolved_pndf(map, fp, Kernel::Gaussian, &bins, samples, seed, SIGMA_EPS)?;
        Ok(Truths {
            bins,
            dirac,
            convolved,
        })
    }

    /// The model's TV to both truths, its bin masses from the adaptive quadrature.
    pub(super) fn compare(&self, model: &(dyn Ndf + Sync), settings: &Settings) -> TwoTruths {
        let q = adaptive_bin_masses(
            model,
            &self.bins,
            settings.quadrature_tolerance,
            settings.max_quadrature,
        );
        let tv = |r: &BinnedPndf| r.tv_to_masses(&q.masses).unwrap_or(f64::NAN);
        TwoTruths {
            dirac: tv(&self.dirac),
            convolved: tv(&self.convolved),
            noise_dirac: self.dirac.tv_error(),
            noise_convolved: self.convolved.tv_error(),
            k: q.k_max,
            change: q.change,
        }
    }
}

/// Mean of the TVs and noises over footprint centres; the finest grid and the largest change.
pub(super) fn mean_truths(v: &[TwoTruths]) -> TwoTruths {
    let k = v.len().max(1) as f64;
    let sum = |f: fn(&TwoTruths) -> f64| v.iter().map(f).sum::<f64>() / k;
    TwoTruths {
        dirac: sum(|t| t.dirac),
        convolved: sum(|t| t.convolved),
        noise_dirac: sum(|t| t.noise_dirac),
        noise_convolved: sum(|t| t.noise_convolved),
        k: v.iter().map(|t| t.k).max().unwrap_or(0),
        change: v.iter().map(|t| t.change).fold(0.0, f64::max),
    }
}

/// ∫⟨wo, m⟩⁺ D dm of the ground truth from its bins: Σ_b mass_b ⟨wo, m_b⟩⁺ / cos θ_b (bin centres).
pub(super) fn reference_visible_area(reference: &BinnedPndf, wo: Vec3) -> f64 {
    let bins = reference.bins();
    reference
        .mass()
        .iter()
        .zip(reference.cos_theta())
        .enumerate()
        .filter(|(_, (m, c))| **m > 0.0 && **c > 0.0)
        .map(|(b, (m, c))| m * (bins.center(b).dot(wo) as f64).max(0.0) / c)
        .sum()
}
