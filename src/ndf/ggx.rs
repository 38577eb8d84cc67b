//! The anisotropic GGX (Trowbridge–Reitz) NDF with its exact Smith Λ and exact samplers.
//!
//! GGX is the distribution of normals of a stretched ellipsoid; its slopes follow a bivariate
//! Student-t with 2 degrees of freedom. D and Λ follow Walter et al. 2007 and Heitz 2014 (anisotropic
//! form); visible normals are sampled with Heitz 2018's hemisphere-projection routine.

use super::Ndf;
use super::beckmann::{keep_visible, unit_square, validated_alpha, validated_alphas};
use crate::Result;
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::frame::normalize_robust;
use core::f32::consts::PI;
use glam::{Vec2, Vec3};

/// The anisotropic GGX (Trowbridge–Reitz) distribution.
///
/// D(m) = 1 / (π α_x α_y cos⁴θ_m (1 + tan²θ_m (cos²φ_m/α_x² + sin²φ_m/α_y²))²)
///      = 1 / (π α_x α_y ((x/α_x)² + (y/α_y)² + z²)²) for m = (x, y, z), z > 0.
///
/// α is clamped to ≥ [`MIN_ALPHA`](super::MIN_ALPHA) = 10⁻⁴ like [`Beckmann`](super::Beckmann) (D(ω_g) = 1/(π α_x α_y)
/// stays ≤ 3.2·10⁷).
///
/// # Reference
/// \[Walter2007\] §5.2 (isotropic D, Λ), \[Heitz2014\] (anisotropic D and Λ), \[Heitz2018\] and
/// \[DupuyBenyoub2023\] (visible normals).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ggx {
    alpha_x: f32,
    alpha_y: f32,
    /// 1/α_x, 1/α_y and 1/(π α_x α_y), precomputed so that `d` has one division.
    inv_alpha_x: f32,
    inv_alpha_y: f32,
    norm: f32,
}

impl Ggx {
    /// An anisotropic GGX NDF with roughness `alpha_x` along x and `alpha_y` along y.
    ///
    /// Errors if either is non-finite, ≤ 0 or above [`MAX_ALPHA`](super::MAX_ALPHA) (naming
    /// `alpha_x` or `alpha_y`); values below [`MIN_ALPHA`](super::MIN_ALPHA) are clamped to it.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Result<Self> {
        let (alpha_x, alpha_y) = validated_alphas(alpha_x, alpha_y)?;
        Ok(Self::from_valid(alpha_x, alpha_y))
    }

    /// An isotropic GGX NDF; errors (naming `alpha`) if `alpha` is non-finite or ≤ 0.
    pub fn isotropic(alpha: f32) -> Result<Self> {
        let alpha = validated_alpha(alpha)?;
        Ok(Self::from_valid(alpha, alpha))
    }

    /// The NDF from validated, clamped α.
    fn from_valid(alpha_x: f32, alpha_y: f32) -> Self {
        Ggx {
            alpha_x,
            alpha_y,
            inv_alpha_x: 1.0 / alpha_x,
            inv_alpha_y: 1.0 / alpha_y,
            norm: 1.0 / (PI * alpha_x * alpha_y),
        }
    }

    /// α along x (after the clamp).
    pub fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    /// α along y (after the clamp).
    pub fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    /// |(α_x x, α_y y)| = α(φ) sin θ for a unit w, or `None` below the horizon / non-finite.
    #[inline]
    fn stretched_sin(&self, w: Vec3) -> Option<f32> {
        (w.z > 0.0 && w.is_finite())
            .then(|| Vec2::new(self.alpha_x * w.x, self.alpha_y * w.y).length())
    }
}

