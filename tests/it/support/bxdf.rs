//! Shared helpers of the classic-BRDF tests (tests/it/bxdf_*.rs): an independent textbook GGX, the
//! hemisphere quadratures of ∫ f cos θi (direct, about an axis, over the half vector), the models
//! under test built from a few numbers, and random directions.

use super::quadrature::integrate_hemisphere;
use brdf::bxdf::{
    BlinnPhongLobe, BlinnPhongNormalization, Bxdf, Masking, MicrofacetBrdf, Phong,
    PhongNormalization, Sampling,
};
use brdf::frame::Frame;
use brdf::fresnel::NoFresnel;
use brdf::ndf::{Beckmann, Ggx, Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use rand::RngExt;

// ---------------------------------------------------------------------------------------------------
// An independent isotropic GGX (Trowbridge-Reitz) written from the textbook formulas, used to test the
// generic microfacet BRDF before the crate's own NDFs exist.
// ---------------------------------------------------------------------------------------------------

/// Isotropic GGX: D = α² / (π ((α² − 1) cos² θ + 1)²), Λ = (−1 + √(1 + α² tan² θ)) / 2
/// ([Walter2007] eqs. 33-34), D cos sampling by inversion of its CDF tan² θ = α² u / (1 − u), and
/// visible-normal sampling with spherical caps (Dupuy & Benyoub 2023, listing 3).
#[derive(Clone, Copy, Debug)]
pub struct TestGgx {
    pub alpha: f32,
}

impl Ndf for TestGgx {
    fn d(&self, m: Vec3) -> f32 {
        if m.z.is_nan() || m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = (a2 - 1.0) * m.z * m.z + 1.0;
        a2 / (std::f32::consts::PI * t * t)
    }

    fn lambda(&self, w: Vec3) -> f32 {
        if w.z.is_nan() || w.z <= 0.0 {
            return 0.0;
        }
        let tan2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
        0.5 * (-1.0 + (1.0 + self.alpha * self.alpha * tan2).sqrt())
    }

    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let ux = u.x.clamp(0.0, 0.999_999);
        let tan2 = self.alpha * self.alpha * ux / (1.0 - ux);
        let z = 1.0 / (1.0 + tan2).sqrt();
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = std::f32::consts::TAU * u.y;
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let a = self.alpha;
        let wh = Vec3::new(wo.x * a, wo.y * a, wo.z).normalize();
        let phi = std::f32::consts::TAU * u.x;
        let z = (1.0 - u.y) * (1.0 + wh.z) - wh.z;
        let st = (1.0 - z * z).clamp(0.0, 1.0).sqrt();
        let h = Vec3::new(st * phi.cos(), st * phi.sin(), z) + wh;
        Vec3::new(h.x * a, h.y * a, h.z.max(0.0)).normalize()
    }
}

// ---------------------------------------------------------------------------------------------------
// Helpers.
// ---------------------------------------------------------------------------------------------------

pub const THETAS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];

/// ∫ f(wo, wi) cos θ_i dω_i of channel 0 over the upper hemisphere about z (direct quadrature).
pub fn albedo_direct(b: &dyn Bxdf, wo: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
    integrate_hemisphere(
        &|wi| b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64,
        panels,
        n_phi,
    )
}

/// The same integral for a BRDF that vanishes outside the hemisphere about `axis` (a pure Phong lobe
/// about the mirror direction): the quadrature is done in a frame whose pole is the lobe's axis, so a
/// peaked lobe sits where the (θ, φ) rule is finest. Below-horizon directions contribute 0.
pub fn albedo_about(b: &dyn Bxdf, wo: Vec3, axis: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
    let frame = Frame::from_normal(axis);
    integrate_hemisphere(
        &|w| {
            let wi = frame.to_world(w);
            b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64
        },
        panels,
        n_phi,
    )
}

