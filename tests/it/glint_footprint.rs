//! Footprints from ray differentials: unclamped views are the differentials, the helpers have the
//! requested area and orientation, the clamps (width, anisotropy, extent), degenerate differentials
//! fall back to the minimal footprint, and the checked constructors refuse non-finite input (and
//! give the unchecked ones' footprint, bit for bit, for finite input).
//!
//! Expected values come from plane geometry and closed-form areas written here.

use crate::support;

use brdf::glint::{
    Footprint, MAX_ANISOTROPY, MAX_EXTENT_PERIODS, MIN_WIDTH_TEXELS, RayCone, RayDifferential,
};
use brdf::{Error, Vec2, Vec3};
use rand::RngExt;

/// (aaᵀ + bbᵀ)/12 in f64, the covariance of a uniform point of the parallelogram (each of the
/// independent coordinates s, t ~ U[−½, ½] has variance 1/12).
fn cov_of(a: Vec2, b: Vec2) -> [f64; 3] {
    let (ax, ay, bx, by) = (a.x as f64, a.y as f64, b.x as f64, b.y as f64);
    [
        (ax * ax + bx * bx) / 12.0,
        (ax * ay + bx * by) / 12.0,
        (ay * ay + by * by) / 12.0,
    ]
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-30)
}

#[test]
fn unclamped_views_are_the_differentials() {
    let (w, h) = (300usize, 120usize);
    let mut rng = support::rng(40);
    for _ in 0..200 {
        let uv = Vec2::new(rng.random_range(0.0..1.0f32), rng.random_range(0.0..1.0f32));
        // Edges of 0.5–20 texels at random angles, aspect well below 32.
        let ang = rng.random_range(0.0..6.3f32);
        let len_a = rng.random_range(2.0..20.0f32);
        let len_b = rng.random_range(0.5..1.0f32) * len_a;
        let skew = rng.random_range(0.6..1.5f32);
        let ea = Vec2::new(ang.cos(), ang.sin()) * len_a;
        let eb = Vec2::new(-(ang + skew).sin(), (ang + skew).cos()) * len_b;
        let size = Vec2::new(w as f32, h as f32);
        let f = Footprint::from_differentials(uv, ea / size, eb / size);
        let (c, a, b) = f.parallelogram_texels(w, h);
        // Only f32 rounding of the uv ↔ texel scaling: 1e-5 relative.
        assert!((c - uv * size).length() < 1e-4);
        assert!((a - ea).length() < 1e-5 * len_a && (b - eb).length() < 1e-5 * len_a);
        let det = (ea.x as f64 * eb.y as f64 - ea.y as f64 * eb.x as f64).abs();
        assert!(
            close(f.area_texels(w, h) as f64, det, 1e-5),
            "{} vs {det}",
            f.area_texels(w, h)
        );
        let (gc, cov) = f.gaussian_texels(w, h);
        assert_eq!(gc, c);
        let want = cov_of(ea, eb);
        let scale = want[0].max(want[2]);
        for (got, want) in [
            (cov.col(0).x, want[0]),
            (cov.col(1).x, want[1]),
            (cov.col(1).y, want[2]),
        ] {
            assert!((got as f64 - want).abs() < 1e-5 * scale);
        }
        // Same area in both views: |det[a b]| = 12 √det Σ.
        let det_cov = want[0] * want[2] - want[1] * want[1];
        assert!(close(12.0 * det_cov.sqrt(), det, 1e-9));
        // uv views are the texel views scaled by 1/size.
        let (cu, au, bu) = f.parallelogram_uv(w, h);
        assert_eq!(cu, f.center_uv());
        assert!((au * size - a).length() < 1e-4 && (bu * size - b).length() < 1e-4);
        let (_, cov_uv) = f.gaussian_uv(w, h);
        assert!((cov_uv.col(0).x as f64 * (w * w) as f64 - want[0]).abs() < 1e-5 * scale);
        assert!((cov_uv.col(1).x as f64 * (w * h) as f64 - want[1]).abs() < 1e-5 * scale);
    }
}

