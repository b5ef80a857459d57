//! `volpt info`: what a scene loads to, in words (the fields are the library's, `volpt::info`).

use std::path::Path;

use volpt::{Effects, PathSettings, SceneDescription};

pub fn describe(
    path: &Path,
    desc: &SceneDescription,
    effects: Effects,
    settings: &PathSettings,
) -> String {
    volpt::info::describe(&path.display().to_string(), desc, effects, settings).to_string()
}