/// ∫ f cos θ_i dω_i for a BRDF whose value is a function of the half vector (microfacet, Blinn-Phong
/// specular), integrated over the half vector m instead: wi = reflect(wo, m), dω_i = 4 |wo·m| dω_m.
/// The map m ↦ wi is a bijection from {wo·m > 0} onto the sphere, and the integrand vanishes for
/// m.z ≤ 0 (D = 0 there), so the upper hemisphere of m covers everything.
pub fn albedo_half_vector(b: &dyn Bxdf, wo: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
    integrate_hemisphere(
        &|m| {
            let c = wo.dot(m);
            if c <= 0.0 {
                return 0.0;
            }
            let wi = 2.0 * c * m - wo;
            b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64 * 4.0 * c as f64
        },
        panels,
        n_phi,
    )
}

/// The mirror direction of `wo` about the normal.
pub fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// A random unit direction in the upper hemisphere with cos θ log-uniform in [1e-7, 1] half of the
/// time (to reach grazing angles) and uniform otherwise.
pub fn random_upper(rng: &mut impl rand::Rng) -> Vec3 {
    let z: f32 = if rng.random::<bool>() {
        10f32.powf(-7.0 * rng.random::<f32>())
    } else {
        rng.random::<f32>().max(1e-7)
    };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The white furnace the way a renderer integrates it: the mean of channel 0 of
/// `sample().weight()` over `n` draws at `wo` (a missing sample counts 0) and its standard error.
pub fn sampled_albedo(b: &dyn Bxdf, wo: Vec3, n: usize, rng: &mut impl rand::Rng) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = glam::Vec2::new(rng.random(), rng.random());
        let w = b
            .sample(wo, rng.random(), u)
            .map_or(0.0, |s| s.weight().x as f64);
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / n as f64;
    (
        mean,
        ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt(),
    )
}

/// The white furnace per channel the way a renderer integrates it: (mean, standard error) of
/// `sample().weight()` over `n` draws at `wo`, u.x stratified in n strata, the lobe choice and u.y
/// random from `seed` (a missing sample counts 0; delta samples count with their weight).
pub fn stratified_weight_moments(b: &dyn Bxdf, wo: Vec3, n: usize, seed: u64) -> [(f64, f64); 3] {
    let mut rng = super::rng(seed);
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for k in 0..n {
        let u = Vec2::new((k as f32 + rng.random::<f32>()) / n as f32, rng.random());
        let w = b
            .sample(wo, rng.random(), u)
            .map_or(Vec3::ZERO, |x| x.weight());
        for c in 0..3 {
            s[c] += w[c] as f64;
            s2[c] += (w[c] as f64).powi(2);
        }
    }
    std::array::from_fn(|c| {
        let m = s[c] / n as f64;
        (m, ((s2[c] / n as f64 - m * m).max(0.0) / n as f64).sqrt())
    })
}

/// The white furnace of a half-vector BRDF (microfacet) at `wo` both ways a renderer integrates
/// it: [`sampled_albedo`] over `n` draws and the quadrature of eval · cos θi over the half vector
/// ([`albedo_half_vector`], 256 × 512; 128 × 256 in the default run, whose error estimate sets
/// the tolerance either way). Asserts that neither exceeds 1 (within 4 standard errors,
/// the quadrature's tolerance) and that they agree; returns the sampled mean. `label` names the case
/// in the printout and the failures.
pub fn assert_half_vector_furnace(
    b: &dyn Bxdf,
    wo: Vec3,
    n: usize,
    rng: &mut impl rand::Rng,
    label: &str,
) -> f64 {
    let (mean, se) = sampled_albedo(b, wo, n, rng);
    let (q, q_err) = albedo_half_vector(b, wo, super::depth(128, 256), super::depth(256, 512));
    println!("{label}: furnace {mean:.4} ± {se:.4}, quadrature {q:.4} ± {q_err:.1e}");
    assert!(mean <= 1.0 + 4.0 * se + 1e-6, "{label}: {mean} ± {se}");
    assert!(q <= 1.0 + furnace_tol(q_err), "{label}: {q}");
    assert!(
        (q - mean).abs() < 4.0 * se + furnace_tol(q_err),
        "{label}: quadrature {q} vs sampled {mean}"
    );
    mean
}

