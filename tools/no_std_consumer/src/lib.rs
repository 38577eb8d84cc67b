//! A `#![no_std]` renderer-side use of `brdf`'s analytic core: a GGX microfacet BRDF with a
//! conductor Fresnel term, an energy-compensated anisotropic Beckmann BRDF, a dielectric Fresnel
//! term and a Lambertian sample, behind C functions so that every call is compiled and linked.
//!
//! There is no std and no allocator here: the build itself is the test (Cargo.toml says how it
//! fails when either enters the dependency graph).

#![no_std]

use brdf::bxdf::{Bxdf, EnergyCompensated, Lambert, MicrofacetBrdf};
use brdf::fresnel::{ConductorFresnel, DielectricFresnel, Fresnel};
use brdf::ndf::{Beckmann, Ggx};
use brdf::{Vec2, Vec3};

/// An RGB value for C.
#[repr(C)]
pub struct Rgb {
    pub r: f32,
    pub g: f32,
    pub b: f32,
}

impl From<Vec3> for Rgb {
    fn from(v: Vec3) -> Self {
        Rgb {
            r: v.x,
            g: v.y,
            b: v.z,
        }
    }
}

fn direction(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z).normalize_or_zero()
}

/// f(wo, wi) · cos θi of anisotropic GGX (αx = 0.3, αy = 0.1) over gold, in the local frame.
#[unsafe(no_mangle)]
pub extern "C" fn brdf_ggx_gold(
    wo_x: f32,
    wo_y: f32,
    wo_z: f32,
    wi_x: f32,
    wi_y: f32,
    wi_z: f32,
) -> Rgb {
    let Ok(ggx) = Ggx::new(0.3, 0.1) else {
        return Vec3::ZERO.into();
    };
    let brdf = MicrofacetBrdf::new(ggx, ConductorFresnel::GOLD);
    let wi = direction(wi_x, wi_y, wi_z);
    (brdf.eval(direction(wo_x, wo_y, wo_z), wi) * wi.z.max(0.0)).into()
}

/// The sample weight f cos θi / pdf of the energy-compensated anisotropic Beckmann BRDF over copper
/// (the anisotropic albedo slice, inline without std), for the random numbers (uc, u1, u2).
#[unsafe(no_mangle)]
pub extern "C" fn brdf_compensated_beckmann_weight(
    wo_x: f32,
    wo_z: f32,
    uc: f32,
    u1: f32,
    u2: f32,
) -> Rgb {
    let Ok(beckmann) = Beckmann::new(0.5, 0.2) else {
        return Vec3::ZERO.into();
    };
    let Ok(brdf) = EnergyCompensated::new(MicrofacetBrdf::new(beckmann, ConductorFresnel::COPPER))
    else {
        return Vec3::ZERO.into();
    };
    let wo = direction(wo_x, 0.0, wo_z);
    brdf.sample(wo, uc, Vec2::new(u1, u2))
        .map_or(Vec3::ZERO, |s| s.weight())
        .into()
}

/// The unpolarised Fresnel reflectance of glass (η = 1.5) at cos θ.
#[unsafe(no_mangle)]
pub extern "C" fn brdf_glass_fresnel(cos_theta: f32) -> f32 {
    DielectricFresnel::new(1.5).map_or(0.0, |f| f.eval(cos_theta).x)
}

/// A cosine-weighted direction of a Lambertian BRDF (ρ = 0.5) for the random numbers (u1, u2): its z.
#[unsafe(no_mangle)]
pub extern "C" fn brdf_lambert_sample_z(u1: f32, u2: f32) -> f32 {
    let Ok(lambert) = Lambert::new(Vec3::splat(0.5)) else {
        return 0.0;
    };
    lambert
        .sample(Vec3::Z, 0.5, Vec2::new(u1, u2))
        .map_or(0.0, |s| s.wi.z)
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
