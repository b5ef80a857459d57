//! `volpt info`: what a scene loads to, in words (the fields are the library's, `volpt::info`).

use std::path::Path;

use volpt_core::PathSettings;
use volpt_render::factory::Effects;
use volpt_scene::SceneDescription;

pub fn describe(
    path: &Path,
    desc: &SceneDescription,
    effects: Effects,
    settings: &PathSettings,
) -> String {
    volpt::info::describe(&path.display().to_string(), desc, effects, settings).to_string()
}
