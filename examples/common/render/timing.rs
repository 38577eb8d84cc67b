//! The render example's frame-time harness (`--timing`): what a glint material costs a path tracer
//! against an analytic GGX material, at three map scales, every material at its default options.
//!
//! The scene is a unit sphere alone (no ground) under a point light (next-event estimation) and a
//! constant sky (one cosine-weighted sky sample per vertex, MIS against `Bxdf::sample`), seen by a
//! pinhole camera; the sphere's materials share one procedural scratched normal map (1024², seed 7):
//!
//! - analytic GGX, α = √2 σ for the map's per-axis RMS slope σ (the Beckmann-equivalent roughness
//!   of the map's slope distribution), silver Fresnel;
//! - the Beckmann mixture, the inverse bin map and the position-normal map, each
//!   `GlintModel::from(Model::build(&map, Params::default()))` in a `GlintMaterial` with the
//!   default `GlintOptions`, silver Fresnel;
//! - the bin map again with `exact_masking_texels` at its floor, 128 (per-query option): footprints
//!   above 128 texels take the masking of their moment lobe (O(1)) instead of their own bins;
//! - conventional normal mapping for reference: `Material::NormalMapped` of GGX α = 0.02 (silver)
//!   through the tilt adapter (the map's interpolated normal at the footprint's centre);
//! - procedural glints (`ProceduralGlints`, no map): the Beckmann limit of the same α as the
//!   analytic GGX, one facet per texel of a `map_size`² grid (the map's texels, so that the texels
//!   per pixel are the same), facet roughness 0.02, silver Fresnel; and the same surface of the GGX
//!   limit ("procedural glints (GGX)", converging to the analytic GGX itself);
//! - the mixture as a glint clear coat (dielectric Fresnel η = 1.5) over red Lambert paint
//!   (`GlintMaterial::over_base`, a `LayeredBrdf`): its time against the plain mixture's is the
//!   cost of the coat's first-bounce reflectance R̂(wo).
//!
//! Every material renders the same image at every scale; within a round the materials alternate
//! (round-robin, scales in turn), so that a change of the machine's load falls on all of them alike.
//! The table reports per material and scale the minimum and median wall time over the rounds, the
//! median's ratio to the analytic GGX's median at that scale, and the mean radiance of the pixels
//! whose centre sees the sphere (an energy sanity check: every material renders the same map).

use super::{Camera, PointLight, Scene, Sky, render};
use crate::common::Res;
use crate::common::render::showcase::progress_bar;
use brdf::fresnel::{ConductorFresnel, DielectricFresnel};
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralLimit, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintOptions, NormalMap, NormalRepair,
    PositionNormalMap, ScratchedParams, TangentConvention, scratched,
};
use brdf::material::{NormalMappedMaterial, NormalMapping};
use brdf::{Ggx, GlintMaterial, Material, Vec2, Vec3};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Settings of one timing run.
#[derive(Clone, Debug)]
pub struct TimingOptions {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Side of the scratched map, in texels.
    pub map_size: usize,
    /// Target mean texels per pixel (the pixel's footprint on the sphere, before the 1/√spp share
    /// of each sample), one scale each.
    pub texels_per_pixel: Vec<f32>,
    /// Rounds of the round-robin (≥ 2).
    pub rounds: usize,
    /// Materials to time, by label substring (case-insensitive; `=label` for the label alone);
    /// empty: all. Analytic GGX is always timed (every ratio is against it).
    pub materials: Vec<String>,
    /// Seed of the scratched map (7: the map of docs/results.md).
    pub seed: u64,
    /// A normal-map image to time instead of the scratched map (square; `map_size` is then its
    /// side), decoded as OpenGL-convention tangent-space normals.
    pub map_file: Option<std::path::PathBuf>,
}

impl TimingOptions {
    /// `--timing`: 320 × 240, 4 spp, 1024² map, ~10, ~500 and ~30,000 texels per pixel, 3 rounds.
    pub fn full() -> TimingOptions {
        TimingOptions {
            width: 320,
            height: 240,
            spp: 4,
            map_size: 1024,
            texels_per_pixel: vec![10.0, 500.0, 30_000.0],
            rounds: 3,
            materials: Vec::new(),
            seed: 7,
            map_file: None,
        }
    }

    /// `--timing --quick`: 160 × 120 and 2 rounds, otherwise as [`TimingOptions::full`].
    pub fn quick() -> TimingOptions {
        TimingOptions {
            width: 160,
            height: 120,
            rounds: 2,
            ..TimingOptions::full()
        }
    }
}

