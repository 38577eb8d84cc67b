//! The non-centred anisotropic Beckmann lobe [`SlopeGaussian`]: a 2D Gaussian of slopes with mean μ
//! and covariance Σ, the building block of the glint mixture of \[Chermain2019\] (§3.2, eq. 2-6).
//!
//! A micronormal m = normalize(−x̃, −ỹ, 1) has slope ñ = (x̃, ỹ); the lobe is the slope density
//! P22(ñ) = exp(−½ (ñ − μ)ᵀ Σ⁻¹ (ñ − μ)) / (2π √|Σ|) and the NDF D(m) = P22(ñ(m)) / cos⁴θ_m.
//! Its masking terms are exact for every view direction w: with the projected slope q = ñ·(cos φ_w,
//! sin φ_w) ~ N(q̄, s²), the signed projected area is A_s = cos θ − sin θ q̄, the visible projected area
//! V(w) = ∫⟨w, m⟩⁺ D dm = s_w G(A_s / s_w) with s_w = sin θ · s and G(z) = E[(z − Z)⁺] the normal ramp,
//! and Λ = V/A − 1 (\[Dupuy2013\], \[Heitz2014\]). Visible normals are sampled exactly by inverting the
//! 1D tilted density ∝ (a − z₁)⁺ φ(z₁) along the view direction in whitened slope space.
//! Derivations: docs/slope_gaussian.md.
//!
//! Per-direction methods do their special-function work in `f64` (libm `erfc`, `exp`), see the
//! costs in docs/results.md; everything else is `f32`.

use super::Ndf;
use super::gauss;
use crate::error::{Error, Result, positive};
#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use crate::math::{finite_f32, finite_or_zero};
use core::f64::consts::{FRAC_1_SQRT_2, PI, SQRT_2};
use glam::{Mat2, Vec2, Vec3};

/// Default floor on the slope standard deviation used by [`SlopeGaussian::from_moments`]:
/// σ_ε = 0.01, the near-specular roughness of \[Chermain2019\] §5.2.2.
pub const DEFAULT_SIGMA_MIN: f32 = 0.01;

/// Smallest `sigma_min` that [`SlopeGaussian::from_moments`] honours (smaller positive values are
/// raised to it): below ~1e-6 the peak density 1/(2π σ²) and L⁻¹ approach the limits of `f32`.
pub const SIGMA_MIN_FLOOR: f32 = 1e-6;

/// Random numbers are clamped into [2⁻²⁶, 1 − 2⁻²⁶] (in `f64`; NaN becomes ½) before they are
/// transformed, so u = 0 and u = 1 − ε give finite normals (at most ~6 standard deviations from the
/// mean). The clamp moves a probability of 2⁻²⁶ ≈ 1.5e-8 per end: far below any test's resolution.
const U_EPS: f64 = 1.0 / (1u64 << 26) as f64;

/// Where a sampled visible normal rounds to ⟨wo, m⟩ ≤ 0 in `f32`, it is moved along wo until
/// ⟨wo, m⟩ = this value (see [`SlopeGaussian::sample_visible`]).
const FACING_NUDGE: f64 = 1e-5;

/// The smallest a = A_s/s_w whose visible draw uses Beckmann's standard visible-slope inversion
/// (`beckmann::visible_slope_x_std`, at cot θ = a/√2, θ ≤ 1.5637 rad: within the range its error
/// test covers, θ ≤ 1.565); below it (views at or past the mean facet's horizon) the `f64` Newton
/// inversion of any real a (`gauss::sample_ramp`).
const A_BECKMANN: f64 = 0.01;

/// 1/(2π).
const FRAC_1_2PI: f32 = 0.159_154_94;

/// The largest slope magnitude a lobe (its mean, and the standard deviation along each axis) may
/// have: 10⁴, i.e. a mean normal at least 10⁻⁴ above the horizon (89.994°). Beyond it the squares of
/// slopes that the samplers and masking terms form approach f32's range, and no surface a renderer
/// shades has such lobes. Equal to [`crate::glint::MAX_SLOPE`], the bound on normal-map slopes.
pub const MAX_SLOPE: f32 = 1.0e4;

/// A non-centred, anisotropic, correlated Beckmann lobe: a 2D Gaussian of microfacet slopes.
///
/// P22(ñ) = exp(−½ (ñ − μ)ᵀ Σ⁻¹ (ñ − μ)) / (2π √|Σ|),  D(m) = P22(ñ(m)) / cos⁴θ_m,
/// with μ = (μx, μy) the mean slope and Σ = [[σx², c], [c, σy²]] the slope covariance. A centred lobe
/// with Σ = diag(αx²/2, αy²/2) is the anisotropic Beckmann NDF (α = √2 σ).
///
/// Stored: μ and the Cholesky factor L (Σ = L Lᵀ, lower triangular) and its inverse L⁻¹, as `f32`:
/// **32 bytes**, 4-byte aligned. The normalisation 1/(2π √|Σ|) = L⁻¹₁₁ L⁻¹₂₂ / (2π) costs two
/// multiplications per evaluation instead of four more bytes.
///
/// Every slope maps to an upper-hemisphere normal, so ∫_{H²} D(m) cos θ_m dm = ∫_{ℝ²} P22 = 1 for
/// every lobe, however far its mean is tilted.
///
/// # Reference
/// \[Chermain2019\] eq. 2 and 4 (lobe), eq. 5-6 (moments); \[Dupuy2013\] (Λ of this lobe);
/// \[Heitz2014\] (Smith masking, visible normals).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeGaussian {
    /// Mean slope μ.
    mean: Vec2,
    /// L = [[l11, 0], [l21, l22]] stored as [l11, l21, l22].
    chol: [f32; 3],
    /// L⁻¹ = [[i11, 0], [i21, i22]] stored as [i11, i21, i22].
    inv_chol: [f32; 3],
}

