//! The footprint references of `glint::reference`: the exact P-BRDF of the interpolated map
//! (\[Chermain2019\] eq. 7 with the true P-NDF, `FootprintBrdf::pbrdf`) and conventional normal-mapped
//! shading averaged over the footprint (`FootprintBrdf::normal_mapped`), checked against values
//! derived by hand for patches of one and two facet orientations.
//!
//! Hand derivation used throughout. A facet of slope s carries the σ_ε lobe
//! D_s(m) = exp(−|ñ(m) − s|² / 2σ²) / (2π σ² cos⁴θ_m) (non-centred Beckmann, crate convention
//! ∫ D cos θ dω = 1), so at its own normal n_s, where ñ = s and cos θ = 1/√(1 + |s|²),
//! D_s(n_s) = (1 + |s|²)² / (2π σ²). Its projected area is A_s(w) = w_z − s·w_xy. When the whole lobe
//! faces w (A_s(w) ≫ σ |w_xy|: every test below has a margin of more than 20 σ) its visible area
//! V_s(w) = ∫⟨w, m⟩⁺ D_s dm equals A_s(w) (the projected-area identity); when the whole lobe faces
//! away from w, V_s(w) = 0. The tails neglected are below exp(−20²/2) ≈ 1e-87.
//!
//! Then with facets s_k of weights w_k (Σ w_k = 1) and h = n_1 (wi the mirror of wo about n_1, other
//! facets more than 20 σ away in slope so that only facet 1 contributes to D at h):
//! - eq. 7 in the renderer's measure: f_a = w_1 D_1(h) A_P(wi) / (4 V_P(wo) V_P(wi) cos θi), with
//!   A_P = Σ w_k A_k (signed), V_P = Σ w_k V_k;
//! - normal-mapped: f_b = w_1 D_1(h) A_1(wi) / (4 V_1(wo) V_1(wi) cos θi) = w_1 D_1(h) / (4 A_1(wo) cos θi).
//!
//! Tolerances: relative 1e-5 where values come from one f32 evaluation of the lobe (D and V to a
//! few f32 ulps, ~1e-6, plus f32 directions); the map-level test states its own bound.

use brdf::glint::{Footprint, FootprintBrdf, Kernel, NormalMap, footprint_brdf};
use brdf::{Vec2, Vec3};

const SIGMA: f64 = 0.01;

/// Unit direction at polar angle θ (degrees) in the xz plane, azimuth 0 (x > 0) or 180°.
fn dir(theta_deg: f64, flip: bool) -> [f64; 3] {
    let t = theta_deg.to_radians();
    let x = if flip { -t.sin() } else { t.sin() };
    [x, 0.0, t.cos()]
}

fn v3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The unit normal of slope s: normalize(−s_x, −s_y, 1).
fn normal(s: [f64; 2]) -> [f64; 3] {
    unit([-s[0], -s[1], 1.0])
}

/// Mirror of w about the unit normal n.
fn reflect(w: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let c = 2.0 * dot(w, n);
    [c * n[0] - w[0], c * n[1] - w[1], c * n[2] - w[2]]
}

/// A_s(w) = w_z − s·w_xy.
fn area(s: [f64; 2], w: [f64; 3]) -> f64 {
    w[2] - s[0] * w[0] - s[1] * w[1]
}

/// D_s at its own normal: (1 + |s|²)² / (2π σ²).
fn peak(s: [f64; 2]) -> f64 {
    let q = 1.0 + s[0] * s[0] + s[1] * s[1];
    q * q / (2.0 * std::f64::consts::PI * SIGMA * SIGMA)
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs()
}

