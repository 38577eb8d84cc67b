//! The camera ray-differential helper (`RayDifferential`: offset rays intersected with the tangent
//! plane, then the least-squares solve for ∂uv/∂x, ∂uv/∂y) against a hand-computed sphere hit.
//!
//! A unit sphere at the origin, parametrised u = φ/2π (φ = atan2(z, x)), v = θ/π (θ = acos y),
//! seen from an eye e. The camera ray D(x, y) = d₀ + s (x r + y b) through pixel offsets (x, y)
//! (r, b ⟂ d₀, s the pixel's angle) hits the sphere at p = e + t D with |p|² = 1; differentiating
//! that, ∂t/∂x = −t (p · s r) / (p · d₀), so ∂p/∂x = ∂t/∂x d₀ + t s r, and ∂u/∂x = ∇u · ∂p/∂x with
//! ∇φ = (−z, 0, x)/(x² + z²), ∇θ = (0, −1/√(1 − y²), 0), all in f64 here, independently of the crate.
//!
//! The helper takes one finite step (the offset ray through the next pixel), so it matches the
//! derivative to first order: its relative error is the second-order term of the tangent-plane
//! intersection, about s · tan θᵢ (θᵢ the incidence angle), plus the f32 rounding of the offset
//! direction d₀ + s r, about 6·10⁻⁸ / s. At s = 10⁻³ and θᵢ ≈ 35° that is ~10⁻³: the tolerance is
//! 3·10⁻³ of the largest derivative, and the error halving with s (first-order convergence) is
//! checked too.

use brdf::glint::RayDifferential;
use brdf::{Vec2, Vec3};

type V = [f64; 3];

fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn mul(a: V, k: f64) -> V {
    [a[0] * k, a[1] * k, a[2] * k]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: V) -> V {
    mul(a, 1.0 / dot(a, a).sqrt())
}
fn f32v(a: V) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// The point of the unit sphere at (θ, φ).
fn sphere_point(theta: f64, phi: f64) -> V {
    [
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    ]
}

/// The hit, the camera and the analytic derivatives, all f64.
struct Setup {
    eye: V,
    d0: V,
    right: V,
    down: V,
    p: V,
    /// ∂p/∂x, ∂p/∂y per pixel of angle s.
    dp: [V; 2],
    /// (∂u/∂x, ∂v/∂x), (∂u/∂y, ∂v/∂y).
    duv: [[f64; 2]; 2],
    dpdu: V,
    dpdv: V,
    uv: [f64; 2],
}

fn setup(s: f64) -> Setup {
    let (theta, phi) = (1.1f64, 0.7f64);
    let p = sphere_point(theta, phi);
    // The eye 3 units out along a direction 35° off the normal: the ray meets the sphere at p first.
    let n = p;
    let side = unit(cross(n, [0.0, 1.0, 0.0]));
    let towards = add(
        mul(n, 35f64.to_radians().cos()),
        mul(side, 35f64.to_radians().sin()),
    );
    let eye = add(p, mul(towards, 3.0));
    let d0 = unit(sub(p, eye));
    let right = unit(cross(d0, [0.0, 1.0, 0.0]));
    let down = cross(d0, right);
    let t = dot(sub(p, eye), d0);
    let dp: [V; 2] = [right, down].map(|e| {
        let dt = -t * dot(p, mul(e, s)) / dot(p, d0);
        add(mul(d0, dt), mul(e, t * s))
    });
    let (x, y, z) = (p[0], p[1], p[2]);
    let grad_phi = [-z / (x * x + z * z), 0.0, x / (x * x + z * z)];
    let grad_theta = [0.0, -1.0 / (1.0 - y * y).sqrt(), 0.0];
    let two_pi = 2.0 * std::f64::consts::PI;
    let pi = std::f64::consts::PI;
    let duv = dp.map(|d| [dot(grad_phi, d) / two_pi, dot(grad_theta, d) / pi]);
    // ∂p/∂u = 2π ∂p/∂φ, ∂p/∂v = π ∂p/∂θ.
    let dpdu = mul(
        [-theta.sin() * phi.sin(), 0.0, theta.sin() * phi.cos()],
        two_pi,
    );
    let dpdv = mul(
        [
            theta.cos() * phi.cos(),
            -theta.sin(),
            theta.cos() * phi.sin(),
        ],
        pi,
    );
    Setup {
        eye,
        d0,
        right,
        down,
        p,
        dp,
        duv,
        dpdu,
        dpdv,
        uv: [phi / two_pi, theta / pi],
    }
}

