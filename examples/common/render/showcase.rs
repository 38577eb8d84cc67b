//! The showcase of the render example: six materials on the same sphere (analytic gold, a mirror,
//! two glint conductors, a glint coat over paint, car paint: procedural metallic flakes over paint
//! under a clear coat), the normal map PNG it writes first, tone mapping and the progress bar.

use super::{Camera, Checker, Image, PointLight, Scene, Sky, render};
use crate::common::{Artifact, Res, save_rgb};
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, SchlickFresnel};
use brdf::glint::mixture::MixtureParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, FlakesParams, GlintModel, NormalMap, NormalRepair, ScratchedParams,
    TangentConvention, flakes, scratched,
};
use brdf::material::AnyFresnel;
use brdf::{Ggx, GlintMaterial, Lambert, Material, Vec2, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;
use std::f32::consts::PI;
use std::path::Path;
use std::time::Instant;

/// Render settings.
#[derive(Clone, Debug)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Side of the normal maps, in texels.
    pub map_size: usize,
    /// Map texels per pixel across the sphere's equator (the tiling follows from it).
    pub texels_per_pixel: f32,
    pub progress: bool,
}

impl Options {
    /// `cargo run --release --example render -- --quick` (≤ ~40 s for the six renders on 2 cores).
    pub fn quick() -> Options {
        Options {
            width: 320,
            height: 200,
            spp: 12,
            map_size: 256,
            texels_per_pixel: 3.0,
            progress: false,
        }
    }
    /// The gallery's preview: [`Options::quick`] at 240 × 150 and 6 spp (about a fifth of its time;
    /// the sky and the ground are noisier, the glints the same).
    pub fn preview() -> Options {
        Options {
            width: 240,
            height: 150,
            spp: 6,
            ..Options::quick()
        }
    }

    /// `cargo run --release --example render` without `--quick`.
    pub fn full() -> Options {
        Options {
            width: 640,
            height: 400,
            spp: 32,
            map_size: 512,
            texels_per_pixel: 3.0,
            progress: true,
        }
    }
}

/// A glint material of `map`: the Beckmann mixture of \[Chermain2019\] with 64 quadrature nodes
/// per lobe (the orb example's setting, 4× faster to build than the default), queried at the
/// default options (`GlintOptions::default()`): the renderer sets no level of detail.
pub fn glint_material(map: &NormalMap, fresnel: impl Into<AnyFresnel>) -> Res<GlintMaterial> {
    let params = MixtureParams {
        samples: 64,
        ..MixtureParams::default()
    };
    let model = GlintModel::from(BeckmannMixture::build(map, params)?);
    Ok(GlintMaterial::new(model, fresnel))
}

/// The car paint's procedural flakes, `n` texels per uv period (the showcase's map
/// size, so that its tiling puts the same ~3 texels per pixel on the sphere as the maps'): facets
/// tilted widely (α = 0.5), so that sparkles spread far from the highlight as metallic flakes do;
/// each facet nearly flat (α_f = 0.01, a point-like sparkle); 8 facets per texel, ~70 per pixel,
/// of which a few per hundred pixels catch the point light near the highlight.
pub fn car_paint_params(n: usize) -> ProceduralParams {
    ProceduralParams {
        alpha: Vec2::splat(0.5),
        facet_alpha: 0.01,
        density: 8.0,
        resolution: [n, n],
        seed: 5,
        ..ProceduralParams::default()
    }
}

/// The car paint's Lambert base: a deep blue.
const CAR_PAINT_BASE: Vec3 = Vec3::new(0.005, 0.01, 0.07);

/// The fraction of the car paint's area its aluminium flakes cover.
const FLAKE_COVERAGE: f32 = 0.2;

/// The car paint's clear coat: a varnish of index 1.5.
const CLEAR_COAT_ETA: f32 = 1.5;

