//! Fresnel reflectance: the free functions [`schlick`], [`dielectric`], [`conductor`],
//! [`f0_from_ior`], [`f0_from_conductor`], and the small [`Fresnel`] trait that the microfacet BRDF is
//! generic over, with its implementations [`NoFresnel`], [`SchlickFresnel`], [`DielectricFresnel`] and
//! [`ConductorFresnel`].
//!
//! Conventions: `cos_theta` is the cosine between the incident direction and the (micro)surface normal.
//! For dielectrics `eta` = n_inside / n_outside, the normal points outside, and cos θ < 0 means the
//! light arrives from inside. Conductors have the complex index η + iκ relative to the outside medium
//! (per RGB channel); their cos θ is clamped into [0, 1]. All reflectances are unpolarised (the mean of
//! the s- and p-polarised reflectances). Every function is total: inputs outside its domain (a NaN
//! cosine, an index that is not finite and positive, a negative or non-finite κ) give a reflectance of
//! 0, as documented on each function; the constructors of the [`Fresnel`] types reject them instead.

use crate::error::{Error, Result, finite, non_negative, positive};
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use core::hint::select_unpredictable;
use glam::{BVec3A, Vec3, Vec3A};

/// Schlick's approximation of Fresnel reflectance: F = F0 + (1 − F0)(1 − cos θ)⁵.
///
/// `f0` is the reflectance at normal incidence per channel (see [`f0_from_ior`],
/// [`f0_from_conductor`]).
///
/// Degenerate cases: `cos_theta` is clamped into [0, 1] (a negative cosine counts as grazing, F = 1);
/// a NaN cosine gives 0; `f0` is clamped into [0, 1] per channel, NaN counting as 0.
///
/// # Reference
/// \[Schlick1994\], eq. 24.
#[inline]
pub fn schlick(f0: Vec3, cos_theta: f32) -> Vec3 {
    if cos_theta.is_nan() {
        return Vec3::ZERO;
    }
    let f0 = f0.max(Vec3::ZERO).min(Vec3::ONE);
    let m = 1.0 - cos_theta.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}

/// Exact unpolarised Fresnel reflectance of a smooth interface between two dielectrics.
///
/// With cos θ_i ≥ 0 (incident from outside) and relative index η = n_inside / n_outside, Snell's law
/// gives η cos θ_t = g = √(η² − 1 + cos²θ_i) and
/// r_∥ = (η cos θ_i − cos θ_t) / (η cos θ_i + cos θ_t) = (η² cos θ_i − g) / (η² cos θ_i + g),
/// r_⊥ = (cos θ_i − η cos θ_t) / (cos θ_i + η cos θ_t) = (cos θ_i − g) / (cos θ_i + g),
/// F = (r_∥² + r_⊥²) / 2.
/// For cos θ_i < 0 (incident from inside) the same formula is used with |cos θ_i| and 1/η.
/// Total internal reflection (g² < 0) needs no branch: g is taken as 0 and both ratios are 1.
///
/// Degenerate cases: total internal reflection gives exactly 1; grazing incidence (cos θ_i = 0)
/// gives 1, except for the index-matched interface η = 1, which gives 0 at every angle (there is no
/// interface); `cos_theta_i` is clamped into [−1, 1]; a NaN cosine, or `eta` NaN, infinite or ≤ 0,
/// gives 0 (the constructors reject such an `eta`). Huge or tiny finite `eta` give values in [0, 1]
/// (the limit 1 where η² over- or underflows).
///
/// # Reference
/// \[BornWolf1999\], §1.5.2 (Fresnel formulae; the cosine form as in \[Pharr2023\], §9.3, "The Fresnel
/// Equations"; the g form as in \[Walter2007\] eq. 22).
#[inline]
pub fn dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    // From inside: flip to the other side. The side is a coin flip for a renderer's random
    // directions: a select, not a branch (the division is cheaper than a misprediction).
    let e = select_unpredictable(cos_theta_i < 0.0, 1.0 / eta, eta);
    let c = cos_theta_i.abs().min(1.0);
    let e2 = e * e;
    // g² = η² cos²θ_t; negative beyond the critical angle, where g = 0 gives r_∥ = r_⊥ = 1.
    let g = ((e2 - 1.0) + c * c).max(0.0).sqrt();
    let ec = e2 * c;
    let r_perp = (c - g) / (c + g);
    let r_parl = (ec - g) / (ec + g);
    let f = 0.5 * (r_parl * r_parl + r_perp * r_perp);
    // `min` maps NaN to 1: 0/0 at grazing incidence with g = 0 (η < 1, whose limit is total
    // reflection), and ∞/∞ or 0/0 where η² over- or underflows (limit 1 as well). One test
    // covers the invalid inputs and the index-matched interface (η = 1 → 0 exactly, which the
    // formula gives anyway except where c² underflows).
    if eta > 0.0 && eta < f32::INFINITY && eta != 1.0 && !cos_theta_i.is_nan() {
        f.min(1.0)
    } else {
        0.0
    }
}

