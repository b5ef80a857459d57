//! What untrusted input may make volpt do: how much memory its declared sizes may claim, how far a
//! compressed stream may expand, how many files a scene may include, how far its parameters may
//! expand, and how dense a medium may be. `docs/reliability.md` explains the choices.
//!
//! Every loader checks a size it derives from input against the bytes actually present and against
//! these limits *before* allocating for it, and opens only regular files (a FIFO blocks `open` for
//! ever, `/dev/zero` never ends).
//!
//! The memory limit is one setting for the whole process, like a `ulimit`: it applies to every
//! file a scene refers to, at any depth, without threading a parameter through every loader.

use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use volpt_film::regular::OpenError;

use crate::error::SceneError;

/// The default memory limit: 8 GiB, more than any of the included scenes needs by a factor of
/// ten, and less than the memory of the machines volpt runs on.
pub const DEFAULT_MEMORY_LIMIT: u64 = 8 << 30;

/// The most a zlib (deflate) stream can expand: 1032 bytes out per byte in is deflate's own limit
/// (a 258-byte match per 2 bits), so a header claiming more than this ratio is lying.
pub const DEFLATE_MAX_RATIO: u64 = 1032;

/// The most `<include>`s one Mitsuba scene may expand, counting repeats: real scenes have a few,
/// and a file that includes another ten times, which includes another ten times, ... grows
/// exponentially.
pub const MAX_INCLUDES: usize = 1024;

/// The most text (attribute values plus a fixed cost per element) one Mitsuba scene may expand to
/// after `$name` substitution and includes: real scenes expand to kilobytes.
pub const MAX_EXPANDED_XML_BYTES: u64 = 64 << 20;

/// The most a scene's majorant extinction times its box's diagonal may be: delta tracking takes
/// about this many tentative collisions to cross the box once, so this bounds the work of a path
/// before its tracking-step budget. Whether steps that short still move an `f32` position is the
/// scale-aware check of `numerics` (a unit box at extinction 1e6, optical depth 1.7e6, renders
/// right and is accepted by both). The included scenes stay below 2 * 10^3.
pub const MAX_OPTICAL_DEPTH: f64 = 1e7;

static MEMORY_LIMIT: AtomicU64 = AtomicU64::new(DEFAULT_MEMORY_LIMIT);

/// Sets the memory limit for everything loaded from now on (`--memory-limit`).
pub fn set_memory_limit(bytes: u64) {
    MEMORY_LIMIT.store(bytes, Ordering::Relaxed);
}

/// The most bytes one piece of loaded data (a grid, a map, a film, a file read whole) may take.
pub fn memory_limit() -> u64 {
    MEMORY_LIMIT.load(Ordering::Relaxed)
}

/// Refuses `bytes` (`None`: it overflowed) over the memory limit; `what` names the data.
pub fn check_memory(path: &Path, what: &str, bytes: Option<u64>) -> Result<(), SceneError> {
    let limit = memory_limit();
    match bytes {
        Some(b) if b <= limit => Ok(()),
        _ => Err(SceneError::OverMemoryLimit {
            path: path.to_path_buf(),
            what: what.to_owned(),
            bytes,
            limit,
        }),
    }
}

/// `count` values of `size` bytes each, or `None` if that overflows.
/// [`check_memory`] for a grid of `values` `f32`s with `resolution` voxels of `channels` each.
pub fn check_grid_memory(
    path: &Path,
    [x, y, z]: [u32; 3],
    channels: u32,
    values: u64,
) -> Result<(), SceneError> {
    check_memory(
        path,
        &format!("the grid of {x} x {y} x {z} voxels x {channels} channels as f32"),
        bytes_of(values, 4),
    )
}

pub fn bytes_of(count: u64, size: u64) -> Option<u64> {
    count.checked_mul(size)
}

/// Opens a regular file and returns it with its length; refuses anything else before opening it
/// (`volpt_film::regular::open_regular`, the one check every reader of volpt's uses).
pub fn open_regular(path: &Path) -> Result<(File, u64), SceneError> {
    volpt_film::regular::open_regular(path).map_err(|e| match e {
        OpenError::NotAFile { kind } => SceneError::NotAFile {
            path: path.to_path_buf(),
            kind,
        },
        OpenError::Io(error) => SceneError::Io {
            path: path.to_path_buf(),
            error,
        },
    })
}

/// Reads a whole regular file, within the memory limit, and no more than its length said.
pub fn read_file(path: &Path) -> Result<Vec<u8>, SceneError> {
    let (file, len) = open_regular(path)?;
    check_memory(path, "the file", Some(len))?;
    let mut bytes = Vec::new();
    // `take`: a file that grows while it is read stops at the length checked above.
    file.take(len)
        .read_to_end(&mut bytes)
        .map_err(|error| SceneError::Io {
            path: path.to_path_buf(),
            error,
        })?;
    Ok(bytes)
}

/// Reads a whole regular text file (UTF-8), within the memory limit.
pub fn read_text(path: &Path) -> Result<String, SceneError> {
    String::from_utf8(read_file(path)?).map_err(|e| SceneError::Io {
        path: path.to_path_buf(),
        error: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (invalid byte at offset {})",
                e.utf8_error().valid_up_to()
            ),
        ),
    })
}

/// Checks what an OpenEXR file's headers declare before a decoder allocates for it: every layer
/// within the memory limit at `extra_bytes_per_pixel` on top of its stored channels (what the
/// caller keeps per pixel), and an offset table the file has the bytes for. A header that does not
/// parse is left for the decoder to report.
pub fn check_exr(path: &Path, what: &str, extra_bytes_per_pixel: u64) -> Result<(), SceneError> {
    let (file, file_bytes) = open_regular(path)?;
    let read = || exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false);
    let Ok(Ok(meta)) = crate::contain::contain_panics(read) else {
        return Ok(());
    };
    // The decoder reserves a block's declared size before reading it, one block per thread.
    let blocks_at_once = std::thread::available_parallelism().map_or(1, usize::from) as u64 + 1;
    for header in &meta.headers {
        let size = header.layer_size;
        let stored_per_pixel = header.channels.bytes_per_pixel as u64;
        let per_pixel = stored_per_pixel.checked_add(extra_bytes_per_pixel);
        let layer = per_pixel.and_then(|p| bytes_of(size.area() as u64, p));
        let block_pixels = match header.blocks {
            exr::meta::BlockDescription::Tiles(tiles) => bytes_of(
                tiles.tile_size.width() as u64,
                tiles.tile_size.height() as u64,
            ),
            exr::meta::BlockDescription::ScanLines => bytes_of(
                header.compression.scan_lines_per_block() as u64,
                size.width() as u64,
            ),
        };
        let blocks = block_pixels
            .and_then(|p| bytes_of(p, stored_per_pixel))
            .and_then(|b| bytes_of(b, blocks_at_once));
        let bytes = layer.zip(blocks).and_then(|(l, b)| l.checked_add(b));
        check_memory(
            path,
            &format!(
                "{what} of {} x {} pixels (with its decoder's blocks)",
                size.width(),
                size.height()
            ),
            bytes,
        )?;
        let table_bytes = (header.chunk_count as u64).saturating_mul(8);
        if table_bytes > file_bytes {
            return Err(SceneError::Io {
                path: path.to_path_buf(),
                error: std::io::Error::new(
                    std::io::ErrorKind::UnexpectedEof,
                    format!(
                        "truncated OpenEXR file: its header declares {} pixel blocks, whose \
                         offsets alone take {table_bytes} bytes, but the file has {file_bytes}",
                        header.chunk_count
                    ),
                ),
            });
        }
    }
    Ok(())
}
