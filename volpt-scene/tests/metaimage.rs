//! MetaImage `.mha` / `.mhd` reading and writing.

use std::io::Write;
use std::path::{Path, PathBuf};

use tempfile::TempDir;
use volpt_scene::{
    read_metaimage, write_metaimage, Bounds, ByteOrder, GridConvention, GridDesc, GridProblem,
    MetaImageOptions, ScalarType, SceneError,
};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/metaimage")
        .join(name)
}

fn grid(resolution: [u32; 3], channels: u32) -> GridDesc {
    let n = (resolution.iter().product::<u32>() * channels) as usize;
    GridDesc {
        layout: volpt_scene::SampleLayout::Dense,
        resolution,
        channels,
        bounds: Bounds {
            min: [-1.0, 0.0, 2.0],
            max: [1.0, 3.0, 2.5],
        },
        convention: GridConvention::Cell,
        data: (0..n).map(|i| (i % 100) as f32).collect(),
    }
}

fn assert_close(a: Bounds, b: Bounds) {
    for (x, y) in a.min.iter().chain(&a.max).zip(b.min.iter().chain(&b.max)) {
        assert!((x - y).abs() <= 1e-5 * (1.0 + y.abs()), "{a:?} vs {b:?}");
    }
}

fn assert_same(read: &GridDesc, written: &GridDesc) {
    assert_eq!(read.resolution, written.resolution);
    assert_eq!(read.channels, written.channels);
    assert_eq!(read.convention, GridConvention::Cell);
    assert_eq!(read.data, written.data);
    assert_close(read.bounds, written.bounds);
}

/// A `.mha` with the given header lines (`ElementDataFile = LOCAL` appended) and data.
fn mha(header: &str, data: &[u8]) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("grid.mha");
    let mut bytes = format!("{header}ElementDataFile = LOCAL\n").into_bytes();
    bytes.extend_from_slice(data);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

const UCHAR_2X2X2: &str = "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n";

fn problem(path: &Path) -> GridProblem {
    match read_metaimage(path) {
        Err(err @ SceneError::Grid { .. }) => {
            let file = path.file_name().unwrap().to_string_lossy().into_owned();
            assert!(err.to_string().contains(&file), "{err}");
            let SceneError::Grid { problem, .. } = err else {
                unreachable!()
            };
            problem
        }
        Err(other) => panic!("expected a grid error, found {other}"),
        Ok(_) => panic!("expected an error"),
    }
}

