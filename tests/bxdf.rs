//! Physics tests of the classic BRDFs: white furnace, reciprocity (and documented non-reciprocity),
//! chi-square goodness of fit of every sampler, sample / eval / pdf agreement, bad input, and a
//! property test for NaN / Inf / negative values.
//!
//! Expected values never come from the code under test: energies are hemisphere quadratures
//! (`support::quadrature`, with their error estimates) or closed forms written here; the microfacet BRDF
//! is checked against an independent textbook isotropic GGX (`TestGgx` below, D, Λ, and two samplers).
//!
//! Run: `cargo test --test bxdf`. Heavier sweeps: `cargo test --test bxdf -- --ignored --nocapture`.

mod support;

use brdf::bxdf::{
    BlinnPhongLobe, BlinnPhongNormalization, Bxdf, Lambert, Masking, MicrofacetBrdf, OriginalPhong,
    OriginalPhongNormalization, Phong, PhongNormalization, Sampling,
};
use brdf::frame::Frame;
use brdf::fresnel::{NoFresnel, SchlickFresnel};
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, SlopeGaussian};
use glam::{Mat2, Vec2, Vec3};
use proptest::prelude::*;
use rand::RngExt;
use std::f64::consts::PI;
use support::chi2::Chi2;
use support::quadrature::integrate_hemisphere;

// ---------------------------------------------------------------------------------------------------
// An independent isotropic GGX (Trowbridge-Reitz) written from the textbook formulas, used to test the
// generic microfacet BRDF before the crate's own NDFs exist.
// ---------------------------------------------------------------------------------------------------

/// Isotropic GGX: D = α² / (π ((α² − 1) cos² θ + 1)²), Λ = (−1 + √(1 + α² tan² θ)) / 2
/// ([Walter2007] eqs. 33-34), D cos sampling by inversion of its CDF tan² θ = α² u / (1 − u), and
/// visible-normal sampling with spherical caps (Dupuy & Benyoub 2023, listing 3).
#[derive(Clone, Copy, Debug)]
struct TestGgx {
    alpha: f32,
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

const THETAS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];

/// ∫ f(wo, wi) cos θ_i dω_i of channel 0 over the upper hemisphere about z (direct quadrature).
fn albedo_direct(b: &dyn Bxdf, wo: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
    integrate_hemisphere(
        &|wi| b.eval(wo, wi).x as f64 * wi.z.max(0.0) as f64,
        panels,
        n_phi,
    )
}

