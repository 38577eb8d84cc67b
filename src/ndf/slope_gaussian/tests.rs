//! Unit tests of `SlopeGaussian` (src/ndf/slope_gaussian.rs).

use super::*;

fn lobe(mx: f32, my: f32, sx: f32, sy: f32, rho: f32) -> SlopeGaussian {
    let c = rho * sx * sy;
    SlopeGaussian::new(
        Vec2::new(mx, my),
        Mat2::from_cols_array(&[sx * sx, c, c, sy * sy]),
    )
    .unwrap()
}

#[test]
fn size_is_32_bytes() {
    assert_eq!(std::mem::size_of::<SlopeGaussian>(), 32);
}

#[test]
fn accessors_round_trip() {
    let g = lobe(0.3, -0.2, 0.2, 0.05, 0.7);
    let cov = g.covariance();
    // f32 storage of L: entries agree to a few ulp of the largest (~1e-7 relative).
    assert!((cov.x_axis.x - 0.04).abs() < 1e-8);
    assert!((cov.y_axis.y - 0.0025).abs() < 1e-9);
    assert!((cov.x_axis.y - 0.7 * 0.2 * 0.05).abs() < 1e-8);
    assert_eq!(cov.x_axis.y, cov.y_axis.x);
    let l = g.cholesky();
    let back = l * l.transpose();
    assert!((back - cov).abs_diff_eq(Mat2::ZERO, 1e-8));
    assert_eq!(g.mean(), Vec2::new(0.3, -0.2));
    let n = g.mean_normal();
    let expected = Vec3::new(-0.3, 0.2, 1.0).normalize();
    assert!((n - expected).length() < 1e-7);
}

#[test]
fn p22_is_the_bivariate_normal() {
    // Independent f64 formula with Σ⁻¹ from the adjugate.
    let (mx, my, sx, sy, rho) = (0.3f64, -0.2, 0.2, 0.05, -0.6);
    let g = lobe(mx as f32, my as f32, sx as f32, sy as f32, rho as f32);
    for &(x, y) in &[(0.3, -0.2), (0.5, -0.1), (0.1, -0.3), (0.0, 0.0)] {
        let (dx, dy) = (x - mx, y - my);
        let q = (dx * dx / (sx * sx) - 2.0 * rho * dx * dy / (sx * sy) + dy * dy / (sy * sy))
            / (1.0 - rho * rho);
        let p = (-0.5 * q).exp() / (2.0 * PI * sx * sy * (1.0 - rho * rho).sqrt());
        let got = g.p22(Vec2::new(x as f32, y as f32)) as f64;
        // f32 exp of an argument up to ~30: relative error ≤ ~30 × 2⁻²³ ≈ 4e-6, plus storage.
        assert!(
            (got - p).abs() <= 1e-5 * p + 1e-30,
            "({x}, {y}): {got} vs {p}"
        );
    }
    assert_eq!(g.p22(Vec2::new(f32::NAN, 0.0)), 0.0);
    assert_eq!(g.p22(Vec2::new(f32::INFINITY, 0.0)), 0.0);
}

#[test]
fn masking_identities_hold() {
    let g = lobe(0.4, 0.1, 0.3, 0.2, 0.5);
    for &(x, y, z) in &[
        (0.0f32, 0.0f32, 1.0f32),
        (0.5, 0.1, 0.8),
        (-0.9, 0.2, 0.3),
        (0.9, 0.3, 0.1),
    ] {
        let w = Vec3::new(x, y, z).normalize();
        let parts = g.visible_area_parts(w);
        let a = g.projected_area(w);
        let v = g.visible_area(w);
        assert_eq!(parts.visible_area, v);
        assert_eq!(parts.signed_area.max(0.0), a);
        assert!(v >= a && v > 0.0);
        let l = g.lambda(w);
        if a > 0.0 {
            // V = A (1 + Λ) to f32 rounding of the three values.
            assert!((a * (1.0 + l) - v).abs() <= 4e-7 * v, "{a} {l} {v}");
        } else {
            assert_eq!(l, f32::MAX);
        }
    }
    assert_eq!(g.lambda(Vec3::Z), 0.0);
    assert_eq!(g.visible_area(Vec3::Z), 1.0);
}

