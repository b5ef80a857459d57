//! volpt as a library: render solid participating media from the files users already have.
//!
//! ```no_run
//! use volpt::{Backend, BackendOptions, Film, RenderSettings, Scene};
//!
//! let scene = Scene::load("scenes/example/cube.xml", &RenderSettings::default())?;
//! let backend = Backend::open(&BackendOptions::default())?; // the CPU; `BackendKind::Cuda` for a GPU
//! let mut film = scene.film();
//! backend.render(&scene, &mut film, 0..scene.spp(), &volpt::Quiet)?;
//! film.image(scene.spp()).write_exr("cube.exr".as_ref())?;
//! # Ok::<(), volpt::Error>(())
//! ```
//!
//! The modules, each re-exported here for what its callers use:
//!
//! - `settings`: [`RenderSettings`], what a user overrides of a scene file's values (scene file <
//!   settings), resolved once when a scene is loaded.
//! - `scene`: [`Scene`], a loaded scene with its resolved settings, its fingerprint and the
//!   parameters that change between renders without reloading its grids ([`Scene::set`]), and
//!   its grids, replaceable ([`Scene::set_grid`]).
//! - `backend`: [`Backend`], the CPU or a GPU with its strategy (or `auto`), math and memory
//!   placement, opened once and reused; [`Backend::render`] adds a request's samples to a
//!   [`Film`].
//! - `preferred`: the backend of a caller who names none where a GPU is the better default (a
//!   GPU where one is usable, else the CPU, and why: [`Backend::open_preferred`]).
//! - `request`: [`RenderRequest`], one render's samples, seed, path settings and lookup over
//!   the scene's: renders only read the scene, so threads share one.
//! - `observer`: what a render tells its caller while it runs (progress, notes) and how the
//!   caller stops it ([`Observer`]).
//! - `auto`: the `auto` strategy: calibration renders, a cache per scene and GPU ([`registers`]
//!   names a register cap as its reports do).
//! - `checkpoint`: long renders saved as they go and resumed bit for bit ([`render_checkpointed`]);
//!   films of disjoint sample ranges ([`Part`]) merged, saved, read and passed as bytes.
//! - `films`: films of sample ranges rendered anywhere, read from their files and merged.
//! - `multi`: several GPUs in one render, pulling batches of samples from one queue.
//! - `fingerprint`: what makes two renders the same render, as one hash.
//! - [`names`]: the words users type for every choice ([`Named`]: backend, strategy, math,
//!   lookup, estimator, ...), one table each, which every front end lists and parses.
//! - [`metrics`]: error metrics against a reference (MSE, bias, per-pixel error maps,
//!   quantiles) and the z test of two estimates for one expectation (`volpt converge`, `compare`).
//! - [`info`]: what a scene loads to, field by field (`volpt info`, Python's `Scene.info()`).
//! - `image`: images read from users' files within the memory limit ([`read_exr`]).
//! - [`limits`]: the memory limit every reader of users' files keeps to.
//! - `error`: every way the above fails, as one [`Error`]; settings are named by their keys in
//!   the library's spelling, which each front end spells its own way ([`Error::spelled`]).
//!
//! The front ends (the command line, the viewer, Python) depend on this crate alone. The scene
//! description a [`Scene`] holds is the scene crate's own data model, re-exported whole as
//! [`scene_files`] (with its writers: Mitsuba 3 export, `.vol` grids); of the other crates below
//! (`volpt-core`, `volpt-render`, `volpt-cpu`, `volpt-cuda`, `volpt-film`, `volpt-gpu-mem`) only
//! the types named here are part of the library.

mod auto;
mod backend;
mod checkpoint;
mod error;
mod films;
mod fingerprint;
mod image;
pub mod info;
pub mod metrics;
mod multi;
pub mod names;
mod observer;
mod preferred;
mod request;
mod scene;
mod settings;

pub use auto::registers;
pub use backend::{
    Backend, BackendKind, BackendOptions, GpuOptions, Gpus, Rendered, StrategyChoice,
    MAX_REGISTERS, REFILL_AT, TILES,
};
pub use checkpoint::{merge, render_checkpointed, Checkpointing, Part};
pub use error::Error;
pub use films::{merge_films, read_film, FilmFile, MergeError, Merged};
pub use image::read_exr;
pub use info::Info;
pub use names::Named;
pub use observer::{Observer, Quiet};
pub use preferred::{preferred_kind, GpuProbe, Preferred};
pub use request::RenderRequest;
pub use scene::{ParamValue, Scene, PARAMS};
pub use settings::{check_majorant_resolution, RenderSettings, Tracking, MAJORANT_RESOLUTION};

pub use volpt_core::{Estimator, PathCounters, PathSettings, Roulette};
pub use volpt_cuda::{CudaRenderer, Math, Schedule, Strategy};
pub use volpt_film::film_file::format_ranges;
pub use volpt_film::tone;
pub use volpt_film::{
    preview_path, Accumulation, CheckpointError, Film, FilmFileError, Image, ImageError,
    RenderStats,
};
pub use volpt_gpu_mem::VolumeMemory;
pub use volpt_render::{Effects, Variant};
pub use volpt_scene::{GridDesc, GridLookup, SceneDescription, SceneError};

pub use volpt_scene as scene_files;

/// The memory limit every reader of users' files keeps to (scene grids, images, films): what a
/// header claims is checked against it before anything is allocated.
pub mod limits {
    pub use volpt_scene::limits::{
        memory_limit, open_regular, set_memory_limit, DEFAULT_MEMORY_LIMIT,
    };
}
