//! Procedural glints (`brdf::glint::procedural`) measured against their limit: how far a
//! footprint's P-NDF is from the limit NDF (Beckmann or GGX) as the footprint grows, whether the
//! mean of the P-NDF over positions is the limit at every size, and what one renderer shading
//! point costs.
//!
//! Five surfaces on the default 1024² grid (facet α_f = 0.02, seed 1): the default (α 0.3, one
//! facet per texel), density 0.1 and 16 facets per texel, α 0.1, and the default of the GGX limit
//! (its "limit" is GGX: its TV and L2 are to GGX). Isotropic footprints of 0.25
//! to 2²⁰ texels (factor 4; `--quick`: factor 16 and the largest). Per (surface, footprint):
//!
//! - **TV to the limit**: the total variation between the normal densities D cos θ of the patch
//!   (default `PatchOptions`) and of `limit()`, by [`density_distances`] (4096 draws), averaged
//!   over 16 random footprint centres (8 in `--quick`), with its standard error over the centres;
//!   the same draws give the relative L2 distance, whose root mean square over the centres is the
//!   measured counterpart of the patch's own `expected_distance()` ρ (the model's prediction for
//!   the lattice before the limit blend);
//! - the patch's `level()`, `limit_weight()` b and `expected_distance()` ρ (the same at every
//!   centre of an isotropic footprint) and its `lobe_count()` (mean and largest over the centres);
//! - **the mean P-NDF check**: the TV between the limit and the mean of the normal densities of
//!   the patches at 256 random centres (64 in `--quick`), by [`mean_pndf_distances`], with the TV
//!   between two such means of independent centres as its noise reference (a finite mean of
//!   spiky patches is itself spiky: its distance to the limit does not vanish at small footprints
//!   even when the model's mean is exact, and is then about the reference or below);
//! - **cost of a shading point** through the public `Material` API, as `shading_cost` measures it
//!   (examples/common/shading_points.rs: `Material::bsdf` for the patch, two `eval_pdf`, one
//!   `sample`, gold Fresnel): 2048 points at random uv and directions (256 in `--quick`), the best
//!   of 7 rounds that alternate the procedural materials and an analytic GGX material (α 0.1,
//!   shading_cost's reference; its best round over all footprints), one thread; the ratio of the
//!   two.
//!
//! Writes `procedural.csv` and `procedural_tv.png` into DIR (`--out DIR`, default
//! `target/brdf-out/`); into a docs-like DIR (one with `data/` and `img/` folders, as
//! `--out docs`) they go to `DIR/data/procedural.csv` and `DIR/img/procedural_tv.png`. Prints a
//! Markdown table (one row per surface and footprint).