/// Label of the bin map with `exact_masking_texels` at its floor (128).
const BIN_MAP_MOMENT: &str = "bin map (moment masking from 128 texels)";

/// One material of the harness: its label and how to make it for a map tiling.
struct Entry {
    label: &'static str,
    make: Box<dyn Fn(Vec2) -> Res<Material>>,
}

/// One row of the result table.
#[derive(Clone, Debug)]
pub struct TimingRow {
    pub material: &'static str,
    pub target_texels: f32,
    /// Mean texels per pixel over the sphere's pixels (the pixel's own footprint).
    pub texels_per_pixel: f64,
    /// The same per sample (the footprint a camera hit queries: the pixel's times 1/spp).
    pub texels_per_sample: f64,
    pub times: Vec<f64>,
    pub mean_radiance: f64,
}

impl TimingRow {
    pub fn min(&self) -> f64 {
        self.times.iter().copied().fold(f64::INFINITY, f64::min)
    }
    pub fn median(&self) -> f64 {
        median(&self.times)
    }
}

/// The median of `xs` (the mean of the middle two for an even count; NaN when empty).
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// The timing scene around `sphere`: a unit sphere at the origin, no ground, a point light above
/// left, a constant sky.
pub fn timing_scene(sphere: Material, width: u32, height: u32) -> Scene {
    Scene {
        materials: vec![sphere],
        center: Vec3::ZERO,
        radius: 1.0,
        sphere: 0,
        ground: None,
        light: Some(PointLight {
            position: Vec3::new(-3.0, 4.0, 3.0),
            intensity: Vec3::splat(30.0),
        }),
        sky: Sky::Constant(Vec3::splat(0.3)),
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 3.6), Vec3::ZERO, 40.0, width, height),
    }
}

/// Pixels whose centre sees the sphere, as indices into the image.
fn sphere_pixels(scene: &Scene) -> Vec<usize> {
    let cam = &scene.camera;
    (0..cam.height)
        .flat_map(|y| (0..cam.width).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let d = cam.direction_to(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            scene.intersect(cam.eye, d).is_some_and(|h| h.sphere)
        })
        .map(|(x, y)| (y * cam.width + x) as usize)
        .collect()
}

