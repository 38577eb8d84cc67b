//! The orb: a metallic sphere with a high-definition normal map under a point light, rendered with
//! each glint model and with the naive per-position reference (\[Chermain2019\] Fig. 1 and 11).
//!
//! The scene is exactly what the comparison needs and nothing more: one sphere of radius 1 at the
//! origin, one pinhole camera on the +z axis, one point light, direct lighting only (a convex sphere
//! cannot shadow itself, so there are no shadow rays). The normal map is tiled over the sphere's
//! (u, v) parametrisation ([`OrbOptions::tiles`] times); every pixel gets a footprint on the map from
//! analytic ray differentials, and the glint models shade it with one BRDF evaluation:
//!
//! L = f(wo, wi) · cos θi · I / r², f = `MicrofacetBrdf::new(model.patch(&footprint), fresnel)`,
//!
//! in the renderer's measure (f = f_P A_P(wi)/cos θi, so L = f_P A_P(wi) I / r² with the P-BRDF of
//! \[Chermain2019\] eq. 7; src/bxdf/microfacet.rs, "The renderer's measure"). Two references see
//! the same positions of the same pixel kernel (the footprint's Gaussian k_P, pixel-centre frame,
//! linear uv) ([`brdf::glint::footprint_brdf`]): (a) the exact P-BRDF of the interpolated map (eq. 7
//! with the true P-NDF), the quantity the glint models approximate, and (b) conventional
//! normal-mapped rendering, what a renderer without glint support converges to. (b) is not the limit
//! of (a); their gap is the P-BRDF formulation's own modelling difference. See docs/orb.md.

use super::{Artifact, Res, register_font, save_rgb};
use brdf::bxdf::{Bxdf, Masking, MicrofacetBrdf};
use brdf::frame::Frame;
use brdf::fresnel::{ConductorFresnel, Fresnel};
use brdf::glint::{
    BeckmannMixture, BinMap, BinMapParams, BrushedParams, FlakesParams, Footprint, GlintNdf,
    Kernel, MaskingMode, MixtureParams, MixturePatch, NormalMap, NormalRepair, PatchOptions,
    PositionNormalMap, PositionNormalParams, ScratchedParams, TangentConvention, brushed, bumpy,
    flakes, footprint_brdf, scratched,
};
use glam::{Vec2, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use plotters::prelude::*;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Where the normal map comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum MapSource {
    /// One of the crate's procedural generators: "scratched", "brushed", "bumpy" or "flakes".
    Procedural(String),
    /// A normal-map image (PNG/EXR, OpenGL convention, below-horizon normals clamped to z ≥ 0.01).
    File(PathBuf),
}

impl MapSource {
    /// Parses `--map`: a generator name, otherwise a path.
    pub fn parse(s: &str) -> MapSource {
        match s {
            "scratched" | "brushed" | "bumpy" | "flakes" => MapSource::Procedural(s.to_string()),
            _ => MapSource::File(PathBuf::from(s)),
        }
    }

    /// A short name for file names and labels.
    pub fn name(&self) -> String {
        match self {
            MapSource::Procedural(n) => n.clone(),
            MapSource::File(p) => p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "map".to_string()),
        }
    }
}

/// Settings of one orb run. `Default` is the command line's default (≤ 60 s on 2 cores).
#[derive(Clone, Debug)]
pub struct OrbOptions {
    /// Image width and height in pixels.
    pub size: u32,
    /// The normal map.
    pub map: MapSource,
    /// Size of a procedural map (texels per side); ignored for files.
    pub map_size: usize,
    /// How many times the map is tiled over the sphere's u (longitude, full turn) and v (pole to
    /// pole). (2k, k) gives square texels at the equator.
    pub tiles: Vec2,
    /// Samples per pixel of the reference (rounded to twice a square: two independent stratified
    /// halves).
    pub spp: u32,
    /// Samples per pixel of the naive "equal-time" row (0: no such row).
    pub naive_spp: u32,
    /// Slope standard deviation σ_ε of the reference's near-specular lobe, and the mixture's floor.
    pub sigma_eps: f32,
    /// Seed of the procedural map and of the reference's jitter.
    pub seed: u64,
    /// Quasi-Monte Carlo nodes per lobe of the mixture build.
    pub mixture_samples: usize,
    /// Show progress bars on stderr.
    pub progress: bool,
}