#[test]
fn helpers_have_the_requested_area_and_orientation() {
    let (w, h) = (512usize, 256usize);
    for n in [1.0f32, 16.0, 256.0, 4096.0] {
        let f = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), n, w, h);
        // f32 sqrt and products: 1e-5 relative.
        assert!(close(f.area_texels(w, h) as f64, n as f64, 1e-5));
        let (_, cov) = f.gaussian_texels(w, h);
        // A square of side s has Σ = s²/12 I.
        assert!(close(cov.col(0).x as f64, n as f64 / 12.0, 1e-5));
        assert!(close(cov.col(1).y as f64, n as f64 / 12.0, 1e-5));
        assert!(cov.col(1).x.abs() < 1e-6 * n);
    }
    for (aspect, angle) in [(4.0f32, 0.3f32), (10.0, 2.0), (1.5, -1.0)] {
        let area = 100.0;
        let f = Footprint::anisotropic_texels(Vec2::new(0.5, 0.5), area, aspect, angle, w, h);
        assert!(close(f.area_texels(w, h) as f64, area as f64, 1e-5));
        let (major, minor) = f.widths_texels(w, h);
        assert!(close((major / minor) as f64, aspect as f64, 1e-5));
        // The major axis points along `angle`: Σ d = λ1 d with λ1 = major²/12.
        let (_, cov) = f.gaussian_texels(w, h);
        let d = Vec2::new(angle.cos(), angle.sin());
        let sd = cov * d;
        let l1 = major * major / 12.0;
        assert!((sd - d * l1).length() < 1e-4 * l1, "{sd} vs {}", d * l1);
    }
}

#[test]
fn clamps() {
    let (w, h) = (64usize, 32usize);
    // Anisotropy: a 1000:1 needle keeps its major width and gets minor = major / 32.
    let f = Footprint::anisotropic_texels(Vec2::new(0.5, 0.5), 4.0, 1000.0, 0.7, w, h);
    let (major, minor) = f.widths_texels(w, h);
    let want_major = (4.0f32 * 1000.0).sqrt();
    assert!(close(major as f64, want_major as f64, 1e-5));
    assert!(close(
        minor as f64,
        (want_major / MAX_ANISOTROPY) as f64,
        1e-5
    ));
    // The clamped parallelogram still has the clamped Gaussian's covariance and area.
    let (_, a, b) = f.parallelogram_texels(w, h);
    let (_, cov) = f.gaussian_texels(w, h);
    let pc = cov_of(a, b);
    let s = pc[0].max(pc[2]);
    assert!((pc[0] - cov.col(0).x as f64).abs() < 1e-5 * s);
    assert!((pc[1] - cov.col(1).x as f64).abs() < 1e-5 * s);
    assert!((pc[2] - cov.col(1).y as f64).abs() < 1e-5 * s);
    let det = (a.x * b.y - a.y * b.x).abs() as f64;
    assert!(close(det, (major * minor) as f64, 1e-4));
    // Its major axis kept its direction.
    let d = Vec2::new(0.7f32.cos(), 0.7f32.sin());
    assert!(((cov * d) - d * major * major / 12.0).length() < 1e-3 * major * major / 12.0);

    // Minimum extent: a point-like footprint becomes a 0.01-texel square.
    let f = Footprint::isotropic_texels(Vec2::new(0.1, 0.2), 1e-12, w, h);
    let (major, minor) = f.widths_texels(w, h);
    assert!(
        close(major as f64, MIN_WIDTH_TEXELS as f64, 1e-6)
            && close(minor as f64, MIN_WIDTH_TEXELS as f64, 1e-6)
    );
    assert!(close(f.area_texels(w, h) as f64, 1e-4, 1e-5));

    // Maximum extent: 2 × max(w, h) texels along every axis.
    let f = Footprint::from_differentials(Vec2::ZERO, Vec2::new(1e6, 0.0), Vec2::new(0.0, 3e5));
    let (major, minor) = f.widths_texels(w, h);
    let max = MAX_EXTENT_PERIODS * 64.0;
    assert!(close(major as f64, max as f64, 1e-6) && close(minor as f64, max as f64, 1e-6));
}

