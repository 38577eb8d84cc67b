//! Warps: each sampler against its density (chi-square on 10⁶ draws), each density normalised
//! (deterministic quadrature), each density equal to the sampler's Jacobian (finite differences of the
//! map itself), and each inverse undoing its sampler on random inputs and random directions.
//!
//! Run: `cargo test --test it warp::` (about 10 s at opt-level 3 on 2 cores, mostly the chi-square tests).

use crate::support;

use brdf::frame::normal_to_slope;
use brdf::warp::*;
use glam::{Vec2, Vec3};
use rand::RngExt;
use std::f64::consts::PI;
use support::chi2::Chi2;
use support::quadrature::{gauss_legendre, integrate_band, integrate_hemisphere};

/// Cone apertures tested everywhere: narrow, half the hemisphere, reaching below the horizon.
const CONES: [f32; 3] = [0.95, 0.3, -0.5];

/// Standard deviation of the slope Gaussian in the chi-square test (σ = 0.5 keeps most normals well
/// above the horizon, so the z grid resolves the lobe).
const SIGMA: f32 = 0.5;

/// Number of chi-square tests in this file (Šidák family).
const FAMILY: usize = 7;

fn chi2(name: &str, z_min: Option<f64>) -> Chi2 {
    Chi2 {
        z_min,
        ..Chi2::new(name, FAMILY)
    }
}

