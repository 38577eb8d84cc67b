//! Accuracy against speed for every glint method: the comparison harness of `examples/compare.rs`.
//!
//! For each procedural map and each method (× setting), it measures
//! - the P-NDF's total-variation distance to two ground truths, per footprint size, averaged over
//!   the footprint centres (three; one with `--quick`) (Gaussian kernel, equal-area bins):
//!   - the **Dirac truth** (`binned_pndf`): the P-NDF of the interpolated normal map itself;
//!   - the **convolved truth** (`convolved_pndf`): the same surface with the material's micro-roughness,
//!     each position's normal spread by the slope Gaussian of σ_ε = 0.01 ([`SIGMA_EPS`]);
//!
//!   both on 64² bins, and on 128² bins as well for footprints up to [`Settings::fine_up_to`] texels,
//!   where 64² bins (~0.044 in slope near the pole, 4.4 σ_ε) blur the glints. Each model's bin masses
//!   come from `adaptive_bin_masses` (midpoint grids refined per bin 2 × 2 → 4 × 4 → … until the
//!   masses change by less than 10⁻³ in TV), and the grid reached is reported;
//! - the cost: build time, bytes per texel, patch construction, one `d` and one BRDF evaluation
//!   (single thread, precomputed inputs, mean over a batch);
//! - per view angle θo (one footprint size): the relative error of the visible projected area
//!   V(wo) = ∫⟨wo, m⟩⁺ D dm against the ground truth's (from its bins), where masking and
//!   normalisation fail at grazing angles, and the white furnace (F = 1) in the patch's own measure
//!   ∫ f A_P(wi)⁺ dωi and with the geometric cosine ∫ f cos θi dωi (docs/mixture.md, "Energy").
//!
//! It writes CSV tables and PNG charts (accuracy against time with the Pareto front, error against
//! footprint size, error and energy against view angle) and prints markdown tables.
//!
//! Methods plug in through [`Method`] (an object-safe view of `brdf::glint::GlintNdf` plus the
//! method's own BRDF); [`builders`] lists them.

use super::pndf_images::maps;
use super::{Artifact, Chart, Res, Scale, Series, line_chart, r2, view};
use brdf::bxdf::{Bxdf, Masking};
use brdf::fresnel::NoFresnel;
use brdf::glint::{
    BeckmannMixture, BinMap, BinMapParams, BinnedPndf, DEFAULT_LOD_LOBES, DEFAULT_MAX_QUADRATURE,
    DEFAULT_QUADRATURE_TOLERANCE, Footprint, GlintNdf, HemisphereBins, Kernel, MaskingMode,
    MixtureParams, NormalMap, PatchOptions, PositionNormalBrdf, PositionNormalMap,
    PositionNormalParams, adaptive_bin_masses, binned_pndf, convolved_pndf,
};
use brdf::ndf::Ndf;
use brdf::{MicrofacetBrdf, Vec2, Vec3};
use std::fmt::Write as _;
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// σ_ε of the convolved truth: the paper's material (\[Chermain2019\] §5.2.2) and the mixture's default
/// variance floor (`MixtureParams::sigma_min`, which floors each lobe's slope σ rather than adding to
/// it). The position-normal baseline adds its own σ_r = 0.005 and the smoothed bin map α = 0.02
/// (σ ≈ 0.014); one truth for all keeps the comparison about the surface, not each model's roughness.
pub const SIGMA_EPS: f64 = brdf::ndf::DEFAULT_SIGMA_MIN as f64;

/// One glint method at one setting, object-safe: the patch of a footprint as `&(dyn Ndf + Sync)`, and the
/// method's BRDF for that footprint.
pub trait Method: Sync {
    /// Legend label, e.g. "mixture (exact)".
    fn label(&self) -> String;
    /// Bytes held per texel of the map (the method's own structures).
    fn bytes_per_texel(&self) -> f64;
    /// Calls `f` with the footprint's patch.
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync)));
    /// Calls `f` with the footprint's BRDF (F = 1). Default: `MicrofacetBrdf` on the patch with
    /// separable G2 (\[Chermain2019\] eq. 7, 16).
    fn with_brdf(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Bxdf + Sync))) {
        self.with_patch(footprint, &mut |p| {
            f(&MicrofacetBrdf::new(p, NoFresnel).with_masking(Masking::Separable))
        });
    }
}

/// The Beckmann mixture with given patch options.
struct Mixture {
    mix: Arc<BeckmannMixture>,
    options: PatchOptions,
    label: &'static str,
    /// Only the moment mip chain counts (the filtered lobe alone needs nothing else).
    mip_only: bool,
}

impl Method for Mixture {
    fn label(&self) -> String {
        self.label.to_string()
    }
    fn bytes_per_texel(&self) -> f64 {
        let m = self.mix.memory();
        let (w, h) = self.mix.map_size();
        let bytes = if self.mip_only {
            m.mip_bytes
        } else {
            m.lobe_bytes + m.hierarchy_bytes + m.mip_bytes
        };
        bytes as f64 / (w * h) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.mix.patch_with(footprint, self.options))
    }
}

