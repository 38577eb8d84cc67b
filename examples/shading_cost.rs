//! Cost and error of one renderer shading point against the footprint's size, for every glint model
//! at its default per-query options and for an analytic GGX material.
//!
//! `cargo run --release --example shading_cost [-- --quick] [--out DIR]`
//!
//! A shading point is what a path tracer does at a hit: `Material::bsdf(&footprint, &scratch)`
//! (the patch), `eval_pdf` toward a light, `eval_pdf` toward a second direction (an MIS
//! companion) and one `sample`, all at one wo. Each model renders the same material (σ_ε = 0.01,
//! examples/common/material.rs) on the four procedural 512² maps, footprints 0.25-131 072 texels.
//! Time: 256 shading points at random uv and directions per (model, footprint), the best of 3
//! rounds that alternate the models (one thread). Error: TV of the default patch to the
//! σ_ε-convolved truth (`convolved_pndf`, 63² bins, 10⁶ positions) at one footprint centre.
//! Writes `shading_cost.csv`, `shading_cost_time.png` and `shading_cost_error.png` (one line per
//! model) into DIR (default `target/brdf-out/`). See docs/results.md, "Cost and error of a
//! shading point against footprint".

use brdf_examples::common;

use brdf::Vec2;
use brdf::fresnel::ConductorFresnel;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, GlintOptions, GlintScratch,
    HemisphereBins, Kernel, NormalMap, PositionNormalMap, bin_masses, convolved_pndf,
};
use brdf::material::{GlintMaterial, Material};
use brdf::ndf::Ggx;
use common::Res;
use common::material::{SIGMA_EPS, binmap_options};
use common::shading_points::{Point, points, shade};
use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

/// Seconds per shading point of `material` at footprints of `area` texels on a `size`² map.
fn time_per_point(material: &Material, pts: &[Point], area: f32, size: usize) -> f64 {
    let scratch = GlintScratch::default();
    let t = Instant::now();
    for p in pts {
        shade(material, p, area, size, &scratch);
    }
    t.elapsed().as_secs_f64() / pts.len() as f64
}

/// The glint materials of one map (name, material, the model's options), like for like.
fn materials(map: &NormalMap) -> Res<Vec<(&'static str, Material, GlintOptions)>> {
    let gold = ConductorFresnel::GOLD;
    let mixture: GlintModel = BeckmannMixture::build(
        map,
        MixtureParams {
            sigma_min: SIGMA_EPS,
            ..MixtureParams::default()
        },
    )?
    .into();
    let bin_map: GlintModel = BinMap::build(
        map,
        BinMapParams {
            sigma_min: SIGMA_EPS,
            ..BinMapParams::default()
        },
    )?
    .into();
    let pn: GlintModel = PositionNormalMap::build(
        map,
        PositionNormalParams {
            sigma_r: SIGMA_EPS,
            ..PositionNormalParams::default()
        },
    )?
    .into();
    let mut bin_options = GlintOptions::default();
    bin_options.bin_map = binmap_options(SIGMA_EPS);
    let glint = |m: GlintModel, o: GlintOptions| -> Material {
        GlintMaterial::new(Arc::new(m), gold).with_options(o).into()
    };
    Ok(vec![
        (
            "mixture",
            glint(mixture, GlintOptions::default()),
            GlintOptions::default(),
        ),
        ("bin map", glint(bin_map, bin_options.clone()), bin_options),
        (
            "position-normal",
            glint(pn, GlintOptions::default()),
            GlintOptions::default(),
        ),
    ])
}

/// TV of `material`'s patch at `fp` to the σ_ε-convolved truth (63² bins).
fn tv(material: &Material, map: &NormalMap, fp: &Footprint, positions: usize) -> Res<f64> {
    let Material::Glint(g) = material else {
        return Ok(f64::NAN);
    };
    let bins = HemisphereBins::new(63)?;
    let truth = convolved_pndf(
        map,
        fp,
        Kernel::Gaussian,
        &bins,
        positions,
        11,
        SIGMA_EPS as f64,
    )?;
    let scratch = GlintScratch::default();
    let patch = g.model().patch_with(fp, g.options(), Some(&scratch));
    Ok(truth
        .tv_to_masses(&bin_masses(&patch, &bins, 4))
        .unwrap_or(f64::NAN))
}

struct Row {
    map: &'static str,
    model: &'static str,
    area: f32,
    seconds: f64,
    tv: f64,
}

