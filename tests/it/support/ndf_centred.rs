//! Shared by the centred-NDF tests (tests/it/ndf_centred_*.rs): the NDFs under test (Beckmann and GGX,
//! isotropic and 4:1 anisotropic, and Blinn-Phong at the Beckmann-equivalent exponents), the α
//! values and the view angles.

use brdf::ndf::{Beckmann, BlinnPhong, Ggx, Ndf, shininess_from_beckmann_alpha};

/// The α values of the brief.
pub const ALPHAS: [f32; 4] = [0.05, 0.125, 0.5, 1.0];
/// Incidence angles (degrees) for the visible-normal samplers.
pub const THETAS: [f64; 5] = [0.0, 30.0, 60.0, 80.0, 89.0];
/// Azimuth of wo for the anisotropic cases (a non-symmetric configuration).
pub const PHI_ANISO: f64 = 35.0;

/// A named NDF under test, boxed so that the three types share one list. `(kx, ky)` is the slope
/// scale of the lobe (α_x, α_y; for Blinn-Phong its Beckmann-equivalent α), used by [`Chart`].
pub struct Case {
    pub name: String,
    pub ndf: Box<dyn Ndf + Sync + Send>,
    pub aniso: bool,
    pub kx: f64,
    pub ky: f64,
}

/// Beckmann and GGX at each α, isotropic and with α_y = α/4.
pub fn microfacet_cases() -> Vec<Case> {
    let mut v = Vec::new();
    for &a in &ALPHAS {
        v.push(Case {
            name: format!("beckmann a={a}"),
            ndf: Box::new(Beckmann::isotropic(a).unwrap()),
            aniso: false,
            kx: a as f64,
            ky: a as f64,
        });
        v.push(Case {
            name: format!("beckmann ax={a} ay={}", a / 4.0),
            ndf: Box::new(Beckmann::new(a, a / 4.0).unwrap()),
            aniso: true,
            kx: a as f64,
            ky: a as f64 / 4.0,
        });
        v.push(Case {
            name: format!("ggx a={a}"),
            ndf: Box::new(Ggx::isotropic(a).unwrap()),
            aniso: false,
            kx: a as f64,
            ky: a as f64,
        });
        v.push(Case {
            name: format!("ggx ax={a} ay={}", a / 4.0),
            ndf: Box::new(Ggx::new(a, a / 4.0).unwrap()),
            aniso: true,
            kx: a as f64,
            ky: a as f64 / 4.0,
        });
    }
    v
}

/// Blinn-Phong with the exponent equivalent to each α (γ = 2/α² − 2: 798, 126, 6, 0).
pub fn blinn_phong_cases() -> Vec<Case> {
    ALPHAS
        .iter()
        .map(|&a| {
            let g = shininess_from_beckmann_alpha(a);
            Case {
                name: format!("blinn-phong gamma={g}"),
                ndf: Box::new(BlinnPhong::new(g).unwrap()),
                aniso: false,
                kx: a as f64,
                ky: a as f64,
            }
        })
        .collect()
}

/// Every case: the microfacet NDFs, then Blinn-Phong.
pub fn all_cases() -> Vec<Case> {
    let mut v = microfacet_cases();
    v.extend(blinn_phong_cases());
    v
}
