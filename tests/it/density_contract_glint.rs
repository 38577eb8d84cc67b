//! The density contract of the glint patches (docs/bxdf.md, "The density contract"), through
//! `MicrofacetBrdf` as a renderer uses them: `eval(wo, wi)` > 0 ⇒ `pdf(wo, wi)` > 0, every value
//! finite, and visible-sample weights within the bound each model states, on the four procedural
//! maps and on extreme ones (slopes of 10³ RMS, one spike at 0.99 `MAX_SLOPE`, a steep tilted
//! plane), footprints from 0.25 to 1,024 texels, over the grid of `density_contract` (cos θ from 1
//! to 10⁻³⁰ for wo and wi, on the axes and off them, mirror neighbourhoods, every draw of the
//! sampler).

use crate::density_contract::{Case, VISIBLE_BOUND, case, grid, run, u_grid, wi_grid};
use brdf::fresnel::NoFresnel;
use brdf::glint::binmap::{BinMapParams, PatchOptions as BinOptions};
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions as MixtureOptions};
use brdf::glint::{
    BeckmannMixture, BinMap, BrushedParams, FlakesParams, Footprint, GlintNdf, MAX_SLOPE,
    NormalMap, PositionNormalMap, ScratchedParams, brushed, bumpy, flakes, scratched,
};
use brdf::{MicrofacetBrdf, Vec2, Vec3};

const SIZE: usize = 32;

/// The procedural maps at 32² and three extreme ones.
fn maps() -> Vec<(String, NormalMap)> {
    let n = SIZE;
    let mut v = vec![
        ("bumpy".to_string(), bumpy(n, n, 0.3, 3.0, 11).unwrap()),
        (
            "brushed".into(),
            brushed(n, n, BrushedParams::default(), 3).unwrap(),
        ),
        (
            "scratched".into(),
            scratched(n, n, ScratchedParams::default(), 5).unwrap(),
        ),
        (
            "flakes".into(),
            flakes(n, n, FlakesParams::default(), 7).unwrap(),
        ),
    ];
    // xorshift64*: slopes scattered with RMS ~10³.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        ((state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    let rough: Vec<Vec2> = (0..n * n)
        .map(|_| Vec2::new(next(), next()) * 1e3)
        .collect();
    v.push((
        "rough 1e3".into(),
        NormalMap::from_slopes(n, n, rough).unwrap(),
    ));
    let spike: Vec<Vec2> = (0..n * n)
        .map(|k| {
            if k == n * n / 2 + n / 2 {
                Vec2::new(0.7, -0.7) * (0.99 * MAX_SLOPE)
            } else {
                Vec2::ZERO
            }
        })
        .collect();
    v.push(("spike".into(), NormalMap::from_slopes(n, n, spike).unwrap()));
    v.push((
        "tilted 50".into(),
        NormalMap::from_slopes(n, n, vec![Vec2::new(50.0, -0.5); n * n]).unwrap(),
    ));
    v
}

/// Square footprints of `w` texels on a side at the map's centre.
fn footprints() -> Vec<(f32, Footprint)> {
    [0.5f32, 2.0, 8.0, 32.0]
        .iter()
        .map(|&w| {
            let d = w / SIZE as f32;
            let fp = Footprint::from_differentials(
                Vec2::new(0.53, 0.47),
                Vec2::new(d, 0.0),
                Vec2::new(0.0, d),
            );
            (w * w, fp)
        })
        .collect()
}

/// The unsmoothed bin map's visible sampler draws ⟨wo, m⟩ bilinearly in each bin: its stated
/// weight bound is 2 F (docs/binmap.md; tests/it/hostile_sampling.rs).
const BIN_MAP_BOUND: f32 = 2.0;

/// The glint model a sweep covers.
#[derive(Clone, Copy)]
enum Model {
    Mixture,
    BinMap,
    PositionNormal,
}

/// `value` for the rest of the test process (the patches borrow their model, and a `Case` holds a
/// `'static` BRDF).
fn leak<T>(value: T) -> &'static T {
    Box::leak(Box::new(value))
}

/// One model's patches on every map and footprint, as `'static` BRDFs: only that model is built.
fn cases(model: Model) -> Vec<Case> {
    cases_on(model, |_| true)
}

