//! The white furnace of glint patches against θo, uncompensated (`MicrofacetBrdf` over the patch)
//! and compensated (`ViewCompensated`: the patch's own albedo estimate gives back what its single
//! scattering loses), in the renderer's measure: the mean of `sample().weight()` over stratified
//! draws, F = 1. Part of the energy example and the gallery (`common::energy::run`).

use super::{Artifact, Chart, Res, Series, line_chart, pndf_images};
use brdf::bxdf::{Bxdf, MicrofacetBrdf, ViewCompensated};
use brdf::fresnel::NoFresnel;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{BeckmannMixture, Footprint, GlintModel, GlintNdf, PositionNormalMap};
use brdf::{Vec2, Vec3};
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use std::path::Path;

/// Side of the maps (texels).
const SIDE: usize = 128;

/// Footprint of every patch (texels, isotropic) and its centre.
const TEXELS: f32 = 256.0;
const CENTRE: Vec2 = Vec2::new(0.37, 0.61);

/// Azimuth of the views (degrees).
const PHI_O: f64 = 20.0;

/// Mean and standard error of channel 0 of `sample().weight()` at `wo` over `n` draws stratified in
/// u.x (the estimator of the integration tests).
fn mean_weight(b: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> (f64, f64) {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        let w = b
            .sample(wo, rng.random(), u)
            .map_or(0.0, |x| x.weight().x as f64);
        s += w;
        s2 += w * w;
    }
    let m = s / n as f64;
    (m, ((s2 / n as f64 - m * m).max(0.0) / n as f64).sqrt())
}

/// The charted surfaces: (label, model) at their defaults. The mixture on bumpy and flakes (the
/// darkest maps uncompensated), position-normal on flakes (whose estimate misses the 2 % target at
/// other footprints and views) and the procedural surface (no map).
fn surfaces() -> Res<Vec<(String, GlintModel)>> {
    let mut out = Vec::new();
    for (name, map) in pndf_images::maps(SIDE)? {
        if name == "bumpy" || name == "flakes" {
            let m = BeckmannMixture::build(&map, MixtureParams::default())?;
            out.push((format!("mixture on {name}"), m.into()));
        }
        if name == "flakes" {
            let p = PositionNormalMap::build(&map, Default::default())?;
            out.push((format!("position-normal on {name}"), p.into()));
        }
    }
    let procedural = ProceduralGlints::new(ProceduralParams::default())?;
    out.push(("procedural".to_string(), procedural.into()));
    Ok(out)
}

/// The chart: furnace against θo (every 5°, quick 10°, to 85°) of each surface's patch of
/// [`TEXELS`] texels at [`CENTRE`], uncompensated and compensated; 4,096 draws per point (quick 512).
pub fn furnace_of_glint_patches(out: &Path, quick: bool) -> Res<Artifact> {
    let (step, draws) = if quick { (10.0, 512) } else { (5.0, 4096) };
    let thetas: Vec<f64> = (0..)
        .map(|k| step * k as f64)
        .take_while(|t| *t <= 85.0)
        .collect();
    let surfaces = surfaces()?;
    let footprint = Footprint::isotropic_texels(CENTRE, TEXELS, SIDE, SIDE);
    let mut series = Vec::new();
    let mut csv = String::from("series,theta_o,furnace,standard_error\n");
    let (mut worst_se, mut worst_comp) = (0.0f64, (0.0f64, String::new()));
    for (label, model) in &surfaces {
        let patch = model.patch(&footprint);
        let values: Vec<[(f64, f64); 2]> = thetas
            .par_iter()
            .map(|&t| {
                let (st, ct) = t.to_radians().sin_cos();
                let (sp, cp) = PHI_O.to_radians().sin_cos();
                let wo = Vec3::new((st * cp) as f32, (st * sp) as f32, ct as f32);
                let plain = MicrofacetBrdf::new(patch.clone(), NoFresnel);
                let e = mean_weight(&plain, wo, draws, 7);
                let compensated = ViewCompensated::new(plain, wo)
                    .map_or((0.0, 0.0), |c| mean_weight(&c, wo, draws, 9));
                [e, compensated]
            })
            .collect();
        for (k, kind) in ["uncompensated", "compensated"].into_iter().enumerate() {
            let name = format!("{label} {kind}");
            let pts: Vec<(f64, f64)> = thetas
                .iter()
                .zip(&values)
                .map(|(&t, v)| (t, v[k].0))
                .collect();
            let errors: Vec<f64> = values.iter().map(|v| 2.0 * v[k].1).collect();
            for ((t, e), v) in pts.iter().zip(&values) {
                csv.push_str(&format!("{name},{t},{e:.6},{:.6}\n", v[k].1));
                worst_se = worst_se.max(v[k].1);
                if k == 1 && v[0].0 > 0.0 && (e - 1.0).abs() > worst_comp.0 {
                    worst_comp = ((e - 1.0).abs(), format!("{label} at θo = {t}°: {e:.3}"));
                }
            }
            series.push(Series::new(name, pts).with_errors(errors));
        }
    }
    std::fs::write(out.join("energy_furnace_glint.csv"), csv)?;
    let path = out.join("energy_furnace_glint.png");
    let mut chart = Chart::new(
        "White furnace (F = 1) of glint patches against θo, 256 texels",
        "θo (degrees)",
        "mean sample weight",
    );
    chart.size = (900, 600);
    chart.markers = true;
    chart.legend = plotters::chart::SeriesLabelPosition::LowerLeft;
    line_chart(&path, &chart, &series)?;
    Ok(Artifact::new(
        path,
        format!(
            "White furnace in the renderer's measure (mean of sample().weight(), {draws} stratified \
             draws per point, bars ±2 standard errors, largest standard error {worst_se:.1e}) of \
             glint patches of {TEXELS} texels at uv {CENTRE} on {SIDE}² maps, φo = {PHI_O}°, \
             against θo: MicrofacetBrdf over the patch (uncompensated) and ViewCompensated (the \
             patch's albedo estimate gives back the energy its single scattering loses). Target: \
             within 2 % of 1 for θo ≤ 80° (tests/it/glint_compensation.rs); over all footprints and \
             views position-normal on flakes and scratched and the bin map still miss it \
             (docs/results.md, \"Energy compensation of glint patches\"). Farthest from 1 \
             compensated here: {}; values in energy_furnace_glint.csv (energy example).",
            worst_comp.1
        ),
    ))
}
