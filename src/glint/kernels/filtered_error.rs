//! The error of an O(1) level-of-detail form against the exact one, measured once per model: for
//! each level l of a mip chain, the mean error over footprints of 4^l lobe cells (the footprints
//! whose lookup reads level l), so that a patch serves the O(1) form only where it stays within the
//! caller's tolerance. The filtered mixture (gmm.rs) of the mixture and the position-normal map is
//! measured by the total variation to the full P-NDF ([`tv`]; their options' `filtered_tolerance`),
//! the bin map's moment-lobe masking by its G1 error (src/glint/binmap/masking_choice.rs).
//!
//! **TV estimator.** TV(p, q) = ½ ∫ |p − q| = E_r[|p − q| / (p + q)] with r = ½ (p + q), p and q the
//! two patches' normal densities D(m) cos θ_m; [`SAMPLES`] normals, half drawn from each patch
//! by its `sample_normal` on a fixed R2 sequence (deterministic), at [`CENTRES`] fixed footprint
//! centres, averaged. The standard error of the mean is ≤ ½ / √(SAMPLES · CENTRES) ≈ 0.016.
//!
//! Measured by each model's build (the mixture's and position-normal's `measured` step, the bin
//! map's) and stored in its file, so that no frame pays for it.
//!
//! **Which levels.** Measured for footprints of 4^l lobe cells with 4^l in [[`FIRST_AREA`],
//! [`LAST_AREA`]]; the full mixture's `d` costs ~0.1 ms at the last one, which bounds the
//! measurement's time (~0.1-0.3 s per map). Coarser levels take the value measured at [`LAST_AREA`] (the
//! filtered mixture's distance falls as footprints grow and their P-NDFs smooth out: measured in
//! docs/results.md), finer ones are not served by the filtered mixture (error 1).

use crate::glint::Footprint;
use crate::ndf::Ndf;
use glam::{Vec2, Vec3};

/// Normals per footprint centre.
const SAMPLES: usize = 256;
/// Footprint centres per level.
const CENTRES: usize = 4;
/// Smallest footprint (lobe cells) at which the error is measured.
pub(crate) const FIRST_AREA: f64 = 64.0;
/// Largest footprint (lobe cells) at which the error is measured.
const LAST_AREA: f64 = 4096.0;

/// The plastic number g (g³ = g + 1), generator of the R2 sequence.
pub(crate) const PLASTIC: f64 = 1.324_717_957_244_746;

/// Point k of the R2 sequence (Roberts 2018, the additive recurrence with the plastic number):
/// a low-discrepancy point in [0, 1)².
pub(crate) fn r2(k: usize) -> [f64; 2] {
    let a = [1.0 / PLASTIC, 1.0 / (PLASTIC * PLASTIC)];
    a.map(|ai| (0.5 + k as f64 * ai).fract())
}

fn r2_f32(k: usize) -> Vec2 {
    let [x, y] = r2(k);
    Vec2::new(x as f32, y as f32)
}

/// TV between the normal densities D cos θ of two patches, by the estimator of the module docs.
pub(crate) fn tv(p: &impl Ndf, q: &impl Ndf) -> f64 {
    let density = |n: &dyn Fn(Vec3) -> f32, m: Vec3| -> f64 {
        if m.z > 0.0 && m.is_finite() {
            (n(m) * m.z) as f64
        } else {
            0.0
        }
    };
    let mut sum = 0.0;
    for k in 0..SAMPLES {
        let u = r2_f32(k);
        let m = if k % 2 == 0 {
            p.sample_normal(u)
        } else {
            q.sample_normal(u)
        };
        let (a, b) = (density(&|m| p.d(m), m), density(&|m| q.d(m), m));
        if a + b > 0.0 && (a + b).is_finite() {
            sum += (a - b).abs() / (a + b);
        }
    }
    sum / SAMPLES as f64
}

/// Per level l of a mip chain of `levels` levels (index l, level 0 included) over a lobe grid of
/// `grid_area` lobes spaced `spacing` texels on a `map` = (width, height) map, the measured mean
/// error of the O(1) form at footprints of 4^l lobe cells (module docs); `tv_at(footprint)` measures
/// one footprint (`None` when the O(1) form does not serve it). Empty when `levels` is 0.
pub(crate) fn errors_per_level(
    levels: usize,
    grid_area: f64,
    spacing: [f64; 2],
    map: (usize, usize),
    tv_at: impl Fn(&Footprint) -> Option<f64> + Sync,
) -> Vec<f32> {
    use rayon::prelude::*;
    let (w, h) = map;
    let [hx, hy] = spacing;
    let measured: Vec<(usize, f32)> = (0..levels)
        .into_par_iter()
        .filter_map(|l| {
            let area = (1u64 << (2 * l)) as f64;
            if !(FIRST_AREA..=LAST_AREA).contains(&area) || area > grid_area {
                return None;
            }
            let mut sum = 0.0;
            for c in 0..CENTRES {
                let uv = r2_f32(1000 + c);
                let fp = Footprint::isotropic_texels(uv, (area * hx * hy) as f32, w, h);
                sum += tv_at(&fp)?;
            }
            Some((l, (sum / CENTRES as f64) as f32))
        })
        .collect();
    if measured.is_empty() {
        return Vec::new();
    }
    let last = measured.iter().max_by_key(|m| m.0).map_or(1.0, |m| m.1);
    let last_level = measured.iter().map(|m| m.0).max().unwrap_or(0);
    (0..levels)
        .map(|l| {
            measured
                .iter()
                .find(|m| m.0 == l)
                .map_or(if l > last_level { last } else { 1.0 }, |m| m.1)
        })
        .collect()
}

/// The filtered mixture's measured error at level of detail `lod`: the larger of the two levels
/// a trilinear lookup reads (1 where not measured, NaN `lod` → level 0).
pub(crate) fn error_at(errors: &[f32], lod: f64) -> f32 {
    if errors.is_empty() {
        return 1.0;
    }
    let top = errors.len() - 1;
    let lod = if lod.is_nan() {
        0.0
    } else {
        lod.clamp(0.0, top as f64)
    };
    let (lo, hi) = (lod.floor() as usize, (lod.ceil() as usize).min(top));
    errors[lo].max(errors[hi])
}
