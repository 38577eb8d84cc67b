//! Procedural glints of the GGX limit (`ProceduralLimit::Ggx`): is the P-NDF normalised, is its
//! mean over the random field GGX at every footprint size, does it converge to GGX as the footprint
//! grows, are its samplers' densities right, its furnace at most one, its work bounded, is it
//! reciprocal in its own measure, and does it survive a file? (The Beckmann limit:
//! procedural_glints.rs, unchanged.)
//!
//! Run: `cargo test --release --test it procedural_ggx::` (the convergence table with
//! `-- --nocapture`).

use crate::support::{self, bxdf::random_upper, chi2::Chi2, density_distances};
use brdf::bxdf::MicrofacetBrdf;
use brdf::fresnel::NoFresnel;
use brdf::glint::procedural::{LimitNdf, ProceduralGlints, ProceduralLimit, ProceduralParams};
use brdf::glint::{Footprint, GlintModel, GlintNdf};
use brdf::ndf::{Ggx, Ndf};
use brdf::{Vec2, Vec3};
use rand::RngExt;

const RES: usize = 1024;

fn params(seed: u64) -> ProceduralParams {
    ProceduralParams {
        seed,
        limit: ProceduralLimit::Ggx,
        ..Default::default()
    }
}

fn surface(seed: u64) -> ProceduralGlints {
    ProceduralGlints::new(params(seed)).unwrap()
}

/// An isotropic footprint of `area` texels at `uv`.
fn fp(uv: Vec2, area: f32) -> Footprint {
    Footprint::isotropic_texels(uv, area, RES, RES)
}

/// Footprint areas from below one facet to GGX alone (default surface, one facet per texel: the
/// GGX blend starts near 25,000 texels and is complete near 100,000).
const AREAS: [f32; 10] = [
    0.25, 1.0, 16.0, 256.0, 4096.0, 16384.0, 40000.0, 65536.0, 131072.0, 262144.0,
];

/// The breakpoints of a partition of u ∈ [−1, 1], the slope axis mapped by s = tan(π u / 2):
/// `n` equal cells, and where slopes of `refine` lie beyond |s| = 2 (where those cells are wider
/// than a facet lobe) cells of 0.005 in s over ± 0.2 around each 0.2 of slope that holds some.
fn breakpoints(n: usize, refine: &[f64]) -> Vec<f64> {
    let mut b: Vec<f64> = (0..=n).map(|i| -1.0 + 2.0 * i as f64 / n as f64).collect();
    // One refined stretch per 0.2 of slope that holds draws (centred on that bin).
    let mut bins: Vec<i64> = refine
        .iter()
        .filter(|s| s.abs() > 2.0 && s.abs() < 1e4)
        .map(|s| (s / 0.2).round() as i64)
        .collect();
    bins.sort_unstable();
    bins.dedup();
    for s in bins.into_iter().map(|k| k as f64 * 0.2) {
        for j in -40..=40 {
            let t = s + 0.005 * j as f64;
            b.push(t.atan() * 2.0 / std::f64::consts::PI);
        }
    }
    b.sort_by(f64::total_cmp);
    b.dedup();
    b
}

