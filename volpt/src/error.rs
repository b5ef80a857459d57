//! Every way loading, configuring and rendering can fail, as one error type whose messages name
//! the file, the field or option, what was expected and what was found.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum Error {
    /// A scene file that cannot be read or describes something volpt cannot render.
    #[error(transparent)]
    Scene(#[from] volpt_scene::SceneError),
    /// A setting that contradicts another (a GPU strategy with the CPU backend, a majorant grid
    /// with global tracking), each named by its key in the library's spelling and its value;
    /// `why` names no key, so that each front end spells the keys its own way
    /// ([`Error::spelled`]). `instead`, where there is one, is the setting and value that
    /// would go with `key`'s (the message then says to use it, or to drop `key`).
    #[error("{}", conflict_text(key, value, with, with_value, why, instead, &library_spelling))]
    Conflict {
        key: &'static str,
        value: String,
        with: &'static str,
        with_value: String,
        why: String,
        /// Boxed: the error stays small enough to return everywhere.
        instead: Option<Box<(&'static str, String)>>,
    },
    /// A film of another size than the scene renders.
    #[error("the film is {}x{} but the scene renders {}x{}", film.0, film.1, scene.0, scene.1)]
    FilmSize { film: (u32, u32), scene: (u32, u32) },
    /// A setting's value out of its range or no name of its choices ([`crate::names`]): `key` in
    /// the library's spelling (`majorant_resolution`), which each front end spells its own way
    /// (`--majorant-resolution`, `settings["majorant_resolution"]`).
    #[error("{}", setting_text(key, expected, found, &library_spelling))]
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

impl Error {
    /// [`Error::Conflict`]: setting `key` at `value` with `with` at `with_value`, refused
    /// because of `why` (in words that name no key).
    pub fn conflict(
        key: &'static str,
        value: impl std::fmt::Display,
        with: &'static str,
        with_value: impl std::fmt::Display,
        why: impl Into<String>,
    ) -> Self {
        Error::Conflict {
            key,
            value: value.to_string(),
            with,
            with_value: with_value.to_string(),
            why: why.into(),
            instead: None,
        }
    }

    /// A [`Error::Conflict`] that `instead` at `value` would resolve; any other error as it is.
    pub fn or_use(self, instead: &'static str, value: impl std::fmt::Display) -> Self {
        match self {
            Error::Conflict {
                key,
                value: v,
                with,
                with_value,
                why,
                ..
            } => Error::Conflict {
                key,
                value: v,
                with,
                with_value,
                why,
                instead: Some(Box::new((instead, value.to_string()))),
            },
            other => other,
        }
    }

    /// The message with every setting's key spelled by `spell(key, value)`, as the front end
    /// that reports it takes the setting (`--max-depth 8` on the command line, `max_depth=8` in
    /// Python); any other error's message as [`std::fmt::Display`] writes it.
    pub fn spelled(&self, spell: &dyn Fn(&str, Option<&str>) -> String) -> String {
        match self {
            Error::Setting {
                key,
                expected,
                found,
            } => setting_text(key, expected, found, spell),
            Error::Conflict {
                key,
                value,
                with,
                with_value,
                why,
                instead,
            } => conflict_text(key, value, with, with_value, why, instead, spell),
            _ => self.to_string(),
        }
    }
}

/// The library's own spelling of a key and its value: `max_depth`, `max_depth = 8`.
fn library_spelling(key: &str, value: Option<&str>) -> String {
    match value {
        Some(value) => format!("{key} = {value}"),
        None => key.to_owned(),
    }
}

fn setting_text(
    key: &str,
    expected: &str,
    found: &str,
    spell: &dyn Fn(&str, Option<&str>) -> String,
) -> String {
    format!("{}: expected {expected}, found {found}", spell(key, None))
}

fn conflict_text(
    key: &str,
    value: &str,
    with: &str,
    with_value: &str,
    why: &str,
    instead: &Option<Box<(&'static str, String)>>,
    spell: &dyn Fn(&str, Option<&str>) -> String,
) -> String {
    let text = format!(
        "{} with {}: {why}",
        spell(key, Some(value)),
        spell(with, Some(with_value))
    );
    match instead.as_deref() {
        Some((other, v)) => format!(
            "{text} (use {}, or drop {})",
            spell(other, Some(v)),
            spell(key, None)
        ),
        None => text,
    }
}