/// [`cases`] on the maps whose name `keep` accepts.
fn cases_on(model: Model, keep: impl Fn(&str) -> bool) -> Vec<Case> {
    let mut v = Vec::new();
    for (name, map) in maps().into_iter().filter(|(name, _)| keep(name)) {
        match model {
            Model::Mixture => {
                let params = MixtureParams {
                    samples: 16,
                    ..MixtureParams::default()
                };
                let mixture = leak(BeckmannMixture::build(&map, params).unwrap());
                for (texels, fp) in footprints() {
                    for masking in [MaskingMode::Exact, MaskingMode::Approximate] {
                        let options = MixtureOptions {
                            masking,
                            ..MixtureOptions::default()
                        };
                        v.push(case(
                            format!("mixture {masking:?} {name} {texels} texels"),
                            MicrofacetBrdf::new(mixture.patch_with(&fp, &options, None), NoFresnel),
                            Some(VISIBLE_BOUND),
                        ));
                    }
                }
            }
            Model::BinMap => {
                let params = BinMapParams {
                    bins_per_axis: 31,
                    ..BinMapParams::default()
                };
                let bin_map = leak(BinMap::build(&map, params).unwrap());
                for (texels, fp) in footprints() {
                    for (alpha, bound) in [(0.0, BIN_MAP_BOUND), (0.05, VISIBLE_BOUND)] {
                        let options = BinOptions {
                            smoothing_alpha: alpha,
                            ..BinOptions::default()
                        };
                        v.push(case(
                            format!("bin map α {alpha} {name} {texels} texels"),
                            MicrofacetBrdf::new(bin_map.patch_with(&fp, &options, None), NoFresnel),
                            Some(bound),
                        ));
                    }
                }
            }
            Model::PositionNormal => {
                let pn = leak(PositionNormalMap::build(&map, Default::default()).unwrap());
                for (texels, fp) in footprints() {
                    v.push(case(
                        format!("position-normal {name} {texels} texels"),
                        MicrofacetBrdf::new(pn.patch(&fp), NoFresnel),
                        Some(VISIBLE_BOUND),
                    ));
                }
            }
        }
    }
    v
}

/// cos θ of the glint sweep's directions: a subset of `density_contract`'s grid (normal to
/// 10⁻³⁰), so that the default run stays within seconds per model.
const COSINES: [f32; 8] = [1.0, 0.5, 0.1, 1e-2, 1e-4, 1e-7, 1e-15, 1e-30];

/// The cosines the default run keeps of [`COSINES`] (support::depth): normal incidence, an
/// oblique view and three grazing ones down to 10⁻³⁰.
const QUICK_COSINES: [f32; 5] = [1.0, 0.5, 1e-2, 1e-7, 1e-30];

/// The glint sweep's directions: [`COSINES`] ([`QUICK_COSINES`] in the default run) × the eight
/// azimuths of `density_contract`.
fn glint_grid() -> Vec<Vec3> {
    let cosines: &[f32] = crate::support::depth(&QUICK_COSINES, &COSINES);
    let g = grid();
    g.into_iter().filter(|w| cosines.contains(&w.z)).collect()
}

#[test]
fn mixture_patches_keep_the_contract() {
    let g = glint_grid();
    run(&cases(Model::Mixture), &g, &wi_grid(&g), &u_grid());
}

/// Open (docs/bxdf.md, "The density contract"): the unsmoothed bin map's visible density is 0
/// where `eval` is positive at views 10⁻²⁵ above the horizon with the half vector perpendicular to
/// wo to `f32` precision (wo·h ~ 10⁻⁴⁴: its density interpolates ⟨wo, m⟩ bilinearly over each
/// bin's corners), and the sample weights of both forms exceed their stated bounds (2 F
/// unsmoothed, up to 8·10³ on the tilted map at 1,024 texels and 27 on bumpy at 4 texels; F
/// smoothed, up to 1.2·10² on the tilted map), on back-scattered draws at grazing views: with exact
/// terms the same bilinear ⟨wo, m⟩ stands in for the exact one, without them (1,024 texels on
/// brushed, scratched and tilted) the visible sampler falls back to D cos θh (docs/bxdf.md, "The
/// density contract"). The full grid:
/// `cargo test --test it density_contract_glint:: -- --ignored --nocapture`.
#[test]
#[ignore = "open: bin map pdf 0 where eval > 0 at wo·h ~ 1e-44, weights above their bounds"]
fn bin_map_patches_keep_the_contract() {
    let g = grid();
    run(&cases(Model::BinMap), &g, &g, &u_grid());
}

/// Position-normal: eval > 0 ⇒ pdf > 0 and visible-sample weights ≤ F (1 + 10⁻⁵) on the glint
/// sweep's grid (its D sums the same `f32` element lobes at the same `f64` slope as its densities),
/// on the extreme maps in the default run (where D and the densities once differed by 19 %) and on
/// every map at full depth; [`position_normal_patches_keep_the_contract_everywhere`] is the full
/// grid of directions.
#[test]
fn position_normal_patches_keep_the_contract() {
    let g = glint_grid();
    let extreme = |name: &str| {
        ["rough", "spike", "tilted"]
            .iter()
            .any(|m| name.starts_with(m))
    };
    let cases = cases_on(Model::PositionNormal, |name| {
        crate::support::full() || extreme(name)
    });
    run(&cases, &g, &wi_grid(&g), &u_grid());
}

/// [`position_normal_patches_keep_the_contract`] on the full grid of directions (every wi of
/// `density_contract`'s grid): `cargo test --release --test it -- --ignored
/// density_contract_glint::position_normal_patches_keep_the_contract_everywhere` (~80 s).
#[test]
#[ignore = "heavy: the full grid, ~80 s in release"]
fn position_normal_patches_keep_the_contract_everywhere() {
    let g = grid();
    run(&cases(Model::PositionNormal), &g, &g, &u_grid());
}
