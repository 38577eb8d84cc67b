//! A small path tracer written against the crate's public API only: the scene (a sphere on a ground
//! plane), a pinhole camera with ray differentials, and the integrator (next-event estimation of a
//! point light and an environment light, multiple importance sampling against BRDF sampling).
//!
//! Every material is a `brdf::Material` in one `Vec`, used the same way: at a hit, its BSDF for
//! the hit's ray footprint and view (`material.bsdf(&footprint, wo, &scratch)`, one `GlintScratch` per thread),
//! then radiance = Σ f(wo, wi) · L · cos θi / pdf, with the geometric cosine (local `wi.z`). World space: y up, lengths in scene units; BRDFs see
//! directions in the local frame of the hit (z = normal, x = ∂p/∂u). See docs/render.md.

use brdf::bxdf::{Bxdf, LobeFlags};
use brdf::frame::Frame;
use brdf::glint::{GlintScratch, RayCone, RayDifferential};
use brdf::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use brdf::{Material, Vec2, Vec3};
use indicatif::ProgressBar;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;
use std::f32::consts::PI;

pub mod showcase;
pub mod timing;

/// Offset of secondary ray origins along the normal (scene units; the scene is ~1 unit across).
const RAY_EPSILON: f32 = 1e-4;
/// Scattering events after the camera ray (the sphere and the plane see each other once or twice).
pub const MAX_BOUNCES: usize = 4;

/// The ground's checkerboard: squares of side `square` scene units alternating between the
/// materials `a` and `b` (indices into [`Scene::materials`]).
pub struct Checker {
    pub a: usize,
    pub b: usize,
    pub square: f32,
}

/// A point light of radiant intensity `intensity` (W/sr per channel).
pub struct PointLight {
    pub position: Vec3,
    pub intensity: Vec3,
}

/// The environment: radiance arriving from direction `d` (world, unit) at infinity.
pub enum Sky {
    /// Horizon-to-zenith blue gradient above, dim brown below, times `scale`.
    Gradient { scale: f32 },
    /// The same radiance from every direction (the white furnace).
    Constant(Vec3),
}

impl Sky {
    /// Radiance toward `-d` from the sky in direction `d`.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match self {
            Sky::Constant(c) => *c,
            Sky::Gradient { scale } => {
                let horizon = Vec3::new(0.95, 0.9, 0.85);
                let zenith = Vec3::new(0.25, 0.45, 0.9);
                let below = Vec3::new(0.25, 0.2, 0.15);
                let c = if d.y >= 0.0 {
                    horizon.lerp(zenith, d.y.sqrt())
                } else {
                    below
                };
                c * *scale
            }
        }
    }
}

/// A pinhole camera: `eye`, orthonormal `forward`, `right`, `up`, `tan_half` = tan(vertical fov / 2).
pub struct Camera {
    pub eye: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    tan_half: f32,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// A camera at `eye` looking at `target` (world up = +y), vertical field of view `fov_deg`.
    pub fn look_at(eye: Vec3, target: Vec3, fov_deg: f32, width: u32, height: u32) -> Camera {
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let tan_half = (0.5 * fov_deg.to_radians()).tan();
        Camera {
            eye,
            forward,
            right,
            up,
            tan_half,
            width,
            height,
        }
    }

    /// One pixel's step in the image plane at unit distance along `forward`.
    fn pixel_step(&self) -> f32 {
        2.0 * self.tan_half / self.height as f32
    }

    /// The (unnormalised) direction through the image point `px` (pixels, y down).
    fn direction(&self, px: Vec2) -> Vec3 {
        let s = self.pixel_step();
        let x = (px.x - 0.5 * self.width as f32) * s;
        let y = (0.5 * self.height as f32 - px.y) * s;
        self.forward + self.right * x + self.up * y
    }

    /// The unit direction through the image point `px` (pixels, y down).
    pub fn direction_to(&self, px: Vec2) -> Vec3 {
        self.direction(px).normalize()
    }

    /// The camera ray toward `p` with its offset rays through the neighbouring pixels (x + 1 to
    /// the right, y + 1 down), aimed as the ray to `p` is: what a camera hit's footprint is made
    /// from (`RayDifferential::footprint`, the tangent-plane step of the Footprint docs' recipe);
    /// secondary hits use the path's `RayCone`.
    pub fn ray_differential(&self, p: Vec3) -> RayDifferential {
        let to_p = p - self.eye;
        let d = to_p / to_p.dot(self.forward).max(1e-6);
        let s = self.pixel_step();
        RayDifferential {
            origin: self.eye,
            direction: d,
            rx_origin: self.eye,
            rx_direction: d + self.right * s,
            ry_origin: self.eye,
            ry_direction: d - self.up * s,
        }
    }
}

/// A ray hit: position, unit normal (geometric = shading), uv and its parametrisation's ∂p/∂u, ∂p/∂v.
pub struct Hit {
    pub p: Vec3,
    pub n: Vec3,
    pub uv: Vec2,
    pub dpdu: Vec3,
    pub dpdv: Vec3,
    /// true: the sphere; false: the ground.
    pub sphere: bool,
}