impl Default for OrbOptions {
    fn default() -> Self {
        OrbOptions {
            size: 256,
            map: MapSource::Procedural("scratched".to_string()),
            map_size: 1024,
            tiles: Vec2::new(8.0, 4.0),
            spp: 512,
            naive_spp: 16,
            sigma_eps: brdf::glint::DEFAULT_SIGMA_MIN,
            seed: 7,
            mixture_samples: 64,
            progress: true,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scene
// ---------------------------------------------------------------------------------------------

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
        let frame = Frame::from_normal_tangent(hit.n, hit.dpdu);
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

// ---------------------------------------------------------------------------------------------
// Images and renderers
// ---------------------------------------------------------------------------------------------

/// A linear RGB image (row major, row 0 at the top).
#[derive(Clone, Debug)]
pub struct Image {
    /// Width and height in pixels.
    pub size: u32,
    /// Pixels.
    pub pixels: Vec<Vec3>,
}

impl Image {
    /// The mean of the channels of pixel k.
    pub fn value(&self, k: usize) -> f64 {
        let p = self.pixels[k];
        (p.x as f64 + p.y as f64 + p.z as f64) / 3.0
    }
}

fn progress_bar(show: bool, len: u64, msg: &str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg:>34} [{bar:30}] {pos}/{len} {elapsed}") {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(msg.to_string());
    pb
}

/// Renders every pixel with `pixel(x, y)`, rows in parallel, with a progress bar.
fn render_rows(size: u32, bar: &ProgressBar, pixel: impl Fn(u32, u32) -> Vec3 + Sync) -> Image {
    let rows: Vec<Vec<Vec3>> = (0..size)
        .into_par_iter()
        .map(|y| {
            let row = (0..size).map(|x| pixel(x, y)).collect();
            bar.inc(1);
            row
        })
        .collect();
    Image {
        size,
        pixels: rows.concat(),
    }
}

/// Renders the orb with a glint model: one BRDF evaluation per pixel at its centre, with the pixel's
/// footprint ([`render_glint_evals`] with 1 evaluation).
pub fn render_glint<G: GlintNdf + Sync>(scene: &Scene, model: &G, bar: &ProgressBar) -> Image {
    render_glint_evals(scene, model, 1, bar)
}

/// Renders the orb with a glint model and q × q evaluations per pixel (q = ⌊√evals⌋, at least 1):
/// sub-pixel j has its centre at the pixel centre's uv + ∂uv/∂x o_x + ∂uv/∂y o_y (o the sub-pixel
/// centre's offset from the pixel centre, in pixels) and differentials ∂uv/∂x / q, ∂uv/∂y / q, so
/// the q² sub-footprints tile the pixel's parallelogram, and their Gaussians together have the
/// pixel Gaussian's covariance (Σ/q² + the offsets' variance (1 − 1/q²)/12 per pixel axis = 1/12).
/// All sub-pixels share the pixel centre's frame, wo and wi (the linearised footprint the references
/// use). The pixel is the mean of
///
/// L = eval(wo, wi) · cos θi · I / r², eval = `MicrofacetBrdf::new(model.patch(&fp), F)` with
/// separable Smith masking (F G2 D_P / (4 A_P(wo) cos θi), the renderer's measure),
///
/// and 0 where the pixel centre misses the sphere.
///
/// # Reference
/// \[Chermain2019\] eq. 7 (P-BRDF), §4.1 (footprint from ray differentials).
pub fn render_glint_evals<G: GlintNdf + Sync>(
    scene: &Scene,
    model: &G,
    evals: u32,
    bar: &ProgressBar,
) -> Image {
    let q = ((evals.max(1) as f64).sqrt().floor() as u32).max(1);
    render_rows(scene.size, bar, |x, y| glint_pixel(scene, model, x, y, q))
}

/// One pixel of [`render_glint_evals`] with q × q evaluations.
pub fn glint_pixel<G: GlintNdf>(scene: &Scene, model: &G, x: u32, y: u32, q: u32) -> Vec3 {
    let q = q.max(1);
    let Some(sp) = scene.shading(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)) else {
        return Vec3::ZERO;
    };
    let (dx, dy) = (sp.duv_dx / q as f32, sp.duv_dy / q as f32);
    let mut sum = Vec3::ZERO;
    for j in 0..q {
        for i in 0..q {
            let o = Vec2::new(
                (i as f32 + 0.5) / q as f32 - 0.5,
                (j as f32 + 0.5) / q as f32 - 0.5,
            );
            let uv = sp.uv + sp.duv_dx * o.x + sp.duv_dy * o.y;
            let fp = Footprint::from_differentials(uv, dx, dy);
            let brdf = MicrofacetBrdf::new(model.patch(&fp), scene.fresnel)
                .with_masking(Masking::Separable);
            // The renderer's measure: eval × the geometric cos θi.
            let l = brdf.eval(sp.wo, sp.wi) * (sp.wi.z.max(0.0) * sp.irradiance);
            if l.is_finite() {
                sum += l;
            }
        }
    }
    sum / (q * q) as f32
}

/// Both footprint references of one pixel from `samples` positions of its Gaussian footprint k_P
/// ([`footprint_brdf`]), as radiances: (exact P-BRDF (a), normal-mapped (b)). The pixel-centre
/// frame, wo, wi and linear uv are used for every position, as the glint models use them.
pub fn reference_pixel(
    scene: &Scene,
    map: &NormalMap,
    sigma_eps: f32,
    sp: &ShadingPoint,
    samples: usize,
    seed: u64,
) -> (Vec3, Vec3) {
    let r = footprint_brdf(
        map,
        &sp.footprint(),
        Kernel::Gaussian,
        sp.wo,
        sp.wi,
        sigma_eps,
        samples,
        seed,
    );
    let Some(h) = (sp.wo + sp.wi).try_normalize() else {
        return (Vec3::ZERO, Vec3::ZERO);
    };
    // eval × the geometric cos θi × I / r², times Fresnel at the (shared) half vector.
    let scale = scene.fresnel.eval(sp.wo.dot(h)) * (sp.wi.z.max(0.0) * sp.irradiance);
    let finite = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
    (
        finite(scale * r.pbrdf() as f32),
        finite(scale * r.normal_mapped() as f32),
    )
}

/// The two references, each as two independent halves (their mean is the reference, their
/// difference estimates its noise).
pub struct References {
    /// (a) the exact P-BRDF of the interpolated map, halves.
    pub pbrdf: (Image, Image),
    /// (b) conventional normal-mapped rendering, halves.
    pub normal_mapped: (Image, Image),
}

/// Renders both references with `k × k` stratified positions of each pixel's Gaussian footprint
/// per half (seeds `seed` and `seed + 1`).
///
/// # Reference
/// \[Chermain2019\] eq. 7 (P-BRDF) and §5.2.2 (naive sampling of the normal map, σ_ε = 0.01).
pub fn render_references(
    scene: &Scene,
    map: &NormalMap,
    sigma_eps: f32,
    k: u32,
    seed: u64,
    bar: &ProgressBar,
) -> References {
    let samples = (k * k) as usize;
    let half = |s: u64| {
        let pixels: Vec<(Vec3, Vec3)> = (0..scene.size)
            .into_par_iter()
            .flat_map_iter(|y| {
                let row: Vec<(Vec3, Vec3)> = (0..scene.size)
                    .map(|x| {
                        let Some(sp) = scene.shading(Vec2::new(x as f32 + 0.5, y as f32 + 0.5))
                        else {
                            return (Vec3::ZERO, Vec3::ZERO);
                        };
                        let pixel = y as u64 * scene.size as u64 + x as u64;
                        let seed = s.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ pixel;
                        reference_pixel(scene, map, sigma_eps, &sp, samples, seed)
                    })
                    .collect();
                bar.inc(1);
                row
            })
            .collect();
        let image = |f: fn(&(Vec3, Vec3)) -> Vec3| Image {
            size: scene.size,
            pixels: pixels.iter().map(f).collect(),
        };
        (image(|p| p.0), image(|p| p.1))
    };
    let (a0, b0) = half(seed);
    let (a1, b1) = half(seed.wrapping_add(1));
    bar.finish();
    References {
        pbrdf: (a0, a1),
        normal_mapped: (b0, b1),
    }
}

/// Naive sampling at `spp` positions per pixel of its Gaussian footprint: conventional normal-mapped
/// rendering, the estimator whose limit is reference (b).
pub fn render_naive(
    scene: &Scene,
    map: &NormalMap,
    sigma_eps: f32,
    spp: u32,
    seed: u64,
    bar: &ProgressBar,
) -> Image {
    render_rows(scene.size, bar, |x, y| {
        let Some(sp) = scene.shading(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)) else {
            return Vec3::ZERO;
        };
        let pixel = y as u64 * scene.size as u64 + x as u64;
        let seed = (0xA5A5_0000 ^ seed).wrapping_mul(0xD1B5_4A32_D192_ED03) ^ pixel;
        reference_pixel(scene, map, sigma_eps, &sp, spp as usize, seed).1
    })
}

