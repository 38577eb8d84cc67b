//! Shared by the hardening suites (tests/it/robustness_*.rs, docs/robustness.md): proptest strategies
//! for the inputs a caller could pass (directions, random numbers, α, maps, footprints), quick glint
//! builds, the energy estimate with its bound, and constructor outcomes as text.

use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::{Footprint, NormalMap};
use brdf::{Bxdf, Error, Vec2, Vec3};
use proptest::prelude::*;

/// A unit direction with cos θ log-uniform in [1e-7, 1] (grazing angles well represented).
pub fn grazing_dir() -> impl Strategy<Value = Vec3> {
    grazing_dir_from(1e-7)
}

/// A unit direction with cos θ log-uniform in [min_cos, 1].
pub fn grazing_dir_from(min_cos: f32) -> impl Strategy<Value = Vec3> {
    (min_cos.log10()..=0.0, 0.0f32..std::f32::consts::TAU).prop_map(|(log_cos, phi)| {
        let c = 10f32.powf(log_cos);
        let s = (1.0 - c * c).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), c)
    })
}

/// Any direction a caller could pass: valid and grazing, below the horizon, exactly on it,
/// unnormalised, zero-length, NaN or infinite components.
pub fn any_dir() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        4 => grazing_dir(),
        1 => grazing_dir().prop_map(|w| Vec3::new(w.x, w.y, -w.z)),
        1 => (proptest::num::f32::ANY, proptest::num::f32::ANY, proptest::num::f32::ANY)
            .prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        1 => prop::sample::select(vec![
            Vec3::ZERO,
            Vec3::Z,
            Vec3::X,
            -Vec3::Z,
            Vec3::new(0.0, 0.0, 1e-30),
            Vec3::new(3.0, -2.0, 5.0),
            Vec3::splat(f32::NAN),
            Vec3::new(0.0, 0.0, f32::INFINITY),
            Vec3::new(f32::INFINITY, 0.0, 1.0),
        ]),
    ]
}

/// Random numbers: in [0, 1) mostly, with 0, 1 − ε, 1, negative, NaN and ∞.
pub fn any_u() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => 0.0f32..1.0,
        1 => prop::sample::select(vec![
            0.0,
            1.0 - f32::EPSILON / 2.0,
            1.0,
            -0.25,
            7.5,
            f32::NAN,
            f32::INFINITY,
        ]),
    ]
}

/// α log-uniform over [1e-4, 10] (the crate clamps at the low end).
pub fn any_alpha() -> impl Strategy<Value = f32> {
    (-4.0f32..=1.0).prop_map(|e| 10f32.powf(e))
}

