//! Normal distribution functions (NDFs) and their Smith masking terms.
//!
//! Frame: local shading frame, z = geometric normal; `w`, `wo`, `m` are unit vectors pointing away from
//! the surface. Every NDF is normalised so that ∫ D(m) (m·ω_g) dm = 1 over the hemisphere.

mod beckmann;
mod beckmann_guess;
mod blinn_phong;
mod ggx;
mod masking;
mod phong_integral;

pub use beckmann::{
    Beckmann, MAX_ALPHA, MIN_ALPHA, alpha_from_roughness, beckmann_alpha_from_shininess,
    shininess_from_beckmann_alpha,
};
pub use blinn_phong::{BlinnPhong, MAX_GAMMA, MAX_VISIBLE_TRIES};
pub use ggx::Ggx;
pub use masking::{
    g1_vcavity, g2_height_correlated_from_lambda, g2_separable_from_lambda, g2_vcavity,
};
pub use phong_integral::{phong_lobe_integral, phong_lobe_integral_arvo};

use glam::{Vec2, Vec3};

pub(crate) mod gauss;
mod slope_gaussian;
pub use slope_gaussian::*;

/// A microfacet normal distribution with its Smith masking function and samplers.
///
/// Conventions (see the crate docs): `d(m)` is a density per unit solid angle of micronormals with
/// ∫ D(m) cos θ_m dm = 1; `projected_area(w)` is A(w), the microsurface's projected area toward `w` per
/// unit geometric area; Smith's identity ∫ ⟨w, m⟩ D(m) dm = A(w) (1 + Λ(w)) defines Λ.
///
/// Every method is total: below-horizon, zero-length or non-finite arguments give 0 (or, for the
/// samplers, a valid upper-hemisphere normal), never NaN, never a panic.
///
/// **The density contract** (every NDF and glint patch of the crate, but for now the mixture's
/// patch, whose densities sum its lobes without the slope truncation of its D; tests/it/pdf_contract.rs):
/// `pdf_normal(m)` and `pdf_visible(wo, m)` are 0 wherever `d(m)` is 0, and `pdf_visible` is 0 for
/// every invalid `wo` (at or below the horizon, −0.0, zero, non-finite) even though
/// `sample_visible` still returns a normal there. A sampler may draw normals where its density is 0
/// (the tails of lobes that D truncates, or where D rounds to 0 in `f32`); `MicrofacetBrdf::sample`
/// returns `None` for them, so the BRDF's pdf remains the density of the directions it produces.
/// `pdf_visible` computes ⟨wo, m⟩ as `wo.dot(m)` in `f32`. `MicrofacetBrdf` forms its density from
/// [`Ndf::pdf_visible_over_cos_given_d`] (D_wo(m)/⟨wo, m⟩, the factor that the reflection Jacobian
/// cancels, left out) and [`Ndf::pdf_normal_over_cos_given_d`], so that neither underflows at
/// grazing views (src/bxdf/microfacet.rs, "Sample weights").
pub trait Ndf {
    /// D(m): micronormal density per unit solid angle. 0 for m below the horizon.
    fn d(&self, m: Vec3) -> f32;

    /// Smith Λ(w). 0 at normal incidence for centred NDFs; large but finite when `w` sees nothing.
    fn lambda(&self, w: Vec3) -> f32;

    /// A(w): projected area of the microsurface toward `w` per unit geometric area.
    /// cos θ_w for a centred NDF (the default), 0 below the horizon or for a non-finite `w`.
    fn projected_area(&self, w: Vec3) -> f32 {
        if w.is_finite() { w.z.max(0.0) } else { 0.0 }
    }

    /// ∫ ⟨w, m⟩ D(m) dm = A(w) (1 + Λ(w)): the projected area of the micronormals that face `w`.
    ///
    /// Masking, visible-normal densities and the microfacet BRDF are written with this quantity so
    /// that no term divides by a vanishing A(w). Override it where it has a form more robust than the
    /// product (non-centred lobes, patches).
    fn visible_area(&self, w: Vec3) -> f32 {
        let a = self.projected_area(w);
        let v = a * (1.0 + self.lambda(w));
        if a > 0.0 && v.is_finite() { v } else { 0.0 }
    }

