//! The orb: a metallic sphere with a high-definition normal map under a point light, rendered with
//! each glint model and with the naive per-position reference (\[Chermain2019\] Fig. 1 and 11).
//!
//! The scene is exactly what the comparison needs and nothing more: one sphere of radius 1 at the
//! origin, one pinhole camera on the +z axis, one point light, direct lighting only (a convex sphere
//! cannot shadow itself, so there are no shadow rays). The normal map is tiled over the sphere's
//! (u, v) parametrisation ([`OrbOptions::tiles`] times); every pixel gets a footprint on the map from
//! analytic ray differentials, and the glint models shade it with one BRDF evaluation:
//!
//! L = f(wo, wi) · cos θi · I / r², f = `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`,
//!
//! in the renderer's measure (f = f_P A_P(wi)/cos θi, so L = f_P A_P(wi) I / r² with the P-BRDF of
//! \[Chermain2019\] eq. 7; src/bxdf/microfacet.rs, "The renderer's measure"). Two references see
//! the same positions of the same pixel kernel (the footprint's Gaussian k_P, pixel-centre frame,
//! linear uv) ([`brdf::glint::footprint_brdf`]): (a) the exact P-BRDF of the interpolated map (eq. 7
//! with the true P-NDF), the quantity the glint models approximate, and (b) conventional
//! normal-mapped rendering, what a renderer without glint support converges to. (b) is not the limit
//! of (a); their gap is the P-BRDF formulation's own modelling difference. See docs/orb.md.
//!
//! Layout: [`scene`] (sphere, camera, light, pixel footprints), [`render`] (the glint models, the
//! references and naive sampling), [`metrics`] (errors against the references), [`table`] (the
//! printed table and the CSV), [`chart`] (tone mapping, the PNGs and the labelled strip); [`run`]
//! does all of it for one map.

pub mod bias;
pub mod chart;
pub mod fractal;
pub mod metrics;
pub mod render;
pub mod scene;
pub mod table;

pub use chart::exposure_of;
pub use metrics::{Errors, coverage, errors, gap_errors, reference_noise};
pub use render::{
    Image, OrbMethod, References, Rendered, glint_pixel, mean_image, render_all,
    render_glint_evals, render_naive, render_references,
};
pub use scene::Scene;

use super::{Artifact, Res};
use brdf::glint::{
    BrushedParams, FlakesParams, NormalMap, NormalRepair, ScratchedParams, TangentConvention,
    brushed, bumpy, flakes, scratched,
};
use glam::Vec2;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where the normal map comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MapSource {
    /// One of the crate's procedural generators ("scratched", "brushed", "bumpy", "flakes") or the
    /// example's fractal height field ("fractal", [`fractal::fractal`]).
    Procedural(String),
    /// A normal-map image (PNG/EXR, OpenGL convention, below-horizon normals clamped to z ≥ 0.01).
    File(PathBuf),
}

impl MapSource {
    /// Parses `--map`: a generator name, otherwise a path.
    pub fn parse(s: &str) -> MapSource {
        match s {
            "scratched" | "brushed" | "bumpy" | "flakes" | "fractal" => {
                MapSource::Procedural(s.to_string())
            }
            _ => MapSource::File(PathBuf::from(s)),
        }
    }

    /// A short name for file names and labels.
    pub fn name(&self) -> String {
        match self {
            MapSource::Procedural(n) => n.clone(),
            MapSource::File(p) => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "map".to_string()),
        }
    }
}

/// Settings of one orb run. `Default` is the command line's default (≤ 60 s on 2 cores).
#[derive(Clone, Debug)]
pub struct OrbOptions {
    /// Image width and height in pixels.
    pub size: u32,
    /// The normal map.
    pub map: MapSource,
    /// Size of a procedural map (texels per side); ignored for files.
    pub map_size: usize,
    /// How many times the map is tiled over the sphere's u (longitude, full turn) and v (pole to
    /// pole). (2k, k) gives square texels at the equator.
    pub tiles: Vec2,
    /// Samples per pixel of the reference (rounded to twice a square: two independent stratified
    /// halves).
    pub spp: u32,
    /// Samples per pixel of the naive "equal-time" row (0: no such row).
    pub naive_spp: u32,
    /// The scene's intrinsic roughness σ_ε (per-axis slope standard deviation): the references' and
    /// naive sampling's near-specular lobe, and every glint model's (examples/common/material.rs).
    pub sigma_eps: f32,
    /// Seed of the procedural map and of the reference's jitter.
    pub seed: u64,
    /// Quasi-Monte Carlo nodes per lobe of the mixture build.
    pub mixture_samples: usize,
    /// Show progress bars on stderr.
    pub progress: bool,
}

impl Default for OrbOptions {
    fn default() -> Self {
        OrbOptions {
            size: 256,
            map: MapSource::Procedural("scratched".to_string()),
            map_size: 1024,
            tiles: Vec2::new(8.0, 4.0),
            spp: 512,
            naive_spp: 16,
            sigma_eps: super::material::SIGMA_EPS,
            seed: 7,
            mixture_samples: 64,
            progress: true,
        }
    }
}

