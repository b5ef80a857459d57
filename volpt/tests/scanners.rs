//! Scanner volumes (NRRD, TIFF stacks, DICOM series written by pynrrd, tifffile and pydicom:
//! `scenes/scanners/make_fixtures.py`) render on the CPU bit for bit as the same volume from
//! `.mha`, from a TOML scene with a transfer function, a Mitsuba `gridvolume`, and on their own
//! (`volpt render FILE_OR_FOLDER`).

mod common;

use common::render;

use std::path::{Path, PathBuf};

use volpt::{RenderSettings, Scene};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/scanners")
}

/// The committed fixtures, or those `scripts/scanner-fixtures.sh` has just written
/// (`VOLPT_SCANNER_FIXTURES`).
fn fixture(name: &str) -> PathBuf {
    match std::env::var_os("VOLPT_SCANNER_FIXTURES") {
        Some(dir) => PathBuf::from(dir).join(name),
        None => scenes().join("fixtures").join(name),
    }
}

fn settings(params: &[(&str, &Path)]) -> RenderSettings {
    RenderSettings {
        resolution: Some((16, 16)),
        spp: Some(4),
        seed: 7,
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), v.display().to_string()))
            .collect(),
        ..RenderSettings::default()
    }
}

const NRRD: [&str; 5] = [
    "raw.nrrd",
    "gzip.nrrd",
    "detached.nhdr",
    "mirrored-x.nrrd",
    "permuted-xy.nrrd",
];
const TIFF: [&str; 4] = [
    "stack-u16.tif",
    "stack-u8-deflate.tif",
    "stack-f32.tif",
    "tiff-folder",
];
const DICOM: [&str; 3] = ["dicom-axial", "dicom-mirrored", "dicom-coronal"];

#[test]
fn every_scanner_fixture_renders_as_the_metaimage_through_a_toml_scene() {
    let load = |name: &str| {
        let file = fixture(name);
        Scene::load(scenes().join("scene.toml"), &settings(&[("volume", &file)]))
            .unwrap_or_else(|e| panic!("{name}: {e:#}"))
    };
    let expected = render(&load("reference.mha"));
    assert!(expected.sums.iter().any(|s| s[0] > 0.0));
    for name in NRRD.iter().chain(&TIFF).chain(&DICOM) {
        assert_eq!(render(&load(name)).sums, expected.sums, "{name}");
    }
}

#[test]
fn nrrd_and_dicom_render_alike_as_a_mitsuba_gridvolume_in_their_own_box() {
    let load = |name: &str| {
        let file = fixture(name);
        Scene::load(scenes().join("scene.xml"), &settings(&[("volume", &file)]))
            .unwrap_or_else(|e| panic!("{name}: {e:#}"))
    };
    let expected = render(&load("raw.nrrd"));
    assert!(expected.sums.iter().any(|s| s[0] > 0.0));
    // An empty cube would transmit the environment unchanged: the volume is seen.
    let background = expected.sums.iter().map(|s| s[0]).fold(0.0f64, f64::max);
    assert!(
        expected.sums.iter().any(|s| s[0] < background),
        "no volume in view"
    );
    for name in NRRD.iter().skip(1).chain(&DICOM) {
        assert_eq!(render(&load(name)).sums, expected.sums, "{name}");
    }
}

#[test]
fn a_bare_file_or_folder_renders_as_the_metaimage() {
    let load = |name: &str| {
        Scene::load(fixture(name), &settings(&[])).unwrap_or_else(|e| panic!("{name}: {e:#}"))
    };
    let expected = render(&load("reference.mha"));
    for name in ["raw.nrrd", "dicom-axial", "dicom-coronal"] {
        assert_eq!(render(&load(name)).sums, expected.sums, "{name}");
    }
    let expected = render(&load("reference-origin0.mha"));
    for name in TIFF {
        assert_eq!(render(&load(name)).sums, expected.sums, "{name}");
    }
}