#[test]
fn degenerate_differentials_fall_back_to_the_minimal_footprint() {
    let (w, h) = (16usize, 16usize);
    let bad = [
        (Vec2::new(f32::NAN, 0.0), Vec2::new(0.0, 0.1)),
        (Vec2::new(0.1, 0.0), Vec2::new(f32::INFINITY, 0.1)),
        (Vec2::ZERO, Vec2::ZERO),
    ];
    for (dx, dy) in bad {
        for uv in [
            Vec2::new(0.5, 0.5),
            Vec2::new(f32::NAN, 0.2),
            Vec2::new(-3.25, 7.5),
        ] {
            let f = Footprint::from_differentials(uv, dx, dy);
            let c = f.center_uv();
            assert!(c.is_finite() && c.cmpge(Vec2::ZERO).all() && c.cmplt(Vec2::ONE).all());
            let (major, minor) = f.widths_texels(w, h);
            assert!(
                close(major as f64, MIN_WIDTH_TEXELS as f64, 1e-6),
                "{major}"
            );
            assert!(
                close(minor as f64, MIN_WIDTH_TEXELS as f64, 1e-6),
                "{minor}"
            );
            let (gc, cov) = f.gaussian_texels(w, h);
            let (pc, a, b) = f.parallelogram_texels(w, h);
            assert!(gc.is_finite() && pc.is_finite() && a.is_finite() && b.is_finite());
            assert!(cov.determinant() > 0.0 && cov.is_finite());
        }
    }
    // Collinear edges: the minor axis is widened by the anisotropy clamp, not NaN.
    let f = Footprint::from_differentials(
        Vec2::new(0.5, 0.5),
        Vec2::new(0.1, 0.1),
        Vec2::new(0.2, 0.2),
    );
    let (major, minor) = f.widths_texels(w, h);
    assert!(close((major / minor) as f64, MAX_ANISOTROPY as f64, 1e-5));
    // uv wraps into [0, 1).
    let f = Footprint::from_differentials(Vec2::new(-3.25, 7.5), Vec2::ZERO, Vec2::ZERO);
    assert_eq!(f.center_uv(), Vec2::new(0.75, 0.5));
}

/// The footprint's fields as bits (the same footprint, bit for bit).
fn bits(f: &Footprint) -> [u32; 6] {
    let v = [f.center_uv(), f.duv_dx(), f.duv_dy()];
    std::array::from_fn(|i| v[i / 2][i % 2].to_bits())
}

/// Whether `r` is the refusal of the argument `name`.
fn refuses(r: brdf::Result<Footprint>, name: &str) -> bool {
    matches!(r, Err(Error::InvalidFootprint { name: n, .. }) if n == name)
}

const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// `v` with component `c` replaced by `x`.
fn with2(v: Vec2, c: usize, x: f32) -> Vec2 {
    let mut a = v.to_array();
    a[c] = x;
    Vec2::from_array(a)
}

fn with3(v: Vec3, c: usize, x: f32) -> Vec3 {
    let mut a = v.to_array();
    a[c] = x;
    Vec3::from_array(a)
}