/// The normal map of the options.
pub fn load_map(opts: &OrbOptions) -> Res<NormalMap> {
    let s = opts.map_size;
    Ok(match &opts.map {
        MapSource::Procedural(name) => match name.as_str() {
            "brushed" => brushed(s, s, BrushedParams::default(), opts.seed)?,
            "bumpy" => bumpy(s, s, 0.25, 4.0, opts.seed)?,
            "flakes" => flakes(s, s, FlakesParams::default(), opts.seed)?,
            "fractal" => fractal::fractal(s, &fractal::FractalParams::default(), opts.seed)?,
            _ => scratched(s, s, ScratchedParams::default(), opts.seed)?,
        },
        MapSource::File(path) => {
            NormalMap::from_image_file(path, TangentConvention::OpenGl, NormalRepair::ClampZ(0.01))?
        }
    })
}

/// Reference (a), the exact P-BRDF, as its row of the table and its panel: label, mean image of
/// the two halves, samples per pixel, render time, the relative noise of (a) and of (b), and the
/// exposure of the pictures.
pub struct ReferenceRow {
    /// "(a) exact P-BRDF, N spp".
    pub label: String,
    /// The mean of the two halves.
    pub image: Image,
    /// Samples per pixel (both halves).
    pub spp: u32,
    /// Render time of both references (s).
    pub render_s: f64,
    /// Relative noise of (a).
    pub noise: f64,
    /// Relative noise of (b).
    pub noise_b: f64,
    /// The exposure of every panel, from this image ([`exposure_of`]).
    pub exposure: f32,
}

/// One rendered row with its errors against reference (a) and its denoised relative RMSE against
/// (b) (NaN for the (b) row itself).
pub struct MethodRow<'a> {
    /// The rendered method.
    pub rendered: &'a Rendered,
    /// Errors against (a); for the (b) row, the gap between the references ([`gap_errors`]).
    pub errors: Errors,
    /// Denoised relative RMSE against (b).
    pub vs_b: f64,
}

impl<'a> MethodRow<'a> {
    /// Measures `rendered` against the references over `mask`.
    fn measure(rendered: &'a Rendered, refs: &References, mask: &[bool]) -> MethodRow<'a> {
        let (a0, a1) = &refs.pbrdf;
        let (b0, b1) = &refs.normal_mapped;
        let is_b = rendered.label.starts_with("(b)");
        let against_a = if is_b {
            gap_errors(refs, mask)
        } else {
            errors(&rendered.image, a0, a1, mask)
        };
        // Against (b); for the (b) row itself this is its own noise, so leave it out.
        let vs_b = if is_b {
            f64::NAN
        } else {
            errors(&rendered.image, b0, b1, mask).rel_rmse_denoised
        };
        MethodRow {
            rendered,
            errors: against_a,
            vs_b,
        }
    }
}

/// Renders, measures and writes everything: one PNG per method, the strip, the CSV. Prints the table.
///
/// Errors are measured against reference (a), the exact P-BRDF of the interpolated map, and (for
/// the "vs (b)" column) against (b), normal-mapped rendering; the row "(b) normal-mapped" measured
/// against (a) is the P-BRDF formulation's own modelling gap.
pub fn run(opts: &OrbOptions, out: &Path) -> Res<Vec<Artifact>> {
    std::fs::create_dir_all(out)?;
    let t = Instant::now();
    let map = load_map(opts)?;
    let map_s = t.elapsed().as_secs_f64();
    let name = opts.map.name();
    let (refs, ref_s, mut methods) = render_all(opts, &map)?;
    let scene = Scene::new(opts.size, opts.tiles);
    let mask = coverage(&scene);
    let (a0, a1) = &refs.pbrdf;
    let (b0, b1) = &refs.normal_mapped;
    let k = (((opts.spp / 2).max(1) as f64).sqrt().round() as u32).max(1);
    let image = mean_image(a0, a1);
    let reference = ReferenceRow {
        label: format!("(a) exact P-BRDF, {} spp", 2 * k * k),
        exposure: exposure_of(&image, &mask),
        image,
        spp: 2 * k * k,
        render_s: ref_s,
        noise: reference_noise(a0, a1, &mask),
        noise_b: reference_noise(b0, b1, &mask),
    };
    // Reference (b) as a row, measured against (a): the modelling gap.
    methods.insert(
        0,
        Rendered {
            label: format!("(b) normal-mapped, {} spp", 2 * k * k),
            image: mean_image(b0, b1),
            build_s: 0.0,
            render_s: ref_s,
        },
    );
    let rows: Vec<MethodRow> = methods
        .iter()
        .map(|m| MethodRow::measure(m, &refs, &mask))
        .collect();

    let map_size = (map.width(), map.height());
    table::print(opts, &name, map_size, map_s, &reference, &rows);
    let mut artifacts = chart::write_images(
        &scene, &name, map_size.0, opts.tiles, &reference, &rows, out,
    )?;
    let csv_path = out.join(format!("orb_{name}.csv"));
    std::fs::write(&csv_path, table::csv(&name, &reference, &rows))?;
    artifacts.push(Artifact::new(&csv_path, "The figures of the table (CSV)."));
    for a in &artifacts {
        println!("wrote {}", a.path.display());
    }
    Ok(artifacts)
}

/// The gallery's part: a small strip (scratched 512² map, 160² image, 256 spp), well under 60 s.
pub fn run_gallery(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let opts = if quick {
        OrbOptions {
            size: 160,
            map_size: 512,
            tiles: Vec2::new(4.0, 2.0),
            spp: 256,
            progress: false,
            ..OrbOptions::default()
        }
    } else {
        OrbOptions {
            progress: false,
            ..OrbOptions::default()
        }
    };
    run(&opts, out)
}