/// The same integral for a BRDF that vanishes outside the hemisphere about `axis` (a pure Phong lobe
/// about the mirror direction): the quadrature is done in a frame whose pole is the lobe's axis, so a
/// peaked lobe sits where the (θ, φ) rule is finest. Below-horizon directions contribute 0.
fn albedo_about(b: &dyn Bxdf, wo: Vec3, axis: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
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
fn albedo_half_vector(b: &dyn Bxdf, wo: Vec3, panels: usize, n_phi: usize) -> (f64, f64) {
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
fn mirror(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// A random unit direction in the upper hemisphere with cos θ log-uniform in [1e-7, 1] half of the
/// time (to reach grazing angles) and uniform otherwise.
fn random_upper(rng: &mut impl rand::Rng) -> Vec3 {
    let z: f32 = if rng.random::<bool>() {
        10f32.powf(-7.0 * rng.random::<f32>())
    } else {
        rng.random::<f32>().max(1e-7)
    };
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Tolerance of a furnace comparison: 4 × the quadrature's error estimate (which overestimates the
/// error of the finer rule, see `support::quadrature`) plus 1e-5 for the f32 rounding of the integrand
/// (relative ~1e-7 per value, accumulated over a sum of positive terms).
fn furnace_tol(err: f64) -> f64 {
    4.0 * err + 1e-5
}

/// Quadrature resolution (θ panels, φ points) for a furnace at θo degrees: near grazing the horizon
/// cuts the lobe (a kink in the integrand), where the rule converges more slowly.
fn res(theta_deg: f64) -> (usize, usize) {
    if theta_deg >= 80.0 {
        (128, 256)
    } else {
        (32, 64)
    }
}

fn phong(rho_d: f32, rho_s: f32, gamma: f32, n: PhongNormalization) -> Phong {
    Phong::new(Vec3::splat(rho_d), Vec3::splat(rho_s), gamma, n).unwrap()
}

fn blinn(rho_d: f32, rho_s: f32, gamma: f32, n: BlinnPhongNormalization) -> BlinnPhongLobe {
    BlinnPhongLobe::new(Vec3::splat(rho_d), Vec3::splat(rho_s), gamma, n).unwrap()
}

fn ggx(alpha: f32) -> MicrofacetBrdf<TestGgx, NoFresnel> {
    MicrofacetBrdf::new(TestGgx { alpha }, NoFresnel)
}

/// The non-centred, correlated lobe of the brief: mean slope (0.3, −0.2), Σ = [[0.04, 0.015],
/// [0.015, 0.02]] (σx = 0.2, σy ≈ 0.14, correlation ≈ 0.53). Its mean normal is tilted by ≈ 20°, so
/// A(w) = 0 for some directions (e.g. θ ≥ 75° at φ = 0) while V(w) > 0.
fn slope_gaussian() -> SlopeGaussian {
    SlopeGaussian::new(
        Vec2::new(0.3, -0.2),
        Mat2::from_cols_array(&[0.04, 0.015, 0.015, 0.02]),
    )
    .unwrap()
}

/// A boxed microfacet BRDF (F = 1) with the given options.
fn mf<D: Ndf + 'static>(ndf: D, masking: Masking, sampling: Sampling) -> Box<dyn Bxdf> {
    Box::new(
        MicrofacetBrdf::new(ndf, NoFresnel)
            .with_masking(masking)
            .with_sampling(sampling),
    )
}

/// The crate's centred NDFs through [`MicrofacetBrdf`]: Beckmann (Cook-Torrance) and GGX, isotropic α
/// and anisotropic (αx, αy) = (α, 2.5α).
fn crate_microfacets(
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

const PHONG_NORMS: [PhongNormalization; 5] = [
    PhongNormalization::Unnormalized,
    PhongNormalization::EnergyConservingOriginal,
    PhongNormalization::EnergyConserving,
    PhongNormalization::EnergyNormalizedArvo,
    PhongNormalization::EnergyNormalizedMallettYuksel,
];

// ---------------------------------------------------------------------------------------------------
// White furnace.
// ---------------------------------------------------------------------------------------------------

#[test]
fn furnace_lambert_is_the_albedo() {
    let l = Lambert::new(Vec3::ONE).unwrap();
    for t in THETAS {
        let (e, err) = albedo_direct(&l, support::dir(t, 20.0), 16, 32);
        assert!((e - 1.0).abs() < furnace_tol(err), "θo = {t}: {e} ± {err}");
    }
}

#[test]
fn furnace_phong_energy_conserving_variants() {
    // ρ_d = 0, ρ_s = 1: the specular lobe alone, integrated about its axis r.
    for gamma in [0.0f32, 1.0, 10.0, 100.0] {
        for norm in [
            PhongNormalization::EnergyConservingOriginal,
            PhongNormalization::EnergyConserving,
        ] {
            let p = phong(0.0, 1.0, gamma, norm);
            for t in THETAS {
                let wo = support::dir(t, 0.0);
                let (e, err) = albedo_about(&p, wo, mirror(wo), res(t).0, res(t).1);
                assert!(
                    err < 1e-4,
                    "{norm:?} γ={gamma} θo={t}: quadrature error {err}"
                );
                assert!(
                    e <= 1.0 + furnace_tol(err),
                    "{norm:?} γ={gamma} θo={t}: {e} ± {err}"
                );
                if t == 0.0 {
                    // Closed forms at normal incidence, I(γ, 1) = 2π/(γ+2): (γ+1)/(γ+2) and 1.
                    let g = gamma as f64;
                    let want = match norm {
                        PhongNormalization::EnergyConserving => 1.0,
                        _ => (g + 1.0) / (g + 2.0),
                    };
                    assert!(
                        (e - want).abs() < furnace_tol(err),
                        "{norm:?} γ={gamma}: {e} vs {want}"
                    );
                }
            }
        }
    }
}

#[test]
fn furnace_phong_energy_normalized_is_one() {
    // Arvo (integer γ) and Mallett-Yuksel (any γ): ∫ f cos = ρ_s = 1 for every wo within 1e-3.
    for gamma in [0.0f32, 1.0, 7.0, 100.0] {
        for norm in [
            PhongNormalization::EnergyNormalizedArvo,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        ] {
            let p = phong(0.0, 1.0, gamma, norm);
            for t in THETAS {
                let wo = support::dir(t, 30.0);
                let (e, err) = albedo_about(&p, wo, mirror(wo), res(t).0, res(t).1);
                // The quadrature must be much finer than the 1e-3 claim for the claim to mean anything.
                assert!(
                    err < 1e-4,
                    "{norm:?} γ={gamma} θo={t}: quadrature error {err}"
                );
                assert!(
                    (e - 1.0).abs() < 1e-3,
                    "{norm:?} γ={gamma} θo={t}: {e} ± {err}"
                );
            }
        }
    }
    // A non-integer exponent, Mallett-Yuksel only.
    let p = phong(
        0.0,
        1.0,
        3.7,
        PhongNormalization::EnergyNormalizedMallettYuksel,
    );
    for t in THETAS {
        let wo = support::dir(t, 0.0);
        let (e, err) = albedo_about(&p, wo, mirror(wo), res(t).0, res(t).1);
        assert!((e - 1.0).abs() < 1e-3, "γ=3.7 θo={t}: {e} ± {err}");
    }
}

#[test]
fn arvo_and_mallett_yuksel_agree() {
    // Both compute I(γ, cos θo) in f64 (an O(γ) recurrence and the incomplete beta function) and
    // round once to f32 before 1/I: they agree to a few f32 ulps (1e-6 relative ≈ 8 ulps; observed
    // bit-identical on this grid).
    for gamma in (0..=12).chain([25, 50, 100, 501]) {
        let a = phong(
            0.0,
            1.0,
            gamma as f32,
            PhongNormalization::EnergyNormalizedArvo,
        );
        let m = phong(
            0.0,
            1.0,
            gamma as f32,
            PhongNormalization::EnergyNormalizedMallettYuksel,
        );
        for t in [0.0, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0, 89.9] {
            let wo = support::dir(t, 0.0);
            let (na, nm) = (a.normalizer(wo), m.normalizer(wo));
            assert!(
                (na - nm).abs() <= 1e-6 * na,
                "γ={gamma} θo={t}: Arvo {na} vs M-Y {nm}"
            );
        }
    }
}

#[test]
fn furnace_phong_with_fresnel() {
    // Energy-normalised lobe with Schlick Fresnel: E = ρ_d (1 − F) + F, F = f0 + (1 − f0)(1 − cos θo)^5
    // (closed form written here). The direct quadrature about z resolves γ = 10 (lobe width ~0.3 rad).
    let (rho_d, f0) = (0.5f32, 0.5f32);
    let p = phong(
        rho_d,
        f0,
        10.0,
        PhongNormalization::EnergyNormalizedMallettYuksel,
    )
    .with_schlick_fresnel();
    for t in THETAS {
        let wo = support::dir(t, 0.0);
        let (e, err) = albedo_direct(&p, wo, 64, 256);
        let c = (t.to_radians()).cos();
        let f = f0 as f64 + (1.0 - f0 as f64) * (1.0 - c).powi(5);
        let want = rho_d as f64 * (1.0 - f) + f;
        // 1e-3: the energy-normalisation claim, as above; the quadrature must be finer.
        assert!(err < 1e-4, "θo={t}: {err}");
        assert!((e - want).abs() < 1e-3, "θo={t}: {e} vs {want} ± {err}");
        assert!(e <= 1.0 + furnace_tol(err));
    }
}

#[test]
fn furnace_original_phong() {
    for gamma in [0.0f32, 1.0, 10.0, 100.0] {
        let p = OriginalPhong::new(
            Vec3::ZERO,
            Vec3::ONE,
            gamma,
            OriginalPhongNormalization::EnergyConserving,
        )
        .unwrap();
        for t in THETAS {
            let wo = support::dir(t, 0.0);
            let (e, err) = albedo_about(&p, wo, mirror(wo), res(t).0, res(t).1);
            assert!(e <= 1.0 + furnace_tol(err), "γ={gamma} θo={t}: {e} ± {err}");
            if t == 0.0 {
                // The whole cap about r = n is above the horizon: exactly 1.
                assert!((e - 1.0).abs() < furnace_tol(err), "γ={gamma}: {e}");
            }
        }
    }
}

#[test]
fn furnace_blinn_phong_energy_conserving() {
    for gamma in [0.0f32, 1.0, 10.0, 100.0, 1000.0] {
        let b = blinn(0.0, 1.0, gamma, BlinnPhongNormalization::EnergyConserving);
        for t in THETAS {
            let (e, err) = albedo_half_vector(&b, support::dir(t, 0.0), res(t).0, res(t).1);
            assert!(err < 1e-4, "γ={gamma} θo={t}: quadrature error {err}");
            assert!(e <= 1.0 + furnace_tol(err), "γ={gamma} θo={t}: {e} ± {err}");
            if t == 0.0 {
                assert!((e - 1.0).abs() < furnace_tol(err), "γ={gamma}: {e} ± {err}");
            }
        }
    }
}

/// The models that are *not* energy conserving, shown with closed forms at normal incidence:
/// unnormalised modified Phong 2π/(γ+2), unnormalised original Phong 2π/(γ+1), and the
/// (γ+8)/(8π) Blinn-Phong factor (γ+8)(γ + 2^(−γ/2))/((γ+2)(γ+4)).
#[test]
fn furnace_documents_the_models_that_gain_energy() {
    let wo = Vec3::Z;
    for gamma in [1.0f32, 2.0, 4.0] {
        let g = gamma as f64;
        let p = phong(0.0, 1.0, gamma, PhongNormalization::Unnormalized);
        let (e, err) = albedo_about(&p, wo, Vec3::Z, 32, 64);
        assert!(
            (e - 2.0 * PI / (g + 2.0)).abs() < furnace_tol(err) && e > 1.0,
            "{gamma}: {e}"
        );
        let o = OriginalPhong::new(
            Vec3::ZERO,
            Vec3::ONE,
            gamma,
            OriginalPhongNormalization::Unnormalized,
        )
        .unwrap();
        let (e, err) = albedo_about(&o, wo, Vec3::Z, 32, 64);
        assert!(
            (e - 2.0 * PI / (g + 1.0)).abs() < furnace_tol(err) && e > 1.0,
            "{gamma}: {e}"
        );
    }
    for gamma in [1.0f32, 10.0, 50.0] {
        let g = gamma as f64;
        let b = blinn(0.0, 1.0, gamma, BlinnPhongNormalization::RealTimeRendering);
        let (e, err) = albedo_half_vector(&b, wo, 32, 64);
        let want = (g + 8.0) * (g + (-0.5 * g).exp2()) / ((g + 2.0) * (g + 4.0));
        assert!(
            (e - want).abs() < furnace_tol(err) && e > 1.0,
            "{gamma}: {e} vs {want}"
        );
    }
}

#[test]
fn furnace_microfacet_ggx() {
    for alpha in [0.1f32, 0.3, 0.6, 1.0] {
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let b = ggx(alpha).with_masking(masking);
            for t in THETAS {
                let (e, err) = albedo_half_vector(&b, support::dir(t, 0.0), res(t).0, res(t).1);
                assert!(
                    err < 1e-4,
                    "α={alpha} {masking:?} θo={t}: quadrature error {err}"
                );
                assert!(
                    e <= 1.0 + furnace_tol(err),
                    "α={alpha} {masking:?} θo={t}: {e} ± {err}"
                );
            }
            // At normal incidence the micronormals beyond 45° reflect below the horizon, so
            // E(n) ≤ 1 − P(θm > 45°) = 1/(1 + α²) (GGX's D cos has P(tan² θm > 1) = α²/(α² + 1)).
            let (e0, err0) = albedo_half_vector(&b, Vec3::Z, 32, 64);
            let bound = 1.0 / (1.0 + (alpha * alpha) as f64);
            assert!(
                e0 <= bound + furnace_tol(err0),
                "α={alpha}: {e0} vs {bound}"
            );
        }
        // Height-correlated masking occludes less than the separable product: more energy.
        for t in THETAS {
            let wo = support::dir(t, 0.0);
            let (es, _) =
                albedo_half_vector(&ggx(alpha).with_masking(Masking::Separable), wo, 32, 64);
            let (eh, _) = albedo_half_vector(&ggx(alpha), wo, 32, 64);
            assert!(eh >= es - 1e-6, "α={alpha} θo={t}: {eh} < {es}");
        }
    }
}

#[test]
fn furnace_microfacet_non_centred_slope_gaussian() {
    let sg = slope_gaussian();
    for masking in [Masking::Separable, Masking::HeightCorrelated] {
        let b = MicrofacetBrdf::new(sg, NoFresnel).with_masking(masking);
        // φ = 0: A(wo) = 0 at θo ≥ 75° (V > 0); φ = 180°: the lobe leans toward the viewer.
        for phi in [0.0, 180.0] {
            for t in THETAS {
                let wo = support::dir(t, phi);
                // The kink of A(wi) = max(A_s, 0) needs the finer rule near grazing.
                let (np, nf) = if t >= 80.0 { (256, 512) } else { (64, 128) };
                let (e, err) = albedo_half_vector(&b, wo, np, nf);
                assert!(
                    err < 3e-3,
                    "{masking:?} φ={phi} θo={t}: quadrature error {err}"
                );
                assert!(
                    e <= 1.0 + furnace_tol(err),
                    "{masking:?} φ={phi} θo={t}: {e} ± {err}"
                );
            }
        }
        // At normal incidence A = V = 1 and nothing is lost but the far tail: E ≈ 1 (observed 0.99968).
        let (e0, err0) = albedo_half_vector(&b, Vec3::Z, 64, 128);
        assert!(
            e0 > 0.999 && e0 <= 1.0 + furnace_tol(err0),
            "{masking:?}: {e0}"
        );
    }
    // The renderer's-measure factor A(wi)/cos θi is what keeps this ≤ 1: the bare P-BRDF f_P with
    // the geometric cosine gains energy for a tilted lobe (observed 1.48 at φ = 180°, θo = 80°,
    // where the lobe leans toward the viewer). f_P = D(h) M(wo, wi) / 4 with the public masking factor.
    let b = MicrofacetBrdf::new(sg, NoFresnel);
    let wo = support::dir(80.0, 180.0);
    let (e, err) = integrate_hemisphere(
        &|m| {
            let c = wo.dot(m);
            let wi = 2.0 * c * m - wo;
            if c <= 0.0 || wi.z <= 0.0 {
                return 0.0;
            }
            let f_p = 0.25 * sg.d(m) as f64 * b.masking_factor(wo, wi) as f64;
            f_p * wi.z as f64 * 4.0 * c as f64
        },
        128,
        256,
    );
    assert!(e > 1.4, "{e} ± {err}");
}

#[test]
fn furnace_microfacet_crate_ndfs() {
    for alpha in [0.1f32, 0.5, 1.0] {
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            for (name, b) in crate_microfacets(alpha, masking, Sampling::VisibleNormals) {
                for t in THETAS {
                    // Anisotropic lobes are checked across and along the stretched axis. The kink of
                    // the horizon cut at 89° leaves an error estimate up to ~1e-4 (0.01 % of E).
                    for phi in [0.0, 90.0] {
                        let (e, err) = albedo_half_vector(
                            b.as_ref(),
                            support::dir(t, phi),
                            res(t).0,
                            res(t).1,
                        );
                        assert!(
                            err < 5e-4,
                            "{name} {masking:?} θo={t} φ={phi}: quadrature error {err}"
                        );
                        assert!(
                            e <= 1.0 + furnace_tol(err),
                            "{name} {masking:?} θo={t} φ={phi}: {e} ± {err}"
                        );
                        if !name.contains('(') {
                            break; // isotropic: φ does not matter
                        }
                    }
                }
            }
        }
    }
    // The Blinn-Phong NDF D = (γ+2)/(2π) cos^γ θm through the same BRDF.
    for gamma in [10.0f32, 100.0] {
        let b = MicrofacetBrdf::new(BlinnPhong::new(gamma).unwrap(), NoFresnel);
        for t in THETAS {
            let (e, err) = albedo_half_vector(&b, support::dir(t, 0.0), res(t).0, res(t).1);
            assert!(
                err < 1e-4 && e <= 1.0 + furnace_tol(err),
                "blinn-phong ndf γ={gamma} θo={t}: {e} ± {err}"
            );
        }
    }
}

/// A name and two implementations of the same BRDF.
type Pair = (&'static str, Box<dyn Bxdf>, Box<dyn Bxdf>);

#[test]
fn crate_ndfs_agree_with_independent_implementations() {
    // Ggx vs the textbook TestGgx above; Beckmann vs SlopeGaussian::beckmann (a different
    // implementation of the same lobe, through its slope density). Both sides are f32 evaluations of
    // steep functions of h (D varies by a factor ~e per α of tilt): 2e-4 relative covers the rounding
    // of h (a few 1e-8) amplified by d ln D/dθ ≲ 2 tan θ / α² (observed ≤ 1.2e-4 for TestGgx at α = 0.1).
    let mut rng = support::rng(31);
    for alpha in [0.1f32, 0.4, 1.0] {
        for masking in [Masking::Separable, Masking::HeightCorrelated] {
            let pairs: [Pair; 2] = [
                (
                    "ggx",
                    mf(
                        Ggx::isotropic(alpha).unwrap(),
                        masking,
                        Sampling::VisibleNormals,
                    ),
                    mf(TestGgx { alpha }, masking, Sampling::VisibleNormals),
                ),
                (
                    "beckmann",
                    mf(
                        Beckmann::isotropic(alpha).unwrap(),
                        masking,
                        Sampling::VisibleNormals,
                    ),
                    mf(
                        SlopeGaussian::beckmann(alpha, alpha).unwrap(),
                        masking,
                        Sampling::VisibleNormals,
                    ),
                ),
            ];
            for (name, a, b) in &pairs {
                for _ in 0..2000 {
                    let (wo, wi) = (random_upper(&mut rng), random_upper(&mut rng));
                    let (fa, fb) = (a.eval(wo, wi).x, b.eval(wo, wi).x);
                    assert!(
                        (fa - fb).abs() <= 2e-4 * fa.max(fb) + 1e-30,
                        "{name} α={alpha} {masking:?} {wo} {wi}: {fa} vs {fb}"
                    );
                    let (pa, pb) = (a.pdf(wo, wi), b.pdf(wo, wi));
                    assert!(
                        (pa - pb).abs() <= 2e-4 * pa.max(pb) + 1e-30,
                        "{name} α={alpha} pdf {wo} {wi}: {pa} vs {pb}"
                    );
                }
            }
        }
    }
}

/// The lobe's peak in the plane of incidence: Phong peaks exactly at the mirror direction; the
/// microfacet BRDF f (without cosine) peaks beyond it, toward grazing, at grazing incidence
/// (the off-specular peak of Torrance-Sparrow, from D(h) G2 / cos θi), and f·cos θi peaks before it.
#[test]
fn off_specular_peaks() {
    let argmax = |g: &dyn Fn(Vec3) -> f32| -> f64 {
        // θi ∈ [0°, 90°) on the mirror side (φ = 180°) in steps of 0.01°.
        (0..9000)
            .map(|k| k as f64 * 0.01)
            .max_by(|&a, &b| g(support::dir(a, 180.0)).total_cmp(&g(support::dir(b, 180.0))))
            .unwrap()
    };
    let wo = support::dir(75.0, 0.0);
    let p = phong(0.0, 1.0, 50.0, PhongNormalization::EnergyConserving);
    // f32 plateau of cos^50 near its maximum: ties within ±0.05° of the exact peak.
    let peak = argmax(&|wi| p.eval(wo, wi).x);
    assert!((peak - 75.0).abs() <= 0.05, "phong peaks at {peak}°");
    for alpha in [0.2f32, 0.4] {
        for (name, b) in
            crate_microfacets(alpha, Masking::HeightCorrelated, Sampling::VisibleNormals)
                .into_iter()
                .take(2)
        {
            let peak_f = argmax(&|wi| b.eval(wo, wi).x);
            let peak_fcos = argmax(&|wi| b.eval(wo, wi).x * wi.z);
            assert!(peak_f > 76.0, "{name}: f peaks at {peak_f}°");
            assert!(peak_fcos < 75.0, "{name}: f cos peaks at {peak_fcos}°");
        }
    }
}

#[test]
fn half_vector_quadrature_matches_direct_quadrature() {
    // Cross-check of the change of variables used above, on a lobe wide enough for both rules.
    let b = ggx(0.5);
    for t in [0.0, 45.0, 80.0] {
        let wo = support::dir(t, 0.0);
        let (a, ea) = albedo_direct(&b, wo, 64, 256);
        let (h, eh) = albedo_half_vector(&b, wo, 32, 64);
        assert!((a - h).abs() < furnace_tol(ea + eh), "θo={t}: {a} vs {h}");
    }
}

// ---------------------------------------------------------------------------------------------------
// The microfacet BRDF against the textbook formula.
// ---------------------------------------------------------------------------------------------------

#[test]
fn microfacet_matches_textbook_torrance_sparrow() {
    // f = D(h) G2 / (4 cos θo cos θi) with G2 = G1 G1 (separable) or 1/(1 + Λo + Λi), G1 = 1/(1 + Λ),
    // computed here from D and Λ alone. f32 arithmetic on both sides: relative 1e-5.
    let n = TestGgx { alpha: 0.35 };
    let mut rng = support::rng(3);
    for _ in 0..2000 {
        let (wo, wi) = (random_upper(&mut rng), random_upper(&mut rng));
        let h = (wo + wi).normalize();
        let (lo, li) = (n.lambda(wo) as f64, n.lambda(wi) as f64);
        let base = n.d(h) as f64 / (4.0 * wo.z as f64 * wi.z as f64);
        for (masking, g2) in [
            (Masking::Separable, 1.0 / ((1.0 + lo) * (1.0 + li))),
            (Masking::HeightCorrelated, 1.0 / (1.0 + lo + li)),
        ] {
            let want = base * g2;
            let got = MicrofacetBrdf::new(n, NoFresnel)
                .with_masking(masking)
                .eval(wo, wi)
                .x as f64;
            assert!(
                (got - want).abs() <= 1e-5 * want + 1e-30,
                "{masking:?} {wo} {wi}: {got} vs {want}"
            );
        }
    }
}

/// An NDF whose projected area can vanish while its visible area does not (as for a non-centred lobe
/// seen edge-on): a GGX whose `projected_area` is 0 for directions with x > 0.5, and whose
/// `visible_area` is supplied independently. The BRDF must stay finite and use the V-based formula.
struct VanishingArea(TestGgx);

impl Ndf for VanishingArea {
    fn d(&self, m: Vec3) -> f32 {
        self.0.d(m)
    }
    fn lambda(&self, w: Vec3) -> f32 {
        self.0.lambda(w)
    }
    fn projected_area(&self, w: Vec3) -> f32 {
        if w.x > 0.5 { 0.0 } else { w.z.max(0.0) }
    }
    fn visible_area(&self, w: Vec3) -> f32 {
        w.z.max(0.0) * (1.0 + self.0.lambda(w))
    }
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        self.0.sample_normal(u)
    }
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        self.0.sample_visible(wo, u)
    }
}

#[test]
fn microfacet_never_divides_by_a_vanishing_projected_area() {
    let ndf = VanishingArea(TestGgx { alpha: 0.4 });
    let wo = support::dir(60.0, 0.0); // x ≈ 0.87: A(wo) = 0, V(wo) > 0
    let wi = support::dir(50.0, 180.0); // A(wi) = cos θi
    let vo = ndf.visible_area(wo) as f64;
    let ai = wi.z as f64;
    let h = (wo + wi).normalize();
    let d = ndf.d(h) as f64;
    // Height-correlated: M = 1/(V_o A_i + V_i A_o − A_o A_i) = 1/(V_o A_i) when A_o = 0.
    let hc = MicrofacetBrdf::new(&ndf, NoFresnel).eval(wo, wi).x as f64;
    assert!((hc - d / (4.0 * vo * ai)).abs() < 1e-5 * hc, "{hc}");
    // Separable: M = 1/(V_o V_i), also finite.
    let vi = ndf.visible_area(wi) as f64;
    let sep = MicrofacetBrdf::new(&ndf, NoFresnel)
        .with_masking(Masking::Separable)
        .eval(wo, wi)
        .x as f64;
    assert!((sep - d / (4.0 * vo * vi)).abs() < 1e-5 * sep, "{sep}");
    // Both projected areas zero (and so the height-correlated denominator): 0, not Inf / NaN.
    let wi2 = support::dir(70.0, 10.0);
    assert_eq!(
        MicrofacetBrdf::new(&ndf, NoFresnel).eval(wo, wi2),
        Vec3::ZERO
    );
}

#[test]
fn microfacet_works_through_a_reference_and_exposes_its_parts() {
    let n = TestGgx { alpha: 0.2 };
    let owned = MicrofacetBrdf::new(
        n,
        SchlickFresnel {
            f0: Vec3::splat(0.04),
        },
    );
    let borrowed = MicrofacetBrdf::new(
        &n,
        SchlickFresnel {
            f0: Vec3::splat(0.04),
        },
    );
    let (wo, wi) = (support::dir(40.0, 10.0), support::dir(35.0, 200.0));
    assert_eq!(owned.eval(wo, wi), borrowed.eval(wo, wi));
    assert_eq!(borrowed.ndf().alpha, 0.2);
    assert_eq!(borrowed.fresnel().f0, Vec3::splat(0.04));
    assert_eq!(owned.masking(), Masking::HeightCorrelated);
    assert_eq!(owned.sampling(), Sampling::VisibleNormals);
}

// ---------------------------------------------------------------------------------------------------
// Reciprocity.
// ---------------------------------------------------------------------------------------------------

/// Asserts f(wo, wi) = f(wi, wo) to 1e-5 relative on 2000 random pairs (f32 evaluation of the same
/// symmetric expression in a different order: a few ulps).
fn assert_reciprocal(name: &str, b: &dyn Bxdf) {
    let mut rng = support::rng(11);
    for _ in 0..2000 {
        let (wo, wi) = (random_upper(&mut rng), random_upper(&mut rng));
        let (a, r) = (b.eval(wo, wi), b.eval(wi, wo));
        let scale = a.abs().max(r.abs()).max_element();
        // 1e-5 relative, plus f32's smallest normal number in absolute terms: a value far in the
        // tail (D ~ 1e-40, subnormal) keeps only a few significant bits through one more product.
        assert!(
            (a - r).abs().max_element() <= 1e-5 * scale + f32::MIN_POSITIVE,
            "{name}: {wo} {wi}: {a} vs {r}"
        );
    }
}

/// A BRDF seen in its projected-area measure: eval · cos θi / A(wi) (the symmetric P-BRDF f_P of a
/// non-centred NDF) where both A(wo) and A(wi) are positive (the relation's domain), else 0.
struct PatchMeasure<'a> {
    brdf: &'a dyn Bxdf,
    area: &'a dyn Fn(Vec3) -> f32,
}

