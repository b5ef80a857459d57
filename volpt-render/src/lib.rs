//! From a scene description to an image on the CPU.
//!
//! - [`factory`]: which monomorphised scene variant a description needs, and building it.
//! - [`cpu`]: the CPU backend, rayon over the shared path step.
//! - [`image`]: the film's result and its EXR/PNG files.

pub mod cpu;
pub mod factory;
pub mod image;

pub use cpu::{render, RenderError, RenderOptions, RenderStats};
pub use factory::{path_settings, with_scene, SceneVisitor, Variant};
pub use image::{Image, ImageError};