/// Exact unpolarised Fresnel reflectance of a conductor with complex index η + iκ per channel.
///
/// Closed form in terms of a² and b², the squared real and imaginary parts of √(n² − sin²θ) with
/// n = η + iκ:
/// a² + b² = √((η² − κ² − sin²θ)² + 4η²κ²), a² = (a² + b² + η² − κ² − sin²θ) / 2,
/// R_s = (a² + b² − 2a cos θ + cos²θ) / (a² + b² + 2a cos θ + cos²θ),
/// R_p = R_s (cos²θ (a² + b²) − 2a cos θ sin²θ + sin⁴θ) / (cos²θ (a² + b²) + 2a cos θ sin²θ + sin⁴θ),
/// F = (R_s + R_p) / 2 = R_s · (cos²θ (a² + b²) + sin⁴θ) / (cos²θ (a² + b²) + 2a cos θ sin²θ + sin⁴θ).
/// a² is evaluated without cancellation when η² − κ² − sin²θ < 0 (as 2η²κ² / (a² + b² − η² + κ² +
/// sin²θ)). The three channels are computed together in SIMD lanes (`Vec3A`), so each division and
/// square root is one instruction for all three. With κ = 0 this equals [`dielectric`] for incidence
/// from outside.
///
/// Degenerate cases: `cos_theta_i` is clamped into [0, 1] (light cannot arrive from inside a
/// conductor; a negative cosine counts as grazing, F = 1); grazing incidence gives 1, except for the
/// index-matched channel η = 1, κ = 0, which gives 0 at every angle as [`dielectric`] does (there is
/// no interface); a NaN cosine gives 0; per channel, η NaN, infinite or ≤ 0, or κ NaN, infinite or
/// < 0, gives 0.
///
/// # Reference
/// \[BornWolf1999\], §14.2 (reflection at a metal: Fresnel's formulae with a complex index); the a², b²
/// form as written in \[Pharr2016\], §8.2.1 (`FrConductor`).
#[inline]
pub fn conductor(cos_theta_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    // NaN → 0 here (`clamp` would keep it); the result is zeroed for a NaN cosine below.
    #[allow(clippy::manual_clamp)]
    let c = cos_theta_i.max(0.0).min(1.0);
    let cos2 = c * c;
    let sin2 = 1.0 - cos2;
    let (eta, k) = (Vec3A::from(eta), Vec3A::from(k));
    let (eta2, k2) = (eta * eta, k * k);
    let ek2 = eta2 * k2;
    let t0 = eta2 - k2 - Vec3A::splat(sin2);
    let a2_plus_b2 = sqrt3(t0 * t0 + 4.0 * ek2);
    // a² = (a² + b² + t0)/2, as 2η²κ² / (a² + b² − t0) when t0 < 0 (no cancellation).
    let a2 = Vec3A::select(
        t0.cmpge(Vec3A::ZERO),
        0.5 * (a2_plus_b2 + t0),
        2.0 * ek2 / (a2_plus_b2 - t0),
    );
    let t2 = (2.0 * c) * sqrt3(a2);
    let t1 = a2_plus_b2 + Vec3A::splat(cos2);
    let t3 = a2_plus_b2 * cos2 + Vec3A::splat(sin2 * sin2);
    let t4 = t2 * sin2;
    let r = (t1 - t2) / (t1 + t2) * (t3 / (t3 + t4));
    // NaN only from 0/0 at grazing incidence with a² + b² = 0 (κ = 0, η = 1: index-matched, set to
    // 0 below) or from overflow of the squares for |η + iκ| ≳ 1e19 (limit 1).
    let r = Vec3A::select(r.cmpeq(r), r, Vec3A::ONE);
    let r = r.max(Vec3A::ZERO).min(Vec3A::ONE);
    // The index-matched channel (η = 1, κ = 0) reflects nothing; its formula is exactly 0 except
    // for the 0/0 at grazing incidence mapped to 1 above.
    let matched = eta.cmpeq(Vec3A::ONE) & k.cmpeq(Vec3A::ZERO);
    let valid = eta.cmpgt(Vec3A::ZERO)
        & eta.cmplt(Vec3A::INFINITY)
        & k.cmpge(Vec3A::ZERO)
        & k.cmplt(Vec3A::INFINITY)
        & !matched
        & BVec3A::splat(!cos_theta_i.is_nan());
    Vec3::from(Vec3A::select(valid, r, Vec3A::ZERO))
}