const _: () = assert!(core::mem::size_of::<SlopeGaussian>() == 32);

/// The per-view quantities every masking term needs, in `f64`.
#[derive(Clone, Copy, Debug)]
struct ViewTerms {
    /// Signed projected area A_s = w_z − μ·w_xy = cos θ − sin θ q̄.
    a_s: f64,
    /// v = Lᵀ w_xy: the projected slope along w_xy is q̄ + v·z/… with z ~ N(0, I).
    vx: f64,
    vy: f64,
    /// s_w = |v| = sin θ · s, the standard deviation of sin θ · q.
    s_w: f64,
}

/// The projected areas of a lobe toward one direction, for mixtures that sum them over lobes.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct VisibleAreaParts {
    /// Signed projected area A_s(w) = ∫ (w·m) D(m) dm = cos θ − sin θ q̄ (may be negative).
    pub signed_area: f32,
    /// Visible projected area V(w) = ∫ ⟨w, m⟩⁺ D(m) dm ≥ max(A_s, 0).
    pub visible_area: f32,
}

impl SlopeGaussian {
    /// A lobe with mean slope `mean` and slope covariance `cov`.
    ///
    /// # Errors
    /// - [`Error::InvalidParameter`] naming `mean` if a component of `mean` is not finite or exceeds
    ///   [`MAX_SLOPE`] in magnitude;
    /// - [`Error::InvalidMatrix`] naming `cov` if an entry is not finite, if `cov` is not symmetric
    ///   (|c₀₁ − c₁₀| > 1e-6 √(c₀₀ c₁₁); the two are then averaged), if it is not positive definite,
    ///   if a variance exceeds [`MAX_SLOPE`]², or if it is so small that L⁻¹ or the normalisation
    ///   1/(2π √|Σ|) leaves the normal `f32` range.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 4.
    pub fn new(mean: Vec2, cov: Mat2) -> Result<Self> {
        for v in [mean.x, mean.y] {
            if v.is_nan() || v.abs() > MAX_SLOPE {
                return Err(Error::InvalidParameter {
                    name: "mean",
                    value: v as f64,
                    reason: "components must be finite with |μ| <= MAX_SLOPE = 1e4",
                });
            }
        }
        let c = cov.to_cols_array().map(f64::from);
        let (c00, c10, c01, c11) = (c[0], c[1], c[2], c[3]);
        let err = |reason| Error::InvalidMatrix {
            name: "cov",
            value: [c00, c01, c10, c11],
            reason,
        };
        if !c.iter().all(|v| v.is_finite()) {
            return Err(err("entries must be finite"));
        }
        if !(c00 > 0.0 && c11 > 0.0) {
            return Err(err("must be positive definite (diagonal entries > 0)"));
        }
        if (c01 - c10).abs() > 1e-6 * (c00 * c11).sqrt() {
            return Err(err("must be symmetric"));
        }
        let sxy = 0.5 * (c01 + c10);
        let det = c00 * c11 - sxy * sxy;
        if det.is_nan() || det <= 0.0 {
            return Err(err("must be positive definite (determinant > 0)"));
        }
        Self::from_cov_f64(mean, c00, sxy, c11)
            .ok_or_else(|| {
                err("too small or too large: a variance above MAX_SLOPE² = 1e8, or L⁻¹ or 1/(2π√|Σ|) leaves the f32 range")
            })
    }

    /// The centred anisotropic Beckmann NDF of roughness (αx, αy): Σ = diag(αx²/2, αy²/2).
    ///
    /// D(m) = exp(−tan²θ (cos²φ/αx² + sin²φ/αy²)) / (π αx αy cos⁴θ).
    ///
    /// # Errors
    /// [`Error::InvalidParameter`] naming `alpha_x` / `alpha_y` if not finite and > 0, or naming
    /// `alpha_x * alpha_y` if the lobe leaves the `f32` range (α below ~1e-18) or α exceeds
    /// √2 · [`MAX_SLOPE`].
    ///
    /// # Reference
    /// \[Walter2007\] eq. 25; \[Chermain2019\] eq. 2 with μ = 0.
    pub fn beckmann(alpha_x: f32, alpha_y: f32) -> Result<Self> {
        let ax = positive("alpha_x", alpha_x)? as f64;
        let ay = positive("alpha_y", alpha_y)? as f64;
        Self::from_cov_f64(Vec2::ZERO, 0.5 * ax * ax, 0.0, 0.5 * ay * ay).ok_or(
            Error::InvalidParameter {
                name: "alpha_x * alpha_y",
                value: ax * ay,
                reason: "lobe too narrow or too wide for f32",
            },
        )
    }

