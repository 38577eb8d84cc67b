//! Multiple-scattering energy compensation: the white furnace before and after
//! (`MicrofacetBrdf` against `EnergyCompensated`) against α and θo, isotropic and anisotropic, the
//! same for glint patches (`ViewCompensated`, `common::energy_glint`), and rough gold spheres under
//! a uniform white sky, uncompensated above compensated (the coloured-metal saturation effect).
//!
//! Every analytic furnace value is the integral ∫ f cos θi dωi itself, by the deterministic
//! hemisphere quadrature of `common::quadrature` (the integration tests' rule), at the crate's
//! defaults (height-correlated masking); each chart's caption gives the largest error estimate of
//! its points. The glint chart's values are means of `sample().weight()` (a glint patch's D is too
//! spiky for a fixed rule), with their standard errors.

use super::quadrature;
use super::{Artifact, Chart, Res, Series, line_chart, save_rgb};
use brdf::Vec3;
use brdf::bxdf::{Bxdf, EnergyCompensated, MicrofacetBrdf};
use brdf::fresnel::{ConductorFresnel, NoFresnel};
use brdf::ndf::{Beckmann, Ggx};
use rayon::prelude::*;
use std::path::Path;

fn dir(theta_deg: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin() as f32, 0.0, t.cos() as f32)
}

/// A BRDF that the furnace points share between threads.
type SharedBxdf = Box<dyn Bxdf + Sync>;

/// GGX or Beckmann at `alpha` with F = 1: single scattering and compensated.
fn white_pair(family: &str, alpha: f32) -> Res<[SharedBxdf; 2]> {
    Ok(match family {
        "GGX" => {
            let ss = MicrofacetBrdf::new(Ggx::isotropic(alpha)?, NoFresnel);
            [Box::new(ss), Box::new(EnergyCompensated::new(ss)?)]
        }
        _ => {
            let ss = MicrofacetBrdf::new(Beckmann::isotropic(alpha)?, NoFresnel);
            [Box::new(ss), Box::new(EnergyCompensated::new(ss)?)]
        }
    })
}

/// The white furnace (channel 0) of each pair (single scattering, compensated) at its view θo
/// (degrees) and roughness α, and the largest quadrature error estimate of all. The points run in
/// parallel; each is the deterministic quadrature, so the values do not depend on the threads.
fn furnaces(points: &[([SharedBxdf; 2], f64, f32)]) -> (Vec<(f64, f64)>, f64) {
    let values: Vec<((f64, f64), f64)> = points
        .par_iter()
        .map(|(pair, theta, alpha)| {
            let [(b, eb), (c, ec)] = pair
                .each_ref()
                .map(|bxdf| quadrature::furnace(bxdf.as_ref(), dir(*theta), *alpha as f64));
            ((b[0], c[0]), eb.max(ec))
        })
        .collect();
    let worst = values.iter().map(|v| v.1).fold(0.0, f64::max);
    (values.into_iter().map(|v| v.0).collect(), worst)
}

