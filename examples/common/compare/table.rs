//! The comparison's tables: the three CSV files (accuracy and costs, view angles, builds) and the
//! markdown tables (summary per method, TV per footprint size on 63² and 127² bins, `d` time per
//! footprint size, visible-area error and furnace per view angle).

use super::{AccuracyRow, MethodSummary, Results, Settings, TwoTruths, ViewRow, geo_mean, mean};
use crate::common::Res;
use std::fmt::Write as _;
use std::path::Path;

/// Writes compare_accuracy.csv, compare_view.csv and compare_build.csv into `out`.
pub(super) fn write_csv(results: &Results, out: &Path) -> Res<()> {
    std::fs::write(out.join("compare_accuracy.csv"), accuracy_csv(results)?)?;
    std::fs::write(out.join("compare_view.csv"), view_csv(results)?)?;
    std::fs::write(out.join("compare_build.csv"), build_csv(results)?)?;
    Ok(())
}

/// A CSV field in double quotes (method labels hold commas), inner quotes doubled.
fn quoted(s: &str) -> String {
    format!("\"{}\"", s.replace('"', "\"\""))
}

/// One line per map, method and footprint size: TV to both truths, their noise and the quadrature
/// on 63² and 127² bins, and the costs.
fn accuracy_csv(results: &Results) -> Res<String> {
    let mut csv = String::from(
        "map,method,footprint_texels,tv_dirac,tv_convolved,noise_dirac,noise_convolved,quad_k,\
         quad_change,tv_dirac_127,tv_convolved_127,noise_dirac_127,noise_convolved_127,quad_k_127,\
         quad_change_127,patch_s,d_s,eval_s\n",
    );
    let cols = |t: &TwoTruths| {
        format!(
            "{:.5},{:.5},{:.5},{:.5},{},{:.2e}",
            t.dirac, t.convolved, t.noise_dirac, t.noise_convolved, t.k, t.change
        )
    };
    for r in &results.accuracy {
        writeln!(
            csv,
            "{},{},{},{},{},{:.3e},{:.3e},{:.3e}",
            r.map,
            quoted(&r.method),
            r.area,
            cols(&r.tv),
            r.tv_fine.as_ref().map_or(",,,,,".to_string(), cols),
            r.patch_s,
            r.d_s,
            r.eval_s
        )?;
    }
    Ok(csv)
}

/// One line per map, method and view angle: visible-area error, furnace and its standard error.
fn view_csv(results: &Results) -> Res<String> {
    let mut csv = String::from("map,method,theta_deg,v_rel_error,furnace,furnace_se\n");
    for r in &results.view {
        writeln!(
            csv,
            "{},{},{},{:.5},{:.5},{:.5}",
            r.map,
            quoted(&r.method),
            r.theta,
            r.v_rel_error,
            r.furnace,
            r.furnace_se
        )?;
    }
    Ok(csv)
}

/// One line per map and method: the family's build time and the method's bytes per texel.
fn build_csv(results: &Results) -> Res<String> {
    let mut csv = String::from("map,family,method,build_s,bytes_per_texel\n");
    for r in &results.build {
        writeln!(
            csv,
            "{},{},{},{:.3},{:.2}",
            r.map,
            r.family,
            quoted(&r.method),
            r.build_s,
            r.bytes_per_texel
        )?;
    }
    Ok(csv)
}

/// The markdown tables, one after the other with a blank line between them (the 127² table only if
/// a footprint has those bins).
pub(super) fn markdown(
    results: &Results,
    settings: &Settings,
    methods: &[String],
    view_methods: &[String],
    summary: &[MethodSummary],
) -> Res<String> {
    let mut tables = vec![
        summary_table(results, summary)?,
        tv_table(results, settings, methods, false),
    ];
    if settings.areas.iter().any(|&a| a <= settings.fine_up_to) {
        tables.push(tv_table(results, settings, methods, true));
    }
    tables.push(d_time_table(results, settings, methods)?);
    tables.push(view_table(results, settings, view_methods)?);
    Ok(tables.join("\n"))
}

/// Per method: mean TV to both truths (≥ 1 texel; the convolved truth first: the material every
/// method is given), BRDF eval time, bytes per texel, build time.
fn summary_table(results: &Results, summary: &[MethodSummary]) -> Res<String> {
    let mut md = String::new();
    writeln!(
        md,
        "| method | mean TV, convolved (≥ 1 texel) | mean TV, Dirac | BRDF eval (µs, geo. mean) | \
         bytes/texel | build (s, mean over maps) |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    for s in summary {
        let (m, t, e, c) = (&s.method, s.eval_us, s.tv_dirac, s.tv_convolved);
        let b = || results.build.iter().filter(|r| &r.method == m);
        writeln!(
            md,
            "| {m} | {c:.3} | {e:.3} | {t:.2} | {:.1} | {:.1} |",
            mean(b().map(|r| r.bytes_per_texel)),
            mean(b().map(|r| r.build_s))
        )?;
    }
    Ok(md)
}

