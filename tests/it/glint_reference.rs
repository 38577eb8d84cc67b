//! The hemisphere bins (equal solid angle, exact mean cosine, a bijection with the square's cells)
//! and the ground-truth P-NDF built on them: normalised, deterministic, convergent, sensitive to the
//! kernel and the footprint size; the TV distance; and the naive per-position BRDF.

use crate::support;

use brdf::glint::{
    BinnedPndf, Footprint, HemisphereBins, Kernel, NormalMap, binned_pndf, bumpy, flakes,
    naive_brdf, tv_distance,
};
use brdf::ndf::{Ndf, SlopeGaussian};
use brdf::{Vec2, Vec3};
use rand::RngExt;

/// Uniform directions on the hemisphere written here (Archimedes: z uniform in [0, 1]).
fn uniform_dir(rng: &mut impl rand::Rng) -> Vec3 {
    let z: f64 = rng.random();
    let phi = std::f64::consts::TAU * rng.random::<f64>();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32)
}

#[test]
fn bins_have_equal_solid_angle_and_exact_mean_cosine() {
    for n in [8usize, 7] {
        let bins = HemisphereBins::new(n).unwrap();
        assert_eq!(bins.len(), n * n);
        assert!((bins.solid_angle() * (n * n) as f64 - std::f64::consts::TAU).abs() < 1e-12);
        let mut rng = support::rng(50 + n as u64);
        let total = 10_000 * n * n;
        let mut count = vec![0usize; n * n];
        let mut zsum = vec![0.0f64; n * n];
        for _ in 0..total {
            let w = uniform_dir(&mut rng);
            let b = bins.bin_of(w).unwrap();
            count[b] += 1;
            zsum[b] += w.z as f64;
        }
        for b in 0..n * n {
            // Binomial count with mean 10⁴ and SD ≤ 100: 5 SD = 500 (failure odds ~1e-5 over the bins).
            assert!(
                (count[b] as f64 - 10_000.0).abs() < 500.0,
                "n = {n}, bin {b}: {}",
                count[b]
            );
            // Sample mean of z in the bin: SD of z within a bin ≤ 0.2, SE ≤ 0.002; 5 SE.
            let mean = zsum[b] / count[b] as f64;
            assert!(
                (mean - bins.mean_cos(b)).abs() < 0.01,
                "bin {b}: {mean} vs {}",
                bins.mean_cos(b)
            );
        }
        // Projected solid angle of the hemisphere: Σ ΔΩ · mean cos = π (exact integration).
        let proj: f64 = (0..n * n)
            .map(|b| bins.mean_cos(b) * bins.solid_angle())
            .sum();
        assert!((proj - std::f64::consts::PI).abs() < 1e-12, "{proj}");
    }
}

#[test]
fn bins_are_a_bijection_with_the_square_cells() {
    for n in [1usize, 2, 5, 16, 33] {
        let bins = HemisphereBins::new(n).unwrap();
        for b in 0..bins.len() {
            for a in [0.05f32, 0.3, 0.5, 0.7, 0.95] {
                for c in [0.05f32, 0.5, 0.95] {
                    let w = bins.sample_in_bin(b, Vec2::new(a, c));
                    assert!((w.length() - 1.0).abs() < 1e-5 && w.z >= 0.0);
                    assert_eq!(bins.bin_of(w), Some(b), "n = {n}, bin {b}, u = ({a}, {c})");
                }
            }
            assert_eq!(bins.bin_of(bins.center(b)), Some(b));
        }
    }
    // Odd n: the pole is the centre of the central bin.
    let bins = HemisphereBins::new(7).unwrap();
    assert_eq!(bins.bin_of(Vec3::Z), Some(3 * 7 + 3));
    assert!((bins.center(3 * 7 + 3) - Vec3::Z).length() < 1e-6);
    // Invalid directions.
    assert_eq!(bins.bin_of(Vec3::new(0.0, 0.0, -1.0)), None);
    assert_eq!(bins.bin_of(Vec3::ZERO), None);
    assert_eq!(bins.bin_of(Vec3::new(f32::NAN, 0.0, 1.0)), None);
    assert!(
        bins.bin_of(Vec3::X).is_some(),
        "horizon directions belong to boundary bins"
    );
    assert!(HemisphereBins::new(0).is_err() && HemisphereBins::new(5000).is_err());
}

/// A piecewise-constant NDF read from a reference (d only; enough for tv_distance).
struct Tabulated<'a>(&'a BinnedPndf);
impl Ndf for Tabulated<'_> {
    fn d(&self, m: Vec3) -> f32 {
        self.0.d_at(m) as f32
    }
    fn lambda(&self, _w: Vec3) -> f32 {
        0.0
    }
    fn sample_normal(&self, _u: Vec2) -> Vec3 {
        Vec3::Z
    }
    fn sample_visible(&self, _wo: Vec3, _u: Vec2) -> Vec3 {
        Vec3::Z
    }
}