/// ∫ D cos θ dω = ∫ P22(s) ds over the whole slope plane: the midpoint rule in u = (2/π) atan s per
/// axis (Jacobian ds/du = (π/2)(1 + s²)), on 1600 equal cells per axis (cells of at most 0.0125 in
/// slope for |s| ≤ 2, below one facet deviation 0.0141, where the midpoint rule of a Gaussian is
/// exact to ~10⁻⁸), refined around slopes where the patch's own normal sampler puts draws beyond
/// |s| = 2 (the sampler only chooses where to refine; the integral is of `d` alone).
fn slope_integral(ndf: &dyn Ndf) -> f64 {
    let mut rng = support::rng(77);
    let (mut rx, mut ry) = (Vec::new(), Vec::new());
    for _ in 0..4000 {
        let m = ndf.sample_normal(Vec2::new(rng.random(), rng.random()));
        if m.z > 0.0 {
            rx.push((-m.x / m.z) as f64);
            ry.push((-m.y / m.z) as f64);
        }
    }
    let (bx, by) = (breakpoints(1600, &rx), breakpoints(1600, &ry));
    let half_pi = std::f64::consts::FRAC_PI_2;
    let cells = |b: &[f64]| -> Vec<(f64, f64)> {
        b.windows(2)
            .map(|w| {
                let u = 0.5 * (w[0] + w[1]);
                let s = (half_pi * u).tan();
                (s, half_pi * (1.0 + s * s) * (w[1] - w[0]))
            })
            .collect()
    };
    let (cx, cy) = (cells(&bx), cells(&by));
    let mut sum = 0.0;
    for &(sy, hy) in &cy {
        for &(sx, hx) in &cx {
            let m = Vec3::new(-sx as f32, -sy as f32, 1.0).normalize();
            if !m.is_finite() {
                continue;
            }
            let c = m.z as f64;
            sum += ndf.d(m) as f64 * c * c * c * c * hx * hy;
        }
    }
    sum
}

/// ∫ D_P cos θ dω = 1 at a small, a medium, a blended and a large footprint, isotropic and
/// anisotropic (quadrature above; the limit lobe alone, GGX itself, is checked the same way).
#[test]
fn ggx_patches_are_normalised() {
    let s = surface(2);
    let mut rng = support::rng(4);
    for area in [1.0f32, 256.0, 40000.0, 262144.0] {
        for aspect in [1.0f32, 8.0] {
            let uv = Vec2::new(rng.random(), rng.random());
            let f = Footprint::anisotropic_texels(uv, area, aspect, 0.7, RES, RES);
            let p = s.patch(&f);
            let integral = slope_integral(&p);
            assert!(
                (integral - 1.0).abs() < 1e-3,
                "area {area} aspect {aspect}: ∫ D cos = {integral} ({} lobes)",
                p.lobe_count()
            );
        }
    }
}

/// The GGX slope distribution in units of α per axis, t = s/α: density 1/(π (1 + |t|²)²), so
/// P(|t| < r) = r²/(1 + r²) and the marginal cdf F(x) = 1/2 + x / (2 √(1 + x²)) (integrals of the
/// density by hand).
fn ggx_disc(r: f64) -> f64 {
    r * r / (1.0 + r * r)
}

fn ggx_tail(x: f64) -> f64 {
    0.5 - x / (2.0 * (1.0 + x * x).sqrt())
}