/// [`assert_half_vector_furnace`] with 50,000 draws at each θo of `thetas` (degrees, φo = 30°),
/// each case named "`label` θo θ".
pub fn assert_half_vector_furnaces(
    b: &dyn Bxdf,
    thetas: impl IntoIterator<Item = f64>,
    rng: &mut impl rand::Rng,
    label: &str,
) {
    for theta in thetas {
        let wo = super::dir(theta, 30.0);
        assert_half_vector_furnace(b, wo, 50_000, rng, &format!("{label} θo {theta}"));
    }
}

/// Tolerance of a furnace comparison: 4 × the quadrature's error estimate (which overestimates the
/// error of the finer rule, see `support::quadrature`) plus 1e-5 for the f32 rounding of the integrand
/// (relative ~1e-7 per value, accumulated over a sum of positive terms).
pub fn furnace_tol(err: f64) -> f64 {
    4.0 * err + 1e-5
}

/// Quadrature resolution (θ panels, φ points) for a furnace at θo degrees: near grazing the horizon
/// cuts the lobe (a kink in the integrand), where the rule converges more slowly.
pub fn res(theta_deg: f64) -> (usize, usize) {
    if theta_deg >= 80.0 {
        (128, 256)
    } else {
        (32, 64)
    }
}

pub fn phong(rho_d: f32, rho_s: f32, gamma: f32, n: PhongNormalization) -> Phong {
    Phong::new(Vec3::splat(rho_d), Vec3::splat(rho_s), gamma, n).unwrap()
}

pub fn blinn(rho_d: f32, rho_s: f32, gamma: f32, n: BlinnPhongNormalization) -> BlinnPhongLobe {
    BlinnPhongLobe::new(Vec3::splat(rho_d), Vec3::splat(rho_s), gamma, n).unwrap()
}

pub fn ggx(alpha: f32) -> MicrofacetBrdf<TestGgx, NoFresnel> {
    MicrofacetBrdf::new(TestGgx { alpha }, NoFresnel)
}

/// The non-centred, correlated lobe of the brief: mean slope (0.3, −0.2), Σ = [[0.04, 0.015],
/// [0.015, 0.02]] (σx = 0.2, σy ≈ 0.14, correlation ≈ 0.53). Its mean normal is tilted by ≈ 20°, so
/// A(w) = 0 for some directions (e.g. θ ≥ 75° at φ = 0) while V(w) > 0.
pub fn slope_gaussian() -> SlopeGaussian {
    SlopeGaussian::new(
        Vec2::new(0.3, -0.2),
        Mat2::from_cols_array(&[0.04, 0.015, 0.015, 0.02]),
    )
    .unwrap()
}

/// A boxed microfacet BRDF (F = 1) with the given options.
pub fn mf<D: Ndf + 'static>(ndf: D, masking: Masking, sampling: Sampling) -> Box<dyn Bxdf> {
    Box::new(
        MicrofacetBrdf::new(ndf, NoFresnel)
            .with_masking(masking)
            .with_sampling(sampling),
    )
}

/// The crate's centred NDFs through [`MicrofacetBrdf`]: Beckmann (Cook-Torrance) and GGX, isotropic α
/// and anisotropic (αx, αy) = (α, 2.5α).
pub fn crate_microfacets(
    alpha: f32,
    masking: Masking,
    sampling: Sampling,
) -> Vec<(String, Box<dyn Bxdf>)> {
    let a2 = 2.5 * alpha;
    vec![
        (
            format!("beckmann α={alpha}"),
            mf(Beckmann::isotropic(alpha).unwrap(), masking, sampling),
        ),
        (
            format!("ggx α={alpha}"),
            mf(Ggx::isotropic(alpha).unwrap(), masking, sampling),
        ),
        (
            format!("beckmann α=({alpha}, {a2})"),
            mf(Beckmann::new(alpha, a2).unwrap(), masking, sampling),
        ),
        (
            format!("ggx α=({alpha}, {a2})"),
            mf(Ggx::new(alpha, a2).unwrap(), masking, sampling),
        ),
    ]
}

pub const PHONG_NORMS: [PhongNormalization; 5] = [
    PhongNormalization::Unnormalized,
    PhongNormalization::EnergyConservingOriginal,
    PhongNormalization::EnergyConserving,
    PhongNormalization::EnergyNormalizedArvo,
    PhongNormalization::EnergyNormalizedMallettYuksel,
];
