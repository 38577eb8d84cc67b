//! A metallic orb with a high-definition normal map under a point light, rendered with each glint
//! model and the two references, the exact P-BRDF of the map and normal-mapped rendering
//! (\[Chermain2019\] Fig. 1 and 11); see docs/orb.md.
//!
//! `cargo run --release --example orb -- [--map scratched|brushed|bumpy|flakes|fractal|PATH] [--spp N]
//! [--size PIXELS] [--map-size TEXELS] [--tiles UxV] [--naive-spp N] [--sigma S]
//! [--out DIR] [--quiet]`, or `-- --quick [--out DIR]` for the gallery's
//! small strip (scratched 512² map, 160² pixels, 256 spp); `-- --curves [--quick] [--out DIR]` for
//! the error-against-time curves and equal-error speedups (examples/common/orb_curves/); `-- --bias
//! [--out DIR]` for the decomposition of the glint models' bias floor (examples/common/orb/bias.rs).
//!
//! Writes one PNG per method, a labelled strip and a CSV of times and errors into DIR (default
//! `target/brdf-out/`), and prints the table.

use brdf_examples::common;

use common::orb::{MapSource, OrbOptions};
use common::{Res, arg_value, has_flag};

fn parsed<T: std::str::FromStr>(name: &str, default: T) -> Res<T> {
    match arg_value(name) {
        Some(v) => v
            .parse()
            .map_err(|_| format!("{name}: cannot parse {v:?}").into()),
        None => Ok(default),
    }
}

fn options() -> Res<OrbOptions> {
    let d = OrbOptions::default();
    let tiles = match arg_value("--tiles") {
        Some(t) => {
            let (u, v) = t.split_once('x').ok_or("--tiles: expected UxV, e.g. 4x2")?;
            glam::Vec2::new(u.parse()?, v.parse()?)
        }
        None => d.tiles,
    };
    Ok(OrbOptions {
        size: parsed("--size", d.size)?,
        map: arg_value("--map").map_or(d.map.clone(), |m| MapSource::parse(&m)),
        map_size: parsed("--map-size", d.map_size)?,
        tiles,
        spp: parsed("--spp", d.spp)?,
        naive_spp: parsed("--naive-spp", d.naive_spp)?,
        sigma_eps: parsed("--sigma", d.sigma_eps)?,
        seed: parsed("--seed", d.seed)?,
        mixture_samples: parsed("--mixture-samples", d.mixture_samples)?,
        progress: !has_flag("--quiet"),
    })
}

