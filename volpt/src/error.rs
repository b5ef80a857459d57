//! Every way loading, configuring and rendering can fail, as one error type whose messages name
//! the file, the field or option, what was expected and what was found.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum Error {
    /// A scene file that cannot be read or describes something volpt cannot render.
    #[error(transparent)]
    Scene(#[from] volpt_scene::SceneError),
    /// Settings that contradict each other or the backend (e.g. a GPU strategy on the CPU).
    #[error("{0}")]
    Settings(String),
    /// A setting's value out of its range or no name of its choices ([`crate::names`]): `key` in
    /// the library's spelling (`majorant_resolution`), which each front end spells its own way
    /// (`--majorant-resolution`, `settings["majorant_resolution"]`).
    #[error("{key}: expected {expected}, found {found}")]
    Setting {
        key: &'static str,
        expected: String,
        found: String,
    },
    /// A scene parameter ([`crate::Scene::get`], [`crate::Scene::set`]) that does not exist;
    /// `expected` lists those that do.
    #[error("parameter {key}: expected {expected}, found no such parameter")]
    UnknownParam { key: String, expected: String },
    /// A scene parameter's value ([`crate::Scene::set`]) out of range.
    #[error("parameter {key}: expected {expected}, found {found}")]
    Param {
        key: String,
        expected: String,
        found: String,
    },
    /// Grid values ([`crate::Scene::set_grid`]) for a grid the scene lacks, of the wrong size,
    /// or out of range.
    #[error("grid {grid}: expected {expected}, found {found}")]
    Grid {
        grid: String,
        expected: String,
        found: String,
    },
    /// The CPU backend failed.
    #[error(transparent)]
    Cpu(#[from] volpt_cpu::RenderError),
    /// The GPU backend failed (including: no GPU, no kernels in this build).
    #[error(transparent)]
    Cuda(#[from] volpt_cuda::CudaError),
    /// A checkpoint or film file that cannot be read, written, or is of another render.
    #[error(transparent)]
    Checkpoint(#[from] volpt_film::CheckpointError),
    /// A film file that cannot be read or written ([`crate::films`]).
    #[error(transparent)]
    FilmFile(#[from] volpt_film::FilmFileError),
    /// Films that do not add up to one render, naming each film ([`crate::films`]).
    #[error(transparent)]
    Films(#[from] crate::films::MergeError),
    /// An image that cannot be written or read.
    #[error(transparent)]
    Image(#[from] volpt_film::ImageError),
}