impl Bxdf for PatchMeasure<'_> {
    fn eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        let a = (self.area)(wi);
        if a > 0.0 && (self.area)(wo) > 0.0 {
            self.brdf.eval(wo, wi) * (wi.z / a)
        } else {
            Vec3::ZERO
        }
    }
    fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.brdf.pdf(wo, wi)
    }
    fn sample(&self, wo: Vec3, uc: f32, u: Vec2) -> Option<brdf::BxdfSample> {
        self.brdf.sample(wo, uc, u)
    }
}

#[test]
fn reciprocal_models() {
    assert_reciprocal("lambert", &Lambert::new(Vec3::new(0.2, 0.5, 0.9)).unwrap());
    for norm in &PHONG_NORMS[..3] {
        let p = phong(0.3, 0.6, 12.0, *norm);
        assert!(p.is_reciprocal());
        assert_reciprocal(&format!("phong {norm:?}"), &p);
    }
    for norm in [
        BlinnPhongNormalization::RealTimeRendering,
        BlinnPhongNormalization::EnergyConserving,
    ] {
        assert_reciprocal(&format!("blinn {norm:?}"), &blinn(0.3, 0.6, 30.0, norm));
    }
    for masking in [Masking::Separable, Masking::HeightCorrelated] {
        assert_reciprocal(&format!("ggx {masking:?}"), &ggx(0.3).with_masking(masking));
        let schlick = MicrofacetBrdf::new(
            TestGgx { alpha: 0.3 },
            SchlickFresnel {
                f0: Vec3::splat(0.1),
            },
        )
        .with_masking(masking);
        assert_reciprocal(&format!("ggx+schlick {masking:?}"), &schlick);
        // A tilted lobe is reciprocal in its own measure: f(wo, wi) cos θi / A(wi) is symmetric.
        let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_masking(masking);
        let a = |w: Vec3| slope_gaussian().projected_area(w);
        let patch_measure = PatchMeasure {
            brdf: &sg,
            area: &a,
        };
        assert_reciprocal(&format!("slope gaussian {masking:?}"), &patch_measure);
        for (name, b) in crate_microfacets(0.3, masking, Sampling::VisibleNormals) {
            assert_reciprocal(&format!("{name} {masking:?}"), b.as_ref());
        }
        let bp =
            MicrofacetBrdf::new(BlinnPhong::new(30.0).unwrap(), NoFresnel).with_masking(masking);
        assert_reciprocal(&format!("blinn-phong ndf {masking:?}"), &bp);
    }
}

