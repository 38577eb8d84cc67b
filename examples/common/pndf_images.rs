//! The procedural normal maps and their ground-truth P-NDFs for footprints of 1, 16, 256 and 4096
//! texels.
//!
//! For each generator (bumpy, brushed, scratched, flakes) this writes:
//! - `pndf_<map>_normals.png`: the map as an RGB normal map (OpenGL convention, c = (n + 1)/2; the
//!   bottom row of the picture is texel row 0, so +v points up);
//! - `pndf_<map>_<N>.png`: the reference P-NDF ([`brdf::glint::binned_pndf`], Gaussian kernel) of an
//!   isotropic footprint of N texels centred at uv = (0.37, 0.61), drawn over the projected
//!   hemisphere disk (orthographic view from +z: the pixel at disk position (x, y) shows the bin of the
//!   direction (x, y, √(1 − x² − y²)); +x to the right, +y up), zoomed to sin θ ≤ 0.7 (θ ≤ 44°, which
//!   holds all the mass of these maps: their slopes stay below ~0.9); the image's edge circle is
//!   θ = 44°;
//! - `pndf_<map>_sheet.png`: the normal map's neighbourhood and the four P-NDFs side by side.
//!
//! Tone mapping: logarithmic over four decades, t = log₁₀(D / D_max) / 4 + 1 clamped to [0, 1] (so the
//! brightest bin is yellow, bins 10⁴ times dimmer or empty are black), each image normalised to its own
//! maximum. The disk's outside is black too.

use super::{Artifact, Res, colormap, save_rgb};
use brdf::glint::{
    BinnedPndf, BrushedParams, FlakesParams, Footprint, HemisphereBins, Kernel, NormalMap,
    ScratchedParams, TangentConvention, binned_pndf, brushed, bumpy, flakes, scratched,
};
use brdf::{Vec2, Vec3};
use std::path::Path;

/// Footprint areas in texels².
pub(super) const FOOTPRINTS: [f32; 4] = [1.0, 16.0, 256.0, 4096.0];
/// Footprint centre (uv).
pub(super) const CENTER: Vec2 = Vec2::new(0.37, 0.61);
/// Decades shown by the logarithmic tone mapping.
const DECADES: f64 = 4.0;
/// sin θ at the rim of the P-NDF images.
const SIN_MAX: f32 = 0.7;

/// Settings of one run.
struct Settings {
    map_size: usize,
    bins: usize,
    samples: usize,
    image: u32,
}

fn settings(quick: bool) -> Settings {
    if quick {
        Settings {
            map_size: 256,
            bins: 64,
            samples: 400_000,
            image: 192,
        }
    } else {
        Settings {
            map_size: 1024,
            bins: 128,
            samples: 4_000_000,
            image: 320,
        }
    }
}

/// The four procedural maps with their default parameters (bumpy: RMS slope 0.25, ℓ = 4 texels).
pub fn maps(size: usize) -> Res<Vec<(&'static str, NormalMap)>> {
    Ok(vec![
        ("bumpy", bumpy(size, size, 0.25, 4.0, 1)?),
        ("brushed", brushed(size, size, BrushedParams::default(), 2)?),
        (
            "scratched",
            scratched(size, size, ScratchedParams::default(), 3)?,
        ),
        ("flakes", flakes(size, size, FlakesParams::default(), 4)?),
    ])
}

/// Log tone mapping of a D value relative to the image maximum (see the module docs).
fn tone(d: f64, max: f64) -> Option<f32> {
    (d > 0.0 && max > 0.0).then(|| ((d / max).log10() / DECADES + 1.0).clamp(0.0, 1.0) as f32)
}

/// RGB pixels of a P-NDF over the projected hemisphere disk up to sin θ = `SIN_MAX` (`size` × `size`,
/// +y up).
fn disk_image(r: &BinnedPndf, size: u32) -> Vec<u8> {
    let max = r.d().iter().copied().fold(0.0f64, f64::max);
    disk_image_of(&|w| r.d_at(w), max, size)
}