/// The mean of the P-NDF over the random field (footprint positions and seeds) is GGX at every
/// footprint size: bin masses of the slope drawn from the patch's own normal sampler (chi-square
/// tested below), one draw per random footprint, against GGX's (the second moment is infinite for
/// GGX: only bounded test functions), each within 5 standard errors.
#[test]
fn mean_over_positions_is_ggx() {
    let alpha = [0.3f64, 0.2];
    let p = ProceduralParams {
        alpha: Vec2::new(0.3, 0.2),
        ..params(0)
    };
    let mut rng = support::rng(8);
    let n = 40_000;
    type SlopeFunction<'a> = Box<dyn Fn([f64; 2]) -> f64 + 'a>;
    let r2 = |t: [f64; 2]| t[0] * t[0] + t[1] * t[1];
    let functions: [(&str, SlopeFunction, f64); 7] = [
        ("P(tx > 0)", Box::new(|t| (t[0] > 0.0) as u8 as f64), 0.5),
        (
            "P(tx > 0, ty > 0)",
            Box::new(|t| (t[0] > 0.0 && t[1] > 0.0) as u8 as f64),
            0.25,
        ),
        (
            "P(tx > 1)",
            Box::new(|t| (t[0] > 1.0) as u8 as f64),
            ggx_tail(1.0),
        ),
        (
            "P(ty < −0.5)",
            Box::new(|t| (t[1] < -0.5) as u8 as f64),
            ggx_tail(0.5),
        ),
        (
            "P(|t| < 0.5)",
            Box::new(move |t| (r2(t) < 0.25) as u8 as f64),
            ggx_disc(0.5),
        ),
        (
            "P(|t| < 2)",
            Box::new(move |t| (r2(t) < 4.0) as u8 as f64),
            ggx_disc(2.0),
        ),
        (
            "P(|t| > 6)",
            Box::new(move |t| (r2(t) > 36.0) as u8 as f64),
            1.0 - ggx_disc(6.0),
        ),
    ];
    for (a, area) in AREAS.into_iter().enumerate() {
        let mut sums = [(0.0f64, 0.0f64); 7];
        for k in 0..n {
            // A surface of its own per draw (a seed of the field): at coarse levels a period holds
            // few cells, and draws from a few seeds would share their lobes' variance scales (the
            // heavy tail of v makes that sharing visible), so that the draws were not independent.
            let seed = (a * n + k) as u64;
            let surface = ProceduralGlints::new(ProceduralParams { seed, ..p }).unwrap();
            let uv = Vec2::new(rng.random(), rng.random());
            let patch = surface.patch(&fp(uv, area));
            let m = patch.sample_normal(Vec2::new(rng.random(), rng.random()));
            let t = [
                (-m.x / m.z) as f64 / alpha[0],
                (-m.y / m.z) as f64 / alpha[1],
            ];
            for (acc, (_, f, _)) in sums.iter_mut().zip(&functions) {
                let v = f(t);
                acc.0 += v;
                acc.1 += v * v;
            }
        }
        for ((sum, sum2), (name, _, exact)) in sums.iter().zip(&functions) {
            let mean = sum / n as f64;
            let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
            assert!(
                (mean - exact).abs() <= 5.0 * se,
                "area {area}: {name} = {mean:.4} ± {se:.4}, GGX {exact:.4}"
            );
        }
    }
}

/// The P-NDF converges to GGX as the footprint grows: the total variation of the normal densities
/// (mean over 8 random centres) falls with the footprint (up to the estimate's noise) and is at most
/// 0.02 from 131,072 texels on (GGX alone). Prints the table of docs/results.md.
#[test]
fn converges_to_the_limit() {
    let s = surface(1);
    let limit = s.limit();
    assert!(matches!(limit, LimitNdf::Ggx(_)));
    let mut rng = support::rng(3);
    let mut last = f64::INFINITY;
    println!("| texels | level | lobes | limit weight | expected distance ρ | TV to GGX |");
    println!("|---|---|---|---|---|---|");
    for area in AREAS {
        let (mut tv, mut lobes) = (0.0, 0);
        let k = 8;
        let mut shown = (0.0, 0.0, 0.0);
        for _ in 0..k {
            let uv = Vec2::new(rng.random(), rng.random());
            let p = s.patch(&fp(uv, area));
            tv += density_distances(&limit, &p, 4096, 9).0 / k as f64;
            lobes = lobes.max(p.lobe_count());
            shown = (p.level(), p.limit_weight(), p.expected_distance());
        }
        let (level, b, rho) = shown;
        println!("| {area} | {level:.2} | {lobes} | {b:.2} | {rho:.3} | {tv:.3} |");
        assert!(tv <= last + 0.03, "area {area}: TV {tv} after {last}");
        if area >= 131072.0 {
            assert!(tv <= 0.02, "area {area}: TV {tv}");
        }
        last = tv;
    }
}

