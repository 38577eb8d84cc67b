//! TEMPORARY stand-ins for items other branches are adding to `main` (`brdf::ndf::phong_lobe_integral*`,
//! `brdf::fresnel`, now merged). Same names and signatures; this file is deleted when those land.
#![allow(dead_code)]

use std::f64::consts::PI;

/// I(γ, c) = ∫_{H²} max(0, ω·r)^γ cos θ dω with r at cos θ_r = c (Mallett & Yuksel 2020).
pub fn phong_lobe_integral(gamma: f32, cos_theta: f32) -> f32 {
    let n = gamma as f64;
    let c = (cos_theta as f64).clamp(0.0, 1.0);
    let s2 = (1.0 - c * c).max(0.0);
    let half = 0.5 * n;
    let mut neg = c;
    if n >= 1e-18 {
        neg *= half * statrs::function::beta::beta_inc(half, 0.5, s2);
    }
    let gq = (statrs::function::gamma::ln_gamma(half + 0.5)
        - statrs::function::gamma::ln_gamma(half + 1.0))
    .exp();
    ((2.0 * PI * c + PI.sqrt() * gq * (s2.powf(half) - neg)) / (n + 2.0)) as f32
}

/// The same integral for integer exponents by Arvo's (1995) recurrence, O(n).
pub fn phong_lobe_integral_arvo(n: u32, cos_theta: f32) -> f32 {
    let c = (cos_theta as f64).clamp(0.0, 1.0);
    let s = (1.0 - c * c).max(0.0).sqrt();
    let (a, mut k, mut tk) = if n % 2 == 0 {
        (PI / 2.0, 0u32, PI / 2.0)
    } else {
        (PI - c.acos(), 1u32, s)
    };
    let mut t = 0.0;
    while k + 2 <= n {
        t += tk;
        k += 2;
        tk *= s * s * (k as f64 - 1.0) / k as f64;
    }
    (2.0 * (tk + a * c + c * c * t) / (n as f64 + 2.0)) as f32
}
