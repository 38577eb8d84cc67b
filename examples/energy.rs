//! Energy compensation charts: the white furnace before / after against α and θo, and rough gold
//! spheres uncompensated against compensated; see `common::energy`.
//!
//! `cargo run --release --example energy -- [--out DIR]` (every value by deterministic quadrature;
//! `--quick` is accepted and changes nothing).

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::energy::run(&out, common::has_flag("--quick"))? {
        println!("{}: {}", a.path.display(), a.caption);
    }
    Ok(())
}