use super::shading_points::{Point, points, shade};
use super::{Artifact, Res, register_font};
use brdf::fresnel::ConductorFresnel;
use brdf::glint::procedural::{ProceduralGlints, ProceduralLimit, ProceduralParams};
use brdf::glint::{Footprint, GlintModel, GlintNdf, GlintScratch};
use brdf::material::{GlintMaterial, Material};
use brdf::ndf::{Ggx, Ndf};
use brdf::{Vec2, Vec3};
use plotters::prelude::*;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Texels per uv side of every surface (the model's default resolution).
const RES: usize = 1024;

/// Draws per TV estimate.
const DRAWS: usize = 4096;

/// The surfaces measured: a short name and the parameters (seed 1).
fn surfaces() -> Vec<(&'static str, ProceduralParams)> {
    let d = ProceduralParams {
        seed: 1,
        ..ProceduralParams::default()
    };
    vec![
        ("default (α 0.3, 1/texel)", d),
        ("density 0.1", ProceduralParams { density: 0.1, ..d }),
        ("density 16", ProceduralParams { density: 16.0, ..d }),
        (
            "α 0.1",
            ProceduralParams {
                alpha: Vec2::splat(0.1),
                ..d
            },
        ),
        (
            "GGX limit (α 0.3, 1/texel)",
            ProceduralParams {
                limit: ProceduralLimit::Ggx,
                ..d
            },
        ),
    ]
}

/// Isotropic footprint areas in texels: 0.25 · 4^k up to 2²⁰ (`quick`: every other one and the
/// largest).
fn areas(quick: bool) -> Vec<f32> {
    (0..=10)
        .filter(|k| !quick || k % 2 == 0)
        .map(|k| 0.25 * 4f32.powi(k))
        .chain([(1u32 << 20) as f32])
        .collect()
}

/// A deterministic generator for one (purpose, surface, footprint) cell.
fn rng(seed: u64) -> rand_pcg::Pcg64 {
    rand_pcg::Pcg64::seed_from_u64(seed)
}

/// The isotropic footprint of `area` texels at `uv`.
fn footprint(uv: Vec2, area: f32) -> Footprint {
    Footprint::isotropic_texels(uv, area, RES, RES)
}

/// TV and squared relative L2 distance between the normal densities f = D cos θ of `limit` and g
/// of `other` (the integration tests' `density_distances`, tests/it/support/mod.rs), from `draws`
/// draws of their even mix r = (f + g)/2, half from each one's own `sample_normal`:
/// TV = ½ E_r[|f − g| / r] and ‖f − g‖₂² / ‖f‖₂² with ‖h‖₂² = E_r[h² / r] (numerator and
/// denominator from the same draws). Both sides' densities are exact, so the TV estimate is
/// unbiased; with 4096 draws its relative standard error is a few per cent.
fn density_distances(limit: &impl Ndf, other: &impl Ndf, draws: usize, seed: u64) -> (f64, f64) {
    let mut rng = rng(seed);
    let (mut tv, mut diff2, mut norm2) = (0.0, 0.0, 0.0);
    for k in 0..draws {
        let u = Vec2::new(rng.random(), rng.random());
        let m = if k % 2 == 0 {
            limit.sample_normal(u)
        } else {
            other.sample_normal(u)
        };
        let f = limit.pdf_normal(m) as f64;
        let g = other.pdf_normal(m) as f64;
        let r = 0.5 * (f + g);
        if r > 0.0 {
            tv += 0.5 * (f - g).abs() / r;
            diff2 += (f - g).powi(2) / r;
            norm2 += f * f / r;
        }
    }
    (tv / draws as f64, diff2 / norm2)
}

/// The mean P-NDF check: ḡ_A and ḡ_B, the means of the normal densities of the patches in `a` and
/// in `b` (two sets of independent random centres), against the limit's f. Returns
/// (½ (TV(ḡ_A, f) + TV(ḡ_B, f)), TV(ḡ_A, ḡ_B)).
///
/// The estimator: every draw comes from the even mix r = (f + ḡ_A + ḡ_B) / 3: a third from the
/// limit's `sample_normal`, a third from ḡ_A and a third from ḡ_B, where a draw from a mean of
/// patches is the `sample_normal` of one of its patches picked uniformly at random (a draw from
/// an equal-weight mixture). At each draw m all three densities are evaluated exactly, ḡ_A(m) and
/// ḡ_B(m) as the average of their patches' `pdf_normal(m)` (every patch of the set, not only the
/// one drawn from), and TV(p, q) = ½ ∫ |p − q| = ½ E_r[|p − q| / r] is the mean of ½ |p − q| / r
/// over the draws: unbiased for the TV of these finite means, since r covers all three.
///
/// TV(ḡ_A, f) measures the finite mean, not the model's mean over all positions: a mean of K
/// patches of few narrow lobes is spiky and stays away from the smooth limit however exact the
/// model's mean is. TV(ḡ_A, ḡ_B) is the size of that fluctuation for the same K: if the model's
/// mean is the limit, f sits "between" the two finite means and TV(ḡ, f) is at most about
/// TV(ḡ_A, ḡ_B) (1/√2 of it where the fluctuations are small and Gaussian, about equal to it where
/// the means are sparse spikes); a bias of the model's mean would add to TV(ḡ, f) alone.
fn mean_pndf_distances(
    limit: &impl Ndf,
    a: &[impl Ndf],
    b: &[impl Ndf],
    draws: usize,
    seed: u64,
) -> (f64, f64) {
    /// The density of the equal-weight mean of `set` at `m`.
    fn mean(set: &[impl Ndf], m: Vec3) -> f64 {
        set.iter().map(|p| p.pdf_normal(m) as f64).sum::<f64>() / set.len() as f64
    }
    let mut rng = rng(seed);
    let (mut tv_af, mut tv_bf, mut tv_ab) = (0.0, 0.0, 0.0);
    for k in 0..draws {
        let u = Vec2::new(rng.random(), rng.random());
        let m = match k % 3 {
            0 => limit.sample_normal(u),
            1 => a[rng.random_range(0..a.len())].sample_normal(u),
            _ => b[rng.random_range(0..b.len())].sample_normal(u),
        };
        let f = limit.pdf_normal(m) as f64;
        let (ga, gb) = (mean(a, m), mean(b, m));
        let r = (f + ga + gb) / 3.0;
        if r > 0.0 {
            tv_af += 0.5 * (ga - f).abs() / r;
            tv_bf += 0.5 * (gb - f).abs() / r;
            tv_ab += 0.5 * (ga - gb).abs() / r;
        }
    }
    let n = draws as f64;
    (0.5 * (tv_af + tv_bf) / n, tv_ab / n)
}

/// One (surface, footprint) cell of the measurement.
#[derive(Clone, Debug)]
struct Row {
    surface: &'static str,
    params: ProceduralParams,
    area: f32,
    level: f32,
    lobes_mean: f64,
    lobes_max: usize,
    limit_weight: f32,
    rho: f32,
    /// Root mean square over the centres of the measured relative L2 distance to the limit.
    l2: f64,
    tv: f64,
    /// Standard error of `tv` over the centres.
    tv_se: f64,
    mean_tv: f64,
    mean_ref_tv: f64,
    /// Seconds per shading point, procedural material and analytic GGX.
    seconds: f64,
    ggx_seconds: f64,
}

/// The statistics of one (surface, footprint) cell (times left at NaN).
fn measure(
    index: u64,
    surface: &'static str,
    glints: &ProceduralGlints,
    area: f32,
    quick: bool,
) -> Row {
    let limit = glints.limit();
    let centres = if quick { 8 } else { 16 };
    let mean_centres = if quick { 64 } else { 256 };
    // Seeds: centres 10⁶ + index, TV draws 1000 index + centre, mean check 7·10⁶ + index (48
    // cells, 16 centres: no two streams share a seed).
    let mut r = rng(1_000_000 + index);
    let mut uv = || Vec2::new(r.random(), r.random());
    let (mut tv, mut tv2, mut l2, mut lobes, mut lobes_max) = (0.0, 0.0, 0.0, 0.0, 0);
    let (mut level, mut limit_weight, mut rho) = (0.0, 0.0, 0.0);
    for c in 0..centres {
        let p = glints.patch(&footprint(uv(), area));
        let (t, d2) = density_distances(&limit, &p, DRAWS, index * 1000 + c as u64);
        tv += t;
        tv2 += t * t;
        l2 += d2;
        lobes += p.lobe_count() as f64;
        lobes_max = lobes_max.max(p.lobe_count());
        (level, limit_weight, rho) = (p.level(), p.limit_weight(), p.expected_distance());
    }
    let n = centres as f64;
    let tv_mean = tv / n;
    let tv_se = ((tv2 / n - tv_mean * tv_mean).max(0.0) / (n - 1.0)).sqrt();
    let set_a: Vec<_> = (0..mean_centres)
        .map(|_| glints.patch(&footprint(uv(), area)))
        .collect();
    let set_b: Vec<_> = (0..mean_centres)
        .map(|_| glints.patch(&footprint(uv(), area)))
        .collect();
    let (mean_tv, mean_ref_tv) =
        mean_pndf_distances(&limit, &set_a, &set_b, DRAWS, 7_000_000 + index);
    Row {
        surface,
        params: *glints.params(),
        area,
        level,
        lobes_mean: lobes / n,
        lobes_max,
        limit_weight,
        rho,
        l2: (l2 / n).sqrt(),
        tv: tv_mean,
        tv_se,
        mean_tv,
        mean_ref_tv,
        seconds: f64::NAN,
        ggx_seconds: f64::NAN,
    }
}

/// Seconds per shading point of `material` at footprints of `area` texels.
fn time_per_point(material: &Material, pts: &[Point], area: f32) -> f64 {
    let scratch = GlintScratch::default();
    let t = Instant::now();
    for p in pts {
        shade(material, p, area, RES, &scratch);
    }
    t.elapsed().as_secs_f64() / pts.len() as f64
}

/// Fills in the times of `rows` (one thread, nothing else running): per footprint, the best of 7
/// rounds that alternate GGX and every surface's material. GGX ignores the footprint: its time is
/// its best round over every footprint (one reference for all ratios, less exposed to the noise of
/// a loaded machine than per-footprint bests).
fn time_rows(rows: &mut [Row], glints: &[ProceduralGlints], quick: bool) -> Res<()> {
    let gold = ConductorFresnel::GOLD;
    let ggx = Material::microfacet(Ggx::isotropic(0.1)?, gold);
    let materials: Vec<Material> = glints
        .iter()
        .map(|g| GlintMaterial::new(Arc::new(GlintModel::from(g.clone())), gold).into())
        .collect();
    let pts = points(if quick { 256 } else { 2048 }, 5);
    let mut areas: Vec<f32> = rows.iter().map(|r| r.area).collect();
    areas.sort_by(f32::total_cmp);
    areas.dedup();
    let mut ggx_best = f64::INFINITY;
    for area in areas {
        let mut best = vec![f64::INFINITY; materials.len() + 1];
        for _ in 0..7 {
            best[0] = best[0].min(time_per_point(&ggx, &pts, area));
            for (k, m) in materials.iter().enumerate() {
                best[k + 1] = best[k + 1].min(time_per_point(m, &pts, area));
            }
        }
        for (k, g) in glints.iter().enumerate() {
            for r in rows
                .iter_mut()
                .filter(|r| r.area == area && r.params == *g.params())
            {
                r.seconds = best[k + 1];
            }
        }
        ggx_best = ggx_best.min(best[0]);
    }
    for r in rows.iter_mut() {
        r.ggx_seconds = ggx_best;
    }
    Ok(())
}

/// `out`'s path for a file of `kind` ("data" or "img"): in `out/kind/` when `out` has both `data/`
/// and `img/` folders (the docs layout), else in `out`.
fn output(out: &Path, kind: &str, name: &str) -> PathBuf {
    if out.join("data").is_dir() && out.join("img").is_dir() {
        out.join(kind).join(name)
    } else {
        out.join(name)
    }
}

fn csv(rows: &[Row]) -> Res<String> {
    let mut s = String::from(
        "surface,alpha,facet_alpha,density,footprint_texels,level,lobes_mean,lobes_max,\
         limit_weight,expected_distance,l2_measured,tv_to_limit,tv_se,mean_pndf_tv,\
         mean_pndf_ref_tv,seconds_per_point,ggx_seconds_per_point,ratio_to_ggx\n",
    );
    for r in rows {
        writeln!(
            s,
            "{},{},{},{},{},{:.3},{:.2},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4},\
             {:.4e},{:.4e},{:.2}",
            r.surface,
            r.params.alpha.x,
            r.params.facet_alpha,
            r.params.density,
            r.area,
            r.level,
            r.lobes_mean,
            r.lobes_max,
            r.limit_weight,
            r.rho,
            r.l2,
            r.tv,
            r.tv_se,
            r.mean_tv,
            r.mean_ref_tv,
            r.seconds,
            r.ggx_seconds,
            r.seconds / r.ggx_seconds
        )?;
    }
    Ok(s)
}

fn table(rows: &[Row]) -> Res<String> {
    let mut s = String::from(
        "| surface | texels | level | lobes (mean / max) | limit weight b | ρ | L2 measured \
         | TV to the limit | mean P-NDF TV (reference) | µs per point (× GGX) |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        writeln!(
            s,
            "| {} | {} | {:.2} | {:.1} / {} | {:.2} | {:.3} | {:.3} | {:.3} ± {:.3} \
             | {:.3} ({:.3}) | {:.2} ({:.1}×) |",
            r.surface,
            r.area,
            r.level,
            r.lobes_mean,
            r.lobes_max,
            r.limit_weight,
            r.rho,
            r.l2,
            r.tv,
            r.tv_se,
            r.mean_tv,
            r.mean_ref_tv,
            r.seconds * 1e6,
            r.seconds / r.ggx_seconds
        )?;
    }
    Ok(s)
}

