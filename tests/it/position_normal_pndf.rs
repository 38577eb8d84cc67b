//! The position-normal P-NDF (Yan 2016): bad parameters named, elements that linearise the slope
//! field, a constant map as one intrinsic lobe, the closed-form element integral against a quadrature
//! over positions, normalisation per footprint, and the query cap as a level of detail.
//!
//! Integrals of the spiky P-NDF are taken in slope space, where D cos θ dω = P(ñ) dñ with
//! P(ñ) = D(m(ñ)) cos⁴θ: the trapezoid rule on a grid whose step is half the narrowest element
//! lobe's minor standard deviation. For a sum of Gaussians the trapezoid rule converges exponentially
//! (aliasing error ~ exp(−2π²σ²/step²) = exp(−8π²) < 1e-30 at step σ/2); every such integral is also
//! computed at twice the step and the difference is reported as the error estimate.

use crate::support;

use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{Footprint, GlintNdf, NormalMap, PositionNormalMap, PositionNormalPatch};
use brdf::ndf::Ndf;
use brdf::{Error, Vec2, Vec3};
use support::position_normal::{build, noise, normal_of, waves};

/// A 2D Gaussian density in f64 (independent of the crate).
fn gauss2(x: [f64; 2], mean: [f64; 2], cov: [f64; 3]) -> f64 {
    let det = cov[0] * cov[2] - cov[1] * cov[1];
    let (dx, dy) = (x[0] - mean[0], x[1] - mean[1]);
    let q = (cov[2] * dx * dx - 2.0 * cov[1] * dx * dy + cov[0] * dy * dy) / det;
    (-0.5 * q).exp() / (std::f64::consts::TAU * det.sqrt())
}

#[test]
fn bad_parameters_are_rejected_by_name() {
    let map = noise(8, 0.3, 1);
    let bad = |p: PositionNormalParams, name: &str| {
        let e = PositionNormalMap::build(&map, p).unwrap_err();
        assert!(
            matches!(e, Error::InvalidParameter { name: n, .. } if n == name),
            "{name}: {e}"
        );
    };
    let d = PositionNormalParams::default();
    bad(
        PositionNormalParams {
            sampling_rate: 0,
            ..d
        },
        "sampling_rate",
    );
    for v in [0.0, -1.0, f32::NAN, 2.0, 1e-6] {
        bad(PositionNormalParams { sigma_r: v, ..d }, "sigma_r");
    }
    for v in [1.0, f32::NAN, f32::INFINITY] {
        bad(
            PositionNormalParams {
                weight_sigmas: v,
                ..d
            },
            "weight_sigmas",
        );
    }
    for v in [0.0, f32::NAN] {
        bad(
            PositionNormalParams {
                slope_sigmas: v,
                ..d
            },
            "slope_sigmas",
        );
    }
    let ok = PositionNormalMap::build(&map, d).unwrap();
    assert_eq!(ok.grid(), (8, 8));
    // σ_h = h/√(8 ln 2): the element Gaussian's full width at half maximum is one spacing.
    let sh = ok.sigma_h() as f64;
    assert!((2.0 * (2.0 * 2f64.ln()).sqrt() * sh - 1.0).abs() < 1e-6);
    let m = ok.memory();
    assert_eq!(m.elements, 64);
    assert_eq!(m.element_bytes, 64 * 24);
}

