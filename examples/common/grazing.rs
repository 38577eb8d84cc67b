//! Grazing-angle stability: where each NDF's masking and each BRDF's sampler break down as θo → 90°.
//!
//! For every analytic NDF (Beckmann, GGX at α = 0.05 and 0.5) and every glint method (a 64-texel
//! patch of the 256² bumpy and scratched maps), over θo from 0° to 89.99°:
//!
//! - **Visible-area error**: |V(wo) − V_ref(wo)| / V_ref(wo), V = A(1 + Λ) = ∫⟨wo, m⟩⁺ D dm, the
//!   quantity every masking term, G1 and visible-normal pdf is built from. Analytic NDFs: V_ref in f64
//!   from the closed forms (Beckmann: ½ cos θ (1 + erf a) + α sin θ e^(−a²)/(2√π), a = cot θ/α; GGX:
//!   ½ (cos θ + √(cos² θ + α² sin² θ))), against the crate's f32 V. Glint patches: V_ref by Monte Carlo
//!   of ∫⟨wo, m⟩⁺ D dm with the patch's own normal sampler (2¹⁴ R2 points, unbiased; its relative
//!   standard error is the floor of what the chart can resolve, written to the CSV).
//! - **White furnace** E(wo) = ∫ f c(wi) dωi with F = 1 and the default `MicrofacetBrdf` (visible-normal
//!   sampling, height-correlated G2), c = cos θi for the analytic lobes and the patch's A_P(wi)⁺ for the
//!   glint patches (the measure they are normalised in); and the **relative spread of the sample weight**
//!   σ_w / E, whose growth is what makes a renderer's noise blow up.
//!
//! `cargo run --release --example grazing -- [--out DIR]` writes `grazing.csv`, three charts and
//! `grazing.md` (also part of the gallery). docs/robustness.md discusses the results.

use super::{Artifact, Chart, Res, Scale, Series, line_chart, r2, view};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintNdf, NormalMap, PositionNormalBrdf, PositionNormalMap,
};
use brdf::ndf::{Beckmann, Ggx, Ndf};
use brdf::{Bxdf, MicrofacetBrdf, Vec2, Vec3};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// View angles (degrees): 90° − θo spans 90° down to 0.01° on the chart's log axis.
pub const THETAS: [f64; 14] = [
    0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 87.0, 88.0, 89.0, 89.5, 89.8, 89.9, 89.95, 89.99,
];

/// One (method, θo) measurement.
#[derive(Clone, Debug)]
pub struct Row {
    /// Method label.
    pub method: String,
    /// View angle θo in degrees.
    pub theta: f64,
    /// |V − V_ref| / V_ref.
    pub v_rel_error: f64,
    /// Relative standard error of V_ref (0 for the closed forms).
    pub v_ref_rel_se: f64,
    /// White furnace E(wo).
    pub furnace: f64,
    /// Standard error of E.
    pub furnace_se: f64,
    /// σ_w / E: relative standard deviation of one sample's weight.
    pub weight_spread: f64,
    /// Fraction of samples the sampler rejected (`None`).
    pub lost: f64,
}

/// Samples per furnace and per Monte Carlo V_ref.
pub struct Settings {
    /// Map side in texels.
    pub map_size: usize,
    /// Footprint area in texels.
    pub footprint: f32,
    /// Samples for the furnace.
    pub furnace_samples: usize,
    /// Samples for the glint V_ref.
    pub v_samples: usize,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings::new()
    }
}

impl Settings {
    /// The example's settings (2¹² furnace samples per point, about two minutes on 2 cores).
    pub fn new() -> Settings {
        Settings {
            map_size: 256,
            footprint: 64.0,
            furnace_samples: 1 << 12,
            v_samples: 1 << 14,
        }
    }

    /// The gallery's preview: a quarter of the samples of [`Settings::new`] each way (2¹⁰ furnace,
    /// 2¹² V_ref samples per point: noise floors twice as high), so that the whole gallery stays
    /// within its time budget.
    pub fn quick() -> Settings {
        Settings {
            furnace_samples: 1 << 10,
            v_samples: 1 << 12,
            ..Settings::new()
        }
    }

    /// Tiny settings for the code-path test.
    pub fn tiny() -> Settings {
        Settings {
            map_size: 16,
            footprint: 16.0,
            furnace_samples: 256,
            v_samples: 1024,
        }
    }
}

/// Beckmann V(w) in f64 at polar angle θ (isotropic α).
fn beckmann_v_ref(alpha: f64, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    if s == 0.0 {
        return c;
    }
    let a = c / (s * alpha);
    0.5 * c * (1.0 + libm::erf(a))
        + alpha * s * (-a * a).exp() / (2.0 * std::f64::consts::PI.sqrt())
}

