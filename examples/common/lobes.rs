//! Lobe plots of the classic BRDFs: polar plots of f·cos θi in the plane of incidence and false-colour
//! images of f·cos θi over the projected hemisphere, for several incidence angles per model.
//!
//! Polar plots: wo = (sin θo, 0, cos θo) for θo ∈ {0, 30, 60, 80}°; wi = (sin t, 0, cos t) for
//! t ∈ (−90°, 90°), drawn as the points r (sin t, cos t) with r = f(wo, wi)·cos θi (channel 0). Each
//! series starts with a line from the origin toward wo (same colour) so the mirror direction can be
//! read off; the x and z axes have (nearly) the same scale (chart 900 × 480 for a range [−R, R] × [0, R]).
//!
//! Hemisphere images: four panels (θo = 0, 30, 60, 80°, left to right); pixel (x, y) of the unit
//! disk ↔ wi = (x, y, √(1 − x² − y²)), +x to the right (toward wo), +y up; linear colour scale from 0
//! to the largest value of the four panels (so panels compare), black outside the disk and between
//! panels.

use super::{Artifact, Chart, Res, Series, line_chart, save_heatmap};
use brdf::bxdf::{
    BlinnPhongLobe, BlinnPhongNormalization, Bxdf, Lambert, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, Phong, PhongNormalization,
};
use brdf::fresnel::NoFresnel;
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use std::path::Path;

/// Incidence angles shown, degrees.
const THETA_O: [f32; 4] = [0.0, 30.0, 60.0, 80.0];

/// One model to plot: file stem, title, the BRDF.
struct Model {
    stem: &'static str,
    title: String,
    bxdf: Box<dyn Bxdf>,
}

fn model(stem: &'static str, title: impl Into<String>, bxdf: impl Bxdf + 'static) -> Model {
    Model {
        stem,
        title: title.into(),
        bxdf: Box::new(bxdf),
    }
}

/// The models and parameters shown (ρ_d = 0, ρ_s = 1 where the model has both, F = 1).
fn models() -> Res<Vec<Model>> {
    let (z, one) = (Vec3::ZERO, Vec3::ONE);
    let tilted = SlopeGaussian::new(
        Vec2::new(0.3, -0.2),
        Mat2::from_cols_array(&[0.04, 0.015, 0.015, 0.02]),
    )?;
    Ok(vec![
        model("lambert", "Lambert, albedo 1", Lambert::new(one)?),
        model(
            "phong_lafortune_g20",
            "Modified Phong (γ+2)/2π, γ = 20",
            Phong::new(z, one, 20.0, PhongNormalization::EnergyConserving)?,
        ),
        model(
            "phong_lafortune_g200",
            "Modified Phong (γ+2)/2π, γ = 200",
            Phong::new(z, one, 200.0, PhongNormalization::EnergyConserving)?,
        ),
        model(
            "phong_mallett_yuksel_g20",
            "Energy-normalised Phong (Mallett-Yuksel), γ = 20",
            Phong::new(
                z,
                one,
                20.0,
                PhongNormalization::EnergyNormalizedMallettYuksel,
            )?,
        ),
        model(
            "phong_original_g20",
            "Original Phong (γ+1)/2π · cos^γ θr / cos θi, γ = 20",
            OriginalPhong::new(z, one, 20.0, OriginalPhongNormalization::EnergyConserving)?,
        ),
        model(
            "blinn_phong_g80",
            "Blinn-Phong lobe (energy conserving), γ = 80",
            BlinnPhongLobe::new(z, one, 80.0, BlinnPhongNormalization::EnergyConserving)?,
        ),
        model(
            "cook_torrance_beckmann_a0.2",
            "Cook-Torrance (Beckmann α = 0.2, F = 1)",
            MicrofacetBrdf::new(Beckmann::isotropic(0.2)?, NoFresnel),
        ),
        model(
            "cook_torrance_beckmann_a0.5",
            "Cook-Torrance (Beckmann α = 0.5, F = 1)",
            MicrofacetBrdf::new(Beckmann::isotropic(0.5)?, NoFresnel),
        ),
        model(
            "microfacet_ggx_a0.2",
            "Torrance-Sparrow with GGX α = 0.2, F = 1",
            MicrofacetBrdf::new(Ggx::isotropic(0.2)?, NoFresnel),
        ),
        model(
            "microfacet_ggx_a0.5",
            "Torrance-Sparrow with GGX α = 0.5, F = 1",
            MicrofacetBrdf::new(Ggx::isotropic(0.5)?, NoFresnel),
        ),
        model(
            "microfacet_blinn_phong_g48",
            "Microfacet with the Blinn-Phong NDF, γ = 48 (≈ Beckmann α = 0.2)",
            MicrofacetBrdf::new(BlinnPhong::new(48.0)?, NoFresnel),
        ),
        model(
            "microfacet_slope_gaussian",
            "Microfacet, non-centred lobe μ = (0.3, −0.2)",
            MicrofacetBrdf::new(tilted, NoFresnel),
        ),
    ])
}