/// D = 1/π: the "Lambertian" NDF (∫ cos/π dω = 1).
struct Uniform;
impl Ndf for Uniform {
    fn d(&self, m: Vec3) -> f32 {
        if m.z > 0.0 {
            std::f32::consts::FRAC_1_PI
        } else {
            0.0
        }
    }
    fn lambda(&self, _w: Vec3) -> f32 {
        0.0
    }
    fn sample_normal(&self, _u: Vec2) -> Vec3 {
        Vec3::Z
    }
    fn sample_visible(&self, _wo: Vec3, _u: Vec2) -> Vec3 {
        Vec3::Z
    }
}

fn check_normalised(r: &BinnedPndf) {
    let dw = r.bins().solid_angle();
    let s: f64 = r
        .d()
        .iter()
        .zip(r.cos_theta())
        .map(|(d, c)| d * c * dw)
        .sum();
    // Σ mass = 1 by construction; the f64 sum of up to 4096 terms rounds at ~1e-13.
    assert!((s - 1.0).abs() < 1e-12, "Σ D cos ΔΩ = {s}");
    let m: f64 = r.mass().iter().sum();
    assert!((m - 1.0).abs() < 1e-12);
    for (b, &c) in r.cos_theta().iter().enumerate() {
        assert!(c > 0.0 && c <= 1.0, "bin {b}: cos {c}");
    }
}

#[test]
fn flat_map_puts_all_mass_in_the_bin_of_its_normal() {
    let s0 = Vec2::new(0.4, -0.25);
    let map = NormalMap::from_slopes(8, 8, vec![s0; 64]).unwrap();
    let n0 = brdf::frame::slope_to_normal(s0);
    let bins = HemisphereBins::new(32).unwrap();
    for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
        let f = Footprint::isotropic_texels(Vec2::new(0.3, 0.7), 16.0, 8, 8);
        let r = binned_pndf(&map, &f, kernel, &bins, 20_000, 1);
        let b0 = bins.bin_of(n0).unwrap();
        assert_eq!(r.mass()[b0], 1.0);
        // D = 1/(cos θ0 ΔΩ) in that bin (f32 normal → 1e-6 relative).
        let want = 1.0 / (n0.z as f64 * bins.solid_angle());
        assert!((r.d()[b0] / want - 1.0).abs() < 1e-6);
        assert!((r.cos_theta()[b0] - n0.z as f64).abs() < 1e-6);
        assert_eq!(r.std_error()[b0], 0.0);
        check_normalised(&r);
        // The uniform NDF against a Dirac: TV = 1 − its mass in that bin, ΔΩ · mean cos / π (exact
        // bin integral), if its total mass is 1. tv_distance's midpoint grid errs on the total by
        // ~1e-4 at k = 4 (measured); the error falls as k⁻² for the smooth cos/π, so k = 64 brings it
        // to ~5e-7: tolerance 5e-6.
        let tv = tv_distance(&Uniform, &r, 64 * 64);
        let want = 1.0 - bins.solid_angle() * bins.mean_cos(b0) / std::f64::consts::PI;
        assert!((tv - want).abs() < 5e-6, "{tv} vs {want}");
        let coarse = tv_distance(&Uniform, &r, 16);
        assert!((coarse - want).abs() < 1e-3, "{coarse} vs {want}");
    }
}

#[test]
fn reference_is_normalised_and_deterministic() {
    let map = bumpy(64, 48, 0.35, 4.0, 3).unwrap();
    let bins = HemisphereBins::new(24).unwrap();
    let f = Footprint::anisotropic_texels(Vec2::new(0.2, 0.9), 300.0, 3.0, 0.4, 64, 48);
    for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
        let r = binned_pndf(&map, &f, kernel, &bins, 100_000, 7);
        check_normalised(&r);
        assert_eq!(r.samples(), 16 * 79 * 79);
        let again = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap()
            .install(|| binned_pndf(&map, &f, kernel, &bins, 100_000, 7));
        assert_eq!(r.d(), again.d());
        assert_eq!(r.mass(), again.mass());
        let other_seed = binned_pndf(&map, &f, kernel, &bins, 100_000, 8);
        assert_ne!(r.mass(), other_seed.mass());
        // Different seeds agree within the noise floor (two independent estimates: √2 × each).
        let tv = r.tv_to(&other_seed).unwrap();
        assert!(
            tv < 4.0 * (r.tv_error() + other_seed.tv_error()),
            "{tv} vs {}",
            r.tv_error()
        );
    }
}

