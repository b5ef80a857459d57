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
    let cases: [(&str, &[u8], &str); 7] = [
        (
            "type: uchar\ndimension: 4\nsizes: 3 2 2 2\nencoding: raw\n",
            &[1; 24],
            "a 4D file, RGB, vector or time series, is not read",
        ),
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

/// An RGB page is refused by name, saying what to do: volpt reads one channel, a density.
#[test]
fn an_rgb_tiff_stack_is_refused_naming_its_colour_type() {
    let dir = tempfile::TempDir::new().unwrap();
    let path = dir.path().join("rgb.tif");
    let file = std::fs::File::create(&path).unwrap();
    let mut encoder = tiff::encoder::TiffEncoder::new(file).unwrap();
    encoder
        .write_image::<tiff::encoder::colortype::RGB8>(2, 2, &[7u8; 12])
        .unwrap();
    drop(encoder);
    let error = volpt_scene::read_tiff_stack(&path).unwrap_err().to_string();
    assert!(
        error.contains("RGB") && error.contains("one channel"),
        "{error}"
    );
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

/// `bytes`, an explicit VR little endian DICOM file, as a deflated one (PS3.5 A.5): the file meta
/// group's transfer syntax becomes 1.2.840.10008.1.2.1.99 (its group length follows) and the data
/// set after it is raw-deflated; `edit` changes the data set before.
fn deflated(bytes: &[u8], edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    use std::io::Write;
    assert_eq!(&bytes[128..132], b"DICM");
    let (mut at, mut meta) = (132, Vec::new());
    while u16::from_le_bytes([bytes[at], bytes[at + 1]]) == 0x0002 {
        let (tag, vr) = (&bytes[at..at + 4], &bytes[at + 4..at + 6]);
        let (header, length) = if matches!(vr, b"OB" | b"OW" | b"UN" | b"SQ" | b"UT") {
            let b = &bytes[at + 8..at + 12];
            (12, u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
        } else {
            (
                8,
                usize::from(u16::from_le_bytes([bytes[at + 6], bytes[at + 7]])),
            )
        };
        if tag == [0x02, 0x00, 0x10, 0x00] {
            let uid = b"1.2.840.10008.1.2.1.99";
            meta.extend_from_slice(&bytes[at..at + 6]);
            meta.extend_from_slice(&(uid.len() as u16).to_le_bytes());
            meta.extend_from_slice(uid);
        } else {
            meta.extend_from_slice(&bytes[at..at + header + length]);
        }
        at += header + length;
    }
    // (0002,0000) UL, the group's length after it, is the first element.
    let group_length = (meta.len() - 12) as u32;
    meta[8..12].copy_from_slice(&group_length.to_le_bytes());
    let mut data_set = bytes[at..].to_vec();
    edit(&mut data_set);
    let mut encoder = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::best());
    encoder.write_all(&data_set).unwrap();
    let mut out = bytes[..132].to_vec();
    out.extend_from_slice(&meta);
    out.extend_from_slice(&encoder.finish().unwrap());
    out
}

/// A deflated copy of the axial series, written to a fresh folder, with `edit` applied to each
/// slice's data set.
fn deflated_series(edit: impl Fn(&mut Vec<u8>)) -> tempfile::TempDir {
    let dir = tempfile::TempDir::new().unwrap();
    for entry in std::fs::read_dir(fixture("dicom-axial")).unwrap() {
        let path = entry.unwrap().path();
        let bytes = deflated(&std::fs::read(&path).unwrap(), &edit);
        std::fs::write(dir.path().join(path.file_name().unwrap()), bytes).unwrap();
    }
    dir
}

#[test]
fn a_deflated_dicom_series_reads_as_the_reference_volume() {
    let reference = read_metaimage(&fixture("reference.mha")).unwrap();
    let dir = deflated_series(|_| {});
    assert_eq!(
        volpt_scene::read_dicom_series(dir.path()).unwrap(),
        reference
    );
}

/// The deflated syntax gets the same check: its data set is inflated (real bytes, within the
/// memory limit) and a length it claims beyond them (PixelData claiming almost 4 GiB) is refused
/// before dicom-object would allocate it.
#[test]
fn a_deflated_dicom_element_claiming_4_gib_is_refused_before_parsing() {
    let dir = deflated_series(|data_set| {
        let tag = b"\xe0\x7f\x10\x00OW\x00\x00";
        let at = data_set.windows(tag.len()).position(|w| w == tag).unwrap() + tag.len();
        data_set[at..at + 4].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    });
    let (_, problem) = problem(volpt_scene::read_dicom_series(dir.path()));
    assert!(problem.to_string().contains("(7FE0,0010)"), "{problem}");
}