    /// Smith masking G1(w, m) = χ⁺(w·m) / (1 + Λ(w)) = χ⁺(w·m) A(w) / ∫⟨w, m'⟩ D dm'.
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        if !(w.z > 0.0 && w.dot(m) > 0.0) {
            return 0.0;
        }
        let v = self.visible_area(w);
        if v > 0.0 {
            (self.projected_area(w) / v).clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Separable (uncorrelated) masking-shadowing G2 = G1(wo, m) · G1(wi, m).
    fn g2(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        self.g1(wo, m) * self.g1(wi, m)
    }

    /// Height-correlated masking-shadowing G2 = χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi))
    /// (Heitz 2014, eq. 99).
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        if !(wo.z > 0.0 && wi.z > 0.0 && wo.dot(m) > 0.0 && wi.dot(m) > 0.0) {
            return 0.0;
        }
        let g = 1.0 / (1.0 + self.lambda(wo) + self.lambda(wi));
        if g.is_finite() {
            g.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    /// Draws a micronormal m with density D(m) cos θ_m (per unit solid angle), from `u` ∈ [0, 1)².
    fn sample_normal(&self, u: Vec2) -> Vec3;

    /// Density of [`Ndf::sample_normal`]: D(m) cos θ_m (0 where that is not finite, e.g. for a
    /// non-finite m, where 0 · ∞ would be NaN; 0 wherever D is).
    fn pdf_normal(&self, m: Vec3) -> f32 {
        let p = self.d(m) * m.z.max(0.0);
        if p.is_finite() { p } else { 0.0 }
    }

    /// Draws a micronormal visible from `wo`, with density D_wo(m) = G1(wo, m) ⟨wo, m⟩ D(m) / A(wo).
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3;

    /// Density of [`Ndf::sample_visible`]: D_wo(m) = χ⁺(wo·m) ⟨wo, m⟩ D(m) / ∫⟨wo, m'⟩ D dm', with
    /// ⟨wo, m⟩ = `wo.dot(m)`; 0 wherever D is and for invalid `wo` (the density contract above).
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        if !(wo.z > 0.0 && c > 0.0) {
            return 0.0;
        }
        let v = self.visible_area(wo);
        if v > 0.0 {
            let p = c * self.d(m) / v;
            if p.is_finite() { p } else { 0.0 }
        } else {
            0.0
        }
    }

    /// V(wo) for the view direction of a shading query: the same number as
    /// [`Ndf::visible_area`]`(wo)`. `MicrofacetBrdf` asks for V at its `wo` through this method
    /// and for V at its `wi` through `visible_area`, so that an NDF whose V costs a pass over many
    /// lobes may answer from a V(wo) computed once by an explicit step for the view it was
    /// prepared for (the glint patches' `prepare_view`; docs/architecture.md, "The view step"),
    /// never from state a query filled. Never override it with another value than
    /// `visible_area(wo)`.
    fn view_visible_area(&self, wo: Vec3) -> f32 {
        self.visible_area(wo)
    }

    /// [`Ndf::pdf_normal`]`(m)` for a caller that has already evaluated `d_m` = `self.d(m)`
    /// (`MicrofacetBrdf::eval_pdf` evaluates D at the half vector for f): the same number, without
    /// evaluating D again where the density needs it (the density contract's `d(m) = 0` check of
    /// a truncated mixture). The default ignores `d_m`. `d_m` must be `self.d(m)`.
    fn pdf_normal_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        let _ = d_m;
        self.pdf_normal(m)
    }

