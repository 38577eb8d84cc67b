//! Where the glint models' bias floor on the orb comes from (`orb -- --bias`): the mixture (and the
//! σ_ε-matched bin map and position-normal map) rendered at 1 evaluation per pixel with one
//! candidate source of error switched off at a time, each against reference (a) of the same
//! lighting. See docs/orb.md, "Bias floor decomposition".
//!
//! The candidates: the level of detail (`lod_lobes` ∞, `lod_tolerance` 0: the full mixture), the
//! masking terms (approximate instead of exact), `MixtureParams::samples` 256 instead of 64 (a
//! control: the default moment method is the separable filter, which does not read it), the seed
//! kernel (the paper's Gaussian on the texel centres instead of the default cell between them), the
//! lobe spacing (0.5 texel instead of 1: twice as many lobe centres per axis, each lobe over a
//! quarter of the area), and the light: a disc light of angular radius
//! [`AREA_LIGHT_DEGREES`] seen from the sphere's centre, in the reference and the model alike, in
//! place of the point light.

use super::metrics::{coverage, errors, reference_noise};
use super::render::{Image, glint_pixel, normal_mapped_pixel};
use super::scene::{Scene, ShadingPoint};
use super::{MapSource, OrbOptions, load_map};
use crate::common::material::{Configured, SIGMA_EPS, binmap_at};
use crate::common::{Artifact, Res, register_font, save_rgb};
use brdf::bxdf::{Bxdf, Masking, MicrofacetBrdf};
use brdf::fresnel::Fresnel;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions, SeedKernel};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, GlintModel, GlintNdf, Kernel, NormalMap, PositionNormalMap, footprint_brdf,
};
use glam::{Vec2, Vec3};
use plotters::prelude::*;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Angular radius of the disc light seen from the sphere's centre (degrees).
pub const AREA_LIGHT_DEGREES: f32 = 3.0;
/// Points of the disc light per pixel (jittered per pixel, the same for the reference and the model).
const LIGHT_POINTS: u32 = 16;
/// Image size, map size, reference positions per half (k²): those of the full `--curves`.
const SIZE: u32 = 128;
const MAP_SIZE: usize = 512;
const REFERENCE_K: u32 = 48;

/// The lighting of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// The scene's point light.
    Point,
    /// A disc of angular radius [`AREA_LIGHT_DEGREES`] centred on the point light, facing the
    /// sphere, of the same total intensity.
    Disc,
}

