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
    /// A scene parameter ([`crate::Scene::set`]) that does not exist or has a value out of range.
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