/// RGB pixels of any function of the direction over the projected hemisphere disk, tone mapped
/// against `max` like [`disk_image`].
pub(super) fn disk_image_of(d: &dyn Fn(Vec3) -> f64, max: f64, size: u32) -> Vec<u8> {
    let mut rgb = Vec::with_capacity((size * size * 3) as usize);
    for row in 0..size {
        for col in 0..size {
            let x = (2.0 * (col as f32 + 0.5) / size as f32 - 1.0) * SIN_MAX;
            let y = (1.0 - 2.0 * (row as f32 + 0.5) / size as f32) * SIN_MAX;
            let r2 = x * x + y * y;
            let px = if r2 < SIN_MAX * SIN_MAX {
                let w = Vec3::new(x, y, (1.0 - r2).sqrt());
                tone(d(w), max).map_or([0, 0, 0], colormap)
            } else {
                [0, 0, 0]
            };
            rgb.extend_from_slice(&px);
        }
    }
    rgb
}

/// A `size` × `size` crop of the normal map around `center` (uv), nearest-texel upscaled so that the
/// largest footprint (64 texels wide) fits with a margin: the crop spans 128 texels.
fn map_crop(map: &NormalMap, center: Vec2, size: u32) -> Vec<u8> {
    let span = 128.0f32.min(map.width() as f32);
    let c = center * map.size_f32();
    let mut rgb = Vec::with_capacity((size * size * 3) as usize);
    for row in 0..size {
        for col in 0..size {
            let p = c + Vec2::new(
                (col as f32 + 0.5) / size as f32 - 0.5,
                0.5 - (row as f32 + 0.5) / size as f32,
            ) * span;
            let n = map.texel_normal(p.x.floor() as i64, p.y.floor() as i64);
            let enc = |v: f32| ((v + 1.0) * 127.5).round().clamp(0.0, 255.0) as u8;
            rgb.extend_from_slice(&[enc(n.x), enc(n.y), enc(n.z)]);
        }
    }
    rgb
}

/// Places equally sized RGB panels side by side with a 4-pixel black gap.
pub(super) fn sheet(panels: &[Vec<u8>], size: u32) -> (u32, Vec<u8>) {
    let gap = 4u32;
    let width = panels.len() as u32 * (size + gap) - gap;
    let mut rgb = vec![0u8; (width * size * 3) as usize];
    for (k, p) in panels.iter().enumerate() {
        let x0 = k as u32 * (size + gap);
        for row in 0..size {
            let dst = ((row * width + x0) * 3) as usize;
            let src = (row * size * 3) as usize;
            rgb[dst..dst + (size * 3) as usize].copy_from_slice(&p[src..src + (size * 3) as usize]);
        }
    }
    (width, rgb)
}

/// Writes the normal maps, their reference P-NDF images and one sheet per map.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let s = settings(quick);
    let bins = HemisphereBins::new(s.bins)?;
    let mut artifacts = Vec::new();
    for (name, map) in maps(s.map_size)? {
        let (w, h) = (map.width(), map.height());
        let path = out.join(format!("pndf_{name}_normals.png"));
        save_rgb(
            &path,
            w as u32,
            h as u32,
            map.to_rgb8(TangentConvention::OpenGl),
        )?;
        artifacts.push(Artifact::new(
            path,
            format!("{name}: the {w}×{h} procedural normal map (RGB, OpenGL convention)"),
        ));
        let mut panels = vec![map_crop(&map, CENTER, s.image)];
        for area in FOOTPRINTS {
            let f = Footprint::isotropic_texels(CENTER, area, w, h);
            let r = binned_pndf(&map, &f, Kernel::Gaussian, &bins, s.samples, 7);
            let rgb = disk_image(&r, s.image);
            let path = out.join(format!("pndf_{name}_{area}.png"));
            save_rgb(&path, s.image, s.image, rgb.clone())?;
            artifacts.push(Artifact::new(
                path,
                format!(
                    "{name}: reference P-NDF of a {area}-texel Gaussian footprint over the projected \
                     hemisphere up to θ = 44° ({0}² bins, {1} samples, log scale over 4 decades; TV noise \
                     floor {2:.3})",
                    s.bins,
                    r.samples(),
                    r.tv_error()
                ),
            ));
            panels.push(rgb);
        }
        let (sw, rgb) = sheet(&panels, s.image);
        let path = out.join(format!("pndf_{name}_sheet.png"));
        save_rgb(&path, sw, s.image, rgb)?;
        artifacts.push(Artifact::new(
            path,
            format!(
                "{name}: a 128-texel crop of the map around the footprint centre, then the P-NDFs of \
                 footprints of 1, 16, 256 and 4096 texels"
            ),
        ));
    }
    Ok(artifacts)
}
