//! The position-normal baseline (Yan 2016): bad input, the closed-form element integral against a
//! quadrature over positions, normalisation per footprint, totality, samplers (chi-square), the
//! published BRDF's formula and its known energy gain, the query cap as a level of detail, and (ignored)
//! the accuracy, furnace and level-of-detail tables.
//!
//! Integrals of the spiky P-NDF are taken in slope space, where D cos θ dω = P(ñ) dñ with
//! P(ñ) = D(m(ñ)) cos⁴θ: the trapezoid rule on a grid whose step is half the narrowest element
//! lobe's minor standard deviation. For a sum of Gaussians the trapezoid rule converges exponentially
//! (aliasing error ~ exp(−2π²σ²/step²) = exp(−8π²) < 1e-30 at step σ/2); every such integral is also
//! computed at twice the step and the difference is reported as the error estimate.

mod support;

use brdf::fresnel::NoFresnel;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    Footprint, GlintNdf, NormalMap, PositionNormalBrdf, PositionNormalMap, PositionNormalPatch,
};
use brdf::ndf::{Beckmann, Ndf};
use brdf::{Bxdf, Error, MicrofacetBrdf, Vec2, Vec3};
use rand::RngExt;
use support::chi2::Chi2;

/// A patch with an explicit query cap, through the one query path (`patch_with` and the model's
/// options).
trait WithCap {
    fn patch_with_cap(&self, fp: &Footprint, cap: f32) -> PositionNormalPatch<'_>;
}

impl WithCap for PositionNormalMap {
    fn patch_with_cap(&self, fp: &Footprint, cap: f32) -> PositionNormalPatch<'_> {
        let options = brdf::glint::position_normal::PatchOptions {
            max_query_texels: cap,
        };
        self.patch_with(fp, &options, None)
    }
}

/// White-noise slopes, uniform in [−a, a]².
fn noise(n: usize, a: f32, seed: u64) -> NormalMap {
    let mut rng = support::rng(seed);
    let slopes = (0..n * n)
        .map(|_| Vec2::new(rng.random_range(-a..a), rng.random_range(-a..a)))
        .collect();
    NormalMap::from_slopes(n, n, slopes).unwrap()
}

/// A smooth periodic height field: a few sinusoids.
fn waves(n: usize) -> NormalMap {
    let tau = std::f64::consts::TAU;
    let h: Vec<f32> = (0..n * n)
        .map(|k| {
            let (x, y) = ((k % n) as f64 / n as f64, (k / n) as f64 / n as f64);
            ((tau * (2.0 * x + y)).sin() + 0.7 * (tau * (3.0 * y - x) + 1.0).sin()) as f32
        })
        .collect();
    NormalMap::from_heights(n, n, &h, 1.0).unwrap()
}

fn build(map: &NormalMap) -> PositionNormalMap {
    PositionNormalMap::build(map, PositionNormalParams::default()).unwrap()
}

