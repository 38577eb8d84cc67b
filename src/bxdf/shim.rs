//! TEMPORARY stand-ins for items other branches are adding to `main` (`brdf::ndf::phong_lobe_integral*`,
//! `brdf::fresnel`). Same names and signatures; this file is deleted when those land.
#![allow(dead_code)]

use glam::Vec3;
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

/// Fresnel reflectance as a function of the cosine between the incident direction and the normal.
pub trait Fresnel {
    /// F(cos θ).
    fn eval(&self, cos_theta: f32) -> Vec3;
}

/// F = 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoFresnel;

impl Fresnel for NoFresnel {
    fn eval(&self, _cos_theta: f32) -> Vec3 {
        Vec3::ONE
    }
}

/// Schlick's approximation F = f0 + (1 − f0)(1 − cos θ)^5.
pub fn schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    let m = (1.0 - cos_theta.clamp(0.0, 1.0)).powi(5);
    f0 + (Vec3::ONE - f0) * m
}

/// Schlick Fresnel with reflectance `f0` at normal incidence.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchlickFresnel {
    /// Reflectance at normal incidence.
    pub f0: Vec3,
}

impl Fresnel for SchlickFresnel {
    fn eval(&self, cos_theta: f32) -> Vec3 {
        schlick(self.f0, cos_theta)
    }
}
