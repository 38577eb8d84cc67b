//! A small path tracer that shades a sphere with the crate's BRDFs, glints included, through the
//! public API only (the scene, camera and integrator are in `examples/common/render.rs`).
//!
//! `cargo run --release --example render [-- --quick] [--out DIR] [--spp N] [--width W]`
//! `cargo run --release --example render -- --timing [--quick] [--texels 10,500,30000]
//! [--materials mixture,bin] [--seed N | --map FILE.png]`
//!
//! Writes into DIR (default `target/brdf-out/`) a hammered normal map PNG (generated from a height
//! field, then loaded back like any asset) and six tone-mapped renders of the same scene: analytic
//! gold, a silver mirror, scratched silver glints (procedural map), hammered copper glints (the PNG
//! map), a glint clear coat over red paint (layered), and car paint (procedural aluminium flakes,
//! no normal map, over dark blue paint, under a smooth clear coat: `Material::clear_coated`).
//! `--quick` is the gallery's small, fast setting.
//!
//! `--timing` instead measures frame times: analytic GGX, the four glint models at their defaults
//! and conventional normal mapping on one scratched map at three map scales, alternating, and writes
//! `render_timing.csv` (examples/common/render/timing.rs). See docs/render.md.

use brdf_examples::common;

use common::Res;
use common::render::showcase::{Options, run_with};
use common::render::timing::{TimingOptions, run_timing};

fn main() -> Res<()> {
    let out = common::out_dir()?;
    if common::has_flag("--timing") {
        let mut opts = if common::has_flag("--quick") {
            TimingOptions::quick()
        } else {
            TimingOptions::full()
        };
        if let Some(list) = common::arg_value("--texels") {
            opts.texels_per_pixel = list.split(',').map(str::parse).collect::<Result<_, _>>()?;
        }
        if let Some(list) = common::arg_value("--materials") {
            opts.materials = list.split(',').map(str::to_string).collect();
        }
        if let Some(seed) = common::arg_value("--seed") {
            opts.seed = seed.parse()?;
        }
        if let Some(path) = common::arg_value("--map") {
            opts.map_file = Some(path.into());
        }
        run_timing(&out, &opts)?;
        return Ok(());
    }
    let mut opts = if common::has_flag("--quick") {
        Options::quick()
    } else {
        Options::full()
    };
    if let Some(spp) = common::arg_value("--spp") {
        opts.spp = spp.parse()?;
    }
    if let Some(w) = common::arg_value("--width") {
        let w: u32 = w.parse()?;
        opts.height = (w * opts.height / opts.width).max(1);
        opts.width = w.max(1);
    }
    opts.progress = true;
    for a in run_with(&out, &opts)? {
        println!("{}: {}", a.path.display(), a.caption);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::common::render::showcase::{Options, glint_material, progress_bar, showcase};
    use super::common::render::{Camera, Scene, Sky, render};
    use brdf::fresnel::NoFresnel;
    use brdf::glint::{ScratchedParams, bumpy, scratched};
    use brdf::{Vec2, Vec3};

    /// A 16 × 16 render at 2 spp of the glint showcase scene is finite and non-negative everywhere,
    /// and not black (the sphere and the lit ground return light).
    #[test]
    fn tiny_render_is_finite_and_non_negative() {
        let opts = Options {
            width: 16,
            height: 16,
            spp: 2,
            map_size: 32,
            texels_per_pixel: 3.0,
            progress: false,
        };
        let map = scratched(32, 32, ScratchedParams::default(), 1).unwrap();
        let glints = glint_material(&map, brdf::fresnel::ConductorFresnel::GOLD).unwrap();
        let scene = showcase(|tiles| Ok(glints.with_uv_scale(tiles)?.into()), &opts).unwrap();
        let img = render(&scene, opts.spp, 1, &progress_bar(false, 16, ""));
        assert_eq!(img.pixels.len(), 256);
        assert!(
            img.pixels
                .iter()
                .all(|p| p.is_finite() && p.min_element() >= 0.0)
        );
        assert!(img.pixels.iter().map(|p| p.element_sum()).sum::<f32>() > 0.0);
    }

    /// White furnace in the renderer's measure: a glint sphere with F = 1 in a constant white
    /// environment, no light, no ground. A surface that reflects at most what it receives gives
    /// pixels ≤ 1; the sphere's mean must be ≤ 1 + 4 standard errors (the standard error from the
    /// spread of the per-pixel means, each an independent estimate), and above 0.5 (the glint
    /// surface loses only its masking's share, so a black or broken integrator fails too).
    #[test]
    fn white_furnace_glint_sphere_is_at_most_one() {
        let (w, h, spp) = (32u32, 32u32, 16u32);
        // A rough map (RMS slope 0.3), so that both the sky sampler and BRDF sampling carry weight.
        let map = bumpy(64, 64, 0.3, 4.0, 2).unwrap();
        let glints = glint_material(&map, NoFresnel).unwrap();
        let glints = glints.with_uv_scale(Vec2::new(2.0, 1.0));
        let scene = Scene {
            materials: vec![glints.unwrap().into()],
            center: Vec3::ZERO,
            radius: 1.0,
            sphere: 0,
            ground: None,
            light: None,
            sky: Sky::Constant(Vec3::ONE),
            camera: Camera::look_at(Vec3::new(0.0, 0.0, 3.2), Vec3::ZERO, 45.0, w, h),
        };
        let img = render(&scene, spp, 3, &progress_bar(false, h as u64, ""));
        // Pixels whose 3 × 3 grid of sub-pixel points all hit the sphere (no background mixed in).
        let inside = |x: u32, y: u32| {
            (0..9).all(|k| {
                let px = Vec2::new(
                    x as f32 + 0.1 + 0.4 * (k % 3) as f32,
                    y as f32 + 0.1 + 0.4 * (k / 3) as f32,
                );
                let d = scene.camera.direction_to(px);
                scene.intersect(scene.camera.eye, d).is_some()
            })
        };
        let values: Vec<f64> = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .filter(|&(x, y)| inside(x, y))
            .map(|(x, y)| img.pixels[(y * w + x) as usize].x as f64)
            .collect();
        assert!(values.len() > 200, "{} pixels on the sphere", values.len());
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        let se = (var / n).sqrt();
        eprintln!(
            "furnace: mean {mean:.4}, standard error {se:.4}, {} pixels",
            values.len()
        );
        assert!(mean <= 1.0 + 4.0 * se, "furnace mean {mean} > 1 + 4 × {se}");
        assert!(mean > 0.5, "furnace mean {mean}");
    }

    /// The timing harness's footprint measure: the mean texel area of the camera's pixel footprints
    /// on the sphere grows as the tiling squared, and the tiling chosen for a target meets it.
    #[test]
    fn timing_texels_per_pixel_follow_the_tiling() {
        use super::common::render::timing::{mean_texels_per_pixel, tiles_for, timing_scene};
        let scene = timing_scene(brdf::Material::mirror(NoFresnel), 64, 48);
        let a = mean_texels_per_pixel(&scene, Vec2::new(2.0, 1.0), 1024);
        let b = mean_texels_per_pixel(&scene, Vec2::new(4.0, 2.0), 1024);
        assert!(a > 0.0 && (b / a - 4.0).abs() < 0.01, "{a} → {b}");
        for target in [10.0f32, 500.0, 30_000.0] {
            let got = mean_texels_per_pixel(&scene, tiles_for(&scene, target, 1024), 1024);
            assert!((got / target as f64 - 1.0).abs() < 0.01, "{target}: {got}");
        }
    }
}
