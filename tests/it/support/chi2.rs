//! Chi-square goodness-of-fit test of a direction sampler against its density.
//!
//! Constants (the reasons are in the comments next to them in [`Chi2::default`]):
//! - `samples` = 10⁶ draws per test, from a seeded PCG so that every run is identical;
//! - cells: an equal-area grid in (z = cos θ, φ) over z ∈ [z_min, 1]; everything else (directions with
//!   z < z_min, below the horizon, and draws for which the sampler returned `None`) is one more
//!   "overflow" cell whose expected count is N·(1 − Σ expected inside);
//! - the expected count of a cell is N ∫_cell pdf dω, by an adaptive Gauss–Legendre rule in (z, φ):
//!   the cell's 6×6 rule is accepted if a 4×4 rule agrees with it within 5 % of the count's standard
//!   deviation √max(E, 1) (or if the cell has no draw and expects less than 0.01); otherwise the cell
//!   is split into quarters, each compared with its parent's share the same way (the quarters' sum
//!   replacing the parent's estimate), down to 10 levels. A fixed 6×6 rule per cell mis-integrated
//!   lobes that fill a sliver of a few cells at grazing views (anisotropic GGX α = 0.3/0.1 at
//!   θo = 89°: χ² = 3977 on 3085 dof; Beckmann χ² = 193,335 on 248); a 48×48 rule, a 96×96 rule and
//!   this adaptive rule all give the same counts there, and the samplers pass;
//! - cells whose expected count is below 5 are pooled (smallest first) until the pool reaches 5, the usual
//!   validity condition of the χ² approximation;
//! - the null hypothesis "samples follow pdf" is rejected at significance 0.01, Šidák-corrected over the
//!   `family` of tests run together: α' = 1 − (1 − 0.01)^(1/family);
//! - draws in cells whose expected count is (numerically) zero, below 10⁻⁹ N, fail the test when
//!   so many draws there are a Poisson event of probability below 10⁻⁶ given those cells' summed
//!   expectation (one draw where the density is 0; a single draw in the far tail of a narrow lobe,
//!   where a few cells expect 10⁻⁴-10⁻³ draws in all, is not a failure).
//!
//! On failure the observed and expected tables are written to `target/chi2/<name>.txt`.

use super::quadrature::gauss_legendre;
use glam::{Vec2, Vec3};
use rand::RngExt;
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::PI;

/// Configuration of one chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2 {
    /// Name used in messages and in the dump file.
    pub name: String,
    /// Number of draws.
    pub samples: usize,
    /// Cells along z = cos θ.
    pub res_z: usize,
    /// Cells along φ.
    pub res_phi: usize,
    /// Lower end of the gridded z range; `None` chooses it from a pilot run (the 0.05 % quantile of z
    /// over 10⁵ draws with another seed, 2·10⁴ in the default run, floored at 0), so that peaked lobes get cells of their own size.
    pub z_min: Option<f64>,
    /// Number of tests in the family (Šidák correction).
    pub family: usize,
    /// Significance level of the whole family.
    pub significance: f64,
    /// RNG seed.
    pub seed: u64,
    /// Gauss–Legendre points per axis of the expected-count quadrature (per cell, and per quarter
    /// of a cell that the adaptive rule splits).
    pub quadrature: usize,
    /// Largest number of times the adaptive rule splits a cell (0: the fixed rule per cell).
    pub max_depth: usize,
}

impl Default for Chi2 {
    fn default() -> Self {
        Chi2 {
            name: "chi2".into(),
            // 10⁶ draws at full power: enough to see a 1 % density error in a 10 %-mass region, ~1 s
            // per test. The default run draws 10⁵ (~30 per cell): a ~3 % error in such a region.
            samples: super::depth(100_000, 1_000_000),
            // 40 × 80 cells: ~310 draws per cell on average; fine enough for the lobes we test.
            res_z: 40,
            res_phi: 80,
            z_min: None,
            family: 1,
            significance: 0.01,
            seed: 7,
            quadrature: 6,
            // 10 levels: quarters down to 1/1024 of a cell side, far below any lobe we test.
            max_depth: 10,
        }
    }
}

impl Chi2 {
    /// A test named `name` in a family of `family` tests, other settings default.
    pub fn new(name: impl Into<String>, family: usize) -> Self {
        Chi2 {
            name: name.into(),
            family,
            ..Chi2::default()
        }
    }

