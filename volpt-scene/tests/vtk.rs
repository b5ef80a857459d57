//! VTK image data (legacy `.vtk`, XML `.vti`) reading and writing.

use std::path::{Path, PathBuf};

use tempfile::TempDir;
use volpt_scene::{read_vtk, write_vtk, Bounds, GridConvention, GridDesc, GridProblem, SceneError};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, DataArray, DataSet, ElementType, Extent, ImageDataPiece,
    Piece, Version,
};
use vtkio::{IOBuffer, Vtk};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/vtk")
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
        data: (0..n).map(|i| i as f32 * 0.25).collect(),
    }
}

fn assert_close(a: Bounds, b: Bounds) {
    for (x, y) in a.min.iter().chain(&a.max).zip(b.min.iter().chain(&b.max)) {
        assert!((x - y).abs() <= 1e-5 * (1.0 + y.abs()), "{a:?} vs {b:?}");
    }
}

fn problem(path: &Path, array: Option<&str>) -> GridProblem {
    match read_vtk(path, array) {
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

fn text_file(name: &str, text: &str) -> (TempDir, PathBuf) {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

/// An image-data model with one point-data scalar array.
fn model(dims: [u32; 3], data: IOBuffer, byte_order: ByteOrder, xml: bool) -> Vtk {
    let extent = if xml {
        Extent::Ranges([
            0..=dims[0] as i32 - 1,
            0..=dims[1] as i32 - 1,
            0..=dims[2] as i32 - 1,
        ])
    } else {
        Extent::Dims(dims)
    };
    Vtk {
        version: Version::new((4, 2)),
        title: "test".into(),
        byte_order,
        file_path: None,
        data: DataSet::ImageData {
            extent: extent.clone(),
            origin: [0.0; 3],
            spacing: [1.0; 3],
            meta: None,
            pieces: vec![Piece::Inline(Box::new(ImageDataPiece {
                extent,
                data: Attributes {
                    point: vec![Attribute::DataArray(DataArray {
                        name: "values".into(),
                        elem: ElementType::Scalars {
                            num_comp: 1,
                            lookup_table: None,
                        },
                        data,
                    })],
                    cell: Vec::new(),
                },
            }))],
        },
    }
}

#[test]
fn legacy_and_xml_round_trip_one_and_three_channels() {
    let dir = TempDir::new().unwrap();
    for channels in [1, 3] {
        let original = grid([3, 2, 2], channels);
        for ext in ["vtk", "vti"] {
            let path = dir.path().join(format!("g{channels}.{ext}"));
            write_vtk(&path, &original, "density").unwrap();
            let read = read_vtk(&path, None).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(read.resolution, original.resolution);
            assert_eq!(read.channels, channels);
            assert_eq!(read.data, original.data);
            assert_close(read.bounds, original.bounds);
            assert_eq!(
                read_vtk(&path, Some("density")).unwrap().data,
                original.data
            );
        }
    }
}

#[test]
fn every_element_type_and_byte_order() {
    let dir = TempDir::new().unwrap();
    let buffers = [
        IOBuffer::U8(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::I8(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::U16(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::I16(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::U32(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::I32(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::U64(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::I64(vec![0, 1, 2, 3, 4, 5, 6, 7]),
        IOBuffer::F32(vec![0., 1., 2., 3., 4., 5., 6., 7.]),
        IOBuffer::F64(vec![0., 1., 2., 3., 4., 5., 6., 7.]),
    ];
    let expected: Vec<f32> = (0..8).map(|i| i as f32).collect();
    for (i, buffer) in buffers.into_iter().enumerate() {
        for (order_name, order) in [
            ("le", ByteOrder::LittleEndian),
            ("be", ByteOrder::BigEndian),
        ] {
            for ext in ["vtk", "vti"] {
                if ext == "vtk" && order == ByteOrder::LittleEndian {
                    continue; // legacy binary files are big-endian by definition
                }
                let path = dir.path().join(format!("t{i}-{order_name}.{ext}"));
                let vtk = model([2, 2, 2], buffer.clone(), order, ext == "vti");
                vtk.export(&path).unwrap();
                let read =
                    read_vtk(&path, None).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                assert_eq!(read.data, expected, "{}", path.display());
            }
        }
    }
}

#[test]
fn legacy_ascii_fixture_and_named_arrays() {
    let path = fixture("tiny_ascii.vtk");
    let density = read_vtk(&path, None).unwrap();
    assert_eq!(density.resolution, [2, 2, 2]);
    assert_eq!(density.data, (0..8).map(|i| i as f32).collect::<Vec<_>>());
    assert_eq!(density.bounds.min, [0.75, 1.75, 2.75]);
    assert_eq!(density.bounds.max, [1.75, 2.75, 3.75]);
    let temperature = read_vtk(&path, Some("temperature")).unwrap();
    assert_eq!(
        temperature.data,
        (10..18).map(|i| i as f32).collect::<Vec<_>>()
    );
    let p = problem(&path, Some("pressure"));
    assert!(p.to_string().contains("pressure"), "{p}");
}

#[test]
fn xml_ascii_fixture_with_an_offset_extent() {
    let grid = read_vtk(&fixture("tiny_ascii.vti"), None).unwrap();
    assert_eq!(grid.resolution, [2, 2, 1]);
    assert_eq!(grid.channels, 3);
    assert_eq!(grid.data[..3], [0.1, 0.2, 0.3]);
    // Extent starts at x = 1: the first voxel's centre is at 1 * spacing.
    assert_eq!(grid.bounds.min, [0.5, -1.0, -1.5]);
    assert_eq!(grid.bounds.max, [2.5, 3.0, 1.5]);
}

const LEGACY_HEAD: &str = "# vtk DataFile Version 3.0\ntest\nASCII\nDATASET STRUCTURED_POINTS\n";

#[test]
fn huge_declared_sizes_are_refused_before_vtkio_reads_them() {
    let text = format!(
        "{LEGACY_HEAD}DIMENSIONS 100000 100000 100000\nORIGIN 0 0 0\nSPACING 1 1 1\n\
         POINT_DATA 1000000000000000\nSCALARS d float 1\nLOOKUP_TABLE default\n0 1\n"
    );
    let (_dir, path) = text_file("huge.vtk", &text);
    assert!(matches!(problem(&path, None), GridProblem::TooLarge { .. }));

    let text = format!(
        "{LEGACY_HEAD}DIMENSIONS 1000 1000 1000\nORIGIN 0 0 0\nSPACING 1 1 1\n\
         POINT_DATA 1000000000\nSCALARS d double 3\nLOOKUP_TABLE default\n0 1\n"
    );
    let (_dir, path) = text_file("big.vtk", &text);
    assert!(matches!(
        problem(&path, None),
        GridProblem::SizeMismatch { .. }
    ));

    let text = std::fs::read_to_string(fixture("tiny_ascii.vti"))
        .unwrap()
        .replace(
            "WholeExtent=\"1 2 0 1 0 0\"",
            "WholeExtent=\"0 99999 0 99999 0 99999\"",
        );
    let (_dir, path) = text_file("huge.vti", &text);
    assert!(matches!(problem(&path, None), GridProblem::TooLarge { .. }));
}

#[test]
fn array_length_must_match_the_dimensions() {
    let text = format!(
        "{LEGACY_HEAD}DIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\n\
         POINT_DATA 4\nSCALARS d float 1\nLOOKUP_TABLE default\n0 1 2 3\n"
    );
    let (_dir, path) = text_file("short.vtk", &text);
    let p = problem(&path, None);
    assert!(matches!(p, GridProblem::SizeMismatch { .. }), "{p}");
}

#[test]
fn negative_and_nan_values_are_errors() {
    let text = format!(
        "{LEGACY_HEAD}DIMENSIONS 2 1 1\nORIGIN 0 0 0\nSPACING 1 1 1\n\
         POINT_DATA 2\nSCALARS d float 1\nLOOKUP_TABLE default\n0 -1\n"
    );
    let (_dir, path) = text_file("negative.vtk", &text);
    assert!(matches!(
        problem(&path, None),
        GridProblem::BadValue {
            voxel: [1, 0, 0],
            ..
        }
    ));

    let dir = TempDir::new().unwrap();
    let mut g = grid([2, 1, 1], 1);
    for bad in [f32::NAN, f32::INFINITY] {
        g.data[1] = bad;
        for ext in ["vtk", "vti"] {
            let path = dir.path().join(format!("bad.{ext}"));
            write_vtk(&path, &g, "d").unwrap();
            assert!(matches!(problem(&path, None), GridProblem::BadValue { .. }));
        }
    }
}

#[test]
fn malformed_and_unsupported_files() {
    let (_dir, path) = text_file("garbage.vtk", "this is not a VTK file\n");
    assert!(matches!(problem(&path, None), GridProblem::Decode { .. }));
    let (_dir, path) = text_file("garbage.vti", "<VTKFile type=\"ImageData\"><oops");
    assert!(matches!(problem(&path, None), GridProblem::Decode { .. }));

    let poly = "# vtk DataFile Version 3.0\nt\nASCII\nDATASET POLYDATA\nPOINTS 1 float\n0 0 0\n";
    let (_dir, path) = text_file("poly.vtk", poly);
    let p = problem(&path, None);
    assert!(
        matches!(
            p,
            GridProblem::Unsupported { .. } | GridProblem::Decode { .. }
        ),
        "{p}"
    );

    let xml = std::fs::read_to_string(fixture("tiny_ascii.vti")).unwrap();
    let compressed = xml.replace(
        "byte_order=\"LittleEndian\"",
        "byte_order=\"LittleEndian\" compressor=\"vtkZLibDataCompressor\"",
    );
    let (_dir, path) = text_file("compressed.vti", &compressed);
    assert!(matches!(
        problem(&path, None),
        GridProblem::Unsupported { .. }
    ));

    let rotated = xml.replace(
        "Spacing=\"1 2 3\"",
        "Spacing=\"1 2 3\" Direction=\"0 1 0 1 0 0 0 0 1\"",
    );
    let (_dir, path) = text_file("rotated.vti", &rotated);
    assert!(matches!(
        problem(&path, None),
        GridProblem::Unsupported { .. }
    ));

    let (_dir, path) = text_file("grid.nrrd", "NRRD0004\n");
    assert!(matches!(
        problem(&path, None),
        GridProblem::Unsupported { .. }
    ));
}

#[test]
fn truncated_binary_data_is_an_error() {
    let dir = TempDir::new().unwrap();
    for ext in ["vtk", "vti"] {
        let path = dir.path().join(format!("full.{ext}"));
        write_vtk(&path, &grid([4, 4, 4], 1), "d").unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let cut = dir.path().join(format!("cut.{ext}"));
        std::fs::write(&cut, &bytes[..bytes.len() * 2 / 3]).unwrap();
        let p = problem(&cut, None);
        assert!(
            matches!(
                p,
                GridProblem::Decode { .. }
                    | GridProblem::SizeMismatch { .. }
                    | GridProblem::BadField { .. }
            ),
            "{p}"
        );
    }
}

#[test]
fn appended_data_that_ends_early_is_an_error_not_a_panic() {
    let text = "<?xml version=\"1.0\"?>\n\
        <VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
        <ImageData WholeExtent=\"0 1 0 0 0 0\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n\
        <Piece Extent=\"0 1 0 0 0 0\"><PointData>\n\
        <DataArray type=\"Float32\" Name=\"d\" format=\"appended\" offset=\"0\"/>\n\
        </PointData><CellData></CellData></Piece></ImageData>\n\
        <AppendedData encoding=\"raw\">_ab</AppendedData>\n</VTKFile>\n";
    let (_dir, path) = text_file("appended.vti", text);
    let p = problem(&path, None);
    assert!(matches!(p, GridProblem::Decode { .. }), "{p}");
}

/// The legacy prescan names the line of the declaration it refuses (line 9: the head takes four
/// lines).
#[test]
fn a_refused_legacy_declaration_names_its_line() {
    let text = format!(
        "{LEGACY_HEAD}DIMENSIONS 2 1 1\nORIGIN 0 0 0\nSPACING 1 1 1\n\
         POINT_DATA 2\nSCALARS d float 1000\nLOOKUP_TABLE default\n0 1\n"
    );
    let (_dir, path) = text_file("wide.vtk", &text);
    let p = problem(&path, None);
    assert!(
        p.to_string()
            .contains("line 9: SCALARS declares 2000 values"),
        "{p}"
    );
}

/// An explicit identity `Direction` is an axis-aligned grid (any other matrix is refused, see
/// `malformed_and_unsupported_files`).
#[test]
fn an_identity_direction_is_accepted() {
    let xml = std::fs::read_to_string(fixture("tiny_ascii.vti")).unwrap();
    let aligned = xml.replace(
        "Spacing=\"1 2 3\"",
        "Spacing=\"1 2 3\" Direction=\"1 0 0  0 1 0  0 0 1\"",
    );
    let (_dir, path) = text_file("aligned.vti", &aligned);
    let grid = read_vtk(&path, None).expect("identity direction");
    assert_eq!(grid, read_vtk(&fixture("tiny_ascii.vti"), None).unwrap());
}

/// A piece's extent is checked like the whole extent: a huge one is refused before vtkio
/// reserves memory for it.
#[test]
fn a_huge_piece_extent_is_refused_before_vtkio_reads_it() {
    let text = std::fs::read_to_string(fixture("tiny_ascii.vti"))
        .unwrap()
        .replace(
            "Piece Extent=\"1 2 0 1 0 0\"",
            "Piece Extent=\"0 99999 0 99999 0 99999\"",
        );
    let (_dir, path) = text_file("huge_piece.vti", &text);
    let p = problem(&path, None);
    assert!(matches!(p, GridProblem::TooLarge { .. }), "{p}");
}

/// A `DataArray` without `NumberOfTuples` has one tuple per point of its piece: 3 components x
/// 200 points declare 600 values, more than this file's bytes, where one tuple would be 3.
#[test]
fn an_array_without_a_tuple_count_has_one_tuple_per_point() {
    let text = "<?xml version=\"1.0\"?>\n\
        <VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
        <ImageData WholeExtent=\"0 9 0 9 0 1\" Origin=\"0 0 0\" Spacing=\"1 1 1\">\n\
        <Piece Extent=\"0 9 0 9 0 1\"><PointData>\n\
        <DataArray type=\"UInt8\" Name=\"d\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0\
        </DataArray>\n</PointData></Piece></ImageData></VTKFile>\n";
    // The extent's 200 points fit the file's bytes; 600 values do not.
    assert!((200..600).contains(&text.len()), "{}", text.len());
    let (_dir, path) = text_file("short.vti", text);
    let p = problem(&path, None);
    assert!(
        p.to_string().contains("DataArray declares 600 values"),
        "{p}"
    );
}

/// A bare grid file renders in the unit cube: its box (2 x 1 x 4 here) scaled so that the longest
/// side is 1, centred at the origin, aspect kept.
#[test]
fn a_bare_grid_file_is_fitted_into_the_unit_cube() {
    let dir = TempDir::new().unwrap();
    let path = dir.path().join("tall.vti");
    let mut g = grid([2, 1, 4], 1);
    g.bounds = Bounds {
        min: [3.0, -1.0, 0.0],
        max: [5.0, 0.0, 4.0],
    };
    write_vtk(&path, &g, "d").unwrap();
    let desc = volpt_scene::SceneAssembler::new(volpt_scene::Config::default())
        .assemble(volpt_scene::builder_for(&path).unwrap().as_ref())
        .expect("a grid file loads");
    let fitted = Bounds {
        min: [-0.25, -0.125, -0.5],
        max: [0.25, 0.125, 0.5],
    };
    assert_close(desc.boundary.bounds, fitted);
    let volpt_scene::DensityDesc::Grid(density) = &desc.medium.density else {
        panic!("a grid file gives a grid density");
    };
    assert_close(density.bounds, fitted);
}