/// Areas, in texels of a `map_size`² map tiled `tiles` times over the sphere's uv, of the camera's
/// pixel footprints at the centres of the sphere's pixels.
fn pixel_areas(scene: &Scene, tiles: Vec2, map_size: usize) -> Vec<f64> {
    let cam = &scene.camera;
    let mut areas = Vec::new();
    for y in 0..cam.height {
        for x in 0..cam.width {
            let d = cam.direction_to(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let Some(hit) = scene.intersect(cam.eye, d).filter(|h| h.sphere) else {
                continue;
            };
            let fp = cam
                .ray_differential(hit.p)
                .footprint(hit.uv, hit.dpdu, hit.dpdv, hit.p, hit.n);
            let mapped = Footprint::from_differentials(
                fp.center_uv() * tiles,
                fp.duv_dx() * tiles,
                fp.duv_dy() * tiles,
            );
            let a = mapped.area_texels(map_size, map_size) as f64;
            if a.is_finite() {
                areas.push(a);
            }
        }
    }
    areas
}

/// Mean area, in texels of a `map_size`² map tiled `tiles` times over the sphere's uv, of the
/// camera's pixel footprints at the centres of the sphere's pixels.
pub fn mean_texels_per_pixel(scene: &Scene, tiles: Vec2, map_size: usize) -> f64 {
    let areas = pixel_areas(scene, tiles, map_size);
    areas.iter().sum::<f64>() / areas.len().max(1) as f64
}

/// Fractions of the sphere's pixels whose per-sample footprint (the pixel's area / `spp`) is below
/// 2 texels, in [2, 4096) and at least 4096: the ranges of the mixture's default forms (sub-texel
/// lobe, gathered lobes, filtered mixture where its measured error allows).
pub fn per_sample_split(scene: &Scene, tiles: Vec2, map_size: usize, spp: u32) -> [f64; 3] {
    let areas = pixel_areas(scene, tiles, map_size);
    let n = areas.len().max(1) as f64;
    let per = |lo: f64, hi: f64| {
        areas
            .iter()
            .filter(|&&a| (lo..hi).contains(&(a / spp.max(1) as f64)))
            .count() as f64
            / n
    };
    [per(0.0, 2.0), per(2.0, 4096.0), per(4096.0, f64::INFINITY)]
}

/// The tiling (2k, k) (square texels on the sphere: u spans 2πr, v spans πr) whose mean pixel
/// footprint is `target` texels. The area grows as k² until footprints reach the clamp of
/// [`Footprint`] (a few map periods, near the sphere's outline at wide footprints), so k is refined
/// by a few steps k ← k √(target / area(k)).
pub fn tiles_for(scene: &Scene, target: f32, map_size: usize) -> Vec2 {
    let unit = Vec2::new(2.0, 1.0);
    let mut k = 1.0f64;
    for _ in 0..8 {
        let a = mean_texels_per_pixel(scene, unit * k as f32, map_size);
        if a.is_nan() || a <= 0.0 {
            break;
        }
        k *= (target as f64 / a).sqrt();
    }
    unit * k as f32
}

/// The harness's procedural surfaces: the limit `limit` of roughness `alpha` (the analytic GGX's),
/// one facet per texel of an `n`² grid (the map's texels), facet α and density at their defaults,
/// seed `seed` (also `tools/shade_ir.rs` and `tools/frame_ir.rs`).
pub fn procedural_params(
    alpha: f32,
    n: usize,
    seed: u64,
    limit: ProceduralLimit,
) -> ProceduralParams {
    ProceduralParams {
        alpha: Vec2::splat(alpha),
        resolution: [n, n],
        seed,
        limit,
        ..Default::default()
    }
}

/// The per-axis RMS slope of `map`: √(⟨s_x² + s_y²⟩ / 2) over its texels.
pub fn rms_slope(map: &NormalMap) -> f32 {
    let s = map.slopes();
    let sum: f64 = s.iter().map(|v| v.length_squared() as f64).sum();
    (sum / (2 * s.len().max(1)) as f64).sqrt() as f32
}

/// The current `uptime` line (the load averages), or /proc/loadavg where `uptime` is missing.
pub fn uptime() -> String {
    std::process::Command::new("uptime")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .or_else(|| std::fs::read_to_string("/proc/loadavg").ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "load unknown".to_string())
}

/// Builds the materials (timed once, reported), then renders every material at every scale in
/// alternation for `opts.rounds` rounds; prints the table and writes `render_timing.csv` into `out`.
pub fn run_timing(out: &Path, opts: &TimingOptions) -> Res<Vec<TimingRow>> {
    let load_before = uptime();
    println!("uptime before: {load_before}");
    let (map, what) = match &opts.map_file {
        Some(path) => (
            NormalMap::from_image_file(path, TangentConvention::OpenGl, NormalRepair::default())?,
            format!("{}", path.display()),
        ),
        None => {
            let n = opts.map_size;
            let map = scratched(n, n, ScratchedParams::default(), opts.seed)?;
            (map, format!("scratched map, seed {}", opts.seed))
        }
    };
    if map.width() != map.height() {
        return Err(format!(
            "the timed map must be square ({}×{})",
            map.width(),
            map.height()
        )
        .into());
    }
    let n = map.width();
    let map = Arc::new(map);
    let alpha = std::f32::consts::SQRT_2 * rms_slope(&map);
    let silver = ConductorFresnel::SILVER;
    let wanted = |label: &str| {
        label == "analytic GGX"
            || opts.materials.is_empty()
            || opts.materials.iter().any(|m| match m.strip_prefix('=') {
                Some(exact) => label.eq_ignore_ascii_case(exact),
                None => label.to_lowercase().contains(&m.to_lowercase()),
            })
    };
    let mut builds = String::new();
    // Builds the model of the materials `labels` if one of them is timed.
    let mut timed_build =
        |labels: &[&str], f: &mut dyn FnMut() -> Res<GlintModel>| -> Res<Option<Arc<GlintModel>>> {
            if !labels.iter().any(|l| wanted(l)) {
                return Ok(None);
            }
            let t = Instant::now();
            let model = Arc::new(f()?);
            let s = t.elapsed().as_secs_f64();
            let _ = writeln!(builds, "  {}: {s:.2} s", labels[0]);
            Ok(Some(model))
        };
    // What a model measures for its level of detail is part of its build (timed with it).
    let mixture = timed_build(
        &[
            "Beckmann mixture",
            "mixture coat",
            "mixture (cut off)",
            "mixture (cut from 1024)",
        ],
        &mut || Ok(BeckmannMixture::build(&map, MixtureParams::default())?.into()),
    )?;
    let bin_map = timed_build(&["bin map", BIN_MAP_MOMENT], &mut || {
        Ok(BinMap::build(&map, BinMapParams::default())?.into())
    })?;
    let position_normal = timed_build(
        &[
            "position-normal",
            "position-normal (cut off)",
            "position-normal (cut from 1024)",
        ],
        &mut || Ok(PositionNormalMap::build(&map, PositionNormalParams::default())?.into()),
    )?;
    let procedural = timed_build(&["procedural glints"], &mut || {
        let params = procedural_params(alpha, n, opts.seed, ProceduralLimit::Beckmann);
        Ok(ProceduralGlints::new(params)?.into())
    })?;
    let procedural_ggx = timed_build(&["procedural glints (GGX)"], &mut || {
        let params = procedural_params(alpha, n, opts.seed, ProceduralLimit::Ggx);
        Ok(ProceduralGlints::new(params)?.into())
    })?;
    println!(
        "builds ({n}² {what}, default parameters, wall time, with the measured errors of \
         the levels of detail):\n{builds}"
    );
    // The forms the default options serve on this map, by footprint size: the footprints whose
    // work grows with their size (gathers) are the ones whose frame time grows with the scale.
    for model in [&mixture, &bin_map, &position_normal, &procedural]
        .into_iter()
        .flatten()
    {
        println!("{}", model.forms(&GlintOptions::default()));
    }
    let plain = |m: &Arc<GlintModel>| GlintMaterial::new(m.clone(), silver);
    let glint = |m: GlintMaterial| -> Box<dyn Fn(Vec2) -> Res<Material>> {
        Box::new(move |tiles| Ok(m.clone().with_uv_scale(tiles)?.into()))
    };
    let entry = |label: &'static str, model: &Option<Arc<GlintModel>>| {
        model.as_ref().map(|m| Entry {
            label,
            make: glint(plain(m)),
        })
    };
    let coat = match &mixture {
        Some(m) => Some(Entry {
            label: "mixture coat",
            make: glint(
                GlintMaterial::new(m.clone(), DielectricFresnel::new(1.5)?)
                    .over_base(Vec3::new(0.5, 0.03, 0.02))?,
            ),
        }),
        None => None,
    };
    let nm_map = map.clone();
    let all = [
        Some(Entry {
            label: "analytic GGX",
            make: Box::new(move |_| Ok(Material::microfacet(Ggx::isotropic(alpha)?, silver))),
        }),
        entry("Beckmann mixture", &mixture),
        mixture.as_ref().map(|m| {
            let mut options = GlintOptions::default();
            options.mixture.cut_nodes = 0;
            Entry {
                label: "mixture (cut off)",
                make: glint(plain(m).with_options(options)),
            }
        }),
        mixture.as_ref().map(|m| {
            let mut options = GlintOptions::default();
            options.mixture.cut_area = 1024.0;
            Entry {
                label: "mixture (cut from 1024)",
                make: glint(plain(m).with_options(options)),
            }
        }),
        entry("bin map", &bin_map),
        bin_map.as_ref().map(|m| {
            let mut options = GlintOptions::default();
            options.bin_map.exact_masking_texels = brdf::glint::binmap::MIN_MOMENT_MASKING_TEXELS;
            Entry {
                label: BIN_MAP_MOMENT,
                make: glint(plain(m).with_options(options)),
            }
        }),
        entry("position-normal", &position_normal),
        position_normal.as_ref().map(|m| {
            let mut options = GlintOptions::default();
            options.position_normal.cut_nodes = 0;
            Entry {
                label: "position-normal (cut off)",
                make: glint(plain(m).with_options(options)),
            }
        }),
        position_normal.as_ref().map(|m| {
            let mut options = GlintOptions::default();
            options.position_normal.cut_area = 1024.0;
            Entry {
                label: "position-normal (cut from 1024)",
                make: glint(plain(m).with_options(options)),
            }
        }),
        Some(Entry {
            label: "normal mapping",
            make: Box::new(move |tiles| {
                let base = Material::microfacet(Ggx::isotropic(0.02)?, silver);
                let nm = NormalMappedMaterial::new(nm_map.clone(), base)?
                    .with_mapping(NormalMapping::Tilt)
                    .with_uv_scale(tiles)?;
                Ok(nm.into())
            }),
        }),
        coat,
        entry("procedural glints", &procedural),
        entry("procedural glints (GGX)", &procedural_ggx),
    ];
    let entries: Vec<Entry> = all
        .into_iter()
        .flatten()
        .filter(|e| wanted(e.label))
        .collect();
    println!(
        "scene: unit sphere, point light + constant sky, {}×{}, {} spp; analytic GGX α = √2 × RMS slope = {alpha:.4}",
        opts.width, opts.height, opts.spp
    );
    let probe = timing_scene(Material::mirror(silver), opts.width, opts.height);
    let inside = sphere_pixels(&probe);
    let scales: Vec<(f32, Vec2, f64)> = opts
        .texels_per_pixel
        .iter()
        .map(|&t| {
            let tiles = tiles_for(&probe, t, n);
            (t, tiles, mean_texels_per_pixel(&probe, tiles, n))
        })
        .collect();
    for &(t, tiles, a) in &scales {
        let [lo, mid, hi] = per_sample_split(&probe, tiles, n, opts.spp);
        println!(
            "~{t} texels per pixel (mean {a:.0}): per-sample footprints < 2 texels {:.0} %, 2-4096 {:.0} %, >= 4096 {:.0} %",
            100.0 * lo,
            100.0 * mid,
            100.0 * hi
        );
    }
    let spp = opts.spp.max(1) as f64;
    let mut rows: Vec<TimingRow> = scales
        .iter()
        .flat_map(|&(t, _, a)| {
            entries.iter().map(move |e| TimingRow {
                material: e.label,
                target_texels: t,
                texels_per_pixel: a,
                texels_per_sample: a / spp,
                times: Vec::new(),
                mean_radiance: f64::NAN,
            })
        })
        .collect();
    for round in 0..opts.rounds.max(2) {
        for (s, &(_, tiles, _)) in scales.iter().enumerate() {
            for (k, e) in entries.iter().enumerate() {
                let scene = timing_scene((e.make)(tiles)?, opts.width, opts.height);
                let t = Instant::now();
                let img = render(&scene, opts.spp, 0x7153, &progress_bar(false, 0, ""));
                let dt = t.elapsed().as_secs_f64();
                let row = &mut rows[s * entries.len() + k];
                row.times.push(dt);
                row.mean_radiance = inside
                    .iter()
                    .map(|&i| img.pixels[i].element_sum() as f64 / 3.0)
                    .sum::<f64>()
                    / inside.len().max(1) as f64;
                eprintln!(
                    "round {round}: {:>16} at {:>6.0} texels/pixel: {dt:.3} s",
                    e.label, row.texels_per_pixel
                );
            }
        }
    }
    let load_after = uptime();
    let table = format_table(&rows, entries.len());
    println!("{table}");
    println!("uptime after: {load_after}");
    let csv = out.join("render_timing.csv");
    std::fs::write(
        &csv,
        format_csv(&rows, entries.len(), &load_before, &load_after),
    )?;
    println!("{}", csv.display());
    Ok(rows)
}