/// Element slopes and Jacobians follow the slope field. The map's slopes are a smooth field that is
/// not a gradient (∂x̃/∂v ≠ ∂ỹ/∂u), so a transposed J would show: x̃ = a sin(k v), ỹ = a sin(k (u + v)),
/// k = 2π/32, whose derivatives are known in closed form. The interpolated field differs from the
/// generating one by the bilinear blend of unit normals (relative curvature error ~ k²/8 ≈ 0.5 %,
/// and a second-order effect of the unit-normal weights) and the central difference over one spacing
/// (factor sin(k h/2)/(k h/2) ≥ 0.993): 2 % of the amplitude plus 1e-3 covers them.
#[test]
fn elements_linearise_the_slope_field() {
    let (n, a) = (32usize, 0.3f64);
    let k = std::f64::consts::TAU / n as f64;
    // Texel (i, j) holds the field at its centre (i + ½, j + ½).
    let field = |u: f64, v: f64| [a * (k * v).sin(), a * (k * (u + v)).sin()];
    let slopes = (0..n * n)
        .map(|t| {
            let f = field((t % n) as f64 + 0.5, (t / n) as f64 + 0.5);
            Vec2::new(f[0] as f32, f[1] as f32)
        })
        .collect();
    let map = NormalMap::from_slopes(n, n, slopes).unwrap();
    for rate in [1usize, 2] {
        let pn = PositionNormalMap::build(
            &map,
            PositionNormalParams {
                sampling_rate: rate,
                ..PositionNormalParams::default()
            },
        )
        .unwrap();
        for (i, j) in [(0i64, 0i64), (3, 7), (10, 21), (17, 5), (40, 40)] {
            let (c, s, jac) = pn.element(i, j);
            let (u, v) = (c.x as f64, c.y as f64);
            let f = field(u, v);
            let tol = |x: f64| 0.02 * x.abs() + 1e-3;
            assert!(
                (s.x as f64 - f[0]).abs() < tol(a) && (s.y as f64 - f[1]).abs() < tol(a),
                "rate {rate} ({i}, {j}): slope {s:?} vs {f:?}"
            );
            // Columns: ∂/∂u, ∂/∂v. Between texel centres the interpolated field is bilinear, so its
            // derivative along an axis is the centres' difference: the generating derivative at the
            // midpoint of the two centres (at a centre, the central difference spans both halves).
            let mid = |x: f64| {
                if (x - 0.5).fract() == 0.0 {
                    x
                } else {
                    (x - 0.5).floor() + 1.0
                }
            };
            let (um, vm) = (mid(u), mid(v));
            let d = [
                [0.0, a * k * (k * vm).cos()],
                [a * k * (k * (um + v)).cos(), a * k * (k * (u + vm)).cos()],
            ];
            let got = [
                [jac.x_axis.x as f64, jac.y_axis.x as f64],
                [jac.x_axis.y as f64, jac.y_axis.y as f64],
            ];
            for r in 0..2 {
                for q in 0..2 {
                    assert!(
                        (got[r][q] - d[r][q]).abs() <= tol(a * k),
                        "rate {rate} ({i}, {j}): J[{r}][{q}] = {} vs {}",
                        got[r][q],
                        d[r][q]
                    );
                }
            }
        }
    }
}

/// A constant map has J = 0: every element is N(ñ0, σ_r² I) whatever the footprint, so the P-NDF is
/// that single Gaussian, D = N(ñ; ñ0, σ_r²) / cos⁴θ.
#[test]
fn constant_map_is_one_intrinsic_lobe() {
    let s0 = [0.2f64, -0.1];
    let map =
        NormalMap::from_slopes(16, 16, vec![Vec2::new(s0[0] as f32, s0[1] as f32); 256]).unwrap();
    let pn = build(&map);
    let sr = PositionNormalParams::DEFAULT_SIGMA_R as f64;
    for area in [0.01f32, 1.0, 30.0, 1e6] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.8), area, 16, 16);
        let patch = pn.patch(&fp);
        for k in 0..49 {
            let (a, b) = ((k % 7) as f64 / 2.0 - 1.5, (k / 7) as f64 / 2.0 - 1.5);
            let s = [s0[0] + a * sr, s0[1] + b * sr];
            let (m, cos) = normal_of(s);
            let expected = gauss2(s, s0, [sr * sr, 0.0, sr * sr]) / cos.powi(4);
            let got = patch.d(m) as f64;
            // f32 rounding of m shifts the slope by ~1e-7 = 2e-5 σ_r; at 2.1 σ from the mean this
            // changes the density by ~4e-5 relative; 1e-3 leaves room for the f32 sums.
            assert!(
                (got - expected).abs() <= 1e-3 * expected,
                "area {area} s {s:?}: {got} vs {expected}"
            );
        }
    }
}