/// wo in the plane of incidence (φ = 0).
fn wo_of(theta_deg: f32) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin(), 0.0, t.cos())
}

/// f·cos θi (channel 0), 0 where it is not finite.
fn f_cos(b: &dyn Bxdf, wo: Vec3, wi: Vec3) -> f32 {
    let v = b.eval(wo, wi).x * wi.z.max(0.0);
    if v.is_finite() { v } else { 0.0 }
}

/// The polar curve of one incidence angle: r(t) (sin t, cos t) for t ∈ (−90°, 90°).
fn polar_curve(b: &dyn Bxdf, wo: Vec3, n: usize) -> Vec<(f64, f64)> {
    (0..=n)
        .map(|k| {
            let t = -std::f32::consts::FRAC_PI_2 + std::f32::consts::PI * k as f32 / n as f32;
            let wi = Vec3::new(t.sin(), 0.0, t.cos());
            let r = f_cos(b, wo, wi) as f64;
            (r * t.sin() as f64, r * t.cos() as f64)
        })
        .collect()
}

fn polar_plot(out: &Path, m: &Model, quick: bool) -> Res<Artifact> {
    let n = if quick { 360 } else { 2000 };
    let curves: Vec<Vec<(f64, f64)>> = THETA_O
        .iter()
        .map(|&t| polar_curve(m.bxdf.as_ref(), wo_of(t), n))
        .collect();
    let radius = curves
        .iter()
        .flatten()
        .map(|p| p.0.hypot(p.1))
        .fold(0.0, f64::max)
        .max(1e-12);
    let mut series: Vec<Series> = THETA_O
        .iter()
        .zip(curves)
        .map(|(&t, curve)| {
            let w = wo_of(t);
            let mut pts = vec![
                (0.95 * radius * w.x as f64, 0.95 * radius * w.z as f64),
                (0.0, 0.0),
            ];
            pts.extend(curve);
            Series::new(format!("θo = {t}° (line: wo)"), pts)
        })
        .collect();
    series.push(Series::new("horizon", vec![(-radius, 0.0), (radius, 0.0)]));
    let path = out.join(format!("lobe_polar_{}.png", m.stem));
    let title = format!("{}: f·cos θi in the plane of incidence", m.title);
    let mut chart = Chart::new(&title, "x = r sin θi", "z = r cos θi");
    chart.size = (900, 480);
    line_chart(&path, &chart, &series)?;
    Ok(Artifact::new(
        path,
        format!(
            "{}: polar plot of f·cos θi in the plane of incidence for θo = 0, 30, 60, 80° (lines toward wo)",
            m.title
        ),
    ))
}

fn hemisphere_image(out: &Path, m: &Model, quick: bool) -> Res<Artifact> {
    let s: usize = if quick { 96 } else { 256 };
    let gap = s / 16;
    let width = THETA_O.len() * s + (THETA_O.len() - 1) * gap;
    let mut values = vec![f32::NAN; width * s];
    for (p, &t) in THETA_O.iter().enumerate() {
        let wo = wo_of(t);
        let x0 = p * (s + gap);
        for row in 0..s {
            let y = 1.0 - 2.0 * (row as f32 + 0.5) / s as f32;
            for col in 0..s {
                let x = 2.0 * (col as f32 + 0.5) / s as f32 - 1.0;
                let r2 = x * x + y * y;
                if r2 < 1.0 {
                    let wi = Vec3::new(x, y, (1.0 - r2).sqrt());
                    values[row * width + x0 + col] = f_cos(m.bxdf.as_ref(), wo, wi);
                }
            }
        }
    }
    let path = out.join(format!("lobe_hemisphere_{}.png", m.stem));
    save_heatmap(&path, width as u32, s as u32, &values, None)?;
    Ok(Artifact::new(
        path,
        format!(
            "{}: f·cos θi over the projected hemisphere (x right toward wo, y up) for θo = 0, 30, 60, 80°, linear scale shared by the panels",
            m.title
        ),
    ))
}

/// Writes a polar plot and a hemisphere image per model into `out`; `quick` lowers the resolution.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    for m in models()? {
        artifacts.push(polar_plot(out, &m, quick)?);
        artifacts.push(hemisphere_image(out, &m, quick)?);
    }
    Ok(artifacts)
}