/// A hammered-metal height field (overlapping parabolic dents, the deepest wins), `n` × `n`, tiled,
/// heights in texels; slopes up to ~0.3.
pub fn hammered_heights(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let dents: Vec<(Vec2, f32)> = (0..n * n / 40)
        .map(|_| {
            let c = Vec2::new(rng.random::<f32>(), rng.random::<f32>()) * n as f32;
            (c, 4.0 + 6.0 * rng.random::<f32>())
        })
        .collect();
    let wrap = |d: f32| d - n as f32 * (d / n as f32).round();
    (0..n * n)
        .map(|k| {
            let p = Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            dents.iter().fold(0.0f32, |h, &(c, r)| {
                let d2 = Vec2::new(wrap(p.x - c.x), wrap(p.y - c.y)).length_squared() / (r * r);
                h.min(-0.15 * r * (1.0 - d2).max(0.0))
            })
        })
        .collect()
}

/// The showcase scene around `sphere`: a unit sphere on a checkered ground, a strong point light
/// above left, a sky gradient. The map tiling puts `texels_per_pixel` texels per pixel on the
/// equator (∂p/∂u spans 2π r, ∂p/∂v π r, hence half as many tiles along v).
pub fn showcase(sphere: impl FnOnce(Vec2) -> Res<Material>, opts: &Options) -> Res<Scene> {
    let camera = Camera::look_at(
        Vec3::new(0.0, 1.5, 4.2),
        Vec3::new(0.0, 0.85, 0.0),
        32.0,
        opts.width,
        opts.height,
    );
    let radius_px = 1.0 / (4.2 * camera.pixel_step());
    let tiles_u = (opts.texels_per_pixel * 2.0 * PI * radius_px / opts.map_size as f32)
        .round()
        .max(1.0);
    let tiles = Vec2::new(tiles_u, (0.5 * tiles_u).round().max(1.0));
    let materials = vec![
        sphere(tiles)?,
        Lambert::new(Vec3::splat(0.6))?.into(),
        Lambert::new(Vec3::splat(0.25))?.into(),
    ];
    Ok(Scene {
        materials,
        center: Vec3::new(0.0, 1.0, 0.0),
        radius: 1.0,
        sphere: 0,
        ground: Some(Checker {
            a: 1,
            b: 2,
            square: 0.5,
        }),
        light: Some(PointLight {
            position: Vec3::new(-3.0, 5.0, 3.0),
            intensity: Vec3::splat(70.0),
        }),
        sky: Sky::Gradient { scale: 0.3 },
        camera,
    })
}

/// Exposure of the showcase images (fixed, so that the renders are comparable).
const EXPOSURE: f32 = 1.3;