/// GGX V(w) in f64 at polar angle θ (isotropic α).
fn ggx_v_ref(alpha: f64, theta: f64) -> f64 {
    let (s, c) = theta.sin_cos();
    0.5 * (c + (c * c + alpha * alpha * s * s).sqrt())
}

/// ∫⟨wo, m⟩⁺ D dm by importance sampling with the NDF's normal sampler: (mean, standard error).
fn v_monte_carlo(ndf: &dyn Ndf, wo: Vec3, n: usize) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for k in 0..n {
        let m = ndf.sample_normal(r2(k));
        let p = ndf.pdf_normal(m) as f64;
        let x = if p > 0.0 {
            (wo.dot(m).max(0.0) as f64) * ndf.d(m) as f64 / p
        } else {
            0.0
        };
        sum += x;
        sum2 += x * x;
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

/// Furnace, its standard error, the weight's relative spread and the lost fraction.
fn furnace(brdf: &dyn Bxdf, wo: Vec3, cosine: &Cosine, n: usize) -> [f64; 4] {
    let (mut sum, mut sum2, mut lost) = (0.0f64, 0.0f64, 0usize);
    for k in 0..n {
        let uc = ((k as f64 + 0.5) / n as f64) as f32;
        match brdf.sample(wo, uc, r2(k)) {
            Some(s) => {
                let x = s.f.x as f64 * cosine(s.wi) as f64 / s.pdf as f64;
                sum += x;
                sum2 += x * x;
            }
            None => lost += 1,
        }
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    let spread = if mean > 0.0 { var.sqrt() / mean } else { 0.0 };
    [
        mean,
        (var / n as f64).sqrt(),
        spread,
        lost as f64 / n as f64,
    ]
}

/// One row; the relative errors are NaN where nothing of the patch faces wo (V_ref = 0: a patch
/// whose micronormals all lean away from a grazing view).
fn row(method: &str, theta: f64, v: f64, v_ref: (f64, f64), f: [f64; 4]) -> Row {
    let rel = |x: f64| if v_ref.0 > 0.0 { x / v_ref.0 } else { f64::NAN };
    Row {
        method: method.to_string(),
        theta,
        v_rel_error: rel((v - v_ref.0).abs()),
        v_ref_rel_se: rel(v_ref.1),
        furnace: f[0],
        furnace_se: f[1],
        weight_spread: f[2],
        lost: f[3],
    }
}

/// The cosine a furnace weights its samples by (shared between threads).
type Cosine = dyn Fn(Vec3) -> f32 + Sync;

/// An analytic NDF, its microfacet BRDF, and its f64 closed-form V(α, θ).
type AnalyticModel<'a> = (
    &'static str,
    &'a (dyn Ndf + Sync),
    &'a (dyn Bxdf + Sync),
    fn(f64, f64) -> f64,
);

fn analytic_rows(settings: &Settings) -> Res<Vec<Row>> {
    let mut rows = Vec::new();
    let cos = |w: Vec3| w.z.max(0.0);
    for alpha in [0.05f32, 0.5] {
        let (b, g) = (Beckmann::isotropic(alpha)?, Ggx::isotropic(alpha)?);
        let models: [AnalyticModel; 2] = [
            (
                "Beckmann",
                &b,
                &MicrofacetBrdf::new(b, NoFresnel),
                beckmann_v_ref,
            ),
            ("GGX", &g, &MicrofacetBrdf::new(g, NoFresnel), ggx_v_ref),
        ];
        for (name, ndf, brdf, v_ref) in models {
            let label = format!("{name} α={alpha}");
            // The view angles in parallel (deterministic R2 points: the same rows either way).
            let of_model: Vec<Row> = THETAS
                .par_iter()
                .map(|&theta| {
                    let wo = view(theta);
                    let f = furnace(brdf, wo, &cos, settings.furnace_samples);
                    let v = (v_ref(alpha as f64, theta.to_radians()), 0.0);
                    row(&label, theta, ndf.visible_area(wo) as f64, v, f)
                })
                .collect();
            rows.extend(of_model);
        }
    }
    Ok(rows)
}

/// The rows of one glint patch inside `MicrofacetBrdf`, furnace in the renderer's measure.
fn patch_rows(label: &str, patch: &(dyn Ndf + Sync), settings: &Settings, rows: &mut Vec<Row>) {
    let cos = |w: Vec3| w.z.max(0.0);
    let brdf = MicrofacetBrdf::new(patch, NoFresnel);
    brdf_rows(label, patch, &brdf, &cos, settings, rows);
}

/// The rows of `brdf` built on `patch`: the patch's V against its Monte Carlo reference, and the
/// BRDF's furnace weighted by `cosine`; the view angles in parallel (deterministic R2 points: the
/// same rows either way).
fn brdf_rows(
    label: &str,
    patch: &(dyn Ndf + Sync),
    brdf: &(dyn Bxdf + Sync),
    cosine: &Cosine,
    settings: &Settings,
    rows: &mut Vec<Row>,
) {
    let of_brdf: Vec<Row> = THETAS
        .par_iter()
        .map(|&theta| {
            let wo = view(theta);
            let v_ref = v_monte_carlo(patch, wo, settings.v_samples);
            let f = furnace(brdf, wo, cosine, settings.furnace_samples);
            row(label, theta, patch.visible_area(wo) as f64, v_ref, f)
        })
        .collect();
    rows.extend(of_brdf);
}

fn glint_rows(name: &str, map: &NormalMap, settings: &Settings) -> Res<Vec<Row>> {
    let mut rows = Vec::new();
    let fp = Footprint::isotropic_texels(
        Vec2::new(0.37, 0.61),
        settings.footprint,
        map.width(),
        map.height(),
    );
    let mixture = BeckmannMixture::build(map, MixtureParams::default())?;
    for (mode, label) in [
        (MaskingMode::Exact, "mixture (exact)"),
        (MaskingMode::Approximate, "mixture (approximate)"),
    ] {
        let options = PatchOptions {
            masking: mode,
            ..PatchOptions::default()
        };
        let patch = mixture.patch_with(&fp, &options, None);
        patch_rows(&format!("{name}: {label}"), &patch, settings, &mut rows);
    }
    let bin_map = BinMap::build(map, BinMapParams::default())?;
    patch_rows(
        &format!("{name}: bin map"),
        &bin_map.patch(&fp),
        settings,
        &mut rows,
    );
    patch_rows(
        &format!("{name}: bin map (smoothed α=0.1)"),
        &bin_map.patch_with(
            &fp,
            &brdf::glint::binmap::PatchOptions {
                smoothing_alpha: 0.1,
                ..Default::default()
            },
            None,
        ),
        settings,
        &mut rows,
    );
    let pn = PositionNormalMap::build(map, PositionNormalParams::default())?;
    let patch = pn.patch(&fp);
    patch_rows(
        &format!("{name}: position-normal"),
        &patch,
        settings,
        &mut rows,
    );
    // The published BRDF (cos θo cos θi normalisation), furnace with the geometric cosine: its V
    // column repeats the patch's.
    let published = PositionNormalBrdf::new(&patch, NoFresnel);
    brdf_rows(
        &format!("{name}: position-normal (published BRDF)"),
        &patch,
        &published,
        &|w: Vec3| w.z.max(0.0),
        settings,
        &mut rows,
    );
    Ok(rows)
}

/// Every measurement.
pub fn measure(settings: &Settings) -> Res<Vec<Row>> {
    let n = settings.map_size;
    let mut rows = analytic_rows(settings)?;
    let bumpy = brdf::glint::bumpy(n, n, 0.25, 4.0, 1)?;
    rows.extend(glint_rows("bumpy", &bumpy, settings)?);
    let scratched = brdf::glint::scratched(n, n, brdf::glint::ScratchedParams::default(), 3)?;
    rows.extend(glint_rows("scratched", &scratched, settings)?);
    Ok(rows)
}

/// The methods in order of first appearance.
fn methods(rows: &[Row]) -> Vec<String> {
    let mut m: Vec<String> = Vec::new();
    for r in rows {
        if !m.contains(&r.method) {
            m.push(r.method.clone());
        }
    }
    m
}

/// One series per kept method against 90° − θo, with error bars of half-width `err` if given.
fn series(
    rows: &[Row],
    keep: &dyn Fn(&str) -> bool,
    y: &dyn Fn(&Row) -> f64,
    err: Option<fn(&Row) -> f64>,
) -> Vec<Series> {
    methods(rows)
        .into_iter()
        .filter(|m| keep(m))
        .map(|m| {
            let of_m: Vec<&Row> = rows.iter().filter(|r| r.method == m).collect();
            let pts = of_m.iter().map(|r| (90.0 - r.theta, y(r))).collect();
            let errors = err.map_or(Vec::new(), |e| of_m.iter().map(|r| e(r)).collect());
            Series::new(m, pts).with_errors(errors)
        })
        .collect()
}

/// One chart of the sweep against 90° − θo.
struct GrazingChart {
    file: &'static str,
    title: &'static str,
    y_label: &'static str,
    log_y: bool,
    y_range: (f64, f64),
    /// Include the published position-normal BRDF (its V column repeats the patch's).
    with_published: bool,
    value: fn(&Row) -> f64,
    /// Half-width of the error bar of a point, if the value is an estimate.
    error: Option<fn(&Row) -> f64>,
    caption: &'static str,
}

/// Writes the CSV, the charts and the markdown table.
pub fn report(rows: &[Row], out: &Path) -> Res<(Vec<Artifact>, String)> {
    std::fs::create_dir_all(out)?;
    let mut csv = String::from(
        "method,theta_deg,v_rel_error,v_ref_rel_se,furnace,furnace_se,weight_spread,lost\n",
    );
    for r in rows {
        writeln!(
            csv,
            "\"{}\",{},{:.6e},{:.3e},{:.6},{:.3e},{:.4e},{:.4}",
            r.method,
            r.theta,
            r.v_rel_error,
            r.v_ref_rel_se,
            r.furnace,
            r.furnace_se,
            r.weight_spread,
            r.lost
        )?;
    }
    let csv_path = out.join("grazing.csv");
    std::fs::write(&csv_path, csv)?;
    let mut artifacts = vec![Artifact::new(
        &csv_path,
        "Grazing sweep: every measurement (CSV).",
    )];
    let charts = [
        GrazingChart {
            file: "grazing_visible_area_error.png",
            title: "Visible-area error against view angle",
            y_label: "|V − V_ref| / V_ref",
            log_y: true,
            y_range: (1e-8, 10.0),
            with_published: false,
            value: |r| r.v_rel_error.max(1e-8),
            error: None,
            caption: "Relative error of V(wo) = A(1 + Λ) against 90° − θo: analytic NDFs against f64 \
                      closed forms, glint patches against a Monte Carlo integral of their own D \
                      (floor ≈ its standard error).",
        },
        GrazingChart {
            file: "grazing_furnace.png",
            title: "White furnace against view angle (F = 1)",
            y_label: "E(wo)",
            log_y: false,
            y_range: (0.0, 1.6),
            with_published: true,
            value: |r| r.furnace,
            error: Some(|r| 2.0 * r.furnace_se),
            caption: "White furnace against 90° − θo in the renderer's measure (∫ eval · cos θi \
                      dωi with the geometric cosine) for every model, the published \
                      position-normal BRDF included: the mean sample weight, bars ±2 standard \
                      errors (of independent samples; the R2 points' error is smaller).",
        },
        GrazingChart {
            file: "grazing_weight_spread.png",
            title: "Spread of the sample weight",
            y_label: "σ_w / E",
            log_y: true,
            y_range: (1e-4, 1e3),
            with_published: true,
            value: |r| r.weight_spread.max(1e-4),
            error: None,
            caption: "Relative standard deviation of one sample's weight f·c/pdf (visible-normal \
                      sampling where the model has it) against 90° − θo: where a renderer's noise \
                      grows.",
        },
    ];
    for c in charts {
        let mut chart = Chart::new(c.title, "90° − θo (degrees, log scale)", c.y_label);
        chart.x_scale = Scale::Log;
        if c.log_y {
            chart.y_scale = Scale::Log;
        }
        chart.markers = true;
        chart.size = (900, 560);
        chart.y_range = Some(c.y_range);
        let path = out.join(c.file);
        let keep = |m: &str| c.with_published || !m.contains("published");
        line_chart(&path, &chart, &series(rows, &keep, &c.value, c.error))?;
        artifacts.push(Artifact::new(&path, c.caption));
    }

    let mut md = String::from(
        "| method | θo | V rel. error | (V_ref rel. SE) | furnace | σ_w/E | lost |\n|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        writeln!(
            md,
            "| {} | {} | {:.1e} | {:.0e} | {:.3} ± {:.3} | {:.2} | {:.3} |",
            r.method,
            r.theta,
            r.v_rel_error,
            r.v_ref_rel_se,
            r.furnace,
            r.furnace_se,
            r.weight_spread,
            r.lost
        )?;
    }
    let md_path = out.join("grazing.md");
    std::fs::write(&md_path, &md)?;
    artifacts.push(Artifact::new(
        &md_path,
        "Grazing sweep: the table (markdown).",
    ));
    Ok((artifacts, md))
}

/// Runs the sweep and writes its files (`quick`: [`Settings::quick`], as the gallery runs it).
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let settings = if quick {
        Settings::quick()
    } else {
        Settings::new()
    };
    let rows = measure(&settings)?;
    let (artifacts, _) = report(&rows, out)?;
    Ok(artifacts)
}