    /// The lobe fitted to slope moments, as \[Chermain2019\] eq. 5-6 builds it (infallible, for hot
    /// paths).
    ///
    /// `m` = `[E(x̃), E(ỹ), E(x̃²), E(ỹ²), E(x̃ỹ)]` (expectations over the footprint). In `f64`:
    /// - μ = (E(x̃), E(ỹ));
    /// - σx² = max(E(x̃²) − E(x̃)², σ_min²), σy² likewise (the floor: a flat region still reflects
    ///   like a near-mirror of roughness σ_min, not a Dirac);
    /// - c = E(x̃ỹ) − E(x̃) E(ỹ) (the paper's eq. 5 prints c², a typo), clamped to
    ///   |c| ≤ √((σx² − σ_min²)(σy² − σ_min²)). This makes Σ − σ_min² I positive semi-definite, so
    ///   **every** direction of Σ has variance ≥ σ_min² (not only the axes) and Σ is positive definite
    ///   with |Σ| ≥ σ_min⁴. A perfectly correlated (one-dimensional) slope set thus keeps a minor axis
    ///   of standard deviation exactly σ_min.
    ///
    /// `sigma_min`: non-finite or ≤ 0 → [`DEFAULT_SIGMA_MIN`]; positive values below
    /// [`SIGMA_MIN_FLOOR`] are raised to it.
    ///
    /// Fallback: if a moment is not finite, the mean exceeds [`MAX_SLOPE`] or a variance
    /// [`MAX_SLOPE`]², the centred isotropic lobe of σ = σ_min is returned.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 4-6.
    pub fn from_moments(m: [f32; 5], sigma_min: f32) -> Self {
        let s = if sigma_min.is_finite() && sigma_min > 0.0 {
            sigma_min.max(SIGMA_MIN_FLOOR)
        } else {
            DEFAULT_SIGMA_MIN
        } as f64;
        let fallback = || {
            Self::from_cov_f64(Vec2::ZERO, s * s, 0.0, s * s)
                .or_else(|| {
                    let d = DEFAULT_SIGMA_MIN as f64;
                    Self::from_cov_f64(Vec2::ZERO, d * d, 0.0, d * d)
                })
                .unwrap_or(Self::UNIT_FALLBACK)
        };
        if !m.iter().all(|v| v.is_finite()) {
            return fallback();
        }
        let [ex, ey, exx, eyy, exy] = m.map(f64::from);
        let s2 = s * s;
        let var_x = (exx - ex * ex).max(s2);
        let var_y = (eyy - ey * ey).max(s2);
        let c_max = ((var_x - s2) * (var_y - s2)).sqrt();
        let c = (exy - ex * ey).clamp(-c_max, c_max);
        Self::from_cov_f64(Vec2::new(m[0], m[1]), var_x, c, var_y).unwrap_or_else(fallback)
    }

    /// Centred isotropic lobe with σ = 1/√2 (Beckmann α = 1): the last-resort fallback, written
    /// out so that no code path can fail.
    const UNIT_FALLBACK: Self = SlopeGaussian {
        mean: Vec2::ZERO,
        chol: [
            core::f32::consts::FRAC_1_SQRT_2,
            0.0,
            core::f32::consts::FRAC_1_SQRT_2,
        ],
        inv_chol: [core::f32::consts::SQRT_2, 0.0, core::f32::consts::SQRT_2],
    };

    /// The lobe of a given mean slope and Cholesky factor L = [[l11, 0], [l21, l22]] (Σ = L Lᵀ),
    /// kept exactly as given (L⁻¹ formed in `f64` as every constructor does): for stored forms that
    /// hold L (the Beckmann mixture's compact lobe blocks), so that the lobe equals the stored one
    /// bit for bit. `None` unless the mean is within [`MAX_SLOPE`], l11, l22 > 0 and L, L⁻¹ and the
    /// normalisation are finite normal `f32` numbers.
    #[cfg(feature = "std")] // used by the glint layer
    pub(crate) fn from_mean_cholesky(mean: Vec2, l11: f32, l21: f32, l22: f32) -> Option<Self> {
        if !(mean.x.abs() <= MAX_SLOPE && mean.y.abs() <= MAX_SLOPE && l11 > 0.0 && l22 > 0.0) {
            return None;
        }
        Self::from_factor_f64(mean, l11 as f64, l21 as f64, l22 as f64)
    }

    /// Builds the lobe from an `f64` covariance; `None` unless Σ is positive definite and L, L⁻¹ and
    /// the normalisation are finite normal `f32` numbers.
    fn from_cov_f64(mean: Vec2, sxx: f64, sxy: f64, syy: f64) -> Option<Self> {
        let max_var = (MAX_SLOPE as f64) * (MAX_SLOPE as f64);
        if !(sxx > 0.0 && sxx <= max_var && syy <= max_var && sxy.is_finite()) {
            return None;
        }
        if !(mean.x.abs() <= MAX_SLOPE && mean.y.abs() <= MAX_SLOPE) {
            return None;
        }
        let l11 = sxx.sqrt();
        let l21 = sxy / l11;
        let l22_sq = syy - l21 * l21;
        if l22_sq.is_nan() || l22_sq <= 0.0 {
            return None;
        }
        Self::from_factor_f64(mean, l11, l21, l22_sq.sqrt())
    }

    /// The lobe of mean `mean` and Cholesky factor L given in `f64` (rounded once to `f32`), with
    /// L⁻¹ formed in `f64`; `None` unless L, L⁻¹ and the normalisation are finite normal `f32`
    /// numbers (L₂₁ and L⁻¹₂₁ finite).
    fn from_factor_f64(mean: Vec2, l11: f64, l21: f64, l22: f64) -> Option<Self> {
        let (i11, i22) = (1.0 / l11, 1.0 / l22);
        let i21 = -l21 * i11 * i22;
        let chol = [l11 as f32, l21 as f32, l22 as f32];
        let inv_chol = [i11 as f32, i21 as f32, i22 as f32];
        let norm = inv_chol[0] * inv_chol[2] * FRAC_1_2PI;
        let normal = |v: f32| v.is_finite() && v.abs() >= f32::MIN_POSITIVE;
        let ok = normal(chol[0])
            && normal(chol[2])
            && normal(inv_chol[0])
            && normal(inv_chol[2])
            && chol[1].is_finite()
            && inv_chol[1].is_finite()
            && normal(norm);
        ok.then_some(SlopeGaussian {
            mean,
            chol,
            inv_chol,
        })
    }

