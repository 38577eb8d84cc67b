//! Procedural glints against their limit: TV of a footprint's P-NDF to the limit Beckmann NDF,
//! the mean P-NDF over positions, and the cost of a shading point against analytic GGX, for four
//! surfaces and footprints of 0.25 to 2²⁰ texels; see `common::procedural`.
//!
//! `cargo run --release --example procedural -- [--out DIR] [--quick]` (`--out docs` writes
//! docs/data/procedural.csv and docs/img/procedural_tv.png).

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::procedural::run(&out, common::has_flag("--quick"))? {
        println!("{}", a.path.display());
    }
    Ok(())
}
