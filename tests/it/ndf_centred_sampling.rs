//! Chi-square tests of every sampler of the centred analytic NDFs (Beckmann, GGX, Blinn-Phong): the
//! visible-normal samplers at three view angles (five in the ignored `_every_view` tests) and the
//! D cos samplers, each binned through a chart that maps the lobe onto the harness's grid.
//!
//! Run: `cargo test --test it ndf_centred_sampling::`.

// `!(x > 0)` is the intended NaN-rejecting comparison (here and in the shared harness).
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use crate::support;

use glam::Vec3;
use rayon::prelude::*;
use support::chi2::Chi2;
use support::ndf_centred::{
    Case, PHI_ANISO, THETAS, all_cases, blinn_phong_cases, microfacet_cases,
};

/// Number of chi-square tests in this file, i.e. the Šidák family:
/// visible: (Beckmann + GGX) × 4 α × (iso, aniso) × 5 θ + Blinn-Phong × 4 α × 5 θ = 100;
/// D cos: (Beckmann + GGX) × 4 α × (iso, aniso) + Blinn-Phong × 4 α = 20.
const FAMILY: usize = 120;

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

/// The views of the default suite's visible-normal tests: normal incidence, oblique and grazing;
/// the `_every_view` tests add 30° and 80° (`THETAS`). Each test keeps the significance of the
/// whole family (`FAMILY`).
const DEFAULT_THETAS: [f64; 3] = [0.0, 60.0, 89.0];

fn chi2_visible_at(cases: &[Case], thetas: &[f64]) {
    let jobs: Vec<(&Case, f64)> = cases
        .iter()
        .flat_map(|c| thetas.iter().map(move |&t| (c, t)))
        .collect();
    report(jobs.par_iter().map(|&(c, t)| chi2_visible(c, t)).collect());
}

#[test]
fn chi2_visible_microfacet() {
    chi2_visible_at(&microfacet_cases(), &DEFAULT_THETAS);
}

/// `cargo test --release --test it -- --ignored ndf_centred_sampling::chi2_visible_microfacet_every_view`
#[test]
#[ignore]
fn chi2_visible_microfacet_every_view() {
    chi2_visible_at(&microfacet_cases(), &THETAS);
}

#[test]
fn chi2_visible_blinn_phong() {
    chi2_visible_at(&blinn_phong_cases(), &DEFAULT_THETAS);
}

/// `cargo test --release --test it -- --ignored ndf_centred_sampling::chi2_visible_blinn_phong_every_view`
#[test]
#[ignore]
fn chi2_visible_blinn_phong_every_view() {
    chi2_visible_at(&blinn_phong_cases(), &THETAS);
}

#[test]
fn chi2_normal_all() {
    let cases = all_cases();
    report(cases.par_iter().map(chi2_normal).collect());
}
