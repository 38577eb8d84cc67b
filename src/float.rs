//! The analytic core's float functions without the standard library: one `libm` function each.
//!
//! `f32::sqrt`, `exp`, `ln`, `sin_cos`, … are methods of std, not of core. With the `std` feature
//! the crate calls std's methods and this module is compiled only for its test. Without it, each file of the core
//! that needs them imports [`Float`] (`#[cfg(not(feature = "std"))] use crate::float::Float as _;`)
//! and the same call sites, `x.sqrt()`, resolve to the trait's methods, which call `libm` (the
//! `f`-suffixed function for `f32`). Inherent methods take precedence over trait methods, so the
//! trait can never change what a std build calls.
//!
//! Two methods are not one libm function: `powi` is libm's `pow` with the integer exponent converted
//! (std's `powi` multiplies repeatedly; the results may differ in the last bits), and `fract` is
//! x − trunc(x), std's own definition.

/// std's float methods that the core calls, for `f32` and `f64`, from `libm`.
pub(crate) trait Float: Sized {
    fn sqrt(self) -> Self;
    fn exp(self) -> Self;
    fn exp2(self) -> Self;
    fn exp_m1(self) -> Self;
    fn ln(self) -> Self;
    fn ln_1p(self) -> Self;
    fn powf(self, n: Self) -> Self;
    fn powi(self, n: i32) -> Self;
    fn sin_cos(self) -> (Self, Self);
    fn acos(self) -> Self;
    fn atan(self) -> Self;
    fn atan2(self, x: Self) -> Self;
    fn round(self) -> Self;
    fn fract(self) -> Self;
}

/// Implements [`Float`] for one float type from the libm functions named for each method.
macro_rules! impl_float {
    ($t:ty, $sqrt:ident, $exp:ident, $exp2:ident, $expm1:ident, $log:ident, $log1p:ident,
     $pow:ident, $sincos:ident, $acos:ident, $atan:ident, $atan2:ident,
     $round:ident, $trunc:ident) => {
        impl Float for $t {
            #[inline]
            fn sqrt(self) -> Self {
                libm::$sqrt(self)
            }
            #[inline]
            fn exp(self) -> Self {
                libm::$exp(self)
            }
            #[inline]
            fn exp2(self) -> Self {
                libm::$exp2(self)
            }
            #[inline]
            fn exp_m1(self) -> Self {
                libm::$expm1(self)
            }
            #[inline]
            fn ln(self) -> Self {
                libm::$log(self)
            }
            #[inline]
            fn ln_1p(self) -> Self {
                libm::$log1p(self)
            }
            #[inline]
            fn powf(self, n: Self) -> Self {
                libm::$pow(self, n)
            }
            #[inline]
            fn powi(self, n: i32) -> Self {
                libm::$pow(self, n as $t)
            }
            #[inline]
            fn sin_cos(self) -> (Self, Self) {
                libm::$sincos(self)
            }
            #[inline]
            fn acos(self) -> Self {
                libm::$acos(self)
            }
            #[inline]
            fn atan(self) -> Self {
                libm::$atan(self)
            }
            #[inline]
            fn atan2(self, x: Self) -> Self {
                libm::$atan2(self, x)
            }
            #[inline]
            fn round(self) -> Self {
                libm::$round(self)
            }
            #[inline]
            fn fract(self) -> Self {
                self - libm::$trunc(self)
            }
        }
    };
}

impl_float!(
    f32, sqrtf, expf, exp2f, expm1f, logf, log1pf, powf, sincosf, acosf, atanf, atan2f, roundf,
    truncf
);
impl_float!(
    f64, sqrt, exp, exp2, expm1, log, log1p, pow, sincos, acos, atan, atan2, round, trunc
);

#[cfg(test)]
mod tests {
    use super::Float;

    /// Each method against std's on a grid of arguments. Both sides are within an ulp or two of
    /// the exact value (libm's and glibc's documented accuracy; `powi` ≤ n/2 ulp more for std's
    /// repeated products), so a relative 1e-6 (f32, ~8 ulp) / 1e-14 (f64) separates them only
    /// where a method calls the wrong function, which is off by far more.
    #[test]
    fn methods_are_the_std_functions() {
        let close32 = |a: f32, b: f32| a == b || (a - b).abs() <= 1e-6 * a.abs().max(b.abs());
        let close64 = |a: f64, b: f64| a == b || (a - b).abs() <= 1e-14 * a.abs().max(b.abs());
        for i in 1..2000 {
            let x = i as f64 / 200.0 - 4.5; // (−4.5, 5.5); both `round`s take ties away from 0
            let (p, f) = (x.abs() + 0.25, x as f32);
            let pf = p as f32;
            let unit = (x / 5.5).clamp(-1.0, 1.0);
            for (mine, std) in [
                (Float::sqrt(pf), pf.sqrt()),
                (Float::exp(f), f.exp()),
                (Float::exp2(f), f.exp2()),
                (Float::exp_m1(f), f.exp_m1()),
                (Float::ln(pf), pf.ln()),
                (Float::ln_1p(pf), pf.ln_1p()),
                (Float::powf(pf, f), pf.powf(f)),
                (Float::powi(f, 5), f.powi(5)),
                (Float::sin_cos(f).0, f.sin()),
                (Float::sin_cos(f).1, f.cos()),
                (Float::acos(unit as f32), (unit as f32).acos()),
                (Float::atan(f), f.atan()),
                (Float::atan2(f, pf), f.atan2(pf)),
                (Float::round(f), f.round()),
                (Float::fract(f), f.fract()),
            ] {
                assert!(close32(mine, std), "f32 at {x}: {mine} against std's {std}");
            }
            for (mine, std) in [
                (Float::sqrt(p), p.sqrt()),
                (Float::exp(x), x.exp()),
                (Float::exp2(x), x.exp2()),
                (Float::exp_m1(x), x.exp_m1()),
                (Float::ln(p), p.ln()),
                (Float::ln_1p(p), p.ln_1p()),
                (Float::powf(p, x), p.powf(x)),
                (Float::powi(x, 5), x.powi(5)),
                (Float::sin_cos(x).0, x.sin()),
                (Float::sin_cos(x).1, x.cos()),
                (Float::acos(unit), unit.acos()),
                (Float::atan(x), x.atan()),
                (Float::atan2(x, p), x.atan2(p)),
                (Float::round(x), x.round()),
                (Float::fract(x), x.fract()),
            ] {
                assert!(close64(mine, std), "f64 at {x}: {mine} against std's {std}");
            }
        }
    }
}