    /// [`Ndf::pdf_visible`]`(wo, m)` for a caller that has already evaluated `d_m` = `self.d(m)`:
    /// the same number (see [`Ndf::pdf_normal_given_d`]). The default ignores `d_m`. `d_m` must be
    /// `self.d(m)`.
    fn pdf_visible_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        let _ = d_m;
        self.pdf_visible(wo, m)
    }

    /// D_wo(m) / ⟨wo, m⟩ = χ⁺(wo·m) D(m) / V(wo) (with `d_m` = `self.d(m)` already evaluated): the
    /// visible-normal density without its factor ⟨wo, m⟩, which the reflection Jacobian
    /// 1/(4 ⟨wo, m⟩) of `MicrofacetBrdf` cancels (\[Heitz2014\] eq. 16 with \[Walter2007\] eq. 14).
    /// Formed without that factor, it does not underflow at grazing views, where ⟨wo, m⟩ may be
    /// 10⁻³⁰ while the BRDF's value is large. 0 exactly where [`Ndf::pdf_visible`] is 0 for a
    /// reason other than rounding (invalid `wo`, wo·m ≤ 0, D = 0).
    ///
    /// The default divides [`Ndf::pdf_visible_given_d`] by `wo.dot(m)`, so that an NDF whose
    /// visible density is not ⟨wo, m⟩ D / V keeps its own (it may still underflow where ⟨wo, m⟩
    /// is tiny); NDFs whose density is that product override it with D / V.
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        let c = wo.dot(m);
        if c.is_nan() || c <= 0.0 {
            return 0.0;
        }
        let p = self.pdf_visible_given_d(wo, m, d_m) / c;
        if p.is_finite() { p } else { 0.0 }
    }

    /// pdf_normal(m) / cos θ_m (with `d_m` = `self.d(m)` already evaluated): the normal density
    /// without its factor cos θ_m, so that `MicrofacetBrdf` can tell a density that is positive
    /// but below `f32`'s range (m near the horizon) from one that is 0. 0 exactly where
    /// [`Ndf::pdf_normal`] is 0 for a reason other than rounding.
    ///
    /// The default divides [`Ndf::pdf_normal_given_d`] by m_z; NDFs whose normal density is
    /// D(m) cos θ_m override it with D.
    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        if m.z.is_nan() || m.z <= 0.0 {
            return 0.0;
        }
        let p = self.pdf_normal_given_d(m, d_m) / m.z;
        if p.is_finite() { p } else { 0.0 }
    }
}

/// D / V: [`Ndf::pdf_visible_over_cos_given_d`] of an NDF whose visible density is
/// χ⁺(wo·m) ⟨wo, m⟩ D(m) / V(wo), with V = `v` already evaluated; 0 for invalid `wo`, wo·m ≤ 0,
/// m below the horizon, D ≤ 0 or a non-finite result.
#[inline]
pub(crate) fn visible_over_cos(wo: Vec3, m: Vec3, d_m: f32, v: f32) -> f32 {
    if !(wo.z > 0.0 && m.z > 0.0 && wo.dot(m) > 0.0 && d_m > 0.0 && v > 0.0) {
        return 0.0;
    }
    let p = d_m / v;
    if p.is_finite() { p } else { 0.0 }
}

/// D: [`Ndf::pdf_normal_over_cos_given_d`] of an NDF whose normal density is D(m) cos θ_m; 0 for
/// m below the horizon, non-finite m or D.
#[inline]
pub(crate) fn normal_over_cos(m: Vec3, d_m: f32) -> f32 {
    if m.z > 0.0 && m.is_finite() && d_m.is_finite() && d_m > 0.0 {
        d_m
    } else {
        0.0
    }
}

/// Λ(w) = V(w)/A(w) − 1 from an NDF's own visible and projected areas: Smith's identity read
/// backwards, for the NDFs whose V and A are the primary quantities (the glint patches, \[Chermain2019\]
/// eq. 15). 0 for a below-horizon or non-finite `w`; `f32::MAX` where A(w) ≤ 0 < w_z (a patch leaning
/// away from `w`: nothing of it is seen).
#[cfg(feature = "std")] // used by the glint layer
pub(crate) fn lambda_from_areas<N: Ndf + ?Sized>(ndf: &N, w: Vec3) -> f32 {
    lambda_of(w, |w| ndf.projected_area(w), |w| ndf.visible_area(w))
}

/// [`lambda_from_areas`] with the two areas given as functions (for a patch that has several ways
/// of computing V, e.g. the mixture's scalar and block sums).
#[cfg(feature = "std")] // used by the glint layer
pub(crate) fn lambda_of(
    w: Vec3,
    projected_area: impl FnOnce(Vec3) -> f32,
    visible_area: impl FnOnce(Vec3) -> f32,
) -> f32 {
    if !(w.z > 0.0 && w.is_finite()) {
        return 0.0;
    }
    let a = projected_area(w);
    if a.is_nan() || a <= 0.0 {
        return f32::MAX;
    }
    ((visible_area(w) as f64 / a as f64 - 1.0).max(0.0) as f32).min(f32::MAX)
}

