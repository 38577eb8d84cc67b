//! Integration tests of the centred analytic NDFs (Beckmann, GGX, Blinn-Phong) and the Phong lobe
//! integrals: chi-square tests of every sampler, hemisphere integrals of the defining identities,
//! Beckmann Λ against an independent f64 evaluation, property tests of totality, bad input.
//!
//! Run: `cargo test --test ndf_centred` (≈ 20–40 s on 2 cores at opt-level 3).

mod support;

use brdf::ndf::{Beckmann, Ggx, Ndf};
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use support::chi2::Chi2;

/// The α values of the brief.
const ALPHAS: [f32; 4] = [0.05, 0.125, 0.5, 1.0];
/// Incidence angles (degrees) for the visible-normal samplers.
const THETAS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];
/// Azimuth of wo for the anisotropic cases (a non-symmetric configuration).
const PHI_ANISO: f64 = 35.0;

/// Number of chi-square tests in this file, i.e. the Šidák family:
/// visible: (Beckmann + GGX) × 4 α × (iso, aniso) × 5 θ + Blinn-Phong × 4 α × 5 θ = 100;
/// D cos: (Beckmann + GGX) × 4 α × (iso, aniso) + Blinn-Phong × 4 α = 20.
const FAMILY: usize = 120;

/// A named NDF under test, boxed so that the three types share one list. `(kx, ky)` is the slope
/// scale of the lobe (α_x, α_y; for Blinn-Phong its Beckmann-equivalent α), used by [`Chart`].
struct Case {
    name: String,
    ndf: Box<dyn Ndf + Sync + Send>,
    aniso: bool,
    kx: f64,
    ky: f64,
}

/// The coordinates in which a sampler is binned by the chi-square harness.
///
/// The harness grids z = cos θ uniformly from a pilot quantile to 1 and φ uniformly, and integrates
/// each cell with a 6 × 6 Gauss–Legendre rule. Binned in the shading frame, two configurations
/// defeat that grid: a lobe much narrower than a cell (GGX at α = 0.05 has heavy tails, so the pilot
/// puts z_min near 0.4 and the whole peak falls into one row), and a boundary of the support that
/// cuts a cell so that all 36 nodes miss the part with mass (draws in a cell of expected count 0).
/// So every direction m is mapped, before binning, by a fixed smooth bijection:
///
/// 1. its slope is divided by (kx, ky): m' = normalize(x/kx, y/ky, z), which turns the lobe into
///    an α ≈ 1 lobe; the support {m·wo > 0, m.z > 0} becomes the lune {m'·v > 0, m'.z > 0} with
///    v = normalize(kx wo.x, ky wo.y, wo.z) (wo·m ∝ wo.z − ñ·wo_xy is linear in the slope);
/// 2. m' is written in spherical coordinates (θ, φ) about a vertex e ∝ z × v of the lune, with
///    φ = 0 on the great circle m'.z = 0, so that the lune is exactly the wedge 0 < φ < Φ,
///    Φ = π − ∠(z, v), 0 < θ < π;
/// 3. (θ, φ) ↦ (θ/2, 2πφ/Φ) puts the wedge onto the harness' hemisphere with both support
///    boundaries on cell edges (φ = 0 ≡ 2π).
///
/// The density transforms with dω_m/dω_w = [kx ky cos³θ_m / cos³θ_m'] · [4 cos(θ/2) Φ/(2π)]
/// (dω = cos³θ dñ with dñ = kx ky dñ'; sin θ dθ dφ = 4 cos(θ/2) · sin(θ/2) d(θ/2) · (Φ/2π) d(2πφ/Φ)).
/// This is a change of variables only: the test still compares the sampler with the NDF's own pdf
/// over the whole hemisphere. For the D cos samplers wo = z (Φ = π, e any horizontal axis).
struct Chart {
    kx: f64,
    ky: f64,
    /// Frame (d1, y, e) of the wedge: pole e, φ measured from d1 toward y.
    d1: [f64; 3],
    y: [f64; 3],
    e: [f64; 3],
    /// Opening angle Φ of the wedge.
    phi_max: f64,
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn scale(a: [f64; 3], s: f64) -> [f64; 3] {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// Normalises an f64 triple; `None` for zero length or non-finite input.
fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(v, v).sqrt();
    (l > 0.0 && l.is_finite()).then(|| scale(v, 1.0 / l))
}

impl Chart {
    fn new(case: &Case, wo: Vec3) -> Chart {
        let z = [0.0, 0.0, 1.0];
        let v = unit([case.kx * wo.x as f64, case.ky * wo.y as f64, wo.z as f64]).unwrap();
        let mut e = unit(cross(z, v)).unwrap_or([1.0, 0.0, 0.0]);
        // d1: on the circle m'.z = 0, orthogonal to e, on the visible side of v.
        let mut d1 = cross(e, z);
        if dot(d1, v) < 0.0 {
            d1 = scale(d1, -1.0);
        }
        let mut y = cross(e, d1);
        // Orient so that the interior (toward z + v) has 0 < φ < Φ.
        if dot(y, [v[0], v[1], v[2] + 1.0]) < 0.0 {
            e = scale(e, -1.0);
            y = scale(y, -1.0);
        }
        let phi_max = std::f64::consts::PI - v[2].clamp(-1.0, 1.0).acos();
        Chart {
            kx: case.kx,
            ky: case.ky,
            d1,
            y,
            e,
            phi_max,
        }
    }