/// Furnace against α (log axis, `n` + 1 values from 0.01 to 1) at θo = 0°, 60°, 85°, before and
/// after, both families.
fn furnace_against_alpha(out: &Path, n: usize) -> Res<Artifact> {
    let alphas: Vec<f32> = (0..=n)
        .map(|k| 0.01 * 100f32.powf(k as f32 / n as f32))
        .collect();
    let curves: Vec<(&str, f64)> = ["GGX", "Beckmann"]
        .into_iter()
        .flat_map(|family| [0.0, 60.0, 85.0].map(|theta| (family, theta)))
        .collect();
    let mut points = Vec::new();
    for &(family, theta) in &curves {
        for &a in &alphas {
            points.push((white_pair(family, a)?, theta, a));
        }
    }
    let (values, worst) = furnaces(&points);
    let mut series = Vec::new();
    for (&(family, theta), e) in curves.iter().zip(values.chunks(alphas.len())) {
        let before = alphas
            .iter()
            .zip(e)
            .map(|(&a, v)| (a as f64, v.0))
            .collect();
        let after = alphas
            .iter()
            .zip(e)
            .map(|(&a, v)| (a as f64, v.1))
            .collect();
        series.push(Series::new(format!("{family} {theta}° single"), before));
        series.push(Series::new(format!("{family} {theta}° compensated"), after));
    }
    // The charted values, for reading off (series label, α, E).
    let mut csv = String::from("series,alpha,furnace\n");
    for s in &series {
        for (a, e) in &s.points {
            csv.push_str(&format!("{},{a:.5},{e:.6}\n", s.label));
        }
    }
    std::fs::write(out.join("energy_furnace_alpha.csv"), csv)?;
    let path = out.join("energy_furnace_alpha.png");
    let mut chart = Chart::new(
        "White furnace (F = 1) against α, θo = 0°, 60°, 85°",
        "α (log scale)",
        "∫ f cos θi dωi",
    );
    chart.x_scale = super::Scale::Log;
    chart.size = (900, 560);
    chart.legend = plotters::chart::SeriesLabelPosition::LowerLeft;
    line_chart(&path, &chart, &series)?;
    Ok(Artifact::new(
        path,
        format!(
            "White furnace ∫ f cos θi dωi of MicrofacetBrdf (single scattering) and \
             EnergyCompensated (Kulla-Conty), GGX and Beckmann, against α at θo = 0°, 60°, 85° \
             (legend: family, θo): the single-scattering loss and its compensation to 1 (target \
             |E − 1| ≤ 0.5 %, tests/it/energy_compensation.rs). Deterministic hemisphere \
             quadrature over the half vector, not Monte Carlo: largest error estimate of any \
             point {worst:.1e}; values in energy_furnace_alpha.csv (energy example)."
        ),
    ))
}

/// Furnace against θo (every `step` degrees below 90°) at α = 0.25, 0.5, 1 (GGX), before and after.
fn furnace_against_theta(out: &Path, step: f64) -> Res<Artifact> {
    let thetas: Vec<f64> = (0..)
        .map(|k| step * k as f64)
        .take_while(|t| *t < 90.0)
        .collect();
    let alphas = [0.25f32, 0.5, 1.0];
    let mut points = Vec::new();
    for alpha in alphas {
        for &t in &thetas {
            points.push((white_pair("GGX", alpha)?, t, alpha));
        }
    }
    let (values, worst) = furnaces(&points);
    let mut series = Vec::new();
    for (alpha, e) in alphas.iter().zip(values.chunks(thetas.len())) {
        let before = thetas.iter().zip(e).map(|(&t, v)| (t, v.0)).collect();
        let after = thetas.iter().zip(e).map(|(&t, v)| (t, v.1)).collect();
        series.push(Series::new(format!("GGX α={alpha} single"), before));
        series.push(Series::new(format!("GGX α={alpha} compensated"), after));
    }
    let path = out.join("energy_furnace_theta.png");
    let mut chart = Chart::new(
        "White furnace (F = 1) against θo, GGX",
        "θo (degrees)",
        "∫ f cos θi dωi",
    );
    chart.size = (900, 560);
    chart.legend = plotters::chart::SeriesLabelPosition::LowerLeft;
    line_chart(&path, &chart, &series)?;
    Ok(Artifact::new(
        path,
        format!(
            "White furnace against θo (0°…88°) for GGX α = 0.25, 0.5, 1, single scattering and \
             compensated, by the deterministic hemisphere quadrature (largest error estimate \
             {worst:.1e}); the target is |E − 1| ≤ 0.5 % for θo ≤ 85° (energy example)."
        ),
    ))
}

/// The anisotropic pairs of the chart: (family, αx, αy).
const ANISOTROPIC: [(&str, f32, f32); 2] = [("GGX", 0.2, 0.8), ("Beckmann", 0.05, 0.5)];

/// GGX or Beckmann at (αx, αy) with F = 1: single scattering and compensated.
fn white_anisotropic_pair(family: &str, ax: f32, ay: f32) -> Res<[SharedBxdf; 2]> {
    Ok(match family {
        "GGX" => {
            let ss = MicrofacetBrdf::new(Ggx::new(ax, ay)?, NoFresnel);
            [Box::new(ss), Box::new(EnergyCompensated::new(ss)?)]
        }
        _ => {
            let ss = MicrofacetBrdf::new(Beckmann::new(ax, ay)?, NoFresnel);
            [Box::new(ss), Box::new(EnergyCompensated::new(ss)?)]
        }
    })
}

