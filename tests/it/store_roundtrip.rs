//! Saving and loading built glint maps and normal maps (docs/format.md): exact round trips, every
//! query of a loaded model bit-identical to the built one, for the normal map, the full and compact
//! mixtures (and a full mixture in format versions 2 and 3), the position-normal map (and in version
//! 3), the bin map and procedural glints (under every version the loader reads). Files hold no
//! per-query options: the options that versions 2 and 3 stored are read and ignored.

use crate::support;

use brdf::glint::binmap::{BinLookup, BinMapParams};
use brdf::glint::mixture::{LobeStorage, MaskingMode, MixtureParams, PatchOptions, SeedKernel};
use brdf::glint::position_normal::{self, PositionNormalParams};
use brdf::glint::procedural::{self, ProceduralGlints, ProceduralParams};
use brdf::glint::{
    BeckmannMixture, BinMap, Footprint, GlintModel, GlintNdf, NormalMap, PositionNormalMap,
};
use brdf::ndf::Ndf;
use brdf::{Vec2, Vec3};
use support::format::reseal;
use support::store::{
    as_version_2, bin_map_as_version_5, dirs, map, mixture_as_version_3, mixture_as_version_4,
    mixture_as_version_5, position_normal_as_version_3, position_normal_as_version_5, saved,
};

/// Asserts that two patches answer every query with the same bits.
fn assert_same_patch(a: &impl Ndf, b: &impl Ndf, what: &str) {
    let ds = dirs();
    let us = [
        Vec2::new(0.1, 0.2),
        Vec2::new(0.5, 0.5),
        Vec2::new(0.93, 0.07),
    ];
    for &w in &ds {
        assert_eq!(a.d(w).to_bits(), b.d(w).to_bits(), "{what}: d({w})");
        assert_eq!(
            a.lambda(w).to_bits(),
            b.lambda(w).to_bits(),
            "{what}: lambda({w})"
        );
        assert_eq!(
            a.projected_area(w).to_bits(),
            b.projected_area(w).to_bits(),
            "{what}: A({w})"
        );
        for &u in &us {
            let (ma, mb) = (a.sample_visible(w, u), b.sample_visible(w, u));
            assert_eq!(
                ma.to_array().map(f32::to_bits),
                mb.to_array().map(f32::to_bits)
            );
            assert_eq!(a.sample_normal(u), b.sample_normal(u), "{what}");
            for &m in &[ma, Vec3::Z] {
                assert_eq!(
                    a.pdf_visible(w, m).to_bits(),
                    b.pdf_visible(w, m).to_bits(),
                    "{what}: pdf_visible({w}, {m})"
                );
            }
        }
    }
}

/// Footprints from sub-texel to most of the map, isotropic and anisotropic, at several centres.
fn footprints(n: usize) -> Vec<Footprint> {
    let mut f = Vec::new();
    for (k, area) in [0.5f32, 4.0, 64.0, 900.0].into_iter().enumerate() {
        let c = Vec2::new(3.3 + 7.1 * k as f32, 11.7 + 2.9 * k as f32);
        f.push(Footprint::isotropic_texels(c, area, n, n));
        f.push(Footprint::anisotropic_texels(c, area, 4.0, 0.6, n, n));
    }
    f
}

#[test]
fn normal_map_round_trip_is_exact() {
    let m = map(24);
    let file = saved(|w| m.save(w));
    // 24-byte header + width, height, count (8 each) + 8 bytes per texel + checksum.
    assert_eq!(file.len(), 24 + 24 + 8 * 24 * 24 + 8);
    let back = NormalMap::load(&mut file.as_slice()).unwrap();
    assert_eq!((back.width(), back.height()), (24, 24));
    let bits = |m: &NormalMap| -> Vec<[u32; 2]> {
        m.slopes()
            .iter()
            .map(|s| s.to_array().map(f32::to_bits))
            .collect()
    };
    assert_eq!(bits(&m), bits(&back));
    let p = Vec2::new(0.37, 0.81);
    assert_eq!(m.normal_at(p), back.normal_at(p));
    assert_eq!(
        m.moment_pyramid().filtered(p * 24.0, 3.0),
        back.moment_pyramid().filtered(p * 24.0, 3.0)
    );
}

#[test]
fn mixture_round_trip_is_exact() {
    for seed in [SeedKernel::Cell, SeedKernel::Gaussian] {
        mixture_round_trip(seed);
    }
}