fn check(result: Result<f64, String>) {
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn chi2_cosine_hemisphere() {
    check(chi2("warp/cosine", Some(0.0)).run(
        |_, u| Some(square_to_cosine_hemisphere(u)),
        |w| pdf_cosine_hemisphere(w) as f64,
    ));
}

#[test]
fn chi2_uniform_hemisphere() {
    check(chi2("warp/uniform", Some(0.0)).run(
        |_, u| Some(square_to_uniform_hemisphere(u)),
        |w| pdf_uniform_hemisphere(w) as f64,
    ));
}

#[test]
fn chi2_equal_area_hemisphere() {
    check(chi2("warp/equal-area", Some(0.0)).run(
        |_, u| Some(square_to_hemisphere_equal_area(u)),
        |w| pdf_hemisphere_equal_area(w) as f64,
    ));
}

#[test]
fn chi2_uniform_cones() {
    for c in CONES {
        // Grid the cone itself; for the wide cone the mass below the horizon is the overflow cell
        // (expected count N·(1 − mass above the horizon)).
        let z_min = (c as f64).max(0.0);
        check(chi2(&format!("warp/cone {c}"), Some(z_min)).run(
            |_, u| Some(square_to_uniform_cone(u, c)),
            |w| pdf_uniform_cone(w, c) as f64,
        ));
    }
}

/// The 2D Gaussian as a distribution of slopes: m = normalize(−σx, −σy, 1) has density
/// p_slope(s) / cos³θ_m per unit solid angle (dω = cos³θ ds), with p_slope(s) = p(s/σ)/σ².
#[test]
fn chi2_gaussian_as_slopes() {
    let s2 = (SIGMA * SIGMA) as f64;
    check(chi2("warp/gaussian slopes", None).run(
        |_, u| {
            Some(brdf::frame::slope_to_normal(
                SIGMA * square_to_gaussian_2d(u),
            ))
        },
        |m| match normal_to_slope(m) {
            Some(s) => pdf_gaussian_2d(s / SIGMA) as f64 / s2 / (m.z as f64).powi(3),
            None => 0.0,
        },
    ));
}

// Quadrature: support::quadrature's error estimate is the difference with a half-resolution rule; the
// densities are smooth on their supports, so the bound 4 × estimate + 1e-6 (f32 densities summed in
// f64) is safe. Cone bands end exactly at the cone's edge so the integrand is smooth on each band.
#[test]
fn direction_pdfs_integrate_to_one() {
    let cases: [(&str, &dyn Fn(Vec3) -> f64); 3] = [
        ("cosine", &|w| pdf_cosine_hemisphere(w) as f64),
        ("uniform", &|w| pdf_uniform_hemisphere(w) as f64),
        ("equal-area", &|w| pdf_hemisphere_equal_area(w) as f64),
    ];
    for (name, pdf) in cases {
        let (v, err) = integrate_hemisphere(pdf, 16, 32);
        assert!((v - 1.0).abs() < 4.0 * err + 1e-6, "{name}: {v} ± {err}");
    }
    for c in CONES {
        let pdf = |w: Vec3| pdf_uniform_cone(w, c) as f64;
        let theta_max = (c as f64).acos();
        let inside = integrate_band(&pdf, 0.0, theta_max, 16, 32);
        let coarse = integrate_band(&pdf, 0.0, theta_max, 8, 16);
        assert!(
            (inside - 1.0).abs() < 4.0 * (inside - coarse).abs() + 1e-6,
            "cone {c}: {inside}"
        );
        // Nothing outside the cone (nodes are interior to the band, so none sits on the edge).
        let outside = integrate_band(&pdf, theta_max, PI, 16, 32);
        assert_eq!(outside, 0.0, "cone {c}");
    }
}

/// ∫∫ pdf(r cos φ, r sin φ) r dr dφ with composite Gauss–Legendre in r and the trapezoid rule in φ.
fn integrate_polar(pdf: &dyn Fn(Vec2) -> f64, r_max: f64, panels: usize) -> f64 {
    let gl = gauss_legendre(8);
    let (n_phi, width) = (64, r_max / panels as f64);
    let mut total = 0.0;
    for p in 0..panels {
        for &(x, wx) in &gl {
            let r = (p as f64 + 0.5 * (x + 1.0)) * width;
            let ring: f64 = (0..n_phi)
                .map(|j| {
                    let phi = 2.0 * PI * (j as f64 + 0.5) / n_phi as f64;
                    pdf(Vec2::new((r * phi.cos()) as f32, (r * phi.sin()) as f32))
                })
                .sum();
            total += ring * 2.0 * PI / n_phi as f64 * r * wx * 0.5 * width;
        }
    }
    total
}

#[test]
fn planar_pdfs_integrate_to_one() {
    // Disk: the density is constant on [0, 1] in r (the rule is exact for r·const) — up to the f32
    // density and f32 points, 1e-6. The edge r = 1 is a panel end, never a node.
    let disk = integrate_polar(&|p| pdf_concentric_disk(p) as f64, 1.0, 4);
    assert!((disk - 1.0).abs() < 1e-6, "disk: {disk}");
    // Gaussian on r ∈ [0, 12] (tail mass exp(−72)); 8-point panels of width 0.5 integrate the smooth
    // radial profile to ~1e-12; f32 rounding of the density dominates: 1e-6.
    let gauss = integrate_polar(&|p| pdf_gaussian_2d(p) as f64, 12.0, 24);
    assert!((gauss - 1.0).abs() < 1e-6, "gaussian: {gauss}");
}

/// |det J| of a map R² → R² or R² → S² at u, by central differences in f64 of the f32 map.
fn jacobian_2d(f: &dyn Fn(Vec2) -> Vec2, u: Vec2, h: f32) -> f64 {
    let d = |du: Vec2| {
        let (p, m) = (f(u + du), f(u - du));
        [
            (p.x as f64 - m.x as f64) / (2.0 * h as f64),
            (p.y as f64 - m.y as f64) / (2.0 * h as f64),
        ]
    };
    let (a, b) = (d(Vec2::new(h, 0.0)), d(Vec2::new(0.0, h)));
    (a[0] * b[1] - a[1] * b[0]).abs()
}

fn jacobian_sphere(f: &dyn Fn(Vec2) -> Vec3, u: Vec2, h: f32) -> f64 {
    let d = |du: Vec2| {
        let (p, m) = (f(u + du).to_array(), f(u - du).to_array());
        [0, 1, 2].map(|k| (p[k] as f64 - m[k] as f64) / (2.0 * h as f64))
    };
    let (a, b) = (d(Vec2::new(h, 0.0)), d(Vec2::new(0.0, h)));
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

/// Points of a 30×30 grid in [0.05, 0.95]², skipping the concentric map's diagonals (where it is only
/// piecewise smooth) when `concentric` is set.
fn jacobian_points(concentric: bool, h: f32) -> Vec<Vec2> {
    let n = 30;
    let mut out = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new(
                0.05 + 0.9 * (i as f32 + 0.5) / n as f32,
                0.05 + 0.9 * (j as f32 + 0.5) / n as f32,
            );
            let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
            if concentric && (a.abs() - b.abs()).abs() < 4.0 * h {
                continue;
            }
            out.push(u);
        }
    }
    out
}

