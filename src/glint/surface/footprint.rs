//! Ray footprints on a normal map: a parallelogram and a Gaussian with the same mean and covariance.
//!
//! A renderer gives, at a shading point, the texture coordinate `uv` and its screen-space derivatives
//! ∂uv/∂x and ∂uv/∂y (ray differentials). The footprint is defined from them in two consistent views:
//!
//! - **Parallelogram** P = {uv + a ∂uv/∂x + b ∂uv/∂y : a, b ∈ [−½, ½]}, of area |det[∂uv/∂x ∂uv/∂y]|
//!   (one pixel's preimage). Used by models that gather texels (the bin map).
//! - **Gaussian** k_P with the same mean and covariance as the uniform density on P:
//!   Σ = (∂uv/∂x ∂uv/∂xᵀ + ∂uv/∂y ∂uv/∂yᵀ) / 12 (a uniform variable on [−½, ½] has variance 1/12). Used by
//!   the Beckmann mixture and the position-normal Gaussians.
//!
//! Both views have the same "area": the parallelogram's area is 12 √det Σ, so a footprint "of N texels"
//! is N texels in both. Models work in texel units of their map; the views convert once, at the
//! boundary, and apply three documented clamps there ([`MIN_WIDTH_TEXELS`], [`MAX_ANISOTROPY`],
//! [`MAX_EXTENT_PERIODS`]). Clamps act on the principal axes of Σ through their *widths*
//! w = √(12 λ) (the side of the rectangle with that variance), so a square of side s texels has widths
//! (s, s).
//!
//! # Reference
//! \[Chermain2019\] §4.1 (Gaussian footprint k_P); \[Igehy1999\] (ray differentials); \[Atanasov2020\] §2
//! (the pixel footprint A of the bin map, from ray differentials).

use crate::{Error, Result};
use glam::{Mat2, Vec2, Vec3};

/// Smallest footprint width along any principal axis, in texels (so the smallest area is 10⁻⁴ texel²).
///
/// Below it every model degenerates: the footprint sees a single point of the interpolated surface, its
/// P-NDF tends to a Dirac delta that no f32 density can represent, and Gaussian weights of the
/// mixture/Yan models underflow. 0.01 texel is far below any useful pixel footprint (a 4096² map seen
/// at 4K resolution is still ~1 texel per pixel) and far above f32 resolution of texel coordinates.
/// Vanishing differentials, and non-finite ones given to the unchecked constructors, give the
/// minimal isotropic footprint (a square of side `MIN_WIDTH_TEXELS`; the type's docs, "Non-finite
/// input").
pub const MIN_WIDTH_TEXELS: f32 = 0.01;

/// Largest ratio of the major to the minor width; the minor axis is widened to major / 32.
///
/// Grazing views give needle-like footprints (aspect 1000+) whose cost grows with the major axis while
/// their area stays small; texture filtering hardware caps the ratio at 16 for the same reason. 32 keeps
/// grazing glints sharp (the widened minor axis only blurs across the needle) while bounding the work
/// of hierarchy queries, whose bounding boxes grow with the major axis.
pub const MAX_ANISOTROPY: f32 = 32.0;

/// Largest width along any axis, in periods of the map: `MAX_EXTENT_PERIODS × max(width, height)`
/// texels.
///
/// A footprint one period wide already covers the whole tiled map; wider footprints add only the
/// same texels again, and would cost gathering models time and f32 precision for nothing. Two periods
/// rather than one: a Gaussian whose width equals the period (σ = period / √12) still weights the tiled
/// map unevenly (the first Fourier coefficient of the periodised weight is e^{−2π²/12} ≈ 0.19), at two
/// periods the ripple is e^{−2π²·4/12} ≈ 1.4·10⁻³.
pub const MAX_EXTENT_PERIODS: f32 = 2.0;

