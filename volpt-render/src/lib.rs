//! From a scene description to an image on the CPU.
//!
//! - [`factory`]: which monomorphised scene variant a description needs, and building it.
//! - [`cpu`]: the CPU backend, rayon over the shared path step.
//!
//! What a render produces (the film, the image and its files, the statistics) is `volpt-film`'s,
//! shared with the GPU backend; it is re-exported here for convenience.

pub mod cpu;
pub mod factory;

pub use cpu::{render, render_samples, RenderError};
pub use factory::{
    path_settings, with_scene, with_scene_as, Effects, RenderScene, SceneVisitor, Variant,
};
pub use volpt_film::{image, Checkpoint, Film, Image, ImageError, RenderOptions, RenderStats};
