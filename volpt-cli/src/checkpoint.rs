//! `volpt render --checkpoint FILE` / `--resume FILE`: the flags' files. The chunked render, the
//! file and the fingerprint are the library's (`volpt::checkpoint`).

use std::path::{Path, PathBuf};

/// `FILE` of `--checkpoint FILE`, or the resumed file when only `--resume` is given.
pub fn save_path(checkpoint: Option<&Path>, resume: Option<&Path>) -> Option<PathBuf> {
    checkpoint.or(resume).map(Path::to_owned)
}
