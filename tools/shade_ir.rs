//! Instructions of a renderer's shading point, for callgrind: `Material::bsdf` (the patch, prepared
//! for wo) + `eval_pdf` toward two directions + one `sample` (examples/common/shading_points.rs),
//! for one material at isotropic footprints of one size.
//!
//! ```text
//! cargo build --release --example shade_ir
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     --toggle-collect='brdf_examples::common::shading_points::shade' \
//!     target/release/examples/shade_ir MATERIAL TEXELS POINTS
//! ```
//! `Collected` / POINTS is the count per shading point (deterministic: independent of the machine's
//! load). MATERIAL: `ggx` and `beckmann` (analytic, α = 0.091), `procedural` and `procedural-ggx`
//! (the render example's procedural surfaces: that α as the limit, one facet per texel of a 1024²
//! grid, seed 7), `mixture`, `bin-map`, `position-normal` (default builds of the 1024² `scratched`
//! map of seed 7, the render example's timed map); silver, default options. The points are drawn
//! from seed 5 (uniform uv, cos θo ≥ 0.2). A glint material's name followed by `+compensated`
//! (`mixture+compensated`) is that material with its energy compensation on. docs/results.md,
//! "Few-lobe patches: instructions per shading point" and "Energy compensation of glint patches".

use brdf::fresnel::ConductorFresnel;
use brdf::glint::procedural::{ProceduralGlints, ProceduralLimit};
use brdf::glint::{
    BeckmannMixture, BinMap, GlintModel, GlintScratch, PositionNormalMap, ScratchedParams,
    scratched,
};
use brdf::material::{GlintMaterial, Material};
use brdf::ndf::{Beckmann, Ggx};
use brdf_examples::common::render::timing::procedural_params;
use brdf_examples::common::shading_points::{points, shade};
use std::sync::Arc;

const SIZE: usize = 1024;
const ALPHA: f32 = 0.091;

fn material(name: &str) -> Result<Material, Box<dyn std::error::Error>> {
    let silver = ConductorFresnel::SILVER;
    // "MODEL+compensated": the glint material with its energy compensation on.
    let (name, compensated) = match name.strip_suffix("+compensated") {
        Some(n) => (n, true),
        None => (name, false),
    };
    let glint = |m: GlintModel| -> Material {
        let g = GlintMaterial::new(Arc::new(m), silver);
        if compensated {
            g.with_energy_compensation()
        } else {
            g
        }
        .into()
    };
    let procedural = |limit| -> Result<Material, Box<dyn std::error::Error>> {
        let params = procedural_params(ALPHA, SIZE, 7, limit);
        Ok(glint(ProceduralGlints::new(params)?.into()))
    };
    let map = || scratched(SIZE, SIZE, ScratchedParams::default(), 7);
    Ok(match name {
        "ggx" => Material::microfacet(Ggx::isotropic(ALPHA)?, silver),
        "beckmann" => Material::microfacet(Beckmann::isotropic(ALPHA)?, silver),
        "procedural" => procedural(ProceduralLimit::Beckmann)?,
        "procedural-ggx" => procedural(ProceduralLimit::Ggx)?,
        "mixture" => glint(BeckmannMixture::build(&map()?, Default::default())?.into()),
        "bin-map" => glint(BinMap::build(&map()?, Default::default())?.into()),
        "position-normal" => glint(PositionNormalMap::build(&map()?, Default::default())?.into()),
        other => return Err(format!("unknown material {other}").into()),
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, name, texels, n] = &args[..] else {
        return Err("usage: shade_ir MATERIAL TEXELS POINTS".into());
    };
    let (texels, n): (f32, usize) = (texels.parse()?, n.parse()?);
    let m = material(name)?;
    let scratch = GlintScratch::default();
    for p in &points(n, 5) {
        shade(&m, p, texels, SIZE, &scratch);
    }
    Ok(())
}