/// Builds a method family from a map: the methods (settings sharing one build) and the build time.
pub type Builder = fn(&NormalMap, &Settings) -> Res<Vec<Box<dyn Method>>>;

/// The Beckmann mixture of \[Chermain2019\] at its defaults: exact terms, approximate terms, the
/// default level of detail (only when a footprint exceeds it: otherwise it is the exact variant),
/// and the single filtered Beckmann lobe (the cheapest model).
fn mixture_methods(map: &NormalMap, settings: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mix = Arc::new(BeckmannMixture::build(map, MixtureParams::default())?);
    // Tolerance 0: these rows are the full mixture (or the filtered lobe), not a level of detail.
    let opts = |masking, lod_lobes| PatchOptions {
        masking,
        lod_lobes,
        lod_tolerance: 0.0,
        ..PatchOptions::default()
    };
    let inf = f32::INFINITY;
    let m = |options, label, mip_only| -> Box<dyn Method> {
        Box::new(Mixture {
            mix: mix.clone(),
            options,
            label,
            mip_only,
        })
    };
    let mut methods = vec![
        m(opts(MaskingMode::Exact, inf), "mixture (exact)", false),
        m(
            opts(MaskingMode::Approximate, inf),
            "mixture (approx.)",
            false,
        ),
    ];
    if settings.areas.iter().any(|&a| a > DEFAULT_LOD_LOBES) {
        methods.push(m(PatchOptions::default(), "mixture (default LOD)", false));
    }
    methods.push(m(
        opts(MaskingMode::Approximate, 0.0),
        "filtered lobe",
        true,
    ));
    Ok(methods)
}

/// The inverse bin map of \[Atanasov2020\] at one bin count, optionally smoothed by a Beckmann lobe.
struct BinMapMethod {
    map: Arc<BinMap>,
    /// Beckmann α of the smoothed variant (`None`: one-bin resolution, the talk's model).
    smoothing: Option<f32>,
}

impl Method for BinMapMethod {
    fn label(&self) -> String {
        let (n, s) = (self.map.params().bins_per_axis, self.map.subdivisions());
        match self.smoothing {
            None => format!("bin map (B = {n}², s = {s})"),
            Some(a) => format!("bin map (B = {n}², s = {s}, smoothed α = {a})"),
        }
    }
    fn bytes_per_texel(&self) -> f64 {
        self.map.memory().total() as f64 / (self.map.width() * self.map.height()) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        match self.smoothing {
            None => f(&self.map.patch(footprint)),
            Some(a) => f(&self.map.patch_smoothed(footprint, a)),
        }
    }
}

/// The bin map at B = 63², 127² and 255² (the default) with the default sub-texel resolution
/// (s = 2), the talk's one normal per texel (127², s = 1), and 127², s = 2 smoothed by α = 0.02
/// (the smoothed cost grows with (n α)², so it is shown at 127², the default before issue 17).
fn binmap_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    for (n, s) in [(63, 2), (127, 1), (127, 2), (255, 2)] {
        let params = BinMapParams {
            bins_per_axis: n,
            subdivisions: s,
            ..BinMapParams::default()
        };
        let bm = Arc::new(BinMap::build(map, params)?);
        methods.push(Box::new(BinMapMethod {
            map: bm.clone(),
            smoothing: None,
        }));
        if n == 127 && s == 2 {
            methods.push(Box::new(BinMapMethod {
                map: bm,
                smoothing: Some(0.02),
            }));
        }
    }
    Ok(methods)
}

/// The position-normal distributions of \[Yan2016\] (the baseline) at one sampling rate, with the BRDF
/// as published (a footprint-independent Smith term, cosines in the denominator).
struct PositionNormalMethod {
    map: Arc<PositionNormalMap>,
}

impl Method for PositionNormalMethod {
    fn label(&self) -> String {
        format!(
            "position-normal (rate {}, published BRDF)",
            self.map.params().sampling_rate
        )
    }
    fn bytes_per_texel(&self) -> f64 {
        let m = self.map.memory();
        let (w, h) = self.map.map_size();
        (m.element_bytes + m.hierarchy_bytes) as f64 / (w * h) as f64
    }
    fn with_patch(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Ndf + Sync))) {
        f(&self.map.patch(footprint))
    }
    fn with_brdf(&self, footprint: &Footprint, f: &mut dyn FnMut(&(dyn Bxdf + Sync))) {
        f(&PositionNormalBrdf::new(
            self.map.patch(footprint),
            NoFresnel,
        ))
    }
}

/// The position-normal baseline at its default rate (1 element per texel) and at rate 2.
fn position_normal_methods(map: &NormalMap, _: &Settings) -> Res<Vec<Box<dyn Method>>> {
    let mut methods: Vec<Box<dyn Method>> = Vec::new();
    for rate in [1, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            ..PositionNormalParams::default()
        };
        methods.push(Box::new(PositionNormalMethod {
            map: Arc::new(PositionNormalMap::build(map, params)?),
        }));
    }
    Ok(methods)
}

