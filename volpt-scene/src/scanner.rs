//! The scanners' formats by path: which reader reads a file or folder that a scene names without
//! saying its format (`volpt render FOLDER`, a Mitsuba `gridvolume`'s `filename`).

use std::path::Path;

use crate::description::GridDesc;
use crate::error::SceneError;
use crate::toml_scene::VolumeFormat;

/// The scanner format of `path` (by extension; a folder: a TIFF stack if it holds TIFF files,
/// else a DICOM series), or `None` for any other file.
pub fn scanner_format(path: &Path) -> Result<Option<VolumeFormat>, SceneError> {
    Ok(if crate::nrrd::is_nrrd(path) {
        Some(VolumeFormat::Nrrd)
    } else if crate::tiff_stack::is_tiff(path) {
        Some(VolumeFormat::Tiff)
    } else if crate::dicom::is_dicom(path) {
        Some(VolumeFormat::Dicom)
    } else if path.is_dir() {
        Some(if crate::tiff_stack::stack_files(path)?.is_empty() {
            VolumeFormat::Dicom
        } else {
            VolumeFormat::Tiff
        })
    } else {
        None
    })
}

/// Reads `path` in a scanner `format`; `None` for volpt's other formats.
pub fn read_scanned(path: &Path, format: VolumeFormat) -> Option<Result<GridDesc, SceneError>> {
    Some(match format {
        VolumeFormat::Nrrd => crate::nrrd::read_nrrd(path),
        VolumeFormat::Tiff => crate::tiff_stack::read_tiff_stack(path),
        VolumeFormat::Dicom => crate::dicom::read_dicom_series(path),
        _ => return None,
    })
}