#[test]
fn reference_converges() {
    // Error against a 64× denser run; for plain Monte Carlo it halves when the samples ×4 (stratified
    // sampling may do better). 0.6 leaves room for the dense run's own error (1/8 of the coarse one).
    let map = bumpy(64, 64, 0.3, 4.0, 5).unwrap();
    let bins = HemisphereBins::new(16).unwrap();
    let f = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 256.0, 64, 64);
    for kernel in [Kernel::Gaussian, Kernel::Parallelogram] {
        let n = 16 * 32 * 32;
        let dense = binned_pndf(&map, &f, kernel, &bins, 64 * n, 100);
        let r1 = binned_pndf(&map, &f, kernel, &bins, n, 1);
        let r4 = binned_pndf(&map, &f, kernel, &bins, 4 * n, 2);
        let (e1, e4) = (r1.tv_to(&dense).unwrap(), r4.tv_to(&dense).unwrap());
        eprintln!(
            "{kernel:?}: error {e1:.2e} → {e4:.2e}; estimated {:.2e} → {:.2e}",
            r1.tv_error(),
            r4.tv_error()
        );
        assert!(e4 < 0.6 * e1, "{kernel:?}: {e1} → {e4}");
        // The reported noise floor predicts the actual error within a factor 2 (the batch estimate
        // of each bin's SE has ~18 % error; summed over ~100 occupied bins it averages out).
        for (e, r) in [(e1, &r1), (e4, &r4)] {
            let ratio = e / r.tv_error();
            assert!(
                ratio > 0.5 && ratio < 2.0,
                "{kernel:?}: actual {e} vs estimated {}",
                r.tv_error()
            );
        }
    }
}

#[test]
fn kernels_differ_and_footprint_size_matters() {
    // The whole map seen through a big footprint vs. one texel: the small footprint concentrates
    // the mass (lower entropy), the big one spreads it. Both views of the same footprint agree
    // closely for large footprints (same mean and covariance over a statistically uniform field).
    let map = bumpy(64, 64, 0.3, 3.0, 6).unwrap();
    let bins = HemisphereBins::new(16).unwrap();
    let big = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 4096.0, 64, 64);
    let small = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 1.0, 64, 64);
    let g = binned_pndf(&map, &big, Kernel::Gaussian, &bins, 400_000, 1);
    let p = binned_pndf(&map, &big, Kernel::Parallelogram, &bins, 400_000, 1);
    let s = binned_pndf(&map, &small, Kernel::Gaussian, &bins, 400_000, 1);
    let occupied = |r: &BinnedPndf| r.mass().iter().filter(|&&m| m > 1e-3).count();
    assert!(
        occupied(&s) * 3 < occupied(&g),
        "{} vs {}",
        occupied(&s),
        occupied(&g)
    );
    let tv_gp = g.tv_to(&p).unwrap();
    let tv_gs = g.tv_to(&s).unwrap();
    eprintln!(
        "occupied {} vs {}; tv gauss/para {tv_gp:.3}, big/small {tv_gs:.3}",
        occupied(&s),
        occupied(&g)
    );
    assert!(tv_gp < 0.1 && tv_gs > 0.5, "{tv_gp} {tv_gs}");
}

#[test]
fn tv_distance_of_the_reference_to_itself_and_to_other_maps() {
    let bins = HemisphereBins::new(32).unwrap();
    let a = bumpy(64, 64, 0.25, 4.0, 1).unwrap();
    let b = flakes(64, 64, brdf::glint::FlakesParams::default(), 1).unwrap();
    let f = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 1024.0, 64, 64);
    let ra = binned_pndf(&a, &f, Kernel::Gaussian, &bins, 200_000, 1);
    let rb = binned_pndf(&b, &f, Kernel::Gaussian, &bins, 200_000, 1);
    // Itself, as a piecewise-constant model: the only difference is the cosine inside each bin
    // (grid mean vs the samples' harmonic mean). Over a bin of width ~2/32 in the square the cosine
    // varies by ≤ 0.1 (slope of z = 1 − r² is ≤ 2 per unit of the square, cell side 1/32 → Δz ≤
    // 0.0625 per axis); relative to cos ≥ 0.5 (where almost all mass of this map lies) ≤ 0.2 and
    // only the within-bin *mean* differences enter, bounded by half of it: TV ≤ ½ · 0.1.
    let self_tv = tv_distance(&Tabulated(&ra), &ra, 16);
    assert!(self_tv < 0.05, "{self_tv}");
    // Two different maps are far apart, far above the noise floor.
    let cross = tv_distance(&Tabulated(&rb), &ra, 16);
    assert!(cross > 0.3 && cross > 20.0 * ra.tv_error(), "{cross}");
    assert!((cross - ra.tv_to(&rb).unwrap()).abs() < 0.1);
    // A Gaussian slope lobe with the map's texel moments approximates a large footprint of a
    // Gaussian field; the same lobe twice as wide does not.
    let big = Footprint::isotropic_texels(Vec2::new(0.5, 0.5), 4096.0, 64, 64);
    let r = binned_pndf(&a, &big, Kernel::Gaussian, &bins, 400_000, 2);
    let m = a.moment_pyramid().level(a.levels() - 1).unwrap()[0];
    let fit = SlopeGaussian::from_moments(m, 0.01);
    let wide = SlopeGaussian::from_moments([m[0], m[1], 4.0 * m[2], 4.0 * m[3], 4.0 * m[4]], 0.01);
    let (t_fit, t_wide) = (tv_distance(&fit, &r, 16), tv_distance(&wide, &r, 16));
    eprintln!(
        "self {self_tv:.4}, cross {cross:.3}, fit {t_fit:.3}, wide {t_wide:.3}, floor {:.4}",
        ra.tv_error()
    );
    assert!(
        t_fit < 0.15 && t_wide > 2.0 * t_fit,
        "fit {t_fit}, wide {t_wide}"
    );
}