/// Square roots of the three lanes in one instruction (SSE's `sqrtps` on x86-64; glam's
/// `Vec3A::sqrt` takes three scalar roots).
#[inline(always)]
fn sqrt3(v: Vec3A) -> Vec3A {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use core::arch::x86_64::{__m128, _mm_sqrt_ps};
        // SAFETY: the cfg guarantees SSE2 (part of the x86-64 baseline), all `_mm_sqrt_ps` needs.
        Vec3A::from(unsafe { _mm_sqrt_ps(__m128::from(v)) })
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        v.sqrt()
    }
}

/// Normal-incidence reflectance of a dielectric: F0 = ((η − 1) / (η + 1))².
///
/// Equals [`dielectric`]`(1, eta)`. Degenerate cases: `eta` NaN, infinite or ≤ 0 gives 0.
///
/// # Reference
/// \[BornWolf1999\], §1.5.3 (reflectivity at normal incidence).
#[inline]
pub fn f0_from_ior(eta: f32) -> f32 {
    if !(eta > 0.0 && eta.is_finite()) {
        return 0.0;
    }
    let r = (eta - 1.0) / (eta + 1.0);
    (r * r).min(1.0)
}

/// Normal-incidence reflectance of a conductor per channel: F0 = ((η − 1)² + κ²) / ((η + 1)² + κ²).
///
/// Evaluated as 1 − 4η / ((η + 1)² + κ²), which cannot overflow to NaN (huge η or κ give the limit 1).
/// Equals [`conductor`]`(1, eta, k)`. Degenerate cases: per channel, η NaN, infinite or ≤ 0, or κ NaN,
/// infinite or < 0, gives 0.
///
/// # Reference
/// \[BornWolf1999\], §14.2 (reflectivity of a metal at normal incidence).
#[inline]
pub fn f0_from_conductor(eta: Vec3, k: Vec3) -> Vec3 {
    let channel = |eta: f32, k: f32| {
        if !(eta > 0.0 && eta.is_finite() && k >= 0.0 && k.is_finite()) {
            return 0.0;
        }
        let d = (eta + 1.0) * (eta + 1.0) + k * k;
        // η / d first: 4η alone may overflow (d = ∞ then gives η/d = 0, the limit).
        (1.0 - 4.0 * (eta / d)).clamp(0.0, 1.0)
    };
    Vec3::new(
        channel(eta.x, k.x),
        channel(eta.y, k.y),
        channel(eta.z, k.z),
    )
}