/// The pixel-wise mean of two images.
pub fn mean_image(a: &Image, b: &Image) -> Image {
    Image {
        size: a.size,
        pixels: a
            .pixels
            .iter()
            .zip(&b.pixels)
            .map(|(p, q)| 0.5 * (*p + *q))
            .collect(),
    }
}

/// A [`BeckmannMixture`] seen with fixed patch options (exact / approximate masking, level of
/// detail), so that each variant is a [`GlintNdf`] of its own.
pub struct MixtureVariant<'a> {
    /// The mixture.
    pub mixture: &'a BeckmannMixture,
    /// The patch options of this variant.
    pub options: PatchOptions,
}

impl GlintNdf for MixtureVariant<'_> {
    type Patch<'b>
        = MixturePatch<'b>
    where
        Self: 'b;

    fn patch(&self, footprint: &Footprint) -> MixturePatch<'_> {
        self.mixture.patch_with(footprint, self.options)
    }
}

// ---------------------------------------------------------------------------------------------
// Metrics
// ---------------------------------------------------------------------------------------------

/// Errors of one image against the reference, over the covered pixels, on the mean of the channels.
#[derive(Clone, Copy, Debug, Default)]
pub struct Errors {
    /// ‖m − r‖ / ‖r‖ per pixel (includes the reference's own noise).
    pub rel_rmse: f64,
    /// The same with the reference's noise variance subtracted: √max(0, ‖m − r‖² − ‖a − b‖²/4) / ‖r‖
    /// (a, b the two halves: E‖a − b‖²/4 = E‖r − E r‖²).
    pub rel_rmse_denoised: f64,
    /// ‖m − r‖ / ‖r‖ on 4 × 4 pixel block sums (the look at a quarter of the resolution).
    pub rel_rmse_blocks: f64,
    /// (Σ m − Σ r) / Σ r: the relative error of the total energy.
    pub energy: f64,
}