#[test]
fn non_reciprocal_models_show_their_asymmetry() {
    let (wo, wi) = (support::dir(20.0, 0.0), support::dir(70.0, 180.0));
    // Original Phong, specular only: f(wo, wi) / f(wi, wo) = cos θo / cos θi exactly (the 1/cos θi).
    let o = OriginalPhong::new(
        Vec3::ZERO,
        Vec3::ONE,
        5.0,
        OriginalPhongNormalization::EnergyConserving,
    )
    .unwrap();
    let ratio = o.eval(wo, wi).x / o.eval(wi, wo).x;
    assert!(
        (ratio - wo.z / wi.z).abs() < 1e-5 * ratio && ratio > 2.5,
        "{ratio}"
    );

    // Energy-normalised Phong: the ratio is N(wo)/N(wi) = I(γ, cos θi)/I(γ, cos θo) (here ≈ 0.6).
    for norm in &PHONG_NORMS[3..] {
        let p = phong(0.0, 1.0, 5.0, *norm);
        assert!(!p.is_reciprocal());
        let ratio = p.eval(wo, wi).x / p.eval(wi, wo).x;
        let want = p.normalizer(wo) / p.normalizer(wi);
        assert!(
            (ratio - want).abs() < 1e-5 && (ratio - 1.0).abs() > 0.1,
            "{norm:?}: {ratio}"
        );
    }

    // Schlick Fresnel at cos θo breaks reciprocity of the otherwise reciprocal Lafortune lobe.
    let p = phong(0.2, 0.3, 5.0, PhongNormalization::EnergyConserving).with_schlick_fresnel();
    assert!(!p.is_reciprocal());
    let (a, b) = (p.eval(wo, wi).x, p.eval(wi, wo).x);
    assert!((a - b).abs() > 0.01 * a.max(b), "{a} {b}");
}

