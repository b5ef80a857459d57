//! volpt's scenes: the plain-data description a renderer consumes, and the loaders that build it.
//!
//! - [`description`]: the scene as plain data ([`SceneDescription`]).
//! - [`error`]: what can go wrong loading one ([`SceneError`]); every message names the file and,
//!   for XML, the line.
//! - [`vol`]: Mitsuba's `.vol` grid files, read and written.
//! - [`mitsuba`]: Mitsuba 0.5/0.6 and Mitsuba 3 XML scene files.
//! - [`generate`]: the thesis's printed-block grids (`cgg-logo`, `ad`), generated rather than stored.

pub mod description;
pub mod error;
pub mod generate;
pub mod mitsuba;
pub mod vol;

use std::path::Path;

pub use description::*;
pub use error::{SceneError, VolProblem};
pub use vol::{read_vol, write_vol, VolGrid};

/// Loads a Mitsuba XML scene with the `<default>` values it declares.
pub fn load_mitsuba(path: &Path) -> Result<SceneDescription, SceneError> {
    mitsuba::load(path, &[])
}

/// Loads a Mitsuba XML scene; `params` are `(name, value)` pairs, as `mitsuba -D name=value`
/// passes them, and take precedence over the scene's `<default>`s.
pub fn load_mitsuba_with(
    path: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription, SceneError> {
    mitsuba::load(path, params)
}
