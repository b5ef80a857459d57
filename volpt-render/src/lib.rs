//! From a scene description to a render-ready scene.
//!
//! - [`factory`]: which monomorphised scene variant a description needs, and building it, for any
//!   backend (a [`SceneVisitor`] receives the scene).
//!
//! For convenience it re-exports the CPU backend (`volpt-cpu`) and what a render produces, on any
//! backend (`volpt-film`: the film, the image and its files, the statistics).

pub mod factory;

pub use factory::{
    path_settings, with_scene, with_scene_as, with_scene_cached, Effects, FactoryCache,
    RenderScene, SceneVisitor, Variant,
};
pub use volpt_cpu::{render, render_samples, RenderError};
pub use volpt_film::{
    image, Accumulation, Checkpoint, Film, Image, ImageError, RenderOptions, RenderStats,
};