    /// m (NDF space) → chart direction; `None` outside the lune (the harness' overflow cell).
    fn forward(&self, m: Vec3) -> Option<Vec3> {
        if !(m.z > 0.0) {
            return None;
        }
        let mp = unit([m.x as f64 / self.kx, m.y as f64 / self.ky, m.z as f64])?;
        let theta = dot(mp, self.e).clamp(-1.0, 1.0).acos();
        let mut phi = dot(mp, self.y).atan2(dot(mp, self.d1));
        if phi < 0.0 {
            phi += 2.0 * std::f64::consts::PI;
        }
        if phi > self.phi_max {
            return None;
        }
        let (th, ph) = (0.5 * theta, 2.0 * std::f64::consts::PI * phi / self.phi_max);
        Some(Vec3::new(
            (th.sin() * ph.cos()) as f32,
            (th.sin() * ph.sin()) as f32,
            th.cos() as f32,
        ))
    }

    /// chart direction → (m, Jacobian dω_m/dω_w); `None` where the map is undefined.
    fn inverse(&self, w: Vec3) -> Option<(Vec3, f64)> {
        let w = unit([w.x as f64, w.y as f64, w.z as f64])?;
        let th = w[2].clamp(-1.0, 1.0).acos();
        let mut ph = w[1].atan2(w[0]);
        if ph < 0.0 {
            ph += 2.0 * std::f64::consts::PI;
        }
        let (theta, phi) = (2.0 * th, ph * self.phi_max / (2.0 * std::f64::consts::PI));
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        let mp = [0, 1, 2].map(|i| st * (cp * self.d1[i] + sp * self.y[i]) + ct * self.e[i]);
        if !(mp[2] > 0.0) {
            return None;
        }
        let m = unit([mp[0] * self.kx, mp[1] * self.ky, mp[2]])?;
        let jac = self.kx * self.ky * (m[2] / mp[2]).powi(3) * 4.0 * th.cos() * self.phi_max
            / (2.0 * std::f64::consts::PI);
        Some((Vec3::new(m[0] as f32, m[1] as f32, m[2] as f32), jac))
    }
}

fn microfacet_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for &a in &ALPHAS {
        v.push(Case {
            name: format!("beckmann a={a}"),
            ndf: Box::new(Beckmann::isotropic(a).unwrap()),
            aniso: false,
            kx: a as f64,
            ky: a as f64,
        });
        v.push(Case {
            name: format!("beckmann ax={a} ay={}", a / 4.0),
            ndf: Box::new(Beckmann::new(a, a / 4.0).unwrap()),
            aniso: true,
            kx: a as f64,
            ky: a as f64 / 4.0,
        });
        v.push(Case {
            name: format!("ggx a={a}"),
            ndf: Box::new(Ggx::isotropic(a).unwrap()),
            aniso: false,
            kx: a as f64,
            ky: a as f64,
        });
        v.push(Case {
            name: format!("ggx ax={a} ay={}", a / 4.0),
            ndf: Box::new(Ggx::new(a, a / 4.0).unwrap()),
            aniso: true,
            kx: a as f64,
            ky: a as f64 / 4.0,
        });
    }
    v
}

fn all_cases() -> Vec<Case> {
    microfacet_cases()
}

fn chi2_visible(case: &Case, theta: f64) -> Result<f64, String> {
    let wo = support::dir(theta, if case.aniso { PHI_ANISO } else { 0.0 });
    let name = format!("visible {} theta={theta}", case.name);
    let chart = Chart::new(case, wo);
    Chi2::new(name, FAMILY).run(
        |_, u| chart.forward(case.ndf.sample_visible(wo, u)),
        |w| {
            chart
                .inverse(w)
                .map_or(0.0, |(m, jac)| case.ndf.pdf_visible(wo, m) as f64 * jac)
        },
    )
}

fn chi2_normal(case: &Case) -> Result<f64, String> {
    let name = format!("normal {}", case.name);
    let chart = Chart::new(case, Vec3::Z);
    Chi2::new(name, FAMILY).run(
        |_, u| chart.forward(case.ndf.sample_normal(u)),
        |w| {
            chart
                .inverse(w)
                .map_or(0.0, |(m, jac)| case.ndf.pdf_normal(m) as f64 * jac)
        },
    )
}

