//! The `.vol` reader and writer.

mod common;

use std::path::{Path, PathBuf};

use common::*;
use tempfile::TempDir;
use volpt_scene::{read_vol, Bounds, SceneError, VolGrid, VolProblem};

/// A header for the given fields, as raw bytes.
fn header(encoding: i32, resolution: [i32; 3], channels: i32, bbox: [f32; 6]) -> Vec<u8> {
    let mut bytes = b"VOL\x03".to_vec();
    for v in [
        encoding,
        resolution[0],
        resolution[1],
        resolution[2],
        channels,
    ] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    for v in bbox {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

fn raw_file(bytes: &[u8]) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("grid.vol");
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

fn problem(err: SceneError) -> VolProblem {
    match err {
        SceneError::Vol { problem, .. } => problem,
        other => panic!("expected a .vol error, found {other}"),
    }
}

#[test]
fn float32_round_trip() {
    let dir = TempDir::new().unwrap();
    let grid = VolGrid {
        resolution: [3, 2, 2],
        channels: 3,
        bbox: Bounds {
            min: [-1.0, -2.0, -3.0],
            max: [1.0, 2.0, 3.5],
        },
        data: (0..36).map(|i| i as f32 * 0.25 - 1.0).collect(),
    };
    let path = write_grid(dir.path(), "rgb.vol", &grid);
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 48 + 36 * 4);
    assert_eq!(read_vol(&path).unwrap(), grid);
}

#[test]
fn uint8_values_are_normalised() {
    let mut bytes = header(3, [2, 1, 1], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    bytes.extend_from_slice(&[0, 255]);
    let (_dir, path) = raw_file(&bytes);
    let grid = read_vol(&path).unwrap();
    assert_eq!(grid.data, vec![0.0, 1.0]);
    assert_eq!(grid.resolution, [2, 1, 1]);
    assert_eq!(grid.bbox, unit_bounds());
}

#[test]
fn float16_values_are_decoded() {
    let mut bytes = header(2, [3, 1, 1], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    for half in [0x3c00u16, 0x3800, 0x0000] {
        bytes.extend_from_slice(&half.to_le_bytes());
    }
    let (_dir, path) = raw_file(&bytes);
    assert_eq!(read_vol(&path).unwrap().data, vec![1.0, 0.5, 0.0]);
}

#[test]
fn smoke_vol_header_if_present() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/smoke.vol");
    if !path.exists() {
        println!(
            "skipping: {} is absent (shared test data not checked out)",
            path.display()
        );
        return;
    }
    let grid = read_vol(&path).unwrap();
    assert_eq!(grid.resolution, [128, 128, 50]);
    assert_eq!(grid.channels, 1);
    assert_eq!(
        grid.bbox,
        Bounds {
            min: [-0.5, -0.5, -0.1953125],
            max: [0.5, 0.5, 0.1953125]
        }
    );
    assert_eq!(grid.data.len(), 128 * 128 * 50);
    grid.check_density(&path).expect("smoke is a valid density");
}

#[test]
fn truncated_data_names_expected_and_actual_bytes() {
    let mut bytes = header(1, [2, 2, 2], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    bytes.extend_from_slice(&[0u8; 7 * 4]);
    let (_dir, path) = raw_file(&bytes);
    let err = read_vol(&path).unwrap_err();
    message_of(&err, &["grid.vol", "32 data bytes", "holds 28 bytes"]);
    assert!(matches!(
        problem(err),
        VolProblem::SizeMismatch {
            expected_bytes: 32,
            actual_bytes: 28,
            ..
        }
    ));
}

#[test]
fn oversized_file_is_an_error() {
    let mut bytes = header(1, [1, 1, 1], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    bytes.extend_from_slice(&[0u8; 8]);
    let (_dir, path) = raw_file(&bytes);
    let err = read_vol(&path).unwrap_err();
    assert!(matches!(
        problem(err),
        VolProblem::SizeMismatch {
            expected_bytes: 4,
            actual_bytes: 8,
            ..
        }
    ));
}

#[test]
fn truncated_header_is_an_error() {
    let (_dir, path) = raw_file(b"VOL\x03\x01\x00");
    let err = read_vol(&path).unwrap_err();
    message_of(&err, &["grid.vol", "expected 48 bytes, found 6"]);
}

#[test]
fn absurd_header_fails_before_allocating() {
    // 100000^3 float32 voxels would be 4 PB; the file is 52 bytes.
    let mut bytes = header(1, [100_000; 3], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    bytes.extend_from_slice(&[0u8; 4]);
    let (_dir, path) = raw_file(&bytes);
    let err = read_vol(&path).unwrap_err();
    message_of(
        &err,
        &[
            "grid.vol",
            "100000 x 100000 x 100000",
            "4000000000000000 data bytes",
            "holds 4 bytes",
        ],
    );

    // Sizes whose product overflows 64 bits.
    let bytes = header(1, [i32::MAX; 3], 3, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    let (_dir, path) = raw_file(&bytes);
    assert!(matches!(
        problem(read_vol(&path).unwrap_err()),
        VolProblem::TooLarge { .. }
    ));
}

#[test]
fn bad_header_fields_are_named() {
    let cases: [(Vec<u8>, &str); 5] = [
        (
            b"XYZ\x03".iter().copied().chain([0u8; 44]).collect(),
            "expected the bytes \"VOL\"",
        ),
        (
            b"VOL\x02".iter().copied().chain([0u8; 44]).collect(),
            "expected .vol format version 3, found version 2",
        ),
        (header(4, [1, 1, 1], 1, [0.0; 6]), "found 4"),
        (header(1, [1, 0, 1], 1, [0.0; 6]), "found 1 x 0 x 1"),
        (
            header(1, [1, 1, 1], 2, [0.0; 6]),
            "expected 1 or 3 channels, found 2",
        ),
    ];
    for (bytes, expected) in cases {
        let (_dir, path) = raw_file(&bytes);
        let err = read_vol(&path).unwrap_err();
        message_of(&err, &["grid.vol", expected]);
    }
}

#[test]
fn nan_value_names_the_voxel() {
    let mut bytes = header(1, [2, 2, 1], 1, [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    for v in [0.0f32, 1.0, 2.0, f32::NAN] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let (_dir, path) = raw_file(&bytes);
    let err = read_vol(&path).unwrap_err();
    message_of(
        &err,
        &[
            "grid.vol",
            "voxel (x=1, y=1, z=0) channel 0",
            "expected a finite number",
            "NaN",
        ],
    );
}

#[test]
fn density_and_albedo_checks() {
    let path = Path::new("g.vol");
    let mut grid = density_grid([2, 2, 2], unit_bounds());
    grid.check_density(path).unwrap();
    grid.data[5] = -0.5;
    let err = grid.check_density(path).unwrap_err();
    message_of(&err, &["g.vol", "voxel (x=1, y=0, z=1)", ">= 0", "-0.5"]);

    let rgb = VolGrid {
        channels: 3,
        data: vec![0.5; 24],
        ..grid.clone()
    };
    // A density per channel.
    rgb.check_density(path).unwrap();
    rgb.check_albedo(path).unwrap();
    let two = VolGrid {
        channels: 2,
        data: vec![0.5; 16],
        ..grid.clone()
    };
    message_of(
        &two.check_density(path).unwrap_err(),
        &["density grid", "1 channel (grey) or 3", "found 2"],
    );
    let bright = VolGrid {
        data: vec![1.5; 8],
        ..grid
    };
    message_of(&bright.check_albedo(path).unwrap_err(), &["[0, 1]", "1.5"]);
}

#[test]
fn missing_file_names_it() {
    let err = read_vol(Path::new("/nonexistent/dir/missing.vol")).unwrap_err();
    message_of(&err, &["/nonexistent/dir/missing.vol"]);
    assert!(matches!(err, SceneError::Io { .. }));
}

#[test]
fn write_refuses_inconsistent_grids() {
    let dir = TempDir::new().unwrap();
    let grid = VolGrid {
        data: vec![0.0; 3],
        ..density_grid([2, 2, 2], unit_bounds())
    };
    let err = volpt_scene::write_vol(&dir.path().join("bad.vol"), &grid).unwrap_err();
    message_of(&err, &["bad.vol", "expected 8 values", "found 3"]);
}