/// Every method family compared, with a name for the build-time table.
///
pub fn builders() -> Vec<(&'static str, Builder)> {
    vec![
        ("Beckmann mixture", mixture_methods as Builder),
        ("inverse bin map", binmap_methods as Builder),
        ("position-normal", position_normal_methods as Builder),
    ]
}

/// Settings of one run.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Map side in texels.
    pub size: usize,
    /// Ground-truth positions per footprint.
    pub reference_samples: usize,
    /// Footprint areas in texels.
    pub areas: Vec<f32>,
    /// View angles in degrees.
    pub thetas: Vec<f64>,
    /// Footprint area of the view-angle sweep.
    pub view_area: f32,
    /// Importance samples per furnace value.
    pub furnace_samples: usize,
    /// Finest per-bin grid of the adaptive quadrature (k of k × k).
    pub max_quadrature: usize,
    /// Tolerance of the adaptive quadrature (change of the bin masses in TV).
    pub quadrature_tolerance: f64,
    /// Footprints up to this many texels are also compared on 128² bins.
    pub fine_up_to: f32,
    /// Footprint centres averaged over (1 to 3, from [`CENTERS`]).
    pub centers: usize,
}

impl Settings {
    /// `--quick`: 1024² maps, footprints up to 256 texels, one footprint centre, 128² bins up to 1
    /// texel (the adaptive quadrature needs ≥ 20 evaluations per bin where a fixed 2 × 2 rule took 4,
    /// and one `d` costs 0.3-1.3 ms at 4096 texels: that size alone took ~5 minutes per map);
    /// otherwise 2048² maps, footprints up to 65536 texels (beyond the default level of detail), 4×
    /// the reference samples, three centres and 128² bins up to 16 texels. The quick run also stops
    /// the per-bin quadrature at 16 × 16 points and a TV change of 5·10⁻³ (the full run: 64 × 64 and
    /// 10⁻³), which keeps the gallery's run to minutes; its TV figures are then good to ~0.005, and
    /// spiky models that have not converged at 16 × 16 say so in the `quad_change` column.
    pub fn new(quick: bool) -> Settings {
        Settings {
            size: if quick { 1024 } else { 2048 },
            reference_samples: if quick { 1_000_000 } else { 4_000_000 },
            areas: if quick {
                vec![0.25, 1.0, 16.0, 256.0]
            } else {
                vec![0.25, 1.0, 16.0, 256.0, 4096.0, 16384.0, 65536.0]
            },
            thetas: vec![0.0, 30.0, 60.0, 75.0, 85.0, 89.0],
            view_area: 256.0,
            furnace_samples: if quick { 500 } else { 2000 },
            max_quadrature: if quick { 16 } else { DEFAULT_MAX_QUADRATURE },
            quadrature_tolerance: if quick {
                5e-3
            } else {
                DEFAULT_QUADRATURE_TOLERANCE
            },
            fine_up_to: if quick { 1.0 } else { 16.0 },
            centers: if quick { 1 } else { 3 },
        }
    }

    /// Tiny settings for the test of the code paths.
    pub fn tiny() -> Settings {
        Settings {
            size: 64,
            reference_samples: 20_000,
            areas: vec![1.0, 64.0],
            thetas: vec![0.0, 85.0],
            view_area: 16.0,
            furnace_samples: 64,
            max_quadrature: DEFAULT_MAX_QUADRATURE,
            quadrature_tolerance: DEFAULT_QUADRATURE_TOLERANCE,
            fine_up_to: 1.0,
            centers: 1,
        }
    }
}

/// Footprint centres (uv); TV is averaged over them.
const CENTERS: [[f32; 2]; 3] = [[0.43, 0.57], [0.71, 0.23], [0.17, 0.81]];

/// TV of a model to both truths on one binning, each truth's noise floor (`tv_error`), and the
/// quadrature used (means over the footprint centres; `k` the finest grid, `change` the largest
/// final change).
#[derive(Clone, Copy, Debug, Default)]
pub struct TwoTruths {
    pub dirac: f64,
    pub convolved: f64,
    pub noise_dirac: f64,
    pub noise_convolved: f64,
    pub k: usize,
    pub change: f64,
}

/// One row of the accuracy table.
#[derive(Clone, Debug)]
pub struct AccuracyRow {
    pub map: &'static str,
    pub method: String,
    pub area: f32,
    /// On 64² bins.
    pub tv: TwoTruths,
    /// On 128² bins (footprints up to [`Settings::fine_up_to`] texels).
    pub tv_fine: Option<TwoTruths>,
    pub patch_s: f64,
    pub d_s: f64,
    pub eval_s: f64,
}

/// One row of the view-angle table.
#[derive(Clone, Debug)]
pub struct ViewRow {
    pub map: &'static str,
    pub method: String,
    pub theta: f64,
    pub v_rel_error: f64,
    /// ∫ f cos θi dωi with the geometric cosine (the renderer's measure).
    pub furnace: f64,
}

