//! The analytic core's float functions without the standard library: one `libm` function each.
//!
//! `f32::sqrt`, `exp`, `ln`, `sin_cos`, … are methods of std, not of core. With the `std` feature
//! the crate calls std's methods and this module is not compiled. Without it, each file of the core
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
