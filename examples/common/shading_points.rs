//! A renderer's shading point, shared by the `shading_cost` example and `benches/shading_point.rs`
//! (which includes this file by path): random inputs, and the calls a path tracer makes at a hit.

use brdf::glint::{Footprint, GlintScratch};
use brdf::material::Material;
use brdf::{Bxdf, Vec2, Vec3};
use rand::{Rng, RngExt, SeedableRng};
use std::hint::black_box;

/// One shading point's inputs: the footprint centre, the view, two light directions, and the
/// numbers of one `sample`.
pub struct Point {
    pub uv: Vec2,
    pub wo: Vec3,
    pub wi: [Vec3; 2],
    pub uc: f32,
    pub u: Vec2,
}

/// A direction of the upper hemisphere with cos θ uniform in [`min_z`, 1].
fn upper(rng: &mut impl Rng, min_z: f32) -> Vec3 {
    let z = min_z + (1.0 - min_z) * rng.random::<f32>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.random::<f32>();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `n` shading points at uniform uv, views with cos θo ≥ 0.2 and light directions with cos θi ≥
/// 0.05, from `seed`.
pub fn points(n: usize, seed: u64) -> Vec<Point> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..n)
        .map(|_| Point {
            uv: Vec2::new(rng.random(), rng.random()),
            wo: upper(&mut rng, 0.2),
            wi: [upper(&mut rng, 0.05), upper(&mut rng, 0.05)],
            uc: rng.random(),
            u: Vec2::new(rng.random(), rng.random()),
        })
        .collect()
}

/// The shading point `p` of `material` on a footprint of `area` texels of a `size`² map:
/// `Material::bsdf` (the patch), `eval_pdf` toward both light directions and one `sample`.
pub fn shade(material: &Material, p: &Point, area: f32, size: usize, scratch: &GlintScratch) {
    let fp = Footprint::isotropic_texels(p.uv, area, size, size);
    let b = material.bsdf(&fp, p.wo, scratch);
    black_box(b.eval_pdf(p.wo, p.wi[0]));
    black_box(b.eval_pdf(p.wo, p.wi[1]));
    black_box(b.sample(p.wo, p.uc, p.u));
}