    /// Runs the test. `sample(uc, u)` draws one direction (or `None`), `pdf(ω)` is its density per unit
    /// solid angle. Returns the p-value, or a report of the failure.
    pub fn run(
        &self,
        mut sample: impl FnMut(f32, Vec2) -> Option<Vec3>,
        pdf: impl Fn(Vec3) -> f64,
    ) -> Result<f64, String> {
        let z_min = self.z_min.unwrap_or_else(|| self.pilot_z_min(&mut sample));
        let (nz, np) = (self.res_z, self.res_phi);
        let dz = (1.0 - z_min) / nz as f64;
        let dphi = 2.0 * PI / np as f64;
        let cell_of = |w: Vec3| -> Option<usize> {
            let z = w.z as f64;
            if z.is_nan() || z < z_min || !w.is_finite() {
                return None;
            }
            let iz = (((z - z_min) / dz) as usize).min(nz - 1);
            let mut phi = (w.y as f64).atan2(w.x as f64);
            if phi < 0.0 {
                phi += 2.0 * PI;
            }
            let ip = ((phi / dphi) as usize).min(np - 1);
            Some(iz * np + ip)
        };

        let mut observed = vec![0.0f64; nz * np + 1];
        let overflow = nz * np;
        let mut rng = super::rng(self.seed);
        for _ in 0..self.samples {
            let uc: f32 = rng.random();
            let u = Vec2::new(rng.random(), rng.random());
            let cell = sample(uc, u).and_then(cell_of).unwrap_or(overflow);
            observed[cell] += 1.0;
        }

        let gl = gauss_legendre(self.quadrature);
        let gl_check = gauss_legendre(self.quadrature.saturating_sub(2).max(1));
        let n = self.samples as f64;
        let mut expected = vec![0.0f64; nz * np + 1];
        for iz in 0..nz {
            for ip in 0..np {
                let (z0, p0) = (z_min + iz as f64 * dz, ip as f64 * dphi);
                let cell = Rect {
                    z0,
                    z1: z0 + dz,
                    p0,
                    p1: p0 + dphi,
                };
                let whole = cell.integrate(&gl, &pdf);
                let quiet = observed[iz * np + ip] == 0.0 && n * whole < 1e-2;
                let agrees =
                    || (cell.integrate(&gl_check, &pdf) - whole).abs() <= tolerance(whole, n);
                expected[iz * np + ip] = if self.max_depth == 0 || quiet || agrees() {
                    n * whole
                } else {
                    n * cell.adaptive(&gl, &pdf, whole, n, self.max_depth)
                };
            }
        }
        let inside: f64 = expected[..overflow].iter().sum();
        expected[overflow] = (n - inside).max(0.0);

        let result = self.evaluate(&observed, &expected);
        if result.is_err() {
            self.dump(&observed, &expected, z_min);
        }
        result
    }

    fn pilot_z_min(&self, sample: &mut impl FnMut(f32, Vec2) -> Option<Vec3>) -> f64 {
        let mut rng = super::rng(self.seed ^ 0x9e37_79b9_7f4a_7c15);
        let mut zs: Vec<f64> = (0..super::depth(20_000, 100_000))
            .filter_map(|_| {
                let uc: f32 = rng.random();
                sample(uc, Vec2::new(rng.random(), rng.random()))
            })
            .map(|w| w.z as f64)
            .filter(|z| z.is_finite())
            .collect();
        if zs.is_empty() {
            return 0.0;
        }
        zs.sort_by(f64::total_cmp);
        let q = zs[(zs.len() as f64 * 0.0005) as usize];
        // Leave a margin of one more cell below the quantile; never below the horizon.
        (q - (1.0 - q) / self.res_z as f64).clamp(0.0, 1.0 - 1e-6)
    }