/// The unit normal of slope s, written independently in f64, with its cos θ.
fn normal_of(s: [f64; 2]) -> (Vec3, f64) {
    let l = (1.0 + s[0] * s[0] + s[1] * s[1]).sqrt();
    (
        Vec3::new((-s[0] / l) as f32, (-s[1] / l) as f32, (1.0 / l) as f32),
        1.0 / l,
    )
}

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
        bad(
            PositionNormalParams {
                max_query_texels: v,
                ..d
            },
            "max_query_texels",
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

/// Any footprint, any direction: finite values, valid samples.
#[test]
fn patches_are_total() {
    use proptest::prelude::*;
    let map = noise(16, 0.5, 3);
    let pn = build(&map);
    let f = |x: f32| prop_oneof![Just(0.0f32), Just(f32::NAN), Just(1e30f32), -x..x];
    proptest!(support::proptest_config(64), |(
        uv in (-2.0f32..2.0, -2.0f32..2.0),
        a in (f(2.0), f(2.0)),
        b in (f(0.1), f(0.1)),
        w in (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0),
        u in (0.0f32..1.0, 0.0f32..1.0),
    )| {
        let fp = Footprint::from_differentials(Vec2::new(uv.0, uv.1), Vec2::new(a.0, a.1), Vec2::new(b.0, b.1));
        let patch = pn.patch(&fp);
        let w = Vec3::new(w.0, w.1, w.2);
        for v in [w, w.normalize_or_zero(), Vec3::Z, Vec3::new(1.0, 0.0, 0.0), Vec3::NAN, -Vec3::Z] {
            for x in [patch.d(v), patch.lambda(v), patch.projected_area(v), patch.visible_area(v),
                      patch.pdf_normal(v), patch.pdf_visible(Vec3::Z, v), patch.pdf_visible(v, Vec3::Z)] {
                prop_assert!(x.is_finite() && x >= 0.0, "{x} at {v:?}");
            }
        }
        let u = Vec2::new(u.0, u.1);
        let wo = w.normalize_or_zero();
        for m in [patch.sample_normal(u), patch.sample_visible(wo, u), patch.sample_visible(Vec3::NAN, u)] {
            prop_assert!(m.is_finite() && m.z > 0.0 && (m.length() - 1.0).abs() < 1e-4, "{m:?}");
        }
        let brdf = PositionNormalBrdf::new(&patch, NoFresnel);
        let wi = Vec3::new(-w.x, w.y, w.z.abs()).normalize_or_zero();
        prop_assert!(brdf.eval(wo, wi).is_finite() && brdf.pdf(wo, wi).is_finite());
    });
}

/// Samplers against their densities, with σ_r = 0.05.
///
/// The chi-square expected counts integrate the pdf over each cell with 6 × 6 Gauss–Legendre nodes,
/// which needs every lobe wider than a cell. An element lobe is J Σ_u Jᵀ + σ_r² I, as thin as σ_r
/// across wherever J is nearly singular, and the default σ_r = 0.005 (0.3°) is narrower than the
/// finest grid's cells (100 z × 200 φ: ~0.2° × 1.2° here): such streaks put draws in cells whose
/// nodes all miss them. σ_r only enters the lobes' covariance, not the sampling logic (element
/// choice, conditional slope Gaussian, visible-normal choice), so σ_r = 0.05 (2.9°, ≥ 2 cells) tests
/// the same code with resolved cells. Footprints of 16 and 64 texels; the BRDF sampler on the smooth
/// map (on the white-noise map a few elements with large Jacobians put far Gaussian tails at
/// grazing wi, where the harness's 6 × 6-node cell integrals of a ~10 σ tail are too coarse).
#[test]
fn samplers_match_their_densities() {
    let map = noise(32, 0.4, 4);
    let pn = PositionNormalMap::build(
        &map,
        PositionNormalParams {
            sigma_r: 0.05,
            ..PositionNormalParams::default()
        },
    )
    .unwrap();
    let family = 5;
    let chi = |name: &str, res_z: usize| Chi2 {
        res_z,
        res_phi: 2 * res_z,
        ..Chi2::new(name, family)
    };
    for (area, res) in [(16.0f32, 100usize), (64.0, 50)] {
        let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), area, 32, 32);
        let patch = pn.patch(&fp);
        chi(&format!("pn_normal_{area}"), res)
            .run(
                |_, u| Some(patch.sample_normal(u)),
                |m| patch.pdf_normal(m) as f64,
            )
            .unwrap();
    }
    let fp = Footprint::isotropic_texels(Vec2::new(0.4, 0.6), 16.0, 32, 32);
    let patch = pn.patch(&fp);
    for theta in [30.0, 70.0] {
        let wo = support::dir(theta, 40.0);
        // 2·10⁵ draws on 50 × 100 cells (~40 per cell): the visible sampler and density cost
        // O(elements) per call each.
        Chi2 {
            samples: 200_000,
            ..chi(&format!("pn_visible_{theta}"), 50)
        }
        .run(
            |_, u| Some(patch.sample_visible(wo, u)),
            |m| patch.pdf_visible(wo, m) as f64,
        )
        .unwrap();
    }
    // The published BRDF's sampler (reflection of `sample_normal`) on the smooth map.
    let smooth = PositionNormalMap::build(
        &waves(32),
        PositionNormalParams {
            sigma_r: 0.05,
            ..PositionNormalParams::default()
        },
    )
    .unwrap();
    let patch = smooth.patch(&fp);
    let brdf = PositionNormalBrdf::new(&patch, NoFresnel);
    let wo = support::dir(45.0, 10.0);
    // 3·10⁵ draws on 50 × 100 cells: each draw evaluates D_P at its half vector (~40 elements of
    // the smooth map overlap there).
    Chi2 {
        samples: 300_000,
        ..chi("pn_brdf_45", 50)
    }
    .run(
        |uc, u| brdf.sample(wo, uc, u).map(|s| s.wi),
        |wi| brdf.pdf(wo, wi) as f64,
    )
    .unwrap();
}