/// The scene: its materials, one sphere (centre, radius, material index), an optional checkered
/// ground plane y = 0, optional point light, a sky, and the camera.
pub struct Scene {
    pub materials: Vec<Material>,
    pub center: Vec3,
    pub radius: f32,
    pub sphere: usize,
    pub ground: Option<Checker>,
    pub light: Option<PointLight>,
    pub sky: Sky,
    pub camera: Camera,
}

impl Scene {
    /// The nearest hit along o + t d (d unit), t > `RAY_EPSILON`.
    pub fn intersect(&self, o: Vec3, d: Vec3) -> Option<Hit> {
        let sphere = self.sphere_t(o, d);
        let ground = match self.ground {
            Some(_) if d.y.abs() > 1e-8 => Some(-o.y / d.y).filter(|t| *t > RAY_EPSILON),
            _ => None,
        };
        match (sphere, ground) {
            (Some(ts), tg) if tg.is_none_or(|tg| ts < tg) => Some(self.sphere_hit(o + d * ts)),
            (_, Some(tg)) => {
                let p = o + d * tg;
                Some(Hit {
                    p,
                    n: Vec3::Y,
                    uv: Vec2::new(p.x, p.z),
                    dpdu: Vec3::X,
                    dpdv: Vec3::Z,
                    sphere: false,
                })
            }
            _ => None,
        }
    }

    fn sphere_t(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let oc = o - self.center;
        let b = oc.dot(d);
        let c = oc.length_squared() - self.radius * self.radius;
        let disc = b * b - c;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        [-b - s, -b + s].into_iter().find(|t| *t > RAY_EPSILON)
    }

    /// The sphere's parametrisation: u = φ / 2π around +y, v = θ / π from the north pole, so that
    /// (∂p/∂u, ∂p/∂v, n) is right-handed and the map's +v runs down the sphere.
    fn sphere_hit(&self, p: Vec3) -> Hit {
        let l = ((p - self.center) / self.radius).normalize();
        let phi = l.z.atan2(l.x).rem_euclid(2.0 * PI);
        let theta = l.y.clamp(-1.0, 1.0).acos();
        let r = self.radius;
        let dpdu = 2.0 * PI * r * Vec3::new(-l.z, 0.0, l.x);
        let dpdv = PI
            * r
            * Vec3::new(
                theta.cos() * phi.cos(),
                -theta.sin(),
                theta.cos() * phi.sin(),
            );
        let uv = Vec2::new(phi / (2.0 * PI), theta / PI);
        Hit {
            p,
            n: l,
            uv,
            dpdu,
            dpdv,
            sphere: true,
        }
    }

    /// The index of the material at `hit`: the sphere's, or the ground's checker square.
    fn material_at(&self, hit: &Hit) -> usize {
        match (&self.ground, hit.sphere) {
            (Some(Checker { a, b, square }), false) => {
                let c = (hit.p.x / square).floor() + (hit.p.z / square).floor();
                if c.rem_euclid(2.0) < 1.0 { *a } else { *b }
            }
            _ => self.sphere,
        }
    }

    /// Whether nothing blocks o + t d for t in (ε, t_max).
    fn unoccluded(&self, o: Vec3, d: Vec3, t_max: f32) -> bool {
        let blocked = |t: Option<f32>| t.is_some_and(|t| t < t_max);
        let ground = self.ground.is_some() && d.y.abs() > 1e-8 && {
            let t = -o.y / d.y;
            t > RAY_EPSILON && t < t_max
        };
        !ground && !blocked(self.sphere_t(o, d))
    }

    /// Density (per solid angle) of the environment light sampler at a point of normal `n`:
    /// cosine-weighted about the normal (the sky is smooth, so this is close to its product with
    /// a diffuse BRDF).
    fn sky_pdf(n: Vec3, d: Vec3) -> f32 {
        n.dot(d).max(0.0) / PI
    }