/// The closed form (completing the square in u) against a quadrature over positions.
///
/// Element i contributes ∫ k_P(u) N(u; u_i, σ_h²) N(ñ; ñ_i + J_i (u − u_i), σ_r²) du. Given u the
/// slope is Gaussian, so the contribution is a Gaussian in ñ whose weight, mean and covariance are the
/// u-integrals of k_P N_i × (1, m(u), m mᵀ + σ_r²): computed here by a midpoint rule on u (step
/// σ_h/6.4 over ±10 σ_h around u_i; the integrands are Gaussians of standard deviation ≤ σ_h centred
/// within 6 σ_h of u_i for every element that carries weight, for which the rule's aliasing error is
/// ~exp(−2π²·41) and the window truncates at ≥ 4 σ of the product, on weights ≤ e^{−18} there). The test's density is
/// then Σ W_i N(ñ; mean_i, cov_i) with W normalised over the elements, evaluated at points drawn
/// from the patch. Wide truncations (6 σ, 8 σ) make the model's truncation error < 1e-7.
#[test]
fn closed_form_matches_position_quadrature() {
    let n = 8;
    let map = noise(n, 0.3, 5);
    for rate in [1usize, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            weight_sigmas: 6.0,
            slope_sigmas: 8.0,
            ..PositionNormalParams::default()
        };
        let pn = PositionNormalMap::build(&map, params).unwrap();
        let fp = Footprint::anisotropic_texels(Vec2::new(0.31, 0.62), 3.0, 2.0, 0.4, n, n);
        let (c, cov) = fp.gaussian_texels(n, n);
        let (c, pc) = (
            [c.x as f64, c.y as f64],
            [
                cov.x_axis.x as f64,
                cov.y_axis.x as f64,
                cov.y_axis.y as f64,
            ],
        );
        let h = 1.0 / rate as f64;
        let sh = pn.sigma_h() as f64;
        let sr2 = (params.sigma_r as f64).powi(2);
        // Every unwrapped element within ±6 texels of the centre (Σ_eff ≤ 0.7 texel² per axis, so
        // the 6 σ ellipse of the kept elements lies inside).
        let mut lobes: Vec<(f64, [f64; 2], [f64; 3])> = Vec::new();
        let reach = (6.0 / h) as i64;
        let (ci, cj) = ((c[0] / h) as i64, (c[1] / h) as i64);
        for j in cj - reach..=cj + reach {
            for i in ci - reach..=ci + reach {
                let (_, s, jac) = pn.element(i, j);
                let ui = [(i as f64 + 0.5) * h, (j as f64 + 0.5) * h];
                let jm = [
                    jac.x_axis.x as f64,
                    jac.y_axis.x as f64,
                    jac.x_axis.y as f64,
                    jac.y_axis.y as f64,
                ];
                let steps = 128;
                let du = 20.0 * sh / steps as f64;
                let mut acc = [0.0f64; 6];
                for b in 0..steps {
                    for a in 0..steps {
                        let u = [
                            ui[0] - 10.0 * sh + (a as f64 + 0.5) * du,
                            ui[1] - 10.0 * sh + (b as f64 + 0.5) * du,
                        ];
                        let w = gauss2(u, c, pc) * gauss2(u, ui, [sh * sh, 0.0, sh * sh]);
                        let d = [u[0] - ui[0], u[1] - ui[1]];
                        let mx = s.x as f64 + jm[0] * d[0] + jm[1] * d[1];
                        let my = s.y as f64 + jm[2] * d[0] + jm[3] * d[1];
                        acc[0] += w;
                        acc[1] += w * mx;
                        acc[2] += w * my;
                        acc[3] += w * mx * mx;
                        acc[4] += w * mx * my;
                        acc[5] += w * my * my;
                    }
                }
                let w = acc[0];
                if w < 1e-300 {
                    continue;
                }
                let mean = [acc[1] / w, acc[2] / w];
                let cov = [
                    acc[3] / w - mean[0] * mean[0] + sr2,
                    acc[4] / w - mean[0] * mean[1],
                    acc[5] / w - mean[1] * mean[1] + sr2,
                ];
                lobes.push((w, mean, cov));
            }
        }
        let total: f64 = lobes.iter().map(|l| l.0).sum();
        let patch = pn.patch(&fp);
        let mut checked = 0;
        for k in 0..40 {
            let u = Vec2::new(
                (k as f32 + 0.5) / 40.0,
                ((k * 17) % 40) as f32 / 40.0 + 0.01,
            );
            let m = patch.sample_normal(u);
            let s = [(-m.x / m.z) as f64, (-m.y / m.z) as f64];
            let (m, cos) = normal_of(s);
            let p: f64 = lobes
                .iter()
                .map(|&(w, mean, cov)| w / total * gauss2(s, mean, cov))
                .sum();
            let expected = p / cos.powi(4);
            let got = patch.d(m) as f64;
            // f32 storage of ñ_i and J_i (relative 6e-8), f32 rounding of m (1e-7 in slope, ≤ 4e-5
            // relative at a few σ_r) and the final f32 conversion: 2e-3 relative is a loose bound.
            assert!(
                (got - expected).abs() <= 2e-3 * expected,
                "rate {rate} s {s:?}: model {got} vs quadrature {expected}"
            );
            checked += 1;
        }
        assert_eq!(checked, 40);
    }
}