    /// The same lobe moved to mean `mean` (covariance unchanged); `None` if a component of `mean` is
    /// not finite or exceeds [`MAX_SLOPE`] in magnitude.
    #[cfg(feature = "std")]
    #[inline]
    pub(crate) fn with_mean(&self, mean: Vec2) -> Option<Self> {
        (mean.x.abs() <= MAX_SLOPE && mean.y.abs() <= MAX_SLOPE)
            .then_some(SlopeGaussian { mean, ..*self })
    }

    /// The mean slope μ.
    #[inline]
    pub fn mean(&self) -> Vec2 {
        self.mean
    }

    /// The slope covariance Σ = L Lᵀ, rebuilt from the stored Cholesky factor (equal to the
    /// constructor's input up to `f32` rounding, ~1e-7 relative).
    pub fn covariance(&self) -> Mat2 {
        let [l11, l21, l22] = self.chol.map(f64::from);
        let (sxx, sxy, syy) = (l11 * l11, l11 * l21, l21 * l21 + l22 * l22);
        Mat2::from_cols_array(&[sxx as f32, sxy as f32, sxy as f32, syy as f32])
    }

    /// The lower-triangular Cholesky factor L of Σ = L Lᵀ (slope = μ + L z with z ~ N(0, I)).
    #[inline]
    pub fn cholesky(&self) -> Mat2 {
        let [l11, l21, l22] = self.chol;
        Mat2::from_cols(Vec2::new(l11, l21), Vec2::new(0.0, l22))
    }

    /// The mean normal ω_n̄ = normalize(−μx, −μy, 1): the normal of the mean slope.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 13 (ω_n̄ᵢ).
    pub fn mean_normal(&self) -> Vec3 {
        slope_to_normal_f64(self.mean.x as f64, self.mean.y as f64)
    }

    /// The squared Mahalanobis distance q = |L⁻¹(ñ − μ)|² of the slope (`sx`, `sy`) from the mean,
    /// in `f64`, and the density's peak (L⁻¹)₁₁ (L⁻¹)₂₂ / (2π) = 1/(2π √|Σ|): P22 = peak ·
    /// exp(−q/2) (the few-lobe sets form the exponential inline, src/glint/kernels/lobe_set.rs).
    #[cfg(feature = "std")]
    #[inline]
    pub(crate) fn mahalanobis2_and_peak_f64(&self, sx: f64, sy: f64) -> (f64, f64) {
        let [i11, i21, i22] = self.inv_chol.map(f64::from);
        let (dx, dy) = (sx - self.mean.x as f64, sy - self.mean.y as f64);
        let (zx, zy) = (i11 * dx, i21 * dx + i22 * dy);
        (zx * zx + zy * zy, i11 * i22 / (2.0 * PI))
    }

    /// [`SlopeGaussian::p22`] at the slope (`sx`, `sy`) in `f64` (0 for non-finite slopes): for sums
    /// over many lobes at one slope, whose common Jacobian the caller applies once.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 4.
    #[inline]
    pub(crate) fn p22_f64(&self, sx: f64, sy: f64) -> f64 {
        let [i11, i21, i22] = self.inv_chol.map(f64::from);
        let (dx, dy) = (sx - self.mean.x as f64, sy - self.mean.y as f64);
        let (zx, zy) = (i11 * dx, i21 * dx + i22 * dy);
        let p = i11 * i22 / (2.0 * PI) * (-0.5 * (zx * zx + zy * zy)).exp();
        if p >= 0.0 { p } else { 0.0 }
    }

    /// The slope density P22(ñ) = exp(−½ |L⁻¹(ñ − μ)|²) / (2π √|Σ|) (per unit slope area).
    ///
    /// `f32`: one 2×2 triangular product and one `exp`. Non-finite slopes give 0.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 4.
    #[inline]
    pub fn p22(&self, slope: Vec2) -> f32 {
        let [i11, i21, i22] = self.inv_chol;
        let d = slope - self.mean;
        let zx = i11 * d.x;
        let zy = i21 * d.x + i22 * d.y;
        let e = (-0.5 * (zx * zx + zy * zy)).exp();
        if e >= 0.0 {
            i11 * i22 * FRAC_1_2PI * e
        } else {
            0.0 // NaN from a non-finite slope
        }
    }

    /// The signed projected area A_s(w) = ∫ (w·m) D(m) dm = w_z − μ·w_xy = cos θ − sin θ q̄.
    ///
    /// Equals ⟨ω_n̄, w⟩ / (ω_n̄·ω_g) before clamping; negative when the mean facet faces away from w.
    /// 0 for w below the horizon or not finite.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 (per lobe, unclamped).
    #[inline]
    pub fn signed_projected_area(&self, w: Vec3) -> f32 {
        self.view_terms(w).map_or(0.0, |t| finite_f32(t.a_s))
    }

    /// Scarf's upper bound of the visible area from the lobe's first two moments alone:
    /// V⁺(w) = ½ (ā + √(ā² + s²)) with ā = cos θ − w_xy·μ and s² = w_xyᵀ Σ w_xy: the largest
    /// E[(w_z − w_xy·ñ)⁺] over **every** slope distribution of mean μ and covariance Σ, so ≥ the
    /// Gaussian lobe's own V and ≥ the V of any P-NDF whose first two slope moments these are.
    /// Masking built on it can only over-shadow (G1 = A/V⁺ errs low), never create energy.
    /// 0 for invalid `w`.
    ///
    /// # Reference
    /// \[Scarf1958\], the bound E\[X⁺\] ≤ ½(E\[X\] + √(E\[X\]² + Var X)).
    pub fn visible_area_bound(&self, w: Vec3) -> f32 {
        let Some(t) = self.view_terms(w) else {
            return 0.0;
        };
        // s_w² = |Lᵀ w_xy|² = w_xyᵀ Σ w_xy.
        finite_or_zero(0.5 * (t.a_s + (t.a_s * t.a_s + t.s_w * t.s_w).sqrt()))
    }