/// One row of the build table.
#[derive(Clone, Debug)]
pub struct BuildRow {
    pub map: &'static str,
    pub family: &'static str,
    pub build_s: f64,
    pub method: String,
    pub bytes_per_texel: f64,
}

/// Everything one run measured.
#[derive(Default, Debug)]
pub struct Results {
    pub accuracy: Vec<AccuracyRow>,
    pub view: Vec<ViewRow>,
    pub build: Vec<BuildRow>,
}

/// ∫⟨wo, m⟩⁺ D dm of the ground truth from its bins: Σ_b mass_b ⟨wo, m_b⟩⁺ / cos θ_b (bin centres).
fn reference_visible_area(reference: &BinnedPndf, wo: Vec3) -> f64 {
    let bins = reference.bins();
    reference
        .mass()
        .iter()
        .zip(reference.cos_theta())
        .enumerate()
        .filter(|(_, (m, c))| **m > 0.0 && **c > 0.0)
        .map(|(b, (m, c))| m * (bins.center(b).dot(wo) as f64).max(0.0) / c)
        .sum()
}

/// The renderer's furnace ∫ f cos θi dωi: the mean of `sample().weight()` with the BRDF's own sampler.
fn furnace(brdf: &(dyn Bxdf + Sync), wo: Vec3, n: usize) -> f64 {
    let mut sum = 0.0;
    for k in 0..n {
        let u = r2(k);
        let uc = ((k as f64 + 0.5) / n as f64) as f32;
        if let Some(s) = brdf.sample(wo, uc, u) {
            sum += s.weight().x as f64;
        }
    }
    sum / n as f64
}

/// Mean single-thread seconds per call of `f` over `n` inputs (after one warm-up pass).
fn time_per_call(n: usize, mut f: impl FnMut(usize) -> f32) -> f64 {
    let mut s = 0.0f32;
    for k in 0..n {
        s += f(k);
    }
    let t = Instant::now();
    for k in 0..n {
        s += f(k);
    }
    black_box(s);
    t.elapsed().as_secs_f64() / n as f64
}

/// Cosine-distributed view directions and, per view, a reflected direction about a normal drawn
/// from the patch (so that BRDF evaluations hit the lobe, as a renderer's light samples do).
fn eval_pairs(patch: &(dyn Ndf + Sync), n: usize) -> Vec<(Vec3, Vec3)> {
    (0..n)
        .map(|k| {
            let u = r2(k + 1000);
            let r = u.x.sqrt();
            let p = std::f32::consts::TAU * u.y;
            let wo = Vec3::new(r * p.cos(), r * p.sin(), (1.0 - u.x).max(1e-4).sqrt());
            let m = patch.sample_normal(r2(k + 5000));
            let wi = 2.0 * wo.dot(m) * m - wo;
            (wo, wi)
        })
        .collect()
}

/// Runs the comparison; `progress` receives one line per step.
/// The Dirac and the convolved truth of one footprint on one binning.
pub struct Truths {
    pub bins: HemisphereBins,
    pub dirac: BinnedPndf,
    pub convolved: BinnedPndf,
}

impl Truths {
    /// Both truths from the same positions (`samples`, `seed`); σ_ε = [`SIGMA_EPS`].
    fn new(map: &NormalMap, fp: &Footprint, n_bins: usize, samples: usize, seed: u64) -> Res<Self> {
        let bins = HemisphereBins::new(n_bins)?;
        let dirac = binned_pndf(map, fp, Kernel::Gaussian, &bins, samples, seed);
        let convolved = convolved_pndf(map, fp, Kernel::Gaussian, &bins, samples, seed, SIGMA_EPS)?;
        Ok(Truths {
            bins,
            dirac,
            convolved,
        })
    }

    /// The model's TV to both truths, its bin masses from the adaptive quadrature.
    fn compare(&self, model: &(dyn Ndf + Sync), settings: &Settings) -> TwoTruths {
        let q = adaptive_bin_masses(
            model,
            &self.bins,
            settings.quadrature_tolerance,
            settings.max_quadrature,
        );
        let tv = |r: &BinnedPndf| r.tv_to_masses(&q.masses).unwrap_or(f64::NAN);
        TwoTruths {
            dirac: tv(&self.dirac),
            convolved: tv(&self.convolved),
            noise_dirac: self.dirac.tv_error(),
            noise_convolved: self.convolved.tv_error(),
            k: q.k_max,
            change: q.change,
        }
    }
}

/// Mean of the TVs and noises over footprint centres; the finest grid and the largest change.
fn mean_truths(v: &[TwoTruths]) -> TwoTruths {
    let k = v.len().max(1) as f64;
    let sum = |f: fn(&TwoTruths) -> f64| v.iter().map(f).sum::<f64>() / k;
    TwoTruths {
        dirac: sum(|t| t.dirac),
        convolved: sum(|t| t.convolved),
        noise_dirac: sum(|t| t.noise_dirac),
        noise_convolved: sum(|t| t.noise_convolved),
        k: v.iter().map(|t| t.k).max().unwrap_or(0),
        change: v.iter().map(|t| t.change).fold(0.0, f64::max),
    }
}