fn zlib(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn every_type_order_compression_and_file_kind_round_trips() {
    let dir = TempDir::new().unwrap();
    let original = grid([3, 2, 4], 1);
    for scalar in ScalarType::ALL {
        for byte_order in [ByteOrder::Little, ByteOrder::Big] {
            for compressed in [false, true] {
                for ext in ["mha", "mhd"] {
                    let name = format!("{scalar:?}-{byte_order:?}-{compressed}.{ext}");
                    let path = dir.path().join(&name);
                    let options = MetaImageOptions {
                        scalar,
                        byte_order,
                        compressed,
                    };
                    write_metaimage(&path, &original, &options).unwrap();
                    let read = read_metaimage(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
                    assert_same(&read, &original);
                }
            }
        }
    }
}

#[test]
fn rgb_grids_round_trip() {
    let dir = TempDir::new().unwrap();
    let mut original = grid([2, 2, 1], 3);
    original.data = (0..12).map(|i| i as f32 / 12.0).collect();
    for ext in ["mha", "mhd"] {
        let path = dir.path().join(format!("rgb.{ext}"));
        write_metaimage(&path, &original, &MetaImageOptions::default()).unwrap();
        assert_same(&read_metaimage(&path).unwrap(), &original);
    }
}

#[test]
fn mhd_data_files_sit_beside_the_header() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("g.mhd");
    let options = MetaImageOptions {
        compressed: true,
        ..MetaImageOptions::default()
    };
    write_metaimage(&path, &grid([2, 2, 2], 1), &options).unwrap();
    assert!(dir.path().join("g.zraw").exists());
    let header = std::fs::read_to_string(&path).unwrap();
    assert!(header.contains("ElementDataFile = g.zraw"), "{header}");
    assert!(header.contains("CompressedDataSize = "), "{header}");
}

#[test]
fn met_long_and_ulong_are_32_bit() {
    let dir = TempDir::new().unwrap();
    let original = grid([2, 2, 2], 1);
    for (scalar, from, to) in [
        (ScalarType::I32, "MET_INT", "MET_LONG"),
        (ScalarType::U32, "MET_UINT", "MET_ULONG"),
    ] {
        let path = dir.path().join(format!("{to}.mhd"));
        let options = MetaImageOptions {
            scalar,
            ..MetaImageOptions::default()
        };
        write_metaimage(&path, &original, &options).unwrap();
        let header = std::fs::read_to_string(&path).unwrap().replace(from, to);
        std::fs::write(&path, header).unwrap();
        assert_same(&read_metaimage(&path).unwrap(), &original);
    }
}

#[test]
fn vertex_grids_are_written_with_their_samples_in_place() {
    let dir = TempDir::new().unwrap();
    let mut original = grid([3, 2, 2], 1);
    original.convention = GridConvention::Vertex;
    original.bounds = Bounds {
        min: [0.0; 3],
        max: [2.0, 1.0, 1.0],
    };
    let path = dir.path().join("vertex.mha");
    write_metaimage(&path, &original, &MetaImageOptions::default()).unwrap();
    let read = read_metaimage(&path).unwrap();
    // Samples at 0, 1, 2 on x: cells of width 1 around them.
    assert_close(
        read.bounds,
        Bounds {
            min: [-0.5, -0.5, -0.5],
            max: [2.5, 1.5, 1.5],
        },
    );
}

#[test]
fn fixture_mhd_with_spacing_and_offset() {
    let grid = read_metaimage(&fixture("tiny.mhd")).unwrap();
    assert_eq!(grid.resolution, [2, 2, 2]);
    assert_eq!(grid.channels, 1);
    assert_eq!(grid.data, (0..8).map(|i| i as f32).collect::<Vec<_>>());
    // Voxel centres at offset + i * spacing: 1 and 1.5 on x.
    assert_eq!(grid.bounds.min, [0.75, 1.75, 2.75]);
    assert_eq!(grid.bounds.max, [1.75, 2.75, 3.75]);
}

#[test]
fn fixture_mha_big_endian_with_element_size_and_position() {
    let grid = read_metaimage(&fixture("msb.mha")).unwrap();
    assert_eq!(grid.data, vec![1.0, 256.0, 1000.0]);
    assert_eq!(grid.bounds.min, [-1.0, -0.5, -0.5]);
    assert_eq!(grid.bounds.max, [5.0, 0.5, 0.5]);
}

#[test]
fn fixture_data_at_the_end_of_the_file() {
    let grid = read_metaimage(&fixture("at_end.mhd")).unwrap();
    assert_eq!(grid.channels, 3);
    assert_eq!(grid.data, vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
}

#[test]
fn header_size_skips_bytes() {
    let (_dir, path) = mha(&format!("{UCHAR_2X2X2}HeaderSize = 3\n"), b"xyz01234567");
    let grid = read_metaimage(&path).unwrap();
    assert_eq!(grid.data[0], f32::from(b'0'));
}

#[test]
fn missing_dim_size() {
    let (_dir, path) = mha("NDims = 3\nElementType = MET_UCHAR\n", &[0; 8]);
    let p = problem(&path);
    assert!(
        matches!(
            p,
            GridProblem::MissingField {
                field: "DimSize",
                ..
            }
        ),
        "{p}"
    );
}

#[test]
fn ndims_other_than_three() {
    let (_dir, path) = mha(
        "NDims = 2\nDimSize = 2 2\nElementType = MET_UCHAR\n",
        &[0; 4],
    );
    let p = problem(&path);
    assert!(
        matches!(&p, GridProblem::BadField { field, line: Some(1), .. } if field == "NDims"),
        "{p}"
    );
}

#[test]
fn unknown_element_type() {
    let (_dir, path) = mha(
        "NDims = 3\nDimSize = 1 1 1\nElementType = MET_HALF\n",
        &[0; 2],
    );
    let p = problem(&path);
    assert!(
        matches!(&p, GridProblem::BadField { field, .. } if field == "ElementType"),
        "{p}"
    );
    assert!(p.to_string().contains("MET_HALF"), "{p}");
}

#[test]
fn bad_numbers() {
    for header in [
        "NDims = 3\nDimSize = 2 2\nElementType = MET_UCHAR\n",
        "NDims = 3\nDimSize = 2 two 2\nElementType = MET_UCHAR\n",
        "NDims = 3\nDimSize = 2 0 2\nElementType = MET_UCHAR\n",
        "NDims = 3\nDimSize = 2 -2 2\nElementType = MET_UCHAR\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementSpacing = 1 0 1\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nOffset = 1 nan 1\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nElementNumberOfChannels = 2\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nCompressedData = maybe\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nHeaderSize = -2\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\nDimSize = 2 2 2\n",
        "NDims = 3\nDimSize = 2 2 2\nthis line has no equals sign\n",
        "NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n\
         BinaryDataByteOrderMSB = True\nElementByteOrderMSB = False\n",
    ] {
        let (_dir, path) = mha(header, &[0; 8]);
        let p = problem(&path);
        assert!(
            matches!(p, GridProblem::BadField { line: Some(_), .. }),
            "{header}: {p}"
        );
    }
}

#[test]
fn binary_data_in_place_of_a_header() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("binary.mha");
    std::fs::write(&path, [0xffu8, 0xfe, 0, 1, b'\n']).unwrap();
    assert!(matches!(
        problem(&path),
        GridProblem::BadField { line: Some(1), .. }
    ));
    std::fs::write(&path, vec![b'x'; 100_000]).unwrap();
    assert!(matches!(
        problem(&path),
        GridProblem::MissingField {
            field: "ElementDataFile",
            ..
        }
    ));
}

#[test]
fn rotated_grids_are_unsupported() {
    let header = format!("{UCHAR_2X2X2}TransformMatrix = 0 1 0 -1 0 0 0 0 1\n");
    let (_dir, path) = mha(&header, &[0; 8]);
    assert!(matches!(problem(&path), GridProblem::Unsupported { .. }));
}

#[test]
fn ascii_data_and_file_lists_are_unsupported() {
    let (_dir, path) = mha(
        &format!("{UCHAR_2X2X2}BinaryData = False\n"),
        b"0 1 2 3 4 5 6 7",
    );
    assert!(matches!(problem(&path), GridProblem::Unsupported { .. }));
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("list.mhd");
    std::fs::write(
        &path,
        format!("{UCHAR_2X2X2}ElementDataFile = slice%03d.raw\n"),
    )
    .unwrap();
    assert!(matches!(problem(&path), GridProblem::Unsupported { .. }));
}

#[test]
fn huge_declared_sizes_are_refused_before_allocating() {
    for dims in ["100000 100000 100000", "4294967295 4294967295 4294967295"] {
        for compressed in ["False", "True"] {
            let header = format!(
                "NDims = 3\nDimSize = {dims}\nElementNumberOfChannels = 3\n\
                 ElementType = MET_DOUBLE\nCompressedData = {compressed}\n"
            );
            let (_dir, path) = mha(&header, &zlib(&[0; 8]));
            let p = problem(&path);
            assert!(matches!(p, GridProblem::TooLarge { .. }), "{dims}: {p}");
        }
    }
    // Below the value limit, but far more than the file holds.
    let header = "NDims = 3\nDimSize = 1000 1000 1000\nElementType = MET_UCHAR\n";
    let (_dir, path) = mha(header, &[0; 8]);
    assert!(matches!(problem(&path), GridProblem::SizeMismatch { .. }));
}

#[test]
fn truncated_and_excess_data() {
    let (_dir, path) = mha(UCHAR_2X2X2, &[0; 7]);
    let p = problem(&path);
    assert!(
        matches!(
            p,
            GridProblem::SizeMismatch {
                expected_bytes: 8,
                actual_bytes: 7,
                ..
            }
        ),
        "{p}"
    );
    let (_dir, path) = mha(UCHAR_2X2X2, &[0; 9]);
    assert!(matches!(problem(&path), GridProblem::ExcessData { .. }));

    let dir = TempDir::new().unwrap();
    let path = dir.path().join("g.mhd");
    std::fs::write(&path, format!("{UCHAR_2X2X2}ElementDataFile = g.raw\n")).unwrap();
    std::fs::write(dir.path().join("g.raw"), [0; 5]).unwrap();
    let p = problem(&path);
    assert!(p.to_string().contains("g.raw"), "{p}");
    assert!(matches!(p, GridProblem::SizeMismatch { .. }));
}

#[test]
fn compressed_data_of_the_wrong_size() {
    let header = format!("{UCHAR_2X2X2}CompressedData = True\n");
    let (_dir, path) = mha(&header, &zlib(&[1; 7]));
    let p = problem(&path);
    assert!(
        matches!(
            p,
            GridProblem::SizeMismatch {
                expected_bytes: 8,
                actual_bytes: 7,
                ..
            }
        ),
        "{p}"
    );
    let (_dir, path) = mha(&header, &zlib(&[1; 9]));
    assert!(matches!(problem(&path), GridProblem::ExcessData { .. }));
    let (_dir, path) = mha(&header, b"this is not zlib data");
    let p = problem(&path);
    assert!(matches!(p, GridProblem::Decode { .. }), "{p}");

    let data = zlib(&[1; 8]);
    let header = format!("{header}CompressedDataSize = {}\n", data.len() + 1);
    let (_dir, path) = mha(&header, &data);
    assert!(matches!(problem(&path), GridProblem::SizeMismatch { .. }));
}

#[test]
fn compressed_data_at_the_end_needs_its_size() {
    let header = format!("{UCHAR_2X2X2}CompressedData = True\nHeaderSize = -1\n");
    let (_dir, path) = mha(&header, &zlib(&[1; 8]));
    assert!(matches!(
        problem(&path),
        GridProblem::MissingField {
            field: "CompressedDataSize",
            ..
        }
    ));
}

#[test]
fn negative_nan_and_infinite_values() {
    let (_dir, path) = mha(
        UCHAR_2X2X2.replace("MET_UCHAR", "MET_CHAR").as_str(),
        &[0, 0, 0, 0xff, 0, 0, 0, 0],
    );
    let p = problem(&path);
    assert!(
        matches!(
            p,
            GridProblem::BadValue {
                voxel: [1, 1, 0],
                ..
            }
        ),
        "{p}"
    );
    for bad in [f32::NAN, f32::NEG_INFINITY, f32::INFINITY] {
        let header = "NDims = 3\nDimSize = 1 1 1\nElementType = MET_FLOAT\n";
        let (_dir, path) = mha(header, &bad.to_le_bytes());
        assert!(matches!(problem(&path), GridProblem::BadValue { .. }));
    }
}

#[test]
fn a_missing_data_file_is_named() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("g.mhd");
    std::fs::write(
        &path,
        format!("{UCHAR_2X2X2}ElementDataFile = nowhere.raw\n"),
    )
    .unwrap();
    let err = read_metaimage(&path).unwrap_err();
    assert!(matches!(err, SceneError::Io { .. }));
    assert!(err.to_string().contains("nowhere.raw"), "{err}");
}

#[test]
fn writer_errors() {
    let dir = TempDir::new().unwrap();
    let g = grid([2, 2, 2], 1);
    let wrong_ext = write_metaimage(&dir.path().join("g.nii"), &g, &MetaImageOptions::default());
    assert!(matches!(
        wrong_ext,
        Err(SceneError::Grid {
            problem: GridProblem::Unsupported { .. },
            ..
        })
    ));
    let mut short = g.clone();
    short.data.pop();
    let err = write_metaimage(
        &dir.path().join("g.mha"),
        &short,
        &MetaImageOptions::default(),
    );
    assert!(matches!(
        err,
        Err(SceneError::Grid {
            problem: GridProblem::DataLength { .. },
            ..
        })
    ));
    let mut fractional = g;
    fractional.data[0] = 0.5;
    let options = MetaImageOptions {
        scalar: ScalarType::U8,
        ..MetaImageOptions::default()
    };
    let err = write_metaimage(&dir.path().join("g.mha"), &fractional, &options);
    assert!(matches!(
        err,
        Err(SceneError::Grid {
            problem: GridProblem::BadValue { .. },
            ..
        })
    ));
}
