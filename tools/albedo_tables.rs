//! Writes `src/bxdf/albedo_tables.rs`: the directional albedo E(μ, α) and its average E_avg(α) of
//! the crate's single-scattering microfacet BRDF (F = 1, height-correlated masking, GGX and
//! Beckmann) on the grid of `brdf::bxdf::AlbedoTable`, for energy compensation.
//!
//! E(μ, α) = ∫ f cos θi dωi is integrated through the crate's own public sampler: with visible-normal
//! sampling, E = ∫_{[0,1)²} w(u) du where w(u) = `MicrofacetBrdf::sample(wo, ·, u).weight()`
//! (= G2/G1(wo) for wi above the horizon, 0 otherwise), by the midpoint rule on an M × M grid of u
//! (deterministic: regeneration is bit-for-bit reproducible). The weight is smooth in u except along
//! the horizon cut, so the rule converges like 1/M there; the tool prints |E(M) − E(M/2)| (θo ≤ 85°)
//! as its error estimate and the largest bilinear-interpolation error at cell centres (θo ≤ 85°).
//! E_avg is the exact average of each row's interpolant (`brdf::bxdf::average_of_row`).
//!
//! It also writes `src/bxdf/albedo_anisotropic_{ggx,beckmann}.bin`: E(μ, φ, αx, αy) on the grid of
//! `brdf::bxdf::AnisotropicAlbedoTable`, as little-endian u16 (E · 65535). There the sample weight is
//! integrated by the midpoint rule on M × M points of the unit square after the change of variables
//! u = q(v) = v³ (10 − 15 v + 6 v²) per axis (weight q'(v) = 30 v² (1 − v)²), which flattens the
//! sampler's mappings at the square's edges: at M = 128 the rule agrees with M = 1024 to ~3·10⁻⁵
//! (the plain rule at M = 512 is off by up to 10⁻³ at grazing views). The tool prints
//! max |E(M) − E(M/2)| (θo ≤ 85°, every fourth φ node), an upper estimate of E(M)'s error. E(φ; αx, αy) = E(π/2 − φ; αy, αx) (mirror symmetry), so only
//! αx ≥ αy is integrated.
//!
//! Run: `cargo run --release --example albedo_tables [-- iso [OUT.rs [M]] | aniso [DIR [M]]]`
//! (no argument: both; defaults: src/bxdf/albedo_tables.rs, M = 512; src/bxdf, M = 96).

use brdf::bxdf::{
    ALBEDO_GRID, ALBEDO_MU_EPSILON, ANISO_ALPHA_NODES, ANISO_ENTRIES, ANISO_MU_NODES,
    ANISO_PHI_NODES, AlbedoTable, AnisotropicAlbedoTable, Bxdf, MicrofacetBrdf, average_of_row,
    encode_albedo,
};
use brdf::fresnel::NoFresnel;
use brdf::ndf::{Beckmann, Ggx, Ndf};
use brdf::{Vec2, Vec3};
use rayon::prelude::*;
use std::fmt::Write as _;

/// E(μ) = mean of the sample weight over the midpoint grid of u (M × M), in f64.
fn albedo<D: Ndf>(ndf: D, mu: f32, m: usize) -> f64 {
    let brdf = MicrofacetBrdf::new(ndf, NoFresnel);
    let mu = mu.max(ALBEDO_MU_EPSILON);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let mut sum = 0.0f64;
    for a in 0..m {
        for b in 0..m {
            let u = Vec2::new(
                ((a as f64 + 0.5) / m as f64) as f32,
                ((b as f64 + 0.5) / m as f64) as f32,
            );
            if let Some(s) = brdf.sample(wo, 0.5, u) {
                sum += s.weight().x as f64;
            }
        }
    }
    sum / (m * m) as f64
}

/// The NDF family by name at α.
fn e_of(family: &str, mu: f32, alpha: f32, m: usize) -> f64 {
    match family {
        "ggx" => albedo(Ggx::isotropic(alpha).expect("α of the grid"), mu, m),
        _ => albedo(Beckmann::isotropic(alpha).expect("α of the grid"), mu, m),
    }
}

type Rows = Vec<[f32; ALBEDO_GRID]>;