#[test]
fn invalid_directions_give_zero() {
    let g = lobe(0.4, 0.1, 0.3, 0.2, 0.5);
    for w in [
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::ZERO,
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 1.0),
    ] {
        assert_eq!(g.d(w), 0.0);
        assert_eq!(g.lambda(w), 0.0);
        assert_eq!(g.projected_area(w), 0.0);
        assert_eq!(g.visible_area(w), 0.0);
        assert_eq!(g.signed_projected_area(w), 0.0);
        assert_eq!(g.pdf_visible(w, Vec3::Z), 0.0);
        assert_eq!(g.pdf_visible(Vec3::Z, w), 0.0);
        assert_eq!(g.g1(w, Vec3::Z), 0.0);
        let m = g.sample_visible(w, Vec2::new(0.3, 0.6));
        assert!(m.z > 0.0 && (m.length() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn from_moments_floors_and_clamps() {
    // A constant slope (0.2, −0.1): variances 0, so σ = σ_min on both axes, c = 0.
    let (x, y) = (0.2f32, -0.1f32);
    let g = SlopeGaussian::from_moments([x, y, x * x, y * y, x * y], 0.01);
    let cov = g.covariance();
    assert_eq!(g.mean(), Vec2::new(x, y));
    // f32 rounding of E[x̃]² vs E[x̃²] leaves |var| ≲ 1e-8 < σ_min² = 1e-4: the floor wins.
    assert!((cov.x_axis.x - 1e-4).abs() < 1e-10 && (cov.y_axis.y - 1e-4).abs() < 1e-10);
    assert!(cov.x_axis.y.abs() < 1e-10);

    // Perfect correlation along the diagonal: var = 0.05 on both axes, c = 0.05 (ρ = 1).
    let g = SlopeGaussian::from_moments([0.0, 0.0, 0.05, 0.05, 0.05], 0.01);
    let cov = g.covariance();
    let (sxx, sxy, syy) = (
        cov.x_axis.x as f64,
        cov.x_axis.y as f64,
        cov.y_axis.y as f64,
    );
    // c clamped to √((σx² − σ²)(σy² − σ²)) = 0.05 − 1e-4: minor eigenvalue exactly σ_min².
    assert!((sxy - (0.05 - 1e-4)).abs() < 1e-8, "{sxy}");
    let mean_eig = 0.5 * (sxx + syy);
    let minor = mean_eig - (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    assert!((minor - 1e-4).abs() < 1e-8, "{minor}");

    // Anti-correlated with distinct variances: clamp to −√((0.09 − σ²)(0.01 − σ²)).
    let g = SlopeGaussian::from_moments([0.0, 0.0, 0.09, 0.01, -0.5], 0.01);
    let c = g.covariance().x_axis.y as f64;
    assert!(
        (c + ((0.09f64 - 1e-4) * (0.01 - 1e-4)).sqrt()).abs() < 1e-8,
        "{c}"
    );

    // A valid moment set is reproduced: σx = 0.3, σy = 0.1, ρ = 0.4, mean (0.5, 0.2).
    let (mx, my, sx, sy, r) = (0.5f64, 0.2f64, 0.3f64, 0.1f64, 0.4f64);
    let m = [
        mx as f32,
        my as f32,
        (sx * sx + mx * mx) as f32,
        (sy * sy + my * my) as f32,
        (r * sx * sy + mx * my) as f32,
    ];
    let cov = SlopeGaussian::from_moments(m, 0.01).covariance();
    // Moments rounded to f32 (relative 6e-8 of E[x̃²] ≈ 0.34): variances good to ~5e-8.
    assert!((cov.x_axis.x as f64 - sx * sx).abs() < 1e-7);
    assert!((cov.y_axis.y as f64 - sy * sy).abs() < 1e-7);
    assert!((cov.x_axis.y as f64 - r * sx * sy).abs() < 1e-7);
}

#[test]
fn from_moments_fallbacks() {
    let centred = |g: SlopeGaussian, s: f32| {
        let cov = g.covariance();
        g.mean() == Vec2::ZERO
            && (cov.x_axis.x - s * s).abs() < 1e-6 * s * s
            && (cov.y_axis.y - s * s).abs() < 1e-6 * s * s
            && cov.x_axis.y == 0.0
    };
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for i in 0..5 {
            let mut m = [0.1, 0.2, 0.3, 0.3, 0.0];
            m[i] = bad;
            assert!(centred(SlopeGaussian::from_moments(m, 0.02), 0.02));
        }
    }
    // Bad sigma_min → DEFAULT_SIGMA_MIN; tiny sigma_min → SIGMA_MIN_FLOOR.
    let flat = [0.0, 0.0, 0.0, 0.0, 0.0];
    assert!(centred(
        SlopeGaussian::from_moments(flat, f32::NAN),
        DEFAULT_SIGMA_MIN
    ));
    assert!(centred(
        SlopeGaussian::from_moments(flat, -1.0),
        DEFAULT_SIGMA_MIN
    ));
    assert!(centred(
        SlopeGaussian::from_moments(flat, 1e-20),
        SIGMA_MIN_FLOOR
    ));
    // Huge second moments beyond f32-representable lobes: fallback, not a panic.
    let g = SlopeGaussian::from_moments([0.0, 0.0, f32::MAX, f32::MAX, 0.0], 0.01);
    assert!(g.d(Vec3::Z).is_finite());
}

#[test]
fn bad_constructor_input_names_the_parameter() {
    let id = Mat2::IDENTITY;
    let e = SlopeGaussian::new(Vec2::new(f32::NAN, 0.0), id).unwrap_err();
    assert!(
        matches!(e, Error::InvalidParameter { name: "mean", .. }),
        "{e}"
    );
    let cases = [
        Mat2::from_cols_array(&[f32::NAN, 0.0, 0.0, 1.0]),
        Mat2::from_cols_array(&[1.0, 0.5, 0.0, 1.0]),
        Mat2::from_cols_array(&[1.0, 2.0, 2.0, 1.0]),
        Mat2::from_cols_array(&[-1.0, 0.0, 0.0, 1.0]),
        Mat2::from_cols_array(&[0.0, 0.0, 0.0, 1.0]),
        Mat2::from_cols_array(&[1e-45, 0.0, 0.0, 1e-45]),
    ];
    for cov in cases {
        let e = SlopeGaussian::new(Vec2::ZERO, cov).unwrap_err();
        assert!(matches!(e, Error::InvalidMatrix { name: "cov", .. }), "{e}");
        assert!(e.to_string().contains("cov"));
    }
    for (ax, ay, name) in [(0.0, 0.1, "alpha_x"), (0.1, f32::NAN, "alpha_y")] {
        let e = SlopeGaussian::beckmann(ax, ay).unwrap_err();
        assert!(e.to_string().contains(name), "{e}");
    }
}

#[test]
fn pdf_visible_is_zero_exactly_where_d_is_when_v_underflows() {
    // σ = 0.05, mean slope (1, 0), view from the side the lobe is tilted away from, 80°:
    // a = (cot 80° − 1)/0.05 ≈ −16.5, V ≈ 0.05 φ(16.5)/16.5² ≈ 1e-63: below f32.
    let g = lobe(1.0, 0.0, 0.05, 0.05, 0.0);
    let wo = Vec3::new(80f32.to_radians().sin(), 0.0, 80f32.to_radians().cos());
    assert_eq!(g.visible_area(wo), 0.0);
    assert_eq!(g.lambda(wo), f32::MAX);
    // The normals facing wo lie ~16 σ out, where D itself rounds to 0 in f32: the pdf is
    // positive exactly where D is (the pdf contract: d = 0 ⇒ pdf_visible = 0), finite always.
    for i in 0..50 {
        let u = Vec2::new((i as f32 + 0.5) / 50.0, ((i * 7) % 50) as f32 / 50.0 + 0.01);
        let m = g.sample_visible(wo, u);
        assert!(m.z > 0.0 && wo.dot(m) > 0.0);
        let p = g.pdf_visible(wo, m);
        assert!(
            p.is_finite() && (p > 0.0) == (g.d(m) > 0.0),
            "{m} {p} {}",
            g.d(m)
        );
    }
}

/// D and the visible densities are formed directly in `f64` (one product, one quotient); the
/// logarithmic forms (`ln_d`, `ln_pdf_visible`) are independent code of the same quantities. Over
/// narrow and wide, tilted and correlated lobes, near-normal to grazing views and normals out to
/// the tails, the two agree to `f32` rounding wherever the value is a normal `f32`, and are zero /
/// positive together.
#[test]
fn direct_densities_match_their_logarithms() {
    let lobes = [
        lobe(0.0, 0.0, 0.1, 0.1, 0.0),
        lobe(0.3, -0.2, 0.02, 0.05, 0.6),
        lobe(-1.5, 0.7, 1e-3, 2e-3, -0.3),
        lobe(2.0, 2.0, 1.5, 0.8, 0.2),
        lobe(0.0, 0.0, 1e-4, 1e-4, 0.0),
    ];
    let mut checked = 0;
    for (k, g) in lobes.iter().enumerate() {
        for (t, p) in [(0.0f32, 0.0f32), (40.0, 30.0), (75.0, 200.0), (89.5, 120.0)] {
            let (t, p) = (t.to_radians(), p.to_radians());
            let wo = Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            for i in 0..64 {
                let u = Vec2::new(
                    (i as f32 + 0.5) / 64.0,
                    ((i * 37 + k) % 64) as f32 / 64.0 + 0.007,
                );
                // Visible normals (the sampler's), and normals about them pushed into the tails.
                let m0 = g.sample_visible(wo, u);
                let tilt = Vec3::new(0.3 * (u.x - 0.5), 0.3 * (u.y - 0.5), 0.0);
                for m in [m0, (m0 + tilt).normalize()] {
                    let d = g.d(m);
                    let d_ln = g.ln_d(m).map_or(0.0, |l| l.exp());
                    if d_ln >= f32::MIN_POSITIVE as f64 && d_ln <= f32::MAX as f64 {
                        assert!(
                            ((d as f64) - d_ln).abs() <= 2e-7 * d_ln,
                            "{k}: D {d} against {d_ln}"
                        );
                        checked += 1;
                    } else if d_ln < f32::MIN_POSITIVE as f64 * 0.5 {
                        assert!(d < f32::MIN_POSITIVE, "{k}: D {d} against {d_ln}");
                    }
                    let pdf = g.pdf_visible(wo, m);
                    assert_eq!(
                        pdf > 0.0,
                        d > 0.0 && wo.dot(m) > 0.0,
                        "{k}: pdf {pdf}, D {d}"
                    );
                    if let Some(l) = g.ln_pdf_visible(wo, m) {
                        let want = l.exp();
                        if d > 0.0 && want >= f32::MIN_POSITIVE as f64 && want <= f32::MAX as f64 {
                            assert!(
                                ((pdf as f64) - want).abs() <= 1e-6 * want,
                                "{k}: pdf {pdf} against {want}"
                            );
                            let q = g.pdf_visible_over_cos_given_d(wo, m, d) as f64;
                            let want_q = want / wo.dot(m) as f64;
                            if want_q <= f32::MAX as f64 {
                                assert!(
                                    (q - want_q).abs() <= 1e-6 * want_q,
                                    "{k}: {q} against {want_q}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(checked > 1000, "{checked}");
}