/// The covered-pixel mask of a scene.
pub fn coverage(scene: &Scene) -> Vec<bool> {
    (0..scene.size * scene.size)
        .map(|k| scene.covered(k % scene.size, k / scene.size))
        .collect()
}

/// Errors of `m` against the reference halves `a`, `b` (reference = their mean) over `mask`.
pub fn errors(m: &Image, a: &Image, b: &Image, mask: &[bool]) -> Errors {
    let n = m.size as usize;
    let (mut e2, mut r2, mut noise2, mut sm, mut sr) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let blocks = n.div_ceil(4);
    let mut bm = vec![0.0f64; blocks * blocks];
    let mut br = vec![0.0f64; blocks * blocks];
    for k in (0..n * n).filter(|&k| mask[k]) {
        let (va, vb, vm) = (a.value(k), b.value(k), m.value(k));
        let vr = 0.5 * (va + vb);
        e2 += (vm - vr) * (vm - vr);
        r2 += vr * vr;
        noise2 += 0.25 * (va - vb) * (va - vb);
        sm += vm;
        sr += vr;
        let blk = (k / n / 4) * blocks + (k % n) / 4;
        bm[blk] += vm;
        br[blk] += vr;
    }
    let be2: f64 = bm.iter().zip(&br).map(|(p, q)| (p - q) * (p - q)).sum();
    let br2: f64 = br.iter().map(|q| q * q).sum();
    let safe = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
    Errors {
        rel_rmse: safe(e2, r2).sqrt(),
        rel_rmse_denoised: safe((e2 - noise2).max(0.0), r2).sqrt(),
        rel_rmse_blocks: safe(be2, br2).sqrt(),
        energy: safe(sm - sr, sr),
    }
}