/// The table of one family: rows over α, columns over μ; and the largest |E(M) − E(M/2)|.
fn table(family: &str, m: usize) -> (Rows, f64) {
    let rows: Vec<([f32; ALBEDO_GRID], f64)> = (0..ALBEDO_GRID)
        .into_par_iter()
        .map(|j| {
            let alpha = AlbedoTable::alpha_node(j);
            let mut row = [0.0f32; ALBEDO_GRID];
            let mut err = 0.0f64;
            for (i, e) in row.iter_mut().enumerate() {
                let mu = AlbedoTable::mu_node(i);
                let fine = e_of(family, mu, alpha, m);
                if mu >= 85f32.to_radians().cos() {
                    let coarse = e_of(family, mu, alpha, m / 2);
                    err = err.max((fine - coarse).abs());
                }
                *e = fine as f32;
            }
            (row, err)
        })
        .collect();
    let err = rows.iter().map(|r| r.1).fold(0.0, f64::max);
    (rows.into_iter().map(|r| r.0).collect(), err)
}

/// The largest |E − bilinear(E)| at the centres of the cells with μ ≥ cos 85°.
fn interpolation_error(family: &str, rows: &Rows, m: usize) -> (f64, f32, f32) {
    let t0 = brdf::bxdf::ALBEDO_ALPHA_MIN.sqrt();
    let n1 = (ALBEDO_GRID - 1) as f32;
    (0..ALBEDO_GRID - 1)
        .into_par_iter()
        .map(|j| {
            let t = t0 + (1.0 - t0) * (j as f32 + 0.5) / n1;
            let alpha = t * t;
            let mut worst = (0.0f64, 0.0f32, 0.0f32);
            for i in 0..ALBEDO_GRID - 1 {
                let mu = (i as f32 + 0.5) / n1;
                if mu < 85f32.to_radians().cos() {
                    continue;
                }
                let interp = 0.25
                    * (rows[j][i] + rows[j][i + 1] + rows[j + 1][i] + rows[j + 1][i + 1]) as f64;
                let d = (e_of(family, mu, alpha, m) - interp).abs();
                if d > worst.0 {
                    worst = (d, mu, alpha);
                }
            }
            worst
        })
        .reduce(|| (0.0, 0.0, 0.0), |a, b| if a.0 >= b.0 { a } else { b })
}

fn write_family(out: &mut String, upper: &str, rows: &Rows) {
    let n = ALBEDO_GRID;
    writeln!(out, "#[rustfmt::skip]").unwrap();
    writeln!(out, "pub(super) const {upper}_E: [[f32; {n}]; {n}] = [").unwrap();
    for row in rows {
        let cells: Vec<String> = row.iter().map(|e| format!("{e:?}")).collect();
        writeln!(out, "    [{}],", cells.join(", ")).unwrap();
    }
    writeln!(out, "];").unwrap();
    let avg: Vec<String> = rows
        .iter()
        .map(|r| format!("{:?}", average_of_row(r) as f32))
        .collect();
    writeln!(out, "#[rustfmt::skip]").unwrap();
    writeln!(
        out,
        "pub(super) const {upper}_E_AVG: [f32; {n}] = [{}];",
        avg.join(", ")
    )
    .unwrap();
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args.first().map(String::as_str).unwrap_or("both");
    let arg = |k: usize| args.get(k).filter(|_| mode != "both").cloned();
    let m = |k: usize, default: usize| -> usize {
        arg(k).map_or(default, |s| s.parse().expect("M: an integer"))
    };
    if mode == "iso" || mode == "both" {
        let path = arg(1).unwrap_or_else(|| "src/bxdf/albedo_tables.rs".into());
        write_isotropic(&path, m(2, 512));
    }
    if mode == "aniso" || mode == "both" {
        let dir = arg(1).unwrap_or_else(|| "src/bxdf".into());
        write_anisotropic(&dir, m(2, 96));
    }
}

/// The smoothstep change of variables of the anisotropic rule: (q(v), q'(v)).
fn smooth_map(v: f64) -> (f64, f64) {
    let v2 = v * v;
    (
        v2 * v * (10.0 - 15.0 * v + 6.0 * v2),
        30.0 * v2 * (1.0 - v) * (1.0 - v),
    )
}

/// E(wo) = ∫ weight(u) du by the mapped midpoint rule on M × M points, in f64.
fn albedo_mapped<D: Ndf>(ndf: D, wo: Vec3, m: usize) -> f64 {
    let brdf = MicrofacetBrdf::new(ndf, NoFresnel);
    let mut sum = 0.0f64;
    for a in 0..m {
        let (ua, ja) = smooth_map((a as f64 + 0.5) / m as f64);
        for b in 0..m {
            let (ub, jb) = smooth_map((b as f64 + 0.5) / m as f64);
            if let Some(s) = brdf.sample(wo, 0.5, Vec2::new(ua as f32, ub as f32)) {
                sum += s.weight().x as f64 * ja * jb;
            }
        }
    }
    sum / (m * m) as f64
}

