//! Error against time on the orb (`orb -- --curves`): naive sampling at 1 … 4096 spp against each
//! glint model at 1, 4 and 16 evaluations per pixel, on the four procedural maps and a sweep of the
//! map's scale, and the equal-error speedups read off those curves. See docs/orb.md.
//!
//! Everything is measured on the same scene, pixel kernel (the footprint's Gaussian k_P, pixel-centre
//! frame, linear uv) and measure (the renderer's) as the orb's references ([`render_references`]).
//! Errors are `rel_rmse_denoised` of [`errors`] against a reference's two independent halves:
//! ‖m − r‖² minus the reference's own noise variance ‖a − b‖²/4 (E‖r − E r‖²), clamped at 0,
//! over ‖r‖² — an unbiased estimate of the squared error against the reference's expectation.

use super::material::{Configured, SIGMA_EPS, binmap_at};
use super::orb::{
    Errors, Image, MapSource, OrbMethod, OrbOptions, Scene, coverage, errors, gap_errors,
    glint_pixel, load_map, reference_noise, render_glint_evals, render_naive, render_references,
};
use super::{Artifact, Res};
use brdf::glint::mixture::{MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{BeckmannMixture, PositionNormalMap};
use glam::Vec2;
use indicatif::ProgressBar;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

mod chart;
use chart::chart;

/// The sweep's settings.
#[derive(Clone, Debug)]
pub struct CurveOptions {
    /// The maps swept (names of [`MAPS`], one row of panels each).
    pub maps: Vec<&'static str>,
    /// Image size (pixels per side).
    pub size: u32,
    /// Procedural map size (texels per side).
    pub map_size: usize,
    /// Map scales: the map is tiled (2k, k) times over the sphere's (u, v) (k < 1: a part of the
    /// map covers the sphere).
    pub scales: Vec<f32>,
    /// Reference: 2 halves of k × k positions per pixel.
    pub reference_k: u32,
    /// Naive: 1, 4, 16, … up to this many spp.
    pub naive_max_spp: u32,
    /// Skip a glint render whose projected time exceeds this (s), said in the output.
    pub budget_s: f64,
}

impl CurveOptions {
    /// The full sweep (`--curves`).
    pub fn full() -> CurveOptions {
        CurveOptions {
            maps: MAPS.to_vec(),
            size: 128,
            map_size: 512,
            // 1, 9, 34, 2 186 and 139 898 texels per pixel (median).
            scales: vec![0.35, 1.0, 2.0, 16.0, 128.0],
            reference_k: 48,
            naive_max_spp: 4096,
            budget_s: 40.0,
        }
    }

    /// The gallery's `--full` sweep (`--curves --quick`): a few minutes at most.
    pub fn quick() -> CurveOptions {
        CurveOptions {
            maps: MAPS.to_vec(),
            size: 64,
            map_size: 256,
            scales: vec![2.0, 32.0],
            reference_k: 32,
            naive_max_spp: 1024,
            budget_s: 10.0,
        }
    }

    /// The gallery's default preview: [`CurveOptions::quick`] on two maps (scratched and flakes:
    /// long thin glints and isolated sparkles) at one scale (~30 texels per pixel), naive sampling
    /// up to 256 spp and a 2 × 24² spp reference; ten seconds or so on 2 cores.
    pub fn preview() -> CurveOptions {
        CurveOptions {
            maps: vec!["scratched", "flakes"],
            scales: vec![2.0],
            reference_k: 24,
            naive_max_spp: 256,
            budget_s: 5.0,
            ..CurveOptions::quick()
        }
    }
}

/// One measured point.
#[derive(Clone, Debug)]
struct Point {
    map: String,
    scale: f32,
    texels_per_pixel: f64,
    method: String,
    evals: u32,
    build_s: f64,
    render_s: f64,
    vs_a: Errors,
    vs_b: Errors,
    /// Relative noise of reference (a) (half the difference of its halves over its norm).
    noise_a: f64,
}

/// The crate's four procedural maps and the example's fractal height field (orb/fractal.rs).
pub const MAPS: [&str; 5] = ["scratched", "brushed", "bumpy", "flakes", "fractal"];
/// The mixture without level of detail is rendered only up to this footprint (texels per pixel):
/// beyond it every pixel reads tens of thousands of lobes.
const NO_LOD_MAX_TEXELS: f64 = 5000.0;
/// Label of the mixture's row without level of detail (the full mixture at every footprint).
const NO_LOD: &str = "mixture (no LOD)";
/// The papers' own settings ("paper default" rows) are rendered only up to this footprint (texels
/// per pixel): beyond it position-normal's rows alone took half of the sweep's time, and both rows
/// are σ-mismatched comparisons whose verdict the smaller footprints already give.
const PAPER_DEFAULT_MAX_TEXELS: f64 = 5000.0;
const EVALS: [u32; 3] = [1, 4, 16];

/// The glint models of one map with their build times, each given the scene's σ_ε the way its
/// paper allows (examples/common/material.rs): the mixture with the options a user gets (lobe floor
/// σ_ε, default `PatchOptions`; `samples` 64 is not read by the default filter moments) and the same
/// mixture with no level of detail (`lod_lobes` ∞, `lod_tolerance` 0, `sub_texel_area` 0,
/// `filtered_area` ∞: the full mixture at every footprint), the bin map at its
/// default bins smoothed by a Beckmann lobe of α = √2 σ_ε, the position-normal map with σ_r = σ_ε;
/// and, as "paper default" rows, the bin map's one-bin resolution (σ = 0) and Yan's σ_r = 0.005.
pub fn build_models(map: &brdf::glint::NormalMap) -> Res<Vec<OrbMethod>> {
    let t = Instant::now();
    let params = MixtureParams {
        sigma_min: SIGMA_EPS,
        samples: 64,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(map, params)?;
    // The filtered mixture's errors (measured on first use) count as build time: the sweep's
    // largest footprints need them.
    built.filtered_mixture_errors();
    let mixture = Configured::new(Arc::new(built.into()));
    let mut full = mixture.clone();
    full.options.mixture = PatchOptions::full();
    let mixture_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    // The masking lobe's floor at σ_ε too.
    let binmap = binmap_at(map, SIGMA_EPS)?;
    let binmap_s = t.elapsed().as_secs_f64();
    let pn = |sigma_r| -> Res<(Configured, f64)> {
        let t = Instant::now();
        let params = PositionNormalParams {
            sigma_r,
            ..PositionNormalParams::default()
        };
        let m = PositionNormalMap::build(map, params)?;
        Ok((
            Configured::new(Arc::new(m.into())),
            t.elapsed().as_secs_f64(),
        ))
    };
    let (pn_eps, pn_eps_s) = pn(SIGMA_EPS)?;
    let paper_r = PositionNormalParams::DEFAULT_SIGMA_R;
    let (pn_paper, pn_paper_s) = pn(paper_r)?;
    let row = |label: &str, glint, build_s, paper_sigma| OrbMethod {
        label: label.to_string(),
        glint,
        build_s,
        paper_sigma,
    };
    Ok(vec![
        row("mixture", mixture, mixture_s, None),
        row(NO_LOD, full, mixture_s, None),
        row(
            "bin map",
            Configured::binmap(binmap.clone(), SIGMA_EPS),
            binmap_s,
            None,
        ),
        row(
            "bin map σ = 0 (paper default)",
            Configured::binmap(binmap, 0.0),
            binmap_s,
            Some(0.0),
        ),
        row("position-normal", pn_eps, pn_eps_s, None),
        row(
            "position-normal σ_r = 0.005 (paper default)",
            pn_paper,
            pn_paper_s,
            Some(paper_r),
        ),
    ])
}

/// Median footprint area (texels², of the clamped pixel parallelogram) over the covered pixels.
fn texels_per_pixel(scene: &Scene, mask: &[bool], map_w: usize, map_h: usize) -> f64 {
    let mut a: Vec<f64> = (0..scene.size * scene.size)
        .filter(|&k| mask[k as usize])
        .filter_map(|k| {
            let (x, y) = (k % scene.size, k / scene.size);
            scene
                .shading(Vec2::new(x as f32 + 0.5, y as f32 + 0.5))
                .map(|sp| sp.footprint().area_texels(map_w, map_h) as f64)
        })
        .collect();
    if a.is_empty() {
        return 0.0;
    }
    a.sort_by(f64::total_cmp);
    a[a.len() / 2]
}

/// Projected render time of `model` at `evals` evaluations per pixel, from 64 covered pixels spread
/// over the image.
fn pilot_seconds(scene: &Scene, mask: &[bool], model: &Configured, evals: u32) -> f64 {
    let covered: Vec<u32> = (0..scene.size * scene.size)
        .filter(|&k| mask[k as usize])
        .collect();
    if covered.is_empty() {
        return 0.0;
    }
    let step = covered.len().div_ceil(64);
    let q = (evals as f64).sqrt() as u32;
    let t = Instant::now();
    let mut n = 0;
    for &k in covered.iter().step_by(step) {
        std::hint::black_box(glint_pixel(scene, model, k % scene.size, k / scene.size, q));
        n += 1;
    }
    // Two cores render in parallel.
    t.elapsed().as_secs_f64() / n as f64 * covered.len() as f64 / 2.0
}

/// The time naive sampling needs to reach `error` on its measured curve `(seconds, error)` (spp
/// increasing), interpolated linearly in log-log between the bracketing points, with a flag: "="
/// interpolated, ">" never reached (the last time, a lower bound), "<" already reached at the first
/// point (its time, an upper bound).
pub fn naive_time_at(curve: &[(f64, f64)], error: f64) -> (f64, &'static str) {
    let floor = 1e-9;
    let e = error.max(floor);
    let Some(i) = curve.iter().position(|&(_, ei)| ei <= e) else {
        return (curve.last().map_or(f64::NAN, |p| p.0), ">");
    };
    if i == 0 {
        return (curve[0].0, "<");
    }
    let (t0, e0) = (curve[i - 1].0.ln(), curve[i - 1].1.max(floor).ln());
    let (t1, e1) = (curve[i].0.ln(), curve[i].1.max(floor).ln());
    let f = if e1 < e0 {
        (e.ln() - e0) / (e1 - e0)
    } else {
        1.0
    };
    ((t0 + f * (t1 - t0)).exp(), "=")
}

/// Runs the sweep ([`CurveOptions::quick`] or [`CurveOptions::full`]) and writes orb_curves.csv,
/// orb_speedup.csv and orb_curves.png into `out`.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    if quick {
        run_with(out, &CurveOptions::quick(), "quick")
    } else {
        run_with(out, &CurveOptions::full(), "full")
    }
}