/// Ground truths of one footprint: 64² bins, and 128² bins (4× the positions, for the same noise
/// per bin) when the footprint is small enough.
struct Reference {
    fp: Footprint,
    coarse: Truths,
    fine: Option<Truths>,
}

pub fn measure(settings: &Settings, progress: &mut dyn FnMut(&str)) -> Res<Results> {
    let bins = HemisphereBins::new(64)?;
    let mut results = Results::default();
    let n = settings.size;
    for (map_name, map) in maps(n)? {
        // Ground truths per footprint size and centre (shared by every method).
        let mut references = Vec::new();
        for &area in &settings.areas {
            let mut per_centre = Vec::new();
            for (k, c) in CENTERS
                .iter()
                .take(settings.centers.clamp(1, CENTERS.len()))
                .enumerate()
            {
                let fp = Footprint::isotropic_texels(Vec2::new(c[0], c[1]), area, n, n);
                let samples = settings.reference_samples;
                let seed = 17 + k as u64;
                let coarse = Truths::new(&map, &fp, 64, samples, seed)?;
                let fine = if area <= settings.fine_up_to {
                    Some(Truths::new(&map, &fp, 128, 4 * samples, seed)?)
                } else {
                    None
                };
                per_centre.push(Reference { fp, coarse, fine });
            }
            references.push((area, per_centre));
        }
        progress(&format!("{map_name}: ground truth done"));
        let view_fp = Footprint::isotropic_texels(
            Vec2::new(CENTERS[0][0], CENTERS[0][1]),
            settings.view_area,
            n,
            n,
        );
        let view_ref = binned_pndf(
            &map,
            &view_fp,
            Kernel::Gaussian,
            &bins,
            settings.reference_samples,
            99,
        );
        for (family, build) in builders() {
            let t = Instant::now();
            let methods = build(&map, settings)?;
            let build_s = t.elapsed().as_secs_f64();
            for method in &methods {
                let label = method.label();
                results.build.push(BuildRow {
                    map: map_name,
                    family,
                    build_s,
                    method: label.clone(),
                    bytes_per_texel: method.bytes_per_texel(),
                });
                for (area, per_centre) in &references {
                    let (mut coarse, mut fine) = (Vec::new(), Vec::new());
                    for r in per_centre {
                        method.with_patch(&r.fp, &mut |p| {
                            coarse.push(r.coarse.compare(p, settings));
                            if let Some(t) = &r.fine {
                                fine.push(t.compare(p, settings));
                            }
                        });
                    }
                    let fp = &per_centre[0].fp;
                    // Costs: patch construction at jittered centres, d and BRDF eval on one patch.
                    let patches = 32;
                    let patch_s = time_per_call(patches, |k| {
                        let c = Vec2::new(CENTERS[0][0], CENTERS[0][1]) + 0.01 * r2(k);
                        let f = Footprint::isotropic_texels(c, *area, n, n);
                        let mut v = 0.0;
                        method.with_patch(&f, &mut |p| v = p.d(Vec3::Z));
                        v
                    });
                    let (mut d_s, mut eval_s) = (0.0, 0.0);
                    let calls = 128;
                    method.with_patch(fp, &mut |p| {
                        let ms: Vec<Vec3> = (0..calls).map(|k| p.sample_normal(r2(k))).collect();
                        d_s = time_per_call(calls, |k| p.d(black_box(ms[k])));
                    });
                    method.with_brdf(fp, &mut |b| {
                        method.with_patch(fp, &mut |p| {
                            let pairs = eval_pairs(p, calls);
                            eval_s = time_per_call(calls, |k| {
                                let (wo, wi) = pairs[k];
                                b.eval(black_box(wo), black_box(wi)).x
                            });
                        })
                    });
                    results.accuracy.push(AccuracyRow {
                        map: map_name,
                        method: label.clone(),
                        area: *area,
                        tv: mean_truths(&coarse),
                        tv_fine: (!fine.is_empty()).then(|| mean_truths(&fine)),
                        patch_s,
                        d_s,
                        eval_s,
                    });
                }
                for &theta in &settings.thetas {
                    let wo = view(theta);
                    let v_ref = reference_visible_area(&view_ref, wo);
                    let mut row = ViewRow {
                        map: map_name,
                        method: label.clone(),
                        theta,
                        v_rel_error: 0.0,
                        furnace: 0.0,
                    };
                    method.with_patch(&view_fp, &mut |p| {
                        let v = p.visible_area(wo) as f64;
                        row.v_rel_error = (v - v_ref).abs() / v_ref.max(1e-12);
                    });
                    method.with_brdf(&view_fp, &mut |b| {
                        row.furnace = furnace(b, wo, settings.furnace_samples);
                    });
                    results.view.push(row);
                }
                progress(&format!("{map_name}: {label} done"));
            }
        }
    }
    Ok(results)
}