    /// Both projected areas toward w at once: A_s(w) and V(w) (see [`VisibleAreaParts`]), for
    /// mixtures that accumulate Σ Wᵢ A_s,i and Σ Wᵢ V_i. Zeros for invalid w.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 13, 17; derivation in docs/slope_gaussian.md.
    #[inline]
    pub fn visible_area_parts(&self, w: Vec3) -> VisibleAreaParts {
        match self.view_terms(w) {
            Some(t) => VisibleAreaParts {
                signed_area: finite_f32(t.a_s),
                visible_area: finite_or_zero(visible_area_f64(&t)),
            },
            None => VisibleAreaParts::default(),
        }
    }

    /// A_s, v = Lᵀ w_xy and s_w = |v| for a usable direction (finite, w_z > 0).
    #[inline]
    fn view_terms(&self, w: Vec3) -> Option<ViewTerms> {
        if !(w.z > 0.0 && w.is_finite()) {
            return None;
        }
        let (wx, wy, wz) = (w.x as f64, w.y as f64, w.z as f64);
        let a_s = wz - (self.mean.x as f64 * wx + self.mean.y as f64 * wy);
        let [l11, l21, l22] = self.chol.map(f64::from);
        let vx = l11 * wx + l21 * wy;
        let vy = l22 * wy;
        let s_w = (vx * vx + vy * vy).sqrt();
        Some(ViewTerms { a_s, vx, vy, s_w })
    }

    /// (A_s(w), s_w(w)) in `f64` for a usable direction (w_z > 0, finite; the caller checks): the
    /// two numbers V(w) = s_w G(A_s/s_w) is made of, for sets of lobes that evaluate G over lanes.
    #[cfg(feature = "std")]
    #[inline]
    pub(crate) fn area_and_spread(&self, w: Vec3) -> (f64, f64) {
        let (wx, wy, wz) = (w.x as f64, w.y as f64, w.z as f64);
        let a_s = wz - (self.mean.x as f64 * wx + self.mean.y as f64 * wy);
        let [l11, l21, l22] = self.chol.map(f64::from);
        let (vx, vy) = (l11 * wx + l21 * wy, l22 * wy);
        (a_s, (vx * vx + vy * vy).sqrt())
    }

    /// tr Σ = l11² + l21² + l22² in `f64` from the stored factor: |Lᵀ w_xy|² ≤ tr Σ |w_xy|².
    #[cfg(feature = "std")]
    #[inline]
    pub(crate) fn covariance_trace_f64(&self) -> f64 {
        let [l11, l21, l22] = self.chol.map(f64::from);
        l11 * l11 + l21 * l21 + l22 * l22
    }

    /// The visible normals of a product grid toward `wo`: for each quantile `u1[i]` of the
    /// whitened slope along the view (the visible sampler's first variate) and each whitened
    /// slope `z2[j]` across it, `f(i, j, m)`. What `sample_visible` draws at (u1, Φ(z2)), with
    /// one inversion per `u1`; nothing for an invalid `wo`.
    #[cfg(feature = "std")]
    pub(crate) fn visible_grid(
        &self,
        wo: Vec3,
        u1: &[f32],
        z2: &[f64],
        mut f: impl FnMut(usize, usize, Vec3),
    ) {
        let Some(t) = self.view_terms(wo) else {
            return;
        };
        // At normal incidence (s_w = 0) every normal is seen alike: z ~ N(0, I), any axis.
        let normal = t.s_w.is_nan() || t.s_w <= 0.0;
        let (ex, ey) = if normal {
            (1.0, 0.0)
        } else {
            (t.vx / t.s_w, t.vy / t.s_w)
        };
        for (i, &u) in u1.iter().enumerate() {
            let z1 = if normal {
                gauss::inv_std_cdf(clamp_u(u))
            } else {
                visible_z1(t.a_s / t.s_w, u)
            };
            for (j, &z2) in z2.iter().enumerate() {
                let m = self.normal_from_z(z1 * ex - z2 * ey, z1 * ey + z2 * ex);
                f(i, j, ensure_facing(wo, m));
            }
        }
    }

    /// The normal of the slope μ + L z.
    #[inline]
    fn normal_from_z(&self, zx: f64, zy: f64) -> Vec3 {
        let [l11, l21, l22] = self.chol.map(f64::from);
        let sx = self.mean.x as f64 + l11 * zx;
        let sy = self.mean.y as f64 + l21 * zx + l22 * zy;
        slope_to_normal_f64(sx, sy)
    }