/// The light points of pixel `pixel` at shading point `sp`: (wi in the tangent frame, I_j / r_j²),
/// with Σ I_j = I. For the disc, [`LIGHT_POINTS`] points of a sunflower spiral over the disc (equal
/// area each), rotated by a per-pixel angle: the same for every method in that pixel.
pub fn light_points(
    scene: &Scene,
    sp: &ShadingPoint,
    light: Light,
    pixel: u64,
) -> Vec<(Vec3, f32)> {
    match light {
        Light::Point => vec![(sp.wi, sp.irradiance)],
        Light::Disc => {
            // The unit sphere's hit point is its normal.
            let p = sp.frame.z;
            let axis = scene.light.normalize();
            let radius = scene.light.length() * AREA_LIGHT_DEGREES.to_radians().tan();
            let u = axis.any_orthonormal_vector();
            let v = axis.cross(u);
            let rot =
                (pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as f32 / (1u64 << 24) as f32;
            let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
            let per = scene.intensity / LIGHT_POINTS as f32;
            (0..LIGHT_POINTS)
                .map(|j| {
                    let r = radius * ((j as f32 + 0.5) / LIGHT_POINTS as f32).sqrt();
                    let a = golden * j as f32 + std::f32::consts::TAU * rot;
                    let q = scene.light + r * (a.cos() * u + a.sin() * v);
                    let d = q - p;
                    let r2 = d.length_squared();
                    (sp.frame.to_local(d / r2.sqrt()), per / r2)
                })
                .collect()
        }
    }
}

fn pixel_index(scene: &Scene, x: u32, y: u32) -> u64 {
    y as u64 * scene.size as u64 + x as u64
}

fn shading_at(scene: &Scene, x: u32, y: u32) -> Option<ShadingPoint> {
    scene.shading(Vec2::new(x as f32 + 0.5, y as f32 + 0.5))
}

fn render(scene: &Scene, pixel: impl Fn(u32, u32) -> Vec3 + Sync) -> Image {
    let pixels: Vec<Vec3> = (0..scene.size * scene.size)
        .into_par_iter()
        .map(|k| pixel(k % scene.size, k / scene.size))
        .collect();
    Image {
        size: scene.size,
        pixels,
    }
}

/// A glint model at 1 evaluation per pixel under `light`: one patch per pixel, evaluated toward
/// every light point (point light: exactly [`glint_pixel`]).
fn render_model(scene: &Scene, model: &Configured, light: Light) -> Image {
    render(scene, |x, y| {
        if light == Light::Point {
            return glint_pixel(scene, model, x, y, 1);
        }
        let Some(sp) = shading_at(scene, x, y) else {
            return Vec3::ZERO;
        };
        let brdf = MicrofacetBrdf::new(model.patch(&sp.footprint()), scene.fresnel)
            .with_masking(Masking::Separable);
        let mut sum = Vec3::ZERO;
        for (wi, e) in light_points(scene, &sp, light, pixel_index(scene, x, y)) {
            let l = brdf.eval(sp.wo, wi) * (wi.z.max(0.0) * e);
            if l.is_finite() {
                sum += l;
            }
        }
        sum
    })
}

/// Reference (a) of one half under `light` (k² positions in all, split evenly over the light
/// points), and reference (b) of the same positions.
fn reference_half(
    scene: &Scene,
    map: &NormalMap,
    light: Light,
    k: u32,
    seed: u64,
) -> (Image, Image) {
    let pixels: Vec<(Vec3, Vec3)> = (0..scene.size * scene.size)
        .into_par_iter()
        .map(|idx| {
            let (x, y) = (idx % scene.size, idx / scene.size);
            let Some(sp) = shading_at(scene, x, y) else {
                return (Vec3::ZERO, Vec3::ZERO);
            };
            let pixel = pixel_index(scene, x, y);
            let lights = light_points(scene, &sp, light, pixel);
            let samples = ((k * k) as usize / lights.len()).max(1);
            let fp = sp.footprint();
            let (mut a, mut b) = (Vec3::ZERO, Vec3::ZERO);
            for (j, (wi, e)) in lights.into_iter().enumerate() {
                let s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ pixel ^ ((j as u64) << 40);
                let r =
                    footprint_brdf(map, &fp, Kernel::Gaussian, sp.wo, wi, SIGMA_EPS, samples, s);
                let radiance = wi.z.max(0.0) * e;
                if let Some(h) = (sp.wo + wi).try_normalize() {
                    let v = scene.fresnel.eval(sp.wo.dot(h)) * (r.pbrdf() as f32 * radiance);
                    if v.is_finite() {
                        a += v;
                    }
                }
                let spj = ShadingPoint {
                    wi,
                    irradiance: e,
                    ..sp
                };
                b += normal_mapped_pixel(scene, map, SIGMA_EPS, &spj, samples, s);
            }
            (a, b)
        })
        .collect();
    let image = |f: fn(&(Vec3, Vec3)) -> Vec3| Image {
        size: scene.size,
        pixels: pixels.iter().map(f).collect(),
    };
    (image(|p| p.0), image(|p| p.1))
}

/// One configuration of the decomposition.
struct Variant {
    label: &'static str,
    model: Configured,
    build_s: f64,
    light: Light,
}

fn mixture(map: &NormalMap, params: MixtureParams) -> Res<(Configured, f64)> {
    let t = Instant::now();
    let m = BeckmannMixture::build(map, params)?;
    Ok((
        Configured::new(Arc::new(m.into())),
        t.elapsed().as_secs_f64(),
    ))
}

fn with_options(c: &Configured, options: PatchOptions) -> Configured {
    let mut c = c.clone();
    c.options.mixture = options;
    c
}

/// The configurations, each with one candidate source switched off from the first ("mixture").
fn variants(map: &NormalMap) -> Res<Vec<Variant>> {
    let base = MixtureParams {
        sigma_min: SIGMA_EPS,
        samples: 64,
        ..MixtureParams::default()
    };
    let (m, m_s) = mixture(map, base)?;
    let (m256, m256_s) = mixture(
        map,
        MixtureParams {
            samples: 256,
            ..base
        },
    )?;
    let (fine, fine_s) = mixture(
        map,
        MixtureParams {
            spacing: 0.5,
            ..base
        },
    )?;
    let (gauss, gauss_s) = mixture(
        map,
        MixtureParams {
            seed: SeedKernel::Gaussian,
            ..base
        },
    )?;
    // Every level of detail off (the full mixture at every footprint), as the curves' "mixture (no
    // LOD)": no cap, no merged levels, no sub-texel lobe, no filtered mixture.
    let no_lod = PatchOptions::full();
    let approx = PatchOptions {
        masking: MaskingMode::Approximate,
        ..PatchOptions::default()
    };
    let t = Instant::now();
    let binmap = binmap_at(map, SIGMA_EPS)?;
    let binmap_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let pn: Arc<GlintModel> = Arc::new(
        PositionNormalMap::build(
            map,
            PositionNormalParams {
                sigma_r: SIGMA_EPS,
                ..PositionNormalParams::default()
            },
        )?
        .into(),
    );
    let pn_s = t.elapsed().as_secs_f64();
    let v = |label, model: Configured, build_s, light| Variant {
        label,
        model,
        build_s,
        light,
    };
    Ok(vec![
        v("mixture", m.clone(), m_s, Light::Point),
        v("(i) no LOD", with_options(&m, no_lod), m_s, Light::Point),
        v(
            "(ii) approx. masking",
            with_options(&m, approx),
            m_s,
            Light::Point,
        ),
        v("256 nodes/lobe", m256, m256_s, Light::Point),
        v("(iii) Gaussian seed", gauss, gauss_s, Light::Point),
        v("(iv) spacing 0.5", fine.clone(), fine_s, Light::Point),
        v(
            "(iv) spacing 0.5 + no LOD",
            with_options(&fine, no_lod),
            fine_s,
            Light::Point,
        ),
        v("(v) disc light", m.clone(), m_s, Light::Disc),
        v(
            "(v) disc light + no LOD",
            with_options(&m, no_lod),
            m_s,
            Light::Disc,
        ),
        v(
            "bin map",
            Configured::binmap(binmap.clone(), SIGMA_EPS),
            binmap_s,
            Light::Point,
        ),
        v(
            "bin map + disc light",
            Configured::binmap(binmap, SIGMA_EPS),
            binmap_s,
            Light::Disc,
        ),
        v(
            "position-normal",
            Configured::new(pn.clone()),
            pn_s,
            Light::Point,
        ),
        v(
            "position-normal + disc light",
            Configured::new(pn),
            pn_s,
            Light::Disc,
        ),
    ])
}

/// One measured configuration.
struct Row {
    map: String,
    scale: f32,
    label: String,
    build_s: f64,
    render_s: f64,
    vs_a: f64,
    vs_b: f64,
    energy: f64,
    noise_a: f64,
}

/// The maps and scales of the decomposition (34 and 2 186 texels per pixel).
pub const MAPS: [&str; 5] = ["scratched", "brushed", "bumpy", "flakes", "fractal"];
/// Map scales k (tiles (2k, k)).
pub const SCALES: [f32; 2] = [2.0, 16.0];

/// The lobe-spacing ladder (`orb -- --bias --spacing [--scales K,K,…]`): the mixture (default
/// options) built at spacings 1, 0.5 and 0.25 texel with each seed kernel, under the point light, on the five maps at each
/// map scale k of `scales` (tiles (2k, k); 0.35, 1, 2 give 1, 9, 34 texels per pixel); writes
/// orb_bias_spacing.csv into `out`.
pub fn run_spacing(out: &Path, scales: &[f32]) -> Res<()> {
    std::fs::create_dir_all(out)?;
    let wall = Instant::now();
    let mut csv = String::from(
        "map,scale,seed,spacing,build_s,render_s,rel_rmse_denoised,rel_rmse_denoised_vs_b,energy_error,reference_noise\n",
    );
    for name in MAPS {
        let orb = OrbOptions {
            map: MapSource::parse(name),
            map_size: MAP_SIZE,
            progress: false,
            ..OrbOptions::default()
        };
        let map = load_map(&orb)?;
        for &scale in scales {
            let scene = Scene::new(SIZE, Vec2::new(2.0 * scale, scale));
            let mask = coverage(&scene);
            let (a0, b0) = reference_half(&scene, &map, Light::Point, REFERENCE_K, orb.seed);
            let (a1, b1) = reference_half(&scene, &map, Light::Point, REFERENCE_K, orb.seed + 1);
            let noise_a = reference_noise(&a0, &a1, &mask);
            for (seed, spacing) in [SeedKernel::Cell, SeedKernel::Gaussian]
                .into_iter()
                .flat_map(|k| [1.0, 0.5, 0.25].map(|h| (k, h)))
            {
                let (m, build_s) = mixture(
                    &map,
                    MixtureParams {
                        sigma_min: SIGMA_EPS,
                        spacing,
                        seed,
                        ..MixtureParams::default()
                    },
                )?;
                let t = Instant::now();
                let img = render_model(&scene, &m, Light::Point);
                let render_s = t.elapsed().as_secs_f64();
                let ea = errors(&img, &a0, &a1, &mask);
                let eb = errors(&img, &b0, &b1, &mask);
                let _ = writeln!(
                    csv,
                    "{name},{scale},{seed:?},{spacing},{build_s:.3},{render_s:.3},{:.4},{:.4},{:.4},{noise_a:.4}",
                    ea.rel_rmse_denoised, eb.rel_rmse_denoised, ea.energy
                );
            }
        }
        eprintln!(
            "spacing: {name} done at {:.0} s",
            wall.elapsed().as_secs_f64()
        );
    }
    let path = out.join("orb_bias_spacing.csv");
    std::fs::write(&path, csv)?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Runs the decomposition; writes orb_bias.csv and orb_bias_decomposition.png into `out`.
pub fn run(out: &Path) -> Res<Vec<Artifact>> {
    std::fs::create_dir_all(out)?;
    let wall = Instant::now();
    let mut rows: Vec<Row> = Vec::new();
    for name in MAPS {
        let orb = OrbOptions {
            map: MapSource::parse(name),
            map_size: MAP_SIZE,
            progress: false,
            ..OrbOptions::default()
        };
        let map = load_map(&orb)?;
        let variants = variants(&map)?;
        for scale in SCALES {
            let scene = Scene::new(SIZE, Vec2::new(2.0 * scale, scale));
            let mask = coverage(&scene);
            for light in [Light::Point, Light::Disc] {
                let (a0, b0) = reference_half(&scene, &map, light, REFERENCE_K, orb.seed);
                let (a1, b1) = reference_half(&scene, &map, light, REFERENCE_K, orb.seed + 1);
                let noise_a = reference_noise(&a0, &a1, &mask);
                for var in variants.iter().filter(|v| v.light == light) {
                    let t = Instant::now();
                    let img = render_model(&scene, &var.model, light);
                    let render_s = t.elapsed().as_secs_f64();
                    let ea = errors(&img, &a0, &a1, &mask);
                    rows.push(Row {
                        map: name.to_string(),
                        scale,
                        label: var.label.to_string(),
                        build_s: var.build_s,
                        render_s,
                        vs_a: ea.rel_rmse_denoised,
                        vs_b: errors(&img, &b0, &b1, &mask).rel_rmse_denoised,
                        energy: ea.energy,
                        noise_a,
                    });
                }
            }
            eprintln!(
                "bias: {name} ×{scale} done at {:.0} s",
                wall.elapsed().as_secs_f64()
            );
        }
    }
    let mut csv = String::from(
        "map,scale,method,build_s,render_s,rel_rmse_denoised,rel_rmse_denoised_vs_b,energy_error,reference_noise\n",
    );
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{:.3},{:.3},{:.4},{:.4},{:.4},{:.4}",
            r.map, r.scale, r.label, r.build_s, r.render_s, r.vs_a, r.vs_b, r.energy, r.noise_a
        );
    }
    let csv_path = out.join("orb_bias.csv");
    std::fs::write(&csv_path, csv)?;
    let chart_path = out.join("orb_bias_decomposition.png");
    chart(&chart_path, &rows)?;
    println!(
        "orb bias decomposition: image {SIZE}², map {MAP_SIZE}², reference 2 × {} positions per pixel, wall time {:.0} s",
        REFERENCE_K * REFERENCE_K,
        wall.elapsed().as_secs_f64()
    );
    for p in [&csv_path, &chart_path] {
        println!("wrote {}", p.display());
    }
    Ok(vec![
        Artifact::new(
            &chart_path,
            format!(
                "Orb bias-floor decomposition: denoised relative RMSE against reference (a) at 1 \
                 evaluation per pixel, one candidate source switched off at a time (no level-of-detail \
                 cap, approximate masking, 256 quadrature nodes per lobe, lobe spacing 0.5, a disc \
                 light of {AREA_LIGHT_DEGREES}° in reference and model), per map at 34 and 2 186 \
                 texels per pixel."
            ),
        ),
        Artifact::new(&csv_path, "Every configuration of the decomposition (CSV)."),
    ])
}