#[test]
fn checked_constructors_refuse_non_finite_differentials() {
    let (uv, dx, dy) = (
        Vec2::new(0.3, 0.7),
        Vec2::new(0.01, 0.002),
        Vec2::new(-0.003, 0.02),
    );
    for x in NON_FINITE {
        for c in 0..2 {
            let r = |uv, dx, dy| Footprint::try_from_differentials(uv, dx, dy);
            assert!(refuses(r(with2(uv, c, x), dx, dy), "uv"));
            assert!(refuses(r(uv, with2(dx, c, x), dy), "duv_dx"));
            assert!(refuses(r(uv, dx, with2(dy, c, x)), "duv_dy"));
        }
    }
    let (dpdu, dpdv, dpdx, dpdy) = (
        Vec3::new(2.0, 0.1, 0.0),
        Vec3::new(0.0, 1.5, 0.3),
        Vec3::new(0.01, 0.0, 0.002),
        Vec3::new(0.0, 0.02, -0.001),
    );
    let r = |uv, pu, pv, px, py| Footprint::try_from_surface_differentials(uv, pu, pv, px, py);
    for x in NON_FINITE {
        for c in 0..3 {
            assert!(refuses(
                r(with2(uv, c % 2, x), dpdu, dpdv, dpdx, dpdy),
                "uv"
            ));
            assert!(refuses(r(uv, with3(dpdu, c, x), dpdv, dpdx, dpdy), "dpdu"));
            assert!(refuses(r(uv, dpdu, with3(dpdv, c, x), dpdx, dpdy), "dpdv"));
            assert!(refuses(r(uv, dpdu, dpdv, with3(dpdx, c, x), dpdy), "dpdx"));
            assert!(refuses(r(uv, dpdu, dpdv, dpdx, with3(dpdy, c, x)), "dpdy"));
        }
    }
    // The message names the argument and its value.
    let e = Footprint::try_from_differentials(uv, dx, Vec2::new(f32::NAN, 0.0)).unwrap_err();
    assert!(
        e.to_string().contains("duv_dy") && e.to_string().contains("NaN"),
        "{e}"
    );
}

#[test]
fn checked_constructors_give_the_same_footprint_for_finite_input() {
    let mut rng = support::rng(41);
    let mut v3 = || {
        Vec3::new(
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
        )
    };
    for _ in 0..200 {
        let (a, b, c, d, e) = (v3(), v3(), v3(), v3(), v3());
        let uv = Vec2::new(a.x * 3.0, a.y * 3.0);
        let (dx, dy) = (b.truncate() * 0.01, c.truncate() * 0.01);
        assert_eq!(
            bits(&Footprint::try_from_differentials(uv, dx, dy).unwrap()),
            bits(&Footprint::from_differentials(uv, dx, dy))
        );
        let (pu, pv, px, py) = (b, c, d * 0.01, e * 0.01);
        assert_eq!(
            bits(&Footprint::try_from_surface_differentials(uv, pu, pv, px, py).unwrap()),
            bits(&Footprint::from_surface_differentials(uv, pu, pv, px, py))
        );
        let cone = RayCone::new(0.01, 0.002);
        let (dir, n) = (d, e);
        assert_eq!(
            bits(&cone.try_footprint(uv, pu, pv, dir, n).unwrap()),
            bits(&cone.footprint(uv, pu, pv, dir, n))
        );
        let ray = RayDifferential {
            origin: a,
            direction: dir,
            rx_origin: a,
            rx_direction: dir + Vec3::X * 1e-3,
            ry_origin: a,
            ry_direction: dir + Vec3::Y * 1e-3,
        };
        let p = a + dir * 2.0;
        assert_eq!(
            bits(&ray.try_footprint(uv, pu, pv, p, n).unwrap()),
            bits(&ray.footprint(uv, pu, pv, p, n))
        );
    }
}

/// One offset-ray field of a `RayDifferential`.
type Field = fn(&mut RayDifferential) -> &mut Vec3;