    /// D(m) in `f64`: P22(ñ) (1 + |ñ|²)² with the slope ñ = (−m_x/m_z, −m_y/m_z) formed in `f64`
    /// from the `f32` normal; `None` for m_z ≤ 0 or a non-finite m.
    ///
    /// [`Ndf::d`] and the visible densities all go through it, so that they agree on where D is
    /// zero: an `f32` slope loses up to 6·10⁻⁸ |ñ| (5·10⁻⁴ at |ñ| = 10⁴, where a lobe may have
    /// σ = 10⁻⁴), and D and the pdf taken from two roundings of it could differ by any factor.
    ///
    /// No step overflows or loses a value `f32` can hold: |ñ| ≤ 1/m_z ≤ 2¹⁴⁹ bounds (1 + |ñ|²)² by
    /// 10¹⁸⁰, the normalisation is at most `f32::MAX`², so the product stays below 10²⁵⁷; and where
    /// the exponential underflows (exponent < −745) the product is below 10⁻⁷⁴⁵ · 10²⁵⁷, far under
    /// the smallest `f32`.
    #[inline]
    fn d_f64(&self, m: Vec3) -> Option<f64> {
        if !(m.z > 0.0 && m.is_finite()) {
            return None;
        }
        let (mx, my, mz) = (m.x as f64, m.y as f64, m.z as f64);
        let (sx, sy) = (-mx / mz, -my / mz);
        let j = 1.0 + sx * sx + sy * sy;
        let d = self.p22_f64(sx, sy) * j * j;
        (!d.is_nan()).then_some(d)
    }

    /// ln D_wo(m) = ln(⟨wo, m⟩ D(m) / V(wo)) in `f64`, or `None` outside the visible support
    /// (m below the horizon, ⟨wo, m⟩ ≤ 0 as `wo.dot(m)` rounds it, invalid wo).
    ///
    /// Finite on the whole support, also where D and V both underflow `f32` (grazing views of a
    /// lobe tilted away: the visible normals then lie tens of σ out), where [`Ndf::pdf_visible`]
    /// is 0 because D is: for references and tests that follow the visible sampler into that tail.
    pub fn ln_pdf_visible(&self, wo: Vec3, m: Vec3) -> Option<f64> {
        let t = self.view_terms(wo)?;
        let ln_d = self.ln_d(m)?;
        let c = facing(wo, m);
        if c.is_nan() || c <= 0.0 {
            return None;
        }
        let ln_pdf = c.ln() + ln_d - ln_visible_area(&t)?;
        (!ln_pdf.is_nan()).then_some(ln_pdf)
    }

    /// ln D(m) in `f64`: −½ |L⁻¹(ñ − μ)|² + ln(L⁻¹₁₁ L⁻¹₂₂ / (2π)) + 2 ln(1 + |ñ|²) (finite where
    /// D underflows `f64`); `None` for m_z ≤ 0 or a non-finite m.
    fn ln_d(&self, m: Vec3) -> Option<f64> {
        if !(m.z > 0.0 && m.is_finite()) {
            return None;
        }
        let (mx, my, mz) = (m.x as f64, m.y as f64, m.z as f64);
        let (sx, sy) = (-mx / mz, -my / mz);
        let [i11, i21, i22] = self.inv_chol.map(f64::from);
        let (dx, dy) = (sx - self.mean.x as f64, sy - self.mean.y as f64);
        let (zx, zy) = (i11 * dx, i21 * dx + i22 * dy);
        let ln_norm = (i11 * i22 / (2.0 * PI)).ln();
        let ln_d = -0.5 * (zx * zx + zy * zy) + ln_norm + 2.0 * (1.0 + sx * sx + sy * sy).ln();
        (!ln_d.is_nan()).then_some(ln_d)
    }

    /// D(m)/V(wo) in `f64` where D rounds to a positive `f32` and m faces wo, else `None`: the
    /// quotient directly where V(wo) is a normal `f64` (D ≥ `f32`'s smallest value there, so the
    /// quotient loses nothing), from logarithms where V underflows (grazing views of a lobe tilted
    /// away).
    fn d_over_v(&self, wo: Vec3, m: Vec3) -> Option<f64> {
        let t = self.view_terms(wo)?;
        let d = self.d_f64(m)?;
        let c = facing(wo, m);
        if (d as f32) <= 0.0 || c.is_nan() || c <= 0.0 {
            return None;
        }
        let v = visible_area_f64(&t);
        let q = if v >= 1.0e-290 {
            d / v
        } else {
            (self.ln_d(m)? - ln_visible_area(&t)?).exp()
        };
        (!q.is_nan()).then_some(q)
    }
}

/// ln V(w) from the view terms, finite where V underflows `f64`; `None` where V is 0.
#[inline]
fn ln_visible_area(t: &ViewTerms) -> Option<f64> {
    if t.s_w > 0.0 {
        Some(t.s_w.ln() + gauss::ln_ramp(t.a_s / t.s_w))
    } else if t.a_s > 0.0 {
        Some(t.a_s.ln())
    } else {
        None
    }
}

/// D in `f32` from its `f64` value, values beyond `f32::MAX` clamped to it.
#[inline]
fn d_to_f32(d: f64) -> f32 {
    (d as f32).min(f32::MAX)
}

impl Ndf for SlopeGaussian {
    /// D(m) = P22(ñ(m)) (1 + |ñ|²)² = P22(ñ) / cos⁴θ_m, formed in `f64` (slope included) and
    /// rounded once to `f32` (see `d_f64`).
    ///
    /// 0 for m.z ≤ 0 or non-finite m and where D underflows `f32`; values beyond `f32::MAX` are
    /// clamped to it.
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 2.
    #[inline]
    fn d(&self, m: Vec3) -> f32 {
        self.d_f64(m).map_or(0.0, d_to_f32)
    }

    /// Smith Λ(w) = V/A − 1 = G(−z)/z with z = A_s / s_w = (μ_w − q̄)/s, μ_w = cot θ.
    ///
    /// G(−z) = φ(z) − z Q(z) is computed without cancellation (Mills' continued fraction for
    /// z > 5). 0 at normal incidence and below the horizon / for invalid w; `f32::MAX` when
    /// A_s ≤ 0 (the mean facet faces away from w: everything is masked) or when Λ overflows.
    ///
    /// # Reference
    /// \[Dupuy2013\] (non-centred anisotropic Beckmann Λ); \[Heitz2014\] eq. 72 (centred case).
    fn lambda(&self, w: Vec3) -> f32 {
        let Some(t) = self.view_terms(w) else {
            return 0.0;
        };
        if t.a_s.is_nan() || t.a_s <= 0.0 {
            return f32::MAX;
        }
        if t.s_w == 0.0 {
            return 0.0;
        }
        let z = t.a_s / t.s_w;
        ((gauss::ramp_neg(z) / z) as f32).min(f32::MAX)
    }