/// Colours of the surfaces (Okabe-Ito: blue, vermillion, bluish green, reddish purple, orange).
const COLOURS: [RGBColor; 5] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
];

/// Two panels against the footprint (log x), linear TV on the left, log TV on the right (where the
/// zeros of the limit lobe alone drop out): per surface (one colour each), the patch's TV to the
/// limit (solid, mean over the centres, ±2 standard errors), the mean P-NDF's (dashed) and the two
/// finite means' TV to each other, the mean's noise reference (dotted).
fn chart(path: &Path, rows: &[Row], names: &[&'static str], quick: bool) -> Res<()> {
    register_font();
    let (w, h) = (1500u32, 620u32);
    let k = if quick { 64 } else { 256 };
    let centres = if quick { 8 } else { 16 };
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE)?;
        let root = root.titled(
            "Procedural glints: TV of a footprint's P-NDF to the limit NDF (Beckmann; GGX for the GGX limit)",
            ("sans-serif", 24),
        )?;
        let (left, right) = root.split_horizontally(w / 2);
        let x_range = (0.15f64..2.0e6).log_scale();
        let per = |name: &str, f: &dyn Fn(&Row) -> f64| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.surface == name)
                .map(|r| (r.area as f64, f(r)))
                .collect()
        };
        macro_rules! panel {
            ($area:expr, $caption:expr, $y:expr, $floor:expr, $legend:expr) => {{
                let mut ctx = ChartBuilder::on($area)
                    .caption($caption, ("sans-serif", 18))
                    .margin(12)
                    .x_label_area_size(45)
                    .y_label_area_size(65)
                    .build_cartesian_2d(x_range.clone(), $y)?;
                ctx.configure_mesh()
                    .x_desc("footprint (texels)")
                    .y_desc("TV to the limit")
                    .x_label_formatter(&|v| {
                        if *v >= 1000.0 {
                            format!("{:.0e}", v)
                        } else {
                            format!("{v}")
                        }
                    })
                    .draw()?;
                let floor: f64 = $floor;
                let keep = |p: &(f64, f64)| p.1 >= floor;
                for (i, &name) in names.iter().enumerate() {
                    let c = COLOURS[i % COLOURS.len()];
                    let solid = per(name, &|r| r.tv);
                    let kept: Vec<(f64, f64)> = solid.iter().copied().filter(keep).collect();
                    ctx.draw_series(LineSeries::new(kept.clone(), c.stroke_width(3)))?
                        .label(name)
                        .legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3))
                        });
                    ctx.draw_series(kept.iter().map(|&p| Circle::new(p, 4, c.filled())))?;
                    let bars = rows
                        .iter()
                        .filter(|r| r.surface == name && r.tv >= floor)
                        .map(|r| {
                            let (x, e) = (r.area as f64, 2.0 * r.tv_se);
                            PathElement::new(
                                vec![(x, (r.tv - e).max(floor)), (x, r.tv + e)],
                                c.stroke_width(2),
                            )
                        });
                    ctx.draw_series(bars)?;
                    let mean: Vec<(f64, f64)> =
                        per(name, &|r| r.mean_tv).into_iter().filter(keep).collect();
                    ctx.draw_series(DashedLineSeries::new(mean, 10, 6, c.stroke_width(2)))?;
                    let reference: Vec<(f64, f64)> = per(name, &|r| r.mean_ref_tv)
                        .into_iter()
                        .filter(keep)
                        .collect();
                    ctx.draw_series(DashedLineSeries::new(reference, 2, 5, c.stroke_width(2)))?;
                }
                if $legend {
                    // The line styles, in black: four dash segments of 24 pixels each (a
                    // solid line repeats its one segment).
                    let styles: [(String, [i32; 4], u32); 3] = [
                        (
                            format!("patch ({centres} centres, ±2 SE)"),
                            [0, 24, 0, 24],
                            3,
                        ),
                        (format!("mean P-NDF of {k} centres"), [0, 10, 16, 24], 2),
                        ("two such means to each other".to_string(), [0, 2, 7, 9], 2),
                    ];
                    for (label, [a0, a1, b0, b1], width) in styles {
                        ctx.draw_series(LineSeries::new(Vec::<(f64, f64)>::new(), BLACK))?
                            .label(label)
                            .legend(move |(x, y)| {
                                let s = BLACK.stroke_width(width);
                                let seg =
                                    |u: i32, v: i32| PathElement::new(vec![(u, 0), (v, 0)], s);
                                // Dotted: the pattern again, 14 pixels on.
                                let (c0, c1, d0, d1) = if b1 < 24 {
                                    (a0 + 14, a1 + 14, b0 + 14, b1 + 14)
                                } else {
                                    (a0, a1, b0, b1)
                                };
                                EmptyElement::at((x, y))
                                    + seg(a0, a1)
                                    + seg(b0, b1)
                                    + seg(c0, c1)
                                    + seg(d0, d1)
                            });
                    }
                    ctx.configure_series_labels()
                        .position(SeriesLabelPosition::UpperRight)
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .draw()?;
                }
            }};
        }
        panel!(&left, "linear", 0.0f64..1.0, f64::NEG_INFINITY, true);
        panel!(
            &right,
            "log (0, the limit lobe alone, not drawn)",
            (7.0e-4f64..1.0).log_scale(),
            1.0e-3,
            false
        );
        root.present()?;
    }
    super::save_rgb(path, w, h, buf)
}