/// The sampler checks at a small (1 texel), a medium (256) and a blended footprint (60,000: GGX
/// and lobes): which of them `cases` selects as (area index, sampler: None normals, Some(θo)
/// visible). 10⁶ draws each (10⁵ in the default run, `support::depth`); draws where the density
/// is 0 (beyond a lobe's slope box) count as `None`, as in procedural_glints.rs; normals beyond
/// θ = 60° form the overflow cell (below).
fn chi2_samplers(cases: &[(usize, Option<f64>)]) {
    let s = surface(5);
    let footprints = [
        (1.0f32, Vec2::new(0.31, 0.62)),
        (256.0, Vec2::new(0.77, 0.12)),
        (60000.0, Vec2::new(0.5, 0.5)),
    ];
    for &(k, sampler) in cases {
        let (area, uv) = footprints[k];
        let p = s.patch(&fp(uv, area));
        if area > 1000.0 {
            assert!(p.limit_weight() > 0.0 && p.limit_weight() < 1.0);
        }
        // Normals beyond θ = 60° (z < 0.5, slopes above 1.7) are one overflow cell, tested in
        // aggregate: a GGX surface has narrow facet lobes (β = σ_f, a wide cell's lobe) far out,
        // where a slope deviation of 0.014 is 8·10⁻⁴ rad at slope 4 and less beyond: 1/25 of a cell
        // or less, between the points of the harness's 6 × 6 rule, which then agrees with its 4 × 4
        // rule on nothing and misses the lobe (measured: 9 draws in cells expecting 0.008 with
        // z_min 0.2). Within 60° a lobe is at least 3.6·10⁻³ rad wide, as the Beckmann surface's.
        let cfg = |name: String| Chi2 {
            z_min: Some(0.5),
            ..Chi2::new(name, cases.len())
        };
        match sampler {
            None => cfg(format!("procedural GGX {area} texels normals")).run(
                |_, u| Some(p.sample_normal(u)).filter(|&m| p.pdf_normal(m) > 0.0),
                |m| p.pdf_normal(m) as f64,
            ),
            Some(theta) => {
                let wo = support::dir(theta, 20.0);
                cfg(format!("procedural GGX {area} texels visible {theta}")).run(
                    |_, u| Some(p.sample_visible(wo, u)).filter(|&m| p.pdf_visible(wo, m) > 0.0),
                    |m| p.pdf_visible(wo, m) as f64,
                )
            }
        }
        .unwrap();
    }
}

/// Chi-square, the default subset: the visible sampler at a small footprint (60°), the normal
/// sampler at a medium one and the visible sampler of the blend at a grazing view (85°).
#[test]
fn samplers_match_their_densities() {
    chi2_samplers(&[(0, Some(60.0)), (1, None), (2, Some(85.0))]);
}

/// Chi-square, the full grid: both samplers (visible at 0°, 60°, 85°) at the three footprints.
/// `cargo test --release --test it procedural_ggx::samplers_match_their_densities_everywhere --
/// --ignored` (~25 s).
#[test]
#[ignore = "the full grid (~25 s); the default run checks a subset"]
fn samplers_match_their_densities_everywhere() {
    let cases: Vec<_> = (0..3)
        .flat_map(|k| [None, Some(0.0), Some(60.0), Some(85.0)].map(|s| (k, s)))
        .collect();
    chi2_samplers(&cases);
}

/// The white furnace the way a renderer computes it, F = 1, at the footprints and views of
/// `cases` (small, medium, blended, GGX alone).
fn furnaces(cases: &[(usize, f64)]) {
    let s = surface(6);
    let mut rng = support::rng(12);
    let footprints = [
        (1.0f32, Vec2::new(0.4, 0.4)),
        (256.0, Vec2::new(0.2, 0.9)),
        (60000.0, Vec2::new(0.6, 0.3)),
        (262144.0, Vec2::new(0.1, 0.5)),
    ];
    for &(k, theta) in cases {
        let (area, uv) = footprints[k];
        let brdf = MicrofacetBrdf::new(s.patch(&fp(uv, area)), NoFresnel);
        support::bxdf::assert_half_vector_furnaces(
            &brdf,
            [theta],
            &mut rng,
            &format!("procedural GGX {area} texels"),
        );
    }
}

/// The furnace is at most one, the default subset: a small footprint at 45°, a medium one at 85°,
/// the blend at 70°.
#[test]
fn furnace_is_at_most_one() {
    furnaces(&[(0, 45.0), (1, 85.0), (2, 70.0)]);
}

/// The furnace everywhere: four footprints × views 0°, 45°, 70°, 85°.
/// `cargo test --release --test it procedural_ggx::furnace_is_at_most_one_everywhere -- --ignored`
/// (~17 s).
#[test]
#[ignore = "the full grid (~17 s); the default run checks a subset"]
fn furnace_is_at_most_one_everywhere() {
    let cases: Vec<_> = (0..4)
        .flat_map(|k| [0.0, 45.0, 70.0, 85.0].map(|t| (k, t)))
        .collect();
    furnaces(&cases);
}