// ---------------------------------------------------------------------------------------------------
// Sampling: chi-square and agreement.
// ---------------------------------------------------------------------------------------------------

/// One chi-square configuration: a model and an outgoing direction.
struct Case {
    name: String,
    bxdf: Box<dyn Bxdf>,
    wo: Vec3,
}

fn case(name: String, bxdf: impl Bxdf + 'static, theta_deg: f64) -> Case {
    Case {
        name: format!("{name} θo={theta_deg}"),
        bxdf: Box::new(bxdf),
        wo: support::dir(theta_deg, 30.0),
    }
}

/// Runs every case (sample → `s.wi`, `None` → lost mass; density `bxdf.pdf(wo, ·)`), Šidák-corrected
/// over the whole list, and reports every failure at once.
fn run_chi2(cases: &[Case]) {
    let failures: Vec<String> = cases
        .iter()
        .filter_map(|c| {
            Chi2::new(&c.name, cases.len())
                .run(
                    |uc, u| c.bxdf.sample(c.wo, uc, u).map(|s| s.wi),
                    |w| c.bxdf.pdf(c.wo, w) as f64,
                )
                .err()
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

/// Lambert, Phong (modified with a constant and an energy-normalised N, with Fresnel, and the original
/// form) and the Blinn-Phong lobe. `full`: γ ∈ {1, 20, 200} × θo ∈ {0, 45, 80, 89} (Lambert: every θo
/// of `THETAS`); otherwise one grazing and one normal-incidence case per model at γ = 20.
fn chi2_cases_classic(full: bool) -> Vec<Case> {
    let (gammas, thetas): (&[f32], &[f64]) = if full {
        (&[1.0, 20.0, 200.0], &[0.0, 45.0, 80.0, 89.0])
    } else {
        (&[20.0], &[0.0, 80.0])
    };
    let mut v = Vec::new();
    for &t in if full { &THETAS[..] } else { &[89.0][..] } {
        v.push(case(
            "lambert".into(),
            Lambert::new(Vec3::splat(0.7)).unwrap(),
            t,
        ));
    }
    for &g in gammas {
        for (k, &t) in thetas.iter().enumerate() {
            // Default run: alternate the angle between models so that each model sees one of them.
            let pick = |i: usize| full || (i + k).is_multiple_of(2);
            if pick(0) {
                let p = phong(0.5, 0.5, g, PhongNormalization::EnergyConserving);
                v.push(case(format!("phong lafortune γ={g}"), p, t));
            }
            if pick(1) {
                let p = phong(
                    0.3,
                    0.7,
                    g,
                    PhongNormalization::EnergyNormalizedMallettYuksel,
                )
                .with_schlick_fresnel();
                v.push(case(format!("phong M-Y+Schlick γ={g}"), p, t));
            }
            if pick(0) {
                let n = OriginalPhongNormalization::EnergyConserving;
                let o = OriginalPhong::new(Vec3::splat(0.2), Vec3::splat(0.8), g, n).unwrap();
                v.push(case(format!("original phong γ={g}"), o, t));
            }
            // Blinn-Phong γ = 200 at 89°: a half-vector lobe compressed in azimuth by the reflection,
            // too thin for the harness's cells (see `chi2_cases_microfacet`); in `grazing_cases`.
            if pick(1) && !(g > 100.0 && t > 85.0) {
                let b = blinn(0.4, 0.6, g, BlinnPhongNormalization::EnergyConserving);
                v.push(case(format!("blinn-phong γ={g}"), b, t));
            }
        }
    }
    v
}

/// The microfacet BRDF × both samplers × α × θo ∈ {0, 30, 60, 80, 89}°.
///
/// Excluded: α < 0.5 at θo = 89°. There the reflected lobe is thinner in azimuth than a harness cell
/// (its width is about 4 α cos θo: 0.007 rad for α = 0.1, against cells of 2π/80 ≈ 0.079 rad), so the
/// harness's 6 × 6 Gauss rule per cell cannot compute the expected counts. Observed for α = 0.25,
/// visible normals: the cells' expected counts add up to a lost mass of 0.414 %, whereas a fine
/// half-vector quadrature of the same pdf gives 0.470 % and the sampler loses 0.470 % (4·10⁶ draws);
/// the chi-square then fails on the overflow cell alone. Those configurations are covered by
/// `lost_mass_matches_the_pdf_deficit` and `sampling_estimator_is_unbiased_at_grazing_angles`
/// ([`grazing_cases`]). The non-centred lobe (slope σ ≈ 0.2) is excluded at 89° for the same reason.
/// The harness now integrates each cell adaptively (tests/support/chi2.rs), which resolves these
/// lobes: their chi-square at 89° is in tests/grazing_chi2.rs; the exclusions here stand until this
/// file's sweep is redone.
fn chi2_cases_microfacet(full: bool) -> Vec<Case> {
    let mut v = Vec::new();
    let samplings = [Sampling::Normals, Sampling::VisibleNormals];
    if full {
        for alpha in [0.1f32, 0.25, 0.5, 1.0] {
            for &t in THETAS.iter().filter(|&&t| alpha >= 0.5 || t < 85.0) {
                for s in samplings {
                    v.push(case(
                        format!("test-ggx α={alpha} {s:?}"),
                        ggx(alpha).with_sampling(s),
                        t,
                    ));
                    for (name, b) in crate_microfacets(alpha, Masking::HeightCorrelated, s) {
                        // Anisotropic (α, 2.5α): the narrow axis is α, same exclusion rule.
                        v.push(Case {
                            name: format!("{name} {s:?} θo={t}"),
                            bxdf: b,
                            wo: support::dir(t, 30.0),
                        });
                    }
                }
            }
        }
        for gamma in [10.0f32, 100.0] {
            for &t in THETAS.iter().filter(|&&t| gamma <= 10.0 || t < 85.0) {
                for s in samplings {
                    let b = MicrofacetBrdf::new(BlinnPhong::new(gamma).unwrap(), NoFresnel)
                        .with_sampling(s);
                    v.push(case(format!("blinn-phong ndf γ={gamma} {s:?}"), b, t));
                }
            }
        }
    } else {
        for s in samplings {
            v.push(case(
                format!("test-ggx α=0.5 {s:?}"),
                ggx(0.5).with_sampling(s),
                89.0,
            ));
            let beckmann = Beckmann::isotropic(0.1).unwrap();
            v.push(case(
                format!("beckmann α=0.1 {s:?}"),
                MicrofacetBrdf::new(beckmann, NoFresnel).with_sampling(s),
                60.0,
            ));
        }
        let aniso = Ggx::new(0.2, 0.5).unwrap();
        v.push(case(
            "ggx α=(0.2, 0.5) VisibleNormals".into(),
            MicrofacetBrdf::new(aniso, NoFresnel),
            30.0,
        ));
        let bp = MicrofacetBrdf::new(BlinnPhong::new(20.0).unwrap(), NoFresnel);
        v.push(case("blinn-phong ndf γ=20 VisibleNormals".into(), bp, 0.0));
    }
    // θo = 89° excluded for the same reason as narrow GGX (σ ≈ 0.2 ≈ α 0.28), see `grazing_cases`.
    let sg_thetas: &[f64] = if full { &THETAS[..4] } else { &[80.0] };
    for &t in sg_thetas {
        for s in samplings {
            let b = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_sampling(s);
            v.push(case(format!("slope-gaussian {s:?}"), b, t));
        }
    }
    v
}

/// Configurations whose lobe the chi-square harness cannot resolve (see [`chi2_cases_microfacet`]):
/// narrow half-vector lobes at θo = 89°, where reflection compresses the lobe in azimuth.
fn grazing_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        v.push(case(
            format!("test-ggx α=0.1 {s:?}"),
            ggx(0.1).with_sampling(s),
            89.0,
        ));
        let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel).with_sampling(s);
        v.push(case(format!("slope-gaussian {s:?}"), sg, 89.0));
    }
    let b = blinn(0.4, 0.6, 200.0, BlinnPhongNormalization::EnergyConserving);
    v.push(case("blinn-phong γ=200".into(), b, 89.0));
    v.push(case(
        "test-ggx α=0.05 Normals".into(),
        ggx(0.05).with_sampling(Sampling::Normals),
        85.0,
    ));
    v
}

