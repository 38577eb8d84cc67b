//! Shading-frame one-liners.
//!
//! Every direction is expressed in the local shading frame: z is the geometric normal ω_g = (0, 0, 1),
//! x is the tangent along which `alpha_x` acts (a surface's ∂p/∂u; y runs along +∂p/∂v, see
//! [`Frame`]). Directions point *away* from the surface and are unit
//! length unless a function says otherwise. Functions here are total: they never panic, and the ones that
//! can meet a degenerate configuration return an `Option` or a documented 0.

#[cfg(not(feature = "std"))]
use crate::float::Float as _;
use glam::{Vec2, Vec3};

/// The geometric normal ω_g of the local frame.
pub const NORMAL: Vec3 = Vec3::Z;

/// cos θ of a unit direction: its z component.
#[inline]
pub fn cos_theta(w: Vec3) -> f32 {
    w.z
}

/// cos² θ of a unit direction.
#[inline]
pub fn cos2_theta(w: Vec3) -> f32 {
    w.z * w.z
}

/// sin² θ of a unit direction, clamped at 0 (computed as x² + y², exact near the pole).
#[inline]
pub fn sin2_theta(w: Vec3) -> f32 {
    (w.x * w.x + w.y * w.y).max(0.0)
}

/// sin θ of a unit direction.
#[inline]
pub fn sin_theta(w: Vec3) -> f32 {
    sin2_theta(w).sqrt()
}

/// tan² θ of a unit direction; `+∞` for directions in the tangent plane (z = 0).
#[inline]
pub fn tan2_theta(w: Vec3) -> f32 {
    sin2_theta(w) / cos2_theta(w)
}

/// (cos φ, sin φ) of a direction; (1, 0) at the pole where φ is undefined.
#[inline]
pub fn cos_sin_phi(w: Vec3) -> Vec2 {
    let s2 = sin2_theta(w);
    if s2 > 0.0 {
        Vec2::new(w.x, w.y) / s2.sqrt()
    } else {
        Vec2::X
    }
}

/// Whether two directions lie strictly on the same side of the tangent plane.
#[inline]
pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// Whether `w` is usable as a reflection direction: finite, of non-zero length, strictly above the
/// tangent plane.
#[inline]
pub fn is_upper(w: Vec3) -> bool {
    w.is_finite() && w.z > 0.0
}

/// Mirror reflection of `w` about the unit normal `n`: 2 (w·n) n − w. Both point away from the surface.
#[inline]
pub fn reflect(w: Vec3, n: Vec3) -> Vec3 {
    2.0 * w.dot(n) * n - w
}

/// The half vector ω_h = (ω_o + ω_i) / ‖ω_o + ω_i‖ of two unit directions.
///
/// `None` when the sum vanishes (ω_o = −ω_i) or is not finite. Not restricted to the upper hemisphere:
/// callers check the hemisphere themselves.
#[inline]
pub fn half_vector(wo: Vec3, wi: Vec3) -> Option<Vec3> {
    half_vector_cos(wo, wi).map(|(h, _)| h)
}

/// The half vector ω_h of two unit directions and the cosine ω_o·ω_h (= ω_i·ω_h), taken as
/// ‖ω_o + ω_i‖ / 2.
///
/// For unit ω_o, ω_i: ω_o·ω_h = (1 + ω_o·ω_i) / ‖ω_o + ω_i‖ = ‖ω_o + ω_i‖ / 2. The dot product loses
/// every digit as ω_i → −ω_o, where 1 + ω_o·ω_i falls below f32's resolution: a sampler reflecting a
/// grazing ω_o (cos θo ~ 10⁻⁶) about a micronormal near the pole returns ω_i ≈ −ω_o, and ω_o·ω_h then
/// comes out of the order of 10⁻³ and of either sign where the true value is ~10⁻⁵. The norm keeps
/// its relative accuracy. Symmetric in (ω_o, ω_i) to the last bit. `None` as [`half_vector`].
#[inline]
pub fn half_vector_cos(wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
    // A multiply by 1/‖s‖, rounded as `Vec3::try_normalize` rounds.
    let s = wo + wi;
    let len = s.length();
    let rcp = 1.0 / len;
    (rcp.is_finite() && rcp > 0.0).then(|| (s * rcp, 0.5 * len))
}

