//! The Beckmann-mixture P-NDF (Chermain 2019) next to the ground truth it approximates.
//!
//! For each procedural map (256² in quick mode, 512² in full mode) and footprints of 16, 256 and 4096
//! texels at the same centre as `pndf_images`, this writes `mixture_<map>.png`: the top row is the
//! reference P-NDF (binned interpolated normals), the bottom row the mixture patch's D evaluated per
//! pixel, both over the projected hemisphere up to θ = 44° with the same logarithmic tone mapping
//! (four decades, each pair normalised to the reference's maximum). The caption gives the total
//! variation distance between the two on the reference's bins (`brdf::glint::tv_distance`).

use super::pndf_images::{CENTER, disk_image_of, maps, sheet};
use super::{Artifact, Res, save_rgb};
use brdf::glint::mixture::MixtureParams;
use brdf::glint::{
    BeckmannMixture, Footprint, GlintNdf, HemisphereBins, Kernel, binned_pndf, tv_distance,
};
use brdf::ndf::Ndf;
use std::path::Path;

/// Footprint areas shown, in texels².
const AREAS: [f32; 3] = [16.0, 256.0, 4096.0];

/// Writes one comparison sheet per map.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let (size, image, samples) = if quick {
        (256, 128, 400_000)
    } else {
        (512, 192, 4_000_000)
    };
    let bins = HemisphereBins::new(64)?;
    let mut artifacts = Vec::new();
    for (name, map) in maps(size)? {
        let mixture = BeckmannMixture::build(&map, MixtureParams::default())?;
        let (mut top, mut bottom, mut tvs) = (Vec::new(), Vec::new(), Vec::new());
        for &area in &AREAS {
            let fp = Footprint::isotropic_texels(CENTER, area, map.width(), map.height());
            let reference = binned_pndf(&map, &fp, Kernel::Gaussian, &bins, samples, 11);
            let patch = mixture.patch(&fp);
            let max = reference.d().iter().copied().fold(0.0f64, f64::max);
            top.push(disk_image_of(&|w| reference.d_at(w), max, image));
            bottom.push(disk_image_of(&|w| patch.d(w) as f64, max, image));
            tvs.push(tv_distance(&patch, &reference, 2));
        }
        let (w, row_top) = sheet(&top, image);
        let (_, row_bottom) = sheet(&bottom, image);
        let gap = vec![0u8; (w * 4 * 3) as usize];
        let rgb = [row_top, gap, row_bottom].concat();
        let path = out.join(format!("mixture_{name}.png"));
        save_rgb(&path, w, 2 * image + 4, rgb)?;
        let tv: Vec<String> = AREAS
            .iter()
            .zip(&tvs)
            .map(|(a, t)| format!("{a} texels: {t:.3}"))
            .collect();
        artifacts.push(Artifact::new(
            path,
            format!(
                "{name} ({size}²): reference P-NDF (top) vs Beckmann mixture (bottom) for 16, 256, \
                 4096 texels; total variation {}.",
                tv.join(", ")
            ),
        ));
    }
    Ok(artifacts)
}
