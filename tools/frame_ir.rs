//! Instructions of one frame of the render example's timing harness, for callgrind: the harness's
//! scene (examples/common/render/timing.rs: a unit sphere, point light + constant sky, 320 × 240,
//! 4 spp) with one material at one target of texels per pixel, rendered once on one thread.
//!
//! ```text
//! cargo build --release --example frame_ir
//! RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     --toggle-collect='brdf_examples::common::render::render' \
//!     target/release/examples/frame_ir MATERIAL TEXELS_PER_PIXEL
//! ```
//! `Collected` is the frame's count (deterministic: independent of the machine's load), the same
//! work the harness times. MATERIAL: `ggx` and `beckmann` (analytic, α = 0.091, the harness's α for its scratched
//! map), `procedural` and `procedural-ggx` (the harness's procedural surfaces: that α as the limit,
//! one facet per texel of a 1024² grid, seed 7), `bin-map` and `mixture` (the default builds of the
//! harness's 1024² `scratched` map of seed 7; the build runs under callgrind too, outside the
//! toggled function);
//! silver, default options. docs/results.md, "Procedural glints" and "Inverse bin map: the masking
//! level of detail".

use brdf::Vec2;
use brdf::fresnel::ConductorFresnel;
use brdf::glint::procedural::{ProceduralGlints, ProceduralLimit};
use brdf::glint::{BeckmannMixture, BinMap, GlintModel, ScratchedParams, scratched};
use brdf::material::{GlintMaterial, Material};
use brdf::ndf::{Beckmann, Ggx};
use brdf_examples::common::render::render;
use brdf_examples::common::render::showcase::progress_bar;
use brdf_examples::common::render::timing::{procedural_params, tiles_for, timing_scene};
use std::sync::Arc;

const SIZE: usize = 1024;
const ALPHA: f32 = 0.091;

fn material(name: &str, tiles: Vec2) -> Result<Material, Box<dyn std::error::Error>> {
    let silver = ConductorFresnel::SILVER;
    let procedural = |limit| -> Result<Material, Box<dyn std::error::Error>> {
        let params = procedural_params(ALPHA, SIZE, 7, limit);
        let model: GlintModel = ProceduralGlints::new(params)?.into();
        Ok(GlintMaterial::new(Arc::new(model), silver)
            .with_uv_scale(tiles)?
            .into())
    };
    Ok(match name {
        "ggx" => Material::microfacet(Ggx::isotropic(ALPHA)?, silver),
        "beckmann" => Material::microfacet(Beckmann::isotropic(ALPHA)?, silver),
        "procedural" => procedural(ProceduralLimit::Beckmann)?,
        "procedural-ggx" => procedural(ProceduralLimit::Ggx)?,
        "bin-map" | "mixture" => {
            let map = scratched(SIZE, SIZE, ScratchedParams::default(), 7)?;
            let model: GlintModel = if name == "mixture" {
                BeckmannMixture::build(&map, Default::default())?.into()
            } else {
                BinMap::build(&map, Default::default())?.into()
            };
            GlintMaterial::new(Arc::new(model), silver)
                .with_uv_scale(tiles)?
                .into()
        }
        other => return Err(format!("unknown material {other}").into()),
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, name, texels] = &args[..] else {
        return Err("usage: frame_ir MATERIAL TEXELS_PER_PIXEL".into());
    };
    let texels: f32 = texels.parse()?;
    let probe = timing_scene(Material::mirror(ConductorFresnel::SILVER), 320, 240);
    let tiles = tiles_for(&probe, texels, SIZE);
    let scene = timing_scene(material(name, tiles)?, 320, 240);
    let image = render(&scene, 4, 1, &progress_bar(false, 1, ""));
    std::hint::black_box(image);
    Ok(())
}