/// The gap between the references, (b) against (a), over `mask`: both see the same positions, so
/// their noises are correlated and [`errors`]' noise subtraction does not apply. With the per-half
/// differences d_k = b_k − a_k: `rel_rmse` = ‖(d_0 + d_1)/2‖ / ‖r_a‖, `rel_rmse_denoised` the same
/// with the noise of the difference ‖d_0 − d_1‖²/4 subtracted (clamped at 0), `energy`
/// = (Σ b − Σ a) / Σ a; the 4 × 4 column is not computed (0).
pub fn gap_errors(refs: &References, mask: &[bool]) -> Errors {
    let (a0, a1) = (&refs.pbrdf.0, &refs.pbrdf.1);
    let (b0, b1) = (&refs.normal_mapped.0, &refs.normal_mapped.1);
    let (mut e2, mut n2, mut r2, mut sa, mut sb) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for k in (0..a0.pixels.len()).filter(|&k| mask[k]) {
        let (d0, d1) = (b0.value(k) - a0.value(k), b1.value(k) - a1.value(k));
        let ra = 0.5 * (a0.value(k) + a1.value(k));
        e2 += 0.25 * (d0 + d1) * (d0 + d1);
        n2 += 0.25 * (d0 - d1) * (d0 - d1);
        r2 += ra * ra;
        sa += ra;
        sb += 0.5 * (b0.value(k) + b1.value(k));
    }
    let safe = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
    Errors {
        rel_rmse: safe(e2, r2).sqrt(),
        // E‖(d0 + d1)/2‖² = ‖gap‖² + Var, and E‖d0 − d1‖²/4 = Var (independent halves).
        rel_rmse_denoised: safe((e2 - n2).max(0.0), r2).sqrt(),
        rel_rmse_blocks: 0.0,
        energy: safe(sb - sa, sa),
    }
}

/// The reference's own relative noise ‖a − b‖/2 / ‖r‖ over `mask`.
pub fn reference_noise(a: &Image, b: &Image, mask: &[bool]) -> f64 {
    let (mut n2, mut r2) = (0.0, 0.0);
    for k in (0..a.pixels.len()).filter(|&k| mask[k]) {
        let (va, vb) = (a.value(k), b.value(k));
        n2 += 0.25 * (va - vb) * (va - vb);
        r2 += 0.25 * (va + vb) * (va + vb);
    }
    if r2 > 0.0 { (n2 / r2).sqrt() } else { 0.0 }
}

// ---------------------------------------------------------------------------------------------
// Output
// ---------------------------------------------------------------------------------------------

