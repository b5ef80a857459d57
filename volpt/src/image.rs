//! Images read from files users give (references, images to compare): an OpenEXR file's header
//! is checked against the memory limit before the decoder allocates what it claims.

use std::path::Path;

use volpt_film::Image;

use crate::Error;

/// The first RGB layer of the OpenEXR file at `path`, `what` naming it in errors ("the
/// reference image"); refused before decoding where its header claims more pixels than the
/// memory limit holds.
pub fn read_exr(path: &Path, what: &str) -> Result<Image, Error> {
    // 12 bytes a pixel: the decoded RGB, f32 each.
    volpt_scene::limits::check_exr(path, what, 12)?;
    Ok(Image::read_exr(path)?)
}
