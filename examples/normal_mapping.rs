//! Normal mapping at grazing views: conventional (`NormalMapTilt`) against microfacet-based
//! (`NormalMapMicrofacet`) normal mapping, as an albedo chart and a lobe image.
//!
//! `cargo run --release --example normal_mapping -- [--out DIR] [--quick]`
//!
//! Writes `normal_mapping_albedo.png` and `normal_mapping_lobes.png` into DIR (default
//! `target/brdf-out/`); `examples/common/normal_mapping.rs` says what they show.

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::normal_mapping::run(&out, common::has_flag("--quick"))? {
        println!("{}: {}", a.path.display(), a.caption);
    }
    Ok(())
}
