//! Whether `f32` arithmetic can render a scene: a render-ready scene is checked once, before any
//! path is traced, so that a scene volpt cannot resolve is a clear error, never a wrong image.
//!
//! Paths store positions in `f32`. A scattering point `x + t * d` is rounded to the spacing of the
//! `f32` values near it, `ulp(|x|)`; when free flights are only a few spacings long, flights into
//! the medium are rounded away and paths pile up on the boundary they entered by (a thick
//! albedo-0.9 cube measures its correct 0.602 up to extinction 3e6 in a unit box, 0.608 at 1e7,
//! 0.637 at 3e7 and 0.755 at 1e8). The mean free path at the majorant must therefore span at least
//! [`MIN_FREE_PATH_SPACINGS`] position spacings of the box. The same holds for a unit box at world
//! coordinates 1e5 (spacing 0.0078) with an extinction above ~8. A scene can always be rescaled
//! into range: a larger box with a proportionally lower extinction has the same optical thickness.

use std::path::Path;

use crate::description::{Bounds, MediumDesc, SceneDescription};
use crate::error::SceneError;
use crate::validate::CheckedData;

/// Shortest mean free path volpt renders, in `f32` position spacings of the box. At 16 the thick
/// cube above is unbiased (within 3e-4); at 2 it is 1% too bright.
pub const MIN_FREE_PATH_SPACINGS: f32 = 16.0;

/// The spacing of `f32` positions in the box: the gap between the largest coordinate magnitude
/// and the next larger `f32`.
pub fn position_spacing(bounds: &Bounds) -> f32 {
    let largest = bounds
        .min
        .iter()
        .chain(&bounds.max)
        .fold(0.0f32, |m, c| m.max(c.abs()));
    f32::from_bits(largest.to_bits() + 1) - largest
}

/// The largest extinction of the medium (delta tracking's majorant).
pub fn max_extinction(medium: &MediumDesc) -> f32 {
    medium.max_extinction()
}

/// Refuses a scene whose mean free path is too short for `f32` positions in its box (or whose
/// extinction is not finite); `source` names the scene in the error.
pub fn check_position_resolution(desc: &SceneDescription, source: &Path) -> Result<(), SceneError> {
    check_free_path(desc, source, max_extinction(&desc.medium))
}

/// [`check_position_resolution`] for a scene whose data `checked` says was checked
/// ([`crate::validate::validate`]): its grids' largest values taken from `checked`, not read
/// again (a viewer moves the camera at every frame, and reading a print's grid took longer than
/// the frame's render).
pub fn check_position_resolution_settings(
    desc: &SceneDescription,
    source: &Path,
    checked: CheckedData,
) -> Result<(), SceneError> {
    let [(_, largest_density), _] = desc.medium.largest_values(checked);
    check_free_path(desc, source, desc.medium.scale * largest_density)
}

/// The check of both: the mean free path at `majorant` against the box's position spacing.
fn check_free_path(
    desc: &SceneDescription,
    source: &Path,
    majorant: f32,
) -> Result<(), SceneError> {
    let spacing = position_spacing(&desc.boundary.bounds);
    let free_path = 1.0 / majorant;
    // Written so that a NaN extinction fails too.
    if free_path >= MIN_FREE_PATH_SPACINGS * spacing {
        return Ok(());
    }
    let largest = spacing / f32::EPSILON;
    Err(SceneError::InvalidValue {
        path: source.to_owned(),
        line: 0,
        field: "medium extinction (scale x density)".into(),
        expected: format!(
            "a finite extinction whose mean free path spans at least {MIN_FREE_PATH_SPACINGS} \
             f32 position steps of the medium's box (coordinates up to ~{largest:.3e} are {spacing:.3e} \
             apart, so an extinction of at most {:.3e}); rescale the scene: a larger box with a \
             proportionally lower extinction has the same optical thickness",
            1.0 / (MIN_FREE_PATH_SPACINGS * spacing)
        ),
        found: format!(
            "a largest extinction of {majorant:e}, whose mean free path {free_path:.3e} is {:.3} \
             position steps; volpt would render it wrongly (free flights rounded away)",
            free_path / spacing
        ),
    })
}