/// Method labels in first-seen order.
fn labels<'a>(rows: impl Iterator<Item = &'a String>) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for l in rows {
        if !out.contains(l) {
            out.push(l.clone());
        }
    }
    out
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// Geometric mean (for times spanning decades).
fn geo_mean(v: impl Iterator<Item = f64>) -> f64 {
    mean(v.map(|x| x.max(1e-15).ln())).exp()
}

/// The non-dominated points (lower time and lower error), sorted by time.
pub fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut p: Vec<(f64, f64)> = points.to_vec();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for q in p {
        if q.1 < best {
            best = q.1;
            front.push(q);
        }
    }
    front
}

/// Writes the CSV files and charts into `out`; returns the artifacts and the markdown tables.
pub fn report(results: &Results, settings: &Settings, out: &Path) -> Res<(Vec<Artifact>, String)> {
    std::fs::create_dir_all(out)?;
    let mut csv = String::from(
        "map,method,footprint_texels,tv_dirac,tv_convolved,noise_dirac,noise_convolved,quad_k,\
         quad_change,tv_dirac_128,tv_convolved_128,noise_dirac_128,noise_convolved_128,quad_k_128,\
         quad_change_128,patch_s,d_s,eval_s\n",
    );
    let cols = |t: &TwoTruths| {
        format!(
            "{:.5},{:.5},{:.5},{:.5},{},{:.2e}",
            t.dirac, t.convolved, t.noise_dirac, t.noise_convolved, t.k, t.change
        )
    };
    for r in &results.accuracy {
        writeln!(
            csv,
            "{},{},{},{},{},{:.3e},{:.3e},{:.3e}",
            r.map,
            r.method,
            r.area,
            cols(&r.tv),
            r.tv_fine.as_ref().map_or(",,,,,".to_string(), cols),
            r.patch_s,
            r.d_s,
            r.eval_s
        )?;
    }
    std::fs::write(out.join("compare_accuracy.csv"), csv)?;
    let mut csv = String::from("map,method,theta_deg,v_rel_error,furnace\n");
    for r in &results.view {
        writeln!(
            csv,
            "{},{},{},{:.5},{:.5}",
            r.map, r.method, r.theta, r.v_rel_error, r.furnace
        )?;
    }
    std::fs::write(out.join("compare_view.csv"), csv)?;
    let mut csv = String::from("map,family,method,build_s,bytes_per_texel\n");
    for r in &results.build {
        writeln!(
            csv,
            "{},{},{},{:.3},{:.2}",
            r.map, r.family, r.method, r.build_s, r.bytes_per_texel
        )?;
    }
    std::fs::write(out.join("compare_build.csv"), csv)?;

    let methods = labels(results.accuracy.iter().map(|r| &r.method));
    let mut artifacts = Vec::new();
    let mut md = String::new();
    let size = settings.size;

    // Accuracy against time, per truth: one point per method (mean TV over maps and footprints of
    // ≥ 1 texel, geometric-mean BRDF eval time), and the Pareto front.
    // (method, eval µs, mean TV Dirac, mean TV convolved)
    let per_method: Vec<(String, f64, f64, f64)> = methods
        .iter()
        .map(|m| {
            let rows = || {
                results
                    .accuracy
                    .iter()
                    .filter(move |r| &r.method == m && r.area >= 1.0)
            };
            (
                m.clone(),
                geo_mean(rows().map(|r| r.eval_s * 1e6)),
                mean(rows().map(|r| r.tv.dirac)),
                mean(rows().map(|r| r.tv.convolved)),
            )
        })
        .collect();
    for (file, truth, pick) in [
        (
            "compare_accuracy_vs_time.png",
            TRUTHS[0],
            (|t: &(String, f64, f64, f64)| t.2) as fn(&(String, f64, f64, f64)) -> f64,
        ),
        ("compare_accuracy_vs_time_convolved.png", TRUTHS[1], |t| t.3),
    ] {
        let front = pareto(
            &per_method
                .iter()
                .map(|t| (t.1, pick(t)))
                .collect::<Vec<_>>(),
        );
        // The front first (underneath), then one marker per method on top.
        let mut series = vec![Series::new("Pareto front", front)];
        series.extend(
            per_method
                .iter()
                .map(|t| Series::new(t.0.clone(), vec![(t.1, pick(t))])),
        );
        let path = out.join(file);
        let title = format!("Accuracy against cost, {truth} ({size}² maps)");
        let mut chart = Chart::new(
            &title,
            "BRDF eval time (µs, geometric mean)",
            "mean TV (64² bins)",
        );
        chart.x_scale = Scale::Log;
        chart.markers = true;
        line_chart(&path, &chart, &series)?;
        artifacts.push(Artifact::new(
            path,
            format!(
                "Accuracy against cost: mean total variation to the {truth} (64² bins) over the \
                 four maps and footprints of 1 texel and more, against the geometric-mean time of \
                 one BRDF evaluation; the line joins the methods no other beats on both."
            ),
        ));
    }

    // Per method, one point per footprint size: `stat` of `value` over the maps (and centres).
    let by_area = |value: &dyn Fn(&AccuracyRow) -> f64,
                   stat: &dyn Fn(&mut dyn Iterator<Item = f64>) -> f64|
     -> Vec<Series> {
        methods
            .iter()
            .map(|m| {
                let pts = settings
                    .areas
                    .iter()
                    .map(|&a| {
                        let mut rows = results
                            .accuracy
                            .iter()
                            .filter(|r| &r.method == m && r.area == a)
                            .map(value);
                        (a as f64, stat(&mut rows))
                    })
                    .collect();
                Series::new(m.clone(), pts)
            })
            .collect()
    };

    // Error against footprint size, per truth.
    for (file, truth, value) in [
        (
            "compare_error_vs_footprint.png",
            TRUTHS[0],
            (|r: &AccuracyRow| r.tv.dirac) as fn(&AccuracyRow) -> f64,
        ),
        ("compare_error_vs_footprint_convolved.png", TRUTHS[1], |r| {
            r.tv.convolved
        }),
    ] {
        let series = by_area(&value, &|v| mean(v));
        let path = out.join(file);
        let title = format!("P-NDF error against footprint size, {truth}");
        let mut chart = Chart::new(&title, "footprint (texels)", "mean TV (64² bins)");
        chart.x_scale = Scale::Log;
        chart.markers = true;
        line_chart(&path, &chart, &series)?;
        artifacts.push(Artifact::new(
            path,
            format!(
                "Total variation to the {truth} (64² bins) against footprint size, mean over the \
                 four maps and the footprint centres (noise floors, 128² bins and the quadrature used are \
                 in compare_accuracy.csv)."
            ),
        ));
    }

    // Cost against footprint size: the per-direction `d` and the per-shading-point `patch()`.
    for (name, value, what, caption) in [
        (
            "compare_d_time_vs_footprint.png",
            &(|r: &AccuracyRow| r.d_s * 1e6) as &dyn Fn(&AccuracyRow) -> f64,
            "D evaluation time against footprint size",
            "Time of one D(h) evaluation (µs, geometric mean over maps and centres, one thread) \
             against footprint size: flat for the bin map (Atanasov 2020's claim), linear in the \
             footprint's lobes or elements for the mixture and the position-normal baseline.",
        ),
        (
            "compare_patch_time_vs_footprint.png",
            &(|r: &AccuracyRow| r.patch_s * 1e6) as &dyn Fn(&AccuracyRow) -> f64,
            "patch() time against footprint size",
            "Time of one patch() (per shading point; µs, geometric mean, one thread) against \
             footprint size.",
        ),
    ] {
        let path = out.join(name);
        let mut chart = Chart::new(what, "footprint (texels)", "µs (log scale)");
        chart.x_scale = Scale::Log;
        chart.y_scale = Scale::Log;
        chart.markers = true;
        line_chart(&path, &chart, &by_area(value, &|v| geo_mean(v)))?;
        artifacts.push(Artifact::new(path, caption));
    }

    // Error and energy against view angle.
    let view_methods = labels(results.view.iter().map(|r| &r.method));
    let by_theta = |f: &dyn Fn(&ViewRow) -> f64| -> Vec<Series> {
        view_methods
            .iter()
            .map(|m| {
                let pts = settings
                    .thetas
                    .iter()
                    .map(|&t| {
                        let v = mean(
                            results
                                .view
                                .iter()
                                .filter(|r| &r.method == m && r.theta == t)
                                .map(f),
                        );
                        (t, v)
                    })
                    .collect();
                Series::new(m.clone(), pts)
            })
            .collect()
    };
    let title = format!(
        "Visible-area error against view angle ({} texels)",
        settings.view_area
    );
    let path = out.join("compare_error_vs_view.png");
    let mut chart = Chart::new(&title, "θo (degrees)", "relative error of V(wo)");
    chart.y_scale = Scale::Log;
    chart.markers = true;
    line_chart(&path, &chart, &by_theta(&|r| r.v_rel_error))?;
    artifacts.push(Artifact::new(
        path,
        "Relative error of the visible projected area ∫⟨wo,m⟩⁺D dm against the ground truth's, mean \
         over the maps: where normalisation and masking fail near grazing.",
    ));
    let title = format!(
        "White furnace, renderer's measure ({} texels)",
        settings.view_area
    );
    let path = out.join("compare_energy_vs_view.png");
    let mut chart = Chart::new(&title, "θo (degrees)", "∫ f cos θi dωi");
    chart.markers = true;
    line_chart(&path, &chart, &by_theta(&|r| r.furnace))?;
    artifacts.push(Artifact::new(
        path,
        "White furnace (F = 1) as a renderer integrates it, ∫ eval · cos θi dωi with the geometric \
         cosine (mean of sample().weight()), mean over the maps: ≤ 1 for an energy-conserving model.",
    ));

    // Markdown tables.
    writeln!(
        md,
        "| method | mean TV, Dirac (≥ 1 texel) | mean TV, convolved | BRDF eval (µs, geo. mean) | \
         bytes/texel | build (s, mean over maps) |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    for (m, t, e, c) in &per_method {
        let b = || results.build.iter().filter(|r| &r.method == m);
        writeln!(
            md,
            "| {m} | {e:.3} | {c:.3} | {t:.2} | {:.1} | {:.1} |",
            mean(b().map(|r| r.bytes_per_texel)),
            mean(b().map(|r| r.build_s))
        )?;
    }
    writeln!(md)?;
    md.push_str(&tv_table(results, settings, &methods, false));
    writeln!(md)?;
    md.push_str(&tv_table(results, settings, &methods, true));
    writeln!(md)?;
    write!(md, "| method |")?;
    for a in &settings.areas {
        write!(md, " d {a} (µs) |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|{}", "---|".repeat(settings.areas.len()))?;
    for m in &methods {
        write!(md, "| {m} |")?;
        for &a in &settings.areas {
            let rows = results
                .accuracy
                .iter()
                .filter(|r| &r.method == m && r.area == a);
            write!(md, " {:.2} |", geo_mean(rows.map(|r| r.d_s * 1e6)))?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    write!(md, "| method | quantity |")?;
    for t in &settings.thetas {
        write!(md, " {t}° |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|---|{}", "---|".repeat(settings.thetas.len()))?;
    for m in &view_methods {
        for (q, f) in [
            (
                "V rel. error",
                &(|r: &ViewRow| r.v_rel_error) as &dyn Fn(&ViewRow) -> f64,
            ),
            ("furnace", &|r: &ViewRow| r.furnace),
        ] {
            write!(md, "| {m} | {q} |")?;
            for &t in &settings.thetas {
                let v = mean(
                    results
                        .view
                        .iter()
                        .filter(|r| &r.method == m && r.theta == t)
                        .map(f),
                );
                write!(md, " {v:.3} |")?;
            }
            writeln!(md)?;
        }
    }
    std::fs::write(out.join("compare_tables.md"), &md)?;
    Ok((artifacts, md))
}

/// Names of the two truths, for titles and captions.
const TRUTHS: [&str; 2] = [
    "Dirac truth (interpolated map)",
    "convolved truth (σ_ε = 0.01)",
];

/// Markdown table of the TV to both truths per footprint size (means over maps and centres), on 64²
/// bins or (`fine`) on 128² bins for the footprints that have them; the last columns give the finest
/// quadrature grid any bin needed (k of k × k, over maps, centres and sizes) and the largest final
/// change of the masses.
fn tv_table(results: &Results, settings: &Settings, methods: &[String], fine: bool) -> String {
    let pick = |r: &AccuracyRow| if fine { r.tv_fine } else { Some(r.tv) };
    let areas: Vec<f32> = settings
        .areas
        .iter()
        .copied()
        .filter(|&a| !fine || a <= settings.fine_up_to)
        .collect();
    let mut md = String::new();
    let bins = if fine { "128²" } else { "64²" };
    md.push_str(&format!("| method ({bins} bins) |"));
    for a in &areas {
        md.push_str(&format!(" {a}: Dirac | {a}: conv. |"));
    }
    md.push_str(" quadrature k | change |\n");
    md.push_str(&format!(
        "|---|{}---|---|\n",
        "---|---|".repeat(areas.len())
    ));
    let (mut noise_d, mut noise_c) = (Vec::new(), Vec::new());
    for m in methods {
        md.push_str(&format!("| {m} |"));
        let all: Vec<TwoTruths> = results
            .accuracy
            .iter()
            .filter(|r| &r.method == m)
            .filter_map(pick)
            .collect();
        for &a in &areas {
            let rows: Vec<TwoTruths> = results
                .accuracy
                .iter()
                .filter(|r| &r.method == m && r.area == a)
                .filter_map(pick)
                .collect();
            md.push_str(&format!(
                " {:.3} | {:.3} |",
                mean(rows.iter().map(|t| t.dirac)),
                mean(rows.iter().map(|t| t.convolved))
            ));
            if m == &methods[0] {
                noise_d.push(mean(rows.iter().map(|t| t.noise_dirac)));
                noise_c.push(mean(rows.iter().map(|t| t.noise_convolved)));
            }
        }
        let k = all.iter().map(|t| t.k).max().unwrap_or(0);
        let change = all.iter().map(|t| t.change).fold(0.0, f64::max);
        md.push_str(&format!(" {k} × {k} | {change:.1e} |\n"));
    }
    md.push_str("| *reference noise* |");
    for (d, c) in noise_d.iter().zip(&noise_c) {
        md.push_str(&format!(" {d:.3} | {c:.3} |"));
    }
    md.push_str(" | |\n");
    md
}

/// The example's entry point: measure, write, return the artifacts.
pub fn run(out: &Path, quick: bool) -> Res<Vec<Artifact>> {
    let settings = Settings::new(quick);
    let t = Instant::now();
    let results = measure(&settings, &mut |s| {
        eprintln!("[{:6.1} s] {s}", t.elapsed().as_secs_f64())
    })?;
    let (artifacts, md) = report(&results, &settings, out)?;
    println!("{md}");
    Ok(artifacts)
}