/// Runs the measurement, writes the CSV and the chart, prints the table.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let t = Instant::now();
    let named = surfaces();
    let glints: Vec<ProceduralGlints> = named
        .iter()
        .map(|(_, p)| ProceduralGlints::new(*p))
        .collect::<Result<_, _>>()?;
    let names: Vec<&'static str> = named.iter().map(|(n, _)| *n).collect();
    let jobs: Vec<(usize, f32)> = (0..glints.len())
        .flat_map(|s| areas(quick).into_iter().map(move |a| (s, a)))
        .collect();
    let mut rows: Vec<Row> = jobs
        .par_iter()
        .enumerate()
        .map(|(i, &(s, area))| measure(i as u64, names[s], &glints[s], area, quick))
        .collect();
    println!("statistics: {:.1} s", t.elapsed().as_secs_f64());
    let t = Instant::now();
    time_rows(&mut rows, &glints, quick)?;
    println!(
        "timing: {:.1} s; analytic GGX {:.3} µs per shading point",
        t.elapsed().as_secs_f64(),
        rows.first().map_or(f64::NAN, |r| r.ggx_seconds * 1e6)
    );
    println!("{}", table(&rows)?);
    let csv_path = output(out, "data", "procedural.csv");
    std::fs::write(&csv_path, csv(&rows)?)?;
    let png = output(out, "img", "procedural_tv.png");
    chart(&png, &rows, &names, quick)?;
    Ok(vec![
        Artifact::new(
            csv_path,
            "Procedural glints per surface and footprint: TV to the limit, ρ, limit weight, \
             lobes, mean P-NDF check, cost of a shading point against GGX.",
        ),
        Artifact::new(
            png,
            "Procedural glints: TV of a footprint's P-NDF to the limit NDF (Beckmann or GGX) against the \
             footprint (mean over random centres, ±2 standard errors), and of the mean P-NDF over \
             random centres.",
        ),
    ])
}
