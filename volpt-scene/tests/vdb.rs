//! `.vdb` files written by the real OpenVDB library (`scenes/vdb/make_fixtures.py`, OpenVDB 10.0.1
//! from Debian's python3-openvdb; default compression: blosc LZ4 with active-mask compression)
//! read into the values, boxes and layouts OpenVDB gave them.

use std::path::{Path, PathBuf};

use volpt_scene::description::{GridConvention, SampleLayout};
use volpt_scene::raw::{read_raw, RawLayout, ScalarType};
use volpt_scene::vdb::{list_grids, read_vdb, Sparsity, VdbOptions};
use volpt_scene::{Bounds, GridDesc, SceneError};

/// The committed fixtures, or those `scripts/vdb-fixtures.sh` has just written with OpenVDB
/// (`VOLPT_VDB_FIXTURES`, set by CI).
fn fixture(name: &str) -> PathBuf {
    match std::env::var_os("VOLPT_VDB_FIXTURES") {
        Some(dir) => PathBuf::from(dir).join(name),
        None => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/vdb/fixtures")
            .join(name),
    }
}

fn read(name: &str, grid: Option<&str>, sparsity: Sparsity) -> GridDesc {
    let options = VdbOptions {
        grid: grid.map(str::to_owned),
        vector: false,
        sparsity,
    };
    read_vdb(&fixture(name), &options).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn bucky_raw() -> GridDesc {
    let layout = RawLayout {
        resolution: [32; 3],
        channels: 1,
        scalar: ScalarType::U8,
        byte_order: Default::default(),
        header_bytes: 0,
    };
    let bounds = Bounds {
        min: [-0.5; 3],
        max: [0.5; 3],
    };
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/bucky/Bucky.raw");
    read_raw(&path, &layout, bounds).unwrap()
}

#[test]
fn bucky_vdb_holds_the_raw_grid_in_its_box() {
    let raw = bucky_raw();
    // OpenVDB records each grid's compression in its metadata (`file_compression`).
    for (name, compression) in [
        ("bucky.vdb", "blosc + active values"),
        ("bucky-half.vdb", "blosc + active values"),
        ("bucky-zip.vdb", "zip + active values"),
        ("bucky-half-none.vdb", "none"),
    ] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        let said = format!("file_compression\x06\0\0\0string{}\0\0\0{compression}", {
            char::from(compression.len() as u8)
        });
        assert!(
            bytes.windows(said.len()).any(|w| w == said.as_bytes()),
            "{name} is not {compression}"
        );
        let sparse = read(name, None, Sparsity::Always);
        assert_eq!(sparse.layout, SampleLayout::Sparse);
        assert_eq!(sparse.resolution, [32; 3], "{name}");
        assert_eq!(sparse.bounds, raw.bounds, "{name}: the transform's box");
        assert_eq!(sparse.convention, GridConvention::Cell);
        assert_eq!(raw.convention, GridConvention::Cell);
        // Bucky has no all-zero leaf: its 64 leaves and the background brick are stored.
        assert_eq!(sparse.samples().len(), 65 * 512, "{name}");
        let dense = sparse.densified();
        assert_eq!(dense.data, raw.data, "{name}: every voxel");
        let never = read(name, None, Sparsity::Never);
        assert_eq!(never.layout, SampleLayout::Dense);
        assert_eq!(never.data, raw.data);
    }
}

#[test]
fn half_leaves_read_as_openvdb_rounded_them() {
    let grid = read("halves.vdb", None, Sparsity::Never);
    assert_eq!(grid.resolution, [16; 3]);
    let mut inexact = 0;
    for k in 0..16u32 {
        for j in 0..16u32 {
            for i in 0..16u32 {
                // numpy's float64 arithmetic, cast to float32, then OpenVDB's float to half.
                let v = (f64::from(i + j + k) * 0.1 + 0.01) as f32;
                let expected = half::f16::from_f32(v).to_f32();
                inexact += usize::from(expected != v);
                assert_eq!(grid.sample(i, j, k, 0), expected, "({i}, {j}, {k})");
            }
        }
    }
    assert!(
        inexact > 3000,
        "only {inexact} values were rounded: not a half test"
    );
}

#[test]
fn scale_and_translation_place_the_grid() {
    let grid = read("transform.vdb", Some("smoke"), Sparsity::Always);
    // Index box [-8, 8) x [16, 24) x [0, 24), voxel centres at index * (0.5, 0.25, 2) + (1, 2, 3):
    // the box reaches half a voxel beyond the outermost centres.
    assert_eq!(grid.resolution, [16, 8, 24]);
    assert_eq!(
        grid.bounds,
        Bounds {
            min: [1.0 + 0.5 * -8.5, 2.0 + 0.25 * 15.5, 3.0 + 2.0 * -0.5],
            max: [1.0 + 0.5 * 7.5, 2.0 + 0.25 * 23.5, 3.0 + 2.0 * 23.5],
        }
    );
    for z in 0..24 {
        for y in 0..8 {
            for x in 0..16 {
                let expected = 1.0 + x as f32 + 2.0 * y as f32 + 3.0 * z as f32;
                assert_eq!(grid.sample(x, y, z, 0), expected, "({x}, {y}, {z})");
            }
        }
    }
    let other = read("transform.vdb", Some("other"), Sparsity::Auto);
    assert_eq!(other.resolution, [8; 3]);
    assert!(other.data.iter().all(|&v| v == 1.0));
}