/// Reciprocity in the patch's own measure (src/bxdf/microfacet.rs), as for the Beckmann limit.
#[test]
fn reciprocal_in_its_own_measure() {
    crate::procedural_glints::assert_reciprocal_in_own_measure(
        &surface(13),
        &[1.0, 256.0, 60000.0],
    );
}

/// Bounded work: at most 48 lobes (GGX counted as one) over random footprints of every size,
/// aspect ratio and orientation, at densities from one facet per uv period to 64 per texel; every
/// value finite at grazing and below-horizon directions.
#[test]
fn every_patch_holds_few_lobes_and_is_total() {
    let mut rng = support::rng(21);
    let dirs = [
        Vec3::new(1.0, 0.0, 1e-30).normalize(),
        Vec3::new(0.0, -1.0, -1e-3).normalize(),
        Vec3::Z,
        Vec3::new(0.6, 0.0, 0.8),
    ];
    for density in [1e-6f32, 0.01, 1.0, 64.0] {
        let s = ProceduralGlints::new(ProceduralParams {
            density,
            ..params(0)
        })
        .unwrap();
        let mut most = 0;
        for _ in 0..2000 {
            let area = 10f32.powf(rng.random_range(-2.0..12.0));
            let aspect = 10f32.powf(rng.random_range(0.0..3.0));
            let angle = rng.random_range(0.0..std::f32::consts::PI);
            let uv = Vec2::new(rng.random(), rng.random());
            let f = Footprint::anisotropic_texels(uv, area, aspect, angle, RES, RES);
            let p = s.patch(&f);
            most = most.max(p.lobe_count());
            for &w in &dirs {
                for &m in &dirs {
                    let v = [p.d(m), p.lambda(w), p.visible_area(w), p.pdf_visible(w, m)];
                    assert!(v.iter().all(|x| x.is_finite() && *x >= 0.0), "{v:?}");
                }
                assert!(p.sample_visible(w, Vec2::new(0.3, 0.9)).is_finite());
            }
        }
        println!("GGX density {density}: at most {most} lobes");
        // At most 2 × 16 candidates and the limit lobe by construction; 16-18 measured.
        assert!(most <= 24, "density {density}: {most} lobes");
    }
}

/// A GGX surface is saved as kind 7 (a reader that predates it refuses the file as an unknown
/// kind) and loads, through its own loader and `GlintModel::load`, to the same parameters and the
/// same patches bit for bit; a Beckmann surface is still kind 6.
#[test]
fn ggx_surfaces_survive_a_file() {
    let s = ProceduralGlints::new(ProceduralParams {
        alpha: Vec2::new(0.12, 0.45),
        facet_alpha: 0.01,
        density: 0.37,
        resolution: [300, 77],
        seed: u64::MAX,
        limit: ProceduralLimit::Ggx,
    })
    .unwrap();
    let mut bytes = Vec::new();
    s.save(&mut bytes).unwrap();
    assert_eq!(u32::from_le_bytes(bytes[12..16].try_into().unwrap()), 7);
    assert_eq!(bytes.len(), 72);
    let back = ProceduralGlints::load(&mut &bytes[..]).unwrap();
    assert_eq!(back.params(), s.params());
    let GlintModel::Procedural(model) = GlintModel::load(&mut &bytes[..]).unwrap() else {
        panic!("not a procedural model");
    };
    assert_eq!(model.params(), s.params());
    let mut rng = support::rng(5);
    for area in [1.0f32, 100.0, 3000.0] {
        let f = Footprint::isotropic_texels(Vec2::new(0.2, 0.7), area, 300, 77);
        let (a, b) = (s.patch(&f), back.patch(&f));
        for _ in 0..64 {
            let m = random_upper(&mut rng);
            assert_eq!(a.d(m).to_bits(), b.d(m).to_bits());
        }
    }
    let beckmann = ProceduralGlints::new(ProceduralParams {
        limit: ProceduralLimit::Beckmann,
        ..*s.params()
    })
    .unwrap();
    let mut old = Vec::new();
    beckmann.save(&mut old).unwrap();
    assert_eq!(u32::from_le_bytes(old[12..16].try_into().unwrap()), 6);
    // The same header but for the kind, the same payload (the checksums differ).
    assert_eq!(
        (old.len(), &old[..12], &old[16..64]),
        (72, &bytes[..12], &bytes[16..64])
    );
    let back = ProceduralGlints::load(&mut &old[..]).unwrap();
    assert_eq!(back.params().limit, ProceduralLimit::Beckmann);
}