/// Writes the hammered normal map PNG, then renders the six materials; returns the files.
pub fn run_with(out: &Path, opts: &Options) -> Res<Vec<Artifact>> {
    let n = opts.map_size;
    let mut artifacts = Vec::new();
    // (c)'s asset: a normal map PNG written from a height field, then read back like any file.
    let png = out.join("render_hammered_normals.png");
    let heights = hammered_heights(n, 11);
    let normals = NormalMap::from_heights(n, n, &heights, 1.0)?;
    save_rgb(
        &png,
        n as u32,
        n as u32,
        normals.to_rgb8(TangentConvention::OpenGl),
    )?;
    artifacts.push(Artifact::new(
        &png,
        "the hammered normal map (OpenGL convention) that the render example writes, then loads",
    ));
    let hammered =
        NormalMap::from_image_file(&png, TangentConvention::OpenGl, NormalRepair::Reject)?;
    let hammered = glint_material(&hammered, ConductorFresnel::COPPER)?;
    let scratched = scratched(n, n, ScratchedParams::default(), 7)?;
    let scratched = glint_material(&scratched, ConductorFresnel::SILVER)?;
    let flakes = flakes(
        n,
        n,
        FlakesParams {
            cell_texels: 6.0,
            tilt_sigma: 0.15,
        },
        3,
    )?;
    let flakes = glint_material(&flakes, DielectricFresnel::new(1.5)?)?;
    // Metallic flakes in the paint, under a clear coat (below). The glint layer covers the whole
    // surface, while a metallic paint's flakes cover a fraction of it: aluminium's reflectance
    // (F0 ≈ 0.91) on a fifth of the area is a Schlick term of f0 = 0.18.
    let flakes_in_paint = GlintMaterial::new(
        GlintModel::from(ProceduralGlints::new(car_paint_params(n))?),
        SchlickFresnel::new(Vec3::splat(FLAKE_COVERAGE) * ConductorFresnel::ALUMINIUM.f0())?,
    );
    type Make = Box<dyn FnOnce(Vec2) -> Res<Material>>;
    let shots: [(&str, &str, Make); 6] = [
        (
            "render_gold.png",
            "analytic gold: GGX α = 0.15, conductor Fresnel",
            Box::new(|_| {
                Ok(Material::microfacet(
                    Ggx::isotropic(0.15)?,
                    ConductorFresnel::GOLD,
                ))
            }),
        ),
        (
            "render_mirror.png",
            "the smooth limit: a perfect silver mirror (a delta lobe, no MIS on its samples)",
            Box::new(|_| Ok(Material::mirror(ConductorFresnel::SILVER))),
        ),
        (
            "render_scratched.png",
            "glints: silver with a procedural scratched map (Beckmann mixture)",
            Box::new(move |tiles| Ok(scratched.with_uv_scale(tiles)?.into())),
        ),
        (
            "render_hammered.png",
            "glints: copper with the hammered PNG normal map (Beckmann mixture)",
            Box::new(move |tiles| Ok(hammered.with_uv_scale(tiles)?.into())),
        ),
        (
            "render_flake_paint.png",
            "layered: a glint clear coat (flakes map, η = 1.5) over red Lambert paint",
            Box::new(move |tiles| {
                let coat = flakes.with_uv_scale(tiles)?;
                Ok(coat.over_base(Vec3::new(0.5, 0.03, 0.02))?.into())
            }),
        ),
        (
            "render_car_paint.png",
            "car paint: procedural metallic flakes (no normal map: α = 0.5, facets of α_f = 0.01, 8 \
             per texel; aluminium on a fifth of the area, Schlick f0 = 0.18) over dark blue Lambert \
             paint, under a smooth clear coat (η = 1.5)",
            Box::new(move |tiles| {
                let flakes = flakes_in_paint.with_uv_scale(tiles)?;
                Ok(Material::clear_coated(
                    flakes.over_base(CAR_PAINT_BASE)?,
                    CLEAR_COAT_ETA,
                )?)
            }),
        ),
    ];
    for (k, (file, caption, make)) in shots.into_iter().enumerate() {
        let scene = showcase(make, opts)?;
        let bar = progress_bar(opts.progress, opts.height as u64, file);
        let t = Instant::now();
        let img = render(&scene, opts.spp, 0x5EED + k as u64, &bar);
        bar.finish();
        let path = out.join(file);
        save_rgb(&path, img.width, img.height, tone_map(&img, EXPOSURE))?;
        let caption = format!(
            "{caption}; {}×{}, {} spp, {:.1} s (cargo run --release --example render)",
            img.width,
            img.height,
            opts.spp,
            t.elapsed().as_secs_f64()
        );
        artifacts.push(Artifact::new(path, caption));
    }
    Ok(artifacts)
}

/// The gallery's entry point: [`Options::preview`], or [`Options::full`] under `--full`.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    run_with(
        out,
        &if quick {
            Options::preview()
        } else {
            Options::full()
        },
    )
}

/// A progress bar over `len` rows (hidden when `show` is false, e.g. in tests).
pub fn progress_bar(show: bool, len: u64, msg: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{msg:>24} [{bar:30}] {pos}/{len} rows {elapsed}")
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(msg.to_string());
    bar
}

/// 8-bit sRGB of `img` scaled by `exposure`, through Narkowicz's fit of the ACES filmic curve
/// (x (2.51 x + 0.03)) / (x (2.43 x + 0.59) + 0.14) per channel, then the sRGB transfer function.
pub fn tone_map(img: &Image, exposure: f32) -> Vec<u8> {
    let aces = |x: f32| (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let srgb = |c: f32| {
        let s = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    img.pixels
        .iter()
        .flat_map(|p| {
            let c = *p * exposure;
            [srgb(aces(c.x)), srgb(aces(c.y)), srgb(aces(c.z))]
        })
        .collect()
}