/// A Fresnel term for BRDFs: RGB reflectance as a function of the cosine between the incident
/// direction and the microfacet normal.
///
/// Implementations are total: they never panic and never return NaN; values lie in [0, 1].
pub trait Fresnel {
    /// Reflectance for the cosine between the incident direction and the microfacet normal.
    fn eval(&self, cos_theta: f32) -> Vec3;
}

impl<T: Fresnel + ?Sized> Fresnel for &T {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        (**self).eval(cos_theta)
    }
}

#[cfg(feature = "std")]
impl<T: Fresnel + ?Sized> Fresnel for Box<T> {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        (**self).eval(cos_theta)
    }
}

/// The Fresnel term 1 (every microfacet is a perfect mirror): for white-furnace tests.
///
/// `eval` returns (1, 1, 1) for every input, NaN included.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoFresnel;

impl Fresnel for NoFresnel {
    #[inline]
    fn eval(&self, _cos_theta: f32) -> Vec3 {
        Vec3::ONE
    }
}

/// Schlick's approximation with a given normal-incidence reflectance: see [`schlick`].
///
/// # Reference
/// \[Schlick1994\], eq. 24.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchlickFresnel {
    /// Reflectance at normal incidence per channel, in [0, 1].
    pub f0: Vec3,
}

impl SchlickFresnel {
    /// A Schlick term with normal-incidence reflectance `f0`.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the channel (`f0.x`, `f0.y`, `f0.z`) when one is not finite
    /// or outside [0, 1].
    pub fn new(f0: Vec3) -> Result<Self> {
        for (name, v) in [("f0.x", f0.x), ("f0.y", f0.y), ("f0.z", f0.z)] {
            if !(0.0..=1.0).contains(&finite(name, v)?) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v as f64,
                    reason: "must be finite and in [0, 1]",
                });
            }
        }
        Ok(SchlickFresnel { f0 })
    }

    /// A Schlick term for a dielectric of relative index `eta`: f0 = [`f0_from_ior`]`(eta)` in every
    /// channel.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `eta` when it is not finite and > 0.
    pub fn from_ior(eta: f32) -> Result<Self> {
        let eta = positive("eta", eta)?;
        Ok(SchlickFresnel {
            f0: Vec3::splat(f0_from_ior(eta)),
        })
    }
}

impl Fresnel for SchlickFresnel {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        schlick(self.f0, cos_theta)
    }
}

/// Exact Fresnel reflectance of a smooth dielectric interface (grey): see [`dielectric`].
///
/// `eta` = n_inside / n_outside; `eval` with a negative cosine means incidence from inside.
///
/// # Reference
/// \[BornWolf1999\], §1.5.2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DielectricFresnel {
    /// Relative index of refraction n_inside / n_outside, finite and > 0.
    pub eta: f32,
}

impl DielectricFresnel {
    /// A dielectric interface of relative index `eta` = n_inside / n_outside (e.g. 1.5 for glass in
    /// air).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `eta` when it is not finite and > 0.
    pub fn new(eta: f32) -> Result<Self> {
        Ok(DielectricFresnel {
            eta: positive("eta", eta)?,
        })
    }
}

impl Fresnel for DielectricFresnel {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        Vec3::splat(dielectric(cos_theta, self.eta))
    }
}

