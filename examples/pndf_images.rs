//! Procedural normal maps and their ground-truth P-NDFs for footprints of 1, 16, 256 and 4096 texels.
//!
//! `cargo run --release --example pndf_images [-- --out DIR] [--quick]`

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::pndf_images::run(&out, common::has_flag("--quick"))? {
        println!("{}", a.path.display());
    }
    Ok(())
}