/// The exposure that maps the 90th percentile of the non-zero covered pixel values to 1 (0.5 after
/// [`tone_map`]'s curve): glints span decades, so a high percentile would leave all but the
/// brightest black.
pub fn exposure_of(img: &Image, mask: &[bool]) -> f32 {
    let mut v: Vec<f64> = (0..img.pixels.len())
        .filter(|&k| mask[k])
        .map(|k| img.value(k))
        .filter(|&x| x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    v.sort_by(f64::total_cmp);
    let p = v[((v.len() - 1) as f64 * 0.9) as usize];
    if p > 0.0 { (1.0 / p) as f32 } else { 1.0 }
}

fn srgb(c: f32) -> u8 {
    let c = if c.is_finite() {
        c.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// 8-bit sRGB of an image at `exposure` through the curve c/(1 + c) per channel (Reinhard), so that
/// the brightest glints saturate smoothly; background (pixel centre off the sphere) dark grey.
pub fn tone_map(scene: &Scene, img: &Image, exposure: f32) -> Vec<u8> {
    let mut rgb = Vec::with_capacity(img.pixels.len() * 3);
    for (k, p) in img.pixels.iter().enumerate() {
        let (x, y) = (k as u32 % img.size, k as u32 / img.size);
        if scene
            .hit(Vec2::new(x as f32 + 0.5, y as f32 + 0.5))
            .is_none()
        {
            rgb.extend_from_slice(&[24, 26, 30]);
        } else {
            let c = *p * exposure;
            let c = c / (Vec3::ONE + c);
            rgb.extend_from_slice(&[srgb(c.x), srgb(c.y), srgb(c.z)]);
        }
    }
    rgb
}

/// Lays out tone-mapped panels side by side with a label band above each (two lines of text).
pub fn strip(panels: &[(Vec<u8>, String, String)], size: u32) -> Res<(u32, u32, Vec<u8>)> {
    register_font();
    let band = 40u32;
    let gap = 4u32;
    let n = panels.len() as u32;
    let (w, h) = (n * size + (n.saturating_sub(1)) * gap, size + band);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    for (i, (rgb, _, _)) in panels.iter().enumerate() {
        let x0 = i as u32 * (size + gap);
        for y in 0..size {
            for x in 0..size {
                let src = ((y * size + x) * 3) as usize;
                let dst = (((y + band) * w + x0 + x) * 3) as usize;
                buf[dst..dst + 3].copy_from_slice(&rgb[src..src + 3]);
            }
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let font = ("sans-serif", 14).into_font();
        for (i, (_, line1, line2)) in panels.iter().enumerate() {
            let x0 = (i as u32 * (size + gap)) as i32 + 3;
            root.draw(&Text::new(line1.clone(), (x0, 3), font.clone()))?;
            root.draw(&Text::new(line2.clone(), (x0, 21), font.clone()))?;
        }
        root.present()?;
    }
    Ok((w, h, buf))
}

// ---------------------------------------------------------------------------------------------
// The run
// ---------------------------------------------------------------------------------------------

/// The normal map of the options.
pub fn load_map(opts: &OrbOptions) -> Res<NormalMap> {
    let s = opts.map_size;
    Ok(match &opts.map {
        MapSource::Procedural(name) => match name.as_str() {
            "brushed" => brushed(s, s, BrushedParams::default(), opts.seed)?,
            "bumpy" => bumpy(s, s, 0.25, 4.0, opts.seed)?,
            "flakes" => flakes(s, s, FlakesParams::default(), opts.seed)?,
            _ => scratched(s, s, ScratchedParams::default(), opts.seed)?,
        },
        MapSource::File(path) => {
            NormalMap::load(path, TangentConvention::OpenGl, NormalRepair::ClampZ(0.01))?
        }
    })
}

/// One rendered method: label, image, build and render times in seconds.
pub struct Rendered {
    /// Label.
    pub label: String,
    /// Image.
    pub image: Image,
    /// Precomputation time (s).
    pub build_s: f64,
    /// Render time (s).
    pub render_s: f64,
}

/// Renders both references and every glint method available. Returns the references, their render
/// time (s) and the methods' images (the naive equal-time row included when `naive_spp > 0`).
pub fn render_all(opts: &OrbOptions, map: &NormalMap) -> Res<(References, f64, Vec<Rendered>)> {
    let scene = Scene::new(opts.size, opts.tiles);
    let rows = opts.size as u64;
    let mut out = Vec::new();

    let t = Instant::now();
    let build_bar = progress_bar(opts.progress, 1000, "building the Beckmann mixture");
    let progress = |f: f32| build_bar.set_position((f * 1000.0) as u64);
    let params = MixtureParams {
        sigma_min: opts.sigma_eps,
        samples: opts.mixture_samples,
        ..MixtureParams::default()
    };
    let mixture = BeckmannMixture::build_with_progress(map, params, Some(&progress))?;
    build_bar.finish();
    let mixture_build = t.elapsed().as_secs_f64();

    let exact = MixtureVariant {
        mixture: &mixture,
        options: PatchOptions {
            masking: MaskingMode::Exact,
            ..PatchOptions::default()
        },
    };
    let approximate = MixtureVariant {
        mixture: &mixture,
        options: PatchOptions {
            masking: MaskingMode::Approximate,
            ..PatchOptions::default()
        },
    };
    let filtered = MixtureVariant {
        mixture: &mixture,
        options: PatchOptions {
            masking: MaskingMode::Approximate,
            lod_lobes: 0.0,
            ..PatchOptions::default()
        },
    };
    // The two other glint methods at their defaults, through the same `MicrofacetBrdf` (for the
    // position-normal baseline this is its patch with the moments-lobe masking, not the published
    // BRDF, so that every column differs only in the P-NDF and its masking).
    let t = Instant::now();
    let binmap = BinMap::build(map, BinMapParams::default())?;
    let binmap_build = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let position_normal = PositionNormalMap::build(map, PositionNormalParams::default())?;
    let position_normal_build = t.elapsed().as_secs_f64();
    // The glint methods. Each is one line: a label, the build time, and the model (any GlintNdf).
    let mut glint = |label: &str, build_s: f64, render: &dyn Fn(&ProgressBar) -> Image| {
        let bar = progress_bar(opts.progress, rows, label);
        let t = Instant::now();
        let image = render(&bar);
        bar.finish();
        out.push(Rendered {
            label: label.to_string(),
            image,
            build_s,
            render_s: t.elapsed().as_secs_f64(),
        });
    };
    glint("mixture, exact masking", mixture_build, &|b| {
        render_glint(&scene, &exact, b)
    });
    glint("mixture, approx. masking", mixture_build, &|b| {
        render_glint(&scene, &approximate, b)
    });
    glint("filtered lobe (LOD 0)", mixture_build, &|b| {
        render_glint(&scene, &filtered, b)
    });
    glint("bin map (Atanasov 2020)", binmap_build, &|b| {
        render_glint(&scene, &binmap, b)
    });
    glint("position-normal (Yan 2016)", position_normal_build, &|b| {
        render_glint(&scene, &position_normal, b)
    });
    if opts.naive_spp > 0 {
        let k = ((opts.naive_spp as f64).sqrt().round() as u32).max(1);
        let label = format!("naive, {} spp", k * k);
        glint(&label, 0.0, &|b| {
            render_naive(&scene, map, opts.sigma_eps, k * k, opts.seed, b)
        });
    }

    let k = (((opts.spp / 2).max(1) as f64).sqrt().round() as u32).max(1);
    let bar = progress_bar(
        opts.progress,
        2 * rows,
        &format!("references, 2 × {} spp", k * k),
    );
    let t = Instant::now();
    let refs = render_references(&scene, map, opts.sigma_eps, k, opts.seed, &bar);
    let ref_s = t.elapsed().as_secs_f64();
    Ok((refs, ref_s, out))
}

fn slug(s: &str) -> String {
    let mut out = String::new();
    for c in s.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

/// Renders, measures and writes everything: one PNG per method, the strip, the CSV. Prints the table.
///
/// Errors are measured against reference (a), the exact P-BRDF of the interpolated map, and (for
/// the "vs (b)" column) against (b), normal-mapped rendering; the row "(b) normal-mapped" measured
/// against (a) is the P-BRDF formulation's own modelling gap.
pub fn run(opts: &OrbOptions, out: &Path) -> Res<Vec<Artifact>> {
    std::fs::create_dir_all(out)?;
    let t = Instant::now();
    let map = load_map(opts)?;
    let map_s = t.elapsed().as_secs_f64();
    let name = opts.map.name();
    let (refs, ref_s, mut methods) = render_all(opts, &map)?;
    let scene = Scene::new(opts.size, opts.tiles);
    let mask = coverage(&scene);
    let (a0, a1) = &refs.pbrdf;
    let (b0, b1) = &refs.normal_mapped;
    let reference = mean_image(a0, a1);
    let exposure = exposure_of(&reference, &mask);
    let noise = reference_noise(a0, a1, &mask);
    let noise_b = reference_noise(b0, b1, &mask);
    let k = (((opts.spp / 2).max(1) as f64).sqrt().round() as u32).max(1);
    let ref_label = format!("(a) exact P-BRDF, {} spp", 2 * k * k);
    // Reference (b) as a row, measured against (a): the modelling gap.
    methods.insert(
        0,
        Rendered {
            label: format!("(b) normal-mapped, {} spp", 2 * k * k),
            image: mean_image(b0, b1),
            build_s: 0.0,
            render_s: ref_s,
        },
    );

    let mut artifacts = Vec::new();
    let mut csv = String::from(
        "map,method,build_s,render_s,rel_rmse,rel_rmse_denoised,rel_rmse_4x4,energy_error,\
         rel_rmse_denoised_vs_b,reference_noise\n",
    );
    let _ = writeln!(csv, "{name},\"{ref_label}\",0,{ref_s:.3},,,,,,{noise:.4}");
    println!(
        "orb: {name} map {}x{} ({map_s:.1} s), tiles {}x{}, image {}², σ_ε {}, Gaussian pixel \
         kernel k_P for every row",
        map.width(),
        map.height(),
        opts.tiles.x,
        opts.tiles.y,
        opts.size,
        opts.sigma_eps
    );
    println!(
        "{:<30} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "method (errors vs (a))",
        "build s",
        "render s",
        "rel RMSE",
        "denoised",
        "4x4",
        "energy",
        "vs (b)"
    );
    println!(
        "{ref_label:<30} {:>8} {ref_s:>8.2} {noise:>9.3} {:>9} {:>9} {:>9} {:>9}",
        "-", "(noise)", "-", "-", "-"
    );
    let mut panels = vec![(
        tone_map(&scene, &reference, exposure),
        ref_label.clone(),
        format!("noise {noise:.2}, {ref_s:.1} s"),
    )];
    for m in &methods {
        let e = if m.label.starts_with("(b)") {
            gap_errors(&refs, &mask)
        } else {
            errors(&m.image, a0, a1, &mask)
        };
        // Against (b); for the (b) row itself this is its own noise, so leave it out.
        let vs_b = if m.label.starts_with("(b)") {
            f64::NAN
        } else {
            errors(&m.image, b0, b1, &mask).rel_rmse_denoised
        };
        println!(
            "{:<30} {:>8.2} {:>8.2} {:>9.3} {:>9.3} {:>9.3} {:>+9.3} {:>9.3}",
            m.label,
            m.build_s,
            m.render_s,
            e.rel_rmse,
            e.rel_rmse_denoised,
            e.rel_rmse_blocks,
            e.energy,
            vs_b
        );
        let _ = writeln!(
            csv,
            "{name},\"{}\",{:.3},{:.3},{:.4},{:.4},{:.4},{:.4},{},",
            m.label,
            m.build_s,
            m.render_s,
            e.rel_rmse,
            e.rel_rmse_denoised,
            e.rel_rmse_blocks,
            e.energy,
            if vs_b.is_nan() {
                format!("noise {noise_b:.4}")
            } else {
                format!("{vs_b:.4}")
            }
        );
        let rgb = tone_map(&scene, &m.image, exposure);
        let path = out.join(format!("orb_{name}_{}.png", slug(&m.label)));
        save_rgb(&path, opts.size, opts.size, rgb.clone())?;
        artifacts.push(Artifact::new(
            &path,
            format!(
                "{}: relative RMSE against the exact P-BRDF {:.2} (4×4 blocks {:.2}), energy {:+.1} %, {:.1} s",
                m.label,
                e.rel_rmse,
                e.rel_rmse_blocks,
                100.0 * e.energy,
                m.render_s
            ),
        ));
        panels.push((
            rgb,
            m.label.clone(),
            format!(
                "err {:.2} / 4x4 {:.2}, {:.1} s",
                e.rel_rmse, e.rel_rmse_blocks, m.render_s
            ),
        ));
    }
    let ref_path = out.join(format!("orb_{name}_reference.png"));
    save_rgb(&ref_path, opts.size, opts.size, panels[0].0.clone())?;
    artifacts.insert(
        0,
        Artifact::new(
            &ref_path,
            format!(
                "reference (a), the exact P-BRDF of the interpolated map, {} spp (relative noise {noise:.3})",
                2 * k * k
            ),
        ),
    );
    let (w, h, buf) = strip(&panels, opts.size)?;
    let strip_path = out.join(format!("orb_{name}_strip.png"));
    save_rgb(&strip_path, w, h, buf)?;
    artifacts.insert(
        0,
        Artifact::new(
            &strip_path,
            format!(
                "Metallic orb, {name} normal map ({}², tiled {}×{}), point light, every row with the \
                 pixel's Gaussian footprint: reference (a) (exact P-BRDF), reference (b) \
                 (normal-mapped) and each glint model at the same exposure (errors against (a): \
                 relative RMSE per pixel / on 4×4 blocks, over the pixels fully on the sphere).",
                map.width(),
                opts.tiles.x,
                opts.tiles.y
            ),
        ),
    );
    let csv_path = out.join(format!("orb_{name}.csv"));
    std::fs::write(&csv_path, csv)?;
    artifacts.push(Artifact::new(&csv_path, "The figures of the table (CSV)."));
    for a in &artifacts {
        println!("wrote {}", a.path.display());
    }
    Ok(artifacts)
}

/// The gallery's part: a small strip (scratched 512² map, 160² image, 256 spp), well under 60 s.
pub fn run_gallery(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let opts = if quick {
        OrbOptions {
            size: 160,
            map_size: 512,
            tiles: Vec2::new(4.0, 2.0),
            spp: 256,
            progress: false,
            ..OrbOptions::default()
        }
    } else {
        OrbOptions {
            progress: false,
            ..OrbOptions::default()
        }
    };
    run(&opts, out)
}
