//! The index-matched interface reflects nothing, for conductors as for dielectrics
//! (docs/robustness.md): `conductor(0, η = 1, κ = 0)` returned 1 (the 0/0 of the closed form at
//! grazing incidence mapped to the grazing limit 1) while `dielectric(0, 1)` returns 0.

use brdf::Vec3;
use brdf::fresnel::{ConductorFresnel, Fresnel, conductor, dielectric};

/// Cosines from normal to grazing incidence, ±0, below the horizon and where c² underflows.
fn cosines() -> Vec<f32> {
    let mut c = vec![0.0f32, -0.0, 1.0, -1.0, 1e-20, 1e-45, f32::MIN_POSITIVE];
    c.extend((1..=1000).map(|i| i as f32 / 1000.0));
    c
}

#[test]
fn index_matched_conductor_reflects_nothing() {
    for c in cosines() {
        assert_eq!(conductor(c, Vec3::ONE, Vec3::ZERO), Vec3::ZERO, "cos {c}");
        assert_eq!(dielectric(c.max(0.0), 1.0), 0.0, "cos {c}");
        assert_eq!(
            ConductorFresnel::new(Vec3::ONE, Vec3::ZERO)
                .unwrap()
                .eval(c),
            Vec3::ZERO,
            "cos {c}"
        );
    }
}

/// Per channel: only the matched channel is 0; the others keep their grazing limit 1.
#[test]
fn only_the_matched_channel_is_zero() {
    let eta = Vec3::new(1.0, 1.0, 1.5);
    let k = Vec3::new(0.0, 1e-3, 0.0);
    assert_eq!(conductor(0.0, eta, k), Vec3::new(0.0, 1.0, 1.0));
    // Next to η = 1 the grazing value is the limit 1, as for the dielectric.
    for e in [1.0 - f32::EPSILON / 2.0, 1.0 + f32::EPSILON] {
        assert_eq!(
            conductor(0.0, Vec3::splat(e), Vec3::ZERO),
            Vec3::ONE,
            "η {e}"
        );
        assert_eq!(dielectric(0.0, e), 1.0, "η {e}");
    }
}