fn main() -> Res<()> {
    let out = common::out_dir()?;
    if let (true, Some(csv)) = (has_flag("--bias"), arg_value("--chart")) {
        common::orb::bias::chart_from_csv(std::path::Path::new(&csv))?;
    } else if has_flag("--bias") && has_flag("--spacing") {
        let scales = match arg_value("--scales") {
            Some(list) => list
                .split(',')
                .map(|k| k.parse::<f32>())
                .collect::<Result<Vec<_>, _>>()?,
            None => vec![common::orb::bias::SCALES[0]],
        };
        common::orb::bias::run_spacing(&out, &scales)?;
    } else if has_flag("--bias") {
        common::orb::bias::run(&out)?;
    } else if has_flag("--curves") {
        common::orb_curves::run(&out, has_flag("--quick"))?;
    } else if has_flag("--quick") {
        common::orb::run_gallery(&out, true)?;
    } else {
        common::orb::run(&options()?, &out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    //! Tiny renders (32² pixels, 64² maps) through every code path, checked against physics computed
    //! here independently of the renderer.

    use super::common::orb::render::{MixtureVariant, render_glint};
    use super::common::orb::*;
    use brdf::fresnel::{ConductorFresnel, Fresnel};
    use brdf::glint::mixture::{MaskingMode, MixtureParams, PatchOptions};
    use brdf::glint::{BeckmannMixture, NormalMap};
    use glam::{Vec2, Vec3};
    use indicatif::ProgressBar;

    const SIZE: u32 = 32;

    fn variants(m: &BeckmannMixture) -> [MixtureVariant<'_>; 3] {
        let v = |masking, lod_lobes| MixtureVariant {
            model: m,
            // Tolerance 0: the full mixture (or the filtered lobe), not a level of detail.
            options: PatchOptions {
                masking,
                lod_lobes,
                lod_tolerance: 0.0,
                ..PatchOptions::default()
            },
        };
        [
            v(MaskingMode::Exact, f32::INFINITY),
            v(MaskingMode::Approximate, f32::INFINITY),
            v(MaskingMode::Approximate, 0.0),
        ]
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn unit(a: [f64; 3]) -> [f64; 3] {
        let l = dot(a, a).sqrt();
        [a[0] / l, a[1] / l, a[2] / l]
    }

    /// Beckmann D(h) with α = √2 σ about the geometric normal n (closed form, [Walter2007] eq. 25).
    fn beckmann_d(alpha: f64, cos_h: f64) -> f64 {
        let c2 = cos_h * cos_h;
        let tan2 = (1.0 - c2) / c2;
        (-tan2 / (alpha * alpha)).exp() / (std::f64::consts::PI * alpha * alpha * c2 * c2)
    }

    /// Smith G1 of Beckmann (closed form with erf, [Walter2007] eq. 27 exact form).
    fn beckmann_g1(alpha: f64, cos_w: f64) -> f64 {
        let tan = (1.0 - cos_w * cos_w).sqrt() / cos_w;
        if tan == 0.0 {
            return 1.0;
        }
        let a = 1.0 / (alpha * tan);
        let lambda =
            0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt());
        1.0 / (1.0 + lambda)
    }

    /// Smith G1 from Scarf's visible-area bound of a centred slope distribution of variance σ² per
    /// axis: A / V⁺ with A = cos θ, V⁺ = ½ (cos θ + √(cos²θ + σ² sin²θ)) (the mixture's approximate
    /// masking, docs/mixture.md).
    fn scarf_g1(sigma: f64, cos_w: f64) -> f64 {
        let sin2 = 1.0 - cos_w * cos_w;
        cos_w / (0.5 * (cos_w + (cos_w * cos_w + sigma * sigma * sin2).sqrt()))
    }

    /// A flat map gives the smooth Beckmann sphere: at every pixel centre, the mixture (exact
    /// masking, and the filtered lobe) equals F · D · G1 G1 / (4 cos θo) · I / r² computed here from
    /// the camera ray, the sphere hit and the closed forms (σ = 0.2 so that the highlight spans many
    /// pixels of a 32² image); with approximate masking, the same with Scarf's G1.
    #[test]
    fn flat_map_is_the_smooth_beckmann_sphere() {
        let sigma = 0.2f32;
        let map = NormalMap::from_slopes(64, 64, vec![Vec2::ZERO; 64 * 64]).unwrap();
        let params = MixtureParams {
            sigma_min: sigma,
            samples: 16,
            ..MixtureParams::default()
        };
        let mixture = BeckmannMixture::build(&map, params).unwrap();
        let scene = Scene::new(SIZE, Vec2::new(4.0, 2.0));
        let alpha = std::f64::consts::SQRT_2 * sigma as f64;
        let fresnel = ConductorFresnel::ALUMINIUM;
        for model in variants(&mixture) {
            let img = render_glint(&scene, &model, &ProgressBar::hidden());
            let (mut checked, mut peak) = (0, 0.0f64);
            for y in 0..SIZE {
                for x in 0..SIZE {
                    // Independent geometry in f64: pinhole ray through the pixel centre,
                    // unit-sphere hit.
                    let s = 2.0 * 0.22 / SIZE as f64;
                    let d = unit([
                        (x as f64 + 0.5 - 16.0) * s,
                        (16.0 - y as f64 - 0.5) * s,
                        -1.0,
                    ]);
                    let o = [0.0, 0.0, 5.0];
                    let b = dot(o, d);
                    let disc = b * b - (dot(o, o) - 1.0);
                    let got = img.pixels[(y * SIZE + x) as usize];
                    if disc < 0.0 {
                        assert_eq!(got, Vec3::ZERO);
                        continue;
                    }
                    let t = -b - disc.sqrt();
                    let n = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
                    let to_l = [-2.0 - n[0], 2.5 - n[1], 7.0 - n[2]];
                    let (wo, wi) = ([-d[0], -d[1], -d[2]], unit(to_l));
                    let h = unit([wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]]);
                    let (co, ci) = (dot(wo, n), dot(wi, n));
                    if co <= 0.01 || ci <= 0.01 {
                        continue; // grazing: f32 geometry and f64 disagree beyond the bound below
                    }
                    let fr = fresnel.eval(dot(wo, h) as f32);
                    let scarf = model.options.masking == MaskingMode::Approximate
                        && model.options.lod_lobes.is_infinite();
                    let g1 = |c: f64| {
                        if scarf {
                            scarf_g1(sigma as f64, c)
                        } else {
                            beckmann_g1(alpha, c)
                        }
                    };
                    let scalar = beckmann_d(alpha, dot(h, n)) * g1(co) * g1(ci) / (4.0 * co) * 60.0
                        / dot(to_l, to_l);
                    let f = [
                        fr.x as f64 * scalar,
                        fr.y as f64 * scalar,
                        fr.z as f64 * scalar,
                    ];
                    for c in 0..3 {
                        // Relative 1e-3: f32 geometry (directions to ~1e-6; D's exponent
                        // tan²/α² ≤ ~15 where the box keeps it amplifies that to ~1e-5) and f32
                        // weights and erf. Absolute 1e-5: each lobe is cut outside its slope box
                        // (P22 = tail = 1e-6 of its peak there, over cos⁴θ ≥ 0.2 at the box's
                        // slope 1.05), i.e. ≤ 5e-6 of the peak D, and the peak radiance is < 2.
                        let (g, e) = (got[c] as f64, f[c]);
                        assert!(
                            (g - e).abs() <= 1e-3 * e + 1e-5,
                            "pixel ({x}, {y}) channel {c}: got {g}, expected {e} ({:?})",
                            model.options
                        );
                    }
                    checked += 1;
                    peak = peak.max(f[0]);
                }
            }
            assert!(checked > 500, "only {checked} pixels checked");
            assert!(
                peak > 0.5 && peak < 2.0,
                "the highlight is on the image, at the scale the tolerance assumes (peak {peak})"
            );
        }
    }

    /// Every code path (three mixture variants, the naive row, the reference) on every
    /// procedural map gives finite, non-negative pixels, and the figures are finite.
    #[test]
    fn every_path_is_finite_and_non_negative() {
        for map in ["scratched", "brushed", "bumpy", "flakes"] {
            let opts = OrbOptions {
                size: SIZE,
                map: MapSource::parse(map),
                map_size: 64,
                spp: 8,
                naive_spp: 4,
                mixture_samples: 16,
                progress: false,
                ..OrbOptions::default()
            };
            let m = load_map(&opts).unwrap();
            let (refs, _, methods) = render_all(&opts, &m).unwrap();
            let (a, b) = (&refs.pbrdf.0, &refs.pbrdf.1);
            // Seven glint renders (mixture exact, approximate, filtered lobe, bin map at σ_ε and
            // at σ = 0, position-normal at σ_ε and at σ_r = 0.005) and naive 16 spp.
            assert_eq!(methods.len(), 8);
            let mask = coverage(&Scene::new(SIZE, opts.tiles));
            let (c, d) = (&refs.normal_mapped.0, &refs.normal_mapped.1);
            for img in [a, b, c, d]
                .into_iter()
                .chain(methods.iter().map(|r| &r.image))
            {
                assert_eq!(img.pixels.len(), (SIZE * SIZE) as usize);
                for p in &img.pixels {
                    assert!(
                        p.is_finite() && p.min_element() >= 0.0,
                        "{map}: pixel {p:?}"
                    );
                }
                let e = errors(img, a, b, &mask);
                assert!(e.rel_rmse.is_finite() && e.energy.is_finite());
            }
            assert!(reference_noise(a, b, &mask).is_finite());
        }
    }

    /// Every glint method the orb and its curves build (through their own constructors) renders
    /// the scene's σ_ε, read back from the built model or from its patches; the only exceptions are
    /// the rows labelled "paper default", which carry exactly the paper's σ they declare. Each
    /// family (mixture, bin map, position-normal) has a row at σ_ε. The orb is built at σ_ε = 0.02,
    /// not the default, so that a model left at its own default fails.
    #[test]
    fn every_method_is_built_with_the_scenes_sigma() {
        use super::common::material::{SIGMA_EPS, same_sigma};
        use super::common::orb::render::build_methods;
        use super::common::orb_curves::build_models;
        let check = |methods: &[OrbMethod], sigma_eps: f32| {
            for family in ["mixture", "bin map", "position-normal"] {
                assert!(
                    methods
                        .iter()
                        .any(|m| m.label.starts_with(family) && m.paper_sigma.is_none()),
                    "{family}: no method at σ_ε"
                );
            }
            for m in methods {
                let sigma = m.glint.sigma();
                match m.paper_sigma {
                    None => assert!(same_sigma(sigma, sigma_eps), "{}: σ = {sigma}", m.label),
                    Some(p) => {
                        assert!(m.label.contains("paper default"), "{}", m.label);
                        assert!(
                            sigma == p || same_sigma(sigma, p),
                            "{}: σ = {sigma}",
                            m.label
                        );
                    }
                }
            }
        };
        assert_eq!(OrbOptions::default().sigma_eps, SIGMA_EPS);
        let opts = OrbOptions {
            map_size: 32,
            sigma_eps: 0.02,
            mixture_samples: 4,
            progress: false,
            ..OrbOptions::default()
        };
        let map = load_map(&opts).unwrap();
        check(&build_methods(&opts, &map).unwrap(), 0.02);
        check(&build_models(&map).unwrap(), SIGMA_EPS);
    }

    /// The references converge: on the bumpy map the noise of (a) and of (b) (half the difference of
    /// two independent halves) falls by more than 2 from 2 × 4 to 2 × 64 spp (1/√spp predicts 4;
    /// stratification only helps), and on a flat map of σ_ε = 0.2 both equal the glint renderer's
    /// values, which the test above ties to the closed form (same pixel kernel and frame: every
    /// position sees the same centred lobe).
    #[test]
    fn reference_converges() {
        let bar = ProgressBar::hidden();
        let scene = Scene::new(SIZE, Vec2::new(4.0, 2.0));
        let mask = coverage(&scene);
        let bumpy = brdf::glint::bumpy(64, 64, 0.25, 4.0, 3).unwrap();
        let noise = |k| {
            let r = render_references(&scene, &bumpy, 0.01, k, 5, &bar);
            [
                reference_noise(&r.pbrdf.0, &r.pbrdf.1, &mask),
                reference_noise(&r.normal_mapped.0, &r.normal_mapped.1, &mask),
            ]
        };
        let (coarse, fine) = (noise(2), noise(8));
        for i in 0..2 {
            assert!(
                fine[i] > 0.0 && coarse[i] / fine[i] > 2.0,
                "reference {i}: noise {} at 8 spp, {} at 128 spp",
                coarse[i],
                fine[i]
            );
        }

        let flat = NormalMap::from_slopes(64, 64, vec![Vec2::ZERO; 64 * 64]).unwrap();
        let params = MixtureParams {
            sigma_min: 0.2,
            samples: 16,
            ..MixtureParams::default()
        };
        let mixture = BeckmannMixture::build(&flat, params).unwrap();
        let centre = render_glint(&scene, &variants(&mixture)[0], &bar);
        let r = render_references(&scene, &flat, 0.2, 4, 9, &bar);
        for (a, b) in [&r.pbrdf, &r.normal_mapped] {
            let e = errors(&centre, a, b, &mask);
            // Every position of a flat map carries the same lobe at the pixel centre's directions,
            // so the references are noiseless and equal the renderer up to f32 evaluation (the
            // per-pixel bound of the test above, relative 1e-3): 2e-3 leaves a factor 2.
            assert!(e.rel_rmse < 2e-3, "{e:?}");
            assert!(e.energy.abs() < 2e-3, "{e:?}");
        }
    }

    /// The tangent frame: on a map of constant slope ñ the highlight sits where the tilted normal
    /// normalize(n − x̃ T − ỹ B) (T east = ŷ × n, B north = n × T, computed here) bisects the
    /// directions to the camera and the light, and that is several pixels away from the flat
    /// map's highlight (so a sign or axis error in the frame cannot pass).
    #[test]
    fn tilted_map_moves_the_highlight_where_the_frame_says() {
        let size = 64u32;
        let scene = Scene::new(size, Vec2::new(4.0, 2.0));
        let argmax = |img: &Image| {
            let k = (0..img.pixels.len())
                .max_by(|&i, &j| img.value(i).total_cmp(&img.value(j)))
                .unwrap();
            ((k as u32 % size) as i32, (k as u32 / size) as i32)
        };
        let expected = |slope: [f64; 2]| {
            let mut best = (f64::MIN, (0, 0));
            for y in 0..size {
                for x in 0..size {
                    let s = 2.0 * 0.22 / size as f64;
                    let c = size as f64 / 2.0;
                    let d = unit([(x as f64 + 0.5 - c) * s, (c - y as f64 - 0.5) * s, -1.0]);
                    let o = [0.0, 0.0, 5.0];
                    let b = dot(o, d);
                    let disc = b * b - (dot(o, o) - 1.0);
                    if disc < 0.0 {
                        continue;
                    }
                    let t = -b - disc.sqrt();
                    let n = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
                    let east = unit([n[2], 0.0, -n[0]]); // ŷ × n
                    let north = [
                        n[1] * east[2] - n[2] * east[1],
                        n[2] * east[0] - n[0] * east[2],
                        n[0] * east[1] - n[1] * east[0],
                    ];
                    let tilted = unit([
                        n[0] - slope[0] * east[0] - slope[1] * north[0],
                        n[1] - slope[0] * east[1] - slope[1] * north[1],
                        n[2] - slope[0] * east[2] - slope[1] * north[2],
                    ]);
                    let wi = unit([-2.0 - n[0], 2.5 - n[1], 7.0 - n[2]]);
                    let h = unit([wi[0] - d[0], wi[1] - d[1], wi[2] - d[2]]);
                    let c = dot(tilted, h);
                    if c > best.0 {
                        best = (c, (x as i32, y as i32));
                    }
                }
            }
            best.1
        };
        let render = |slope: Vec2| {
            let map = NormalMap::from_slopes(16, 16, vec![slope; 256]).unwrap();
            let params = MixtureParams {
                sigma_min: 0.03,
                samples: 16,
                ..MixtureParams::default()
            };
            let mixture = BeckmannMixture::build(&map, params).unwrap();
            render_glint(&scene, &variants(&mixture)[0], &ProgressBar::hidden())
        };
        let flat = argmax(&render(Vec2::ZERO));
        assert_eq!(flat, expected([0.0, 0.0]));
        for slope in [[0.25, 0.0], [0.0, -0.25], [-0.2, 0.15]] {
            let got = argmax(&render(Vec2::new(slope[0] as f32, slope[1] as f32)));
            let want = expected(slope);
            // The brightest pixel of a σ = 0.03 lobe is the one whose centre has the best-aligned
            // normal, up to one pixel where two neighbours are nearly tied (masking and D's
            // anisotropy off the pole shift the peak by a fraction of a pixel).
            assert!(
                (got.0 - want.0).abs() <= 1 && (got.1 - want.1).abs() <= 1,
                "slope {slope:?}: highlight at {got:?}, expected {want:?}"
            );
            let moved = (got.0 - flat.0).abs().max((got.1 - flat.1).abs());
            assert!(moved >= 4, "slope {slope:?}: moved only {moved} px");
        }
    }

    /// The equal-error reading of the naive curve: on a curve that halves its error per 4× time
    /// (the 1/√N law), the time at an error between two points is their log-log interpolation
    /// (error 1/√2 between (1 s, 1) and (4 s, 0.5) is reached at 2 s); errors below the curve give
    /// its last time as a lower bound, errors above its first point that time as an upper bound.
    #[test]
    fn naive_time_at_interpolates_in_log_log_and_flags_bounds() {
        use super::common::orb_curves::naive_time_at;
        let curve = [(1.0, 1.0), (4.0, 0.5), (16.0, 0.25)];
        let (t, flag) = naive_time_at(&curve, std::f64::consts::FRAC_1_SQRT_2);
        assert_eq!(flag, "=");
        assert!((t - 2.0).abs() < 1e-12, "{t}");
        assert_eq!(naive_time_at(&curve, 0.1), (16.0, ">"));
        assert_eq!(naive_time_at(&curve, 2.0), (1.0, "<"));
        // A noisy, non-monotone curve: the first point at or below the error counts.
        let noisy = [(1.0, 1.0), (4.0, 1.2), (16.0, 0.3)];
        let (t, flag) = naive_time_at(&noisy, 0.6);
        assert_eq!(flag, "=");
        assert!(t > 4.0 && t < 16.0, "{t}");
    }
    /// The fractal map has the requested RMS slope (computed here from the map's texels), and its
    /// random wave directions spread the slope variance over both axes (isotropy within 30 %).
    #[test]
    fn fractal_map_has_its_rms_slope_and_is_isotropic() {
        use super::common::orb::fractal::{FractalParams, fractal};
        let p = FractalParams::default();
        let map = fractal(64, &p, 3).unwrap();
        let n = map.slopes().len() as f64;
        let mx = map
            .slopes()
            .iter()
            .map(|s| (s.x as f64).powi(2))
            .sum::<f64>()
            / n;
        let my = map
            .slopes()
            .iter()
            .map(|s| (s.y as f64).powi(2))
            .sum::<f64>()
            / n;
        let rms = (0.5 * (mx + my)).sqrt();
        assert!((rms - p.rms_slope as f64).abs() < 1e-3, "rms {rms}");
        let ratio = mx / my;
        assert!(
            ratio > 0.7 && ratio < 1.0 / 0.7,
            "x/y variance ratio {ratio}"
        );
    }

    /// The disc light's points carry the point light's irradiance (to the disc's small change of
    /// distance) and lie within the disc's angular radius seen from the shading point; the point
    /// light is the shading point's own direction.
    #[test]
    fn disc_light_points_share_the_intensity_and_stay_on_the_disc() {
        use super::common::orb::bias::{AREA_LIGHT_DEGREES, Light, light_points};
        let scene = Scene::new(SIZE, Vec2::new(2.0, 1.0));
        let sp = scene.shading(Vec2::new(12.5, 14.5)).unwrap();
        let point = light_points(&scene, &sp, Light::Point, 0);
        assert_eq!(point.len(), 1);
        assert_eq!(point[0].0, sp.wi);
        let disc = light_points(&scene, &sp, Light::Disc, 77);
        let sum: f32 = disc.iter().map(|l| l.1).sum();
        assert!(
            (sum / sp.irradiance - 1.0).abs() < 0.02,
            "{sum} vs {}",
            sp.irradiance
        );
        // Hit point = normal on the unit sphere; the disc's radius over the distance to its centre.
        let p = sp.frame.z;
        let radius = scene.light.length() * AREA_LIGHT_DEGREES.to_radians().tan();
        let max_angle = (radius / (scene.light - p).length()).atan() * 1.05;
        for (wi, _) in &disc {
            let angle = wi.dot(sp.wi).clamp(-1.0, 1.0).acos();
            assert!(angle <= max_angle, "{angle} > {max_angle}");
        }
        // Not all in one place: the spread reaches half the radius.
        let widest = disc
            .iter()
            .map(|l| l.0.dot(sp.wi).clamp(-1.0, 1.0).acos())
            .fold(0.0f32, f32::max);
        assert!(widest > 0.5 * max_angle / 1.05, "{widest}");
    }
}