/// Exact Fresnel reflectance of a conductor with complex index η + iκ per channel: see [`conductor`].
///
/// Presets ([`ConductorFresnel::GOLD`], [`SILVER`](ConductorFresnel::SILVER),
/// [`COPPER`](ConductorFresnel::COPPER), [`ALUMINIUM`](ConductorFresnel::ALUMINIUM)) give η and κ at
/// 650, 550 and 450 nm for the R, G and B channels, relative to vacuum (dividing by air's index
/// 1.0003 changes F0 by at most 9e-5).
///
/// # Reference
/// \[BornWolf1999\], §14.2; data: \[JohnsonChristy1972\], \[Rakic1995\] via \[Polyanskiy2024\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConductorFresnel {
    /// Real part η of the complex index per channel, finite and > 0.
    pub eta: Vec3,
    /// Extinction coefficient κ per channel, finite and ≥ 0.
    pub k: Vec3,
}

impl ConductorFresnel {
    /// Gold: Johnson & Christy (1972), "Optical constants of the noble metals", Phys. Rev. B 6, 4370,
    /// as tabulated in the refractiveindex.info database (M. N. Polyanskiy, dataset
    /// `main/Au/nk/Johnson.yml`), linearly interpolated in wavelength to 650 / 550 / 450 nm and rounded
    /// to three decimals (\[JohnsonChristy1972\], \[Polyanskiy2024\]). F0 ≈ (0.956, 0.792, 0.408).
    pub const GOLD: ConductorFresnel = ConductorFresnel {
        eta: Vec3::new(0.156, 0.424, 1.383),
        k: Vec3::new(3.602, 2.472, 1.916),
    };

    /// Silver: Johnson & Christy (1972), refractiveindex.info dataset `main/Ag/nk/Johnson.yml`,
    /// interpolated as for [`ConductorFresnel::GOLD`]. F0 ≈ (0.990, 0.983, 0.980).
    pub const SILVER: ConductorFresnel = ConductorFresnel {
        eta: Vec3::new(0.052, 0.060, 0.040),
        k: Vec3::new(4.409, 3.597, 2.648),
    };

    /// Copper: Johnson & Christy (1972), refractiveindex.info dataset `main/Cu/nk/Johnson.yml`,
    /// interpolated as for [`ConductorFresnel::GOLD`]. F0 ≈ (0.935, 0.623, 0.538).
    pub const COPPER: ConductorFresnel = ConductorFresnel {
        eta: Vec3::new(0.238, 1.007, 1.240),
        k: Vec3::new(3.626, 2.582, 2.393),
    };

    /// Aluminium: Rakić (1995), "Algorithm for the determination of intrinsic optical constants of
    /// metal films: application to aluminum", Appl. Opt. 34, 4755, as tabulated in the
    /// refractiveindex.info database (dataset `main/Al/nk/Rakic.yml`), interpolated as for
    /// [`ConductorFresnel::GOLD`] (\[Rakic1995\], \[Polyanskiy2024\]). F0 ≈ (0.906, 0.915, 0.922).
    pub const ALUMINIUM: ConductorFresnel = ConductorFresnel {
        eta: Vec3::new(1.558, 1.015, 0.633),
        k: Vec3::new(7.712, 6.627, 5.454),
    };

    /// A conductor with complex index `eta` + i`k` per channel, relative to the outside medium.
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming the channel (`eta.x` … `k.z`) when an `eta` is not finite
    /// and > 0 or a `k` is not finite and ≥ 0.
    pub fn new(eta: Vec3, k: Vec3) -> Result<Self> {
        positive("eta.x", eta.x)?;
        positive("eta.y", eta.y)?;
        positive("eta.z", eta.z)?;
        non_negative("k.x", k.x)?;
        non_negative("k.y", k.y)?;
        non_negative("k.z", k.z)?;
        Ok(ConductorFresnel { eta, k })
    }

    /// Normal-incidence reflectance [`f0_from_conductor`]`(eta, k)`, e.g. to build a
    /// [`SchlickFresnel`] that approximates this conductor.
    #[inline]
    pub fn f0(&self) -> Vec3 {
        f0_from_conductor(self.eta, self.k)
    }
}

