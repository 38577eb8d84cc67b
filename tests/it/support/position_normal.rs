//! Shared helpers of the position-normal tests (tests/it/position_normal_*.rs): a smooth test map, the
//! default build, and the unit normal of a slope written independently in f64.

use brdf::Vec3;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{NormalMap, PositionNormalMap};

/// White-noise slopes, uniform in [−a, a]², on an n × n map.
pub fn noise(n: usize, a: f32, seed: u64) -> NormalMap {
    super::noise_map(n, n, a, seed)
}

/// A smooth periodic height field: a few sinusoids.
pub fn waves(n: usize) -> NormalMap {
    let tau = std::f64::consts::TAU;
    let h: Vec<f32> = (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
            ((tau * (2.0 * x + y)).sin() + 0.7 * (tau * (3.0 * y - x) + 1.0).sin()) as f32
        })
        .collect();
    NormalMap::from_heights(n, n, &h, 1.0).unwrap()
}

/// The position-normal map of `map` with the default parameters.
pub fn build(map: &NormalMap) -> PositionNormalMap {
    PositionNormalMap::build(map, PositionNormalParams::default()).unwrap()
}

/// The unit normal of slope s, written independently in f64, with its cos θ.
pub fn normal_of(s: [f64; 2]) -> (Vec3, f64) {
    let l = (1.0 + s[0] * s[0] + s[1] * s[1]).sqrt();
    (
        Vec3::new((-s[0] / l) as f32, (-s[1] / l) as f32, (1.0 / l) as f32),
        1.0 / l,
    )
}