/// Implements every method of [`Ndf`] for a type that hands each call to an NDF it holds: `$dispatch!`
/// is a macro of the form `($s:ident, $n:ident => $e:expr)` that binds the inner NDF of `$s` to `$n`
/// and evaluates `$e` (a `match` over an enum's variants, or a dereference). Written once, so every
/// forwarding type forwards every method, the default ones included (an inner NDF that overrides a
/// default keeps its override behind the wrapper); the unit test
/// `forward_ndf_names_every_method_of_the_trait` fails when the trait gains a method this list lacks.
/// `[$generics]` are the impl's generic parameters, possibly empty.
macro_rules! forward_ndf {
    ([$($generics:tt)*] $ty:ty, $dispatch:ident) => {
        impl<$($generics)*> $crate::ndf::Ndf for $ty {
            #[inline]
            fn d(&self, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.d(m))
            }
            #[inline]
            fn lambda(&self, w: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.lambda(w))
            }
            #[inline]
            fn projected_area(&self, w: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.projected_area(w))
            }
            #[inline]
            fn visible_area(&self, w: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.visible_area(w))
            }
            #[inline]
            fn g1(&self, w: glam::Vec3, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.g1(w, m))
            }
            #[inline]
            fn g2(&self, wo: glam::Vec3, wi: glam::Vec3, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.g2(wo, wi, m))
            }
            #[inline]
            fn g2_height_correlated(&self, wo: glam::Vec3, wi: glam::Vec3, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.g2_height_correlated(wo, wi, m))
            }
            #[inline]
            fn sample_normal(&self, u: glam::Vec2) -> glam::Vec3 {
                $dispatch!(self, n => n.sample_normal(u))
            }
            #[inline]
            fn pdf_normal(&self, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.pdf_normal(m))
            }
            #[inline]
            fn sample_visible(&self, wo: glam::Vec3, u: glam::Vec2) -> glam::Vec3 {
                $dispatch!(self, n => n.sample_visible(wo, u))
            }
            #[inline]
            fn pdf_visible(&self, wo: glam::Vec3, m: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.pdf_visible(wo, m))
            }
            #[inline]
            fn view_visible_area(&self, wo: glam::Vec3) -> f32 {
                $dispatch!(self, n => n.view_visible_area(wo))
            }
            #[inline]
            fn pdf_normal_given_d(&self, m: glam::Vec3, d_m: f32) -> f32 {
                $dispatch!(self, n => n.pdf_normal_given_d(m, d_m))
            }
            #[inline]
            fn pdf_visible_given_d(&self, wo: glam::Vec3, m: glam::Vec3, d_m: f32) -> f32 {
                $dispatch!(self, n => n.pdf_visible_given_d(wo, m, d_m))
            }
            #[inline]
            fn pdf_visible_over_cos_given_d(&self, wo: glam::Vec3, m: glam::Vec3, d_m: f32) -> f32 {
                $dispatch!(self, n => n.pdf_visible_over_cos_given_d(wo, m, d_m))
            }
            #[inline]
            fn pdf_normal_over_cos_given_d(&self, m: glam::Vec3, d_m: f32) -> f32 {
                $dispatch!(self, n => n.pdf_normal_over_cos_given_d(m, d_m))
            }
        }
    };
}
#[cfg(feature = "std")]
pub(crate) use forward_ndf;

/// The dispatch of a reference: binds `$n` to the referent.
macro_rules! deref_dispatch {
    ($s:ident, $n:ident => $e:expr) => {{
        let $n = &**$s;
        $e
    }};
}
pub(crate) use deref_dispatch;

// A reference to an NDF is an NDF (so a BRDF can borrow a patch or a shared lobe).
forward_ndf!([T: Ndf + ?Sized] &T, deref_dispatch);

#[cfg(test)]
pub(crate) mod forwarding_tests {
    use std::collections::BTreeSet;

    /// The names of the `fn`s in `text` (comment lines skipped).
    pub(crate) fn fn_names(text: &str) -> BTreeSet<String> {
        text.lines()
            .map(str::trim_start)
            .filter(|l| !l.starts_with("//"))
            .filter_map(|l| l.split("fn ").nth(1))
            .map(|rest| rest.split('(').next().unwrap_or("").trim().to_string())
            .collect()
    }

    /// The text from the line that starts with `head` to the first line that is `}` alone.
    pub(crate) fn block<'a>(src: &'a str, head: &str) -> &'a str {
        let start = src.find(head).expect("block head");
        let len = src[start..].find("\n}\n").expect("block end");
        &src[start..start + len]
    }

    #[test]
    fn forward_ndf_names_every_method_of_the_trait() {
        let src = include_str!("mod.rs");
        let methods = fn_names(block(src, "pub trait Ndf {"));
        let forwarded = fn_names(block(src, "macro_rules! forward_ndf {"));
        assert!(methods.len() >= 16, "{methods:?}");
        assert_eq!(methods, forwarded);
    }
}
