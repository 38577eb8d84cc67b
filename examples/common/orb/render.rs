//! Rendering the orb: each glint model with one (or q × q) BRDF evaluations per pixel, the two
//! footprint references as independent halves, naive sampling of the normal map, [`build_methods`],
//! which builds every glint method at the scene's σ_ε, and [`render_all`], which renders every row
//! of the comparison.

use super::OrbOptions;
use super::scene::{Scene, ShadingPoint};
use crate::common::Res;
use crate::common::material::{Configured, beckmann_alpha, binmap_at};
use brdf::bxdf::{Bxdf, Masking, MicrofacetBrdf, NormalMapTilt, ShadingNormal};
use brdf::frame::slope_to_normal;
use brdf::fresnel::{ConductorFresnel, Fresnel};
use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::{
    BeckmannMixture, Footprint, GlintModel, GlintNdf, Kernel, NormalMap, PositionNormalMap,
    footprint_brdf, for_each_footprint_slope,
};
use brdf::ndf::Beckmann;
use glam::{Vec2, Vec3};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Instant;

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
    if let Ok(style) = ProgressStyle::with_template("{msg:>44} [{bar:30}] {pos}/{len} {elapsed}") {
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

/// Both footprint references of one pixel from `samples` positions of its Gaussian footprint k_P,
/// as radiances: (exact P-BRDF (a), normal-mapped (b)). The pixel-centre frame, wo, wi and linear
/// uv are used for every position, as the glint models use them.
///
/// (a) is [`footprint_brdf`]'s P-BRDF times Fresnel at the shared half vector. (b) is
/// conventional normal mapping through the public [`NormalMapTilt`] adapter, averaged over the
/// same positions ([`for_each_footprint_slope`], same seed): at each position the facet lobe of
/// [`conventional_brdf`], with the scene's Fresnel, evaluated in the renderer's measure.
pub fn reference_pixel(
    scene: &Scene,
    map: &NormalMap,
    sigma_eps: f32,
    sp: &ShadingPoint,
    samples: usize,
    seed: u64,
) -> (Vec3, Vec3) {
    let fp = sp.footprint();
    let r = footprint_brdf(
        map,
        &fp,
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
    // eval × the geometric cos θi × I / r².
    let light = sp.wi.z.max(0.0) * sp.irradiance;
    let fresnel_a = scene.fresnel.eval(sp.wo.dot(h));
    let a = fresnel_a * (r.pbrdf() as f32 * light);
    (
        if a.is_finite() { a } else { Vec3::ZERO },
        normal_mapped_pixel(scene, map, sigma_eps, sp, samples, seed),
    )
}

/// Reference (b) of one pixel alone (the second half of [`reference_pixel`], same positions for
/// the same seed): conventional normal mapping averaged over `samples` positions of the pixel's
/// Gaussian footprint, as a radiance. Naive sampling is this estimator.
pub fn normal_mapped_pixel(
    scene: &Scene,
    map: &NormalMap,
    sigma_eps: f32,
    sp: &ShadingPoint,
    samples: usize,
    seed: u64,
) -> Vec3 {
    let fp = sp.footprint();
    let (mut sum, mut n) = (Vec3::ZERO, 0u32);
    for_each_footprint_slope(map, &fp, Kernel::Gaussian, samples, seed, |slope| {
        if let Some(brdf) = conventional_brdf(slope, sigma_eps, scene.fresnel) {
            sum += brdf.eval(sp.wo, sp.wi);
        }
        n += 1;
    });
    let b = sum / n.max(1) as f32 * (sp.wi.z.max(0.0) * sp.irradiance);
    if b.is_finite() { b } else { Vec3::ZERO }
}

/// Conventional normal mapping at one position of slope `slope`: a near-specular Beckmann lobe
/// (separable masking, Fresnel `fresnel`) in the frame of the interpolated normal n, through
/// [`NormalMapTilt`]; `None` where the slope gives no usable shading normal.
///
/// The lobe is the position's facet lobe of [`brdf::glint::FootprintBrdf`] (slope covariance
/// σ_ε² I in the geometric frame, \[Chermain2019\] §5.2.2) carried into the shading frame: the
/// Jacobian of the map from geometric slopes to shading-frame slopes at n is diag(n_z², n_z) along
/// and across the lean, so the lobe is Beckmann with α_x = √2 σ_ε n_z² along the lean (the
/// tangent) and α_y = √2 σ_ε n_z (D then also matches: D_u(n) = D_shading(n)/n_z). To first order in
/// σ_ε the tilt adapter's value f_inner ⟨wi, n⟩ / cos θi is then the slope lobe's
/// D G1 G1 A(wi) / (4 V(wo) V(wi) cos θi).
pub fn conventional_brdf(
    slope: Vec2,
    sigma_eps: f32,
    fresnel: ConductorFresnel,
) -> Option<NormalMapTilt<MicrofacetBrdf<Beckmann, ConductorFresnel>>> {
    let n = slope_to_normal(slope);
    let lean = Vec3::new(n.x, n.y, 0.0);
    let tangent = lean.try_normalize();
    let shading = ShadingNormal::new(n, tangent).ok()?;
    let a = std::f32::consts::SQRT_2 * sigma_eps;
    let ndf = Beckmann::new(a * n.z * n.z, a * n.z).ok()?;
    let inner = MicrofacetBrdf::new(ndf, fresnel).with_masking(Masking::Separable);
    Some(NormalMapTilt::new(inner, shading))
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
        normal_mapped_pixel(scene, map, sigma_eps, &sp, spp as usize, seed)
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

/// A glint model seen with fixed per-query options (for the mixture: exact / approximate masking,
/// level of detail), so that each variant is a [`GlintNdf`] of its own: its queries take no options
/// (`()`) and pass the variant's to the model, as a renderer's material would.
pub struct WithOptions<'a, G: GlintNdf> {
    /// The model.
    pub model: &'a G,
    /// The per-query options of this variant.
    pub options: G::Options,
}

/// A [`BeckmannMixture`] with fixed [`PatchOptions`].
pub type MixtureVariant<'a> = WithOptions<'a, BeckmannMixture>;

impl<G: GlintNdf> GlintNdf for WithOptions<'_, G> {
    type Patch<'b>
        = G::Patch<'b>
    where
        Self: 'b;

    type Options = ();

    fn patch_with<'b>(
        &'b self,
        footprint: &Footprint,
        _options: &(),
        scratch: Option<&'b brdf::glint::GlintScratch>,
    ) -> G::Patch<'b> {
        self.model.patch_with(footprint, &self.options, scratch)
    }
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