/// `v` normalised, exactly even where its squared length leaves f32's normal range (below ~10⁻³⁸ or
/// above ~10³⁸: the plain `normalize` then rounds through a subnormal or infinite square and can
/// return a vector of length 0.9); `None` for zero-length or non-finite `v`.
///
/// The common case costs one extra comparison; out of range, `v` is first divided by its largest
/// component. Samplers end with it so that what they return is unit whatever the input (fuzz
/// findings: GGX's visible sampler at α = 10⁻⁴ built a half vector of length ~10⁻²⁰).
#[inline]
pub fn normalize_robust(v: Vec3) -> Option<Vec3> {
    let l2 = v.length_squared();
    if (1e-30..1e30).contains(&l2) {
        return Some(v * (1.0 / l2.sqrt()));
    }
    let s = v.abs().max_element();
    if !(s > 0.0 && s.is_finite()) {
        return None;
    }
    (v / s).try_normalize()
}

/// The slope ñ = (−x/z, −y/z) of a normal ω_n = (x, y, z) (Chermain 2019, §3).
///
/// Returns `None` for normals with z ≤ 0 or non-finite components (slopes are undefined there).
#[inline]
pub fn normal_to_slope(n: Vec3) -> Option<Vec2> {
    if n.z > 0.0 && n.is_finite() {
        let s = Vec2::new(-n.x / n.z, -n.y / n.z);
        s.is_finite().then_some(s)
    } else {
        None
    }
}

/// The unit normal normalize(−x̃, −ỹ, 1) of a slope ñ = (x̃, ỹ) (Chermain 2019, §3).
///
/// A non-finite slope returns the geometric normal `Vec3::Z`, so that callers never see NaN.
#[inline]
pub fn slope_to_normal(s: Vec2) -> Vec3 {
    Vec3::new(-s.x, -s.y, 1.0)
        .try_normalize()
        .unwrap_or(Vec3::Z)
}

/// An orthonormal frame (tangent, bitangent, normal) for moving directions between world space and
/// the local shading frame.
///
/// # Handedness
/// The local x and y axes are the u and v axes of whatever the BRDF is defined over (a normal map's
/// texels, an anisotropic roughness): a texel's slope (x̃, ỹ) is along (x, y). Build the frame of a
/// surface hit with [`Frame::from_surface`]`(n, ∂p/∂u, ∂p/∂v)`: x runs along ∂p/∂u and y along +∂p/∂v
/// whatever the handedness of the parametrisation, so a left-handed (u, v) — a mirrored mesh, a uv
/// set flipped in u — gives a frame of determinant −1 ([`Frame::handedness`] = −1) rather than a map
/// mirrored across its u axis. Every BRDF works on local coordinates, which an orthonormal frame of
/// either handedness preserves (dot products and lengths), so nothing else changes.
/// [`Frame::from_normal_tangent`] always builds y = n × x (determinant +1): it agrees with
/// `from_surface` only for right-handed parametrisations ((∂p/∂u × ∂p/∂v)·n > 0), and on a
/// left-handed one it silently mirrors v, which is invisible on isotropic maps and wrong on brushed
/// or scratched ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Local x axis (tangent) in world space.
    pub x: Vec3,
    /// Local y axis (bitangent) in world space.
    pub y: Vec3,
    /// Local z axis (shading normal) in world space.
    pub z: Vec3,
}

impl Frame {
    /// A frame around the unit normal `n` with an arbitrary but continuous tangent
    /// (Duff et al. 2017, "Building an orthonormal basis, revisited", listing 3).
    pub fn from_normal(n: Vec3) -> Frame {
        let (x, y) = n.any_orthonormal_pair();
        Frame { x, y, z: n }
    }

    /// A frame around the unit normal `n` whose x axis is `tangent` made orthogonal to `n`
    /// (Gram-Schmidt) and whose y axis is n × x (determinant +1). Falls back to
    /// [`Frame::from_normal`] when the tangent is parallel to `n`.
    ///
    /// For a surface hit prefer [`Frame::from_surface`]: with a left-handed parametrisation this
    /// frame's y runs along −∂p/∂v and mirrors anisotropic maps (see the type's docs).
    pub fn from_normal_tangent(n: Vec3, tangent: Vec3) -> Frame {
        match (tangent - n * n.dot(tangent)).try_normalize() {
            Some(x) => Frame {
                x,
                y: n.cross(x),
                z: n,
            },
            None => Frame::from_normal(n),
        }
    }