/// A ray footprint on a tiled normal map, in uv units of the map. Cheap to copy.
///
/// # Building one per shading point (the recipe)
///
/// A renderer with ray differentials (pbrt's `RayDifferential`: the camera ray plus the rays through
/// the neighbouring pixels, offsets (rx_o, rx_d) and (ry_o, ry_d)) does, at a hit p with normal n,
/// uv and the parametrisation's ∂p/∂u, ∂p/∂v:
/// 1. intersect the two offset rays with the tangent plane at p: t_x = n·(p − rx_o) / n·rx_d,
///    ∂p/∂x ≈ rx_o + t_x rx_d − p (same for y). Without ray differentials, ∂p/∂x can be
///    approximated from the camera (pbrt-v4's `Camera::Approximate_dp_dxy`). Scale both by
///    1/√(samples per pixel) when each pixel takes several samples, so that the footprints of all
///    samples of a pixel tile it rather than each covering it whole;
/// 2. call [`Footprint::from_surface_differentials`]`(uv, ∂p/∂u, ∂p/∂v, ∂p/∂x, ∂p/∂y)`, which solves
///    ∂p/∂x = ∂p/∂u ∂u/∂x + ∂p/∂v ∂v/∂x in the least-squares sense for ∂uv/∂x (and y);
/// 3. if the material scales uv (a map repeated k times: uv' = k uv), scale uv and both differentials
///    by k, or call [`Footprint::from_differentials`] with the scaled ∂uv directly.
///
/// [`RayDifferential::footprint`](crate::glint::RayDifferential::footprint) does steps 1 and 2 from
/// pbrt-style offset rays.
///
/// Secondary rays (after a diffuse or glossy bounce) have no ray differentials: carry a
/// [`RayCone`](crate::glint::RayCone) along the path instead and read the footprint from it at each
/// hit ([`RayCone::footprint`](crate::glint::RayCone::footprint)), which ends in step 2 too.
///
/// The shading frame of the same hit is [`Frame::from_surface`](crate::frame::Frame::from_surface)`(n,
/// ∂p/∂u, ∂p/∂v)`.
///
/// # Handedness
/// A footprint lives in the map's (u, v) coordinates, and step 2 solves for ∂uv/∂x in those
/// coordinates directly: a left-handed parametrisation (∂p/∂u × ∂p/∂v pointing against n, e.g. u
/// mirrored) gives the footprint of the mirrored map region, with no sign to choose. The
/// frame must agree: [`Frame::from_surface`](crate::frame::Frame::from_surface) puts the local x
/// along ∂p/∂u and y along +∂p/∂v for either handedness, so a slope (x̃, ỹ) of the map and the
/// footprint's axes are the same (u, v) axes. (`Frame::from_normal_tangent(n, ∂p/∂u)` instead mirrors
/// v on a left-handed parametrisation: its slopes would no longer match the footprint's texels.)
///
/// # Non-finite input
/// Every footprint constructor comes in two forms. The unchecked ones
/// ([`Footprint::from_differentials`], [`Footprint::from_surface_differentials`],
/// [`RayCone::footprint`](crate::glint::RayCone::footprint),
/// [`RayDifferential::footprint`](crate::glint::RayDifferential::footprint)) are total, as
/// evaluation is: a non-finite uv becomes (0, 0), non-finite differentials become zero, i.e. the
/// minimal isotropic footprint ([`MIN_WIDTH_TEXELS`]), so no NaN reaches a model. That fallback is
/// the patch of one point of the surface, which renders as sparse sparkles: a NaN differential is
/// always a bug upstream (a zero-length vector normalised, a degenerate camera), and the fallback
/// hides it. The checked ones (`try_*`) return the same footprint bit for bit for finite input and
/// [`Error::InvalidFootprint`] naming the first non-finite argument otherwise.
///
/// Both are kept, rather than `Result` everywhere, because the footprint is built in the
/// renderer's shading loop once per hit, where an error has no handling but a fallback: a renderer
/// calls the checked form where it can act on the error (a debug build, a validation pass, its
/// tests, a `debug_assert!` of its own) and the unchecked form where it cannot, and the crate's
/// evaluation stays total either way.
///
/// Then read it in texel units of a map with [`Footprint::gaussian_texels`] or
/// [`Footprint::parallelogram_texels`] (the glint models do this). See the
/// [`glint` module docs](crate::glint) and the constants for the two views and the clamps. Map
/// sizes of 0 given to the views are treated as 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    uv: Vec2,
    duv_dx: Vec2,
    duv_dy: Vec2,
}

