//! Opening the files volpt reads as regular files only: `open` on a FIFO blocks until a writer
//! appears (for ever), and a device such as `/dev/zero` never ends. The kind is checked on the
//! path before opening, and again on the open file, since the path may have been replaced in
//! between. The one implementation: volpt's own formats here (film files, checkpoints) and every
//! loader of `volpt-scene` (`volpt_scene::limits::open_regular`, which names the path in a
//! `SceneError`).

use std::fs::File;
use std::io;
use std::path::Path;

/// Why a path was not opened.
#[derive(Debug, thiserror::Error)]
pub enum OpenError {
    /// The path is not a regular file: it was not opened.
    #[error("expected a regular file, found {kind}")]
    NotAFile { kind: &'static str },
    #[error(transparent)]
    Io(#[from] io::Error),
}

impl From<OpenError> for io::Error {
    /// A path that is not a regular file is [`io::ErrorKind::InvalidInput`], named in the message.
    fn from(e: OpenError) -> Self {
        match e {
            OpenError::NotAFile { .. } => {
                io::Error::new(io::ErrorKind::InvalidInput, e.to_string())
            }
            OpenError::Io(e) => e,
        }
    }
}

/// Opens the regular file at `path` and returns it with its length; anything else is
/// [`OpenError::NotAFile`], naming what the path is, and is never opened.
pub fn open_regular(path: &Path) -> Result<(File, u64), OpenError> {
    let kind = std::fs::metadata(path)?.file_type();
    if !kind.is_file() {
        return Err(OpenError::NotAFile {
            kind: kind_name(kind),
        });
    }
    let file = File::open(path)?;
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(OpenError::NotAFile {
            kind: kind_name(metadata.file_type()),
        });
    }
    Ok((file, metadata.len()))
}

/// What a path that is not a regular file is, in words.
pub fn kind_name(kind: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if kind.is_char_device() || kind.is_block_device() {
            return "a device";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "something that is not a regular file"
    }
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    /// A FIFO is refused without opening it (opening it would block this test for ever); a
    /// directory is refused too.
    #[test]
    fn a_fifo_or_a_directory_is_refused_before_it_is_opened() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("fifo");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let err = io::Error::from(open_regular(&fifo).unwrap_err());
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(err.to_string().contains("FIFO"), "{err}");
        assert!(open_regular(dir.path())
            .unwrap_err()
            .to_string()
            .contains("directory"));
        let file = dir.path().join("f");
        std::fs::write(&file, b"abc").unwrap();
        assert_eq!(open_regular(&file).unwrap().1, 3);
    }
}
