//! The comparison's charts: accuracy against cost with the Pareto front, error and costs against
//! footprint size, and visible-area error and white furnace against view angle. Each chart's caption
//! (its [`Artifact`]) says what is compared, on which inputs and with which measure.

use super::{AccuracyRow, MethodSummary, Results, Settings, ViewRow, geo_mean, mean, pareto};
use crate::common::{Artifact, Chart, Res, Scale, Series, line_chart};
use std::path::Path;

/// Names of the two truths, for titles and captions.
const TRUTHS: [&str; 2] = [
    "Dirac truth (interpolated map)",
    "convolved truth (σ_ε = 0.01)",
];

/// Accuracy against time, per truth: one point per method (mean TV over maps and footprints of
/// ≥ 1 texel, geometric-mean BRDF eval time), and the Pareto front.
pub(super) fn accuracy_vs_time(
    summary: &[MethodSummary],
    size: usize,
    out: &Path,
) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    for (file, truth, pick) in [
        (
            "compare_accuracy_vs_time.png",
            TRUTHS[0],
            (|s: &MethodSummary| s.tv_dirac) as fn(&MethodSummary) -> f64,
        ),
        ("compare_accuracy_vs_time_convolved.png", TRUTHS[1], |s| {
            s.tv_convolved
        }),
    ] {
        let front = pareto(
            &summary
                .iter()
                .map(|s| (s.eval_us, pick(s)))
                .collect::<Vec<_>>(),
        );
        // The front first (underneath), then one marker per method on top.
        let mut series = vec![Series::new("Pareto front", front)];
        series.extend(
            summary
                .iter()
                .map(|s| Series::new(s.method.clone(), vec![(s.eval_us, pick(s))])),
        );
        let path = out.join(file);
        let title = format!("Accuracy against cost, {truth} ({size}² maps)");
        let mut chart = Chart::new(
            &title,
            "BRDF eval time (µs, geometric mean)",
            "mean TV (63² bins)",
        );
        chart.x_scale = Scale::Log;
        chart.markers = true;
        line_chart(&path, &chart, &series)?;
        artifacts.push(Artifact::new(
            path,
            format!(
                "Accuracy against cost: mean total variation to the {truth} (63² bins) over the \
                 four maps and footprints of 1 texel and more, against the geometric-mean time of \
                 one BRDF evaluation; the line joins the methods no other beats on both."
            ),
        ));
    }
    Ok(artifacts)
}

/// Per method, one point per footprint size: `stat` of `value` over the maps (and centres).
fn by_area(
    results: &Results,
    settings: &Settings,
    methods: &[String],
    value: &dyn Fn(&AccuracyRow) -> f64,
    stat: &dyn Fn(&mut dyn Iterator<Item = f64>) -> f64,
) -> Vec<Series> {
    methods
        .iter()
        .map(|m| {
            let pts = settings
                .areas
                .iter()
                .map(|&a| {
                    let mut rows = results
                        .accuracy
                        .iter()
                        .filter(|r| &r.method == m && r.area == a)
                        .map(value);
                    (a as f64, stat(&mut rows))
                })
                .collect();
            Series::new(m.clone(), pts)
        })
        .collect()
}

/// Error against footprint size, per truth (mean TV over the maps and centres, 63² bins).
pub(super) fn error_vs_footprint(
    results: &Results,
    settings: &Settings,
    methods: &[String],
    out: &Path,
) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    for (file, truth, value) in [
        (
            "compare_error_vs_footprint.png",
            TRUTHS[0],
            (|r: &AccuracyRow| r.tv.dirac) as fn(&AccuracyRow) -> f64,
        ),
        ("compare_error_vs_footprint_convolved.png", TRUTHS[1], |r| {
            r.tv.convolved
        }),
    ] {
        let series = by_area(results, settings, methods, &value, &|v| mean(v));
        let path = out.join(file);
        let title = format!("P-NDF error against footprint size, {truth}");
        let mut chart = Chart::new(&title, "footprint (texels)", "mean TV (63² bins)");
        chart.x_scale = Scale::Log;
        chart.markers = true;
        line_chart(&path, &chart, &series)?;
        artifacts.push(Artifact::new(
            path,
            format!(
                "Total variation to the {truth} (63² bins) against footprint size, mean over the \
                 four maps and the footprint centres (noise floors, 127² bins and the quadrature used are \
                 in compare_accuracy.csv)."
            ),
        ));
    }
    Ok(artifacts)
}

