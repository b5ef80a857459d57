//! Writing the files volpt produces from scenes (generated inputs, exported scenes), with errors
//! that name the path.

use std::path::Path;

use exr::prelude::IntoSample;

use crate::error::SceneError;

/// `std::fs::create_dir_all`, its error naming `dir`.
pub(crate) fn create_dir(dir: &Path) -> Result<(), SceneError> {
    std::fs::create_dir_all(dir).map_err(|error| SceneError::Io {
        path: dir.to_owned(),
        error,
    })
}

/// Writes an RGB OpenEXR image whose pixel `(x, y)` (from the top-left) is `pixel(x, y)`, in the
/// sample type `pixel` returns (`f32` or `f16`).
pub(crate) fn write_rgb_exr<R, G, B>(
    path: &Path,
    width: usize,
    height: usize,
    pixel: impl Sync + Fn(usize, usize) -> (R, G, B),
) -> Result<(), SceneError>
where
    R: IntoSample,
    G: IntoSample,
    B: IntoSample,
{
    exr::prelude::write_rgb_file(path, width, height, pixel).map_err(|e| SceneError::Io {
        path: path.to_owned(),
        error: match e {
            exr::error::Error::Io(error) => error,
            other => std::io::Error::other(other.to_string()),
        },
    })
}