    /// A(w) = max(A_s(w), 0) = max(cos θ − sin θ q̄, 0) = ⟨ω_n̄, w⟩ / (ω_n̄·ω_g).
    ///
    /// # Reference
    /// \[Chermain2019\] eq. 17 (one lobe).
    #[inline]
    fn projected_area(&self, w: Vec3) -> f32 {
        self.view_terms(w).map_or(0.0, |t| finite_or_zero(t.a_s))
    }

    /// V(w) = ∫ ⟨w, m⟩⁺ D(m) dm = s_w G(A_s / s_w) = A_s Φ(z) + s_w φ(z), exact for every w.
    ///
    /// Stable forms: A_s + s_w G(−z) for z > 0 (two non-negative terms; the second is dropped for
    /// z > 8 where it is < 1e-17 A_s), s_w G(−|z|) for z ≤ 0 (Mills' ratio, no overflow or 0/0), A_s at
    /// normal incidence. Never divides by sin θ. 0 for invalid w.
    ///
    /// # Reference
    /// docs/slope_gaussian.md; \[Chermain2019\] eq. 12-13 (the integral per lobe).
    #[inline]
    fn visible_area(&self, w: Vec3) -> f32 {
        self.view_terms(w)
            .map_or(0.0, |t| finite_or_zero(visible_area_f64(&t)))
    }

    /// Exact sampling of D(m) cos θ_m: slope = μ + L z, z = Box–Muller(u).
    ///
    /// z = √(−2 ln u₁) (cos 2πu₂, sin 2πu₂) with u clamped into [2⁻²⁶, 1 − 2⁻²⁶] (NaN → ½), so every
    /// u gives a finite unit upper-hemisphere normal.
    ///
    /// # Reference
    /// \[BoxMuller1958\]; \[Chermain2019\] eq. 2 (the slope density being sampled).
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        let (u1, u2) = (clamp_u(u.x), clamp_u(u.y));
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (gauss::TWO_PI * u2).sin_cos();
        self.normal_from_z(r * c, r * s)
    }

    /// Sampling of the visible normals D_wo(m) ∝ ⟨wo, m⟩⁺ D(m) (exact up to the inversion's stated
    /// cdf error).
    ///
    /// In slope space the density is ∝ (A_s − w_xy·ñ)⁺ P22(ñ). With ñ = μ + L z and v = Lᵀ w_xy
    /// the weight is |v| (a − z₁)⁺, a = A_s/|v|, z₁ = v̂·z; z₂ = v̂⊥·z stays N(0, 1) and independent.
    /// z₁ is drawn by inverting its cdf (a Φ(x) + φ(x)) / (a Φ(a) + φ(a)) with u.x: for a ≥ 0.01
    /// (`A_BECKMANN`: wo on the side the mean facet faces) as √2 x, x the standard visible slope of
    /// a Beckmann lobe at cot θ = a/√2 (the same density in x = z₁/√2; Halley's iteration from a
    /// tabulated first iterate, ~1 evaluation, cdf error ≤ 3·10⁻⁶: `Beckmann::sample_visible`),
    /// else by Newton in `f64` (any real a, cdf to `f64` precision). z₂ = Φ⁻¹(u.y). u is clamped as
    /// in [`Ndf::sample_normal`].
    ///
    /// Degenerate cases: wo invalid or at normal incidence → [`Ndf::sample_normal`] (exact at normal
    /// incidence). If `f32` rounding puts the normal at ⟨wo, m⟩ ≤ 0 (possible only where the
    /// visible set is thinner than `f32` resolution), m is moved along wo to ⟨wo, m⟩ = 1e-5, so the
    /// returned normal always has a positive [`Ndf::pdf_visible`].
    ///
    /// # Reference
    /// \[Heitz2014\] §5 (visible normals); derivation in docs/slope_gaussian.md; \[Jakob2014\] (the
    /// inversion in erf(x)).
    fn sample_visible(&self, wo: Vec3, u: Vec2) -> Vec3 {
        let Some(t) = self.view_terms(wo) else {
            return self.sample_normal(u);
        };
        if t.s_w == 0.0 {
            return self.sample_normal(u);
        }
        let z1 = visible_z1(t.a_s / t.s_w, u.x);
        let z2 = gauss::inv_std_cdf(clamp_u(u.y));
        let (ex, ey) = (t.vx / t.s_w, t.vy / t.s_w);
        let m = self.normal_from_z(z1 * ex - z2 * ey, z1 * ey + z2 * ex);
        ensure_facing(wo, m)
    }

    /// D_wo(m) = ⟨wo, m⟩⁺ D(m) / V(wo), formed in `f64` (from logarithms where V underflows `f64`:
    /// grazing views of lobes tilted away), so that it stays finite where V underflows `f32`.
    ///
    /// 0 outside the visible set (m below the horizon or ⟨wo, m⟩ ≤ 0), for invalid wo, and wherever
    /// [`Ndf::d`] is 0 (the density contract of every NDF: no density where D rounds to 0 in `f32`,
    /// even where the `f64` density is positive, as tens of σ out at grazing views of a lobe tilted
    /// away: the visible sampler may then return normals whose pdf is 0, and
    /// [`SlopeGaussian::ln_pdf_visible`] gives their `f64` density). Elsewhere, values below
    /// `f32::MIN_POSITIVE` are returned as `f32::MIN_POSITIVE` (the density is positive there; a
    /// caller testing pdf > 0 for "in the support" stays right) and values above `f32::MAX` as
    /// `f32::MAX`.
    fn pdf_visible(&self, wo: Vec3, m: Vec3) -> f32 {
        match self.d_over_v(wo, m) {
            Some(q) => ((facing(wo, m) * q) as f32).clamp(f32::MIN_POSITIVE, f32::MAX),
            None => 0.0,
        }
    }

    /// D(m) / V(wo): [`Ndf::pdf_visible`] without its factor ⟨wo, m⟩ (which the reflection
    /// Jacobian cancels), formed in `f64` like it and clamped like it, 0 where it is 0 (`d_m` is
    /// not needed: D is formed again in `f64`).
    ///
    /// # Reference
    /// \[Heitz2014\] eq. 16.
    fn pdf_visible_over_cos_given_d(&self, wo: Vec3, m: Vec3, d_m: f32) -> f32 {
        let _ = d_m;
        match self.d_over_v(wo, m) {
            Some(q) => (q as f32).clamp(f32::MIN_POSITIVE, f32::MAX),
            None => 0.0,
        }
    }

    /// D(m): [`Ndf::pdf_normal`] = D cos θ_m without its cosine.
    fn pdf_normal_over_cos_given_d(&self, m: Vec3, d_m: f32) -> f32 {
        super::normal_over_cos(m, d_m)
    }
}