/// Furnace against θo (every `step` degrees below 90°) of two anisotropic surfaces, the view along
/// each axis (φo = 0°: x, 90°: y) and 2.5° from the smooth one, single scattering and compensated.
fn furnace_anisotropic(out: &Path, step: f64) -> Res<Artifact> {
    let thetas: Vec<f64> = (0..)
        .map(|k| step * k as f64)
        .take_while(|t| *t < 90.0)
        .collect();
    let curves: Vec<(&str, f32, f32, f64)> = ANISOTROPIC
        .iter()
        .flat_map(|&(f, ax, ay)| [0.0, 2.5, 90.0].map(|phi| (f, ax, ay, phi)))
        .collect();
    let points: Vec<([SharedBxdf; 2], Vec3, (f64, f64))> = curves
        .iter()
        .flat_map(|&(f, ax, ay, phi)| {
            thetas.iter().map(move |&t| {
                let (st, ct) = t.to_radians().sin_cos();
                let (sp, cp) = phi.to_radians().sin_cos();
                let wo = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
                white_anisotropic_pair(f, ax, ay).map(|p| (p, wo, (ax as f64, ay as f64)))
            })
        })
        .collect::<Res<_>>()?;
    let values: Vec<((f64, f64), f64)> = points
        .par_iter()
        .map(|(pair, wo, (ax, ay))| {
            let [single, compensated] = pair;
            let (b, eb) = quadrature::furnace_anisotropic(single.as_ref(), *wo, *ax, *ay);
            let (c, ec) = quadrature::furnace_anisotropic_plus_smooth(
                compensated.as_ref(),
                single.as_ref(),
                *wo,
                *ax,
                *ay,
            );
            ((b[0], c[0]), eb.max(ec))
        })
        .collect();
    let worst = values.iter().map(|v| v.1).fold(0.0, f64::max);
    let mut series = Vec::new();
    let mut csv = String::from("series,theta_o,furnace\n");
    for (&(f, ax, ay, phi), e) in curves.iter().zip(values.chunks(thetas.len())) {
        for (k, kind) in ["single", "compensated"].into_iter().enumerate() {
            let pts: Vec<(f64, f64)> = thetas
                .iter()
                .zip(e)
                .map(|(&t, v)| (t, if k == 0 { v.0.0 } else { v.0.1 }))
                .collect();
            let label = format!("{f} ({ax}, {ay}) φo={phi}° {kind}");
            for (t, v) in &pts {
                csv.push_str(&format!("{label},{t},{v:.6}\n"));
            }
            series.push(Series::new(label, pts));
        }
    }
    std::fs::write(out.join("energy_furnace_anisotropic.csv"), csv)?;
    let path = out.join("energy_furnace_anisotropic.png");
    let mut chart = Chart::new(
        "White furnace (F = 1) against θo, anisotropic NDFs",
        "θo (degrees)",
        "∫ f cos θi dωi",
    );
    chart.size = (900, 600);
    chart.legend = plotters::chart::SeriesLabelPosition::LowerLeft;
    line_chart(&path, &chart, &series)?;
    Ok(Artifact::new(
        path,
        format!(
            "White furnace against θo (0°…{}°) of anisotropic MicrofacetBrdf (single scattering) and \
             EnergyCompensated (the anisotropic table E(μ, φo, αx, αy)), GGX (0.2, 0.8) and \
             Beckmann (0.05, 0.5), viewed along x (φo = 0°, the smooth axis), 2.5° from it and along \
             y (90°); the target is |E − 1| ≤ 1 % and E ≤ 1.005 for θo ≤ 85° \
             (tests/it/energy_compensation.rs). Quadrature over the stretched half vector (the \
             compensation lobe over wi; largest error estimate {worst:.1e}); values in energy_furnace_anisotropic.csv (energy example).",
            thetas.last().copied().unwrap_or(0.0)
        ),
    ))
}