/// The density equals 1 / |Jacobian| of the sampler, pointwise: pdf(warp(u)) · |J(u)| = 1.
///
/// Tolerance: central differences with h = 1e-3 have truncation error O(h²) relative (≤ 1e-5 for these
/// smooth maps) and rounding error ~ ulp(1)/h ~ 1e-4 relative to each derivative (of size ≥ 0.1 here);
/// 2e-3 covers both with margin.
#[test]
fn pdf_is_the_inverse_jacobian() {
    let h = 1e-3f32;
    let tol = 2e-3;
    type DirectionCase<'a> = (
        &'a str,
        bool,
        &'a dyn Fn(Vec2) -> Vec3,
        &'a dyn Fn(Vec3) -> f32,
    );
    let directions: [DirectionCase; 6] = [
        (
            "cosine",
            true,
            &square_to_cosine_hemisphere,
            &pdf_cosine_hemisphere,
        ),
        (
            "uniform",
            false,
            &square_to_uniform_hemisphere,
            &pdf_uniform_hemisphere,
        ),
        (
            "equal-area",
            true,
            &square_to_hemisphere_equal_area,
            &pdf_hemisphere_equal_area,
        ),
        (
            "cone 0.95",
            false,
            &|u| square_to_uniform_cone(u, 0.95),
            &|w| pdf_uniform_cone(w, 0.95),
        ),
        (
            "cone 0.3",
            false,
            &|u| square_to_uniform_cone(u, 0.3),
            &|w| pdf_uniform_cone(w, 0.3),
        ),
        (
            "cone -0.5",
            false,
            &|u| square_to_uniform_cone(u, -0.5),
            &|w| pdf_uniform_cone(w, -0.5),
        ),
    ];
    for (name, concentric, warp, pdf) in directions {
        for u in jacobian_points(concentric, h) {
            let w = warp(u);
            if w.z < 0.02 && name == "cosine" {
                // The cosine density vanishes at the horizon; the product is 0·∞ there.
                continue;
            }
            let product = pdf(w) as f64 * jacobian_sphere(warp, u, h);
            assert!((product - 1.0).abs() < tol, "{name} at {u}: {product}");
        }
    }
    type PlanarCase<'a> = (
        &'a str,
        bool,
        &'a dyn Fn(Vec2) -> Vec2,
        &'a dyn Fn(Vec2) -> f32,
    );
    let planar: [PlanarCase; 2] = [
        (
            "disk",
            true,
            &square_to_concentric_disk,
            &pdf_concentric_disk,
        ),
        ("gaussian", false, &square_to_gaussian_2d, &pdf_gaussian_2d),
    ];
    for (name, concentric, warp, pdf) in planar {
        for u in jacobian_points(concentric, h) {
            let product = pdf(warp(u)) as f64 * jacobian_2d(warp, u, h);
            assert!((product - 1.0).abs() < tol, "{name} at {u}: {product}");
        }
    }
}