/// The clamped footprint in texel units (f64): centre, parallelogram edges and covariance.
#[derive(Clone, Copy, Debug)]
struct TexelView {
    center: [f64; 2],
    a: [f64; 2],
    b: [f64; 2],
    /// Covariance (xx, xy, yy).
    cov: [f64; 3],
    /// Principal widths √(12 λ), major first.
    widths: [f64; 2],
}

/// Symmetric 2 × 2 eigen decomposition: eigenvalues (λ1 ≥ λ2 ≥ 0) and the unit eigenvector of λ1.
fn eigen(cov: [f64; 3]) -> ([f64; 2], [f64; 2]) {
    let [sxx, sxy, syy] = cov;
    let half_tr = 0.5 * (sxx + syy);
    let d = (0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy).sqrt();
    let l1 = (half_tr + d).max(0.0);
    let l2 = (half_tr - d).max(0.0);
    let e1 = if sxy.abs() > 1e-300 {
        let (x, y) = (l1 - syy, sxy);
        let n = (x * x + y * y).sqrt();
        [x / n, y / n]
    } else if sxx >= syy {
        [1.0, 0.0]
    } else {
        [0.0, 1.0]
    };
    ([l1, l2], e1)
}

fn covariance(a: [f64; 2], b: [f64; 2]) -> [f64; 3] {
    [
        (a[0] * a[0] + b[0] * b[0]) / 12.0,
        (a[0] * a[1] + b[0] * b[1]) / 12.0,
        (a[1] * a[1] + b[1] * b[1]) / 12.0,
    ]
}

