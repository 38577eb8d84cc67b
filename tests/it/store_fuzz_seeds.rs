//! Writes the seed files of the store fuzz targets (fuzz/seeds/store_*/, small valid files of each
//! kind); ignored: `cargo test --test it store_fuzz_seeds:: -- --ignored`.

use crate::support;

use brdf::Vec2;
use brdf::glint::binmap::BinMapParams;
use brdf::glint::mixture::{LobeStorage, MixtureParams, SeedKernel};
use brdf::glint::position_normal::PositionNormalParams;
use brdf::glint::procedural::{ProceduralGlints, ProceduralParams};
use brdf::glint::{BeckmannMixture, BinMap, PositionNormalMap};
use support::format::reseal;
use support::store::{
    bin_map_as_version_5, map, mixture_as_version_3, mixture_as_version_4, mixture_as_version_5,
    position_normal_as_version_3, position_normal_as_version_5, saved,
};

/// Writes the seed files of the store fuzz targets (small valid files of each kind):
/// `cargo test --test it store_fuzz_seeds:: -- --ignored`.
#[test]
#[ignore]
fn write_fuzz_seeds() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds");
    let write = |dir: &str, name: &str, bytes: Vec<u8>| {
        let d = root.join(dir);
        std::fs::create_dir_all(&d).unwrap();
        // The store targets read a flag byte, a footprint and a probe before the file: prefix zeros.
        let mut input = vec![0u8; 1 + 6 * 4 + 9 * 4];
        input.extend(bytes);
        std::fs::write(d.join(name), input).unwrap();
    };
    for n in [1usize, 3] {
        let m = map(n);
        write("store_normal_map", &format!("map{n}"), saved(|w| m.save(w)));
        let params = MixtureParams {
            samples: 4,
            ..MixtureParams::default()
        };
        let mx = BeckmannMixture::build(&m, params).unwrap();
        write(
            "store_mixture",
            &format!("mixture{n}"),
            saved(|w| mx.save(w)),
        );
        // As format version 5 wrote it (no filtered mixture: built on load).
        write(
            "store_mixture",
            &format!("mixture{n}_v5"),
            mixture_as_version_5(&saved(|w| mx.save(w))),
        );
        // A Gaussian-seeded one, also as format versions 4 (no seed kernel) and 3 (with patch
        // options, read and ignored) wrote it.
        let gauss = MixtureParams {
            seed: SeedKernel::Gaussian,
            ..params
        };
        let file = saved(|w| BeckmannMixture::build(&m, gauss).unwrap().save(w));
        write(
            "store_mixture",
            &format!("mixture{n}_v4"),
            mixture_as_version_4(&file),
        );
        write(
            "store_mixture",
            &format!("mixture{n}_v3"),
            mixture_as_version_3(&file, 1, 256.0),
        );
        write("store_mixture", &format!("mixture{n}_gaussian"), file);
        // Compact storage (model kind 5): 1², 3² (no level-2 node: the single block's own frame)
        // and 8² (frames from the quadtree's level 2).
        for k in [n, n + 5] {
            let cm = BeckmannMixture::build(
                &map(k),
                MixtureParams {
                    storage: LobeStorage::Compact,
                    ..params
                },
            )
            .unwrap();
            write(
                "store_mixture",
                &format!("compact{k}"),
                saved(|w| cm.save(w)),
            );
        }
        let pn = PositionNormalMap::build(&m, PositionNormalParams::default()).unwrap();
        let file = saved(|w| pn.save(w));
        let v3 = position_normal_as_version_3(&file, 128.0);
        let v5 = position_normal_as_version_5(&file);
        write("store_position_normal", &format!("pn{n}"), file);
        write("store_position_normal", &format!("pn{n}_v3"), v3);
        write("store_position_normal", &format!("pn{n}_v5"), v5);
        for (bins, leaf) in [(3, 1), (7, 2)] {
            let params = BinMapParams {
                bins_per_axis: bins,
                leaf_size: leaf,
                ..BinMapParams::default()
            };
            let bm = BinMap::build(&map(n + 3), params).unwrap();
            let file = saved(|w| bm.save(w));
            let errors = bm.moment_masking_errors().len();
            write(
                "store_binmap",
                &format!("bm{n}_{bins}_v5"),
                bin_map_as_version_5(&file, errors),
            );
            write("store_binmap", &format!("bm{n}_{bins}"), file);
        }
    }
    // Procedural glints (model kinds 6 and 7): the defaults, a surface with no two parameters alike
    // (anisotropic, non-square, under one facet per texel) and the GGX limit (kind 7), also under
    // format version 2 (the payload is the same in every version).
    let procedural = [
        (
            "procedural",
            ProceduralParams {
                seed: 1,
                ..ProceduralParams::default()
            },
        ),
        (
            "procedural_aniso",
            ProceduralParams {
                alpha: Vec2::new(0.1, 0.5),
                facet_alpha: 0.01,
                density: 0.4,
                resolution: [48, 20],
                seed: u64::MAX,
                ..ProceduralParams::default()
            },
        ),
        (
            "procedural_ggx",
            ProceduralParams {
                seed: 2,
                limit: brdf::glint::procedural::ProceduralLimit::Ggx,
                ..ProceduralParams::default()
            },
        ),
    ];
    for (name, params) in procedural {
        let file = saved(|w| ProceduralGlints::new(params).unwrap().save(w));
        let mut v2 = file.clone();
        v2[8..12].copy_from_slice(&2u32.to_le_bytes());
        write("store_procedural", &format!("{name}_v2"), reseal(v2));
        write("store_procedural", name, file);
    }
}