/// ∫_{H²} pdf(wo, wi) dω_i by the half-vector change of variables (dω_i = 4 (wo·m) dω_m), which puts
/// half-vector lobes at the pole of the quadrature.
fn pdf_mass(b: &dyn Bxdf, wo: Vec3) -> (f64, f64) {
    integrate_hemisphere(
        &|m| {
            let c = wo.dot(m);
            if c <= 0.0 {
                return 0.0;
            }
            b.pdf(wo, 2.0 * c * m - wo) as f64 * 4.0 * c as f64
        },
        128,
        256,
    )
}

/// The probability that `sample` returns `None` equals 1 − ∫_{H²} pdf (the pdf is the density of the
/// directions actually produced), checked where the chi-square harness cannot resolve the lobe.
/// The None fraction over 5·10⁵ draws has binomial standard error √(p(1−p)/n); tolerance
/// 4 standard errors + 4 × the quadrature's error estimate.
#[test]
fn lost_mass_matches_the_pdf_deficit() {
    let mut rng = support::rng(17);
    for c in grazing_cases() {
        let (mass, err) = pdf_mass(c.bxdf.as_ref(), c.wo);
        let n = 500_000;
        let lost = (0..n)
            .filter(|_| {
                let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
                c.bxdf.sample(c.wo, uc, u).is_none()
            })
            .count() as f64
            / n as f64;
        let se = (lost * (1.0 - lost) / n as f64).sqrt();
        assert!(
            (lost - (1.0 - mass)).abs() < 4.0 * se + 4.0 * err,
            "{}: lost {lost} ± {se}, 1 − ∫pdf = {} ± {err}",
            c.name,
            1.0 - mass
        );
    }
}

#[test]
fn chi2_classic() {
    run_chi2(&chi2_cases_classic(false));
}

#[test]
fn chi2_microfacet() {
    run_chi2(&chi2_cases_microfacet(false));
}

/// The whole sweep (~1 min): `cargo test --test bxdf -- --ignored chi2_full`.
#[test]
#[ignore]
fn chi2_full_classic() {
    run_chi2(&chi2_cases_classic(true));
}

/// The whole sweep (~1 min): `cargo test --test bxdf -- --ignored chi2_full`.
#[test]
#[ignore]
fn chi2_full_microfacet() {
    run_chi2(&chi2_cases_microfacet(true));
}

/// Where the chi-square harness cannot resolve the lobe ([`grazing_cases`]), the sampler is also
/// checked through its estimator: if draws followed a density q ≠ pdf, the mean of f cos θi / pdf
/// would be ∫ f cos θi q/pdf ≠ ∫ f cos θi. The mean weight over 2·10⁵ draws (`None` counts 0) must
/// match the half-vector quadrature of ∫ f cos θi within 4 standard errors plus the quadrature
/// tolerance.
#[test]
fn sampling_estimator_is_unbiased_at_grazing_angles() {
    let mut rng = support::rng(21);
    for c in grazing_cases() {
        let (e, err) = albedo_half_vector(c.bxdf.as_ref(), c.wo, 128, 256);
        let n = 200_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
            let w = c
                .bxdf
                .sample(c.wo, uc, u)
                .map_or(0.0, |s| s.weight().x as f64);
            sum += w;
            sum2 += w * w;
        }
        let mean = sum / n as f64;
        let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
        assert!(
            (mean - e).abs() < 4.0 * se + furnace_tol(err),
            "{}: MC {mean} ± {se} vs quadrature {e} ± {err}",
            c.name
        );
    }
}

/// sample / eval / pdf / eval_pdf agreement and weight() = f cos / pdf, on 5000 random draws.
fn assert_consistent(name: &str, b: &dyn Bxdf) {
    let mut rng = support::rng(5);
    let mut some = 0;
    for _ in 0..5000 {
        let wo = random_upper(&mut rng);
        let (uc, u) = (rng.random::<f32>(), Vec2::new(rng.random(), rng.random()));
        let Some(s) = b.sample(wo, uc, u) else {
            continue;
        };
        some += 1;
        assert!(
            (s.wi.length() - 1.0).abs() < 1e-5,
            "{name}: |wi| = {}",
            s.wi.length()
        );
        assert!(
            s.wi.z > 0.0 && s.pdf > 0.0 && s.pdf.is_finite(),
            "{name}: {s:?}"
        );
        let (f, pdf) = (b.eval(wo, s.wi), b.pdf(wo, s.wi));
        let (f2, pdf2) = b.eval_pdf(wo, s.wi);
        // Same f32 expressions evaluated at the same direction: equal up to 1e-6 relative.
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * a.abs().max(b.abs());
        assert!(
            close(s.pdf, pdf) && close(pdf, pdf2),
            "{name}: pdf {} {pdf} {pdf2}",
            s.pdf
        );
        for k in 0..3 {
            assert!(
                close(s.f[k], f[k]) && close(f[k], f2[k]),
                "{name}: f {} {f} {f2}",
                s.f
            );
        }
        let w = s.f * s.wi.z / s.pdf;
        assert!(
            (s.weight() - w).abs().max_element() <= 1e-6 * w.max_element(),
            "{name}"
        );
    }
    assert!(some > 1000, "{name}: only {some} samples");
}