/// One facet orientation: (a) and (b) coincide and equal D(h) / (4 A(wo) cos θi), at the facet's
/// mirror direction (the peak) and off it (D then carries exp(−|ñ(h) − s|² / 2σ²), ñ(h) computed here
/// from h), for several facet slopes and view angles. Through the map: a constant-slope map and
/// footprints of 1, 300 and 10⁴ texels, Gaussian and parallelogram kernels.
#[test]
fn single_facet_orientation_both_references_equal_the_closed_form() {
    for s in [[0.0, 0.0], [0.2, -0.1], [-0.35, 0.25]] {
        let map = NormalMap::from_slopes(32, 32, vec![Vec2::new(s[0] as f32, s[1] as f32); 1024])
            .unwrap();
        let n = normal(s);
        for theta in [0.0, 25.0, 50.0] {
            let wo = unit(dir(theta, false));
            for offset in [0.0, 0.01, 0.02] {
                // wi: the mirror of wo about n, then tilted so that h leaves n by ~offset rad.
                let wi0 = reflect(wo, n);
                let wi = unit([wi0[0] + 2.0 * offset, wi0[1] + offset, wi0[2]]);
                let h = unit([wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]]);
                let sh = [-h[0] / h[2], -h[1] / h[2]];
                let dev2 = (sh[0] - s[0]).powi(2) + (sh[1] - s[1]).powi(2);
                let d = (-dev2 / (2.0 * SIGMA * SIGMA)).exp()
                    / (2.0 * std::f64::consts::PI * SIGMA * SIGMA * h[2].powi(4));
                let want = d / (4.0 * area(s, wo) * wi[2]);
                for (area_texels, kernel) in [
                    (1.0, Kernel::Gaussian),
                    (300.0, Kernel::Parallelogram),
                    (1e4, Kernel::Gaussian),
                ] {
                    let fp = Footprint::isotropic_texels(Vec2::new(0.3, 0.6), area_texels, 32, 32);
                    let r = footprint_brdf(&map, &fp, kernel, v3(wo), v3(wi), SIGMA as f32, 64, 5);
                    for (name, got) in [("pbrdf", r.pbrdf()), ("normal-mapped", r.normal_mapped())]
                    {
                        assert!(
                            close(got, want, 1e-5),
                            "{name}: slope {s:?}, θo {theta}, offset {offset}, {area_texels} texels: \
                             got {got}, closed form {want}"
                        );
                    }
                }
            }
        }
    }
}

/// Two facets of weights ½, ½, both facing wo and wi: V_P = A_P, so eq. 7 gives
/// f_a = ½ D_1 / (4 A_P(wo) cos θi) while normal mapping gives f_b = ½ D_1 / (4 A_1(wo) cos θi).
/// With s_1 = 0, s_2 = (0.5, 0), θo = 40° in the xz plane and wi its mirror about z:
/// A_1(wo) = cos 40° = 0.76604, A_2(wo) = cos 40° − 0.5 sin 40° = 0.44466, A_P(wo) = 0.60535,
/// D_1(h) = 1/(2π σ²) = 1591.549, so f_a = 1591.549 / (8 · 0.60535 · 0.76604) = 429.02 and
/// f_b / f_a = A_P(wo) / A_1(wo) = 0.79023.
#[test]
fn two_facets_facing_both_directions_give_the_hand_derived_eq7_value() {
    let wo = dir(40.0, false);
    let wi = dir(40.0, true);
    let mut acc = FootprintBrdf::new(v3(wo), v3(wi), SIGMA as f32);
    acc.add_weighted(Vec2::ZERO, 0.5);
    acc.add_weighted(Vec2::new(0.5, 0.0), 0.5);
    // The numbers of the doc comment, written out by hand.
    let want_a = 1591.549 / (8.0 * 0.60535 * 0.76604);
    assert!(close(want_a, 429.02, 1e-4), "hand arithmetic: {want_a}");
    assert!(close(acc.pbrdf(), want_a, 1e-4), "eq. 7: {}", acc.pbrdf());
    // And exactly from the formula in f64 (the hand numbers carry 5 digits).
    let (a1, a2) = (area([0.0, 0.0], wo), area([0.5, 0.0], wo));
    let exact_a = 0.5 * peak([0.0, 0.0]) / (4.0 * 0.5 * (a1 + a2) * wi[2]);
    assert!(
        close(acc.pbrdf(), exact_a, 1e-5),
        "{} vs {exact_a}",
        acc.pbrdf()
    );
    let exact_b = 0.5 * peak([0.0, 0.0]) / (4.0 * a1 * wi[2]);
    assert!(
        close(acc.normal_mapped(), exact_b, 1e-5),
        "{} vs {exact_b}",
        acc.normal_mapped()
    );
    assert!(close(acc.normal_mapped() / acc.pbrdf(), 0.79023, 1e-4));
}