fn report(results: Vec<Result<f64, String>>) {
    let failures: Vec<String> = results.into_iter().filter_map(Result::err).collect();
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn chi2_visible_microfacet() {
    let cases = microfacet_cases();
    let jobs: Vec<(&Case, f64)> = cases
        .iter()
        .flat_map(|c| THETAS.iter().map(move |&t| (c, t)))
        .collect();
    report(jobs.par_iter().map(|&(c, t)| chi2_visible(c, t)).collect());
}

#[test]
fn chi2_normal_all() {
    let cases = all_cases();
    report(cases.par_iter().map(chi2_normal).collect());
}

// ---------------------------------------------------------------------------------------------
// The Phong lobe integrals.

/// max(0, ω·a)^γ max(0, ω·z) for the axis a at polar angle acos(c) in the xz-plane, in f64.
fn phong_integrand(gamma: f64, c: f64) -> impl Fn(Vec3) -> f64 {
    let s = (1.0 - c * c).max(0.0).sqrt();
    move |w: Vec3| {
        let d = s * w.x as f64 + c * w.z as f64;
        if d > 0.0 && w.z > 0.0 {
            d.powf(gamma) * w.z as f64
        } else {
            0.0
        }
    }
}

#[test]
fn phong_lobe_integral_matches_quadrature() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    let gammas = [0.0, 0.5, 1.0, 2.5, 10.0, 64.0, 300.0];
    let cosines = [1.0, 0.8, 0.5, 0.1, 0.0, -0.3];
    let jobs: Vec<(f64, f64)> = gammas
        .iter()
        .flat_map(|&g| cosines.iter().map(move |&c| (g, c)))
        .collect();
    let failures: Vec<String> = jobs
        .par_iter()
        .filter_map(|&(g, c)| {
            // 192 θ panels × 8 nodes and 768 φ nodes resolve a lobe of width 1/√300 ≈ 0.06 rad
            // with ≥ 10 nodes across it in both directions. Measured error estimates: ≤ 1e-6 for
            // γ > 0, up to 1.1e-4 for γ = 0 (the integrand is then discontinuous at ω·a = 0).
            let (q, err) =
                support::quadrature::integrate_hemisphere(&phong_integrand(g, c), 192, 768);
            let got = phong_lobe_integral(g as f32, c as f32) as f64;
            // Tolerance: 4× the quadrature's error estimate (which overestimates its true error)
            // + 1e-6 relative (directions are rounded to f32 inside the quadrature; the result
            // is rounded to f32) + 1e-9 absolute (I = 0 cases).
            let tol = 4.0 * err + 1e-6 * q.abs() + 1e-9;
            let mut msg = Vec::new();
            if (got - q).abs() > tol {
                msg.push(format!("MY γ={g} c={c}: {got} vs quadrature {q} ± {err}"));
            }
            if g.fract() == 0.0 {
                let arvo = phong_lobe_integral_arvo(g as u32, c as f32) as f64;
                if (arvo - q).abs() > tol {
                    msg.push(format!(
                        "Arvo n={g} c={c}: {arvo} vs quadrature {q} ± {err}"
                    ));
                }
            }
            (!msg.is_empty()).then(|| msg.join("\n"))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn phong_arvo_equals_mallett_yuksel() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    let mut worst = 0.0f64;
    for n in (0..=40).chain([63, 64, 255, 256, 1000, 4097, 100_000]) {
        for i in 0..=200 {
            let c = -1.0 + 2.0 * i as f32 / 200.0;
            let a = phong_lobe_integral_arvo(n, c) as f64;
            let m = phong_lobe_integral(n as f32, c) as f64;
            // Both are f64 computations rounded to f32; Arvo's sum accumulates ~n·ε₆₄ and statrs'
            // incomplete beta is good to ~1e-13: relative 1e-6 (plus 1e-12 absolute where I ≈ 0
            // and the c < 0 identity cancels).
            let err = (a - m).abs() / m.abs().max(1e-6);
            worst = worst.max(err);
            assert!(
                (a - m).abs() <= 1e-6 * m.abs() + 1e-12,
                "n = {n}, c = {c}: Arvo {a} vs Mallett-Yuksel {m}"
            );
        }
    }
    println!("Arvo vs Mallett-Yuksel: worst relative difference {worst:e}");
}

#[test]
fn phong_lobe_integral_at_normal_incidence() {
    use brdf::ndf::{phong_lobe_integral, phong_lobe_integral_arvo};
    for g in [0.0f32, 0.25, 1.0, 3.5, 20.0, 1e3, 1e6] {
        let expected = 2.0 * std::f64::consts::PI / (g as f64 + 2.0);
        let got = phong_lobe_integral(g, 1.0) as f64;
        // One f32 rounding of an f64 value: relative 6e-8, doubled for the Γ ratio.
        assert!((got / expected - 1.0).abs() < 2e-7, "γ = {g}");
        if g.fract() == 0.0 && g < 1e4 {
            let a = phong_lobe_integral_arvo(g as u32, 1.0) as f64;
            assert!((a / expected - 1.0).abs() < 2e-7, "Arvo n = {g}");
        }
    }
}
