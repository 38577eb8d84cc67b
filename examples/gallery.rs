//! The crate's main job: every example on embedded defaults, in one run, with an HTML index.
//!
//! `cargo run --release --example gallery [-- --out DIR] [--full]`
//! writes the charts and images of every example into DIR (default `target/brdf-out/`) and an
//! `index.html` that shows each with one line of explanation. By default the examples run as a small
//! preview (fewer maps, scales, samples and pixels where a part would be slow; each blurb says what the
//! preview leaves out) so that the whole gallery, release build included, stays within about three
//! minutes of a fresh clone on an idle 2-core machine; `--full` runs them at full size.

use brdf_examples::common;

use common::{Artifact, Res};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

type Part = fn(&Path, bool) -> Res<Vec<Artifact>>;

fn main() -> Res<()> {
    let out = common::out_dir()?;
    let quick = !common::has_flag("--full");
    let parts: [(&str, &str, Part); 11] = [
        (
            "Analytic core",
            "NDF slices, Smith masking and Fresnel curves.",
            common::curves::run,
        ),
        (
            "Classic BRDF lobes",
            "f·cos in the plane of incidence (polar plots) and over the projected hemisphere, for \
             Lambert, the Phong family, Blinn-Phong and the microfacet BRDF.",
            common::lobes::run,
        ),
        (
            "Energy compensation",
            "The white furnace of the microfacet BRDF before and after Kulla-Conty compensation \
             against α and θo (isotropic and anisotropic), of glint patches before and after \
             their own compensation, and rough gold spheres uncompensated against compensated \
             (the energy example; preview: 13 values of α, θo every 4° (anisotropic 8°, glint \
             10° at 512 draws), the spheres from 33 values of μ, where --full computes 25, every \
             2° (4°, 5° at 4,096 draws) and 129).",
            common::energy::run,
        ),
        (
            "Normal maps and ground-truth P-NDFs",
            "The four procedural maps and the P-NDF of their interpolated normals seen through \
             footprints of 1 to 4096 texels (projected hemisphere, log scale).",
            common::pndf_images::run,
        ),
        (
            "Glints: the Beckmann mixture (Chermain 2019)",
            "The mixture's P-NDF against the ground truth, per map and footprint size.",
            common::mixture_images::run,
        ),
        (
            "Orb renders",
            "A metallic sphere with a high-definition normal map under a point light (Chermain 2019 \
             Fig. 1): each glint method beside the two references, (a) the exact P-BRDF of the \
             interpolated map and (b) normal-mapped rendering, all with the same pixel kernel (the \
             orb example, small strip).",
            common::orb::run_gallery,
        ),
        (
            "Orb: error against time",
            "Naive sampling against each glint model at 1, 4 and 16 evaluations per pixel, with \
             equal-error speedups. Preview (the default): the scratched and flakes maps at one map \
             scale (~34 texels per pixel), naive 1…256 spp, reference 2 × 576 spp. Under --full: \
             the orb example's --curves --quick, the four procedural maps and a fractal height \
             field at two map scales, naive 1…1024 spp. The full sweep, 1 to 139,898 texels per \
             pixel, takes ~16 min of a quiet 2-core machine: run it as `orb -- --curves`; its \
             results are in docs/results.md.",
            |out, quick| {
                if quick {
                    common::orb_curves::run_preview(out)
                } else {
                    common::orb_curves::run(out, true)
                }
            },
        ),
        (
            "Accuracy against speed",
            "Every glint method on the four procedural maps: distance to the ground truth against \
             cost, footprint size and view angle, and the white furnace (the compare example). \
             Preview (the default): 256² maps, 2.5·10⁵ ground-truth positions per footprint, \
             footprints of 0.25 to 256 texels on 63² bins only, a coarser per-bin quadrature (TV \
             good to ~0.01) and 256 furnace samples; `compare -- --quick` is the larger quick run, \
             --full runs the full comparison.",
            |out, quick| {
                if quick {
                    common::compare::run_with(out, &common::compare::Settings::preview())
                } else {
                    common::compare::run(out, false)
                }
            },
        ),
        (
            "Grazing angles",
            "Where masking and sampling break down as the view approaches the horizon: visible-area \
             error, white furnace and the spread of the sample weight of every NDF and glint method \
             (the grazing example; preview: 2¹⁰ furnace and 2¹² V_ref samples per point, a quarter \
             of the example's, noise floors twice as high).",
            common::grazing::run,
        ),
        (
            "Normal mapping at grazing views",
            "Conventional (tilt the frame) against microfacet-based normal mapping (Schüssler 2017): \
             directional albedo against the view angle and a lobe image (the normal_mapping example).",
            common::normal_mapping::run,
        ),
        (
            "Glints in a path tracer",
            "A small path tracer (point light + sky, next-event estimation with MIS, a few bounces) \
             shading one sphere with analytic gold, a perfect mirror, two glint conductors (a \
             procedural scratched map and a PNG normal map the example writes first), a glint \
             coat over red paint and car paint (procedural aluminium flakes over dark blue paint, no \
             normal map, under a smooth clear coat), every material a `brdf::Material`, through the \
             public API only (the render example; preview: 240 × 150 at 6 spp, where `render -- \
             --quick` renders 320 × 200 at 12 spp).",
            common::render::showcase::run,
        ),
    ];
    let mut sections = Vec::new();
    for (title, blurb, run) in parts {
        let t = Instant::now();
        let artifacts = run(&out, quick)?;
        println!(
            "{title}: {} files in {:.1} s",
            artifacts.len(),
            t.elapsed().as_secs_f64()
        );
        sections.push((title, blurb, artifacts));
    }
    let index = out.join("index.html");
    std::fs::write(&index, html(&out, &sections))?;
    println!("wrote {}", index.display());
    Ok(())
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn html(out: &Path, sections: &[(&str, &str, Vec<Artifact>)]) -> String {
    let mut s = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>brdf gallery</title>\
         <style>body{font-family:sans-serif;max-width:1100px;margin:auto}figure{display:inline-block;\
         margin:8px;max-width:520px;vertical-align:top}img{max-width:500px;image-rendering:pixelated}\
         figcaption{font-size:14px}</style></head><body><h1>brdf gallery</h1>\n",
    );
    for (title, blurb, artifacts) in sections {
        let _ = writeln!(s, "<h2>{}</h2><p>{}</p>", escape(title), escape(blurb));
        for a in artifacts {
            let rel = a.path.strip_prefix(out).unwrap_or(&a.path);
            let rel = escape(&rel.to_string_lossy());
            let is_image = rel.ends_with(".png") || rel.ends_with(".svg");
            if is_image {
                let _ = writeln!(
                    s,
                    "<figure><a href=\"{rel}\"><img src=\"{rel}\"></a><figcaption>{}</figcaption></figure>",
                    escape(&a.caption)
                );
            } else {
                let _ = writeln!(
                    s,
                    "<p><a href=\"{rel}\">{rel}</a>: {}</p>",
                    escape(&a.caption)
                );
            }
        }
    }
    s.push_str("</body></html>\n");
    s
}
