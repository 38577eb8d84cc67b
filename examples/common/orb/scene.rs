//! The orb's scene: a unit sphere at the origin, a pinhole camera on +z and a point light; camera
//! rays, their hits with the sphere's (u, v) parametrisation, and the shading point of a pixel with
//! its footprint on the map from analytic ray differentials.

use brdf::frame::Frame;
use brdf::fresnel::ConductorFresnel;
use brdf::glint::Footprint;
use glam::{Vec2, Vec3};

/// The fixed scene: unit sphere at the origin, camera on +z, a point light up and to the left.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Image width = height, in pixels.
    pub size: u32,
    /// Camera position (looking toward −z, +y up).
    pub camera: Vec3,
    /// tan of half the vertical field of view.
    pub tan_half_fov: f32,
    /// Point light position.
    pub light: Vec3,
    /// Point light intensity (radiant intensity, same in every channel).
    pub intensity: f32,
    /// Map tiling over (u, v).
    pub tiles: Vec2,
    /// The conductor.
    pub fresnel: ConductorFresnel,
}

impl Scene {
    /// The orb scene at `size` pixels with the given tiling.
    pub fn new(size: u32, tiles: Vec2) -> Scene {
        Scene {
            size: size.max(1),
            camera: Vec3::new(0.0, 0.0, 5.0),
            // The sphere subtends asin(1/5) = 11.5° (tan 0.204): 0.22 leaves a small margin.
            tan_half_fov: 0.22,
            light: Vec3::new(-2.0, 2.5, 7.0),
            intensity: 60.0,
            tiles,
            fresnel: ConductorFresnel::ALUMINIUM,
        }
    }

    /// The unnormalised camera ray direction through the continuous pixel position `px`
    /// (x right, y down, pixel (i, j) covers [i, i + 1) × [j, j + 1)), and its derivatives along x, y.
    fn ray(&self, px: Vec2) -> (Vec3, Vec3, Vec3) {
        let s = 2.0 * self.tan_half_fov / self.size as f32;
        let dir = Vec3::new(
            (px.x - 0.5 * self.size as f32) * s,
            (0.5 * self.size as f32 - px.y) * s,
            -1.0,
        );
        (dir, Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, -s, 0.0))
    }

    /// The sphere hit of the ray through `px`, if any.
    pub fn hit(&self, px: Vec2) -> Option<Hit> {
        let (dir, _, _) = self.ray(px);
        let d = dir.normalize();
        intersect_unit_sphere(self.camera, d).map(|t| Hit::at(self.camera + t * d, t))
    }

    /// Whether the whole pixel (its four corners) lies on the sphere: the pixels the errors are
    /// measured on (silhouette pixels are partly background in the reference).
    pub fn covered(&self, x: u32, y: u32) -> bool {
        [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
            .iter()
            .all(|&(a, b)| self.hit(Vec2::new(x as f32 + a, y as f32 + b)).is_some())
    }

    /// The shading point of the ray through `px`: frame, directions, map uv and its derivatives.
    pub fn shading(&self, px: Vec2) -> Option<ShadingPoint> {
        let (dir, ddir_dx, ddir_dy) = self.ray(px);
        let len = dir.length();
        let d = dir / len;
        // Derivative of normalize(dir): (ḋ − d (d·ḋ)) / |dir|.
        let dd = |v: Vec3| (v - d * d.dot(v)) / len;
        let (dd_dx, dd_dy) = (dd(ddir_dx), dd(ddir_dy));
        let t = intersect_unit_sphere(self.camera, d)?;
        let hit = Hit::at(self.camera + t * d, t);
        // p(x) = o + t(x) d(x) constrained to the surface: to first order n·dp = 0, so
        // dt = −t (n·ḋ)/(n·d) and dp = t ḋ + dt d ([Igehy1999], transfer onto the tangent plane).
        let nd = hit.n.dot(d);
        let dp = |ddv: Vec3| t * ddv - d * (t * hit.n.dot(ddv) / nd);
        let (dp_dx, dp_dy) = (dp(dd_dx), dp(dd_dy));
        // ∂p/∂u ⊥ ∂p/∂v on a sphere: project dp on each.
        let duv = |dpv: Vec3| {
            Vec2::new(
                dpv.dot(hit.dpdu) / hit.dpdu.length_squared(),
                dpv.dot(hit.dpdv) / hit.dpdv.length_squared(),
            )
        };
        let frame = Frame::from_surface(hit.n, hit.dpdu, hit.dpdv);
        let to_light = self.light - hit.p;
        let r2 = to_light.length_squared();
        Some(ShadingPoint {
            frame,
            uv: hit.uv * self.tiles,
            duv_dx: duv(dp_dx) * self.tiles,
            duv_dy: duv(dp_dy) * self.tiles,
            wo: frame.to_local(-d),
            wi: frame.to_local(to_light / r2.sqrt()),
            irradiance: self.intensity / r2,
        })
    }
}