fn main() -> Res<()> {
    let out = common::out_dir()?;
    let quick = common::has_flag("--quick");
    let size = if quick { 256 } else { 512 };
    let areas: Vec<f32> = if quick {
        vec![0.25, 4.0, 64.0, 1024.0, 16384.0]
    } else {
        vec![
            0.25, 1.0, 4.0, 16.0, 64.0, 256.0, 1024.0, 4096.0, 16384.0, 65536.0, 131072.0,
        ]
    };
    let n_points = if quick { 64 } else { 256 };
    let positions = if quick { 200_000 } else { 1_000_000 };
    let pts = points(n_points, 5);
    let ggx = Material::microfacet(Ggx::isotropic(0.1)?, ConductorFresnel::GOLD);
    let mut rows: Vec<Row> = Vec::new();
    for (name, map) in common::pndf_images::maps(size)? {
        let t = Instant::now();
        let mats = materials(&map)?;
        println!("{name}: built in {:.1} s", t.elapsed().as_secs_f64());
        if let Material::Glint(g) = &mats[0].1
            && let GlintModel::Mixture(m) = g.model()
        {
            println!(
                "  filtered mixture TV per level: {:?}",
                m.filtered_mixture_errors()
            );
        }
        for &area in &areas {
            // Alternate the models within each round; keep each one's best round.
            let mut best = vec![f64::INFINITY; mats.len() + 1];
            for _ in 0..3 {
                best[0] = best[0].min(time_per_point(&ggx, &pts, area, size));
                for (k, (_, m, _)) in mats.iter().enumerate() {
                    best[k + 1] = best[k + 1].min(time_per_point(m, &pts, area, size));
                }
            }
            rows.push(Row {
                map: name,
                model: "analytic GGX",
                area,
                seconds: best[0],
                tv: f64::NAN,
            });
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, size, size);
            for (k, (model, m, _)) in mats.iter().enumerate() {
                let e = tv(m, &map, &fp, positions)?;
                println!(
                    "{name} {area:>8} texels {model:>16}: {:>9.2} µs ({:>6.1}× GGX), TV {e:.3}",
                    best[k + 1] * 1e6,
                    best[k + 1] / best[0]
                );
                rows.push(Row {
                    map: name,
                    model,
                    area,
                    seconds: best[k + 1],
                    tv: e,
                });
            }
        }
    }
    let mut csv =
        String::from("map,model,footprint_texels,seconds_per_point,ratio_to_ggx,tv_convolved\n");
    for r in &rows {
        let ggx = rows
            .iter()
            .find(|g| g.map == r.map && g.area == r.area && g.model == "analytic GGX")
            .map_or(f64::NAN, |g| g.seconds);
        writeln!(
            csv,
            "{},{},{},{:.4e},{:.2},{:.4}",
            r.map,
            r.model,
            r.area,
            r.seconds,
            r.seconds / ggx,
            r.tv
        )?;
    }
    std::fs::write(out.join("shading_cost.csv"), &csv)?;
    chart(&out, &rows)?;
    for f in [
        "shading_cost.csv",
        "shading_cost_time.png",
        "shading_cost_error.png",
    ] {
        println!("{}", out.join(f).display());
    }
    Ok(())
}

/// Two charts against footprint (log-log): time per shading point (geometric mean over maps) and
/// TV to the truth (mean over maps), one line per model.
fn chart(out: &std::path::Path, rows: &[Row]) -> Res<()> {
    use common::{Chart, Scale, Series, line_chart};
    let mut areas: Vec<f32> = rows.iter().map(|r| r.area).collect();
    areas.sort_by(f32::total_cmp);
    areas.dedup();
    let series = |model: &str, f: &dyn Fn(&Row) -> f64, geometric: bool| -> Series {
        let points = areas
            .iter()
            .filter_map(|&a| {
                let v: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.model == model && r.area == a)
                    .map(f)
                    .filter(|v| v.is_finite() && *v > 0.0)
                    .collect();
                let n = v.len() as f64;
                (!v.is_empty()).then(|| {
                    let m = if geometric {
                        (v.iter().map(|x| x.ln()).sum::<f64>() / n).exp()
                    } else {
                        v.iter().sum::<f64>() / n
                    };
                    (a as f64, m)
                })
            })
            .collect();
        Series::new(model, points)
    };
    let models = ["analytic GGX", "mixture", "bin map", "position-normal"];
    let time: Vec<Series> = models
        .iter()
        .map(|m| series(m, &|r| r.seconds * 1e6, true))
        .collect();
    // Every model in both charts (analytic GGX has no TV: an empty series), so that a model keeps
    // its colour.
    let tv: Vec<Series> = models.iter().map(|m| series(m, &|r| r.tv, false)).collect();
    let chart = |title, y_label, y_scale| Chart {
        title,
        x_label: "footprint (texels)",
        y_label,
        x_scale: Scale::Log,
        y_scale,
        markers: true,
        ..Chart::new(title, "", "")
    };
    line_chart(
        &out.join("shading_cost_time.png"),
        &chart(
            "Time per shading point (geometric mean over maps)",
            "µs",
            Scale::Log,
        ),
        &time,
    )?;
    line_chart(
        &out.join("shading_cost_error.png"),
        &chart(
            "TV to the σ_ε-convolved truth (mean over maps)",
            "TV",
            Scale::Linear,
        ),
        &tv,
    )?;
    Ok(())
}