/// The round trip of a mixture seeded by `seed`; for the Gaussian seed (which older formats hold),
/// also as format versions 4, 3 and 2 wrote it.
fn mixture_round_trip(seed: SeedKernel) {
    let n = 32;
    let m = map(n);
    let params = MixtureParams {
        samples: 32,
        seed,
        ..MixtureParams::default()
    };
    let built = BeckmannMixture::build(&m, params).unwrap();
    let file = saved(|w| built.save(w));
    assert_eq!(&file[8..12], &6u32.to_le_bytes());
    let loaded = BeckmannMixture::load(&mut file.as_slice()).unwrap();
    assert_eq!(loaded.params(), built.params());
    assert_eq!(loaded.memory(), built.memory());
    // The measured errors are read, not measured again (the 32² grid measures 64 to 1024 lobes).
    assert!(!built.filtered_mixture_errors().is_empty());
    assert_eq!(
        loaded.filtered_mixture_errors(),
        built.filtered_mixture_errors()
    );
    for (masking, lod) in [
        (MaskingMode::Exact, f32::INFINITY),
        (MaskingMode::Approximate, 64.0),
    ] {
        let options = PatchOptions {
            masking,
            lod_lobes: lod,
            ..PatchOptions::default()
        };
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch_with(f, &options, None),
                &loaded.patch_with(f, &options, None),
                &format!("{masking:?} fp {k}"),
            );
        }
    }
    // Saving the loaded model gives the same bytes.
    assert_eq!(saved(|w| loaded.save(w)), file);
    if seed != SeedKernel::Gaussian {
        return;
    }
    // An older file of the same mixture loads to it (same parameters, bit-identical patches) and,
    // for versions 3 to 5, re-saves as the version-6 file.
    let same_as_built = |old_file: Vec<u8>, version: u32| {
        let old = BeckmannMixture::load(&mut old_file.as_slice()).unwrap();
        assert_eq!(old.params(), built.params());
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch(f),
                &old.patch(f),
                &format!("fp {k}, version {version}"),
            );
        }
        old
    };
    // Version 5: no filtered-mixture chain or errors (built and measured on load, as the build
    // does: the same values).
    let old = same_as_built(mixture_as_version_5(&file), 5);
    assert_eq!(
        old.filtered_mixture_errors(),
        built.filtered_mixture_errors()
    );
    assert_eq!(saved(|w| old.save(w)), file);
    // Version 4: no seed kernel (Gaussian).
    let old = same_as_built(mixture_as_version_4(&file), 4);
    assert_eq!(saved(|w| old.save(w)), file);
    // Version 3, with non-default options stored (approximate masking, a cost cap of one lobe):
    // the stored options are ignored (its default patch is the built mixture's default patch).
    let old = same_as_built(mixture_as_version_3(&file, 1, 1.0), 3);
    assert_eq!(saved(|w| old.save(w)), file);
    // Version 2 (no merge errors: recomputed on load) answers the same, so the stored errors are the
    // ones the build computes.
    same_as_built(as_version_2(&file), 2);
}