/// Two facets of weights ½, ½ where facet 2 (s_2 = (1.5, 0)) faces away from wo (A_2(wo) =
/// cos 40° − 1.5 sin 40° = −0.19815, more than 30 σ_ε behind) but toward wi: then V_P(wo) = ½ A_1(wo),
/// V_P(wi) = A_P(wi) = ½ (A_1(wi) + A_2(wi)), so G1_P(wi) = 1 and f_a = ½ D_1 / (4 · ½ A_1(wo) cos θi)
/// = D_1 / (4 A_1(wo) cos θi): exactly twice normal mapping's ½ D_1 / (4 A_1(wo) cos θi). The
/// masked facet hides nothing in eq. 7's measure (it is not visible), so the visible facet carries
/// the patch's whole radiance; normal mapping still charges it half.
#[test]
fn two_facets_one_hidden_from_the_viewer_double_the_eq7_value() {
    let wo = dir(40.0, false);
    let wi = dir(40.0, true);
    assert!(
        area([1.5, 0.0], wo) < -30.0 * SIGMA * wo[0],
        "facet 2 is well behind wo"
    );
    let mut acc = FootprintBrdf::new(v3(wo), v3(wi), SIGMA as f32);
    acc.add_weighted(Vec2::ZERO, 0.5);
    acc.add_weighted(Vec2::new(1.5, 0.0), 0.5);
    let a1 = area([0.0, 0.0], wo);
    let want_a = peak([0.0, 0.0]) / (4.0 * a1 * wi[2]);
    assert!(
        close(acc.pbrdf(), want_a, 1e-5),
        "{} vs {want_a}",
        acc.pbrdf()
    );
    assert!(close(acc.pbrdf() / acc.normal_mapped(), 2.0, 1e-5));
}

/// The same two-facet patch through a normal map and the footprint sampler: a 4096 × 128 map whose
/// left half has slope 0 and right half slope (0.5, 0), seen through a parallelogram footprint
/// covering exactly one period (aspect 32, the clamp's limit). The closed form of the test above
/// holds up to the positions that do not see a pure facet: the two 1-texel interpolation strips at
/// the half boundaries and the strata straddling them (strata are 4 texels wide with 1024² samples),
/// at most 2 × 5 / 4096 = 0.25 % of the weight. Each of D̄, A_P and V_P moves by at most that
/// fraction of its range, so f_a by at most ~3 × 0.25 % < 1 %: the tolerance. (Dropping the patch
/// masking or normalising by A_1 instead of A_P changes f_a by 26 %.)
#[test]
fn two_facet_map_through_the_footprint_sampler_matches_the_closed_form() {
    let (w, h) = (4096usize, 128usize);
    let slopes: Vec<Vec2> = (0..w * h)
        .map(|k| {
            if k % w < w / 2 {
                Vec2::ZERO
            } else {
                Vec2::new(0.5, 0.0)
            }
        })
        .collect();
    let map = NormalMap::from_slopes(w, h, slopes).unwrap();
    let fp = Footprint::anisotropic_texels(Vec2::new(0.5, 0.5), (w * h) as f32, 32.0, 0.0, w, h);
    let (_, a, b) = fp.parallelogram_texels(w, h);
    assert!(
        (a.x - 4096.0).abs() < 1.0 && (b.y - 128.0).abs() < 0.1,
        "edges {a} {b}"
    );
    let wo = dir(40.0, false);
    let wi = dir(40.0, true);
    let r = footprint_brdf(
        &map,
        &fp,
        Kernel::Parallelogram,
        v3(wo),
        v3(wi),
        0.01,
        1 << 20,
        3,
    );
    let (a1, a2) = (area([0.0, 0.0], wo), area([0.5, 0.0], wo));
    let want_a = 0.5 * peak([0.0, 0.0]) / (4.0 * 0.5 * (a1 + a2) * wi[2]);
    let want_b = 0.5 * peak([0.0, 0.0]) / (4.0 * a1 * wi[2]);
    assert!(
        close(r.pbrdf(), want_a, 0.01),
        "eq. 7: {} vs {want_a}",
        r.pbrdf()
    );
    assert!(
        close(r.normal_mapped(), want_b, 0.01),
        "{} vs {want_b}",
        r.normal_mapped()
    );
}

/// Degenerate input gives 0, never NaN.
#[test]
fn degenerate_directions_give_zero() {
    let down = Vec3::new(0.0, 0.0, -1.0);
    for (wo, wi) in [
        (down, Vec3::Z),
        (Vec3::Z, down),
        (Vec3::NAN, Vec3::Z),
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, -0.8)),
    ] {
        let mut acc = FootprintBrdf::new(wo, wi, 0.01);
        acc.add(Vec2::new(0.1, 0.2));
        assert_eq!((acc.pbrdf(), acc.normal_mapped()), (0.0, 0.0));
    }
    let mut acc = FootprintBrdf::new(Vec3::Z, Vec3::Z, 0.0);
    acc.add(Vec2::ZERO);
    assert_eq!(acc.pbrdf(), 0.0);
    let empty = FootprintBrdf::new(Vec3::Z, Vec3::Z, 0.01);
    assert_eq!((empty.pbrdf(), empty.normal_mapped()), (0.0, 0.0));
}
