//! Running the methods: for each map, the ground truths per footprint size and centre, then per
//! method its build, its TV to both truths and its costs per footprint size, and per view angle the
//! error of its visible projected area and its white furnace.

use super::methods::{Method, builders};
use super::truth::{Truths, TwoTruths, mean_truths, reference_visible_area};
use crate::common::pndf_images::maps;
use crate::common::{Res, r2, view};
use brdf::bxdf::Bxdf;
use brdf::glint::{
    BinnedPndf, DEFAULT_MAX_QUADRATURE, DEFAULT_QUADRATURE_TOLERANCE, Footprint, HemisphereBins,
    Kernel, NormalMap, binned_pndf,
};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use std::hint::black_box;
use std::time::Instant;

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
    /// Footprints up to this many texels are also compared on 127² bins.
    pub fine_up_to: f32,
    /// Footprint centres averaged over (1 to 3, from [`CENTERS`]).
    pub centers: usize,
}

impl Settings {
    /// `--quick`: 1024² maps, footprints up to 256 texels, one footprint centre, 127² bins up to 1
    /// texel (the adaptive quadrature needs ≥ 20 evaluations per bin where a fixed 2 × 2 rule took 4,
    /// and one `d` costs 0.3-1.3 ms at 4096 texels: that size alone took ~5 minutes per map);
    /// otherwise 2048² maps, footprints up to 65536 texels (beyond the default level of detail), 4×
    /// the reference samples, three centres and 127² bins up to 16 texels. The quick run also stops
    /// the per-bin quadrature at 16 × 16 points and a TV change of 5·10⁻³ (the full run: 64 × 64 and
    /// 10⁻³), which keeps the gallery's run to minutes; its TV figures are then good to ~0.005, and
    /// spiky models that have not converged at 16 × 16 say so in the `quad_change` column.
    pub fn new(quick: bool) -> Settings {
        Settings {
            size: if quick { 1024 } else { 2048 },
            reference_samples: if quick { 1_000_000 } else { 4_000_000 },
            areas: if quick {
                vec![0.25, 1.0, 4.0, 16.0, 256.0]
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

    /// The gallery's preview: [`Settings::new`]`(true)` on 256² maps with a quarter of the
    /// ground-truth positions (noise floors of the TV about twice as high), footprints of 0.25, 1, 16
    /// and 256 texels on 63² bins only, the per-bin quadrature stopped at 8 × 8 points and a TV
    /// change of 10⁻² (TV figures good to ~0.01) and 256 furnace samples: the same methods, maps and
    /// view angles in about a quarter of the time (the gallery's compare part: 81 → 18 s at load 3-4).
    pub fn preview() -> Settings {
        Settings {
            size: 256,
            reference_samples: 250_000,
            areas: vec![0.25, 1.0, 16.0, 256.0],
            furnace_samples: 256,
            max_quadrature: 8,
            quadrature_tolerance: 1e-2,
            fine_up_to: 0.0,
            ..Settings::new(true)
        }
    }

    /// Tiny settings for the test of the code paths.
    pub fn tiny() -> Settings {
        Settings {
            // 32² maps: most of the test's time is position-normal's build (its filtered mixture's
            // measured errors), which grows with the map.
            size: 32,
            reference_samples: 20_000,
            areas: vec![1.0, 16.0],
            thetas: vec![0.0, 85.0],
            view_area: 16.0,
            furnace_samples: 64,
            // The quick run's quadrature stop (16 × 16 points, a TV change of 5·10⁻³): the test
            // checks the code paths, not the figures' last digit.
            max_quadrature: 16,
            quadrature_tolerance: 5e-3,
            fine_up_to: 1.0,
            centers: 1,
        }
    }
}

/// Bins per axis of the coarse binning of the truths (63² bins of ~0.045 in slope near the pole).
/// Odd, so that the pole is the centre of a bin: with an even count it is the corner of four bins,
/// and the Dirac truth would put every flat texel into one of them while any model with σ > 0
/// splits that mass four ways.
pub const COARSE_BINS: usize = 63;

/// Bins per axis of the fine binning (odd for the same reason).
pub const FINE_BINS: usize = 127;

/// Footprint centres (uv); TV is averaged over them.
const CENTERS: [[f32; 2]; 3] = [[0.43, 0.57], [0.71, 0.23], [0.17, 0.81]];

/// One row of the accuracy table.
#[derive(Clone, Debug)]
pub struct AccuracyRow {
    pub map: &'static str,
    pub method: String,
    pub area: f32,
    /// On 63² bins.
    pub tv: TwoTruths,
    /// On 127² bins (footprints up to [`Settings::fine_up_to`] texels).
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
    /// The furnace's standard error.
    pub furnace_se: f64,
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

/// The renderer's furnace ∫ f cos θi dωi: the mean of `sample().weight()` with the BRDF's own
/// sampler, and its standard error as if the points were independent (an upper estimate of the
/// R2 points' error).
fn furnace(brdf: &(dyn Bxdf + Sync), wo: Vec3, n: usize) -> (f64, f64) {
    let (mut sum, mut sum2) = (0.0, 0.0);
    for k in 0..n {
        let u = r2(k);
        let uc = ((k as f64 + 0.5) / n as f64) as f32;
        if let Some(s) = brdf.sample(wo, uc, u) {
            let w = s.weight().x as f64;
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    let var = (sum2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
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

/// Ground truths of one footprint: 63² bins, and 127² bins (4× the positions, for the same noise
/// per bin) when the footprint is small enough.
struct Reference {
    fp: Footprint,
    coarse: Truths,
    fine: Option<Truths>,
}

/// Runs the comparison; `progress` receives one line per step.
pub fn measure(settings: &Settings, progress: &mut dyn FnMut(&str)) -> Res<Results> {
    let bins = HemisphereBins::new(COARSE_BINS)?;
    let mut results = Results::default();
    let n = settings.size;
    for (map_name, map) in maps(n)? {
        // Ground truths per footprint size and centre (shared by every method).
        let references = references(&map, settings)?;
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
                    let (tv, tv_fine) = accuracy(method.as_ref(), per_centre, settings);
                    let (patch_s, d_s, eval_s) =
                        costs(method.as_ref(), *area, &per_centre[0].fp, n);
                    results.accuracy.push(AccuracyRow {
                        map: map_name,
                        method: label.clone(),
                        area: *area,
                        tv,
                        tv_fine,
                        patch_s,
                        d_s,
                        eval_s,
                    });
                }
                for &theta in &settings.thetas {
                    let (v_rel_error, (furnace, furnace_se)) =
                        at_view(method.as_ref(), &view_fp, &view_ref, theta, settings);
                    results.view.push(ViewRow {
                        map: map_name,
                        method: label.clone(),
                        theta,
                        v_rel_error,
                        furnace,
                        furnace_se,
                    });
                }
                progress(&format!("{map_name}: {label} done"));
            }
        }
    }
    Ok(results)
}

/// The ground truths of every footprint size, at each footprint centre (seeds 17, 18, …).
fn references(map: &NormalMap, settings: &Settings) -> Res<Vec<(f32, Vec<Reference>)>> {
    let n = settings.size;
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
            let coarse = Truths::new(map, &fp, COARSE_BINS, samples, seed)?;
            let fine = if area <= settings.fine_up_to {
                Some(Truths::new(map, &fp, FINE_BINS, 4 * samples, seed)?)
            } else {
                None
            };
            per_centre.push(Reference { fp, coarse, fine });
        }
        references.push((area, per_centre));
    }
    Ok(references)
}

/// A method's TV to both truths at one footprint size, mean over the centres: on 63² bins, and on
/// 127² bins where the footprint has them.
fn accuracy(
    method: &dyn Method,
    per_centre: &[Reference],
    settings: &Settings,
) -> (TwoTruths, Option<TwoTruths>) {
    let (mut coarse, mut fine) = (Vec::new(), Vec::new());
    for r in per_centre {
        method.with_patch(&r.fp, &mut |p| {
            coarse.push(r.coarse.compare(p, settings));
            if let Some(t) = &r.fine {
                fine.push(t.compare(p, settings));
            }
        });
    }
    (
        mean_truths(&coarse),
        (!fine.is_empty()).then(|| mean_truths(&fine)),
    )
}

/// A method's costs at one footprint size, single thread, in seconds per call: patch construction
/// at jittered centres, and `d` and the BRDF's eval on the patch of `fp`.
fn costs(method: &dyn Method, area: f32, fp: &Footprint, n: usize) -> (f64, f64, f64) {
    let patches = 32;
    let patch_s = time_per_call(patches, |k| {
        let c = Vec2::new(CENTERS[0][0], CENTERS[0][1]) + 0.01 * r2(k);
        let f = Footprint::isotropic_texels(c, area, n, n);
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
    (patch_s, d_s, eval_s)
}

/// At view angle `theta` on the view-sweep footprint: the relative error of the method's visible
/// projected area against the ground truth's, and its white furnace.
fn at_view(
    method: &dyn Method,
    view_fp: &Footprint,
    view_ref: &BinnedPndf,
    theta: f64,
    settings: &Settings,
) -> (f64, (f64, f64)) {
    let wo = view(theta);
    let v_ref = reference_visible_area(view_ref, wo);
    let (mut v_rel_error, mut furnace_value) = (0.0, (0.0, 0.0));
    method.with_patch(view_fp, &mut |p| {
        let v = p.visible_area(wo) as f64;
        v_rel_error = (v - v_ref).abs() / v_ref.max(1e-12);
    });
    method.with_brdf(view_fp, &mut |b| {
        furnace_value = furnace(b, wo, settings.furnace_samples);
    });
    (v_rel_error, furnace_value)
}
