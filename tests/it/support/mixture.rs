//! Helpers of the Beckmann-mixture tests (tests/it/mixture*.rs): the 64² test maps, patch options with the
//! level of detail off, footprints, and the slope-grid quadrature of a patch's P22.
//!
//! Integrals of the spiky P-NDF are taken in slope space, where D cos θ dω = P22 ds: the trapezoid
//! rule on a grid whose step is at most the narrowest lobe's minor standard deviation. For a sum of
//! Gaussians the trapezoid rule converges exponentially (aliasing error ~ exp(−2π²σ²/step²) < 1e-8
//! at step ≤ σ); kinks (⟨w, m⟩⁺) add an O(step²) term. Every such integral is also computed at twice
//! the step, and the difference is reported as the error estimate next to each tolerance.

use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::{BeckmannMixture, Footprint, GlintNdf, MixturePatch, NormalMap};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use rand::RngExt;

/// Side of the test maps, in texels.
pub const N: usize = 64;

/// White noise slopes, uniform in [−0.4, 0.4]².
pub fn noise(n: usize, seed: u64) -> NormalMap {
    let mut rng = super::rng(seed);
    let slopes = (0..n * n)
        .map(|_| Vec2::new(rng.random_range(-0.4..0.4), rng.random_range(-0.4..0.4)))
        .collect();
    NormalMap::from_slopes(n, n, slopes).unwrap()
}

/// The four procedural maps (the stand-ins for \[Chermain2019\] Fig. 7, same parameters and seeds as
/// the gallery) at 64², and white-noise slopes as a stress case.
pub fn maps() -> Vec<(&'static str, NormalMap)> {
    let mut maps = super::procedural_maps(N);
    maps.push(("noise", noise(N, 2)));
    maps
}

/// The four procedural maps only.
pub fn procedural_maps() -> Vec<(&'static str, NormalMap)> {
    maps().into_iter().take(4).collect()
}

/// Patch options with the level of detail and the sub-texel lobe off, so that every footprint
/// exercises the mixture.
pub fn exact_options() -> PatchOptions {
    PatchOptions {
        masking: MaskingMode::Exact,
        ..PatchOptions::full()
    }
}

/// The patch of `mix` through `fp` with [`exact_options`] (allocating).
pub fn exact_patch<'a>(mix: &'a BeckmannMixture, fp: &Footprint) -> MixturePatch<'a> {
    mix.patch_with(fp, &exact_options(), None)
}

pub fn footprint(area: f32, center: Vec2) -> Footprint {
    Footprint::isotropic_texels(center, area, N, N)
}

/// The footprint areas (texels) of the identity and brute-force checks.
pub const AREAS: [f32; 4] = [1.0, 16.0, 256.0, 4096.0];

/// The normal of slope s, written independently in f64.
pub fn normal_of(s: [f64; 2]) -> (Vec3, f64) {
    let l = (1.0 + s[0] * s[0] + s[1] * s[1]).sqrt();
    (
        Vec3::new((-s[0] / l) as f32, (-s[1] / l) as f32, (1.0 / l) as f32),
        1.0 / l,
    )
}

/// A slope grid covering every lobe of the patch to ±8 σ, step = the narrowest minor σ.
pub struct SlopeGrid {
    pub lo: [f64; 2],
    pub step: f64,
    pub n: [usize; 2],
}

pub fn slope_grid(patch: &MixturePatch) -> SlopeGrid {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    let mut min_sigma = f64::MAX;
    for (_, g) in patch.weighted_lobes() {
        let c = g.covariance();
        let (a, b, d) = (c.x_axis.x as f64, c.x_axis.y as f64, c.y_axis.y as f64);
        let minor = 0.5 * (a + d) - (0.25 * (a - d) * (a - d) + b * b).sqrt();
        min_sigma = min_sigma.min(minor.max(0.0).sqrt());
        let m = g.mean();
        for (k, (mk, v)) in [(m.x as f64, a), (m.y as f64, d)].into_iter().enumerate() {
            lo[k] = lo[k].min(mk - 8.0 * v.sqrt());
            hi[k] = hi[k].max(mk + 8.0 * v.sqrt());
        }
    }
    let step = 0.5 * min_sigma;
    let n = [0, 1].map(|k| ((hi[k] - lo[k]) / step).ceil() as usize + 1);
    if std::env::var("GRID_DEBUG").is_ok() {
        eprintln!("grid {n:?} step {step} slots {}", patch.lobe_count());
    }
    SlopeGrid { lo, step, n }
}

/// P22_P on the slope grid of a patch, evaluated once through the model's `d`.
pub struct GridValues {
    pub grid: SlopeGrid,
    pub p22: Vec<f64>,
}

pub fn grid_values(patch: &MixturePatch) -> GridValues {
    let grid = slope_grid(patch);
    let mut p22 = Vec::with_capacity(grid.n[0] * grid.n[1]);
    for j in 0..grid.n[1] {
        for i in 0..grid.n[0] {
            let s = [
                grid.lo[0] + i as f64 * grid.step,
                grid.lo[1] + j as f64 * grid.step,
            ];
            let (m, mz) = normal_of(s);
            p22.push(patch.d(m) as f64 * mz.powi(4));
        }
    }
    GridValues { grid, p22 }
}

/// ∫ g(s, P22_P(s)) ds by the trapezoid rule (the integrand vanishes at the edges) at the grid's step
/// (half the narrowest σ) and at twice the step; returns (fine, |fine − coarse|).
pub fn integrate_grid(gv: &GridValues, g: &dyn Fn([f64; 2], f64) -> f64) -> (f64, f64) {
    let grid = &gv.grid;
    let (mut fine, mut coarse) = (0.0, 0.0);
    for j in 0..grid.n[1] {
        for i in 0..grid.n[0] {
            let s = [
                grid.lo[0] + i as f64 * grid.step,
                grid.lo[1] + j as f64 * grid.step,
            ];
            let v = g(s, gv.p22[j * grid.n[0] + i]);
            fine += v;
            if i % 2 == 0 && j % 2 == 0 {
                coarse += v;
            }
        }
    }
    let a = grid.step * grid.step;
    (fine * a, (fine * a - coarse * 4.0 * a).abs())
}

/// A direction to probe D at: draw k (even) from the patch's normal sampler, odd k uniform in
/// θ ∈ [0°, 40°).
pub fn probe_normal(patch: &MixturePatch, rng: &mut impl RngExt, k: usize) -> Vec3 {
    let u = Vec2::new(rng.random(), rng.random());
    if k.is_multiple_of(2) {
        patch.sample_normal(u)
    } else {
        super::dir(rng.random_range(0.0..40.0), rng.random_range(0.0..360.0))
    }
}

/// The four procedural maps and the noise map at 64², built once for the property tests (query
/// them with [`exact_options`]).
pub fn block_mixtures() -> &'static [(&'static str, BeckmannMixture)] {
    static MIX: std::sync::OnceLock<Vec<(&'static str, BeckmannMixture)>> =
        std::sync::OnceLock::new();
    MIX.get_or_init(|| {
        maps()
            .into_iter()
            .map(|(name, map)| {
                (
                    name,
                    BeckmannMixture::build(&map, MixtureParams::default()).unwrap(),
                )
            })
            .collect()
    })
}
