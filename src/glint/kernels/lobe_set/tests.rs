//! Unit tests of the lobe set (src/glint/kernels/lobe_set.rs).

use super::*;
use glam::Mat2;

/// A set of narrow and wide, tilted lobes (some wholly behind grazing views).
fn set() -> LobeSet {
    let mut s = LobeSet::default();
    let lobes = [
        (0.2, [0.0, 0.0], [0.1, 0.1]),
        (0.1, [0.8, -0.3], [0.02, 0.05]),
        (0.3, [-2.0, 1.0], [0.01, 0.01]),
        (0.15, [0.1, 0.4], [1.2, 0.6]),
        (0.25, [3.0, 0.0], [0.05, 0.3]),
    ];
    for k in 0..4 {
        for (w, m, sd) in lobes {
            let mean = Vec2::new(m[0] + 0.1 * k as f32, m[1]);
            let cov = Mat2::from_diagonal(Vec2::new(sd[0] * sd[0], sd[1] * sd[1]));
            s.push(w, SlopeGaussian::new(mean, cov).unwrap());
        }
    }
    s.normalise();
    s
}

/// Σ w_i V_i(w) from each lobe's own `f64` V (erfc): what the set's V pass is checked against.
fn lobes_own_v(s: &LobeSet, w: Vec3) -> f64 {
    s.iter()
        .map(|(wi, g)| wi as f64 * g.visible_area(w) as f64)
        .sum()
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// V over lanes against the lobes' own `f64` V (erfc), and D at one slope against the lobes'
/// own D, summed: within the lanes' 10⁻⁶ (and `f32` rounding; D also within the slope boxes'
/// tails), at views up to 89.9°.
#[test]
fn lane_terms_match_the_lobes_own() {
    let s = set();
    assert_eq!(s.len(), 20);
    for (t, p) in [
        (0.0, 0.0),
        (30.0, 10.0),
        (60.0, 100.0),
        (80.0, 190.0),
        (89.9, 300.0),
    ] {
        let w = dir(t, p);
        let (got, want) = (s.visible_area(w) as f64, lobes_own_v(&s, w));
        assert!(
            (got - want).abs() <= 2e-6 * want,
            "V at {t}°: {got} against {want}"
        );
        for k in 0..200 {
            let m = dir(60.0 * (k as f32 / 200.0), 37.0 * k as f32);
            let want: f64 = s.iter().map(|(wi, g)| wi as f64 * g.d(m) as f64).sum();
            // A lobe whose slope box misses m is left out: its P22 there is at most
            // 10⁻⁶ (`BOX_TAIL`) of its peak.
            let sl = crate::frame::normal_to_slope(m).unwrap();
            let j = (1.0 + sl.length_squared() as f64).powi(2);
            let tails: f64 = s
                .iter()
                .map(|(wi, g)| wi as f64 * g.p22(g.mean()) as f64 * BOX_TAIL * j)
                .sum();
            let got = s.d(m) as f64;
            assert!(
                (got - want).abs() <= 1e-6 * want + tails,
                "D: {got} against {want}"
            );
        }
    }
}

/// A set of narrow lobes around the pole (a procedural patch's): at views where every lobe is
/// well in front, V takes the signed areas alone (the O(1) bound holds), within 10⁻⁶ of the
/// lobes' own `f64` V; where one lobe comes within a few spreads of the horizon the bound
/// refuses and the ramp pass serves, as accurately. A bound that let a lobe near its horizon
/// through fails here.
#[test]
fn lobes_in_front_take_their_signed_areas() {
    let mut s = LobeSet::default();
    for k in 0..7 {
        let mean = Vec2::new(0.03 * (k as f32 - 3.0), 0.05 * ((k * 5 % 7) as f32 - 3.0));
        let cov = Mat2::from_diagonal(Vec2::new(0.02 * 0.02, 0.03 * 0.03));
        s.push(
            0.1 + 0.05 * k as f32,
            SlopeGaussian::new(mean, cov).unwrap(),
        );
    }
    s.normalise();
    let mut taken = 0;
    for theta in [
        0.0f32, 20.0, 45.0, 60.0, 70.0, 75.0, 80.0, 84.0, 86.0, 88.0, 89.5,
    ] {
        for phi in [0.0f32, 50.0, 135.0, 200.0, 290.0] {
            let w = dir(theta, phi);
            let (got, want) = (s.visible_area(w) as f64, lobes_own_v(&s, w));
            assert!(
                (got - want).abs() <= 1e-6 * want,
                "V at ({theta}°, {phi}°): {got} against {want}"
            );
            if all_in_front(&s.mean_box, s.trace_max, w) {
                taken += 1;
                // The bound is conservative: every lobe is in front by more than FRONT_T.
                for (_, g) in s.iter() {
                    let (a, sw) = g.area_and_spread(w);
                    assert!(a > FRONT_T * sw, "({theta}°, {phi}°): t = {}", a / sw);
                }
            }
        }
    }
    // The fast path serves every view to 60° here (20 views) and some beyond (measured 22 of
    // 55), not only normal incidence.
    assert!(taken >= 20, "fast path at {taken} of 55 views");
}

/// The prepared view's pick weights are the terms of V(wo): the prepared set samples and
/// answers as the unprepared one, bit for bit, at the prepared view and at another.
#[test]
fn prepared_set_samples_as_the_unprepared_one() {
    let plain = set();
    let mut prepared = set();
    let wo = dir(70.0, 40.0);
    prepared.prepare_view(wo);
    for w in [wo, dir(20.0, 250.0)] {
        assert_eq!(prepared.view_visible_area(w), plain.view_visible_area(w));
        for k in 0..64 {
            let u = Vec2::new((k as f32 + 0.5) / 64.0, (k * 29 % 64) as f32 / 64.0);
            let m = plain.sample_visible(w, u);
            assert_eq!(prepared.sample_visible(w, u), m);
            assert_eq!(prepared.pdf_visible(w, m), plain.pdf_visible(w, m));
        }
    }
    // A change of the set forgets the view.
    prepared.push(0.1, SlopeGaussian::beckmann(0.3, 0.3).unwrap());
    assert!(prepared.prepared_lobes(wo).is_none());
}