/// sRGB encoding of a linear value in [0, 1].
fn srgb(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// The directional albedo (RGB) of a BRDF of roughness `alpha` on `steps` + 1 values of
/// μ = cos θo in [0, 1], by quadrature (the values in parallel, each deterministic); the largest
/// error estimate so far kept in `worst`.
fn albedo_curve(b: &(dyn Bxdf + Sync), alpha: f32, steps: usize, worst: &mut f64) -> Vec<Vec3> {
    let values: Vec<([f64; 3], f64)> = (0..=steps)
        .into_par_iter()
        .map(|k| {
            let mu = (k as f32 / steps as f32).max(1e-3);
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            quadrature::furnace(b, wo, alpha as f64)
        })
        .collect();
    values
        .into_iter()
        .map(|(e, err)| {
            *worst = worst.max(err);
            Vec3::new(e[0] as f32, e[1] as f32, e[2] as f32)
        })
        .collect()
}

/// Rough gold spheres under a uniform white sky (radiance 1): a pixel's radiance is the directional
/// albedo at its μ = n·v, so each sphere shows E(μ) from its centre (μ = 1) to its rim (μ → 0).
/// Top row: single scattering; bottom row: compensated; α = 0.2, 0.4, 0.7, 1 from left to right.
fn gold_spheres(out: &Path, steps: usize) -> Res<Artifact> {
    let alphas = [0.2f32, 0.4, 0.7, 1.0];
    let r = 80usize;
    let cell = 2 * r + 16;
    let (w, h) = (cell * alphas.len(), cell * 2);
    let mut rgb = vec![24u8; w * h * 3];
    let mut means = Vec::new();
    let mut worst = 0.0f64;
    for (col, &alpha) in alphas.iter().enumerate() {
        let ss = MicrofacetBrdf::new(Ggx::isotropic(alpha)?, ConductorFresnel::GOLD);
        let ms = EnergyCompensated::new(ss)?;
        let curves = [
            albedo_curve(&ss, alpha, steps, &mut worst),
            albedo_curve(&ms, alpha, steps, &mut worst),
        ];
        for (row, curve) in curves.into_iter().enumerate() {
            means.push((alpha, row, curve[steps]));
            let (cx, cy) = (col * cell + cell / 2, row * cell + cell / 2);
            for py in 0..2 * r {
                for px in 0..2 * r {
                    let x = (px as f32 + 0.5 - r as f32) / r as f32;
                    let y = (py as f32 + 0.5 - r as f32) / r as f32;
                    let d2 = x * x + y * y;
                    if d2 >= 1.0 {
                        continue;
                    }
                    let mu = (1.0 - d2).sqrt();
                    let t = mu * steps as f32;
                    let i = (t as usize).min(steps - 1);
                    let e = curve[i].lerp(curve[i + 1], t - i as f32);
                    let (ix, iy) = (cx - r + px, cy - r + py);
                    let o = (iy * w + ix) * 3;
                    rgb[o] = srgb(e.x);
                    rgb[o + 1] = srgb(e.y);
                    rgb[o + 2] = srgb(e.z);
                }
            }
        }
    }
    let path = out.join("energy_gold_spheres.png");
    save_rgb(&path, w as u32, h as u32, rgb)?;
    let centre: Vec<String> = means
        .iter()
        .map(|(a, row, e)| {
            let kind = if *row == 0 { "single" } else { "compensated" };
            format!("α={a} {kind} ({:.3}, {:.3}, {:.3})", e.x, e.y, e.z)
        })
        .collect();
    Ok(Artifact::new(
        path,
        format!(
            "Rough gold (ConductorFresnel::GOLD, GGX) spheres under a uniform white sky, dark \
             background: single scattering (top) against Kulla-Conty compensated (bottom), α = 0.2, \
             0.4, 0.7, 1 left to right. A pixel is the directional albedo at its cos θo \
             (hemisphere quadrature on {} values of μ, linear between them, largest error \
             estimate {worst:.1e}). \
             Compensation brightens rough gold and saturates it (red gains more than blue). Centre \
             albedo: {}.",
            steps + 1,
            centre.join("; ")
        ),
    ))
}

/// Writes the energy-compensation charts into `out`. Every analytic value is the deterministic
/// quadrature; `quick` (the gallery's preview) computes fewer of them: 13 values of α instead of 25,
/// θo every 4° instead of 2° (anisotropic: 8° instead of 4°), the spheres' albedo on 33 values of μ
/// instead of 129, and the glint chart every 10° with 512 draws per point instead of every 5° with
/// 4,096.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let (n_alpha, theta_step, mu_steps) = if quick { (12, 4.0, 32) } else { (24, 2.0, 128) };
    Ok(vec![
        furnace_against_alpha(out, n_alpha)?,
        furnace_against_theta(out, theta_step)?,
        furnace_anisotropic(out, 2.0 * theta_step)?,
        super::energy_glint::furnace_of_glint_patches(out, quick)?,
        gold_spheres(out, mu_steps)?,
    ])
}