/// ∫ P(ñ) dñ by the trapezoid rule on a slope grid covering every element lobe of the patch to
/// ±6 σ (the untruncated mixture leaves < e^{−18} outside), at step `scale` × half the narrowest
/// minor σ. `f` maps a normal to D.
fn slope_integral(patch: &PositionNormalPatch, scale: f64, f: &dyn Fn(Vec3) -> f64) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    let mut min_sigma = f64::MAX;
    for (_, g) in patch.weighted_lobes() {
        let c = g.covariance();
        let (a, b, d) = (c.x_axis.x as f64, c.x_axis.y as f64, c.y_axis.y as f64);
        let minor = 0.5 * (a + d) - (0.25 * (a - d) * (a - d) + b * b).sqrt();
        min_sigma = min_sigma.min(minor.max(0.0).sqrt());
        let m = g.mean();
        for (k, (mk, v)) in [(m.x as f64, a), (m.y as f64, d)].into_iter().enumerate() {
            lo[k] = lo[k].min(mk - 6.0 * v.sqrt());
            hi[k] = hi[k].max(mk + 6.0 * v.sqrt());
        }
    }
    let step = 0.5 * min_sigma * scale;
    let n = [0, 1].map(|k| ((hi[k] - lo[k]) / step).ceil() as usize + 1);
    let mut sum = 0.0;
    for j in 0..n[1] {
        for i in 0..n[0] {
            let s = [lo[0] + i as f64 * step, lo[1] + j as f64 * step];
            let (m, cos) = normal_of(s);
            sum += f(m) * cos.powi(4);
        }
    }
    sum * step * step
}

