//! NRRD, TIFF stacks and DICOM series (written by pynrrd, tifffile and pydicom:
//! `scenes/scanners/make_fixtures.py`) read as the same grid as the `.mha` of the same volume:
//! values, resolution and box bit for bit, whichever way the file orders, mirrors or permutes its
//! axes; and their bad input refused with errors naming the file and field.

use std::path::{Path, PathBuf};

use volpt_scene::{read_metaimage, GridDesc, GridProblem, SceneError};

/// The committed fixtures, or those `scripts/scanner-fixtures.sh` has just written
/// (`VOLPT_SCANNER_FIXTURES`).
fn fixture(name: &str) -> PathBuf {
    match std::env::var_os("VOLPT_SCANNER_FIXTURES") {
        Some(dir) => PathBuf::from(dir).join(name),
        None => Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenes/scanners/fixtures")
            .join(name),
    }
}

fn read(name: &str) -> GridDesc {
    let path = fixture(name);
    let format = volpt_scene::scanner::scanner_format(&path)
        .unwrap()
        .unwrap_or_else(|| panic!("{name}: not a scanner format"));
    volpt_scene::scanner::read_scanned(&path, format)
        .unwrap()
        .unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn problem(result: Result<GridDesc, SceneError>) -> (PathBuf, GridProblem) {
    match result {
        Err(SceneError::Grid { path, problem }) => (path, problem),
        other => panic!("expected a grid error, got {other:?}"),
    }
}

#[test]
fn nrrd_files_read_as_the_reference_volume() {
    let reference = read_metaimage(&fixture("reference.mha")).unwrap();
    // The volume is asymmetric: no value repeats, so any misplaced voxel shows.
    let mut values = reference.data.clone();
    values.sort_by(f32::total_cmp);
    values.dedup();
    assert_eq!(values.len(), reference.data.len());
    for name in [
        "raw.nrrd",
        "gzip.nrrd",
        "detached.nhdr",
        "mirrored-x.nrrd",
        "permuted-xy.nrrd",
    ] {
        assert_eq!(read(name), reference, "{name}");
    }
}

#[test]
fn tiff_stacks_read_as_the_reference_volume_at_the_origin() {
    let reference = read_metaimage(&fixture("reference-origin0.mha")).unwrap();
    for name in [
        "stack-u16.tif",
        "stack-u8-deflate.tif",
        "stack-f32.tif",
        "tiff-folder",
    ] {
        assert_eq!(read(name), reference, "{name}");
    }
}

#[test]
fn dicom_series_read_as_the_reference_volume_in_hounsfield_units_above_air() {
    let reference = read_metaimage(&fixture("reference.mha")).unwrap();
    for name in ["dicom-axial", "dicom-mirrored", "dicom-coronal"] {
        assert_eq!(read(name), reference, "{name}");
    }
}

#[test]
fn a_compressed_dicom_transfer_syntax_is_refused_by_name() {
    let (_, problem) = problem(volpt_scene::read_dicom_series(&fixture("dicom-jpeg")));
    let message = problem.to_string();
    assert!(
        message.contains("1.2.840.10008.1.2.4.50") && message.contains("JPEG Baseline"),
        "{message}"
    );
}

#[test]
fn a_dicom_series_missing_a_slice_is_refused_naming_the_files() {
    let dir = tempfile::TempDir::new().unwrap();
    for name in ["IM0001", "IM0002", "IM0004"] {
        std::fs::copy(fixture("dicom-axial").join(name), dir.path().join(name)).unwrap();
    }
    let (path, problem) = problem(volpt_scene::read_dicom_series(dir.path()));
    let message = problem.to_string();
    assert!(message.contains("ImagePositionPatient"), "{message}");
    assert!(message.contains("evenly spaced"), "{message}");
    // Sorted by position: IM0004, IM0002 (the gap), IM0001.
    assert!(path.ends_with("IM0002"), "{path:?}");
    assert!(message.contains("after IM0004"), "{message}");
}

#[test]
fn two_dicom_series_in_one_folder_are_refused() {
    let dir = tempfile::TempDir::new().unwrap();
    std::fs::copy(fixture("dicom-axial/IM0001"), dir.path().join("a")).unwrap();
    std::fs::copy(fixture("dicom-mirrored/slice0.dcm"), dir.path().join("b")).unwrap();
    let (_, problem) = problem(volpt_scene::read_dicom_series(dir.path()));
    assert!(
        problem.to_string().contains("SeriesInstanceUID"),
        "{problem}"
    );
}

/// An NRRD header with the given fields and data after it.
fn nrrd(dir: &Path, fields: &str, data: &[u8]) -> PathBuf {
    let path = dir.join("g.nrrd");
    let mut bytes = format!("NRRD0004\n{fields}\n").into_bytes();
    bytes.extend_from_slice(data);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn an_nrrd_header_declaring_more_than_the_memory_limit_is_refused_before_allocating() {
    let dir = tempfile::TempDir::new().unwrap();
    let path = nrrd(
        dir.path(),
        "type: float\ndimension: 3\nsizes: 100000 100000 100000\nendian: little\nencoding: raw\n",
        &[0; 16],
    );
    let err = volpt_scene::read_nrrd(&path).unwrap_err();
    assert!(
        matches!(
            err,
            SceneError::Grid { .. } | SceneError::OverMemoryLimit { .. }
        ),
        "{err}"
    );
}

#[test]
fn nrrd_errors_name_the_field_expected_and_found() {
    let dir = tempfile::TempDir::new().unwrap();
    let cases: [(&str, &[u8], &str); 6] = [
        (
            "type: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
            &[1; 7],
            "voxel data",
        ),
        (
            "type: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n",
            &[1; 8],
            "bzip2",
        ),
        (
            "type: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n",
            &[1; 16],
            "endian",
        ),
        (
            "type: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspace directions: (1,1,0) (0,1,0) (0,0,1)\n",
            &[1; 8],
            "axis-aligned",
        ),
        (
            "type: uchar\ndimension: 3\nsizes: 200 200 200\nencoding: gzip\n",
            &[1; 1],
            "deflate's limit",
        ),
        (
            "type: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n",
            &[0x1f, 0x8b, 8, 0],
            "decompressed voxel data",
        ),
    ];
    for (fields, data, expected) in cases {
        let path = nrrd(dir.path(), fields, data);
        let err = volpt_scene::read_nrrd(&path).unwrap_err().to_string();
        assert!(err.contains(expected), "{fields}: {err}");
        assert!(err.contains("g.nrrd"), "{err}");
    }
}

#[test]
fn a_folder_is_not_read_as_an_nrrd_file() {
    let dir = tempfile::TempDir::new().unwrap();
    let folder = dir.path().join("x.nrrd");
    std::fs::create_dir(&folder).unwrap();
    let err = volpt_scene::read_nrrd(&folder).unwrap_err();
    assert!(matches!(err, SceneError::NotAFile { .. }), "{err}");
}

#[test]
fn a_tiff_stack_whose_pages_differ_in_size_is_refused() {
    let dir = tempfile::TempDir::new().unwrap();
    std::fs::copy(fixture("stack-u16.tif"), dir.path().join("a.tif")).unwrap();
    std::fs::copy(fixture("tiff-folder/slice_8.tif"), dir.path().join("b.tif")).unwrap();
    // Same size: a stack of 4 + 1 pages reads.
    assert_eq!(
        volpt_scene::read_tiff_stack(dir.path()).unwrap().resolution,
        [5, 3, 5]
    );
    std::fs::copy(fixture("raw.nrrd"), dir.path().join("c.tif")).unwrap();
    let (path, problem) = problem(volpt_scene::read_tiff_stack(dir.path()));
    assert!(path.ends_with("c.tif"), "{path:?}: {problem}");
}

/// dicom-object allocates a value's declared length before reading it: a length beyond the file
/// (here PixelData claiming almost 4 GiB) is refused before the file reaches it.
#[test]
fn a_dicom_element_longer_than_its_file_is_refused_before_parsing() {
    let mut bytes = std::fs::read(fixture("dicom-axial/IM0001")).unwrap();
    let tag = b"\xe0\x7f\x10\x00OW\x00\x00";
    let at = bytes.windows(tag.len()).position(|w| w == tag).unwrap() + tag.len();
    bytes[at..at + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    let dir = tempfile::TempDir::new().unwrap();
    std::fs::write(dir.path().join("IM0001"), bytes).unwrap();
    let (_, problem) = problem(volpt_scene::read_dicom_series(dir.path()));
    assert!(problem.to_string().contains("(7FE0,0010)"), "{problem}");
}