/// Beckmann Λ for α, written here in f64 (Walter 2007 eq. 27 / Heitz 2014 eq. 72).
fn beckmann_lambda(alpha: f64, w: Vec3) -> f64 {
    let cos = w.z as f64;
    let tan = (1.0 - cos * cos).max(0.0).sqrt() / cos;
    if tan == 0.0 {
        return 0.0;
    }
    let a = 1.0 / (alpha * tan);
    0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * std::f64::consts::PI.sqrt())
}

#[test]
fn naive_brdf_on_a_flat_map_is_the_beckmann_brdf() {
    let map = NormalMap::from_slopes(2, 2, vec![Vec2::ZERO; 4]).unwrap();
    let sigma = 0.2f64;
    let alpha = 2f64.sqrt() * sigma;
    for (to, po, ti, pi) in [
        (30.0, 0.0, 30.0, 180.0),
        (60.0, 20.0, 10.0, 150.0),
        (75.0, 90.0, 70.0, 270.0),
        (0.0, 0.0, 20.0, 45.0),
    ] {
        let (wo, wi) = (support::dir(to, po), support::dir(ti, pi));
        let f = naive_brdf(&map, Vec2::new(0.3, 0.3), wo, wi, sigma as f32) as f64;
        let h = (wo + wi).normalize();
        let (ch, cht) = (
            h.z as f64,
            (1.0 - (h.z as f64).powi(2)) / (h.z as f64).powi(2),
        );
        let d =
            (-cht / (alpha * alpha)).exp() / (std::f64::consts::PI * alpha * alpha * ch.powi(4));
        let g = 1.0 / (1.0 + beckmann_lambda(alpha, wo)) / (1.0 + beckmann_lambda(alpha, wi));
        let want = d * g / (4.0 * wo.z as f64 * wi.z as f64);
        // f32 lobe arithmetic on values up to ~10: 1e-4 relative.
        assert!(
            (f / want - 1.0).abs() < 1e-4,
            "({to}, {po}, {ti}, {pi}): {f} vs {want}"
        );
    }
    assert_eq!(
        naive_brdf(&map, Vec2::ZERO, Vec3::Z, Vec3::new(0.0, 0.0, -1.0), 0.01),
        0.0
    );
    assert_eq!(naive_brdf(&map, Vec2::ZERO, Vec3::Z, Vec3::Z, 0.0), 0.0);
    assert_eq!(naive_brdf(&map, Vec2::ZERO, Vec3::NAN, Vec3::Z, 0.01), 0.0);
    assert!(naive_brdf(&map, Vec2::NAN, Vec3::Z, Vec3::Z, 0.01).is_finite());
}

#[test]
fn naive_brdf_peaks_at_the_mirror_direction_of_the_local_normal() {
    // A map tilted toward +x: the specular peak for normal view is the mirror about the normal.
    let s0 = Vec2::new(-0.3, 0.1);
    let map = NormalMap::from_slopes(4, 4, vec![s0; 16]).unwrap();
    let n0 = brdf::frame::slope_to_normal(s0);
    let wo = support::dir(20.0, 200.0);
    let mirror = 2.0 * wo.dot(n0) * n0 - wo;
    let mut best = (0.0f32, Vec3::Z);
    for t in 0..90 {
        for p in 0..360 {
            let wi = support::dir(t as f64, p as f64);
            let f = naive_brdf(&map, Vec2::new(0.5, 0.5), wo, wi, 0.01);
            if f > best.0 {
                best = (f, wi);
            }
        }
    }
    // Grid of 1°: the argmax is within ~1° of the mirror direction (the lobe has width 2σε ≈ 1.1°).
    assert!(
        best.1.dot(mirror) > (2.0f32).to_radians().cos(),
        "{} vs {mirror}",
        best.1
    );
}