/// V(w) from the view terms (see [`Ndf::visible_area`] for the branches).
#[inline]
fn visible_area_f64(t: &ViewTerms) -> f64 {
    if t.s_w == 0.0 {
        return t.a_s.max(0.0);
    }
    let z = t.a_s / t.s_w;
    if z > 8.0 {
        // s_w G(−z) / A_s = G(−z)/z < 1e-17 here: below f64 resolution of A_s.
        t.a_s
    } else if z > 0.0 {
        t.a_s + t.s_w * gauss::ramp_neg(z)
    } else {
        t.s_w * gauss::ramp_neg(-z)
    }
}

/// ⟨wo, m⟩ as `wo.dot(m)` rounds it in `f32` (the same arithmetic in the sampler, in the pdf and
/// in `MicrofacetBrdf`'s reflection Jacobian 1/(4 wo·h), so that the visible-normal weight
/// F G2/G1 ≤ F holds to rounding even where the cosine is below f32's resolution), widened to `f64`.
#[inline]
fn facing(wo: Vec3, m: Vec3) -> f64 {
    wo.dot(m) as f64
}

/// m if it faces wo after rounding, else m moved along wo to ⟨wo, m⟩ = [`FACING_NUDGE`].
/// The whitened visible slope along the view, z₁ ∝ (a − z₁)⁺ φ(z₁), at quantile `u`: for
/// a ≥ `A_BECKMANN` √2 x with x Beckmann's standard visible slope at cot θ = a/√2
/// (x ∝ (a/√2 − x)⁺ e^(−x²)), else the `f64` inversion of the ramp.
fn visible_z1(a: f64, u: f32) -> f64 {
    if a >= A_BECKMANN {
        let (cot, tan) = ((a * FRAC_1_SQRT_2) as f32, (SQRT_2 / a) as f32);
        let theta = libm::atan2(SQRT_2, a) as f32;
        let ux = clamp_u(u) as f32;
        SQRT_2 * super::beckmann::visible_slope_x_std(cot, tan, theta, ux) as f64
    } else {
        gauss::sample_ramp(a, clamp_u(u))
    }
}

fn ensure_facing(wo: Vec3, m: Vec3) -> Vec3 {
    let c = facing(wo, m);
    if c > 0.0 {
        return m;
    }
    let k = FACING_NUDGE - c;
    let n = [
        m.x as f64 + k * wo.x as f64,
        m.y as f64 + k * wo.y as f64,
        m.z as f64 + k * wo.z as f64,
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let n = Vec3::new(
        (n[0] / len) as f32,
        (n[1] / len) as f32,
        (n[2] / len) as f32,
    );
    if n.is_finite() && n.z > 0.0 && facing(wo, n) > 0.0 {
        n
    } else {
        // wo itself faces wo; normalised, since a caller may pass a non-unit wo (fuzz findings: a
        // wo of length 1e-18 came back as the "normal"; one of length 2e-22, whose squared length
        // is subnormal in f32, normalised to length 0.99).
        crate::frame::normalize_robust(wo)
            .filter(|w| w.z > 0.0)
            .unwrap_or(Vec3::Z)
    }
}

/// normalize(−sx, −sy, 1) in `f64`, rounded to `f32`; the geometric normal if that fails.
#[inline]
fn slope_to_normal_f64(sx: f64, sy: f64) -> Vec3 {
    let inv = 1.0 / (1.0 + sx * sx + sy * sy).sqrt();
    let m = Vec3::new((-sx * inv) as f32, (-sy * inv) as f32, inv as f32);
    if m.is_finite() && m.z > 0.0 {
        m
    } else {
        Vec3::Z
    }
}

/// u into [2⁻²⁶, 1 − 2⁻²⁶] in `f64`; NaN → ½.
#[inline]
fn clamp_u(u: f32) -> f64 {
    let u = u as f64;
    if u.is_nan() {
        0.5
    } else {
        u.clamp(U_EPS, 1.0 - U_EPS)
    }
}

#[cfg(test)]
mod tests;
