//! What can go wrong reading or writing a print, each message naming the file, and for a value
//! what was expected and what was found. Nothing is returned half-loaded: a reader returns a
//! whole print or one of these.

use std::path::PathBuf;

use thiserror::Error;
use volpt_scene::SceneError;

#[derive(Debug, Error)]
pub enum PrintError {
    /// Opening or reading a file, or a size over the memory limit (volpt-scene's checks, which
    /// every volpt reader applies).
    #[error(transparent)]
    Scene(#[from] SceneError),

    /// A file could not be written or a folder listed.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// A value out of range or of the wrong form.
    #[error("{}: {field}: expected {expected}, found {found}", path.display())]
    Invalid {
        path: PathBuf,
        field: String,
        expected: String,
        found: String,
    },

    /// `materials.toml` is not TOML of the expected form.
    #[error("{}: {source}", path.display())]
    Toml {
        path: PathBuf,
        #[source]
        source: Box<toml::de::Error>,
    },

    /// A PNG (a target image) that does not decode.
    #[error("{}: not a PNG slice volpt reads: {source}", path.display())]
    Png {
        path: PathBuf,
        #[source]
        source: png::DecodingError,
    },

    /// A slice missing from, or extra to, the numbering `slice_0000.png` .. that `layers` implies.
    #[error("{}: expected {expected}, found {found}", path.display())]
    SliceNumbering {
        path: PathBuf,
        expected: String,
        found: String,
    },
}