impl Footprint {
    /// The footprint of a shading point from its uv and ray differentials ∂uv/∂x, ∂uv/∂y.
    ///
    /// Infallible: a non-finite `uv` is replaced by (0, 0) and is otherwise wrapped into [0, 1)² (maps
    /// tile); if either differential is non-finite both are set to 0, which the texel views turn into
    /// the minimal isotropic footprint ([`MIN_WIDTH_TEXELS`]). Never produces NaN. To have
    /// non-finite input reported instead: [`Footprint::try_from_differentials`] (the type's docs,
    /// "Non-finite input").
    pub fn from_differentials(uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Footprint {
        let uv = Vec2::select(uv.is_finite_mask(), uv, Vec2::ZERO);
        let mut uv = uv - uv.floor();
        // uv − floor(uv) rounds to 1.0 for tiny negative uv.
        uv = Vec2::select(uv.cmpge(Vec2::ONE), Vec2::ZERO, uv);
        let (duv_dx, duv_dy) = if duv_dx.is_finite() && duv_dy.is_finite() {
            (duv_dx, duv_dy)
        } else {
            (Vec2::ZERO, Vec2::ZERO)
        };
        Footprint { uv, duv_dx, duv_dy }
    }

    /// [`Footprint::from_differentials`] that refuses non-finite input instead of falling back:
    /// the same footprint, bit for bit, for finite input.
    ///
    /// # Errors
    /// [`Error::InvalidFootprint`] naming the first of `uv`, `duv_dx`, `duv_dy` that is not finite.
    pub fn try_from_differentials(uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Result<Footprint> {
        finite_input("uv", uv.extend(0.0))?;
        finite_input("duv_dx", duv_dx.extend(0.0))?;
        finite_input("duv_dy", duv_dy.extend(0.0))?;
        Ok(Footprint::from_differentials(uv, duv_dx, duv_dy))
    }

    /// [`Footprint::from_surface_differentials`] that refuses non-finite input instead of falling
    /// back: the same footprint, bit for bit, for finite input (a singular parametrisation, which
    /// is geometry rather than a bug, still gives the minimal footprint).
    ///
    /// # Errors
    /// [`Error::InvalidFootprint`] naming the first of `uv`, `dpdu`, `dpdv`, `dpdx`, `dpdy` that is
    /// not finite.
    pub fn try_from_surface_differentials(
        uv: Vec2,
        dpdu: Vec3,
        dpdv: Vec3,
        dpdx: Vec3,
        dpdy: Vec3,
    ) -> Result<Footprint> {
        finite_input("uv", uv.extend(0.0))?;
        finite_input("dpdu", dpdu)?;
        finite_input("dpdv", dpdv)?;
        finite_input("dpdx", dpdx)?;
        finite_input("dpdy", dpdy)?;
        Ok(Footprint::from_surface_differentials(
            uv, dpdu, dpdv, dpdx, dpdy,
        ))
    }

    /// The footprint of a ray hit from the surface's ∂p/∂u, ∂p/∂v and the ray differentials ∂p/∂x,
    /// ∂p/∂y (any common world frame and unit; the recipe is in the type's docs): ∂uv/∂x is the
    /// least-squares solution of ∂p/∂u ∂u/∂x + ∂p/∂v ∂v/∂x = ∂p/∂x (normal equations in `f64`), the
    /// same for y, then [`Footprint::from_differentials`].
    ///
    /// Any handedness of (∂p/∂u, ∂p/∂v) is fine: the solve is in (u, v) coordinates, the axes of
    /// [`Frame::from_surface`](crate::frame::Frame::from_surface) (the type's docs, "Handedness").
    ///
    /// Degenerate cases: a singular parametrisation (∂p/∂u ∥ ∂p/∂v, or either zero) or non-finite
    /// input gives zero differentials, i.e. the minimal footprint ([`MIN_WIDTH_TEXELS`]); the result
    /// is never NaN ([`Footprint::try_from_surface_differentials`] reports non-finite input
    /// instead). A finite solution beyond the f32 range (∂p/∂u tiny against ∂p/∂x) is clamped to
    /// ±`f32::MAX`, a footprint the texel views clamp to [`MAX_EXTENT_PERIODS`], never a minimal
    /// one.
    ///
    /// # Reference
    /// \[Igehy1999\] (ray differentials); the least-squares step is pbrt-v4's
    /// `SurfaceInteraction::ComputeDifferentials` (\[Pharr2023\] §10.1.1).
    pub fn from_surface_differentials(
        uv: Vec2,
        dpdu: Vec3,
        dpdv: Vec3,
        dpdx: Vec3,
        dpdy: Vec3,
    ) -> Footprint {
        let f = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let (pu, pv) = (f(dpdu), f(dpdv));
        let (a00, a01, a11) = (dot(pu, pu), dot(pu, pv), dot(pv, pv));
        let det = a00 * a11 - a01 * a01;
        // Relative test: ∂p/∂u and ∂p/∂v (nearly) parallel, or zero.
        let solve = |d: Vec3| -> Vec2 {
            if !(det > 1e-12 * a00 * a11 && det.is_finite()) {
                return Vec2::ZERO;
            }
            let (b0, b1) = (dot(pu, f(d)), dot(pv, f(d)));
            let du = (a11 * b0 - a01 * b1) / det;
            let dv = (a00 * b1 - a01 * b0) / det;
            let to_f32 = |x: f64| x.clamp(-f32::MAX as f64, f32::MAX as f64) as f32;
            Vec2::new(to_f32(du), to_f32(dv))
        };
        Footprint::from_differentials(uv, solve(dpdx), solve(dpdy))
    }

    /// A square footprint of `area_texels` texels² (side √area texels, axis aligned) centred at
    /// `center_uv`, for a `width × height` map. For tests and benchmarks.
    pub fn isotropic_texels(
        center_uv: Vec2,
        area_texels: f32,
        width: usize,
        height: usize,
    ) -> Footprint {
        Footprint::anisotropic_texels(center_uv, area_texels, 1.0, 0.0, width, height)
    }

    /// A rectangular footprint of `area_texels` texels², `aspect` times wider along the direction at
    /// angle `angle` (radians, from the +u texel axis toward +v) than across it, centred at
    /// `center_uv`, for a `width × height` map. For tests and benchmarks.
    ///
    /// The edges in texels are √(area·aspect) (cos, sin) and √(area/aspect) (−sin, cos). Bad values
    /// (non-finite, non-positive area or aspect) give the fallback of [`Footprint::from_differentials`].
    pub fn anisotropic_texels(
        center_uv: Vec2,
        area_texels: f32,
        aspect: f32,
        angle: f32,
        width: usize,
        height: usize,
    ) -> Footprint {
        let size = Vec2::new(width.max(1) as f32, height.max(1) as f32);
        let (s, c) = angle.sin_cos();
        let major = (area_texels * aspect).sqrt();
        let minor = (area_texels / aspect).sqrt();
        let a = Vec2::new(c, s) * major / size;
        let b = Vec2::new(-s, c) * minor / size;
        Footprint::from_differentials(center_uv, a, b)
    }

    /// The centre uv, in [0, 1)².
    #[inline]
    pub fn center_uv(&self) -> Vec2 {
        self.uv
    }

    /// ∂uv/∂x as given (after the non-finite fallback), before clamping.
    #[inline]
    pub fn duv_dx(&self) -> Vec2 {
        self.duv_dx
    }

    /// ∂uv/∂y as given (after the non-finite fallback), before clamping.
    #[inline]
    pub fn duv_dy(&self) -> Vec2 {
        self.duv_dy
    }

    /// The clamped texel view (see the module docs).
    fn texel_view(&self, width: usize, height: usize) -> TexelView {
        let (w, h) = (width.max(1) as f64, height.max(1) as f64);
        let center = [self.uv.x as f64 * w, self.uv.y as f64 * h];
        let mut a = [self.duv_dx.x as f64 * w, self.duv_dx.y as f64 * h];
        let mut b = [self.duv_dy.x as f64 * w, self.duv_dy.y as f64 * h];
        let cov = covariance(a, b);
        let ([l1, l2], e1) = eigen(cov);
        let e2 = [-e1[1], e1[0]];
        let widths = [(12.0 * l1).sqrt(), (12.0 * l2).sqrt()];
        let max_width = MAX_EXTENT_PERIODS as f64 * w.max(h);
        let min_width = MIN_WIDTH_TEXELS as f64;
        let major = widths[0].clamp(min_width, max_width);
        let minor = widths[1]
            .clamp(min_width, max_width)
            .max(major / MAX_ANISOTROPY as f64);
        if major == widths[0] && minor == widths[1] {
            return TexelView {
                center,
                a,
                b,
                cov,
                widths,
            };
        }
        if widths[1] > 1e-9 * widths[0].max(1e-300) && widths[1] > 1e-12 {
            // Stretch along the principal axes: T = E diag(major/w1, minor/w2) Eᵀ keeps the
            // parallelogram's shape and maps Σ to E diag(λ1', λ2') Eᵀ.
            let (s1, s2) = (major / widths[0], minor / widths[1]);
            let t = |v: [f64; 2]| {
                let (p1, p2) = (v[0] * e1[0] + v[1] * e1[1], v[0] * e2[0] + v[1] * e2[1]);
                [
                    s1 * p1 * e1[0] + s2 * p2 * e2[0],
                    s1 * p1 * e1[1] + s2 * p2 * e2[1],
                ]
            };
            a = t(a);
            b = t(b);
        } else {
            // Degenerate (collinear or vanishing edges): a rectangle along the principal axes.
            a = [major * e1[0], major * e1[1]];
            b = [minor * e2[0], minor * e2[1]];
        }
        let (l1, l2) = (major * major / 12.0, minor * minor / 12.0);
        let cov = [
            l1 * e1[0] * e1[0] + l2 * e2[0] * e2[0],
            l1 * e1[0] * e1[1] + l2 * e2[0] * e2[1],
            l1 * e1[1] * e1[1] + l2 * e2[1] * e2[1],
        ];
        TexelView {
            center,
            a,
            b,
            cov,
            widths: [major, minor],
        }
    }

    /// The Gaussian view in texel units of a `width × height` map: (centre, covariance Σ in texels²).
    ///
    /// centre = uv · (width, height); Σ = D (∂uv/∂x ∂uv/∂xᵀ + ∂uv/∂y ∂uv/∂yᵀ) D / 12 with
    /// D = diag(width, height), then clamped along its principal axes (module docs). The footprint
    /// kernel is k_P(p) = exp(−½ (p − c)ᵀ Σ⁻¹ (p − c)) / (2π √det Σ), normalised over the plane.
    ///
    /// # Reference
    /// \[Chermain2019\], §4.1.
    pub fn gaussian_texels(&self, width: usize, height: usize) -> (Vec2, Mat2) {
        let v = self.texel_view(width, height);
        (to_vec2(v.center), to_mat2(v.cov))
    }

    /// The parallelogram view in texel units: (centre c, edge a, edge b); the footprint is
    /// {c + s a + t b : s, t ∈ [−½, ½]}, of area |det[a b]|.
    ///
    /// Without active clamps a = D ∂uv/∂x and b = D ∂uv/∂y exactly. When a clamp applies, both edges are
    /// stretched along the principal axes of Σ (keeping the shape) so that the parallelogram's
    /// covariance is the clamped Σ of [`Footprint::gaussian_texels`]; collinear or vanishing edges are
    /// replaced by a rectangle along the principal axes.
    pub fn parallelogram_texels(&self, width: usize, height: usize) -> (Vec2, Vec2, Vec2) {
        let v = self.texel_view(width, height);
        (to_vec2(v.center), to_vec2(v.a), to_vec2(v.b))
    }

    /// The clamped Gaussian view in uv units: (centre uv, covariance D⁻¹ Σ D⁻¹).
    pub fn gaussian_uv(&self, width: usize, height: usize) -> (Vec2, Mat2) {
        let v = self.texel_view(width, height);
        let (w, h) = (width.max(1) as f64, height.max(1) as f64);
        let cov = [v.cov[0] / (w * w), v.cov[1] / (w * h), v.cov[2] / (h * h)];
        (self.uv, to_mat2(cov))
    }

    /// The clamped parallelogram view in uv units: (centre uv, edge a, edge b).
    pub fn parallelogram_uv(&self, width: usize, height: usize) -> (Vec2, Vec2, Vec2) {
        let v = self.texel_view(width, height);
        let (w, h) = (width.max(1) as f64, height.max(1) as f64);
        let a = [v.a[0] / w, v.a[1] / h];
        let b = [v.b[0] / w, v.b[1] / h];
        (self.uv, to_vec2(a), to_vec2(b))
    }

    /// Widths of the clamped footprint along its principal axes in texels, (major, minor):
    /// w = √(12 λ) for the eigenvalues λ of Σ. The area is major × minor texels².
    pub fn widths_texels(&self, width: usize, height: usize) -> (f32, f32) {
        let v = self.texel_view(width, height);
        (v.widths[0] as f32, v.widths[1] as f32)
    }

    /// Area of the clamped footprint in texels²: |det[a b]| = 12 √det Σ.
    pub fn area_texels(&self, width: usize, height: usize) -> f32 {
        let v = self.texel_view(width, height);
        (v.widths[0] * v.widths[1]) as f32
    }
}

/// `Ok` if every component of the argument `name` is finite, else [`Error::InvalidFootprint`].
pub(crate) fn finite_input(name: &'static str, value: Vec3) -> Result<()> {
    if value.is_finite() {
        return Ok(());
    }
    Err(Error::InvalidFootprint {
        name,
        value: value.to_array(),
        reason: "must be finite",
    })
}

fn to_vec2(v: [f64; 2]) -> Vec2 {
    Vec2::new(v[0] as f32, v[1] as f32)
}

fn to_mat2(c: [f64; 3]) -> Mat2 {
    Mat2::from_cols(
        Vec2::new(c[0] as f32, c[1] as f32),
        Vec2::new(c[1] as f32, c[2] as f32),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_diagonal_and_rotated() {
        let (l, e) = eigen([4.0, 0.0, 1.0]);
        assert_eq!(l, [4.0, 1.0]);
        assert_eq!(e, [1.0, 0.0]);
        let (l, e) = eigen([1.0, 0.0, 4.0]);
        assert_eq!(l, [4.0, 1.0]);
        assert_eq!(e, [0.0, 1.0]);
        // 45°: [[2.5, 1.5], [1.5, 2.5]] has eigenvalues 4 and 1, e1 = (1, 1)/√2.
        let (l, e) = eigen([2.5, 1.5, 2.5]);
        assert!((l[0] - 4.0).abs() < 1e-12 && (l[1] - 1.0).abs() < 1e-12);
        assert!((e[0] - e[1]).abs() < 1e-12 && (e[0] - 0.5f64.sqrt()).abs() < 1e-12);
    }
}