/// E at (μ, φ) for the family at (αx, αy), by the mapped rule.
fn e_aniso(family: &str, ax: f32, ay: f32, mu: f32, phi: f32, m: usize) -> f64 {
    let mu = mu.max(ALBEDO_MU_EPSILON);
    let st = (1.0 - mu * mu).max(0.0).sqrt();
    let wo = Vec3::new(st * phi.cos(), st * phi.sin(), mu);
    match family {
        "ggx" => albedo_mapped(Ggx::new(ax, ay).expect("α of the grid"), wo, m),
        _ => albedo_mapped(Beckmann::new(ax, ay).expect("α of the grid"), wo, m),
    }
}

/// Writes `DIR/albedo_anisotropic_{family}.bin` for both families.
fn write_anisotropic(dir: &str, m: usize) {
    type T = AnisotropicAlbedoTable;
    let grazing = 85f32.to_radians().cos();
    for family in ["ggx", "beckmann"] {
        let start = std::time::Instant::now();
        // (a, b, k) rows with αx_a ≥ αy_b; the others by E(φ; αx, αy) = E(π/2 − φ; αy, αx).
        let rows: Vec<(usize, usize, usize)> = (0..ANISO_ALPHA_NODES)
            .flat_map(|a| (0..=a).flat_map(move |b| (0..ANISO_PHI_NODES).map(move |k| (a, b, k))))
            .collect();
        let done: Vec<([f64; ANISO_MU_NODES], f64)> = rows
            .par_iter()
            .map(|&(a, b, k)| {
                let (ax, ay, phi) = (T::alpha_node(a), T::alpha_node(b), T::phi_node(k));
                let mut row = [0.0f64; ANISO_MU_NODES];
                let mut err = 0.0f64;
                for (i, e) in row.iter_mut().enumerate() {
                    let mu = T::mu_node(i);
                    *e = e_aniso(family, ax, ay, mu, phi, m);
                    if mu >= grazing && k % 4 == 0 {
                        let coarse = e_aniso(family, ax, ay, mu, phi, m / 2);
                        err = err.max((*e - coarse).abs());
                    }
                }
                (row, err)
            })
            .collect();
        let mut table = vec![0u16; ANISO_ENTRIES];
        let mut err = 0.0f64;
        for (&(a, b, k), (row, e)) in rows.iter().zip(&done) {
            err = err.max(*e);
            for (i, &v) in row.iter().enumerate() {
                table[T::index(a, b, k, i)] = encode_albedo(v);
                if a != b {
                    table[T::index(b, a, ANISO_PHI_NODES - 1 - k, i)] = encode_albedo(v);
                }
            }
        }
        let bytes: Vec<u8> = table.iter().flat_map(|v| v.to_le_bytes()).collect();
        let path = format!("{dir}/albedo_anisotropic_{family}.bin");
        std::fs::write(&path, &bytes).expect("write the table file");
        eprintln!(
            "{family}: anisotropic, {} entries ({} bytes), quadrature |E(M) − E(M/2)| ≤ {err:.2e} \
             (θo ≤ 85°, M = {m}), {:.0} s; wrote {path}",
            table.len(),
            bytes.len(),
            start.elapsed().as_secs_f64()
        );
    }
}

/// Writes the isotropic table file.
fn write_isotropic(path: &str, m: usize) {
    let mut out = String::new();
    writeln!(
        out,
        "//! GENERATED by `cargo run --release --example albedo_tables` (tools/albedo_tables.rs); do not edit.\n\
         //! Directional albedo E[α_j][μ_i] and average E_avg[α_j] of the single-scattering microfacet BRDF\n\
         //! (F = 1, height-correlated masking) on the grid of `albedo.rs`, integrated with the midpoint rule on\n\
         //! {m} × {m} points of the visible-normal sampler's unit square."
    )
    .unwrap();
    for (family, upper) in [("ggx", "GGX"), ("beckmann", "BECKMANN")] {
        let (rows, err) = table(family, m);
        let (ierr, mu, alpha) = interpolation_error(family, &rows, m);
        eprintln!(
            "{family}: quadrature |E(M) − E(M/2)| ≤ {err:.2e} (θo ≤ 85°); bilinear error ≤ {ierr:.2e} \
             (at μ = {mu:.3}, α = {alpha:.4}, θo ≤ 85°)"
        );
        writeln!(out).unwrap();
        writeln!(
            out,
            "/// {upper}: E[α_j][μ_i] (quadrature |E(M) − E(M/2)| ≤ {err:.1e} at θo ≤ 85°)."
        )
        .unwrap();
        write_family(&mut out, upper, &rows);
    }
    std::fs::write(path, out).expect("write the table file");
    eprintln!("wrote {path}");
}