/// Cost against footprint size: the per-direction `d` and the per-shading-point `patch()`.
pub(super) fn cost_vs_footprint(
    results: &Results,
    settings: &Settings,
    methods: &[String],
    out: &Path,
) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    for (name, value, what, caption) in [
        (
            "compare_d_time_vs_footprint.png",
            &(|r: &AccuracyRow| r.d_s * 1e6) as &dyn Fn(&AccuracyRow) -> f64,
            "D evaluation time against footprint size",
            "Time of one D(h) evaluation (µs, geometric mean over maps and centres, one thread) \
             against footprint size: flat for the bin map (Atanasov 2020's claim), linear in the \
             footprint's lobes or elements for the mixture and the position-normal baseline.",
        ),
        (
            "compare_patch_time_vs_footprint.png",
            &(|r: &AccuracyRow| r.patch_s * 1e6) as &dyn Fn(&AccuracyRow) -> f64,
            "patch() time against footprint size",
            "Time of one patch() (per shading point; µs, geometric mean, one thread) against \
             footprint size.",
        ),
    ] {
        let path = out.join(name);
        let mut chart = Chart::new(what, "footprint (texels)", "µs (log scale)");
        chart.x_scale = Scale::Log;
        chart.y_scale = Scale::Log;
        chart.markers = true;
        line_chart(
            &path,
            &chart,
            &by_area(results, settings, methods, value, &|v| geo_mean(v)),
        )?;
        artifacts.push(Artifact::new(path, caption));
    }
    Ok(artifacts)
}

/// Per method, one point per view angle: `f` of the view rows, mean over the maps.
fn by_theta(
    results: &Results,
    settings: &Settings,
    view_methods: &[String],
    f: &dyn Fn(&ViewRow) -> f64,
) -> Vec<Series> {
    view_methods
        .iter()
        .map(|m| {
            let pts = settings
                .thetas
                .iter()
                .map(|&t| {
                    let v = mean(
                        results
                            .view
                            .iter()
                            .filter(|r| &r.method == m && r.theta == t)
                            .map(f),
                    );
                    (t, v)
                })
                .collect();
            Series::new(m.clone(), pts)
        })
        .collect()
}

/// Visible-area error and white furnace (the renderer's measure) against view angle.
pub(super) fn view_angle(
    results: &Results,
    settings: &Settings,
    view_methods: &[String],
    out: &Path,
) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    let title = format!(
        "Visible-area error against view angle ({} texels)",
        settings.view_area
    );
    let path = out.join("compare_error_vs_view.png");
    let mut chart = Chart::new(&title, "θo (degrees)", "relative error of V(wo)");
    chart.y_scale = Scale::Log;
    chart.markers = true;
    line_chart(
        &path,
        &chart,
        &by_theta(results, settings, view_methods, &|r| r.v_rel_error),
    )?;
    artifacts.push(Artifact::new(
        path,
        "Relative error of the visible projected area ∫⟨wo,m⟩⁺D dm against the ground truth's, mean \
         over the maps: where normalisation and masking fail near grazing.",
    ));
    let title = format!(
        "White furnace, renderer's measure ({} texels)",
        settings.view_area
    );
    let path = out.join("compare_energy_vs_view.png");
    let mut chart = Chart::new(&title, "θo (degrees)", "∫ f cos θi dωi");
    chart.markers = true;
    // Error bars: ±2 standard errors of the mean over the m maps, √(Σ se²) / m = √(mean se² / m).
    let mut maps: Vec<&str> = results.view.iter().map(|r| r.map).collect();
    maps.sort_unstable();
    maps.dedup();
    let m = maps.len().max(1) as f64;
    let furnace: Vec<Series> = by_theta(results, settings, view_methods, &|r| r.furnace)
        .into_iter()
        .zip(by_theta(results, settings, view_methods, &|r| {
            r.furnace_se * r.furnace_se
        }))
        .map(|(s, var)| {
            let bars = var.points.iter().map(|p| 2.0 * (p.1 / m).sqrt()).collect();
            s.with_errors(bars)
        })
        .collect();
    line_chart(&path, &chart, &furnace)?;
    artifacts.push(Artifact::new(
        path,
        "White furnace (F = 1) as a renderer integrates it, ∫ eval · cos θi dωi with the geometric \
         cosine (mean of sample().weight()), mean over the maps, bars ±2 standard errors: ≤ 1 for \
         an energy-conserving model.",
    ));
    Ok(artifacts)
}
