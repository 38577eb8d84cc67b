//! A normal map whose statistics are not those of the crate's generators: the gradient of a
//! fractal (fractional Brownian) height field with the power-law spectrum measured on rough
//! machined and ground metal surfaces, synthesised in the example by a sum of random-phase waves.
//!
//! Height power spectral density P(f) ∝ f^−2(H+1) (isotropic, Hurst exponent H; a self-affine
//! surface, the model profilometry of many rough engineering surfaces fits, e.g. Persson et al.
//! 2005, "On the nature of surface roughness with application to contact mechanics", J. Phys.:
//! Condens. Matter 17 R1). The field is a sum of `waves` cosines with integer wave vectors (so it
//! tiles the map), radial frequencies drawn log-uniformly in [f_min, f_max] cycles per map and
//! directions uniformly: each wave then stands for an equal step of ln f, whose share of the
//! height variance is 2π f² P(f) Δln f ∝ f^−2H, so its amplitude is ∝ f^−H. The slopes are the
//! field's exact gradient (no finite differences), rescaled to a target RMS slope.

use brdf::glint::NormalMap;
use glam::Vec2;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;

/// Settings of [`fractal`].
#[derive(Clone, Copy, Debug)]
pub struct FractalParams {
    /// Hurst exponent H (0 < H < 1): height PSD ∝ f^−2(H+1), slope PSD ∝ f^−2H.
    pub hurst: f32,
    /// RMS slope per axis after rescaling.
    pub rms_slope: f32,
    /// Number of waves.
    pub waves: usize,
    /// Lowest radial frequency, cycles per map.
    pub f_min: f32,
    /// Shortest wavelength, texels (≥ 2: below Nyquist).
    pub min_wavelength: f32,
}

impl Default for FractalParams {
    fn default() -> Self {
        FractalParams {
            hurst: 0.7,
            rms_slope: 0.2,
            waves: 1024,
            f_min: 2.0,
            min_wavelength: 4.0,
        }
    }
}

/// One wave: integer wave vector (cycles per map), slope amplitude and phase.
struct Wave {
    k: [i32; 2],
    amplitude: f32,
    phase: f32,
}

fn waves(size: usize, p: &FractalParams, seed: u64) -> Vec<Wave> {
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed ^ 0x0F2A_C7A1);
    let f_max = size as f32 / p.min_wavelength.max(2.0);
    let (l0, l1) = (p.f_min.ln(), f_max.max(p.f_min).ln());
    (0..p.waves)
        .filter_map(|_| {
            let f = (l0 + rng.random::<f32>() * (l1 - l0)).exp();
            let a = std::f32::consts::TAU * rng.random::<f32>();
            let k = [(f * a.cos()).round() as i32, (f * a.sin()).round() as i32];
            (k != [0, 0]).then(|| Wave {
                k,
                amplitude: f.powf(-p.hurst),
                phase: std::f32::consts::TAU * rng.random::<f32>(),
            })
        })
        .collect()
}

/// A `size` × `size` fractal normal map (module docs): the gradient of
/// h(x, y) = Σ_w A_w cos(2π (k_x x + k_y y)/size + φ_w), rescaled so that each slope axis has RMS
/// `rms_slope`.
pub fn fractal(size: usize, p: &FractalParams, seed: u64) -> brdf::Result<NormalMap> {
    let waves = waves(size, p, seed);
    let n = size as f64;
    // Per-row gradient: ∂h/∂x = −A (2π k_x / size) sin(θ), θ = θ_x + θ_y, sin θ from the angle sum.
    let rows: Vec<Vec<Vec2>> = (0..size)
        .into_par_iter()
        .map(|y| {
            let mut row = vec![[0.0f64; 2]; size];
            for w in &waves {
                let ty = std::f64::consts::TAU * w.k[1] as f64 * y as f64 / n + w.phase as f64;
                let (sy, cy) = ty.sin_cos();
                let g = [
                    -w.amplitude as f64 * std::f64::consts::TAU * w.k[0] as f64 / n,
                    -w.amplitude as f64 * std::f64::consts::TAU * w.k[1] as f64 / n,
                ];
                let dx = std::f64::consts::TAU * w.k[0] as f64 / n;
                for (x, r) in row.iter_mut().enumerate() {
                    let (sx, cx) = (dx * x as f64).sin_cos();
                    let s = sx * cy + cx * sy;
                    r[0] += g[0] * s;
                    r[1] += g[1] * s;
                }
            }
            row.iter()
                .map(|r| Vec2::new(r[0] as f32, r[1] as f32))
                .collect()
        })
        .collect();
    let slopes: Vec<Vec2> = rows.concat();
    let ms = slopes
        .iter()
        .map(|s| s.length_squared() as f64)
        .sum::<f64>()
        / (2.0 * slopes.len().max(1) as f64);
    let scale = if ms > 0.0 {
        (p.rms_slope as f64 / ms.sqrt()) as f32
    } else {
        0.0
    };
    NormalMap::from_slopes(size, size, slopes.iter().map(|s| *s * scale).collect())
}