/// The published BRDF is F G D_P / (4 cos θo cos θi) with the separable Smith G of Beckmann α = 0.1,
/// and its samples agree with eval and pdf.
#[test]
fn published_brdf_formula_and_sample_consistency() {
    let map = waves(32);
    let pn = build(&map);
    let fp = Footprint::isotropic_texels(Vec2::new(0.2, 0.3), 20.0, 32, 32);
    let patch = pn.patch(&fp);
    let brdf = PositionNormalBrdf::new(&patch, NoFresnel);
    let beck = Beckmann::isotropic(0.1).unwrap();
    let mut rng = support::rng(9);
    let mut nonzero = 0;
    for _ in 0..2000 {
        let wo = support::dir(rng.random_range(0.0..80.0), rng.random_range(0.0..360.0));
        let u = Vec2::new(rng.random(), rng.random());
        let Some(s) = brdf.sample(wo, 0.5, u) else {
            continue;
        };
        assert_eq!(s.f, brdf.eval(wo, s.wi));
        assert_eq!(s.pdf, brdf.pdf(wo, s.wi));
        let h = (wo + s.wi).normalize();
        let g = beck.g1(wo, h) as f64 * beck.g1(s.wi, h) as f64;
        let expected = patch.d(h) as f64 * g / (4.0 * wo.z as f64 * s.wi.z as f64);
        // h recomputed in f32 here and in eval: D changes by ~1e-7 / σ_r × (distance in σ) relative.
        assert!(
            (s.f.x as f64 - expected).abs() <= 1e-3 * expected + 1e-30,
            "{} vs {expected}",
            s.f.x
        );
        nonzero += (expected > 0.0) as usize;
    }
    assert!(nonzero > 1000, "{nonzero}");
}

/// The published BRDF creates energy where the surface is tilted: on a constant map of slope ñ0
/// (normal n0, tilted by θ0) the P-NDF is one narrow lobe around n0, and for wo = n0 the albedo
/// ∫ f cos θi dωi → G(wo, wi, n0) (wo·n0) / (cos θ0 cos θo) = G / cos²θ0 as σ_r → 0, above 1 for
/// θ0 = 20°: 1/cos²20° = 1.1325 (G is 1 within 1e-6 for α = 0.1 at 20°). The microfacet
/// BRDF of the same patch (projected-area normalisation) gives G2 ≤ 1 instead.
#[test]
fn published_brdf_creates_energy_on_tilted_surfaces() {
    let theta0 = 20f64.to_radians();
    let s0 = Vec2::new(theta0.tan() as f32, 0.0);
    let map = NormalMap::from_slopes(8, 8, vec![s0; 64]).unwrap();
    let pn = build(&map);
    let patch = pn.patch(&Footprint::isotropic_texels(Vec2::splat(0.5), 4.0, 8, 8));
    let n0 = normal_of([s0.x as f64, 0.0]).0;
    let wo = n0;
    let yan = PositionNormalBrdf::new(&patch, NoFresnel);
    let micro = MicrofacetBrdf::new(&patch, NoFresnel);
    let albedo = |b: &dyn Bxdf| {
        let mut rng = support::rng(3);
        let n = 20_000;
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let w = b
                .sample(wo, 0.5, Vec2::new(rng.random(), rng.random()))
                .map_or(0.0, |x| x.weight().x as f64);
            s += w;
            s2 += w * w;
        }
        let mean = s / n as f64;
        (mean, ((s2 / n as f64 - mean * mean) / n as f64).sqrt())
    };
    let (a_yan, se) = albedo(&yan);
    let expected = 1.0 / theta0.cos().powi(2);
    // Tolerance: 5 standard errors plus the finite-σ_r correction, O(σ_r²) = 2.5e-5 relative
    // times a coefficient of a few (curvature of (wo·h)/cos θh and of the slope Jacobian).
    assert!(
        (a_yan - expected).abs() <= 5.0 * se + 2e-4 * expected,
        "published albedo {a_yan} ± {se} vs {expected}"
    );
    let (a_micro, se) = albedo(&micro);
    assert!(
        a_micro <= 1.0 + 5.0 * se,
        "microfacet albedo {a_micro} ± {se}"
    );
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
    let default = pn.patch(&fp);
    let same = pn.patch_with_cap(&fp, PositionNormalParams::DEFAULT_MAX_QUERY_TEXELS);
    assert_eq!(default.query_scale(), 1.0);
    assert_eq!(default.element_count(), same.element_count());
    let m = Vec3::new(0.1, -0.05, 1.0).normalize();
    assert_eq!(default.d(m).to_bits(), same.d(m).to_bits());
    // Cap 12 texels: σ → 4, scale 4 / 9.24 (f32 footprint covariance: 1e-5 relative).
    let capped = pn.patch_with_cap(&fp, 12.0);
    let want = 4.0 / sigma;
    assert!(
        (capped.query_scale() as f64 - want).abs() < 1e-5,
        "{}",
        capped.query_scale()
    );
    assert!(capped.element_count() < default.element_count());
    let uncapped = pn.patch_with_cap(&fp, f32::INFINITY);
    assert_eq!(uncapped.query_scale(), 1.0);
    assert_eq!(uncapped.element_count(), default.element_count());
    for cap in [0.0, -1.0, f32::NAN] {
        let p = pn.patch_with_cap(&fp, cap);
        assert_eq!(p.query_scale(), 0.0);
        assert!(p.element_count() >= 1);
        assert!(p.d(m).is_finite() && p.lambda(m).is_finite());
    }
}