/// Redraws orb_bias_decomposition.png next to `csv` from an orb_bias.csv written by [`run`]
/// (`orb -- --bias --chart CSV`).
pub fn chart_from_csv(csv: &Path) -> Res<()> {
    let text = std::fs::read_to_string(csv)?;
    let mut rows = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 9 {
            continue;
        }
        // The label may hold commas: everything between the scale and the last six fields.
        let n = f.len();
        rows.push(Row {
            map: f[0].to_string(),
            scale: f[1].parse()?,
            label: f[2..n - 6].join(","),
            build_s: f[n - 6].parse()?,
            render_s: f[n - 5].parse()?,
            vs_a: f[n - 4].parse()?,
            vs_b: f[n - 3].parse()?,
            energy: f[n - 2].parse()?,
            noise_a: f[n - 1].parse()?,
        });
    }
    let path = csv.with_file_name("orb_bias_decomposition.png");
    chart(&path, &rows)?;
    println!("wrote {}", path.display());
    Ok(())
}

/// Grouped bars: one panel per scale, maps along x, one bar per configuration.
fn chart(path: &Path, rows: &[Row]) -> Res<()> {
    register_font();
    let mut labels: Vec<&str> = Vec::new();
    for r in rows {
        if !labels.contains(&r.label.as_str()) {
            labels.push(&r.label);
        }
    }
    let (pw, ph) = (900u32, 340u32);
    let (w, h) = (pw, ph * SCALES.len() as u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let panels = root.split_evenly((SCALES.len(), 1));
        let n = labels.len() as f64;
        for (pi, (area, scale)) in panels.iter().zip(SCALES).enumerate() {
            // Room above the bars for the legend in the first panel.
            let top = if pi == 0 { 1.7 } else { 0.5 };
            let tpp = if scale < 4.0 { 34 } else { 2186 };
            let mut c = ChartBuilder::on(area)
                .caption(
                    format!(
                        "denoised rel. RMSE vs (a), 1 eval/px, ~{tpp} texels/px (tiles {}x{scale})",
                        2.0 * scale
                    ),
                    ("sans-serif", 14),
                )
                .margin(6)
                .x_label_area_size(22)
                .y_label_area_size(40)
                .build_cartesian_2d(0.0..MAPS.len() as f64, 0.0..top)?;
            c.configure_mesh()
                .disable_x_mesh()
                .x_labels(MAPS.len() * 2 + 1)
                .x_label_formatter(&|x| {
                    let i = x.floor() as usize;
                    if (x - i as f64 - 0.5).abs() < 0.01 && i < MAPS.len() {
                        MAPS[i].to_string()
                    } else {
                        String::new()
                    }
                })
                .label_style(("sans-serif", 11))
                .draw()?;
            for (li, label) in labels.iter().enumerate() {
                let col = Palette99::pick(li).to_rgba();
                let bars: Vec<Rectangle<(f64, f64)>> = rows
                    .iter()
                    .filter(|r| r.scale == scale && r.label == *label)
                    .filter_map(|r| {
                        let m = MAPS.iter().position(|&x| x == r.map)? as f64;
                        let x0 = m + 0.05 + 0.9 * li as f64 / n;
                        let x1 = x0 + 0.9 / n;
                        Some(Rectangle::new(
                            [(x0, 0.0), (x1, r.vs_a.min(top))],
                            col.filled(),
                        ))
                    })
                    .collect();
                c.draw_series(bars)?.label(*label).legend(move |(x, y)| {
                    Rectangle::new([(x, y - 4), (x + 10, y + 4)], col.filled())
                });
            }
            c.draw_series(LineSeries::new(
                [(0.0, 0.1), (MAPS.len() as f64, 0.1)],
                BLACK.stroke_width(1),
            ))?;
            if pi == 0 {
                c.configure_series_labels()
                    .position(SeriesLabelPosition::UpperLeft)
                    .label_font(("sans-serif", 10))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()?;
            }
        }
        root.present()?;
    }
    save_rgb(path, w, h, buf)
}