/// The GGX limit NDF of a surface is the crate's `Ggx` of the same α, and a footprint much
/// larger than the blend's end is that NDF alone.
#[test]
fn large_footprints_are_ggx() {
    let s = surface(3);
    let g = Ggx::new(0.3, 0.3).unwrap();
    assert_eq!(s.limit(), LimitNdf::Ggx(g));
    let p = s.patch(&fp(Vec2::new(0.5, 0.5), 1.0e6));
    assert_eq!(p.lobe_count(), 1);
    assert_eq!(p.limit_weight(), 1.0);
    let mut rng = support::rng(6);
    for _ in 0..64 {
        let m = random_upper(&mut rng);
        assert_eq!(p.d(m).to_bits(), g.d(m).to_bits());
    }
}

/// The density contract through `MicrofacetBrdf` (tests/it/density_contract.rs): eval > 0 ⇒
/// pdf > 0, every value finite, visible-sample weights at most F, for GGX patches below a facet,
/// of lobes, blended with GGX and GGX alone, over the contract's directions of cos θ 1 to 10⁻³⁰
/// (a subset of its grid, as density_contract_glint.rs) and every draw of its `u` grid.
#[test]
fn ggx_patches_keep_the_density_contract() {
    use crate::density_contract::{VISIBLE_BOUND, case, grid, run, u_grid};
    let s: &'static ProceduralGlints = Box::leak(Box::new(surface(17)));
    let cases: Vec<_> = [0.5f32, 256.0, 60000.0, 262144.0]
        .into_iter()
        .map(|area| {
            let patch = s.patch(&fp(Vec2::new(0.43, 0.61), area));
            case(
                format!("procedural GGX {area} texels"),
                MicrofacetBrdf::new(patch, NoFresnel),
                Some(VISIBLE_BOUND),
            )
        })
        .collect();
    let cosines = [1.0f32, 0.5, 0.1, 1e-2, 1e-4, 1e-7, 1e-15, 1e-30];
    let g: Vec<Vec3> = grid()
        .into_iter()
        .filter(|w| cosines.contains(&w.z))
        .collect();
    run(&cases, &g, &g, &u_grid());
}

/// The P-NDF is continuous in the footprint's size: across every level boundary and across the
/// hand-over to GGX alone (where the patch stops gathering lobes), a 0.1 % larger footprint changes
/// it by little (TV < 0.01), as for the Beckmann limit (procedural_glints.rs).
#[test]
fn the_ggx_pattern_is_continuous() {
    let s = surface(9);
    let at = |area: f32| s.patch(&fp(Vec2::splat(0.37), area));
    // The smallest area at which `crossed` holds (it holds from there on), by bisection.
    let boundary = |crossed: &dyn Fn(f32) -> bool| {
        let (mut lo, mut hi) = (0.25f32, 1.0e7f32);
        for _ in 0..60 {
            let mid = (lo * hi).sqrt();
            if crossed(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (lo, hi)
    };
    let mut checked = Vec::new();
    for level in 1..9 {
        checked.push((
            format!("level {level}"),
            boundary(&|a| at(a).level() >= level as f32),
        ));
    }
    checked.push(("GGX alone".into(), boundary(&|a| at(a).lobe_count() == 1)));
    for (name, (lo, hi)) in checked {
        let (below, above) = (at(lo * 0.9995), at(hi * 1.0005));
        let tv = density_distances(&below, &above, 4096, 6).0;
        assert!(tv < 0.01, "{name} at {hi} texels: TV {tv}");
    }
}
