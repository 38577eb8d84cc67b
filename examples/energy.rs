//! Energy compensation charts: the white furnace before / after against α and θo (isotropic and
//! anisotropic), the same for glint patches, and rough gold spheres uncompensated against
//! compensated; see `common::energy`.
//!
//! `cargo run --release --example energy -- [--out DIR] [--quick]` (every analytic value by
//! deterministic quadrature, the glint values by the mean sample weight; `--quick`, the gallery's
//! preview, computes every other α, every other θo, a quarter of the spheres' μ values and the glint
//! chart every 10° with 512 draws).

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::energy::run(&out, common::has_flag("--quick"))? {
        println!("{}: {}", a.path.display(), a.caption);
    }
    Ok(())
}