    fn evaluate(&self, observed: &[f64], expected: &[f64]) -> Result<f64, String> {
        // Draws where the density is (numerically) zero: the sampler and the pdf disagree on the
        // support. The cells expecting less than 10⁻⁹ N draws together expect E_low; their draws are
        // a failure when a Poisson(E_low) count that large has probability below 10⁻⁶ (one draw
        // where E_low ~ 10⁻⁹, or many), not when the tails of narrow lobes put 10⁻⁴-10⁻³ expected
        // draws in a few cells and one of them is drawn (probability ~E_low).
        let (mut low_o, mut low_e, mut worst) = (0.0f64, 0.0f64, None);
        for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
            if e < 1e-9 * self.samples as f64 && i != observed.len() - 1 {
                low_o += o;
                low_e += e;
                if o > 0.0 {
                    worst = Some((i, o, e));
                }
            }
        }
        if let Some((i, o, e)) = worst {
            // P(Poisson(λ) ≥ k) = 1 − Σ_{j<k} e^−λ λ^j / j!.
            let k = low_o as usize;
            let (mut term, mut below) = ((-low_e).exp(), 0.0f64);
            for j in 0..k {
                below += term;
                term *= low_e / (j + 1) as f64;
            }
            let p = (1.0 - below).max(term);
            if p < 1e-6 {
                return Err(format!(
                    "{}: {o} draws in cell {i} whose expected count is {e:e} ({low_o} draws in \
                     cells expecting {low_e:e} in all)",
                    self.name
                ));
            }
        }
        // Pool cells with expected < 5, smallest first.
        let mut order: Vec<usize> = (0..expected.len()).collect();
        order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
        let (mut chi2, mut dof, mut pool_o, mut pool_e) = (0.0, 0usize, 0.0, 0.0);
        for &i in &order {
            if expected[i] < 5.0 || pool_e > 0.0 && pool_e < 5.0 {
                pool_o += observed[i];
                pool_e += expected[i];
                if pool_e >= 5.0 {
                    chi2 += (pool_o - pool_e).powi(2) / pool_e;
                    dof += 1;
                    pool_o = 0.0;
                    pool_e = 0.0;
                }
            } else {
                chi2 += (observed[i] - expected[i]).powi(2) / expected[i];
                dof += 1;
            }
        }
        if pool_e > 0.0 {
            chi2 += (pool_o - pool_e).powi(2) / pool_e.max(1e-300);
            dof += 1;
        }
        if dof < 2 {
            return Err(format!("{}: fewer than 2 cells after pooling", self.name));
        }
        let dist = ChiSquared::new((dof - 1) as f64).map_err(|e| e.to_string())?;
        let p = 1.0 - dist.cdf(chi2);
        let alpha = 1.0 - (1.0 - self.significance).powf(1.0 / self.family as f64);
        if p < alpha {
            Err(format!(
                "{}: chi2 = {chi2:.1} with {} dof, p = {p:.3e} < {alpha:.3e} (Šidák over {})",
                self.name,
                dof - 1,
                self.family
            ))
        } else {
            Ok(p)
        }
    }

    fn dump(&self, observed: &[f64], expected: &[f64], z_min: f64) {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/chi2");
        let _ = std::fs::create_dir_all(&dir);
        let mut s = format!(
            "# {}: z in [{z_min}, 1], {} x {} cells (rows: z, columns: phi), last line: overflow\n",
            self.name, self.res_z, self.res_phi
        );
        for (title, table) in [("observed", observed), ("expected", expected)] {
            s.push_str(&format!("## {title}\n"));
            for row in table[..self.res_z * self.res_phi].chunks(self.res_phi) {
                let line: Vec<String> = row.iter().map(|v| format!("{v:.1}")).collect();
                s.push_str(&line.join(" "));
                s.push('\n');
            }
            s.push_str(&format!("overflow {:.1}\n", table[table.len() - 1]));
        }
        let file: String = self
            .name
            .chars()
            .map(|c| if c.is_alphanumeric() { c } else { '_' })
            .collect();
        let _ = std::fs::write(dir.join(format!("{file}.txt")), s);
    }
}

/// The adaptive rule's tolerance on a cell's probability `p` at `n` draws: 5 % of the standard
/// deviation of its count, √max(n p, 1) / n (module docs).
fn tolerance(p: f64, n: f64) -> f64 {
    0.05 * (n * p).max(1.0).sqrt() / n
}

/// A cell [z0, z1] × [p0, p1] of the (z = cos θ, φ) grid, or a part of one.
#[derive(Clone, Copy)]
struct Rect {
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
}

impl Rect {
    /// ∫ pdf dω over the rectangle (dω = dz dφ) by the tensor Gauss–Legendre rule `gl`.
    fn integrate(&self, gl: &[(f64, f64)], pdf: &impl Fn(Vec3) -> f64) -> f64 {
        let (dz, dp) = (self.z1 - self.z0, self.p1 - self.p0);
        let mut s = 0.0;
        for &(xz, wz) in gl {
            let z = self.z0 + 0.5 * dz * (xz + 1.0);
            let st = (1.0 - z * z).max(0.0).sqrt();
            for &(xp, wp) in gl {
                let phi = self.p0 + 0.5 * dp * (xp + 1.0);
                let w = Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, z as f32);
                s += wz * wp * pdf(w);
            }
        }
        s * 0.25 * dz * dp
    }

    fn quarters(&self) -> [Rect; 4] {
        let (zm, pm) = (0.5 * (self.z0 + self.z1), 0.5 * (self.p0 + self.p1));
        [
            Rect {
                z1: zm,
                p1: pm,
                ..*self
            },
            Rect {
                z0: zm,
                p1: pm,
                ..*self
            },
            Rect {
                z1: zm,
                p0: pm,
                ..*self
            },
            Rect {
                z0: zm,
                p0: pm,
                ..*self
            },
        ]
    }

    /// The adaptive integral given this rectangle's own estimate `whole` (see the module docs): the
    /// quarters' sum if it agrees with `whole` within 5 % of the count's standard deviation at `n`
    /// draws, else each quarter refined the same way, down to `depth` more levels.
    fn adaptive(
        &self,
        gl: &[(f64, f64)],
        pdf: &impl Fn(Vec3) -> f64,
        whole: f64,
        n: f64,
        depth: usize,
    ) -> f64 {
        if depth == 0 {
            return whole;
        }
        let parts = self.quarters().map(|q| (q, q.integrate(gl, pdf)));
        let sum: f64 = parts.iter().map(|(_, v)| v).sum();
        if (sum - whole).abs() <= tolerance(sum, n) {
            return sum;
        }
        parts
            .iter()
            .map(|(q, v)| q.adaptive(gl, pdf, *v, n, depth - 1))
            .sum()
    }
}