/// Markdown table of the TV to both truths per footprint size (convolved first, means over maps and
/// centres), on 63²
/// bins or (`fine`) on 127² bins for the footprints that have them; the last columns give the finest
/// quadrature grid any bin needed (k of k × k, over maps, centres and sizes) and the largest final
/// change of the masses.
fn tv_table(results: &Results, settings: &Settings, methods: &[String], fine: bool) -> String {
    let pick = |r: &AccuracyRow| if fine { r.tv_fine } else { Some(r.tv) };
    let areas: Vec<f32> = settings
        .areas
        .iter()
        .copied()
        .filter(|&a| !fine || a <= settings.fine_up_to)
        .collect();
    let mut md = String::new();
    let bins = if fine { "127²" } else { "63²" };
    md.push_str(&format!("| method ({bins} bins) |"));
    for a in &areas {
        md.push_str(&format!(" {a}: conv. | {a}: Dirac |"));
    }
    md.push_str(" quadrature k | change |\n");
    md.push_str(&format!(
        "|---|{}---|---|\n",
        "---|---|".repeat(areas.len())
    ));
    let (mut noise_d, mut noise_c) = (Vec::new(), Vec::new());
    for m in methods {
        md.push_str(&format!("| {m} |"));
        let all: Vec<TwoTruths> = results
            .accuracy
            .iter()
            .filter(|r| &r.method == m)
            .filter_map(pick)
            .collect();
        for &a in &areas {
            let rows: Vec<TwoTruths> = results
                .accuracy
                .iter()
                .filter(|r| &r.method == m && r.area == a)
                .filter_map(pick)
                .collect();
            md.push_str(&format!(
                " {:.3} | {:.3} |",
                mean(rows.iter().map(|t| t.convolved)),
                mean(rows.iter().map(|t| t.dirac))
            ));
            if m == &methods[0] {
                noise_d.push(mean(rows.iter().map(|t| t.noise_dirac)));
                noise_c.push(mean(rows.iter().map(|t| t.noise_convolved)));
            }
        }
        let k = all.iter().map(|t| t.k).max().unwrap_or(0);
        let change = all.iter().map(|t| t.change).fold(0.0, f64::max);
        md.push_str(&format!(" {k} × {k} | {change:.1e} |\n"));
    }
    md.push_str("| *reference noise* |");
    for (d, c) in noise_d.iter().zip(&noise_c) {
        md.push_str(&format!(" {c:.3} | {d:.3} |"));
    }
    md.push_str(" | |\n");
    md
}

/// Per method and footprint size: the time of one `d` (µs, geometric mean over maps and centres).
fn d_time_table(results: &Results, settings: &Settings, methods: &[String]) -> Res<String> {
    let mut md = String::new();
    write!(md, "| method |")?;
    for a in &settings.areas {
        write!(md, " d {a} (µs) |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|{}", "---|".repeat(settings.areas.len()))?;
    for m in methods {
        write!(md, "| {m} |")?;
        for &a in &settings.areas {
            let rows = results
                .accuracy
                .iter()
                .filter(|r| &r.method == m && r.area == a);
            write!(md, " {:.2} |", geo_mean(rows.map(|r| r.d_s * 1e6)))?;
        }
        writeln!(md)?;
    }
    Ok(md)
}

/// Per method and view angle: the visible-area error and the furnace (means over the maps).
fn view_table(results: &Results, settings: &Settings, view_methods: &[String]) -> Res<String> {
    let mut md = String::new();
    write!(md, "| method | quantity |")?;
    for t in &settings.thetas {
        write!(md, " {t}° |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|---|{}", "---|".repeat(settings.thetas.len()))?;
    for m in view_methods {
        for (q, f) in [
            (
                "V rel. error",
                &(|r: &ViewRow| r.v_rel_error) as &dyn Fn(&ViewRow) -> f64,
            ),
            ("furnace", &|r: &ViewRow| r.furnace),
        ] {
            write!(md, "| {m} | {q} |")?;
            for &t in &settings.thetas {
                let v = mean(
                    results
                        .view
                        .iter()
                        .filter(|r| &r.method == m && r.theta == t)
                        .map(f),
                );
                write!(md, " {v:.3} |")?;
            }
            writeln!(md)?;
        }
    }
    Ok(md)
}