/// Compact storage (`LobeStorage::Compact`, model kind 5): the same exactness, on a grid whose
/// levels halve down to 1 × 1 (32²), one that stops halving (24² → 3²) and one with no level-2
/// quadtree node on its coarsest levels (6²).
#[test]
fn compact_mixture_round_trip_is_exact() {
    for (n, masking) in [
        (32, MaskingMode::Exact),
        (24, MaskingMode::Approximate),
        (6, MaskingMode::Exact),
    ] {
        let m = map(n);
        // Gaussian-seeded, so that the version-3 form below holds it.
        let params = MixtureParams {
            storage: LobeStorage::Compact,
            seed: SeedKernel::Gaussian,
            ..MixtureParams::default()
        };
        let options = PatchOptions {
            masking,
            lod_tolerance: 0.5,
            ..PatchOptions::default()
        };
        let built = BeckmannMixture::build(&m, params).unwrap();
        let file = saved(|w| built.save(w));
        assert_eq!(&file[12..16], &5u32.to_le_bytes());
        let loaded = BeckmannMixture::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params().storage, LobeStorage::Compact);
        assert_eq!(loaded.memory(), built.memory());
        assert_eq!(loaded.level_count(), built.level_count());
        let mut levels = std::collections::BTreeSet::new();
        for (k, f) in footprints(n).iter().enumerate() {
            // Options are not stored in files: both with the same per-query options.
            let (a, b) = (
                built.patch_with(f, &options, None),
                loaded.patch_with(f, &options, None),
            );
            levels.insert(a.level());
            assert_eq!(a.level(), b.level());
            assert_same_patch(&a, &b, &format!("compact {n}² {masking:?} fp {k}"));
        }
        if n >= 24 {
            assert!(
                levels.len() >= 2,
                "{n}²: the footprints use levels {levels:?}"
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
        // As format version 3 wrote it, with non-default options stored (approximate masking, a
        // cost cap of 0): the stored options are ignored.
        let v3 = mixture_as_version_3(&file, 1, 0.0);
        let old = BeckmannMixture::load(&mut v3.as_slice()).unwrap();
        for (k, f) in footprints(n).iter().enumerate() {
            let what = format!("compact {n}² fp {k}, version 3");
            assert_same_patch(&built.patch(f), &old.patch(f), &what);
        }
        assert_eq!(saved(|w| old.save(w)), file);
    }
}

#[test]
fn position_normal_round_trip_is_exact() {
    let n = 24;
    let m = map(n);
    for rate in [1, 2] {
        let params = PositionNormalParams {
            sampling_rate: rate,
            ..PositionNormalParams::default()
        };
        let built = PositionNormalMap::build(&m, params).unwrap();
        let file = saved(|w| built.save(w));
        let loaded = PositionNormalMap::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.memory(), built.memory());
        assert!(!built.filtered_mixture_errors().is_empty());
        assert_eq!(
            loaded.filtered_mixture_errors(),
            built.filtered_mixture_errors()
        );
        // As format version 5 wrote it (no chain, no errors): built and measured on load.
        let v5 =
            PositionNormalMap::load(&mut position_normal_as_version_5(&file).as_slice()).unwrap();
        assert_eq!(
            v5.filtered_mixture_errors(),
            built.filtered_mixture_errors()
        );
        assert_eq!(saved(|w| v5.save(w)), file);
        let capped = position_normal::PatchOptions {
            max_query_texels: 8.0,
            cut_nodes: 0,
            ..position_normal::PatchOptions::default()
        };
        for (k, f) in footprints(n).iter().enumerate() {
            assert_same_patch(
                &built.patch(f),
                &loaded.patch(f),
                &format!("rate {rate} fp {k}"),
            );
            assert_same_patch(
                &built.patch_with(f, &capped, None),
                &loaded.patch_with(f, &capped, None),
                &format!("rate {rate} fp {k}, cap 8"),
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
        // As format version 3 wrote it, with a cap of 1 texel stored: the stored cap is ignored.
        let old = PositionNormalMap::load(&mut position_normal_as_version_3(&file, 1.0).as_slice())
            .unwrap();
        assert_eq!(old.params(), built.params());
        for (k, f) in footprints(n).iter().enumerate() {
            let what = format!("rate {rate} fp {k}, version 3");
            assert_same_patch(&built.patch(f), &old.patch(f), &what);
        }
        assert_eq!(saved(|w| old.save(w)), file);
    }
}

#[test]
fn bin_map_round_trip_is_exact() {
    let n = 48;
    let m = map(n);
    for (bins, leaf, lookup) in [(31, 4, BinLookup::Dense), (15, 1, BinLookup::Hash)] {
        let params = BinMapParams {
            bins_per_axis: bins,
            leaf_size: leaf,
            lookup,
            ..BinMapParams::default()
        };
        let built = BinMap::build(&m, params).unwrap();
        assert!(!built.forest().is_empty(), "the test needs trees");
        let file = saved(|w| built.save(w));
        let loaded = BinMap::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.memory(), built.memory());
        let errors = built.moment_masking_errors();
        assert!(
            !errors.is_empty(),
            "the 48² map measures 256 to 2,304 texels"
        );
        assert_eq!(loaded.moment_masking_errors(), errors);
        // As format version 5 wrote it (no errors): measured on load, as the build does.
        let v5 = BinMap::load(&mut bin_map_as_version_5(&file, errors.len()).as_slice()).unwrap();
        assert_eq!(v5.moment_masking_errors(), errors);
        assert_eq!(saved(|w| v5.save(w)), file);
        assert_eq!(loaded.inverse_bin_map(), built.inverse_bin_map());
        assert_eq!(loaded.forest(), built.forest());
        // 𝓑 is derived on load, not stored: the same bin for every sub-texel.
        let (gw, gh) = built.grid_size();
        for k in 0..gw * gh {
            assert_eq!(
                loaded.bin_of_texel(k),
                built.bin_of_texel(k),
                "sub-texel {k}"
            );
        }
        for (k, f) in footprints(n).iter().enumerate() {
            let what = format!("{lookup:?} fp {k}");
            assert_same_patch(&built.patch(f), &loaded.patch(f), &what);
            assert_same_patch(
                &built.patch_with(
                    f,
                    &brdf::glint::binmap::PatchOptions {
                        smoothing_alpha: 0.1,
                        ..Default::default()
                    },
                    None,
                ),
                &loaded.patch_with(
                    f,
                    &brdf::glint::binmap::PatchOptions {
                        smoothing_alpha: 0.1,
                        ..Default::default()
                    },
                    None,
                ),
                &what,
            );
        }
        assert_eq!(saved(|w| loaded.save(w)), file);
    }
}

/// Procedural glints (model kind 6): the file is the parameters, 40 bytes of payload at the
/// offsets of docs/format.md; the loaded surface answers every query with the same bits, with the
/// default tolerance and another; the payload loads the same whatever version from 2 to 6 the
/// header states, and re-saves as the version-6 file; `GlintModel` writes and reads the same bytes.
#[test]
fn procedural_round_trip_is_exact() {
    let surfaces = [
        ProceduralParams {
            seed: 9,
            ..ProceduralParams::default()
        },
        // Anisotropic, non-square, a density below one facet per texel, the largest seed: no two
        // fields alike, so none can be swapped unseen.
        ProceduralParams {
            alpha: Vec2::new(0.12, 0.45),
            facet_alpha: 0.01,
            density: 0.37,
            resolution: [300, 77],
            seed: u64::MAX,
            ..ProceduralParams::default()
        },
    ];
    let loose = procedural::PatchOptions { tolerance: 0.3 };
    for params in surfaces {
        let built = ProceduralGlints::new(params).unwrap();
        let file = saved(|w| built.save(w));
        // Header (magic, version 6, kind 6, payload 40), alpha.x, alpha.y, facet_alpha, density
        // (f32), resolution[0], resolution[1], seed (u64), checksum.
        assert_eq!(file.len(), 24 + 40 + 8);
        let u32_at = |at: usize| u32::from_le_bytes(file[at..at + 4].try_into().unwrap());
        let u64_at = |at: usize| u64::from_le_bytes(file[at..at + 8].try_into().unwrap());
        assert_eq!(&file[..8], b"BRDFGLNT");
        assert_eq!((u32_at(8), u32_at(12), u64_at(16)), (6, 6, 40));
        let p = &params;
        assert_eq!(
            [u32_at(24), u32_at(28), u32_at(32), u32_at(36)],
            [p.alpha.x, p.alpha.y, p.facet_alpha, p.density].map(f32::to_bits)
        );
        assert_eq!(
            [u64_at(40), u64_at(48), u64_at(56)],
            [p.resolution[0] as u64, p.resolution[1] as u64, p.seed]
        );
        assert_eq!(reseal(file.clone()), file, "the documented checksum");

        let loaded = ProceduralGlints::load(&mut file.as_slice()).unwrap();
        assert_eq!(loaded.params(), built.params());
        assert_eq!(loaded.level_count(), built.level_count());
        assert_eq!(loaded.map_size(), built.map_size());
        let (w, h) = built.map_size();
        for (k, area) in [0.5f32, 4.0, 64.0, 900.0, 30_000.0, 300_000.0]
            .into_iter()
            .enumerate()
        {
            let c = Vec2::new(0.13 + 0.31 * k as f32, 0.77 - 0.23 * k as f32);
            for f in [
                Footprint::isotropic_texels(c, area, w, h),
                Footprint::anisotropic_texels(c, area, 4.0, 0.6, w, h),
            ] {
                let what = format!("{params:?} fp {k}");
                assert_same_patch(&built.patch(&f), &loaded.patch(&f), &what);
                assert_same_patch(
                    &built.patch_with(&f, &loose, None),
                    &loaded.patch_with(&f, &loose, None),
                    &format!("{what}, tolerance 0.3"),
                );
            }
        }
        assert_eq!(saved(|w| loaded.save(w)), file);

        // The payload never changed: a header stating any version the loader reads gives the
        // same surface, re-saved as the current file.
        for version in 2u32..=5 {
            let mut old = file.clone();
            old[8..12].copy_from_slice(&version.to_le_bytes());
            let old = ProceduralGlints::load(&mut reseal(old).as_slice()).unwrap();
            assert_eq!(old.params(), built.params(), "version {version}");
            assert_eq!(saved(|w| old.save(w)), file, "version {version}");
        }

        // Through the registry: the same bytes, the same surface.
        let model = GlintModel::from(built.clone());
        assert_eq!(saved(|w| model.save(w)), file);
        match GlintModel::load(&mut file.as_slice()).unwrap() {
            GlintModel::Procedural(p) => assert_eq!(p.params(), built.params()),
            other => panic!("a procedural file loaded as a {}", other.name()),
        }
    }
}