#[test]
fn grids_are_picked_by_name_and_a_wrong_name_lists_the_grids() {
    let names = list_grids(&fixture("transform.vdb")).unwrap();
    assert_eq!(
        names,
        vec![
            ("smoke".to_owned(), "Tree_float_5_4_3".to_owned()),
            ("other".to_owned(), "Tree_float_5_4_3".to_owned())
        ]
    );
    let options = |grid: Option<&str>| VdbOptions {
        grid: grid.map(str::to_owned),
        ..Default::default()
    };
    for grid in [Some("nope"), None] {
        let error = read_vdb(&fixture("transform.vdb"), &options(grid))
            .unwrap_err()
            .to_string();
        assert!(error.contains("transform.vdb"), "{error}");
        assert!(
            error.contains("smoke") && error.contains("other"),
            "{error}"
        );
    }
    let error = read_vdb(&fixture("cloud-rgb.vdb"), &options(Some("albedo")))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("expected a float grid, found \"Tree_vec3s_5_4_3\""),
        "{error}"
    );
}

#[test]
fn a_vec3_grid_is_an_rgb_albedo() {
    let options = VdbOptions {
        grid: Some("albedo".into()),
        vector: true,
        sparsity: Sparsity::Always,
    };
    let albedo = read_vdb(&fixture("cloud-rgb.vdb"), &options).unwrap();
    assert_eq!(albedo.channels, 3);
    assert_eq!(albedo.resolution, [24; 3]);
    assert_eq!(albedo.sample(5, 6, 7, 0), 0.25);
    assert_eq!(albedo.sample(5, 6, 7, 1), 0.5);
    assert_eq!(albedo.sample(23, 0, 11, 2), 0.75);
    let density = read("cloud-rgb.vdb", None, Sparsity::Auto);
    assert_eq!(density.max_value(), 5.0);
}

/// Every prefix of every fixture, and each fixture with bytes overwritten throughout, is an
/// error or a grid, never a panic (the fuzz target explores further: fuzz/).
#[test]
fn truncated_and_corrupted_files_are_errors_not_panics() {
    // A corrupted origin can claim a box of gigabytes, which the default limit (8 GiB) admits and
    // which would take minutes to zero: the fuzzers' limit keeps this test to seconds. (The other
    // tests of this file read files far below it.)
    volpt_scene::limits::set_memory_limit(256 << 20);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.vdb");
    for name in [
        "bucky.vdb",
        "bucky-zip.vdb",
        "bucky-half-none.vdb",
        "halves.vdb",
        "transform.vdb",
        "cloud-rgb.vdb",
    ] {
        let bytes = std::fs::read(fixture(name)).unwrap();
        let step = (bytes.len() / 300).max(1);
        for len in (0..bytes.len()).step_by(step) {
            std::fs::write(&path, &bytes[..len]).unwrap();
            let result = read_vdb(&path, &VdbOptions::default());
            assert!(result.is_err(), "{name} cut at {len} read as a grid");
        }
        for at in (0..bytes.len()).step_by(step) {
            let mut bad = bytes.clone();
            for b in &mut bad[at..(at + 4).min(bytes.len())] {
                *b ^= 0xA5;
            }
            std::fs::write(&path, &bad).unwrap();
            for sparsity in [Sparsity::Always, Sparsity::Never] {
                let options = VdbOptions {
                    sparsity,
                    ..Default::default()
                };
                if let Ok(grid) = read_vdb(&path, &options) {
                    if grid.layout == SampleLayout::Sparse {
                        volpt_scene::sparse::check(&grid).unwrap();
                    }
                }
            }
        }
    }
    let bucky = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/bucky/Bucky.raw");
    let error = read_vdb(&bucky, &VdbOptions::default()).unwrap_err();
    assert!(
        matches!(error, SceneError::Grid { .. }) && error.to_string().contains("magic number"),
        "{error}"
    );
}

/// A Mitsuba 3 `gridvolume` whose file is a `.vdb`: the grid (chosen by `grid`), on the box its
/// own transform gives, then moved by `to_world`; an albedo `gridvolume` reads the vec3 grid.
#[test]
fn a_mitsuba_gridvolume_reads_a_vdb() {
    let dir = tempfile::tempdir().unwrap();
    let xml = dir.path().join("scene.xml");
    let (transform, cloud) = (fixture("transform.vdb"), fixture("cloud-rgb.vdb"));
    std::fs::write(
        &xml,
        format!(
            r#"<scene version="3.0.0">
    <sensor type="perspective"><float name="fov" value="30"/></sensor>
    <medium type="heterogeneous" id="m">
        <volume name="sigma_t" type="gridvolume">
            <string name="filename" value="{}"/>
            <string name="grid" value="smoke"/>
            <transform name="to_world"><translate value="10, 0, 0"/></transform>
        </volume>
        <volume name="albedo" type="gridvolume">
            <string name="filename" value="{}"/>
        </volume>
    </medium>
    <shape type="cube"><bsdf type="null"/><ref name="interior" id="m"/></shape>
</scene>"#,
            transform.display(),
            cloud.display()
        ),
    )
    .unwrap();
    let desc = volpt_scene::load_mitsuba(&xml).unwrap_or_else(|e| panic!("{e}"));
    let volpt_scene::DensityDesc::Grid(density) = &desc.medium.density else {
        panic!("a grid density");
    };
    assert_eq!(density.resolution, [16, 8, 24]);
    assert_eq!(density.convention, GridConvention::Cell);
    assert_eq!(
        density.bounds.min,
        [10.0 + 1.0 + 0.5 * -8.5, 2.0 + 0.25 * 15.5, 2.0]
    );
    let volpt_scene::AlbedoDesc::Grid(albedo) = &desc.medium.albedo else {
        panic!("a grid albedo");
    };
    assert_eq!((albedo.channels, albedo.resolution), (3, [24; 3]));
}
