//! Curves of the analytic core: NDF slices, Smith G1 and Fresnel reflectance.
//!
//! Every chart is a plain function of one angle, drawn straight from the library's evaluators, so a
//! reader can check the shapes against the formulas in docs/ndf.md and docs/fresnel.md.

use super::{Artifact, Chart, Res, Scale, Series, line_chart};
use brdf::fresnel;
use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, beckmann_alpha_from_shininess};
use brdf::{Vec3, frame};
use std::path::Path;

fn degrees(n: usize, max: f64) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| max * i as f64 / n as f64)
}

fn dir(theta_deg: f64) -> Vec3 {
    let t = theta_deg.to_radians();
    Vec3::new(t.sin() as f32, 0.0, t.cos() as f32)
}

/// A named curve of `f(ω(θ))` for θ from 0° to 90° in degrees, ω(θ) in the plane y = 0.
fn slice(label: impl Into<String>, f: impl Fn(Vec3) -> f32) -> Series {
    Series::new(
        label,
        degrees(180, 90.0).map(|t| (t, f(dir(t)) as f64)).collect(),
    )
}

/// Writes the NDF, G1 and Fresnel charts into `out`.
pub fn run(out: &Path, _quick: bool) -> Res<Vec<Artifact>> {
    let mut artifacts = Vec::new();
    let alphas = [0.1f32, 0.25, 0.5, 1.0];

    // D(m) cos θm along θm: the density of micronormal directions per unit solid angle.
    let mut series = Vec::new();
    for &a in &alphas {
        let b = Beckmann::isotropic(a)?;
        let g = Ggx::isotropic(a)?;
        series.push(slice(format!("Beckmann α={a}"), |w| b.d(w)));
        series.push(slice(format!("GGX α={a}"), |w| g.d(w)));
    }
    let path = out.join("ndf_d.png");
    let mut chart = Chart::new("D(m) along θm", "θm (degrees)", "D (1/sr), log scale");
    chart.y_scale = Scale::Log;
    chart.y_range = Some((1e-4, 40.0));
    line_chart(&path, &chart, &series)?;
    artifacts.push(Artifact::new(
        path,
        "Beckmann and GGX D(θm) for α = 0.1 … 1: GGX's long tails against Beckmann's Gaussian fall-off.",
    ));

    // Blinn-Phong against its Beckmann equivalent.
    let mut series = Vec::new();
    for gamma in [2.0f32, 10.0, 50.0, 200.0] {
        let bp = BlinnPhong::new(gamma)?;
        let b = Beckmann::isotropic(beckmann_alpha_from_shininess(gamma))?;
        series.push(slice(format!("Blinn-Phong γ={gamma}"), |w| bp.d(w)));
        series.push(Series::new(
            format!("Beckmann α(γ={gamma})"),
            degrees(180, 90.0)
                .map(|t| (t, b.d(dir(t)) as f64))
                .collect(),
        ));
    }
    let path = out.join("ndf_blinn_phong.png");
    let mut chart = Chart::new(
        "Blinn-Phong and its Beckmann equivalent α = √(2/(γ+2))",
        "θm (degrees)",
        "D (1/sr), log scale",
    );
    chart.y_scale = Scale::Log;
    chart.y_range = Some((1e-4, 40.0));
    line_chart(&path, &chart, &series)?;
    artifacts.push(Artifact::new(
        path,
        "Blinn-Phong D next to the Beckmann lobe of equivalent α: nearly equal for large γ.",
    ));

    // Smith G1 against the view angle, with m = n.
    let mut series = Vec::new();
    for &a in &alphas {
        let b = Beckmann::isotropic(a)?;
        let g = Ggx::isotropic(a)?;
        series.push(slice(format!("Beckmann α={a}"), |w| {
            b.g1(w, frame::NORMAL)
        }));
        series.push(slice(format!("GGX α={a}"), |w| g.g1(w, frame::NORMAL)));
    }
    let path = out.join("ndf_g1.png");
    line_chart(
        &path,
        &Chart::new("Smith G1(ω, n) against θ", "θ (degrees)", "G1"),
        &series,
    )?;
    artifacts.push(Artifact::new(
        path,
        "Smith masking G1 = 1/(1+Λ): 1 at normal incidence, falling to 0 at grazing, faster for rough surfaces.",
    ));

    // Fresnel reflectance against the angle of incidence.
    let mut series = Vec::new();
    for eta in [1.33f32, 1.5, 2.4] {
        series.push(slice(format!("dielectric η={eta}"), |w| {
            fresnel::dielectric(w.z, eta)
        }));
        let f0 = Vec3::splat(fresnel::f0_from_ior(eta));
        series.push(Series::new(
            format!("Schlick f0(η={eta})"),
            degrees(180, 90.0)
                .map(|t| {
                    let c = t.to_radians().cos() as f32;
                    (t, fresnel::schlick(f0, c).x as f64)
                })
                .collect(),
        ));
    }
    series.push(slice("glass from inside (η=1.5)", |w| {
        fresnel::dielectric(-w.z, 1.5)
    }));
    let gold = fresnel::ConductorFresnel::GOLD;
    for (k, name) in [(0usize, "R"), (1, "G"), (2, "B")] {
        series.push(slice(format!("gold {name}"), |w| {
            fresnel::conductor(w.z, gold.eta, gold.k)[k]
        }));
    }
    let path = out.join("fresnel.png");
    line_chart(
        &path,
        &Chart::new("Fresnel reflectance", "θi (degrees)", "F"),
        &series,
    )?;
    artifacts.push(Artifact::new(
        path,
        "Fresnel: exact dielectric (with total internal reflection from inside), Schlick, and gold per channel.",
    ));
    Ok(artifacts)
}
