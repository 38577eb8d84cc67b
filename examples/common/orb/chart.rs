//! The orb's pictures: exposure and tone mapping, one PNG per method and the reference, and the
//! labelled strip of every row at the same exposure (plotters draws the labels).

use super::render::Image;
use super::scene::Scene;
use super::{MethodRow, ReferenceRow};
use crate::common::{Artifact, Res, register_font, save_rgb};
use glam::{Vec2, Vec3};
use plotters::prelude::*;
use std::path::Path;

/// Writes one PNG per method, the reference's PNG and the strip of all of them into `out`; returns
/// their artifacts, the strip first, then the reference, then the methods in order.
pub fn write_images(
    scene: &Scene,
    name: &str,
    map_width: usize,
    tiles: Vec2,
    reference: &ReferenceRow,
    rows: &[MethodRow],
    out: &Path,
) -> Res<Vec<Artifact>> {
    let size = scene.size;
    let (noise, exposure) = (reference.noise, reference.exposure);
    let mut artifacts = Vec::new();
    let mut panels = vec![(
        tone_map(scene, &reference.image, exposure),
        reference.label.clone(),
        format!("noise {noise:.2}"),
    )];
    for row in rows {
        let (m, e) = (row.rendered, &row.errors);
        let rgb = tone_map(scene, &m.image, exposure);
        let path = out.join(format!("orb_{name}_{}.png", slug(&m.label)));
        save_rgb(&path, size, size, rgb.clone())?;
        artifacts.push(Artifact::new(
            &path,
            format!(
                "{}: relative RMSE against the exact P-BRDF {:.2} (4×4 blocks {:.2}), energy {:+.1} %, {:.1} s",
                m.label,
                e.rel_rmse,
                e.rel_rmse_blocks,
                100.0 * e.energy,
                m.render_s
            ),
        ));
        panels.push((
            rgb,
            m.label.clone(),
            format!("err {:.2} / 4x4 {:.2}", e.rel_rmse, e.rel_rmse_blocks),
        ));
    }
    let ref_path = out.join(format!("orb_{name}_reference.png"));
    save_rgb(&ref_path, size, size, panels[0].0.clone())?;
    artifacts.insert(
        0,
        Artifact::new(
            &ref_path,
            format!(
                "reference (a), the exact P-BRDF of the interpolated map, {} spp (relative noise {noise:.3})",
                reference.spp
            ),
        ),
    );
    let (w, h, buf) = strip(&panels, size)?;
    let strip_path = out.join(format!("orb_{name}_strip.png"));
    save_rgb(&strip_path, w, h, buf)?;
    artifacts.insert(
        0,
        Artifact::new(
            &strip_path,
            format!(
                "Metallic orb, {name} normal map ({}², tiled {}×{}), point light, every row with the \
                 pixel's Gaussian footprint: reference (a) (exact P-BRDF), reference (b) \
                 (normal-mapped) and each glint model at the same exposure (errors against (a): \
                 relative RMSE per pixel / on 4×4 blocks, over the pixels fully on the sphere; \
                 render times in the per-method captions and the printed table).",
                map_width, tiles.x, tiles.y
            ),
        ),
    );
    Ok(artifacts)
}

/// The exposure that maps the 90th percentile of the non-zero covered pixel values to 1 (0.5 after
/// [`tone_map`]'s curve): glints span decades, so a high percentile would leave all but the
/// brightest black.
pub fn exposure_of(img: &Image, mask: &[bool]) -> f32 {
    let mut v: Vec<f64> = (0..img.pixels.len())
        .filter(|&k| mask[k])
        .map(|k| img.value(k))
        .filter(|&x| x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    v.sort_by(f64::total_cmp);
    let p = v[((v.len() - 1) as f64 * 0.9) as usize];
    if p > 0.0 { (1.0 / p) as f32 } else { 1.0 }
}

fn srgb(c: f32) -> u8 {
    let c = if c.is_finite() {
        c.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// 8-bit sRGB of an image at `exposure` through the curve c/(1 + c) per channel (Reinhard), so that
/// the brightest glints saturate smoothly; background (pixel centre off the sphere) dark grey.
pub fn tone_map(scene: &Scene, img: &Image, exposure: f32) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(img.pixels.len() * 3);
    for (k, p) in img.pixels.iter().enumerate() {
        let (x, y) = (k as u32 % img.size, k as u32 / img.size);
        if scene
            .hit(Vec2::new(x as f32 + 0.5, y as f32 + 0.5))
            .is_none()
        {
            rgb.extend_from_slice(&[24, 26, 30]);
        } else {
            let c = *p * exposure;
            let c = c / (Vec3::ONE + c);
            rgb.extend_from_slice(&[srgb(c.x), srgb(c.y), srgb(c.z)]);
        }
    }
    rgb
}

/// Font size and line height (pixels) of the strip's labels.
const LABEL_PX: u32 = 13;
const LINE_PX: u32 = 16;

/// `text` broken at spaces into lines no wider than `width` pixels in `font` (a word wider than
/// that stays on a line of its own).
fn wrap(text: &str, font: &FontDesc, width: u32) -> Vec<String> {
    let fits = |s: &str| font.box_size(s).map_or(true, |(w, _)| w <= width);
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(line) if fits(&format!("{line} {word}")) => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Lays out tone-mapped panels side by side with a label band above each: the title and the
/// figures, each wrapped to the panel's width, the band as tall as the longest label needs.
pub fn strip(panels: &[(Vec<u8>, String, String)], size: u32) -> Res<(u32, u32, Vec<u8>)> {
    register_font();
    let font = ("sans-serif", LABEL_PX).into_font();
    let labels: Vec<Vec<String>> = panels
        .iter()
        .map(|(_, title, figures)| {
            // 12 px of margin: neighbouring labels stay apart even when one fills its panel.
            let mut lines = wrap(title, &font, size - 12);
            lines.extend(wrap(figures, &font, size - 12));
            lines
        })
        .collect();
    let band = labels.iter().map(Vec::len).max().unwrap_or(0) as u32 * LINE_PX + 6;
    let gap = 4u32;
    let n = panels.len() as u32;
    let (w, h) = (n * size + (n.saturating_sub(1)) * gap, size + band);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    for (i, (rgb, _, _)) in panels.iter().enumerate() {
        let x0 = i as u32 * (size + gap);
        for y in 0..size {
            for x in 0..size {
                let src = ((y * size + x) * 3) as usize;
                let dst = (((y + band) * w + x0 + x) * 3) as usize;
                buf[dst..dst + 3].copy_from_slice(&rgb[src..src + 3]);
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        for (i, lines) in labels.iter().enumerate() {
            let x0 = (i as u32 * (size + gap)) as i32 + 3;
            for (k, line) in lines.iter().enumerate() {
                let y = 3 + (k as u32 * LINE_PX) as i32;
                root.draw(&Text::new(line.clone(), (x0, y), font.clone()))?;
            }
        }
        root.present()?;
    }
    Ok((w, h, buf))
}

/// A file-name form of a label: lower-case alphanumerics, runs of anything else as one `_`.
fn slug(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}
