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
//! - [`settings`]: [`RenderSettings`], what a user overrides of a scene file's values (scene file <
//!   settings), resolved once when a scene is loaded.
//! - [`scene`]: [`Scene`], a loaded scene with its resolved settings, its [`fingerprint`] and the
//!   parameters that change between renders without reloading its grids ([`Scene::set`]).
//! - [`backend`]: [`Backend`], the CPU or a GPU with its strategy (or `auto`), math and memory
//!   placement, opened once and reused; [`Backend::render`] adds a request's samples to a
//!   [`Film`].
//! - [`request`]: [`RenderRequest`], one render's samples, seed, path settings and lookup over
//!   the scene's: renders only read the scene, so threads share one.
//! - [`observer`]: what a render tells its caller while it runs (progress, notes) and how the caller
//!   stops it ([`Observer`]).
//! - [`auto`]: the `auto` strategy: calibration renders, a cache per scene and GPU.
//! - [`checkpoint`]: long renders saved as they go and resumed bit for bit; films of disjoint sample
//!   ranges merged.
//! - [`films`]: films of sample ranges rendered anywhere, read from their files and merged.
//! - [`multi`]: several GPUs in one render, pulling batches of samples from one queue.
//! - [`fingerprint`]: what makes two renders the same render, as one hash.
//! - [`names`]: the words users type for every choice ([`Named`]: backend, strategy, math,
//!   lookup, estimator, ...), one table each, which every front end lists and parses.
//! - [`metrics`]: error metrics against a reference (MSE, bias, per-pixel error maps,
//!   quantiles) and the z test of two estimates for one expectation (`volpt converge`, `compare`).
//! - [`info`]: what a scene loads to, field by field (`volpt info`, Python's `Scene.info()`).
//! - [`error`]: every way the above fails, as one [`Error`].
//!
//! The crates below this one (`volpt-core`, `volpt-scene`, `volpt-render`, `volpt-cpu`,
//! `volpt-cuda`, `volpt-film`) are re-exported for what the facade does not wrap.

pub mod auto;
pub mod backend;
pub mod checkpoint;
pub mod error;
pub mod films;
pub mod fingerprint;
pub mod info;
pub mod metrics;
pub mod multi;
pub mod names;
pub mod observer;
pub mod request;
pub mod scene;
pub mod settings;

pub use backend::{
    Backend, BackendKind, BackendOptions, GpuOptions, Gpus, Rendered, StrategyChoice,
    MAX_REGISTERS, REFILL_AT,
};
pub use checkpoint::{merge, render_checkpointed, Checkpointing, Part};
pub use error::Error;
pub use films::{merge_films, read_film, FilmFile, MergeError, Merged};
pub use info::Info;
pub use names::Named;
pub use observer::{Observer, Quiet};
pub use request::RenderRequest;
pub use scene::{ParamValue, Scene, PARAMS};
pub use settings::{check_majorant_resolution, RenderSettings, Tracking, MAJORANT_RESOLUTION};

pub use volpt_core::{Estimator, PathSettings, Roulette};
pub use volpt_cuda::{Math, Strategy};
pub use volpt_film::{Accumulation, Film, Image, RenderStats};
pub use volpt_gpu_mem::VolumeMemory;
pub use volpt_render::{Effects, Variant};
pub use volpt_scene::{GridLookup, SceneDescription};

pub use volpt_core as core;
pub use volpt_cuda as cuda;
pub use volpt_film as film;
pub use volpt_render as render;
pub use volpt_scene as scene_files;
