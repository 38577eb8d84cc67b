//! Grazing-angle stability of every NDF and glint method: visible-area error, white furnace and the
//! spread of the sample weight as θo → 90°.
//!
//! `cargo run --release --example grazing -- [--out DIR]`
//!
//! Writes `grazing.csv`, `grazing_*.png` and `grazing.md` into DIR (default `target/brdf-out/`) and
//! prints the table. See `examples/common/grazing.rs` for what is measured and docs/robustness.md for
//! what it shows.

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    let rows = common::grazing::measure(&common::grazing::Settings::new())?;
    let (artifacts, md) = common::grazing::report(&rows, &out)?;
    println!("{md}");
    for a in artifacts {
        println!("{}", a.path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::common::grazing::*;

    /// Every code path on tiny inputs: finite measurements, the closed-form references agree with the
    /// crate's f32 visible areas away from grazing, files written.
    #[test]
    fn tiny_run_is_finite_and_sane() {
        let rows = measure(&Settings::tiny()).unwrap();
        assert!(!rows.is_empty());
        for r in &rows {
            // NaN marks a patch that shows wo nothing (V_ref = 0); everything else is finite.
            assert!(
                !r.v_rel_error.is_infinite()
                    && r.furnace.is_finite()
                    && r.weight_spread.is_finite(),
                "{r:?}"
            );
            assert!((0.0..=1.0).contains(&r.lost), "{r:?}");
            // The f64 closed forms and the f32 code agree to f32 rounding (a few 1e-7) well away
            // from grazing, which checks the references themselves.
            if (r.method.starts_with("Beckmann") || r.method.starts_with("GGX")) && r.theta <= 80.0
            {
                assert!(r.v_rel_error < 1e-5, "{r:?}");
            }
        }
        let out = std::env::temp_dir().join("brdf-grazing-test");
        let (artifacts, md) = report(&rows, &out).unwrap();
        assert!(md.contains("GGX α=0.5"));
        for a in artifacts {
            assert!(a.path.exists(), "{}", a.path.display());
        }
    }
}
