//! `serde` support (feature `serde`): every built model and the normal map round-trip through a binary
//! serde format (postcard) bit-identically, and a damaged byte string is an error, not a panic.
//!
//! `cargo test --features serde --test serde` (CI runs it).

#[path = "it/support/mod.rs"]
mod support;

use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::MixtureParams;
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, NormalMap, PositionNormalMap,
};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};

fn map() -> NormalMap {
    brdf::glint::bumpy(24, 24, 0.3, 3.0, 5).unwrap()
}

/// d, lambda and pdf_visible of two patches agree bit for bit over a few directions.
fn same(a: &impl Ndf, b: &impl Ndf) {
    for th in [0.0f64, 40.0, 80.0] {
        for ph in [0.0f64, 130.0] {
            let w = support::dir(th, ph);
            let m = (w + Vec3::Z).normalize();
            assert_eq!(a.d(m).to_bits(), b.d(m).to_bits(), "d at {th} {ph}");
            assert_eq!(a.lambda(w).to_bits(), b.lambda(w).to_bits(), "lambda");
            assert_eq!(
                a.pdf_visible(w, m).to_bits(),
                b.pdf_visible(w, m).to_bits(),
                "pdf_visible"
            );
        }
    }
}

fn footprint() -> Footprint {
    Footprint::from_differentials(
        Vec2::new(0.4, 0.55),
        Vec2::new(3.0 / 24.0, 0.0),
        Vec2::new(0.0, 3.0 / 24.0),
    )
}

fn round_trip<T: serde::Serialize + serde::de::DeserializeOwned>(t: &T) -> T {
    let bytes = postcard::to_allocvec(t).unwrap();
    postcard::from_bytes(&bytes).unwrap()
}

#[test]
fn every_model_round_trips_through_postcard() {
    let m = map();
    let back = round_trip(&m);
    assert_eq!(back.slopes(), m.slopes());

    let mix = BeckmannMixture::build(
        &m,
        MixtureParams {
            samples: 16,
            ..MixtureParams::default()
        },
    )
    .unwrap();
    same(
        &mix.patch(&footprint()),
        &round_trip(&mix).patch(&footprint()),
    );

    let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
    same(
        &pn.patch(&footprint()),
        &round_trip(&pn).patch(&footprint()),
    );

    let bm = BinMap::build(&m, BinMapParams::default()).unwrap();
    same(
        &bm.patch(&footprint()),
        &round_trip(&bm).patch(&footprint()),
    );

    // Anisotropic, non-square and an uneven density, so that no field can be swapped unseen.
    let pg = procedural();
    let back = round_trip(&pg);
    assert_eq!(back.params(), pg.params());
    same(&pg.patch(&footprint()), &back.patch(&footprint()));
}

/// A procedural glint surface with no two parameters alike.
fn procedural() -> ProceduralGlints {
    ProceduralGlints::new(ProceduralParams {
        alpha: Vec2::new(0.25, 0.4),
        facet_alpha: 0.03,
        density: 2.5,
        resolution: [24, 40],
        seed: u64::MAX - 3,
        limit: brdf::glint::procedural::ProceduralLimit::Ggx,
    })
    .unwrap()
}

/// A model serialised on its own deserialises as a `GlintModel` (the same bytes: its file), and
/// back.
#[test]
fn a_model_deserialises_as_a_glint_model() {
    let pg = procedural();
    let bytes = postcard::to_allocvec(&pg).unwrap();
    let model: GlintModel = postcard::from_bytes(&bytes).unwrap();
    assert!(
        matches!(&model, GlintModel::Procedural(p) if p.params() == pg.params()),
        "{}",
        model.name()
    );
    assert_eq!(postcard::to_allocvec(&model).unwrap(), bytes);
    let again: ProceduralGlints = postcard::from_bytes(&bytes).unwrap();
    assert_eq!(again.params(), pg.params());
}

#[test]
fn damaged_bytes_are_errors() {
    let bytes = postcard::to_allocvec(&map()).unwrap();
    // Flip a byte inside the slopes: the checksum catches it.
    let mut bad = bytes.clone();
    let k = bad.len() / 2;
    bad[k] ^= 0x40;
    let e = postcard::from_bytes::<NormalMap>(&bad);
    assert!(e.is_err());
    // Cut short: the byte string itself is incomplete.
    assert!(postcard::from_bytes::<NormalMap>(&bytes[..bytes.len() - 9]).is_err());
    // A normal map's bytes are not a bin map.
    assert!(postcard::from_bytes::<BinMap>(&bytes).is_err());

    // A procedural surface's 40-byte payload: a flipped parameter byte is caught by the checksum,
    // and its bytes are no other model's.
    let bytes = postcard::to_allocvec(&procedural()).unwrap();
    // Postcard writes a one-byte length, then the 72-byte file; byte 26 of the file is in alpha.x.
    assert_eq!(bytes.len(), 1 + 72);
    let mut bad = bytes.clone();
    bad[1 + 26] ^= 0x01;
    let e = postcard::from_bytes::<ProceduralGlints>(&bad).unwrap_err();
    assert!(matches!(e, postcard::Error::SerdeDeCustom), "{e}");
    // Postcard keeps no custom message: the loader's error on the same file bytes, which is what
    // the custom error carried.
    let e = ProceduralGlints::load(&mut &bad[1..]).unwrap_err();
    assert!(matches!(e, brdf::Error::ChecksumMismatch { .. }), "{e}");
    assert!(postcard::from_bytes::<ProceduralGlints>(&bytes[..bytes.len() - 1]).is_err());
    assert!(postcard::from_bytes::<BinMap>(&bytes).is_err());
    assert!(postcard::from_bytes::<NormalMap>(&bytes).is_err());
}

#[test]
fn every_registered_model_round_trips_through_serde() {
    let map = brdf::glint::scratched(32, 32, Default::default(), 11).unwrap();
    for ex in support::registry::examples(&map) {
        let bytes = postcard::to_allocvec(&ex.model).unwrap();
        let back: GlintModel = postcard::from_bytes(&bytes).unwrap();
        assert_eq!(
            support::registry::fingerprint(&back, &ex.options),
            support::registry::fingerprint(&ex.model, &ex.options),
            "{}",
            ex.label
        );
    }
}