#[test]
fn sample_eval_pdf_agree() {
    assert_consistent("lambert", &Lambert::new(Vec3::new(0.1, 0.5, 1.0)).unwrap());
    for norm in PHONG_NORMS {
        assert_consistent(&format!("phong {norm:?}"), &phong(0.4, 0.5, 8.0, norm));
        assert_consistent(
            &format!("phong {norm:?} fresnel"),
            &phong(0.4, 0.5, 8.0, norm).with_schlick_fresnel(),
        );
    }
    for norm in [
        OriginalPhongNormalization::Unnormalized,
        OriginalPhongNormalization::EnergyConserving,
    ] {
        let o = OriginalPhong::new(Vec3::splat(0.3), Vec3::splat(0.6), 15.0, norm).unwrap();
        assert_consistent(&format!("original {norm:?}"), &o);
    }
    assert_consistent(
        "blinn",
        &blinn(0.3, 0.6, 40.0, BlinnPhongNormalization::EnergyConserving),
    );
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        for m in [Masking::Separable, Masking::HeightCorrelated] {
            let sg = MicrofacetBrdf::new(slope_gaussian(), NoFresnel)
                .with_sampling(s)
                .with_masking(m);
            assert_consistent(&format!("slope gaussian {s:?} {m:?}"), &sg);
            for (name, b) in crate_microfacets(0.3, m, s) {
                assert_consistent(&format!("{name} {s:?} {m:?}"), b.as_ref());
            }
            let bp = mf(BlinnPhong::new(40.0).unwrap(), m, s);
            assert_consistent(&format!("blinn-phong ndf {s:?} {m:?}"), bp.as_ref());
            assert_consistent(
                &format!("ggx {s:?} {m:?}"),
                &ggx(0.3).with_sampling(s).with_masking(m),
            );
        }
    }
}

#[test]
fn weights_of_perfect_importance_sampling() {
    // Specular only (ρ_d = 0, so the lobe is always chosen) and pdf = (γ+1)/(2π) cos^γ θr:
    // original Phong: f cos θi / pdf = ρ_s N cos^γ θr / ((γ+1)/(2π) cos^γ θr) = 2π N/(γ+1) = 1 with
    // the energy-conserving N; modified Phong (Lafortune N): 2π N cos θi/(γ+1) = (γ+2)/(γ+1) cos θi.
    // f32 arithmetic: 1e-5 relative.
    let mut rng = support::rng(9);
    let g = 10.0;
    let o = OriginalPhong::new(
        Vec3::ZERO,
        Vec3::ONE,
        g,
        OriginalPhongNormalization::EnergyConserving,
    )
    .unwrap();
    let p = phong(0.0, 1.0, g, PhongNormalization::EnergyConserving);
    let mut count = 0;
    for _ in 0..2000 {
        let wo = random_upper(&mut rng);
        let u = Vec2::new(rng.random(), rng.random());
        if let Some(s) = o.sample(wo, 0.5, u) {
            assert!(
                (s.weight().x - 1.0).abs() < 1e-5,
                "original: {}",
                s.weight()
            );
            count += 1;
        }
        if let Some(s) = p.sample(wo, 0.5, u) {
            let want = (g + 2.0) / (g + 1.0) * s.wi.z;
            assert!(
                (s.weight().x - want).abs() < 1e-5 * want,
                "modified: {} vs {want}",
                s.weight()
            );
        }
    }
    assert!(count > 500, "{count}");
}

// ---------------------------------------------------------------------------------------------------
// Bad input.
// ---------------------------------------------------------------------------------------------------

#[test]
fn invalid_parameters_are_named() {
    let has = |r: Result<(), brdf::Error>, name: &str| {
        let e = r.expect_err(name);
        assert!(e.to_string().contains(name), "{e} does not name {name}");
    };
    let pn = PhongNormalization::EnergyConserving;
    has(Lambert::new(Vec3::new(1.1, 0.0, 0.0)).map(drop), "albedo");
    has(
        Lambert::new(Vec3::new(f32::NAN, 0.0, 0.0)).map(drop),
        "albedo",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::ONE, -1.0, pn).map(drop),
        "gamma",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::ONE, f32::INFINITY, pn).map(drop),
        "gamma",
    );
    has(
        Phong::new(
            Vec3::ZERO,
            Vec3::ONE,
            2.5,
            PhongNormalization::EnergyNormalizedArvo,
        )
        .map(drop),
        "gamma",
    );
    has(
        Phong::new(Vec3::splat(0.6), Vec3::splat(0.6), 2.0, pn).map(drop),
        "rho_d + rho_s",
    );
    has(
        Phong::new(Vec3::splat(-0.1), Vec3::ZERO, 2.0, pn).map(drop),
        "rho_d",
    );
    has(
        Phong::new(Vec3::ZERO, Vec3::new(0.0, 2.0, 0.0), 2.0, pn).map(drop),
        "rho_s",
    );
    let on = OriginalPhongNormalization::EnergyConserving;
    has(
        OriginalPhong::new(Vec3::ZERO, Vec3::ONE, f32::NAN, on).map(drop),
        "gamma",
    );
    has(
        OriginalPhong::new(Vec3::ONE, Vec3::ONE, 1.0, on).map(drop),
        "rho_d + rho_s",
    );
    let bn = BlinnPhongNormalization::EnergyConserving;
    has(
        BlinnPhongLobe::new(Vec3::ZERO, Vec3::ONE, -0.5, bn).map(drop),
        "gamma",
    );
    has(
        BlinnPhongLobe::new(Vec3::splat(0.5), Vec3::splat(0.7), 1.0, bn).map(drop),
        "rho_d + rho_s",
    );
    // The boundary is allowed: ρ_d + ρ_s = 1 with f32 inputs 0.7 + 0.3.
    assert!(Phong::new(Vec3::splat(0.7), Vec3::splat(0.3), 1.0, pn).is_ok());
}

fn all_models() -> Vec<(String, Box<dyn Bxdf>)> {
    let mut v: Vec<(String, Box<dyn Bxdf>)> = vec![(
        "lambert".into(),
        Box::new(Lambert::new(Vec3::splat(0.5)).unwrap()),
    )];
    for norm in PHONG_NORMS {
        v.push((
            format!("phong {norm:?}"),
            Box::new(phong(0.3, 0.5, 6.0, norm)),
        ));
        v.push((
            format!("phong {norm:?} fresnel"),
            Box::new(phong(0.3, 0.5, 6.0, norm).with_schlick_fresnel()),
        ));
    }
    for norm in [
        OriginalPhongNormalization::Unnormalized,
        OriginalPhongNormalization::EnergyConserving,
    ] {
        v.push((
            format!("original {norm:?}"),
            Box::new(OriginalPhong::new(Vec3::splat(0.3), Vec3::splat(0.5), 6.0, norm).unwrap()),
        ));
    }
    for norm in [
        BlinnPhongNormalization::RealTimeRendering,
        BlinnPhongNormalization::EnergyConserving,
    ] {
        v.push((
            format!("blinn {norm:?}"),
            Box::new(blinn(0.3, 0.5, 6.0, norm)),
        ));
    }
    for s in [Sampling::Normals, Sampling::VisibleNormals] {
        for m in [Masking::Separable, Masking::HeightCorrelated] {
            v.push((
                format!("ggx {s:?} {m:?}"),
                Box::new(ggx(0.3).with_sampling(s).with_masking(m)),
            ));
            v.push((
                format!("slope gaussian {s:?} {m:?}"),
                Box::new(
                    MicrofacetBrdf::new(slope_gaussian(), NoFresnel)
                        .with_sampling(s)
                        .with_masking(m),
                ),
            ));
        }
    }
    for (name, b) in crate_microfacets(0.3, Masking::HeightCorrelated, Sampling::VisibleNormals) {
        v.push((name, b));
    }
    v.push((
        "blinn-phong ndf".into(),
        mf(
            BlinnPhong::new(40.0).unwrap(),
            Masking::HeightCorrelated,
            Sampling::VisibleNormals,
        ),
    ));
    v
}

