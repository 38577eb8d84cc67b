//! Fresnel reflectance against closed forms and an independent f64 reference.
//!
//! The reference is written here from Fresnel's equations with a tiny complex type (f64), so it shares
//! no code and no formula shape with the crate (which uses the cosine form for dielectrics and the a², b²
//! form for conductors, in f32). Dielectric checks also use the trigonometric form of Fresnel's
//! equations. Tolerances are float bounds derived next to each assertion.
//!
//! Run: `cargo test --test it fresnel::`.

use brdf::Vec3;
use brdf::fresnel::{
    ConductorFresnel, DielectricFresnel, Fresnel, NoFresnel, SchlickFresnel, conductor, dielectric,
    f0_from_conductor, f0_from_ior, schlick,
};
use proptest::prelude::*;

use crate::support;

/// Unit roundoff-level constant of f32 (2⁻²³).
const EPS32: f64 = f32::EPSILON as f64;

/// Just enough complex arithmetic for Fresnel's equations.
#[derive(Clone, Copy, Debug)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> C {
        C { re, im }
    }
    fn real(re: f64) -> C {
        C { re, im: 0.0 }
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn norm2(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root (Re ≥ 0). For n = η + iκ with κ ≥ 0 this picks the transmitted wave that
    /// decays into the medium (Im(n cos θ_t) ≥ 0).
    fn sqrt(self) -> C {
        let r = self.norm2().sqrt();
        let re = ((r + self.re) * 0.5).max(0.0).sqrt();
        let im = ((r - self.re) * 0.5).max(0.0).sqrt();
        C::new(re, if self.im < 0.0 { -im } else { im })
    }
}

/// (R_s, R_p) for light arriving from a medium of index 1 onto one of complex index n, at cos θ_i ∈ [0, 1]:
/// r_s = (cos θ_i − n cos θ_t)/(cos θ_i + n cos θ_t), r_p = (n cos θ_i − cos θ_t)/(n cos θ_i + cos θ_t),
/// cos θ_t = √(1 − sin²θ_i / n²).
fn reference_rs_rp(cos_i: f64, n: C) -> (f64, f64) {
    let ci = C::real(cos_i);
    let sin2 = C::real(1.0 - cos_i * cos_i);
    let ct = C::real(1.0).sub(sin2.div(n.mul(n))).sqrt();
    let rs = ci.sub(n.mul(ct)).div(ci.add(n.mul(ct)));
    let rp = n.mul(ci).sub(ct).div(n.mul(ci).add(ct));
    (rs.norm2(), rp.norm2())
}

/// Unpolarised reflectance from the reference.
fn reference(cos_i: f64, eta: f64, k: f64) -> f64 {
    let (rs, rp) = reference_rs_rp(cos_i, C::new(eta, k));
    0.5 * (rs + rp)
}

/// Dielectric reference with the crate's sign convention (cos < 0: from inside, relative index 1/η).
fn reference_dielectric(cos_i: f64, eta: f64) -> f64 {
    if cos_i < 0.0 {
        reference(-cos_i, 1.0 / eta, 0.0)
    } else {
        reference(cos_i, eta, 0.0)
    }
}

/// (R_s, R_p) of a dielectric from the trigonometric form of Fresnel's equations (valid for
/// 0 < θ_i < θ_critical): R_s = sin²(θ_i − θ_t)/sin²(θ_i + θ_t), R_p = tan²(θ_i − θ_t)/tan²(θ_i + θ_t).
fn trig_rs_rp(theta_i: f64, eta_rel: f64) -> (f64, f64) {
    let theta_t = (theta_i.sin() / eta_rel).asin();
    let rs = ((theta_i - theta_t).sin() / (theta_i + theta_t).sin()).powi(2);
    let rp = ((theta_i - theta_t).tan() / (theta_i + theta_t).tan()).powi(2);
    (rs, rp)
}

/// The reference itself agrees with the trigonometric form and with Stokes' normal-incidence value,
/// so that a disagreement below is the crate's.
#[test]
fn reference_is_consistent() {
    for eta in [1.33, 1.5, 2.4, 1.0 / 1.5] {
        for deg in [5.0f64, 20.0, 35.0, 40.0] {
            let t = deg.to_radians();
            let (rs, rp) = trig_rs_rp(t, eta);
            let (crs, crp) = reference_rs_rp(t.cos(), C::real(eta));
            assert!(
                (rs - crs).abs() < 1e-13 && (rp - crp).abs() < 1e-13,
                "{eta} {deg}"
            );
        }
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        assert!((reference(1.0, eta, 0.0) - f0).abs() < 1e-15);
    }
}

#[test]
fn normal_incidence_is_f0() {
    for eta in [1.0f32, 1.0003, 1.33, 1.5, 1.76, 2.4, 4.0, 0.75, 1.0 / 1.5] {
        let f0 = ((eta as f64 - 1.0) / (eta as f64 + 1.0)).powi(2);
        // A handful of f32 operations on values ≤ 1: ≤ 8 ulp(1) absolute.
        let tol = 8.0 * EPS32;
        assert!((dielectric(1.0, eta) as f64 - f0).abs() < tol, "{eta}");
        assert!(
            (dielectric(-1.0, eta) as f64 - f0).abs() < tol,
            "{eta} from inside"
        );
        assert!((f0_from_ior(eta) as f64 - f0).abs() < tol, "{eta}");
    }
    for (eta, k) in [(0.2f32, 3.0f32), (1.5, 0.0), (1.0, 1.0), (2.8, 8.4)] {
        let (e, kk) = (eta as f64, k as f64);
        let f0 = ((e - 1.0).powi(2) + kk * kk) / ((e + 1.0).powi(2) + kk * kk);
        let tol = 8.0 * EPS32;
        let c = conductor(1.0, Vec3::splat(eta), Vec3::splat(k));
        let f = f0_from_conductor(Vec3::splat(eta), Vec3::splat(k));
        assert!(
            (c.x as f64 - f0).abs() < tol && (f.x as f64 - f0).abs() < tol,
            "{eta} {k}"
        );
    }
}

/// At Brewster's angle tan θ_B = η_rel the p-polarised reflectance vanishes, so the unpolarised value
/// is half the s-polarised one, computed here from the trigonometric form.
#[test]
fn brewster_angle_is_half_the_s_reflectance() {
    for eta in [1.33f64, 1.5, 2.4] {
        // From outside (η_rel = η) and from inside (η_rel = 1/η, passed as a negative cosine).
        for (eta_rel, sign) in [(eta, 1.0), (1.0 / eta, -1.0)] {
            let theta_b = eta_rel.atan();
            let (rs, rp) = trig_rs_rp(theta_b, eta_rel);
            assert!(rp < 1e-28, "the test's p-reflectance at Brewster: {rp}");
            let got = dielectric((sign * theta_b.cos()) as f32, eta as f32) as f64;
            // f32 evaluation (≤ 8 ulp(1)) plus the rounding of cos θ_B to f32 times |dR/dcos| (≤ 2
            // here, the slope of R_s/2 near Brewster for these η): 8 ulp(1) + 2 ulp(1).
            let tol = 10.0 * EPS32;
            assert!(
                (got - 0.5 * rs).abs() < tol,
                "η = {eta}, side {sign}: {got} vs {}",
                0.5 * rs
            );
        }
    }
}

/// An index-matched interface (η = 1) has no interface to reflect from: F = 0 at every angle,
/// grazing incidence (±0) and cosines whose square underflows included (`dielectric(0.0, 1.0)` once
/// returned 1).
#[test]
fn index_matched_dielectric_reflects_nothing() {
    let mut cosines = vec![
        0.0f32,
        -0.0,
        1.0,
        -1.0,
        1e-20,
        -1e-20,
        1e-45,
        f32::MIN_POSITIVE,
    ];
    cosines.extend((1..=1000).map(|i| i as f32 / 1000.0));
    cosines.extend((1..=1000).map(|i| -(i as f32) / 1000.0));
    for c in cosines {
        assert_eq!(dielectric(c, 1.0), 0.0, "cos {c}");
        assert_eq!(
            DielectricFresnel::new(1.0).unwrap().eval(c),
            Vec3::ZERO,
            "cos {c}"
        );
    }
    // Next to η = 1 the grazing value is the limit 1 again (on both sides of 1).
    for eta in [1.0 - f32::EPSILON / 2.0, 1.0 + f32::EPSILON] {
        assert_eq!(dielectric(0.0, eta), 1.0, "η {eta}");
    }
}

#[test]
fn grazing_incidence_gives_one() {
    // η = 1 excepted: see `index_matched_dielectric_reflects_nothing`.
    for eta in [1e-3f32, 0.5, 1.0001, 1.5, 3.0, 1e3] {
        assert_eq!(dielectric(0.0, eta), 1.0, "{eta}");
        assert_eq!(dielectric(-0.0, eta), 1.0, "{eta}");
    }
    // η = 1, κ = 0 excepted: see `index_matched_conductor_reflects_nothing`.
    for (eta, k) in [
        (0.2f32, 3.0f32),
        (1.5, 0.0),
        (1.0, 1e-3),
        (2.8, 8.4),
        (1e3, 100.0),
    ] {
        assert_eq!(
            conductor(0.0, Vec3::splat(eta), Vec3::splat(k)),
            Vec3::ONE,
            "{eta} {k}"
        );
    }
    // Approaching grazing incidence, the reflectance goes to 1 continuously: compare with the
    // reference at the same f32 cosine (|dR/dcos| ≤ 2(η² + 1)/η near grazing, rounding ≤ 8 ulp(1)).
    for c in [1e-2f32, 1e-3, 1e-4, 1e-5] {
        let got = dielectric(c, 1.5) as f64;
        let want = reference(c as f64, 1.5, 0.0);
        assert!((got - want).abs() < 8.0 * EPS32, "{c}: {got} vs {want}");
        let g = ConductorFresnel::GOLD;
        let got = conductor(c, g.eta, g.k).x as f64;
        let want = reference(c as f64, g.eta.x as f64, g.k.x as f64);
        assert!(
            (got - want).abs() < 16.0 * EPS32,
            "gold {c}: {got} vs {want}"
        );
    }
}

/// Beyond the critical angle (from the denser side) the reflectance is exactly 1.
#[test]
fn total_internal_reflection_is_exactly_one() {
    for eta in [1.33f32, 1.5, 2.4] {
        let sin_c = 1.0 / eta as f64;
        let cos_c = (1.0 - sin_c * sin_c).sqrt();
        // 200 cosines from just beyond the critical angle to grazing, from inside (negative cosine).
        for i in 0..200 {
            let c = cos_c * (1.0 - 1e-5) * (1.0 - i as f64 / 200.0);
            assert_eq!(dielectric(-(c as f32), eta), 1.0, "η = {eta}, cos = {c}");
            // The same interface seen from outside of a medium with η < 1.
            assert_eq!(
                dielectric(c as f32, 1.0 / eta),
                1.0,
                "η = 1/{eta}, cos = {c}"
            );
        }
    }
}

/// Just inside the critical angle R → 1 continuously. With cos θ_t = ε (from Snell at the exact f32
/// input), 1 − R ≤ 2ε (η_r² + 1)/(η_r cos θ_i) (from r² = ((1 − x)/(1 + x))² ≥ 1 − 4x), so the
/// reflectance meets the value 1 of total internal reflection at ε = 0.
#[test]
fn continuous_at_the_critical_angle() {
    for eta in [1.33f32, 1.5, 2.4] {
        let eta_r = 1.0 / eta as f64; // relative index seen from inside
        let sin_c = eta_r;
        let mut previous_gap = f64::INFINITY;
        for eps in [0.3f64, 0.1, 0.03, 0.01, 3e-3, 1e-3] {
            // sin θ_i = sin θ_t · η_r with cos θ_t = ε.
            let sin_i = (1.0 - eps * eps).sqrt() * sin_c;
            let cos_i = ((1.0 - sin_i * sin_i).sqrt()) as f32;
            let ci = cos_i as f64;
            // ε at the f32 input actually passed.
            let eps = (1.0 - (1.0 - ci * ci) / (eta_r * eta_r)).max(0.0).sqrt();
            let got = dielectric(-cos_i, eta) as f64;
            let slope = 2.0 * (eta_r * eta_r + 1.0) / (eta_r * ci);
            // The crate's cos²θ_t = 1 − sin²θ_i/η_r² carries ≤ 4 roundings of values ≤ 1
            // (Δ ≤ 4 ulp(1)); its cos θ_t is then off by ≤ min(√Δ, Δ/(2ε)); R moves by ≤ slope × that.
            let delta = 4.0 * EPS32;
            let f32_term = slope * delta.sqrt().min(delta / (2.0 * eps)) + 8.0 * EPS32;
            let want = reference(ci, eta_r, 0.0);
            assert!(
                (got - want).abs() <= f32_term,
                "η {eta} ε {eps}: {got} vs {want}"
            );
            let gap = 1.0 - got;
            assert!(
                gap >= -f32_term && gap <= slope * eps + f32_term,
                "η {eta} ε {eps}: 1 − R = {gap}"
            );
            // And the gap closes monotonically as ε → 0 (up to the float term).
            assert!(gap <= previous_gap + f32_term, "η {eta} ε {eps}");
            previous_gap = gap;
        }
    }
}

/// A Snell pair (θ_i outside, θ_t inside) has equal reflectance from both sides (Stokes relations:
/// r' = −r for each polarisation).
#[test]
fn snell_pairs_reflect_equally() {
    for eta in [1.33f64, 1.5, 2.4] {
        for deg in (0..=85).step_by(5) {
            let theta_i = (deg as f64).to_radians();
            let theta_t = (theta_i.sin() / eta).asin();
            let (ci, ct) = (theta_i.cos() as f32, theta_t.cos() as f32);
            let outside = dielectric(ci, eta as f32) as f64;
            let inside = dielectric(-ct, eta as f32) as f64;
            // Each cosine is rounded to f32 (≤ ulp(1)/2 each) and R has |dR/dcos| ≤ 2(η² + 1)/(η cos)
            // on either side (see `continuous_at_the_critical_angle`); plus 8 ulp(1) per evaluation.
            let slope = |eta_r: f64, c: f64| 2.0 * (eta_r * eta_r + 1.0) / (eta_r * c);
            let tol = (slope(eta, ci as f64) + slope(1.0 / eta, ct as f64)) * EPS32 + 16.0 * EPS32;
            assert!(
                (outside - inside).abs() < tol,
                "η {eta} θ {deg}°: {outside} vs {inside}"
            );
        }
    }
}

/// A conductor without absorption is a dielectric seen from outside.
#[test]
fn conductor_with_zero_k_is_a_dielectric() {
    for eta in [0.5f32, 0.8, 1.0, 1.33, 1.5, 2.4, 10.0] {
        for i in 0..=100 {
            let c = i as f32 / 100.0;
            let sin = (1.0 - (c as f64).powi(2)).sqrt();
            if (sin - eta as f64).abs() < 0.02 {
                // Within 0.02 of the critical angle both forms are ill-conditioned (see
                // `continuous_at_the_critical_angle`); the comparison with the reference covers it.
                continue;
            }
            let d = dielectric(c, eta) as f64;
            let k0 = conductor(c, Vec3::splat(eta), Vec3::ZERO).x as f64;
            // Away from the critical angle: two f32 evaluations of ≤ 20 operations each, on values of
            // like magnitude; measured maximum difference 1.8e-7 (1.5 ulp(1)), bound 16 ulp(1).
            assert!(
                (d - k0).abs() < 16.0 * EPS32,
                "η {eta} cos {c}: {d} vs {k0}"
            );
        }
    }
}

/// The crate against the complex-arithmetic reference on a grid of metals and cosines.
#[test]
fn conductor_matches_the_complex_reference() {
    let mut metals: Vec<(f32, f32)> = Vec::new();
    for c in [
        ConductorFresnel::GOLD,
        ConductorFresnel::SILVER,
        ConductorFresnel::COPPER,
        ConductorFresnel::ALUMINIUM,
    ] {
        for i in 0..3 {
            metals.push((c.eta[i], c.k[i]));
        }
    }
    metals.extend([
        (1e-3, 0.5),
        (0.05, 100.0),
        (1e3, 100.0),
        (3.0, 1e-3),
        (1.2, 0.3),
    ]);
    let mut worst = 0.0f64;
    for &(eta, k) in &metals {
        for i in 0..=200 {
            let c = i as f32 / 200.0;
            let got = conductor(c, Vec3::splat(eta), Vec3::splat(k)).x as f64;
            let want = reference(c as f64, eta as f64, k as f64);
            worst = worst.max((got - want).abs());
            // f32 evaluation of ~25 operations; every intermediate ratio is of values of like size
            // (no cancellation after the a² rewrite): measured maximum 1.9e-7 (1.6 ulp(1)) over
            // this grid, bound 32 ulp(1) = 3.8e-6.
            assert!(
                (got - want).abs() < 32.0 * EPS32,
                "η {eta} κ {k} cos {c}: {got} vs {want}"
            );
        }
    }
    println!("conductor vs reference: max |Δ| = {worst:e}");
}

#[test]
fn dielectric_matches_the_complex_reference() {
    for eta in [1e-3f32, 0.5, 1.0, 1.33, 1.5, 2.4, 1e3] {
        for i in -200..=200 {
            let c = i as f32 / 200.0;
            let got = dielectric(c, eta) as f64;
            if c == 0.0 {
                // Grazing: the reference is 0/0 for η = 1, where the crate gives the limit of the
                // index-matched interface, 0; every other η gives the limit 1.
                assert_eq!(got, if eta == 1.0 { 0.0 } else { 1.0 }, "η {eta}");
                continue;
            }
            let want = reference_dielectric(c as f64, eta as f64);
            let eta_r = if c < 0.0 {
                1.0 / eta as f64
            } else {
                eta as f64
            };
            let ci = (c as f64).abs();
            let sin2 = 1.0 - ci * ci;
            let cos_t = (1.0 - sin2 / (eta_r * eta_r)).max(0.0).sqrt();
            // Same float model as in `continuous_at_the_critical_angle`: cos θ_t off by
            // ≤ min(√Δ, Δ/(2 cos θ_t)) with Δ = 4 ulp(1), scaled by the slope 2(η_r² + 1)/(η_r cos θ_i).
            let delta = 4.0 * EPS32;
            let slope = if ci > 0.0 {
                2.0 * (eta_r * eta_r + 1.0) / (eta_r * ci)
            } else {
                0.0
            };
            let tol = slope * delta.sqrt().min(delta / (2.0 * cos_t)) + 8.0 * EPS32;
            assert!(
                (got - want).abs() <= tol,
                "η {eta} cos {c}: {got} vs {want} (tol {tol:e})"
            );
        }
    }
}

/// Schlick against its definition, computed here in f64, and its relation to the exact dielectric:
/// both agree at normal and grazing incidence.
#[test]
fn schlick_closed_form() {
    for f0 in [0.0f32, 0.04, 0.5, 0.9, 1.0] {
        for i in 0..=50 {
            let c = i as f32 / 50.0;
            let want = f0 as f64 + (1.0 - f0 as f64) * (1.0 - c as f64).powi(5);
            let got = schlick(Vec3::splat(f0), c).x as f64;
            assert!((got - want).abs() < 4.0 * EPS32, "f0 {f0} cos {c}");
        }
    }
    let f0 = f0_from_ior(1.5);
    assert!((schlick(Vec3::splat(f0), 1.0).x - dielectric(1.0, 1.5)).abs() < 1e-7);
    assert_eq!(schlick(Vec3::splat(f0), 0.0).x, dielectric(0.0, 1.5));
}

/// The presets are the tabulated data interpolated linearly in wavelength (rows copied from the
/// refractiveindex.info datasets named in the doc comments), rounded to 3 decimals.
#[test]
fn presets_match_their_sources() {
    // (wavelength µm, n, k) rows bracketing 450, 550 and 650 nm.
    let au = [
        (0.4305, 1.45, 1.948),
        (0.4509, 1.38, 1.914),
        (0.5486, 0.43, 2.455),
        (0.5821, 0.29, 2.863),
        (0.6168, 0.21, 3.272),
        (0.6595, 0.14, 3.697),
    ];
    let ag = [
        (0.4305, 0.04, 2.462),
        (0.4509, 0.04, 2.657),
        (0.5486, 0.06, 3.586),
        (0.5821, 0.05, 3.858),
        (0.6168, 0.06, 4.152),
        (0.6595, 0.05, 4.483),
    ];
    let cu = [
        (0.4305, 1.25, 2.305),
        (0.4509, 1.24, 2.397),
        (0.5486, 1.02, 2.577),
        (0.5821, 0.70, 2.704),
        (0.6168, 0.30, 3.205),
        (0.6595, 0.22, 3.747),
    ];
    let al = [
        (0.4428, 0.60790, 5.3676),
        (0.47687, 0.72780, 5.7781),
        (0.5166, 0.87340, 6.2418),
        (0.56357, 1.0728, 6.7839),
        (0.61993, 1.3660, 7.4052),
        (0.65225, 1.5724, 7.7354),
    ];
    let interp = |rows: &[(f64, f64, f64)], w: f64| {
        let i = rows
            .windows(2)
            .position(|p| p[0].0 <= w && w <= p[1].0)
            .unwrap();
        let ((w0, n0, k0), (w1, n1, k1)) = (rows[i], rows[i + 1]);
        let t = (w - w0) / (w1 - w0);
        (n0 + t * (n1 - n0), k0 + t * (k1 - k0))
    };
    for (preset, rows) in [
        (ConductorFresnel::GOLD, &au[..]),
        (ConductorFresnel::SILVER, &ag[..]),
        (ConductorFresnel::COPPER, &cu[..]),
        (ConductorFresnel::ALUMINIUM, &al[..]),
    ] {
        for (ch, w) in [0.650, 0.550, 0.450].into_iter().enumerate() {
            let (n, k) = interp(rows, w);
            // Rounded to 3 decimals: |Δ| ≤ 5e-4 (+ f32 representation).
            assert!(
                (preset.eta[ch] as f64 - n).abs() <= 5.1e-4,
                "{preset:?} {w}: n {n}"
            );
            assert!(
                (preset.k[ch] as f64 - k).abs() <= 5.1e-4,
                "{preset:?} {w}: k {k}"
            );
        }
    }
    // Physical sanity of the colours at normal incidence: gold and copper reflect red more than blue,
    // silver and aluminium are bright and nearly grey.
    let f = |c: ConductorFresnel| c.f0();
    let (au, cu, ag, al) = (
        f(ConductorFresnel::GOLD),
        f(ConductorFresnel::COPPER),
        f(ConductorFresnel::SILVER),
        f(ConductorFresnel::ALUMINIUM),
    );
    assert!(au.x > au.y && au.y > au.z, "{au}");
    assert!(cu.x > cu.y && cu.y > cu.z, "{cu}");
    assert!(ag.min_element() > 0.95, "{ag}");
    assert!(
        al.min_element() > 0.9 && al.max_element() - al.min_element() < 0.03,
        "{al}"
    );
}

#[test]
fn nan_cosine_gives_zero_everywhere() {
    for eta in [1e-3f32, 1.5, 1e3] {
        assert_eq!(dielectric(f32::NAN, eta), 0.0);
        assert_eq!(
            conductor(f32::NAN, Vec3::splat(eta), Vec3::splat(1.0)),
            Vec3::ZERO
        );
    }
    assert_eq!(schlick(Vec3::splat(0.04), f32::NAN), Vec3::ZERO);
    assert_eq!(
        DielectricFresnel::new(1.5).unwrap().eval(f32::NAN),
        Vec3::ZERO
    );
    assert_eq!(ConductorFresnel::GOLD.eval(f32::NAN), Vec3::ZERO);
    assert_eq!(NoFresnel.eval(f32::NAN), Vec3::ONE);
}

/// log-uniform η in [1e-3, 1e3].
fn eta_range() -> impl Strategy<Value = f32> {
    (-3.0f32..=3.0).prop_map(|e| 10f32.powf(e))
}

fn in_unit(x: f32) -> bool {
    x.is_finite() && (0.0..=1.0).contains(&x)
}

fn vec_in_unit(v: Vec3) -> bool {
    in_unit(v.x) && in_unit(v.y) && in_unit(v.z)
}

proptest! {
    #![proptest_config(support::proptest_config(2000))]

    #[test]
    fn dielectric_is_a_reflectance(c in -1.1f32..=1.1, eta in eta_range()) {
        let r = dielectric(c, eta);
        prop_assert!(in_unit(r), "{} {} -> {}", c, eta, r);
        // The crate's f0 is the normal-incidence value.
        prop_assert!((dielectric(1.0, eta) - f0_from_ior(eta)).abs() < 8.0 * f32::EPSILON);
    }

    #[test]
    fn conductor_is_a_reflectance(
        c in -1.1f32..=1.1,
        eta in (eta_range(), eta_range(), eta_range()),
        k in (0.0f32..=100.0, 0.0f32..=100.0, 0.0f32..=100.0),
    ) {
        let (eta, k) = (Vec3::new(eta.0, eta.1, eta.2), Vec3::new(k.0, k.1, k.2));
        let r = conductor(c, eta, k);
        prop_assert!(vec_in_unit(r), "{} {} {} -> {}", c, eta, k, r);
        let f0 = f0_from_conductor(eta, k);
        prop_assert!(vec_in_unit(f0));
        // f0_from_conductor is conductor(1, …): both f32, ≤ 16 ulp(1) apart.
        prop_assert!((conductor(1.0, eta, k) - f0).abs().max_element() < 16.0 * f32::EPSILON);
        let fr = ConductorFresnel::new(eta, k).unwrap();
        prop_assert!(vec_in_unit(fr.eval(c)));
    }

    #[test]
    fn schlick_is_a_reflectance(
        c in -1.1f32..=1.1,
        f0 in (0.0f32..=1.0, 0.0f32..=1.0, 0.0f32..=1.0),
    ) {
        let f0 = Vec3::new(f0.0, f0.1, f0.2);
        let r = schlick(f0, c);
        prop_assert!(vec_in_unit(r));
        // Schlick interpolates between f0 and 1.
        prop_assert!(r.cmpge(f0).all());
        prop_assert!(vec_in_unit(SchlickFresnel::new(f0).unwrap().eval(c)));
    }

    /// Any f32 at all — NaN, infinities, subnormals — gives a reflectance in [0, 1], never NaN.
    #[test]
    fn arbitrary_input_never_gives_nan(
        c in proptest::num::f32::ANY,
        eta in proptest::num::f32::ANY,
        k in proptest::num::f32::ANY,
    ) {
        prop_assert!(in_unit(dielectric(c, eta)));
        prop_assert!(vec_in_unit(conductor(c, Vec3::splat(eta), Vec3::splat(k))));
        prop_assert!(vec_in_unit(schlick(Vec3::splat(eta), c)));
        prop_assert!(in_unit(f0_from_ior(eta)));
        prop_assert!(vec_in_unit(f0_from_conductor(Vec3::splat(eta), Vec3::splat(k))));
    }
}
