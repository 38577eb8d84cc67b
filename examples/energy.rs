//! Energy compensation charts: the white furnace before / after against α and θo, and rough gold
//! spheres uncompensated against compensated; see `common::energy`.
//!
//! `cargo run --release --example energy -- [--out DIR] [--quick]` (every value by deterministic
//! quadrature; `--quick`, the gallery's preview, computes every other α, every other θo and a quarter
//! of the spheres' μ values).

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::energy::run(&out, common::has_flag("--quick"))? {
        println!("{}: {}", a.path.display(), a.caption);
    }
    Ok(())
}