/// The ray cone's and the ray differential's checked footprints refuse every non-finite argument
/// (and a zero direction or normal); the unchecked ones fall back to the minimal footprint.
#[test]
fn ray_footprints_refuse_non_finite_input() {
    let (uv, pu, pv) = (Vec2::new(0.3, 0.7), Vec3::X * 2.0, Vec3::Z * 1.5);
    let (dir, n, p) = (Vec3::new(0.2, -1.0, 0.1), Vec3::Y, Vec3::new(0.1, 0.0, 0.2));
    let cone = RayCone::new(0.01, 0.001);
    let ray = RayDifferential {
        origin: Vec3::new(0.0, 2.0, 0.0),
        direction: dir,
        rx_origin: Vec3::new(0.0, 2.0, 0.0),
        rx_direction: dir + Vec3::X * 1e-3,
        ry_origin: Vec3::new(0.0, 2.0, 0.0),
        ry_direction: dir + Vec3::Z * 1e-3,
    };
    assert!(cone.try_footprint(uv, pu, pv, dir, n).is_ok());
    assert!(ray.try_footprint(uv, pu, pv, p, n).is_ok());
    for x in NON_FINITE {
        for c in 0..3 {
            let cf = |uv, pu, pv, dir, n| cone.try_footprint(uv, pu, pv, dir, n);
            assert!(refuses(cf(with2(uv, c % 2, x), pu, pv, dir, n), "uv"));
            assert!(refuses(cf(uv, with3(pu, c, x), pv, dir, n), "dpdu"));
            assert!(refuses(cf(uv, pu, with3(pv, c, x), dir, n), "dpdv"));
            assert!(refuses(cf(uv, pu, pv, with3(dir, c, x), n), "dir"));
            assert!(refuses(cf(uv, pu, pv, dir, with3(n, c, x)), "n"));
            let rf = |ray: RayDifferential, uv, pu, pv, p, n| ray.try_footprint(uv, pu, pv, p, n);
            assert!(refuses(rf(ray, with2(uv, c % 2, x), pu, pv, p, n), "uv"));
            assert!(refuses(rf(ray, uv, with3(pu, c, x), pv, p, n), "dpdu"));
            assert!(refuses(rf(ray, uv, pu, with3(pv, c, x), p, n), "dpdv"));
            assert!(refuses(rf(ray, uv, pu, pv, with3(p, c, x), n), "p"));
            assert!(refuses(rf(ray, uv, pu, pv, p, with3(n, c, x)), "n"));
            let fields: [(&str, Field); 4] = [
                ("rx_origin", |r| &mut r.rx_origin),
                ("rx_direction", |r| &mut r.rx_direction),
                ("ry_origin", |r| &mut r.ry_origin),
                ("ry_direction", |r| &mut r.ry_direction),
            ];
            for (name, field) in fields {
                let mut bad = ray;
                let v = field(&mut bad);
                *v = with3(*v, c, x);
                assert!(refuses(rf(bad, uv, pu, pv, p, n), name), "{name}");
                // The unchecked form falls back: finite, and no wider than the other offset's.
                let f = bad.footprint(uv, pu, pv, p, n);
                assert!(f.duv_dx().is_finite() && f.duv_dy().is_finite(), "{name}");
            }
        }
    }
    assert!(refuses(
        cone.try_footprint(uv, pu, pv, Vec3::ZERO, n),
        "dir"
    ));
    assert!(refuses(
        cone.try_footprint(uv, pu, pv, dir, Vec3::ZERO),
        "n"
    ));
    assert!(refuses(ray.try_footprint(uv, pu, pv, p, Vec3::ZERO), "n"));
    // The unchecked cone footprint of a NaN direction is the minimal one.
    let f = cone.footprint(uv, pu, pv, Vec3::NAN, n);
    let (major, minor) = f.widths_texels(64, 64);
    assert_eq!((major, minor), (MIN_WIDTH_TEXELS, MIN_WIDTH_TEXELS));
}

/// A finite solution beyond the f32 range (∂p/∂u tiny against ∂p/∂x) is a footprint at the maximum
/// extent, not the minimal one a non-finite value would fall back to.
#[test]
fn an_overflowing_solution_is_the_widest_footprint() {
    let (w, h) = (64usize, 64usize);
    let f = Footprint::from_surface_differentials(
        Vec2::new(0.5, 0.5),
        Vec3::X * 1e-30,
        Vec3::Y * 1e-30,
        Vec3::X * 1e10,
        Vec3::Y * 1e10,
    );
    assert!(f.duv_dx().is_finite() && f.duv_dy().is_finite());
    let (major, minor) = f.widths_texels(w, h);
    let max = MAX_EXTENT_PERIODS * w as f32;
    assert!(close(major as f64, max as f64, 1e-6), "{major}");
    assert!(close(minor as f64, max as f64, 1e-6), "{minor}");
}
