//! Accuracy against speed of every glint method, on the four procedural maps.
//!
//! `cargo run --release --example compare -- [--out DIR] [--quick]`
//!
//! Writes `compare_*.csv`, `compare_*.png` and `compare_tables.md` into DIR (default
//! `target/brdf-out/`) and prints the tables. `--quick`: 1024² maps (≈ minutes on 2 cores); without
//! it, 2048² maps and 4× the ground-truth samples. Accuracy is the total variation to two truths:
//! the P-NDF of the interpolated map (Dirac) and the same convolved with the material's σ_ε = 0.01
//! micro-roughness. See `examples/common/compare/` for what is measured and how.

use brdf_examples::common;

fn main() -> common::Res<()> {
    let out = common::out_dir()?;
    for a in common::compare::run(&out, common::has_flag("--quick"))? {
        println!("{}", a.path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::common::compare::*;

    /// Every code path on tiny inputs: finite measurements, sane ranges, files written.
    #[test]
    fn tiny_run_is_finite_and_sane() {
        let settings = Settings::tiny();
        let results = measure(&settings, &mut |_| {}).unwrap();
        assert!(!results.accuracy.is_empty() && !results.view.is_empty());
        for r in &results.accuracy {
            // TV lies in [0, 1] (+ rounding: a model's bin masses sum to 1 only up to its own
            // normalisation error, a few 1e-3 at most); times are positive.
            let tvs = std::iter::once(r.tv).chain(r.tv_fine);
            for t in tvs {
                for v in [t.dirac, t.convolved] {
                    assert!((0.0..=1.0 + 1e-2).contains(&v), "{r:?}");
                }
                assert!(t.k >= 4 && t.change.is_finite(), "{r:?}");
            }
            // 127² bins exactly for the footprints up to `fine_up_to`.
            assert_eq!(r.tv_fine.is_some(), r.area <= settings.fine_up_to, "{r:?}");
            assert!(r.patch_s > 0.0 && r.d_s > 0.0 && r.eval_s > 0.0, "{r:?}");
        }
        for r in &results.view {
            assert!(r.v_rel_error.is_finite() && r.furnace.is_finite(), "{r:?}");
            // Every model except the published position-normal BRDF (the compare's
            // "position-normal" rows) conserves energy in the renderer's measure (Monte Carlo with
            // 64 samples: a generous 10 % for the noise).
            if !r.method.starts_with("position-normal") {
                assert!(r.furnace <= 1.1, "{r:?}");
            }
        }
        let out = std::env::temp_dir().join("brdf-compare-test");
        let (artifacts, md) = report(&results, &settings, &out).unwrap();
        assert!(md.contains("mixture (exact)"));
        for a in artifacts {
            assert!(a.path.exists(), "{}", a.path.display());
        }
    }

    /// Every method the harness builds (through its own builders) renders the scene's σ_ε, read
    /// back from the built method; the only exceptions are the rows labelled "paper default",
    /// which carry exactly the paper's σ they declare, and each family has a σ_ε-matched method.
    #[test]
    fn every_method_is_built_with_the_scenes_sigma() {
        use super::common::material::{SIGMA_EPS, same_sigma};
        let settings = Settings::tiny();
        let map = brdf::glint::scratched(32, 32, Default::default(), 7).unwrap();
        for (family, build) in methods::builders() {
            let methods = build(&map, &settings).unwrap();
            assert!(
                methods.iter().any(|m| m.paper_default().is_none()),
                "{family}: no method at σ_ε"
            );
            for m in &methods {
                let (label, sigma) = (m.label(), m.sigma());
                match m.paper_default() {
                    None => assert!(same_sigma(sigma, SIGMA_EPS), "{label}: σ = {sigma}"),
                    Some(p) => {
                        assert!(label.contains("paper default"), "{label}");
                        assert!(same_sigma(sigma, p) || sigma == p, "{label}: σ = {sigma}");
                        assert!(!same_sigma(p, SIGMA_EPS), "{label}");
                    }
                }
            }
        }
        // The convolved truth is the same material.
        assert!(same_sigma(truth::SIGMA_EPS as f32, SIGMA_EPS));
    }

    #[test]
    fn pareto_front_keeps_the_non_dominated() {
        let pts = [(1.0, 0.5), (2.0, 0.6), (3.0, 0.1), (0.5, 0.9)];
        assert_eq!(pareto(&pts), vec![(0.5, 0.9), (1.0, 0.5), (3.0, 0.1)]);
    }
}