/// A map of 1 to 9 texels per side (1×N, N×1, non-square, non-power-of-two): flat, random with an
/// RMS slope from 1e-3 to 1e3 (extremely rough), a single spike of slope length 0.99e4 (MAX_SLOPE = 1e4 is the largest accepted),
/// or a tilted plane.
pub fn any_map() -> impl Strategy<Value = NormalMap> {
    (1usize..=9, 1usize..=9, 0u8..4, -3.0f32..=3.0, any::<u64>()).prop_map(
        |(w, h, kind, log_scale, seed)| {
            let scale = 10f32.powf(log_scale);
            let mut state = seed | 1;
            let mut next = move || {
                // xorshift64*: a tiny deterministic generator, enough to scatter slopes.
                state ^= state >> 12;
                state ^= state << 25;
                state ^= state >> 27;
                ((state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32)
                    * 2.0
                    - 1.0
            };
            let slopes: Vec<Vec2> = (0..w * h)
                .map(|k| match kind {
                    0 => Vec2::ZERO,
                    1 => Vec2::new(next(), next()) * scale,
                    2 if k == 0 => Vec2::new(0.7, -0.7) * brdf::glint::MAX_SLOPE,
                    2 => Vec2::ZERO,
                    _ => Vec2::new(scale.min(50.0), -0.5),
                })
                .collect();
            NormalMap::from_slopes(w, h, slopes).expect("finite slopes within MAX_SLOPE")
        },
    )
}

/// Footprints from ray differentials of every kind: ordinary, zero, sub-texel, larger than the map,
/// NaN or infinite, extremely anisotropic, centred far outside [0, 1)².
pub fn any_footprint() -> impl Strategy<Value = Footprint> {
    let diff = prop_oneof![
        4 => (-0.5f32..0.5, -0.5f32..0.5).prop_map(|(x, y)| Vec2::new(x, y)),
        1 => prop::sample::select(vec![
            Vec2::ZERO,
            Vec2::new(1e-9, 0.0),
            Vec2::new(1e6, -1e6),
            Vec2::new(f32::NAN, 0.1),
            Vec2::new(f32::INFINITY, 0.0),
            Vec2::new(1.0, 1e-7),
        ]),
    ];
    let uv = prop_oneof![
        4 => (0.0f32..1.0, 0.0f32..1.0).prop_map(|(x, y)| Vec2::new(x, y)),
        1 => prop::sample::select(vec![
            Vec2::new(-1e6, 3e7),
            Vec2::new(f32::NAN, 0.5),
            Vec2::new(f32::INFINITY, f32::NEG_INFINITY),
            Vec2::new(123.456, -0.75),
        ]),
    ];
    (uv, diff.clone(), diff).prop_map(|(uv, dx, dy)| Footprint::from_differentials(uv, dx, dy))
}

/// Few QMC nodes: the build's accuracy does not matter here, its totality does.
pub fn quick_mixture_params() -> MixtureParams {
    MixtureParams {
        samples: 16,
        ..MixtureParams::default()
    }
}

/// Patch options with `masking` and the cost cap `lod_lobes` (the rest at their defaults).
pub fn mixture_options(masking: MaskingMode, lod_lobes: f32) -> PatchOptions {
    PatchOptions {
        masking,
        lod_lobes,
        ..PatchOptions::default()
    }
}

pub fn small_bins() -> BinMapParams {
    BinMapParams {
        bins_per_axis: 15,
        ..BinMapParams::default()
    }
}

/// Samples per energy estimate: the standard error of a mean of weights ≤ w_max is ≤ w_max/√N.
pub const ENERGY_SAMPLES: u32 = 4096;

/// The albedo ∫ f c(wi) dωi estimated with the BRDF's own sampler over a stratified 64 × 64 grid of
/// `u` (one `uc` sequence), where c is `cosine(wi)` (cos θi, or a glint patch's A_P(wi)⁺), with its
/// standard error. A sampler that returns `None` contributes 0 (lost mass only lowers the estimate).
pub fn albedo(brdf: &dyn Bxdf, wo: Vec3, cosine: &dyn Fn(Vec3) -> f32) -> (f64, f64) {
    let n = (ENERGY_SAMPLES as f64).sqrt() as u32;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for k in 0..ENERGY_SAMPLES {
        let (i, j) = (k % n, k / n);
        let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
        let uc = ((k as f64 * 0.618_033_988_749_894_9).fract()) as f32;
        let x = brdf
            .sample(wo, uc, u)
            .map_or(0.0, |s| (s.f.max_element() * cosine(s.wi) / s.pdf) as f64);
        sum += x;
        sum2 += x * x;
    }
    let m = sum / ENERGY_SAMPLES as f64;
    let var = (sum2 / ENERGY_SAMPLES as f64 - m * m).max(0.0);
    (m, (var / ENERGY_SAMPLES as f64).sqrt())
}

/// The bound every energy assertion uses: 1 + 4 standard errors (the family below runs a few
/// hundred estimates; 4σ keeps a false alarm below 10⁻⁴ per estimate for a Gaussian mean, and
/// stratified draws make the plain standard error conservative) + 1e-4 for f32 evaluation of f and
/// pdf (a few ulps each, relative) summed over the samples.
pub fn assert_energy(what: &str, (e, err): (f64, f64)) {
    assert!(e.is_finite() && e >= 0.0, "{what}: albedo {e}");
    assert!(
        e <= 1.0 + 4.0 * err + 1e-4,
        "{what}: albedo {e} ± {err} > 1"
    );
}

/// The error's message, or "Ok".
pub fn outcome<T>(r: Result<T, Error>) -> String {
    match r {
        Ok(_) => "Ok".into(),
        Err(e) => e.to_string(),
    }
}

/// Asserts that `r` is an error whose message contains `needle`.
pub fn err_naming<T>(r: Result<T, Error>, needle: &str) {
    let o = outcome(r);
    assert!(
        o != "Ok" && o.contains(needle),
        "expected an error naming `{needle}`, got {o}"
    );
}
