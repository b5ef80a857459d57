//! VDB volumes (written by the real OpenVDB library: `scenes/vdb/make_fixtures.py`) render on the
//! CPU bit for bit as the same grids read from other files, sparse or dense.

mod common;

use common::render;

use std::path::{Path, PathBuf};

use volpt::{Backend, GridLookup, Quiet, RenderSettings, Scene};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The committed fixtures, or those `scripts/vdb-fixtures.sh` has just written with OpenVDB
/// (`VOLPT_VDB_FIXTURES`, set by CI).
fn fixture(name: &str) -> PathBuf {
    match std::env::var_os("VOLPT_VDB_FIXTURES") {
        Some(dir) => PathBuf::from(dir).join(name),
        None => scenes().join("vdb/fixtures").join(name),
    }
}

fn small() -> RenderSettings {
    RenderSettings {
        resolution: Some((16, 16)),
        spp: Some(4),
        seed: 11,
        ..RenderSettings::default()
    }
}

fn with(settings: RenderSettings, params: &[(&str, &str)]) -> RenderSettings {
    RenderSettings {
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        ..settings
    }
}

/// `scenes/vdb/bucky.toml` is `scenes/bucky/scene.toml` with its grid from `bucky.vdb` (float
/// leaves) or `bucky-half.vdb` (half leaves: Bucky's integer values are exact in half), blosc
/// compressed, or their zip (`bucky-zip.vdb`) and uncompressed (`bucky-half-none.vdb`) copies: the same
/// values, box and transfer function, so the same image bit for bit, through the sparse layout
/// and the any-layout medium where the raw grid takes the dense one.
#[test]
fn bucky_from_vdb_renders_bit_for_bit_as_bucky_raw() {
    let raw = Scene::load(scenes().join("bucky/scene.toml"), &small()).unwrap();
    let expected = render(&raw);
    assert!(expected.sums.iter().any(|s| s[0] > 0.0));
    for vdb in [
        "bucky.vdb",
        "bucky-half.vdb",
        "bucky-zip.vdb",
        "bucky-half-none.vdb",
    ] {
        let file = fixture(vdb).display().to_string();
        let scene = Scene::load(
            scenes().join("vdb/bucky.toml"),
            &with(small(), &[("vdb", &file)]),
        )
        .unwrap();
        let info = scene.info();
        let memory = info.get("memory").unwrap();
        assert!(memory.contains("sparse"), "{vdb}: {memory}");
        assert_ne!(
            info.get("variant"),
            raw.info().get("variant"),
            "the sparse grid takes the any-layout medium"
        );
        assert_eq!(render(&scene).sums, expected.sums, "{vdb}");
    }
}

/// A cloud whose corner bricks are empty (pruned by OpenVDB), with a vec3 albedo grid: kept sparse
/// and read dense, the same image bit for bit.
#[test]
fn a_sparse_cloud_renders_as_its_dense_copy() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = fixture("cloud-rgb.vdb");
    let load = |sparse: &str| {
        let path = dir.path().join(format!("{sparse}.toml"));
        std::fs::write(
            &path,
            format!(
                "[volume]\nfile = {:?}\nsparse = {sparse:?}\nscale = 8\n[albedo]\ngrid = \"albedo\"\n\
                 [boundary]\nbsdf = \"null\"\n[camera]\nfov = 1.2\n",
                cloud.display()
            ),
        )
        .unwrap();
        Scene::load(&path, &small()).unwrap()
    };
    let (sparse, dense) = (load("always"), load("never"));
    let memory = sparse.info().get("memory").unwrap().to_owned();
    assert!(
        memory.contains("density grid") && memory.contains("sparse ("),
        "{memory}"
    );
    assert!(
        !memory.contains("27 stored bricks of 27"),
        "{memory}: the corner bricks must be empty"
    );
    assert!(
        dense.info().get("memory").unwrap().contains("dense"),
        "{:?}",
        dense.info()
    );
    let image = render(&sparse);
    assert!(image.sums.iter().any(|s| s[0] > 0.0));
    assert_eq!(image.sums, render(&dense).sums);
}

/// `volpt render cloud.vdb`: a bare VDB file renders in the default setup of grid files, kept
/// sparse, its memory reported.
#[test]
fn a_bare_vdb_file_renders_sparse() {
    let settings = RenderSettings {
        resolution: Some((8, 8)),
        spp: Some(1),
        ..RenderSettings::default()
    };
    let scene = Scene::load(fixture("sparse-cloud.vdb"), &settings).unwrap();
    let memory = scene.info().get("memory").unwrap().to_owned();
    assert!(memory.contains("dense 512.00 MiB"), "{memory}");
    render(&scene);
}

/// Textures hold dense grids: a texture lookup of a sparse grid is refused, at load and when set
/// on a loaded scene, and the scene keeps its lookup.
#[test]
fn texture_lookups_of_a_sparse_grid_are_refused() {
    let settings = |lookup| RenderSettings { lookup, ..small() };
    for lookup in [GridLookup::Texture, GridLookup::TextureHalf] {
        let Err(error) = Scene::load(fixture("sparse-cloud.vdb"), &settings(Some(lookup))) else {
            panic!("{lookup:?} of a sparse grid was not refused");
        };
        let error = error.to_string();
        assert!(error.contains("sparse"), "{error}");
        let mut scene = Scene::load(fixture("sparse-cloud.vdb"), &settings(None)).unwrap();
        assert!(scene.set_lookup(lookup).is_err());
        assert_eq!(scene.description().medium.lookup, GridLookup::Trilinear);
        // Nor may one render ask for it.
        let request = volpt::RenderRequest::samples(0..1).with_lookup(lookup);
        let error = Backend::cpu()
            .render(&scene, &mut scene.film(), &request, &Quiet)
            .unwrap_err()
            .to_string();
        assert!(error.contains("sparse"), "{error}");
    }
}