/// The nearest positive t with |o + t d| = 1 (d unit), if the ray hits the unit sphere.
fn intersect_unit_sphere(o: Vec3, d: Vec3) -> Option<f32> {
    let b = o.dot(d);
    let c = o.length_squared() - 1.0;
    let disc = b * b - c;
    if disc.is_nan() || disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t > 0.0).then_some(t)
}

/// A point on the unit sphere with its (u, v) parametrisation and tangents.
///
/// p = (sin θ sin φ, cos θ, sin θ cos φ), u = φ / 2π ∈ [0, 1) (φ = 0 faces the camera), v = 1 − θ/π
/// (v = 0 at the bottom pole), so ∂p/∂u points east and ∂p/∂v north: (∂p/∂u, ∂p/∂v, n) is right
/// handed and the map's slope axes (x̃ along +u, ỹ along +v) are the frame's x and y.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    /// Position (= outward unit normal).
    pub p: Vec3,
    /// Outward unit normal.
    pub n: Vec3,
    /// Sphere (u, v) in [0, 1)².
    pub uv: Vec2,
    /// ∂p/∂u = 2π (n_z, 0, −n_x).
    pub dpdu: Vec3,
    /// ∂p/∂v = π (−n_x n_y / ρ, ρ, −n_y n_z / ρ), ρ = sin θ.
    pub dpdv: Vec3,
    /// Ray parameter.
    pub t: f32,
}

impl Hit {
    fn at(p: Vec3, t: f32) -> Hit {
        let n = p.normalize_or(Vec3::Z);
        let theta = n.y.clamp(-1.0, 1.0).acos();
        let phi = n.x.atan2(n.z);
        let u = (phi / std::f32::consts::TAU).rem_euclid(1.0);
        let v = 1.0 - theta / std::f32::consts::PI;
        // At the poles (ρ → 0) the parametrisation degenerates; keep the tangents finite and
        // orthogonal (the footprint clamps take over there).
        let rho = (n.x * n.x + n.z * n.z).sqrt().max(1e-6);
        let dpdu = std::f32::consts::TAU * Vec3::new(n.z, 0.0, -n.x);
        let dpdv = std::f32::consts::PI * Vec3::new(-n.x * n.y / rho, rho, -n.y * n.z / rho);
        Hit {
            p,
            n,
            uv: Vec2::new(u, v.clamp(0.0, 1.0)),
            dpdu: if dpdu.length_squared() > 0.0 {
                dpdu
            } else {
                Vec3::X
            },
            dpdv,
            t,
        }
    }
}

/// Everything the shading of one pixel needs, in the sphere's tangent frame (z = n, x = ∂p/∂u).
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// World ↔ tangent frame.
    pub frame: Frame,
    /// Map uv (sphere uv × tiles).
    pub uv: Vec2,
    /// ∂uv/∂x of the map.
    pub duv_dx: Vec2,
    /// ∂uv/∂y of the map.
    pub duv_dy: Vec2,
    /// Toward the camera, local.
    pub wo: Vec3,
    /// Toward the light, local.
    pub wi: Vec3,
    /// I / r².
    pub irradiance: f32,
}

impl ShadingPoint {
    /// The footprint of the pixel on the map.
    pub fn footprint(&self) -> Footprint {
        Footprint::from_differentials(self.uv, self.duv_dx, self.duv_dy)
    }
}
