//! Raw grids with a caller-given layout, and normalisation.

use std::path::{Path, PathBuf};

use tempfile::TempDir;
use volpt_scene::{
    normalise, read_raw, read_raw_into, write_raw, Bounds, ByteOrder, GridConvention, GridDesc,
    GridProblem, RawLayout, ScalarType, SceneError,
};

fn unit() -> Bounds {
    Bounds {
        min: [0.0; 3],
        max: [1.0; 3],
    }
}

fn layout(resolution: [u32; 3], channels: u32, scalar: ScalarType) -> RawLayout {
    RawLayout {
        resolution,
        channels,
        scalar,
        byte_order: ByteOrder::Little,
        header_bytes: 0,
    }
}

fn grid(resolution: [u32; 3], channels: u32, data: Vec<f32>) -> GridDesc {
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution,
        channels,
        bounds: unit(),
        convention: GridConvention::Cell,
        data,
    }
}

fn file(bytes: &[u8]) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("grid.raw");
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

fn problem(result: Result<GridDesc, SceneError>, path: &Path) -> GridProblem {
    match result {
        Err(err @ SceneError::Grid { .. }) => {
            assert!(
                err.to_string().contains(&path.display().to_string()),
                "{err}"
            );
            let SceneError::Grid { problem, .. } = err else {
                unreachable!()
            };
            problem
        }
        Err(other) => panic!("expected a grid error, found {other}"),
        Ok(_) => panic!("expected an error"),
    }
}

#[test]
fn every_type_and_byte_order_round_trips() {
    let dir = TempDir::new().unwrap();
    let data: Vec<f32> = (0..24).map(|i| (i * 5) as f32).collect();
    let original = grid([2, 3, 4], 1, data);
    for scalar in ScalarType::ALL {
        for byte_order in [ByteOrder::Little, ByteOrder::Big] {
            let path = dir.path().join(format!("{scalar:?}-{byte_order:?}.raw"));
            write_raw(&path, &original, scalar, byte_order).unwrap();
            let size = std::fs::metadata(&path).unwrap().len();
            assert_eq!(size, 24 * scalar.bytes() as u64);
            let layout = RawLayout {
                byte_order,
                ..layout([2, 3, 4], 1, scalar)
            };
            assert_eq!(
                read_raw(&path, &layout, unit()).unwrap(),
                original,
                "{scalar:?}"
            );
        }
    }
}

#[test]
fn three_channels_and_fractions_round_trip_as_f32() {
    let dir = TempDir::new().unwrap();
    let original = grid([2, 1, 1], 3, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
    let path = dir.path().join("rgb.raw");
    write_raw(&path, &original, ScalarType::F32, ByteOrder::Big).unwrap();
    let layout = RawLayout {
        byte_order: ByteOrder::Big,
        ..layout([2, 1, 1], 3, ScalarType::F32)
    };
    assert_eq!(read_raw(&path, &layout, unit()).unwrap(), original);
}

#[test]
fn header_bytes_are_skipped() {
    let mut bytes = b"HEADER".to_vec();
    bytes.extend_from_slice(&[1, 0, 2, 0]);
    let (_dir, path) = file(&bytes);
    let layout = RawLayout {
        header_bytes: 6,
        ..layout([2, 1, 1], 1, ScalarType::U16)
    };
    assert_eq!(
        read_raw(&path, &layout, unit()).unwrap().data,
        vec![1.0, 2.0]
    );
}

#[test]
fn truncated_data_is_an_error() {
    let (_dir, path) = file(&[1, 2, 3]);
    let p = problem(
        read_raw(&path, &layout([2, 2, 1], 1, ScalarType::U8), unit()),
        &path,
    );
    assert!(matches!(
        p,
        GridProblem::SizeMismatch {
            expected_bytes: 4,
            actual_bytes: 3,
            ..
        }
    ));
}

#[test]
fn too_much_data_is_an_error() {
    let (_dir, path) = file(&[1, 2, 3, 4, 5]);
    let p = problem(
        read_raw(&path, &layout([2, 2, 1], 1, ScalarType::U8), unit()),
        &path,
    );
    assert!(matches!(
        p,
        GridProblem::ExcessData {
            expected_bytes: 4,
            ..
        }
    ));
}

#[test]
fn huge_and_overflowing_layouts_are_refused_before_allocating() {
    let (_dir, path) = file(&[1, 2, 3, 4]);
    for (resolution, channels) in [([100_000; 3], 1), ([u32::MAX; 3], 3)] {
        let p = problem(
            read_raw(
                &path,
                &layout(resolution, channels, ScalarType::F64),
                unit(),
            ),
            &path,
        );
        assert!(matches!(p, GridProblem::TooLarge { .. }), "{p}");
    }
    // Within the value limit but far beyond the file: a size mismatch, still before allocating.
    let p = problem(
        read_raw(&path, &layout([1000; 3], 1, ScalarType::U8), unit()),
        &path,
    );
    assert!(matches!(p, GridProblem::SizeMismatch { .. }), "{p}");
}

#[test]
fn empty_layouts_are_an_error() {
    let (_dir, path) = file(&[]);
    let p = problem(
        read_raw(&path, &layout([0, 1, 1], 1, ScalarType::U8), unit()),
        &path,
    );
    assert!(matches!(p, GridProblem::BadField { .. }), "{p}");
}

#[test]
fn negative_nan_and_infinite_values_are_errors() {
    let (_dir, path) = file(&[0, 0, 0xff, 0xff]);
    let p = problem(
        read_raw(&path, &layout([2, 1, 1], 1, ScalarType::I16), unit()),
        &path,
    );
    assert!(matches!(
        p,
        GridProblem::BadValue {
            voxel: [1, 0, 0],
            channel: 0,
            ..
        }
    ));
    for bad in [f32::NAN, f32::INFINITY, -1.0] {
        let mut bytes = 1.0f32.to_le_bytes().to_vec();
        bytes.extend_from_slice(&bad.to_le_bytes());
        let (_dir, path) = file(&bytes);
        let p = problem(
            read_raw(&path, &layout([1, 1, 1], 2, ScalarType::F32), unit()),
            &path,
        );
        assert!(matches!(p, GridProblem::BadValue { channel: 1, .. }), "{p}");
    }
    // Finite in f64, infinite as f32.
    let (_dir, path) = file(&1e300f64.to_le_bytes());
    let p = problem(
        read_raw(&path, &layout([1, 1, 1], 1, ScalarType::F64), unit()),
        &path,
    );
    assert!(matches!(p, GridProblem::BadValue { .. }), "{p}");
}

#[test]
fn missing_file_names_it() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("absent.raw");
    let err = read_raw(&path, &layout([1, 1, 1], 1, ScalarType::U8), unit()).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("absent.raw"), "{err}");
}

