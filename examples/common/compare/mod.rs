//! Accuracy against speed for every glint method: the comparison harness of `examples/compare.rs`.
//!
//! For each procedural map and each method (× setting), it measures
//! - the P-NDF's total-variation distance to two ground truths, per footprint size, averaged over
//!   the footprint centres (three; one with `--quick`) (Gaussian kernel, equal-area bins):
//!   - the **Dirac truth** (`binned_pndf`): the P-NDF of the interpolated normal map itself;
//!   - the **convolved truth** (`convolved_pndf`): the same surface with the material's micro-roughness,
//!     each position's normal spread by the slope Gaussian of σ_ε = 0.01 ([`truth::SIGMA_EPS`]);
//!
//!   both on 63² bins, and on 127² bins as well for footprints up to [`Settings::fine_up_to`] texels,
//!   where 63² bins (~0.045 in slope near the pole, 4.5 σ_ε) blur the glints. The bin counts are odd
//!   ([`measure::COARSE_BINS`]): the pole is the centre of a bin, not the corner of four, so the
//!   flat texels of the Dirac truth do not favour σ = 0 models over those that add σ_ε. Each model's bin masses
//!   come from `adaptive_bin_masses` (midpoint grids refined per bin 2 × 2 → 4 × 4 → … until the
//!   masses change by less than 10⁻³ in TV), and the grid reached is reported;
//! - the cost: build time, bytes per texel, patch construction, one `d` and one BRDF evaluation
//!   (single thread, precomputed inputs, mean over a batch);
//! - per view angle θo (one footprint size): the relative error of the visible projected area
//!   V(wo) = ∫⟨wo, m⟩⁺ D dm against the ground truth's (from its bins), where masking and
//!   normalisation fail at grazing angles, and the white furnace (F = 1) in the patch's own measure
//!   ∫ f A_P(wi)⁺ dωi and with the geometric cosine ∫ f cos θi dωi (docs/mixture.md, "Energy").
//!
//! It writes CSV tables and PNG charts (accuracy against time with the Pareto front, error against
//! footprint size, error and energy against view angle) and prints markdown tables.
//!
//! Methods plug in through [`methods::Method`] (an object-safe view of `brdf::glint::GlintNdf` plus
//! the method's own BRDF); [`methods::builders`] lists them. Every method renders the one material
//! of the convolved truth, σ_ε included ([`crate::common::material`]); the bin map and the
//! position-normal baseline are also shown at their papers' own σ, labelled "paper default".
//!
//! Layout: [`methods`] (the methods compared), [`truth`] (the ground truths and the TV to them),
//! [`measure`](mod@measure) (running the methods), [`table`] (CSV files and markdown tables),
//! [`chart`] (the PNG charts); [`report`] writes the tables and charts, [`run`] is the example's
//! entry point.

mod chart;
pub mod measure;
pub mod methods;
mod table;
pub mod truth;

pub use measure::{AccuracyRow, Results, Settings, ViewRow, measure};
pub use truth::TwoTruths;

use super::{Artifact, Res};
use std::path::Path;
use std::time::Instant;

/// Writes the CSV files and charts into `out`; returns the artifacts and the markdown tables.
pub fn report(results: &Results, settings: &Settings, out: &Path) -> Res<(Vec<Artifact>, String)> {
    std::fs::create_dir_all(out)?;
    table::write_csv(results, out)?;
    let methods = labels(results.accuracy.iter().map(|r| &r.method));
    let view_methods = labels(results.view.iter().map(|r| &r.method));
    let summary = MethodSummary::all(results, &methods);
    let mut artifacts = chart::accuracy_vs_time(&summary, settings.size, out)?;
    artifacts.extend(chart::error_vs_footprint(results, settings, &methods, out)?);
    artifacts.extend(chart::cost_vs_footprint(results, settings, &methods, out)?);
    artifacts.extend(chart::view_angle(results, settings, &view_methods, out)?);
    let md = table::markdown(results, settings, &methods, &view_methods, &summary)?;
    std::fs::write(out.join("compare_tables.md"), &md)?;
    Ok((artifacts, md))
}

/// The example's entry point: measure, write, return the artifacts.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    run_with(out, &Settings::new(quick))
}

/// [`run`] on the given settings (the gallery's [`Settings::preview`]).
pub fn run_with(out: &Path, settings: &Settings) -> Res<Vec<Artifact>> {
    let t = Instant::now();
    let results = measure(settings, &mut |s| {
        eprintln!("[{:6.1} s] {s}", t.elapsed().as_secs_f64())
    })?;
    let (artifacts, md) = report(&results, settings, out)?;
    println!("{md}");
    Ok(artifacts)
}

/// One method's summary over maps and footprints of ≥ 1 texel: the geometric-mean BRDF eval time
/// and the mean TV to each truth (the accuracy-against-cost charts and the first table).
struct MethodSummary {
    method: String,
    /// BRDF eval time, µs (geometric mean).
    eval_us: f64,
    /// Mean TV to the Dirac truth (63² bins).
    tv_dirac: f64,
    /// Mean TV to the convolved truth (63² bins).
    tv_convolved: f64,
}

impl MethodSummary {
    /// The summary of every method, in the order of `methods`.
    fn all(results: &Results, methods: &[String]) -> Vec<MethodSummary> {
        methods
            .iter()
            .map(|m| {
                let rows = || {
                    results
                        .accuracy
                        .iter()
                        .filter(move |r| &r.method == m && r.area >= 1.0)
                };
                MethodSummary {
                    method: m.clone(),
                    eval_us: geo_mean(rows().map(|r| r.eval_s * 1e6)),
                    tv_dirac: mean(rows().map(|r| r.tv.dirac)),
                    tv_convolved: mean(rows().map(|r| r.tv.convolved)),
                }
            })
            .collect()
    }
}

/// Method labels in first-seen order.
fn labels<'a>(rows: impl Iterator<Item = &'a String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for l in rows {
        if !out.contains(l) {
            out.push(l.clone());
        }
    }
    out
}

/// Arithmetic mean (NaN for none).
fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// Geometric mean (for times spanning decades).
fn geo_mean(v: impl Iterator<Item = f64>) -> f64 {
    mean(v.map(|x| x.max(1e-15).ln())).exp()
}

/// The non-dominated points (lower time and lower error), sorted by time.
pub fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for q in p {
        if q.1 < best {
            best = q.1;
            front.push(q);
        }
    }
    front
}