/// ∫ D_P cos θ dω = 1 for every footprint: two maps (white noise, smooth waves) × two sampling
/// rates × sub-texel to 64-texel anisotropic footprints.
#[test]
fn pndf_is_normalised_per_footprint() {
    let cases = [
        ("noise", noise(32, 0.2, 2), 1usize, [0.2f32, 16.0]),
        ("waves", waves(32), 2, [1.0, 64.0]),
    ];
    for (name, map, rate, areas) in &cases {
        let pn = PositionNormalMap::build(
            map,
            PositionNormalParams {
                sampling_rate: *rate,
                ..PositionNormalParams::default()
            },
        )
        .unwrap();
        for &area in areas {
            let fp = Footprint::anisotropic_texels(Vec2::new(0.37, 0.71), area, 1.5, 0.3, 32, 32);
            let patch = pn.patch(&fp);
            let d = |m: Vec3| patch.d(m) as f64;
            let (fine, coarse) = (
                slope_integral(&patch, 1.0, &d),
                slope_integral(&patch, 2.0, &d),
            );
            let quad = (fine - coarse).abs();
            // Truncation: each element's slope box holds ≥ 4 σ per side, so at most 4 Q(4) =
            // 1.27e-4 of the mass is missing; plus the quadrature error estimate and 1e-5 for f32.
            assert!(
                fine <= 1.0 + quad + 1e-5 && fine >= 1.0 - 1.27e-4 - quad - 1e-5,
                "{name} rate {rate} area {area}: ∫ D cos = {fine} (quad err {quad:.1e})"
            );
        }
    }
}

/// The query cap as an explicit level of detail: `patch()` is `patch_with_cap` at the map's cap,
/// `query_scale` is the σ ratio the cap imposes (k_w σ ≤ cap), no cap keeps every element, and a
/// degenerate cap shrinks the footprint to its centre without breaking totality.
#[test]
fn query_cap_is_an_explicit_level_of_detail() {
    let n = 64;
    let map = noise(n, 0.3, 5);
    let pn = build(&map);
    // A square footprint of area A has σ = √(A/12) per axis: 1024 texels → σ = 9.24, k_w σ = 27.7.
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 1024.0, n, n);
    let sigma = (1024.0f64 / 12.0).sqrt();
    // The cap is the element sum's level of detail; the cut (position_normal_cut.rs) is off in
    // the element sums compared here, whatever its default threshold.
    let default = pn.patch_with(
        &fp,
        &brdf::glint::position_normal::PatchOptions {
            cut_nodes: 0,
            ..Default::default()
        },
        None,
    );
    let same = pn.patch_with(
        &fp,
        &brdf::glint::position_normal::PatchOptions {
            max_query_texels: PositionNormalParams::DEFAULT_MAX_QUERY_TEXELS,
            cut_nodes: 0,
            ..Default::default()
        },
        None,
    );
    assert_eq!(default.query_scale(), 1.0);
    assert_eq!(default.element_count(), same.element_count());
    let m = Vec3::new(0.1, -0.05, 1.0).normalize();
    assert_eq!(default.d(m).to_bits(), same.d(m).to_bits());
    // Cap 12 texels: σ → 4, scale 4 / 9.24 (f32 footprint covariance: 1e-5 relative).
    let capped = pn.patch_with(
        &fp,
        &brdf::glint::position_normal::PatchOptions {
            max_query_texels: 12.0,
            cut_nodes: 0,
            ..Default::default()
        },
        None,
    );
    let want = 4.0 / sigma;
    assert!(
        (capped.query_scale() as f64 - want).abs() < 1e-5,
        "{}",
        capped.query_scale()
    );
    assert!(capped.element_count() < default.element_count());
    let uncapped = pn.patch_with(
        &fp,
        &brdf::glint::position_normal::PatchOptions {
            max_query_texels: f32::INFINITY,
            cut_nodes: 0,
            ..Default::default()
        },
        None,
    );
    assert_eq!(uncapped.query_scale(), 1.0);
    assert_eq!(uncapped.element_count(), default.element_count());
    for cap in [0.0, -1.0, f32::NAN] {
        let p = pn.patch_with(
            &fp,
            &brdf::glint::position_normal::PatchOptions {
                max_query_texels: cap,
                cut_nodes: 0,
                ..Default::default()
            },
            None,
        );
        assert_eq!(p.query_scale(), 0.0);
        assert!(p.element_count() >= 1);
        assert!(p.d(m).is_finite() && p.lambda(m).is_finite());
    }
}