/// Round trips on random inputs: u → warp → inverse → u. Bounds as in the unit tests (src/warp.rs):
/// 8 ulp(1), with the azimuthal coordinate's error scaled by the radius (its conditioning is 1/r).
#[test]
fn random_round_trips() {
    let mut rng = support::rng(3);
    let tol = 8.0 * f32::EPSILON;
    let polar = |u: Vec2, back: Vec2, r: f32| {
        let dy = (back.y - u.y).abs();
        (back.x - u.x).abs().max(dy.min(1.0 - dy) * r)
    };
    for _ in 0..100_000 {
        let u = Vec2::new(rng.random(), rng.random());
        let e = (concentric_disk_to_square(square_to_concentric_disk(u)) - u).abs();
        assert!(e.max_element() <= tol, "disk {u}");
        let e = (cosine_hemisphere_to_square(square_to_cosine_hemisphere(u)) - u).abs();
        assert!(e.max_element() <= tol, "cosine {u}");
        let e = (hemisphere_to_square_equal_area(square_to_hemisphere_equal_area(u)) - u).abs();
        assert!(e.max_element() <= tol, "equal-area {u}");
        let w = square_to_uniform_hemisphere(u);
        let r = (w.x * w.x + w.y * w.y).sqrt();
        assert!(
            polar(u, uniform_hemisphere_to_square(w), r) <= tol,
            "uniform {u}"
        );
        for c in CONES {
            let w = square_to_uniform_cone(u, c);
            let r = (w.x * w.x + w.y * w.y).sqrt();
            assert!(
                polar(u, uniform_cone_to_square(w, c), r) <= tol,
                "cone {c} {u}"
            );
        }
        let p = square_to_gaussian_2d(u);
        let back = gaussian_2d_to_square(p);
        assert!(polar(u, back, p.length().min(1.0)) <= tol, "gaussian {u}");
    }
}

/// The other way round, on directions the samplers did not produce: ω → inverse → warp → ω.
/// Uniform random directions from an independent generator (normalised Gaussian triples, f64).
#[test]
fn inverse_then_warp_returns_the_direction() {
    let mut rng = support::rng(5);
    let mut normal = || {
        // Box–Muller in f64, written here.
        let (a, b): (f64, f64) = (rng.random(), rng.random());
        (-2.0 * (1.0 - a).ln()).sqrt() * (2.0 * PI * b).cos()
    };
    // Inverse then forward: the direction error is the u error (≤ 8 ulp) times the map's stretch
    // (≤ 5.1 for the equal-area map, see its continuity test) plus the normalisation: 64 ulp(1) = 7.6e-6.
    let tol = 64.0 * f32::EPSILON;
    // The other maps compute one coordinate as √x of a quantity x that the rounding of u (≤ 2⁻²⁴)
    // knows only to ~2⁻²² absolute: z = √((1 − r)(1 + r)) for the cosine map near the horizon,
    // sin θ = √((1 − z)(1 + z)) for the cylinder maps near the poles. That coordinate is then off by
    // ≤ 2⁻²² / (2√x); we allow four times that.
    let ill = |x: f32| 2f32.powi(-21) / x.max(1e-6);
    let mut done = 0;
    while done < 100_000 {
        let v = [normal(), normal(), normal()];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if n < 1e-3 {
            continue;
        }
        let w = Vec3::new(
            (v[0] / n) as f32,
            (v[1] / n) as f32,
            (v[2] / n).abs() as f32,
        );
        done += 1;
        let sin_theta = (w.x * w.x + w.y * w.y).sqrt();
        let back = square_to_hemisphere_equal_area(hemisphere_to_square_equal_area(w));
        assert!((back - w).length() < tol, "equal-area {w}: {back}");
        let back = square_to_cosine_hemisphere(cosine_hemisphere_to_square(w));
        assert!((back - w).length() < tol + ill(w.z), "cosine {w}: {back}");
        let back = square_to_uniform_hemisphere(uniform_hemisphere_to_square(w));
        assert!(
            (back - w).length() < tol + ill(sin_theta),
            "uniform {w}: {back}"
        );
        let full = Vec3::new(w.x, w.y, (v[2] / n) as f32);
        let back = square_to_uniform_cone(uniform_cone_to_square(full, -1.0), -1.0);
        assert!(
            (back - full).length() < tol + ill(sin_theta),
            "sphere cone {full}: {back}"
        );
        let p = Vec2::new(v[0] as f32, v[1] as f32);
        let back = square_to_gaussian_2d(gaussian_2d_to_square(p));
        // Relative to the radius (unbounded, here < 6), plus the quantisation of u.x near 1: u.x is
        // rounded to ≤ 2⁻²⁴ absolute, s = 1 − u.x = exp(−r²/2) then carries a relative error
        // 2⁻²⁴/s, and r = √(−2 ln s) moves by that over r (dr = −ds/(s r)). Twice that, for margin.
        let r = p.length() as f64;
        let quantisation = 2.0 * 2f64.powi(-24) * (0.5 * r * r).exp() / r.max(1e-3);
        assert!(
            ((back - p).length() as f64) < (tol * p.length().max(1.0)) as f64 + quantisation,
            "gaussian {p}: {back}"
        );
    }
}