    /// One path sample of the radiance arriving at the camera along (o, d); `footprint_scale`
    /// shrinks the pixel's differentials to one sample's share (1/√spp).
    pub fn radiance(
        &self,
        mut o: Vec3,
        mut d: Vec3,
        rng: &mut Pcg32,
        scratch: &GlintScratch,
        footprint_scale: f32,
    ) -> Vec3 {
        let mut total = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        // (normal, BRDF pdf) of the previous vertex, for the MIS weight of a sky hit; None at the camera.
        let mut previous: Option<(Vec3, f32)> = None;
        // Camera hits use the camera's ray differentials; later hits the ray cone of the path,
        // started at one pixel's angle (one sample's share of it) and carried through every bounce.
        let mut cone = RayCone::from_camera(self.camera.pixel_step().atan() * footprint_scale);
        for bounce in 0..=MAX_BOUNCES {
            let Some(hit) = self.intersect(o, d) else {
                let w = previous.map_or(1.0, |(n, pdf)| power_heuristic(pdf, Self::sky_pdf(n, d)));
                total += throughput * self.sky.radiance(d) * w;
                break;
            };
            let frame = Frame::from_surface(hit.n, hit.dpdu, hit.dpdv);
            let wo = frame.to_local(-d);
            if wo.z <= 0.0 {
                break;
            }
            cone = cone.propagate((hit.p - o).length());
            let footprint = if bounce == 0 {
                self.camera
                    .ray_differential(hit.p)
                    .scaled(footprint_scale)
                    .footprint(hit.uv, hit.dpdu, hit.dpdv, hit.p, hit.n)
            } else {
                cone.footprint(hit.uv, hit.dpdu, hit.dpdv, d, hit.n)
            };
            let material = &self.materials[self.material_at(&hit)];
            let bsdf = material.bsdf(&footprint, wo, scratch);
            let u = [
                rng.random::<f32>(),
                rng.random(),
                rng.random(),
                rng.random(),
                rng.random(),
            ];
            total += throughput * self.direct(&hit, &frame, wo, &bsdf, Vec2::new(u[0], u[1]));
            let Some(s) = bsdf.sample(wo, u[2], Vec2::new(u[3], u[4])) else {
                break;
            };
            let (wi, weight, pdf) = (frame.to_world(s.wi), s.weight(), s.pdf);
            throughput *= weight;
            o = hit.p + hit.n * RAY_EPSILON;
            d = wi;
            // The sphere, seen from outside, is convex of curvature 1/radius; the ground is flat.
            // The cone's rule at a bounce (RayCone's docs): the curvature step always, the
            // roughness step unless the sample is a delta lobe's.
            let curvature = if hit.sphere { 1.0 / self.radius } else { 0.0 };
            cone = cone.bounce(curvature, &s);
            // A delta sample (a mirror) has no density to weigh against the sky sampler (its pdf
            // is a convention, not a density: the crate's delta-lobe convention).
            previous = if s.flags.contains(LobeFlags::SPECULAR) {
                None
            } else {
                Some((hit.n, pdf))
            };
        }
        if total.is_finite() {
            total.max(Vec3::ZERO)
        } else {
            Vec3::ZERO
        }
    }

    /// Next-event estimation at a hit: the point light (a delta light: light sampling only) plus one
    /// environment sample drawn with [`Scene::sky_pdf`], weighted against BRDF sampling by the power
    /// heuristic. Each term is f · L · cos θi / pdf with the geometric cos θi = local `wi.z`.
    fn direct(&self, hit: &Hit, frame: &Frame, wo: Vec3, bxdf: &impl Bxdf, u: Vec2) -> Vec3 {
        let origin = hit.p + hit.n * RAY_EPSILON;
        let mut l = Vec3::ZERO;
        if let Some(light) = &self.light {
            let to = light.position - origin;
            let dist2 = to.length_squared();
            let wi_world = to / dist2.sqrt();
            let wi = frame.to_local(wi_world);
            if wi.z > 0.0 && self.unoccluded(origin, wi_world, dist2.sqrt()) {
                l += bxdf.eval(wo, wi) * wi.z * light.intensity / dist2;
            }
        }
        let wi = square_to_cosine_hemisphere(u);
        let pdf_light = pdf_cosine_hemisphere(wi);
        let wi_world = frame.to_world(wi);
        if pdf_light > 0.0 && self.unoccluded(origin, wi_world, f32::INFINITY) {
            let (f, pdf_brdf) = bxdf.eval_pdf(wo, wi);
            let w = power_heuristic(pdf_light, pdf_brdf);
            l += f * self.sky.radiance(wi_world) * (wi.z * w / pdf_light);
        }
        l
    }
}

/// Veach's power heuristic (β = 2) for one sample of strategy a against strategy b ([Veach1997] eq. 9.13).
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a + b > 0.0 && (a + b).is_finite() {
        a / (a + b)
    } else if pdf_a > 0.0 {
        1.0
    } else {
        0.0
    }
}

/// A linear HDR image, row major.
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

/// Renders `scene` at `spp` jittered samples per pixel, rows in parallel (one [`GlintScratch`] per
/// rayon worker via `map_init`), advancing `bar` per row. Deterministic for a given `seed`.
pub fn render(scene: &Scene, spp: u32, seed: u64, bar: &ProgressBar) -> Image {
    let cam = &scene.camera;
    let footprint_scale = 1.0 / (spp.max(1) as f32).sqrt();
    let rows: Vec<Vec<Vec3>> = (0..cam.height)
        .into_par_iter()
        .map_init(GlintScratch::default, |scratch, y| {
            let row = (0..cam.width)
                .map(|x| {
                    let pixel = (y as u64) * cam.width as u64 + x as u64;
                    let mut rng =
                        Pcg32::seed_from_u64(seed ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    let mut sum = Vec3::ZERO;
                    for _ in 0..spp {
                        let px = Vec2::new(
                            x as f32 + rng.random::<f32>(),
                            y as f32 + rng.random::<f32>(),
                        );
                        let d = cam.direction(px).normalize();
                        sum += scene.radiance(cam.eye, d, &mut rng, scratch, footprint_scale);
                    }
                    sum / spp.max(1) as f32
                })
                .collect();
            bar.inc(1);
            row
        })
        .collect();
    Image {
        width: cam.width,
        height: cam.height,
        pixels: rows.concat(),
    }
}
