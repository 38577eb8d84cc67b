//! Element construction: the slope and Jacobian of the interpolated normal map at each element
//! centre, and the element's footprint-independent slope box.
//!
//! # Reference
//! \[Yan2016\] §4 (linearised elements).

use super::PositionNormalParams;
use crate::glint::NormalMap;
use glam::Vec2;
use rayon::prelude::*;

/// The elements of an `nx × ny` grid of spacing `h` texels, row major:
/// [ñx, ñy, ∂ñx/∂u, ∂ñx/∂v, ∂ñy/∂u, ∂ñy/∂v] at u = ((i + ½) h, (j + ½) h).
///
/// J by central differences of step δ = h/2: ∂ñ/∂u ≈ (ñ(u + δ e_u) − ñ(u − δ e_u)) / (2δ). The
/// interpolated slope field is only piecewise smooth (bilinear normals, kinks at texel centres), so
/// the one-sided derivatives differ at a texel centre; the central difference over one element
/// spacing averages them, which is the secant that best matches the field across the element.
pub(super) fn elements(map: &NormalMap, grid: [usize; 2], h: f64) -> Vec<[f32; 6]> {
    let [nx, ny] = grid;
    let delta = 0.5 * h;
    (0..ny)
        .into_par_iter()
        .flat_map_iter(|j| {
            (0..nx).map(move |i| {
                let u = Vec2::new(((i as f64 + 0.5) * h) as f32, ((j as f64 + 0.5) * h) as f32);
                let s = map.slope_at_texel(u);
                let du = Vec2::new(delta as f32, 0.0);
                let dv = Vec2::new(0.0, delta as f32);
                let su = (map.slope_at_texel(u + du) - map.slope_at_texel(u - du)) / h as f32;
                let sv = (map.slope_at_texel(u + dv) - map.slope_at_texel(u - dv)) / h as f32;
                [s.x, s.y, su.x, sv.x, su.y, sv.y]
            })
        })
        .collect()
}

/// The slope box of an element valid for every footprint: ñ_i ± ((k_w + k_s) σ_h ‖row_k J‖ + k_s σ_r)
/// per axis k, as [x_min, y_min, x_max, y_max].
///
/// Under a footprint the element's slope density is N(ñ_i + J (μ_u − u_i), J Σ_u Jᵀ + σ_r² I)
/// (docs/position_normal.md) with |μ_u − u_i| ≤ k_w σ_h for every kept element and Σ_u ≤ σ_h² I, so
/// along axis k the mean is within k_w σ_h ‖row_k J‖ of ñ_i and the standard deviation is at most
/// σ_h ‖row_k J‖ + σ_r: the box holds at least k_s standard deviations on each side.
pub(super) fn slope_box(e: &[f32; 6], sigma_h: f64, params: &PositionNormalParams) -> [f32; 4] {
    let (kw, ks) = (params.weight_sigmas as f64, params.slope_sigmas as f64);
    let sr = params.sigma_r as f64;
    // The squares of f32 values are exact in f64 and their sum is rounded once, so this is within an
    // f64 ulp of `hypot` (which the f32 margin below dwarfs) at a fraction of its cost; stored
    // Jacobians are bounded (`PositionNormalMap::load` checks), so the squares cannot overflow.
    let norm = |a: f32, b: f32| ((a as f64) * (a as f64) + (b as f64) * (b as f64)).sqrt();
    let row_x = norm(e[2], e[3]);
    let row_y = norm(e[4], e[5]);
    let hx = (kw + ks) * sigma_h * row_x + ks * sr;
    let hy = (kw + ks) * sigma_h * row_y + ks * sr;
    let (sx, sy) = (e[0] as f64, e[1] as f64);
    // Rounded outward so that the f32 box contains the f64 one.
    [
        (sx - hx) as f32 - f32::EPSILON * (sx.abs() + hx) as f32,
        (sy - hy) as f32 - f32::EPSILON * (sy.abs() + hy) as f32,
        (sx + hx) as f32 + f32::EPSILON * (sx.abs() + hx) as f32,
        (sy + hy) as f32 + f32::EPSILON * (sy.abs() + hy) as f32,
    ]
}