fn ray(su: &Setup, s: f64) -> RayDifferential {
    RayDifferential {
        origin: f32v(su.eye),
        direction: f32v(su.d0),
        rx_origin: f32v(su.eye),
        rx_direction: f32v(add(su.d0, mul(su.right, s))),
        ry_origin: f32v(su.eye),
        ry_direction: f32v(add(su.d0, mul(su.down, s))),
    }
}

/// Largest error of the helper's ∂uv/∂x, ∂uv/∂y against the analytic ones, relative to the largest
/// analytic derivative.
fn duv_error(s: f64) -> f64 {
    let su = setup(s);
    let fp = ray(&su, s).footprint(
        Vec2::new(su.uv[0] as f32, su.uv[1] as f32),
        f32v(su.dpdu),
        f32v(su.dpdv),
        f32v(su.p),
        f32v(su.p),
    );
    let got = [fp.duv_dx(), fp.duv_dy()];
    let scale = su.duv.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for (g, e) in got.iter().zip(&su.duv) {
        worst = worst.max((g.x as f64 - e[0]).abs() / scale);
        worst = worst.max((g.y as f64 - e[1]).abs() / scale);
    }
    worst
}

#[test]
fn footprint_matches_the_analytic_sphere_derivatives() {
    let su = setup(1e-3);
    // The analytic values are not degenerate: all four derivatives matter.
    assert!(
        su.duv.iter().flatten().all(|v| v.abs() > 1e-6),
        "{:?}",
        su.duv
    );
    let e = duv_error(1e-3);
    assert!(e < 3e-3, "relative error {e:.2e}");
    // First-order convergence: half the step, about half the error (the second-order term
    // dominates the rounding at these steps).
    let e_half = duv_error(5e-4);
    println!("relative error of ∂uv/∂(x, y): {e:.2e} at s = 1e-3, {e_half:.2e} at s = 5e-4");
    assert!(
        e_half < 0.7 * e,
        "{e:.2e} at s = 1e-3, {e_half:.2e} at 5e-4"
    );
}

#[test]
fn surface_differentials_match_the_analytic_dp() {
    let s = 1e-3;
    let su = setup(s);
    let (dpdx, dpdy) = ray(&su, s).surface_differentials(f32v(su.p), f32v(su.p));
    for (got, want) in [dpdx, dpdy].iter().zip(&su.dp) {
        let scale = dot(*want, *want).sqrt();
        let err = sub([got.x as f64, got.y as f64, got.z as f64], *want);
        assert!(dot(err, err).sqrt() < 3e-3 * scale, "{got} vs {want:?}");
    }
    // Scaled by ½ (pbrt's ScaleDifferentials for 4 samples per pixel): half the derivatives, to the
    // same first-order tolerance.
    let (hx, _) = ray(&su, s)
        .scaled(0.5)
        .surface_differentials(f32v(su.p), f32v(su.p));
    let want = mul(su.dp[0], 0.5);
    let err = sub([hx.x as f64, hx.y as f64, hx.z as f64], want);
    assert!(dot(err, err).sqrt() < 3e-3 * dot(want, want).sqrt(), "{hx}");
}

/// An offset ray parallel to the tangent plane (a silhouette) gives a zero differential for that
/// offset, not NaN; the other offset is still used.
#[test]
fn an_offset_ray_parallel_to_the_plane_gives_zero() {
    let r = RayDifferential {
        origin: Vec3::new(0.0, 1.0, 0.0),
        direction: -Vec3::Y,
        rx_origin: Vec3::new(0.0, 1.0, 0.0),
        rx_direction: Vec3::X,
        ry_origin: Vec3::new(0.0, 1.0, 0.0),
        ry_direction: Vec3::new(0.0, -1.0, 1e-3),
    };
    let (dx, dy) = r.surface_differentials(Vec3::ZERO, Vec3::Y);
    assert_eq!(dx, Vec3::ZERO);
    assert!((dy - Vec3::new(0.0, 0.0, 1e-3)).length() < 1e-9, "{dy}");
}
