//! Lobe plots of the classic BRDFs (polar plots and hemisphere images); see `common::lobes`.
//!
//! `cargo run --release --example lobes -- [--out DIR] [--quick]`

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::lobes::run(&out, common::has_flag("--quick"))? {
        println!("{}", a.path.display());
    }
    Ok(())
}