/// One glint method of the orb: its label, the model with the options of its patches, its build
/// time, and for a row kept at its paper's own σ (labelled "paper default"), that σ.
pub struct OrbMethod {
    /// Label.
    pub label: String,
    /// The model and its patch options.
    pub glint: Configured,
    /// Precomputation time (s).
    pub build_s: f64,
    /// The paper's σ of a "paper default" row; `None` for a row at the scene's σ_ε.
    pub paper_sigma: Option<f32>,
}

/// Builds every glint method of the orb, each given the scene's σ_ε (`opts.sigma_eps`) the way its
/// paper allows (examples/common/material.rs): the mixture's lobe floor (exact masking, approximate
/// masking, the filtered lobe), the bin map smoothed by a Beckmann lobe of α = √2 σ_ε, the
/// position-normal elements' σ_r = σ_ε; and the bin map's one-bin resolution (σ = 0) and Yan's
/// σ_r = 0.005 as "paper default" rows. Every model renders through the same `MicrofacetBrdf` (for
/// the position-normal baseline this is its patch with the moments-lobe masking, not the published
/// BRDF, so that every row differs only in the P-NDF and its masking).
pub fn build_methods(opts: &OrbOptions, map: &NormalMap) -> Res<Vec<OrbMethod>> {
    let sigma = opts.sigma_eps;
    let t = Instant::now();
    let build_bar = progress_bar(opts.progress, 1000, "building the Beckmann mixture");
    let progress = |f: f32| build_bar.set_position((f * 1000.0) as u64);
    let params = MixtureParams {
        sigma_min: sigma,
        samples: opts.mixture_samples,
        ..MixtureParams::default()
    };
    let mixture: Arc<GlintModel> =
        Arc::new(BeckmannMixture::build_with_progress(map, params, Some(&progress))?.into());
    // What each model measures for its level of detail is part of its build (and build time).
    build_bar.finish();
    let mixture_build = t.elapsed().as_secs_f64();
    let variant = |masking, lod_lobes| {
        let mut c = Configured::new(mixture.clone());
        c.options.mixture = PatchOptions {
            masking,
            lod_lobes,
            ..PatchOptions::default()
        };
        c
    };
    let default_lod = PatchOptions::default().lod_lobes;
    let t = Instant::now();
    // The masking lobe's floor at σ_ε too.
    let binmap = binmap_at(map, sigma)?;
    let binmap_build = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let pn = |sigma_r| {
        PositionNormalMap::build(
            map,
            PositionNormalParams {
                sigma_r,
                ..PositionNormalParams::default()
            },
        )
        .map(|m| Configured::new(Arc::new(m.into())))
    };
    let position_normal = pn(sigma)?;
    let position_normal_build = t.elapsed().as_secs_f64();
    let paper_r = PositionNormalParams::DEFAULT_SIGMA_R;
    let t = Instant::now();
    let position_normal_paper = pn(paper_r)?;
    let position_normal_paper_build = t.elapsed().as_secs_f64();
    let row = |label: &str, glint, build_s, paper_sigma| OrbMethod {
        label: label.to_string(),
        glint,
        build_s,
        paper_sigma,
    };
    Ok(vec![
        row(
            "mixture, exact masking",
            variant(MaskingMode::Exact, default_lod),
            mixture_build,
            None,
        ),
        row(
            "mixture, approx. masking",
            variant(MaskingMode::Approximate, default_lod),
            mixture_build,
            None,
        ),
        row(
            "filtered lobe (LOD 0)",
            variant(MaskingMode::Approximate, 0.0),
            mixture_build,
            None,
        ),
        row(
            &format!("bin map, α = {:.4}", beckmann_alpha(sigma)),
            Configured::binmap(binmap.clone(), sigma),
            binmap_build,
            None,
        ),
        row(
            "bin map, σ = 0 (paper default)",
            Configured::binmap(binmap, 0.0),
            binmap_build,
            Some(0.0),
        ),
        row(
            &format!("position-normal, σ_r = {sigma}"),
            position_normal,
            position_normal_build,
            None,
        ),
        row(
            &format!("position-normal, σ_r = {paper_r} (paper default)"),
            position_normal_paper,
            position_normal_paper_build,
            Some(paper_r),
        ),
    ])
}

/// Renders both references and every glint method of [`build_methods`]. Returns the references,
/// their render time (s) and the methods' images (the naive equal-time row, at the same σ_ε,
/// included when `naive_spp > 0`).
pub fn render_all(opts: &OrbOptions, map: &NormalMap) -> Res<(References, f64, Vec<Rendered>)> {
    let scene = Scene::new(opts.size, opts.tiles);
    let rows = opts.size as u64;
    let mut out = Vec::new();
    let methods = build_methods(opts, map)?;
    // Each row: a label, the build time, and the render.
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
    for m in &methods {
        glint(&m.label, m.build_s, &|b| render_glint(&scene, &m.glint, b));
    }
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