/// The gallery's default: [`CurveOptions::preview`].
pub fn run_preview(out: &Path) -> Res<Vec<Artifact>> {
    run_with(out, &CurveOptions::preview(), "preview")
}

/// Runs the sweep of `opts` (`setting` names it in the output and the chart's title) and writes
/// orb_curves.csv, orb_speedup.csv and orb_curves.png into `out`.
pub fn run_with(out: &Path, opts: &CurveOptions, setting: &str) -> Res<Vec<Artifact>> {
    std::fs::create_dir_all(out)?;
    let wall = Instant::now();
    let hidden = ProgressBar::hidden();
    let mut points: Vec<Point> = Vec::new();
    let mut notes = String::new();
    for &map_name in &opts.maps {
        let orb = OrbOptions {
            map: MapSource::parse(map_name),
            map_size: opts.map_size,
            progress: false,
            ..OrbOptions::default()
        };
        let map = load_map(&orb)?;
        let models = build_models(&map)?;
        for &k in &opts.scales {
            let scene = Scene::new(opts.size, Vec2::new(2.0 * k, k));
            let mask = coverage(&scene);
            let tpp = texels_per_pixel(&scene, &mask, map.width(), map.height());
            let t = Instant::now();
            let refs =
                render_references(&scene, &map, SIGMA_EPS, opts.reference_k, orb.seed, &hidden);
            let ref_s = t.elapsed().as_secs_f64();
            let (a0, a1) = (&refs.pbrdf.0, &refs.pbrdf.1);
            let (b0, b1) = (&refs.normal_mapped.0, &refs.normal_mapped.1);
            let noise_a = reference_noise(a0, a1, &mask);
            let point = |method: &str, evals, build_s, render_s, img: &Image| Point {
                map: map_name.to_string(),
                scale: k,
                texels_per_pixel: tpp,
                method: method.to_string(),
                evals,
                build_s,
                render_s,
                vs_a: errors(img, a0, a1, &mask),
                vs_b: errors(img, b0, b1, &mask),
                noise_a,
            };
            // The gap: reference (b) against (a) (same positions: the correlated-noise form).
            let gap = gap_errors(&refs, &mask);
            points.push(Point {
                map: map_name.to_string(),
                scale: k,
                texels_per_pixel: tpp,
                method: "(b) normal-mapped reference".to_string(),
                evals: 2 * opts.reference_k * opts.reference_k,
                build_s: 0.0,
                render_s: ref_s,
                vs_a: gap,
                vs_b: Errors {
                    rel_rmse: reference_noise(b0, b1, &mask),
                    ..Errors::default()
                },
                noise_a,
            });
            let mut spp = 1;
            while spp <= opts.naive_max_spp {
                let t = Instant::now();
                let img = render_naive(&scene, &map, SIGMA_EPS, spp, 1000 + spp as u64, &hidden);
                let s = t.elapsed().as_secs_f64();
                points.push(point("naive", spp, 0.0, s, &img));
                spp *= 4;
            }
            for OrbMethod {
                label,
                glint: model,
                build_s,
                ..
            } in &models
            {
                if label == NO_LOD && tpp > NO_LOD_MAX_TEXELS {
                    continue;
                }
                if label.ends_with("(paper default)") && tpp > PAPER_DEFAULT_MAX_TEXELS {
                    continue;
                }
                for evals in EVALS {
                    let projected = pilot_seconds(&scene, &mask, model, evals);
                    if projected > opts.budget_s {
                        let _ = writeln!(
                            notes,
                            "{map_name} ×{k} {label} {evals} evals: skipped (projected {projected:.0} s > budget {} s)",
                            opts.budget_s
                        );
                        continue;
                    }
                    let t = Instant::now();
                    let img = render_glint_evals(&scene, model, evals, &hidden);
                    let s = t.elapsed().as_secs_f64();
                    points.push(point(label, evals, *build_s, s, &img));
                }
            }
            eprintln!(
                "curves: {map_name} ×{k} ({tpp:.0} texels/pixel) done at {:.0} s",
                wall.elapsed().as_secs_f64()
            );
        }
    }
    let wall_s = wall.elapsed().as_secs_f64();

    // orb_curves.csv
    let mut csv = String::from(
        "map,scale,texels_per_pixel,method,evals_per_pixel,build_s,render_s,rel_rmse,\
         rel_rmse_denoised,rel_rmse_vs_b,rel_rmse_denoised_vs_b,energy_error,reference_noise\n",
    );
    for p in &points {
        let _ = writeln!(
            csv,
            "{},{},{:.0},{},{},{:.3},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
            p.map,
            p.scale,
            p.texels_per_pixel,
            p.method,
            p.evals,
            p.build_s,
            p.render_s,
            p.vs_a.rel_rmse,
            p.vs_a.rel_rmse_denoised,
            p.vs_b.rel_rmse,
            p.vs_b.rel_rmse_denoised,
            p.vs_a.energy,
            p.noise_a
        );
    }
    let curves_path = out.join("orb_curves.csv");
    std::fs::write(&curves_path, csv)?;

    // orb_speedup.csv: per map, scale, method and evals, against each truth.
    let mut sp = String::from(
        "map,scale,texels_per_pixel,method,evals_per_pixel,truth,method_error,naive_s_at_error,\
         naive_bound,method_render_s,build_s,speedup,speedup_with_build\n",
    );
    for p in points
        .iter()
        .filter(|p| p.method != "naive" && !p.method.starts_with("(b)"))
    {
        for truth in ["a", "b"] {
            let err = |e: &Point| {
                if truth == "a" {
                    e.vs_a.rel_rmse_denoised
                } else {
                    e.vs_b.rel_rmse_denoised
                }
            };
            let curve: Vec<(f64, f64)> = points
                .iter()
                .filter(|q| q.method == "naive" && q.map == p.map && q.scale == p.scale)
                .map(|q| (q.render_s, err(q)))
                .collect();
            let (tn, bound) = naive_time_at(&curve, err(p));
            let _ = writeln!(
                sp,
                "{},{},{:.0},{},{},{truth},{:.4},{:.4},{bound},{:.4},{:.3},{:.2},{:.3}",
                p.map,
                p.scale,
                p.texels_per_pixel,
                p.method,
                p.evals,
                err(p),
                tn,
                p.render_s,
                p.build_s,
                tn / p.render_s,
                tn / (p.render_s + p.build_s)
            );
        }
    }
    let speedup_path = out.join("orb_speedup.csv");
    std::fs::write(&speedup_path, sp)?;

    let chart_path = out.join("orb_curves.png");
    chart(&chart_path, &points, opts, setting)?;
    println!(
        "orb curves ({setting}): maps {:?}, image {}², map {}², scales {:?}, reference 2 × {} spp, wall time {wall_s:.0} s",
        opts.maps,
        opts.size,
        opts.map_size,
        opts.scales,
        opts.reference_k * opts.reference_k
    );
    print!("{notes}");
    for p in [&curves_path, &speedup_path, &chart_path] {
        println!("wrote {}", p.display());
    }
    Ok(vec![
        Artifact::new(
            &chart_path,
            format!(
                "Orb error against time (denoised relative RMSE against reference (a), the exact \
                 P-BRDF; Gaussian pixel kernel for every curve): naive sampling 1…{} spp (solid: \
                 against (a); dotted: against (b), its own limit), each glint model at 1, 4, 16 \
                 evaluations per pixel (filled: render time; hollow: + build). Rows: maps; columns: \
                 map scale (median texels per pixel in the title). Points on the bottom edge \
                 (1e-3) are within the reference's noise.",
                opts.naive_max_spp
            ),
        ),
        Artifact::new(&curves_path, "Every point of the curves (CSV)."),
        Artifact::new(
            &speedup_path,
            "Equal-error speedups against naive sampling, with and without build (CSV).",
        ),
    ])
}