#[test]
fn writer_refuses_values_the_type_cannot_hold() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("out.raw");
    let err = write_raw(
        &path,
        &grid([1, 1, 1], 1, vec![300.0]),
        ScalarType::U8,
        ByteOrder::Little,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        SceneError::Grid {
            problem: GridProblem::BadValue { .. },
            ..
        }
    ));
    let err = write_raw(
        &path,
        &grid([2, 1, 1], 1, vec![1.0]),
        ScalarType::U8,
        ByteOrder::Little,
    )
    .unwrap_err();
    assert!(matches!(
        err,
        SceneError::Grid {
            problem: GridProblem::DataLength { .. },
            ..
        }
    ));
}

#[test]
fn bucky_reads_and_normalises() {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/bucky/Bucky.raw"
    ));
    let grid = read_raw(path, &layout([32; 3], 1, ScalarType::U8), unit()).unwrap();
    assert_eq!(grid.data.len(), 32 * 32 * 32);
    assert_eq!(grid.convention, GridConvention::Cell);
    let max = grid.max_value();
    assert!(max > 100.0 && max <= 255.0, "max {max}");
    assert!(grid.data.iter().all(|v| v.fract() == 0.0));
    let empty = grid.data.iter().filter(|&&v| v == 0.0).count();
    assert!(empty > 0 && empty < grid.data.len(), "{empty} empty voxels");

    let density = normalise(grid.clone(), 40.0);
    assert_eq!(density.max_value(), 40.0);
    for (d, v) in density.data.iter().zip(&grid.data) {
        assert!((d - v * 40.0 / max).abs() <= 1e-5 * 40.0);
    }
}

/// Streaming into a caller's buffer (page-locked memory for a GPU, say) reads exactly what
/// `read_raw` reads, with the same checks, and refuses a buffer of the wrong size before reading.
#[test]
fn streaming_into_a_callers_buffer_reads_what_read_raw_reads() {
    let dir = TempDir::new().unwrap();
    let data: Vec<f32> = (0..3 * 70_000).map(|i| (i % 977) as f32).collect();
    let original = grid([70, 50, 20], 3, data);
    for scalar in [ScalarType::F32, ScalarType::U16, ScalarType::F64] {
        let path = dir.path().join(format!("{scalar:?}.raw"));
        write_raw(&path, &original, scalar, ByteOrder::Big).unwrap();
        let layout = RawLayout {
            byte_order: ByteOrder::Big,
            ..layout([70, 50, 20], 3, scalar)
        };
        let mut out = vec![f32::NAN; original.data.len()];
        read_raw_into(&path, &layout, &mut out).unwrap();
        assert_eq!(out, read_raw(&path, &layout, unit()).unwrap().data);
        assert_eq!(out, original.data, "{scalar:?}");

        let mut short = vec![0.0; original.data.len() - 1];
        let err = read_raw_into(&path, &layout, &mut short).unwrap_err();
        let message = err.to_string();
        assert!(message.contains("210000 values"), "{message}");
        assert!(message.contains("209999 values"), "{message}");
        assert!(short.iter().all(|&v| v == 0.0), "nothing was read");
    }

    let mut bytes = Vec::new();
    for v in [1.0f32, 2.0, -3.0, 4.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let (_dir, path) = file(&bytes);
    let layout = layout([2, 2, 1], 1, ScalarType::F32);
    let streamed = read_raw_into(&path, &layout, &mut [0.0; 4]).map(|()| grid([1; 3], 1, vec![]));
    assert_eq!(
        problem(streamed, &path),
        problem(read_raw(&path, &layout, unit()), &path)
    );
    let (_dir, path) = file(&bytes[..12]);
    assert!(matches!(
        problem(
            read_raw_into(&path, &layout, &mut [0.0; 4]).map(|()| grid([1; 3], 1, vec![])),
            &path
        ),
        GridProblem::SizeMismatch { .. }
    ));
}