impl Ndf for Ggx {
    /// D(m) = 1 / (π α_x α_y ((x/α_x)² + (y/α_y)² + z²)²); 0 for z ≤ 0 or non-finite m.
    ///
    /// Checked last: the plain arithmetic runs first and one comparison rejects z ≤ 0 and a
    /// non-finite result (NaN input, or a squared sum that under- or overflows).
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        let (sx, sy) = (m.x * self.inv_alpha_x, m.y * self.inv_alpha_y);
        let t = sx * sx + sy * sy + m.z * m.z;
        let d = self.norm / (t * t);
        if m.z > 0.0 && d <= f32::MAX { d } else { 0.0 }
    }

    /// Λ(w) = (√(1 + α(φ)² tan²θ) − 1)/2, written as n²/(2z(√(z² + n²) + z)) with
    /// n = α(φ) sin θ, z = cos θ (no cancellation near normal incidence). 0 below the horizon;
    /// finite (capped at `f32::MAX`) at grazing.
    #[inline]
    fn lambda(&self, w: Vec3) -> f32 {
        let Some(n) = self.stretched_sin(w) else {
            return 0.0;
        };
        let z = w.z;
        let r = Vec2::new(z, n).length();
        let l = n * (n / (2.0 * z * (r + z)));
        if l.is_finite() { l } else { f32::MAX }
    }

    /// ∫⟨w, m⟩⁺ D dm = cos θ (1 + Λ) = (z + √(z² + n²))/2: finite down to the horizon.
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        match self.stretched_sin(w) {
            Some(n) => {
                // Finite for unit w; the check keeps an overflowing non-unit w at 0.
                let v = 0.5 * (w.z + Vec2::new(w.z, n).length());
                if v.is_finite() { v } else { 0.0 }
            }
            None => 0.0,
        }
    }

    /// G1(w, m) = χ⁺(w·m) / (1 + Λ(w)) = χ⁺(w·m) 2z / (z + √(z² + n²)), n² = (α_x x)² + (α_y y)²
    /// under one square root. 0 below the horizon, for w·m ≤ 0 and where w·m is not finite (a NaN
    /// or infinite component in w or m); capped at 1 (z² may underflow for z < 10⁻¹⁹), which also
    /// maps the NaN of an infinite z to a finite value.
    ///
    /// # Reference
    /// \[Walter2007\] eq. 34, \[Heitz2014\] eq. 72 (anisotropic form).
    #[inline]
    fn g1(&self, w: Vec3, m: Vec3) -> f32 {
        let c = w.dot(m);
        let (x, y) = (self.alpha_x * w.x, self.alpha_y * w.y);
        let g = 2.0 * w.z / (w.z + (w.z * w.z + x * x + y * y).sqrt());
        if w.z > 0.0 && c > 0.0 && c <= f32::MAX {
            g.min(1.0)
        } else {
            0.0
        }
    }

    /// D_wo(m) = χ⁺(wo·m) ⟨wo, m⟩ D(m) / V(wo) = 2 ⟨wo, m⟩ / (π α_x α_y t² (z + √(z² + n²))),
    /// t = (m_x/α_x)² + (m_y/α_y)² + m_z² (D = 1/(π α_x α_y t²), V = (z + √(z² + n²))/2): one
    /// square root and one division. 0 for degenerate input (below-horizon wo or m, wo·m ≤ 0, NaN
    /// or infinite components, a non-finite result); checked once, on the result.
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16 (the distribution of visible normals).
    #[inline]
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        let c = wo.dot(m);
        let (x, y) = (self.alpha_x * wo.x, self.alpha_y * wo.y);
        let s = (wo.z * wo.z + x * x + y * y).sqrt();
        let (sx, sy) = (m.x * self.inv_alpha_x, m.y * self.inv_alpha_y);
        let t = sx * sx + sy * sy + m.z * m.z;
        let p = (2.0 * self.norm) * c / (t * t * (wo.z + s));
        if wo.z > 0.0 && m.z > 0.0 && c > 0.0 && p <= f32::MAX {
            p
        } else {
            0.0
        }
    }

    /// D(m) / V(wo) with V = (z + √(z² + n²))/2: [`Ndf::pdf_visible`] without its factor
    /// ⟨wo, m⟩, which the reflection Jacobian cancels (no underflow at grazing views).
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16.
    #[inline]
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        let (x, y) = (self.alpha_x * wo.x, self.alpha_y * wo.y);
        let s = (wo.z * wo.z + x * x + y * y).sqrt();
        super::visible_over_cos(wo, m, d_m, 0.5 * (wo.z + s))
    }

    /// D(m): [`Ndf::pdf_normal`] = D cos θ_m without its cosine.
    #[inline]
    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        super::normal_over_cos(m, d_m)
    }

    /// Height-correlated G2 = χ⁺(wo·m) χ⁺(wi·m) / (1 + Λ(wo) + Λ(wi)); 0 for degenerate input.
    fn g2_height_correlated(&self, wo: Vec3, wi: Vec3, m: Vec3) -> f32 {
        super::masking::g2_height_correlated_checked(self, wo, wi, m)
    }

    /// m ~ D(m) cos θ_m by exact inversion: the standard radial slope has CDF r²/(1 + r²), so
    /// r² = u₁/(1 − u₁); the normal ∝ (−α_x √u₁ cos φ, −α_y √u₁ sin φ, √(1 − u₁)) (multiplied
    /// through by √(1 − u₁) so that nothing overflows as u₁ → 1), φ = 2π u₂.
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let u1 = u.x.clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let (s, c) = (2.0 * PI * u.y).sin_cos();
        let r = u1.sqrt();
        Vec3::new(
            -self.alpha_x * r * c,
            -self.alpha_y * r * s,
            (1.0 - u1).sqrt(),
        )
        .try_normalize()
        .unwrap_or(Vec3::Z)
    }

    /// m ~ D_wo(m) exactly, by Dupuy & Benyoub 2023: stretch wo to the hemisphere configuration
    /// (wₕ = normalize(α_x x, α_y y, z)); the visible normals of the unit hemisphere seen from wₕ
    /// are the half vectors c + wₕ of a point c drawn uniformly on the spherical cap
    /// z_c ∈ (−z_h, 1] (z_c = (1 − u₂)(1 + z_h) − z_h, azimuth 2πu₁); unstretch and normalise.
    /// The same distribution as Heitz 2018's disk-projection routine with two square roots fewer.
    /// Below-horizon `wo` falls back to [`Ndf::sample_normal`], as does any non-finite
    /// intermediate (non-finite or zero-length `wo`; checked once, on the result).
    ///
    /// The half vector keeps z ≥ 10⁻³⁰ (u₂ = 1 would put it on the horizon). Where rounding leaves
    /// the result not strictly visible from wo (u₂ within ~10⁻⁶ of 1 with wₕ near the pole or the
    /// horizon, where c + wₕ cancels), the sample is redrawn at the same u by Heitz 2018's routine,
    /// which has no such cancellation and the same distribution.
    ///
    /// # Reference
    /// \[DupuyBenyoub2023\] listing 3 (spherical caps), \[Heitz2018\] (stretch / unstretch).
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(z > 0)` also rejects NaN
    #[inline]
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if !(wo.z > 0.0) {
            return self.sample_normal(u);
        }
        // NaN → 0, clamp to [0, 1]: also what the fallbacks below receive.
        let u = unit_square(u);
        let v = Vec3::new(self.alpha_x * wo.x, self.alpha_y * wo.y, wo.z);
        let wh = v * (1.0 / v.length());
        let (sp, cp) = (2.0 * PI * u.x).sin_cos();
        // z_c + z_h = (1 − u₂)(1 + z_h) ≥ 0, formed without the cancellation of z_c + z_h.
        let hz = (1.0 - u.y) * (1.0 + wh.z);
        // sin θ_c = √((1 + z_c)(1 − z_c)) with 1 + z_c = h_z + (1 − z_h) and
        // 1 − z_h = (x_h² + y_h²)/(1 + z_h): no cancellation where c is nearly −wₕ (u₂ → 1 with
        // wₕ near the pole), where 1 − z_c² in f32 had no correct digit and c + wₕ then pointed
        // anywhere (found by the 200 000-case totality property test).
        let one_minus_zh = (wh.x * wh.x + wh.y * wh.y) / (1.0 + wh.z);
        let one_plus_zc = hz + one_minus_zh;
        let sin_c = (one_plus_zc * (2.0 - one_plus_zc)).max(0.0).sqrt();
        let m = Vec3::new(
            self.alpha_x * (sin_c * cp + wh.x),
            self.alpha_y * (sin_c * sp + wh.y),
            hz.max(1e-30),
        );
        match normalize_robust(m) {
            Some(m) if m.z > 0.0 && m.dot(wo) > 0.0 => m,
            _ => self.sample_visible_disk(wo, u),
        }
    }
}

impl Ggx {
    /// Heitz 2018's disk-projection sampler of D_wo: the fallback of [`Ndf::sample_visible`] where
    /// the spherical cap loses every digit.
    ///
    /// Near the end of the cap (u₂ → 1) the cap point c is nearly −wₕ and the half vector c + wₕ is
    /// a difference of nearly equal `f32` numbers; when wₕ is also near the horizon (grazing wo,
    /// small α) its direction is then rounding noise and may face away from wo. This routine works
    /// in a frame built on wₕ and has no such cancellation. It draws from the same distribution, so
    /// using it on that set (of measure ~10⁻⁶ in u) changes nothing but the u → m mapping there.
    /// Non-finite or below-horizon `wo` falls back to [`Ndf::sample_normal`]; the result keeps
    /// z ≥ 10⁻³⁰ and is nudged toward wo if rounding leaves it orthogonal to wo.
    ///
    /// # Reference
    /// \[Heitz2018\] listing 1.
    #[cold]
    #[inline(never)]
    fn sample_visible_disk(&self, wo: Vec3, u: Vec2) -> Vec3 {
        if !(wo.z > 0.0 && wo.is_finite()) {
            return self.sample_normal(u);
        }
        let Some(vh) = Vec3::new(self.alpha_x * wo.x, self.alpha_y * wo.y, wo.z).try_normalize()
        else {
            return self.sample_normal(u);
        };
        // Orthonormal basis (t1, t2, vh); t1 horizontal.
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = vh.cross(t1);
        // Uniform point on the unit disk, lower half squashed toward the horizon's projection.
        let r = u.x.sqrt();
        let (sp, cp) = (2.0 * PI * u.y).sin_cos();
        let p1 = r * cp;
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * (r * sp);
        let lift = (1.0 - p1 * p1 - p2 * p2).max(1e-14).sqrt();
        let nh = p1 * t1 + p2 * t2 + lift * vh;
        let m = normalize_robust(Vec3::new(
            self.alpha_x * nh.x,
            self.alpha_y * nh.y,
            nh.z.max(1e-30),
        ))
        .unwrap_or(Vec3::Z);
        keep_visible(m, wo)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (200 000-case property test, seed 1): for a tiny α, wo away from the pole
    /// (so wₕ is within 10⁻³ of it) and u₂ at the top of [0, 1), the cap point c is nearly −wₕ;
    /// the half vector c + wₕ must still be visible from wo, with a positive pdf.
    #[test]
    fn sample_visible_near_the_cap_end() {
        let n = Ggx::isotropic(10f32.powf(-3.253_356_2)).unwrap();
        let wo = Vec3::new(-0.860_859_5, -0.116_034_34, 0.495_436_07);
        let mut worst = f32::MAX;
        for k in 0..=64 {
            for uy in [0.999_999_94f32, 0.999_999_9, 0.999_999] {
                let u = Vec2::new(k as f32 / 64.0, uy);
                let m = n.sample_visible(wo, u);
                assert!(m.is_finite() && m.z > 0.0, "{u:?}: {m:?}");
                assert!(n.pdf_visible(wo, m) > 0.0, "{u:?}: {m:?}");
                worst = worst.min(m.dot(wo));
            }
        }
        assert!(worst > 0.0, "{worst}");
    }

    /// Regression (same property test): grazing wo along −x with α = 3.2·10⁻³ puts wₕ near the
    /// horizon; at u = (0, 1 − 2⁻²⁴) the cap's half vector was rounding noise facing away from wo.
    #[test]
    fn sample_visible_grazing_cap_end() {
        let n = Ggx::isotropic(10f32.powf(-2.488_697)).unwrap();
        for wo in [
            Vec3::new(-1.0, -6.036_363_5e-7, 3.114_992_6e-7),
            Vec3::new(0.6, -0.8, 1e-6).normalize(),
        ] {
            for k in 0..=64 {
                for uy in [0.999_999_94f32, 0.999_999_9, 0.999_999] {
                    let u = Vec2::new(k as f32 / 64.0, uy);
                    let m = n.sample_visible(wo, u);
                    assert!(m.is_finite() && m.z > 0.0, "{u:?}: {m:?}");
                    assert!(m.dot(wo) > 0.0, "{wo:?} {u:?}: {m:?}");
                    assert!(n.pdf_visible(wo, m) > 0.0, "{wo:?} {u:?}: {m:?}");
                }
            }
        }
    }
}