impl Fresnel for ConductorFresnel {
    #[inline]
    fn eval(&self, cos_theta: f32) -> Vec3 {
        conductor(cos_theta, self.eta, self.k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // f32 evaluation of short closed forms of values ≤ 1: a few ulp(1); 1e-6 is a safe absolute bound.
    const F32_TOL: f32 = 1e-6;

    #[test]
    fn normal_incidence_matches_f0() {
        for eta in [1.0f32, 1.33, 1.5, 2.4, 0.5, 1.0 / 1.5] {
            let f0 = ((eta as f64 - 1.0) / (eta as f64 + 1.0)).powi(2) as f32;
            assert!((dielectric(1.0, eta) - f0).abs() < F32_TOL, "{eta}");
            // From inside at normal incidence the reflectance is the same.
            assert!((dielectric(-1.0, eta) - f0).abs() < F32_TOL, "{eta}");
            assert!((f0_from_ior(eta) - f0).abs() < F32_TOL);
        }
        assert!((dielectric(1.0, 1.5) - 0.04).abs() < F32_TOL);
        let g = ConductorFresnel::GOLD;
        assert!((conductor(1.0, g.eta, g.k) - g.f0()).abs().max_element() < F32_TOL);
    }

    #[test]
    fn grazing_and_total_internal_reflection_are_one() {
        assert_eq!(dielectric(0.0, 1.5), 1.0);
        assert_eq!(dielectric(-0.0, 1.5), 1.0);
        assert_eq!(dielectric(0.0, 0.7), 1.0);
        // Critical angle from inside glass: sin θ_c = 1/1.5; beyond it, exactly 1.
        let cos_c = (1.0f32 - 1.0 / 2.25).sqrt();
        assert_eq!(dielectric(-(cos_c - 1e-3), 1.5), 1.0);
        assert_eq!(dielectric(-0.1, 1.5), 1.0);
        assert!(dielectric(-(cos_c + 1e-3), 1.5) < 1.0);
        assert_eq!(
            conductor(0.0, Vec3::splat(0.2), Vec3::splat(3.0)),
            Vec3::ONE
        );
        assert_eq!(
            conductor(-0.5, Vec3::splat(0.2), Vec3::splat(3.0)),
            Vec3::ONE
        );
        // κ = 0, η = 1 at grazing incidence: 0/0 in the closed form; the index-matched channel
        // has no interface and reflects nothing, as the dielectric (η = 1) does.
        assert_eq!(conductor(0.0, Vec3::ONE, Vec3::ZERO), Vec3::ZERO);
        assert_eq!(dielectric(0.0, 1.0), 0.0);
        assert_eq!(schlick(Vec3::splat(0.04), 0.0), Vec3::ONE);
        assert_eq!(schlick(Vec3::splat(0.04), 1.0), Vec3::splat(0.04));
    }

    #[test]
    fn out_of_domain_values_are_documented() {
        for eta in [0.0f32, -1.5, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert_eq!(dielectric(0.5, eta), 0.0, "{eta}");
            assert_eq!(dielectric(-0.5, eta), 0.0, "{eta}");
            assert_eq!(f0_from_ior(eta), 0.0, "{eta}");
            assert_eq!(conductor(0.5, Vec3::splat(eta), Vec3::ONE), Vec3::ZERO);
            assert_eq!(f0_from_conductor(Vec3::splat(eta), Vec3::ONE), Vec3::ZERO);
        }
        for k in [-1e-3f32, f32::NAN, f32::INFINITY] {
            assert_eq!(conductor(0.5, Vec3::ONE, Vec3::splat(k)), Vec3::ZERO, "{k}");
            assert_eq!(f0_from_conductor(Vec3::ONE, Vec3::splat(k)), Vec3::ZERO);
        }
        assert_eq!(dielectric(f32::NAN, 1.5), 0.0);
        assert_eq!(conductor(f32::NAN, Vec3::ONE, Vec3::ONE), Vec3::ZERO);
        assert_eq!(schlick(Vec3::splat(0.5), f32::NAN), Vec3::ZERO);
        // f0 is clamped into [0, 1], NaN counting as 0 (then F = (1 − cos θ)⁵).
        let f = schlick(Vec3::new(f32::NAN, -1.0, 2.0), 0.5);
        assert_eq!(f, Vec3::new(0.03125, 0.03125, 1.0));
        // Cosines beyond ±1 are clamped.
        assert_eq!(dielectric(1.5, 1.5), dielectric(1.0, 1.5));
        assert_eq!(dielectric(-1.5, 1.5), dielectric(-1.0, 1.5));
        // Extreme but valid indices: the limit 1, never NaN.
        for eta in [1e-30f32, 1e-40, 1e30, f32::MAX] {
            for c in [-1.0f32, -0.5, 0.5, 1.0] {
                let r = dielectric(c, eta);
                assert!((0.0..=1.0).contains(&r), "{c} {eta}: {r}");
            }
            let r = conductor(0.5, Vec3::splat(eta), Vec3::splat(eta));
            assert!(
                r.cmpge(Vec3::ZERO).all() && r.cmple(Vec3::ONE).all(),
                "{eta}: {r}"
            );
        }
        assert_eq!(NoFresnel.eval(f32::NAN), Vec3::ONE);
    }

    #[test]
    fn constructors_validate_and_name_the_parameter() {
        assert!(SchlickFresnel::new(Vec3::new(0.0, 0.5, 1.0)).is_ok());
        let e = SchlickFresnel::new(Vec3::new(0.5, 1.5, 0.5)).unwrap_err();
        assert!(e.to_string().contains("f0.y"), "{e}");
        assert!(SchlickFresnel::new(Vec3::new(0.5, 0.5, f32::NAN)).is_err());
        assert!(SchlickFresnel::new(Vec3::new(-0.1, 0.5, 0.5)).is_err());
        assert_eq!(
            SchlickFresnel::from_ior(1.5).unwrap().f0,
            Vec3::splat(f0_from_ior(1.5))
        );
        assert!(SchlickFresnel::from_ior(0.0).is_err());
        assert!(DielectricFresnel::new(1.5).is_ok());
        for bad in [0.0f32, -1.0, f32::NAN, f32::INFINITY] {
            let e = DielectricFresnel::new(bad).unwrap_err();
            assert!(e.to_string().contains("eta"), "{e}");
        }
        let e = ConductorFresnel::new(Vec3::new(1.0, 0.0, 1.0), Vec3::ONE).unwrap_err();
        assert!(e.to_string().contains("eta.y"), "{e}");
        let e = ConductorFresnel::new(Vec3::ONE, Vec3::new(1.0, 1.0, -1.0)).unwrap_err();
        assert!(e.to_string().contains("k.z"), "{e}");
        assert!(ConductorFresnel::new(Vec3::ONE, Vec3::ZERO).is_ok());
        for c in [
            ConductorFresnel::GOLD,
            ConductorFresnel::SILVER,
            ConductorFresnel::COPPER,
            ConductorFresnel::ALUMINIUM,
        ] {
            assert_eq!(ConductorFresnel::new(c.eta, c.k).unwrap(), c);
        }
    }

    #[test]
    fn trait_objects_and_references_forward() {
        let d = DielectricFresnel::new(1.5).unwrap();
        let boxed: Box<dyn Fresnel> = Box::new(d);
        assert_eq!(boxed.eval(0.3), Vec3::splat(dielectric(0.3, 1.5)));
        assert_eq!(<&DielectricFresnel as Fresnel>::eval(&&d, 0.3), d.eval(0.3));
        let s = SchlickFresnel::new(Vec3::splat(0.04)).unwrap();
        assert_eq!(s.eval(0.3), schlick(Vec3::splat(0.04), 0.3));
        let c = ConductorFresnel::COPPER;
        assert_eq!(c.eval(0.3), conductor(0.3, c.eta, c.k));
    }
}