/// The median time of the first row (analytic GGX) of the block of `per_scale` rows holding row `i`.
fn reference_median(rows: &[TimingRow], per_scale: usize, i: usize) -> f64 {
    rows[i / per_scale * per_scale].median()
}

/// The result table in Markdown.
pub fn format_table(rows: &[TimingRow], per_scale: usize) -> String {
    let mut s = String::from(
        "| material | texels/pixel (per sample) | min s | median s | × analytic GGX (median) | mean radiance |\n|---|---|---|---|---|---|\n",
    );
    for (i, r) in rows.iter().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {:.0} ({:.0}) | {:.3} | {:.3} | {:.1} | {:.4} |",
            r.material,
            r.texels_per_pixel,
            r.texels_per_sample,
            r.min(),
            r.median(),
            r.median() / reference_median(rows, per_scale, i),
            r.mean_radiance
        );
    }
    s
}

/// The result table as CSV, the loads as comment lines.
pub fn format_csv(rows: &[TimingRow], per_scale: usize, before: &str, after: &str) -> String {
    let mut s = format!("# uptime before: {before}\n# uptime after: {after}\n");
    s.push_str("material,target_texels_per_pixel,texels_per_pixel,texels_per_sample,rounds,min_s,median_s,ratio_to_ggx_median,mean_radiance\n");
    for (i, r) in rows.iter().enumerate() {
        let _ = writeln!(
            s,
            "{},{},{:.1},{:.1},{},{:.4},{:.4},{:.3},{:.5}",
            r.material,
            r.target_texels,
            r.texels_per_pixel,
            r.texels_per_sample,
            r.times.len(),
            r.min(),
            r.median(),
            r.median() / reference_median(rows, per_scale, i),
            r.mean_radiance
        );
    }
    s
}