    /// The shading frame of a surface hit from its normal `n` and the parametrisation's ∂p/∂u,
    /// ∂p/∂v: z = n, x = ∂p/∂u made orthogonal to n (Gram-Schmidt), y = ±(n × x) with the sign
    /// that makes y·∂p/∂v ≥ 0. The map's u and v axes are then the local x and y for either
    /// handedness of (u, v); a left-handed parametrisation gives [`Frame::handedness`] = −1 (see the
    /// type's docs). `n` need not be unit length: it is normalised.
    ///
    /// Degenerate input is handled totally, from the best information left:
    /// - ∂p/∂u zero, non-finite or parallel to n: y = ∂p/∂v made orthogonal to n, x = y × n
    ///   (determinant +1: with one tangent direction known, the handedness is not);
    /// - both tangents unusable: [`Frame::from_normal`] (an arbitrary tangent);
    /// - `n` zero or non-finite: n = ∂p/∂u × ∂p/∂v normalised, and if that fails too the world
    ///   axes (x, y, z). The result is always orthonormal and finite.
    pub fn from_surface(n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Frame {
        let finite = |v: Vec3| Some(v).filter(|v| v.is_finite());
        let Some(n) = finite(n)
            .and_then(normalize_robust)
            .or_else(|| finite(dpdu.cross(dpdv)).and_then(normalize_robust))
        else {
            return Frame {
                x: Vec3::X,
                y: Vec3::Y,
                z: Vec3::Z,
            };
        };
        let tangent = |t: Vec3| finite(t).and_then(|t| normalize_robust(t - n * n.dot(t)));
        match (tangent(dpdu), tangent(dpdv)) {
            (Some(x), v) => {
                let y = n.cross(x);
                // Flip y only on evidence: a usable ∂p/∂v on the other side of n × x.
                let left = v.is_some_and(|v| v.dot(y) < 0.0);
                Frame {
                    x,
                    y: if left { -y } else { y },
                    z: n,
                }
            }
            (None, Some(y)) => Frame {
                x: y.cross(n),
                y,
                z: n,
            },
            (None, None) => Frame::from_normal(n),
        }
    }

    /// The frame's handedness: +1 if (x × y)·z ≥ 0 (right-handed), −1 otherwise (a left-handed
    /// parametrisation given to [`Frame::from_surface`]).
    #[inline]
    pub fn handedness(&self) -> f32 {
        if self.x.cross(self.y).dot(self.z) >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }

    /// World → local.
    #[inline]
    pub fn to_local(&self, w: Vec3) -> Vec3 {
        Vec3::new(w.dot(self.x), w.dot(self.y), w.dot(self.z))
    }

    /// Local → world.
    #[inline]
    pub fn to_world(&self, w: Vec3) -> Vec3 {
        self.x * w.x + self.y * w.y + self.z * w.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn slope_round_trip() {
        let n = Vec3::new(0.3, -0.2, 0.9).normalize();
        let s = normal_to_slope(n).unwrap();
        assert_relative_eq!(s.x, -n.x / n.z);
        let back = slope_to_normal(s);
        assert_relative_eq!(back.x, n.x, epsilon = 1e-6);
        assert_relative_eq!(back.y, n.y, epsilon = 1e-6);
        assert_relative_eq!(back.z, n.z, epsilon = 1e-6);
        assert_eq!(normal_to_slope(Vec3::new(1.0, 0.0, 0.0)), None);
        assert_eq!(normal_to_slope(Vec3::new(f32::NAN, 0.0, 1.0)), None);
        assert_eq!(slope_to_normal(Vec2::new(f32::NAN, 0.0)), Vec3::Z);
    }

    #[test]
    fn reflect_and_half_vector() {
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wi = reflect(wo, Vec3::Z);
        assert_relative_eq!(wi.x, -0.6);
        assert_relative_eq!(wi.z, 0.8);
        let h = half_vector(wo, wi).unwrap();
        assert_relative_eq!(h.z, 1.0);
        assert_eq!(half_vector(wo, -wo), None);
    }

    #[test]
    fn trig_at_pole_and_horizon() {
        assert_eq!(cos_sin_phi(Vec3::Z), Vec2::X);
        assert_eq!(tan2_theta(Vec3::X), f32::INFINITY);
        assert_eq!(sin2_theta(Vec3::Z), 0.0);
        assert!(same_hemisphere(Vec3::Z, Vec3::new(0.0, 1.0, 1e-7)));
        assert!(!same_hemisphere(Vec3::Z, Vec3::X));
    }

    #[test]
    fn frame_round_trip() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.2, 0.5, -0.3).normalize()] {
            let f = Frame::from_normal(n);
            let w = Vec3::new(0.1, -0.7, 0.4).normalize();
            let back = f.to_world(f.to_local(w));
            assert!((back - w).length() < 1e-6);
            assert!((f.to_local(n) - Vec3::Z).length() < 1e-6);
        }
        let f = Frame::from_normal_tangent(Vec3::Z, Vec3::new(1.0, 0.0, 0.5));
        assert!((f.x - Vec3::X).length() < 1e-6);
    }

    fn assert_orthonormal(f: &Frame) {
        for (a, b) in [(f.x, f.y), (f.y, f.z), (f.z, f.x)] {
            assert!(a.dot(b).abs() < 1e-5, "{f:?}");
        }
        for v in [f.x, f.y, f.z] {
            assert!((v.length() - 1.0).abs() < 1e-5, "{f:?}");
        }
    }

    #[test]
    fn from_surface_follows_u_and_v_for_both_handednesses() {
        let n = Vec3::new(0.1, 0.2, 1.0).normalize();
        let (dpdu, dpdv) = (Vec3::new(2.0, 0.1, 0.0), Vec3::new(0.3, 1.5, -0.2));
        for (su, sv) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
            let (pu, pv) = (dpdu * su, dpdv * sv);
            let f = Frame::from_surface(n, pu, pv);
            assert_orthonormal(&f);
            assert!(f.x.dot(pu) > 0.0 && f.y.dot(pv) > 0.0, "{su} {sv}: {f:?}");
            assert!((f.z - n).length() < 1e-6);
            let right = pu.cross(pv).dot(n) > 0.0;
            assert_eq!(f.handedness(), if right { 1.0 } else { -1.0 });
            // Right-handed parametrisations: the same frame as from_normal_tangent.
            let g = Frame::from_normal_tangent(n, pu);
            assert_eq!(right, (g.y - f.y).length() < 1e-6, "{su} {sv}");
            let w = Vec3::new(0.3, -0.5, 0.6).normalize();
            assert!((f.to_world(f.to_local(w)) - w).length() < 1e-6);
        }
    }

    #[test]
    fn from_surface_is_total() {
        let nan = Vec3::splat(f32::NAN);
        let cases = [
            (Vec3::Z, Vec3::ZERO, Vec3::Y),
            (Vec3::Z, Vec3::Z * 3.0, -Vec3::Y),
            (Vec3::Z, nan, Vec3::Y),
            (Vec3::Z, Vec3::ZERO, Vec3::ZERO),
            (Vec3::ZERO, Vec3::X, Vec3::Y),
            (nan, Vec3::X, -Vec3::Y),
            (nan, nan, nan),
            (Vec3::Z * 1e-30, Vec3::X * 1e30, Vec3::Y),
        ];
        for (n, pu, pv) in cases {
            let f = Frame::from_surface(n, pu, pv);
            assert_orthonormal(&f);
        }
        // ∂p/∂u unusable: y follows ∂p/∂v.
        let f = Frame::from_surface(Vec3::Z, Vec3::ZERO, -Vec3::Y);
        assert!((f.y + Vec3::Y).length() < 1e-6);
        // No normal: the parametrisation's.
        let f = Frame::from_surface(nan, Vec3::X, -Vec3::Y);
        assert!((f.z + Vec3::Z).length() < 1e-6);
        assert!((f.y + Vec3::Y).length() < 1e-6);
        assert_eq!(f.handedness(), 1.0);
    }
}