/// Accuracy against the ground truth (same maps, footprints and bins as the mixture's table).
/// `cargo test --release --test position_normal -- --ignored accuracy_table --nocapture`
#[test]
#[ignore]
fn accuracy_table() {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, tv_distance};
    let n = 256;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | elements | TV position-normal | TV rate 2 | TV moments lobe | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, map) in &maps {
        let pn = build(map);
        let pn2 = PositionNormalMap::build(
            map,
            PositionNormalParams {
                sampling_rate: 2,
                ..PositionNormalParams::default()
            },
        )
        .unwrap();
        for area in [1.0f32, 16.0, 256.0, 4096.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let reference = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let patch = pn.patch(&fp);
            let tv = tv_distance(&patch, &reference, 4);
            let tv2 = tv_distance(&pn2.patch(&fp), &reference, 4);
            let tv_lobe = tv_distance(patch.moments_lobe(), &reference, 4);
            println!(
                "| {name} | {area} | {} | {tv:.3} | {tv2:.3} | {tv_lobe:.3} | {:.3} |",
                patch.element_count(),
                reference.tv_error()
            );
        }
    }
    let pn = build(&maps[0].1);
    let m = pn.memory();
    println!(
        "\nmemory ({n}², rate 1): {} elements, {} bytes of elements, {} bytes of hierarchy ({:.1} bytes per element)",
        m.elements,
        m.element_bytes,
        m.hierarchy_bytes,
        (m.element_bytes + m.hierarchy_bytes) as f64 / m.elements as f64
    );
}

/// White furnace of the published BRDF (F = 1) and of `MicrofacetBrdf` on the same patch, by
/// importance sampling (2·10⁵ samples, ± one standard error).
/// `cargo test --release --test position_normal -- --ignored furnace_table --nocapture`
#[test]
#[ignore]
fn furnace_table() {
    use brdf::glint::{FlakesParams, ScratchedParams, bumpy, flakes, scratched};
    let n = 256;
    let maps = vec![
        ("bumpy 0.25", bumpy(n, n, 0.25, 4.0, 1).unwrap()),
        ("bumpy 0.6", bumpy(n, n, 0.6, 4.0, 1).unwrap()),
        (
            "scratched",
            scratched(n, n, ScratchedParams::default(), 3).unwrap(),
        ),
        ("flakes", flakes(n, n, FlakesParams::default(), 4).unwrap()),
    ];
    println!(
        "| map | footprint (texels) | θo | published (Yan 2016) | MicrofacetBrdf (exact masking) |"
    );
    println!("|---|---|---|---|---|");
    for (name, map) in &maps {
        let pn = build(map);
        for area in [1.0f32, 16.0, 256.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let patch = pn.patch(&fp);
            let yan = PositionNormalBrdf::new(&patch, NoFresnel);
            let micro = MicrofacetBrdf::new(&patch, NoFresnel);
            for theta in [0.0, 45.0, 75.0] {
                let wo = support::dir(theta, 30.0);
                let est = |b: &dyn Bxdf| {
                    let mut rng = support::rng(11);
                    let k = 200_000;
                    let (mut s, mut s2) = (0.0f64, 0.0f64);
                    for _ in 0..k {
                        let w = b
                            .sample(wo, 0.5, Vec2::new(rng.random(), rng.random()))
                            .map_or(0.0, |x| x.weight().x as f64);
                        s += w;
                        s2 += w * w;
                    }
                    let m = s / k as f64;
                    (m, ((s2 / k as f64 - m * m) / k as f64).sqrt())
                };
                let (a, sa) = est(&yan);
                let (b, sb) = est(&micro);
                println!("| {name} | {area} | {theta}° | {a:.3} ± {sa:.3} | {b:.3} ± {sb:.3} |");
            }
        }
    }
}

