//! A small path tracer written against the crate's public API only: the scene (a sphere on a ground
//! plane), a pinhole camera with ray differentials, and the integrator (next-event estimation of a
//! point light and an environment light, multiple importance sampling against BRDF sampling).
//!
//! Every BRDF is used the same way: radiance = Σ f(wo, wi) · L · cos θi / pdf, with the geometric
//! cosine (local `wi.z`); the glint materials are `MicrofacetBrdf::new(model.patch_in(&footprint,
//! scratch), fresnel)` and need nothing else. World space: y up, lengths in scene units; BRDFs see
//! directions in the local frame of the hit (z = normal, x = ∂p/∂u). See docs/render.md.

use super::{Artifact, Res, save_rgb};
use brdf::bxdf::{Bxdf, LayeredBrdf, MicrofacetBrdf};
use brdf::frame::Frame;
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, Fresnel};
use brdf::glint::{
    BeckmannMixture, FlakesParams, Footprint, GlintModel, GlintNdf, GlintScratch, MixtureParams,
    NormalMap, NormalRepair, PatchOptions, ScratchedParams, TangentConvention, flakes, scratched,
};
use brdf::warp::{pdf_cosine_hemisphere, square_to_cosine_hemisphere};
use brdf::{Ggx, Lambert, Vec2, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg32;
use rayon::prelude::*;
use std::f32::consts::PI;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Offset of secondary ray origins along the normal (scene units; the scene is ~1 unit across).
const RAY_EPSILON: f32 = 1e-4;
/// Scattering events after the camera ray (the sphere and the plane see each other once or twice).
pub const MAX_BOUNCES: usize = 4;
/// Footprint growth per bounce: after a diffuse or glossy bounce the rays of one pixel spread far
/// more than the camera's differentials say; ray cones would track it, this example widens the
/// footprint by a fixed factor per bounce (secondary glints are then smooth, as they should be).
const SECONDARY_FOOTPRINT_GROWTH: f32 = 16.0;

/// A surface material. The glint variants hold the model behind an `Arc`, shared by every material
/// that uses the same normal map; `tiles` repeats the map over the sphere's (u, v).
pub enum Material {
    /// A Lambertian checkerboard (the ground), squares of side `square` scene units.
    Checker { a: Lambert, b: Lambert, square: f32 },
    /// An analytic microfacet conductor.
    Conductor(MicrofacetBrdf<Ggx, ConductorFresnel>),
    /// A glint microfacet BRDF over a normal map.
    Glint {
        model: Arc<GlintModel>,
        fresnel: Box<dyn Fresnel + Send + Sync>,
        tiles: Vec2,
    },
    /// A glint specular layer over a Lambertian base of albedo `base` ([`LayeredBrdf`]).
    GlintCoat {
        model: Arc<GlintModel>,
        fresnel: Box<dyn Fresnel + Send + Sync>,
        tiles: Vec2,
        base: Vec3,
    },
}

/// A black BRDF, for the one impossible case (a layered base already validated at scene build).
struct Black;
impl Bxdf for Black {
    fn eval(&self, _: Vec3, _: Vec3) -> Vec3 {
        Vec3::ZERO
    }
    fn pdf(&self, _: Vec3, _: Vec3) -> f32 {
        0.0
    }
    fn sample(&self, _: Vec3, _: f32, _: Vec2) -> Option<brdf::BxdfSample> {
        None
    }
}

impl Material {
    /// Runs `f` with the material's BRDF at `hit`; `dp_dxy` are the hit's ∂p/∂x, ∂p/∂y.
    fn with_bxdf<R>(
        &self,
        hit: &Hit,
        dp_dxy: (Vec3, Vec3),
        scratch: &mut GlintScratch,
        f: impl FnOnce(&dyn Bxdf) -> R,
    ) -> R {
        // The footprint of a map repeated `tiles` times: uv and ∂p/∂(u, v) in tile units (Footprint docs).
        let footprint = |tiles: Vec2| {
            let (dpdu, dpdv) = (hit.dpdu / tiles.x, hit.dpdv / tiles.y);
            Footprint::from_surface_differentials(hit.uv * tiles, dpdu, dpdv, dp_dxy.0, dp_dxy.1)
        };
        match self {
            Material::Checker { a, b, square } => {
                let c = (hit.p.x / square).floor() + (hit.p.z / square).floor();
                f(if c.rem_euclid(2.0) < 1.0 { a } else { b })
            }
            Material::Conductor(brdf) => f(brdf),
            Material::Glint {
                model,
                fresnel,
                tiles,
            } => f(&MicrofacetBrdf::new(
                model.patch_in(&footprint(*tiles), scratch),
                fresnel,
            )),
            Material::GlintCoat {
                model,
                fresnel,
                tiles,
                base,
            } => {
                let coat = MicrofacetBrdf::new(model.patch_in(&footprint(*tiles), scratch), fresnel);
                match LayeredBrdf::new(coat, *base) {
                    Ok(layered) => f(&layered),
                    Err(_) => f(&Black),
                }
            }
        }
    }
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
        Camera { eye, forward, right, up, tan_half, width, height }
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

    /// ∂p/∂x, ∂p/∂y at a hit (p, n): the rays through the neighbouring pixels intersected with the
    /// tangent plane (the Footprint docs' recipe), the rays aimed at p itself. For a camera hit this
    /// is the ray differential; for a secondary hit it is pbrt-v4's approximation
    /// (`Camera::Approximate_dp_dxy`). Zero where an offset ray runs parallel to the plane.
    fn dp_dxy(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let to_p = p - self.eye;
        let d = to_p / to_p.dot(self.forward).max(1e-6);
        let s = self.pixel_step();
        let offset = |step: Vec3| {
            let dir = d + step * s;
            let denom = n.dot(dir);
            if denom.abs() < 1e-8 {
                return Vec3::ZERO;
            }
            self.eye + dir * (n.dot(to_p) / denom) - p
        };
        (offset(self.right), offset(-self.up))
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

/// The scene: one sphere (centre, radius, material), an optional ground plane y = 0, optional point
/// light, a sky, and the camera.
pub struct Scene {
    pub center: Vec3,
    pub radius: f32,
    pub sphere: Material,
    pub ground: Option<Material>,
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
                Some(Hit { p, n: Vec3::Y, uv: Vec2::new(p.x, p.z), dpdu: Vec3::X, dpdv: Vec3::Z, sphere: false })
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
        let dpdv = PI * r * Vec3::new(theta.cos() * phi.cos(), -theta.sin(), theta.cos() * phi.sin());
        let uv = Vec2::new(phi / (2.0 * PI), theta / PI);
        Hit { p, n: l, uv, dpdu, dpdv, sphere: true }
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
        scratch: &mut GlintScratch,
        footprint_scale: f32,
    ) -> Vec3 {
        let mut total = Vec3::ZERO;
        let mut throughput = Vec3::ONE;
        // (normal, BRDF pdf) of the previous vertex, for the MIS weight of a sky hit; None at the camera.
        let mut previous: Option<(Vec3, f32)> = None;
        let mut spread = footprint_scale;
        for _ in 0..=MAX_BOUNCES {
            let Some(hit) = self.intersect(o, d) else {
                let w = previous.map_or(1.0, |(n, pdf)| power_heuristic(pdf, Self::sky_pdf(n, d)));
                total += throughput * self.sky.radiance(d) * w;
                break;
            };
            let frame = Frame::from_normal_tangent(hit.n, hit.dpdu);
            let wo = frame.to_local(-d);
            if wo.z <= 0.0 {
                break;
            }
            let (dpdx, dpdy) = self.camera.dp_dxy(hit.p, hit.n);
            let material = if hit.sphere { &self.sphere } else { self.ground.as_ref().unwrap_or(&self.sphere) };
            let u = [rng.random::<f32>(), rng.random(), rng.random(), rng.random(), rng.random()];
            let (direct, next) = material.with_bxdf(&hit, (dpdx * spread, dpdy * spread), scratch, |bxdf| {
                let direct = self.direct(&hit, &frame, wo, bxdf, Vec2::new(u[0], u[1]));
                let s = bxdf.sample(wo, u[2], Vec2::new(u[3], u[4]));
                (direct, s.map(|s| (frame.to_world(s.wi), s.weight(), s.pdf)))
            });
            total += throughput * direct;
            let Some((wi, weight, pdf)) = next else { break };
            throughput *= weight;
            o = hit.p + hit.n * RAY_EPSILON;
            d = wi;
            previous = Some((hit.n, pdf));
            spread *= SECONDARY_FOOTPRINT_GROWTH;
        }
        if total.is_finite() { total.max(Vec3::ZERO) } else { Vec3::ZERO }
    }

    /// Next-event estimation at a hit: the point light (a delta light: light sampling only) plus one
    /// environment sample drawn with [`Scene::sky_pdf`], weighted against BRDF sampling by the power
    /// heuristic. Each term is f · L · cos θi / pdf with the geometric cos θi = local `wi.z`.
    fn direct(&self, hit: &Hit, frame: &Frame, wo: Vec3, bxdf: &dyn Bxdf, u: Vec2) -> Vec3 {
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
    if a + b > 0.0 && (a + b).is_finite() { a / (a + b) } else if pdf_a > 0.0 { 1.0 } else { 0.0 }
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
                    let mut rng = Pcg32::seed_from_u64(seed ^ pixel.wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    let mut sum = Vec3::ZERO;
                    for _ in 0..spp {
                        let px = Vec2::new(x as f32 + rng.random::<f32>(), y as f32 + rng.random::<f32>());
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
    Image { width: cam.width, height: cam.height, pixels: rows.concat() }
}

/// A progress bar over `len` rows (hidden when `show` is false, e.g. in tests).
pub fn progress_bar(show: bool, len: u64, msg: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg:>24} [{bar:30}] {pos}/{len} rows {elapsed}") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(msg.to_string());
    bar
}

/// 8-bit sRGB of `img` scaled by `exposure`, through Narkowicz's fit of the ACES filmic curve
/// (x (2.51 x + 0.03)) / (x (2.43 x + 0.59) + 0.14) per channel, then the sRGB transfer function.
pub fn tone_map(img: &Image, exposure: f32) -> Vec<u8> {
    let aces = |x: f32| (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0);
    let srgb = |c: f32| {
        let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0).round() as u8
    };
    img.pixels
        .iter()
        .flat_map(|p| {
            let c = *p * exposure;
            [srgb(aces(c.x)), srgb(aces(c.y)), srgb(aces(c.z))]
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// The showcase: four materials on the same sphere
// ---------------------------------------------------------------------------------------------

/// Render settings.
#[derive(Clone, Debug)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Side of the normal maps, in texels.
    pub map_size: usize,
    /// Map texels per pixel across the sphere's equator (the tiling follows from it).
    pub texels_per_pixel: f32,
    pub progress: bool,
}

impl Options {
    /// The gallery's settings (≤ ~40 s for the four images on 2 cores).
    pub fn quick() -> Options {
        Options { width: 320, height: 200, spp: 12, map_size: 256, texels_per_pixel: 3.0, progress: false }
    }
    /// `cargo run --release --example render` without `--quick`.
    pub fn full() -> Options {
        Options { width: 800, height: 500, spp: 32, map_size: 512, texels_per_pixel: 3.0, progress: true }
    }
}

/// A glint model of `map`: the Beckmann mixture of \[Chermain2019\] with 64 quadrature nodes per
/// lobe (the orb example's setting, 4× faster to build than the default) and its level of detail at
/// 256 lobes, so that the wide footprints of secondary hits cost one filtered lobe (the default
/// threshold, 16384, lets a bounce off the ground query thousands of lobes: minutes per image).
pub fn glint_model(map: &NormalMap) -> Res<Arc<GlintModel>> {
    let params = MixtureParams {
        samples: 64,
        patch: PatchOptions { lod_lobes: 256.0, ..PatchOptions::default() },
        ..MixtureParams::default()
    };
    Ok(Arc::new(BeckmannMixture::build(map, params)?.into()))
}

/// A hammered-metal height field (overlapping parabolic dents, the deepest wins), `n` × `n`, tiled,
/// heights in texels; slopes up to ~0.3.
pub fn hammered_heights(n: usize, seed: u64) -> Vec<f32> {
    let mut rng = Pcg32::seed_from_u64(seed);
    let dents: Vec<(Vec2, f32)> = (0..n * n / 40)
        .map(|_| {
            let c = Vec2::new(rng.random::<f32>(), rng.random::<f32>()) * n as f32;
            (c, 4.0 + 6.0 * rng.random::<f32>())
        })
        .collect();
    let wrap = |d: f32| d - n as f32 * (d / n as f32).round();
    (0..n * n)
        .map(|k| {
            let p = Vec2::new((k % n) as f32 + 0.5, (k / n) as f32 + 0.5);
            dents.iter().fold(0.0f32, |h, &(c, r)| {
                let d2 = Vec2::new(wrap(p.x - c.x), wrap(p.y - c.y)).length_squared() / (r * r);
                h.min(-0.15 * r * (1.0 - d2).max(0.0))
            })
        })
        .collect()
}

/// The showcase scene around `sphere`: a unit sphere on a checkered ground, a strong point light
/// above left, a sky gradient. The map tiling puts `texels_per_pixel` texels per pixel on the
/// equator (∂p/∂u spans 2π r, ∂p/∂v π r, hence half as many tiles along v).
pub fn showcase(sphere: impl FnOnce(Vec2) -> Res<Material>, opts: &Options) -> Res<Scene> {
    let camera = Camera::look_at(Vec3::new(0.0, 1.5, 4.2), Vec3::new(0.0, 0.85, 0.0), 32.0, opts.width, opts.height);
    let radius_px = 1.0 / (4.2 * camera.pixel_step());
    let tiles_u = (opts.texels_per_pixel * 2.0 * PI * radius_px / opts.map_size as f32).round().max(1.0);
    let tiles = Vec2::new(tiles_u, (0.5 * tiles_u).round().max(1.0));
    Ok(Scene {
        center: Vec3::new(0.0, 1.0, 0.0),
        radius: 1.0,
        sphere: sphere(tiles)?,
        ground: Some(Material::Checker {
            a: Lambert::new(Vec3::splat(0.6))?,
            b: Lambert::new(Vec3::splat(0.25))?,
            square: 0.5,
        }),
        light: Some(PointLight { position: Vec3::new(-3.0, 5.0, 3.0), intensity: Vec3::splat(70.0) }),
        sky: Sky::Gradient { scale: 0.3 },
        camera,
    })
}

/// Exposure of the showcase images (fixed, so that the four are comparable).
const EXPOSURE: f32 = 1.3;

/// Writes the hammered normal map PNG, then renders the four materials; returns the files.
pub fn run_with(out: &Path, opts: &Options) -> Res<Vec<Artifact>> {
    let n = opts.map_size;
    let mut artifacts = Vec::new();
    // (c)'s asset: a normal map PNG written from a height field, then read back like any file.
    let png = out.join("render_hammered_normals.png");
    let heights = hammered_heights(n, 11);
    let normals = NormalMap::from_heights(n, n, &heights, 1.0)?;
    save_rgb(&png, n as u32, n as u32, normals.to_rgb8(TangentConvention::OpenGl))?;
    artifacts.push(Artifact::new(&png, "the hammered normal map (OpenGL convention) that the render example writes, then loads"));
    let hammered = glint_model(&NormalMap::load(&png, TangentConvention::OpenGl, NormalRepair::Reject)?)?;
    let scratched = glint_model(&scratched(n, n, ScratchedParams::default(), 7)?)?;
    let flakes = glint_model(&flakes(n, n, FlakesParams { cell_texels: 6.0, tilt_sigma: 0.15 }, 3)?)?;
    type Make = Box<dyn FnOnce(Vec2) -> Res<Material>>;
    let shots: [(&str, &str, Make); 4] = [
        ("render_gold.png", "analytic gold: GGX α = 0.15, conductor Fresnel", Box::new(|_| {
            Ok(Material::Conductor(MicrofacetBrdf::new(Ggx::isotropic(0.15)?, ConductorFresnel::GOLD)))
        })),
        ("render_scratched.png", "glints: silver with a procedural scratched map (Beckmann mixture)", Box::new(move |tiles| {
            Ok(Material::Glint { model: scratched, fresnel: Box::new(ConductorFresnel::SILVER), tiles })
        })),
        ("render_hammered.png", "glints: copper with the hammered PNG normal map (Beckmann mixture)", Box::new(move |tiles| {
            Ok(Material::Glint { model: hammered, fresnel: Box::new(ConductorFresnel::COPPER), tiles })
        })),
        ("render_flake_paint.png", "layered: a glint clear coat (flakes map, η = 1.5) over red Lambert paint", Box::new(move |tiles| {
            let fresnel = Box::new(DielectricFresnel::new(1.5)?);
            Ok(Material::GlintCoat { model: flakes, fresnel, tiles, base: Vec3::new(0.5, 0.03, 0.02) })
        })),
    ];
    for (k, (file, caption, make)) in shots.into_iter().enumerate() {
        let scene = showcase(make, opts)?;
        let bar = progress_bar(opts.progress, opts.height as u64, file);
        let t = Instant::now();
        let img = render(&scene, opts.spp, 0x5EED + k as u64, &bar);
        bar.finish();
        let path = out.join(file);
        save_rgb(&path, img.width, img.height, tone_map(&img, EXPOSURE))?;
        let caption = format!(
            "{caption}; {}×{}, {} spp, {:.1} s (cargo run --release --example render)",
            img.width, img.height, opts.spp, t.elapsed().as_secs_f64()
        );
        artifacts.push(Artifact::new(path, caption));
    }
    Ok(artifacts)
}

/// The gallery's entry point.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    run_with(out, &if quick { Options::quick() } else { Options::full() })
}