/// The equal-area map's bins: an n×n grid of the square gives n² hemisphere regions of solid angle
/// 2π/n² each. Each cell's solid angle is measured independently of the map's Jacobian, by the line
/// integral Ω = ∮ (1 − cos θ) dφ along the image of the cell's boundary (Stokes: the area element
/// sin θ dθ dφ is d((1 − cos θ) dφ); valid also for cells touching the pole, where 1 − cos θ = 0).
#[test]
fn equal_area_bins_have_equal_solid_angle() {
    let n = 16;
    let segments = 2048; // per side of a cell
    let expected = 2.0 * PI / (n * n) as f64;
    let mut worst = 0.0f64;
    let mut total = 0.0;
    for i in 0..n {
        for j in 0..n {
            // Counter-clockwise corners of the cell in u (the map preserves orientation).
            let c = |a: usize, b: usize| Vec2::new(a as f32 / n as f32, b as f32 / n as f32);
            let corners = [c(i, j), c(i + 1, j), c(i + 1, j + 1), c(i, j + 1), c(i, j)];
            let mut omega = 0.0f64;
            for side in corners.windows(2) {
                let at = |t: f64| {
                    let u = side[0] + (side[1] - side[0]) * t as f32;
                    let w = square_to_hemisphere_equal_area(u);
                    ((w.y as f64).atan2(w.x as f64), w.z as f64)
                };
                let mut prev = at(0.0);
                for s in 1..=segments {
                    let next = at(s as f64 / segments as f64);
                    let mut dphi = next.0 - prev.0;
                    if dphi > PI {
                        dphi -= 2.0 * PI;
                    } else if dphi < -PI {
                        dphi += 2.0 * PI;
                    }
                    // Trapezoid rule in 1 − z along the segment.
                    omega += (1.0 - 0.5 * (prev.1 + next.1)) * dphi;
                    prev = next;
                }
            }
            total += omega;
            worst = worst.max((omega / expected - 1.0).abs());
            // Trapezoid error O((stretch / (n · segments))²) ≈ 2e-8 relative on each smooth piece of
            // the boundary; z and φ carry f32 rounding (~1e-7 relative, averaging out along the
            // boundary). Measured worst cell: see the message; bound 1e-5 relative, while a cell
            // larger or smaller by one part in 10⁵ would fail.
            assert!(
                (omega / expected - 1.0).abs() < 1e-5,
                "cell ({i}, {j}): {omega} sr vs {expected} sr"
            );
        }
    }
    println!("equal-area cells: worst relative deviation {worst:e}");
    // The cells tile the hemisphere.
    assert!((total - 2.0 * PI).abs() < 1e-5 * 2.0 * PI, "{total}");
}