/// The level-of-detail chart behind `DEFAULT_MAX_QUERY_TEXELS`: on 512² procedural maps, for
/// footprints of 1 to 65 536 texels, the distance of the P-NDF to the ground truth (64² bins,
/// 4·10⁶ positions, one evaluation per bin) and the time of one `patch()` and one `d` (one thread,
/// 512 normals, half from D_P cos, half bin centres), with the query cap of 128 texels (the
/// released code's) and without a cap. Where the cap does not bite (`query_scale` 1) the two
/// patches are the same computation and one row is printed. Maps run in parallel (rayon).
///
/// `cargo test --test position_normal -- --ignored lod_table --nocapture` (the test profile is
/// opt-level 3; times from one run on a loaded machine: read them as ratios).
#[test]
#[ignore]
fn lod_table() {
    use brdf::glint::{HemisphereBins, Kernel, binned_pndf, tv_distance};
    use rayon::prelude::*;
    use std::time::Instant;
    let n = 512;
    let maps = support::procedural_maps(n);
    let bins = HemisphereBins::new(64).unwrap();
    println!(
        "| map | footprint (texels) | cap (texels) | σ scale | elements | TV | patch() | d | reference noise |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    maps.par_iter().for_each(|(name, map)| {
        let pn = build(map);
        for area in [1.0f32, 16.0, 256.0, 4096.0, 16384.0, 65536.0] {
            let fp = Footprint::isotropic_texels(Vec2::new(0.43, 0.57), area, n, n);
            let reference = binned_pndf(map, &fp, Kernel::Gaussian, &bins, 4_000_000, 17);
            let capped = pn.patch(&fp).query_scale() < 1.0;
            let caps: &[f32] = if capped {
                &[128.0, f32::INFINITY]
            } else {
                &[128.0]
            };
            for &cap in caps {
                let patch = pn.patch_with_cap(&fp, cap);
                let tv = tv_distance(&patch, &reference, 1);
                let normals: Vec<Vec3> = (0..512)
                    .map(|k| {
                        let u = Vec2::new((k as f32 + 0.5) / 512.0, (k as f32 * 0.618_034).fract());
                        if k % 2 == 0 {
                            patch.sample_normal(u)
                        } else {
                            bins.center(k * 7 % bins.len())
                        }
                    })
                    .collect();
                let t = Instant::now();
                let s: f32 = normals.iter().map(|&m| patch.d(m)).sum();
                assert!(s.is_finite());
                let t_d = t.elapsed().as_secs_f64() / normals.len() as f64;
                let reps = 10;
                let t = Instant::now();
                for _ in 0..reps {
                    let p = pn.patch_with_cap(std::hint::black_box(&fp), cap);
                    std::hint::black_box(p.element_count());
                }
                let t_patch = t.elapsed().as_secs_f64() / reps as f64;
                println!(
                    "| {name} | {area} | {} | {:.3} | {} | {tv:.3} | {:.1} µs | {:.1} µs | {:.3} |",
                    match (capped, cap.is_finite()) {
                        (false, _) => "any".to_string(),
                        (true, true) => format!("{cap}"),
                        (true, false) => "none".to_string(),
                    },
                    patch.query_scale(),
                    patch.element_count(),
                    t_patch * 1e6,
                    t_d * 1e6,
                    reference.tv_error()
                );
            }
        }
    });
}