#[test]
fn degenerate_directions_give_zero_and_none() {
    let up = support::dir(30.0, 40.0);
    let below = Vec3::new(0.3, 0.1, -0.9).normalize();
    let horizon = Vec3::X;
    let bad = [
        below,
        horizon,
        Vec3::ZERO,
        Vec3::splat(f32::NAN),
        Vec3::new(f32::INFINITY, 0.0, 1.0),
        Vec3::new(0.0, 0.0, f32::INFINITY),
    ];
    for (name, b) in all_models() {
        for w in bad {
            for (wo, wi) in [(up, w), (w, up), (w, w)] {
                assert_eq!(b.eval(wo, wi), Vec3::ZERO, "{name}: eval({wo}, {wi})");
                assert_eq!(b.pdf(wo, wi), 0.0, "{name}: pdf({wo}, {wi})");
                assert_eq!(b.eval_pdf(wo, wi), (Vec3::ZERO, 0.0), "{name}");
            }
            assert!(
                b.sample(w, 0.3, Vec2::new(0.2, 0.7)).is_none(),
                "{name}: sample({w})"
            );
        }
        // wo = −wi: one of them is below the horizon.
        assert_eq!(b.eval(up, -up), Vec3::ZERO, "{name}");
        // wo = wi = n: a valid configuration; finite and non-negative.
        let (f, p) = b.eval_pdf(Vec3::Z, Vec3::Z);
        assert!(
            f.is_finite() && f.min_element() >= 0.0 && p.is_finite() && p >= 0.0,
            "{name}: {f} {p}"
        );
        // Non-finite random numbers: no sample, no panic.
        assert!(
            b.sample(up, f32::NAN, Vec2::new(f32::NAN, 0.5)).is_none(),
            "{name}"
        );
    }
}

// ---------------------------------------------------------------------------------------------------
// Property test.
// ---------------------------------------------------------------------------------------------------

/// A unit upper-hemisphere direction with cos θ = 10^(−7 t), t ∈ [0, 1], so down to cos θ = 1e-7.
fn upper_dir(t: f32, phi: f32) -> Vec3 {
    let z = 10f32.powf(-7.0 * t);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn check_values(
    name: &str,
    b: &dyn Bxdf,
    wo: Vec3,
    wi: Vec3,
    uc: f32,
    u: Vec2,
) -> Result<(), TestCaseError> {
    let (f, p) = b.eval_pdf(wo, wi);
    prop_assert!(
        f.is_finite() && f.min_element() >= 0.0,
        "{}: f = {} at {} {}",
        name,
        f,
        wo,
        wi
    );
    prop_assert!(
        p.is_finite() && p >= 0.0,
        "{}: pdf = {} at {} {}",
        name,
        p,
        wo,
        wi
    );
    if let Some(s) = b.sample(wo, uc, u) {
        prop_assert!(
            s.wi.is_finite() && s.f.is_finite() && s.f.min_element() >= 0.0,
            "{}: {:?}",
            name,
            s
        );
        prop_assert!(s.pdf.is_finite() && s.pdf > 0.0, "{}: {:?}", name, s);
        prop_assert!(s.weight().is_finite(), "{}: {:?}", name, s);
    }
    Ok(())
}

proptest! {
    #![proptest_config(crate::support::proptest_config(512))]

    #[test]
    fn no_nan_inf_or_negative(
        rho_d in 0.0f32..=1.0, split in 0.0f32..=1.0, gamma in 0.0f32..1e4, alpha in 1e-3f32..2.0,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        uc in 0.0f32..1.0, u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let rho_s = (1.0 - rho_d) * split;
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        let d = Vec3::splat(rho_d);
        let s = Vec3::splat(rho_s);
        check_values("lambert", &Lambert::new(d).unwrap(), wo, wi, uc, u)?;
        for norm in PHONG_NORMS {
            let g = if norm == PhongNormalization::EnergyNormalizedArvo { gamma.round().min(2000.0) } else { gamma };
            let p = Phong::new(d, s, g, norm).unwrap();
            check_values("phong", &p, wo, wi, uc, u)?;
            check_values("phong+fresnel", &p.with_schlick_fresnel(), wo, wi, uc, u)?;
        }
        for norm in [OriginalPhongNormalization::Unnormalized, OriginalPhongNormalization::EnergyConserving] {
            check_values("original", &OriginalPhong::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u)?;
        }
        for norm in [BlinnPhongNormalization::RealTimeRendering, BlinnPhongNormalization::EnergyConserving] {
            check_values("blinn", &BlinnPhongLobe::new(d, s, gamma, norm).unwrap(), wo, wi, uc, u)?;
        }
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                check_values("ggx", &ggx(alpha).with_sampling(sm).with_masking(m), wo, wi, uc, u)?;
            }
        }
    }

    #[test]
    fn microfacet_slope_gaussian_no_nan_inf_or_negative(
        mx in -1.5f32..1.5, my in -1.5f32..1.5, sx in 0.005f32..1.0, sy in 0.005f32..1.0,
        rho in -0.95f32..0.95, f0 in 0.0f32..=1.0,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let c = rho * sx * sy;
        let sg = SlopeGaussian::new(Vec2::new(mx, my), Mat2::from_cols_array(&[sx * sx, c, c, sy * sy])).unwrap();
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        let fresnel = SchlickFresnel::new(Vec3::splat(f0)).unwrap();
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                let b = MicrofacetBrdf::new(&sg, fresnel).with_sampling(sm).with_masking(m);
                check_values("slope gaussian", &b, wo, wi, 0.5, u)?;
            }
        }
    }

    #[test]
    fn microfacet_crate_ndfs_no_nan_inf_or_negative(
        ax in 1e-3f32..2.0, ay in 1e-3f32..2.0, gamma in 0.0f32..1e4,
        to in 0.0f32..=1.0, po in 0.0f32..6.3, ti in 0.0f32..=1.0, pi in 0.0f32..6.3,
        u0 in 0.0f32..1.0, u1 in 0.0f32..1.0,
    ) {
        let (wo, wi, u) = (upper_dir(to, po), upper_dir(ti, pi), Vec2::new(u0, u1));
        for sm in [Sampling::Normals, Sampling::VisibleNormals] {
            for m in [Masking::Separable, Masking::HeightCorrelated] {
                check_values("beckmann", mf(Beckmann::new(ax, ay).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
                check_values("ggx", mf(Ggx::new(ax, ay).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
                check_values("blinn-phong ndf", mf(BlinnPhong::new(gamma).unwrap(), m, sm).as_ref(), wo, wi, 0.5, u)?;
            }
        }
    }
}

/// The single-scattering energy loss 1 − E(wo), E = ∫ f cos θi dω_i with F = 1, of the microfacet
/// BRDF with Beckmann and GGX, for the table in docs/results.md (`## Classic BRDFs`):
/// `cargo test --test bxdf -- --ignored energy_loss_table --nocapture`.
/// Half-vector quadrature at 256 panels × 8 points in θ and 512 in φ; the largest error estimate is
/// printed under each table.
#[test]
#[ignore]
fn energy_loss_table() {
    let alphas = [0.05f32, 0.1, 0.25, 0.5, 0.75, 1.0];
    for masking in [Masking::HeightCorrelated, Masking::Separable] {
        for ndf in ["Beckmann", "GGX"] {
            println!("\n{ndf}, {masking:?} masking: 1 − E(wo)\n");
            println!("| α \\ θo | 0° | 30° | 60° | 80° | 89° |\n|---|---|---|---|---|---|");
            let mut worst = 0.0f64;
            for alpha in alphas {
                let b: Box<dyn Bxdf> = if ndf == "GGX" {
                    mf(
                        Ggx::isotropic(alpha).unwrap(),
                        masking,
                        Sampling::VisibleNormals,
                    )
                } else {
                    mf(
                        Beckmann::isotropic(alpha).unwrap(),
                        masking,
                        Sampling::VisibleNormals,
                    )
                };
                let mut row = format!("| {alpha} |");
                for t in THETAS {
                    let (e, err) = albedo_half_vector(b.as_ref(), support::dir(t, 0.0), 256, 512);
                    worst = worst.max(err);
                    row.push_str(&format!(" {:.4} |", 1.0 - e));
                }
                println!("{row}");
            }
            println!("\nlargest quadrature error estimate: {worst:.1e}");
        }
    }
}
