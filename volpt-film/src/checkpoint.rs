//! Checkpoints of a render in progress: the film's per-pixel sums and how many samples they hold.
//!
//! With the counter-based RNG, sample `s` of pixel `p` is the same path whoever traces it and
//! whenever, and the sums are added in sample order: a render resumed from a checkpoint gives the
//! uninterrupted render's image bit for bit.
//!
//! File layout (little-endian): the magic `VOLPTCK1`, the scene's fingerprint (`u64`), width,
//! height, seed and samples (`u32` each), `3 * width * height` `f64` sums, and an FNV-1a checksum
//! (`u64`) of everything before it. The size is checked against the header before anything is
//! allocated, and the checksum before the sums are used.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::{Accumulation, Film};

const MAGIC: &[u8; 8] = b"VOLPTCK1";
const HEADER: usize = 8 + 8 + 4 * 4;

/// A render's state: which scene (by fingerprint), which seed, and the sums of samples
/// `0 .. samples` of every pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub fingerprint: u64,
    pub seed: u32,
    pub samples: u32,
    pub film: Film,
}

#[derive(Debug, Error)]
pub enum CheckpointError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: not a volpt checkpoint, or a damaged one: {problem}", path.display())]
    Corrupt { path: PathBuf, problem: String },
    #[error(
        "{}: the checkpoint is of another render: its {field} is {found}, this render's is \
         {expected}",
        path.display()
    )]
    Mismatch {
        path: PathBuf,
        field: &'static str,
        expected: String,
        found: String,
    },
    /// A film of samples that do not start at 0, which a checkpoint cannot hold.
    #[error(
        "{}: a checkpoint holds samples 0..n of every pixel; this film holds samples {}..{} \
         (merge it with the films of the samples before it first)",
        path.display(), samples.start, samples.end
    )]
    NotFromZero {
        path: PathBuf,
        samples: std::ops::Range<u32>,
    },
}

/// What a checkpoint's header says: whose render it is and the film's size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub fingerprint: u64,
    pub width: u32,
    pub height: u32,
    pub seed: u32,
}

/// FNV-1a, 64 bit: a checksum against damaged files, and the scene fingerprint's hash.
#[derive(Clone, Copy, Debug)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    pub fn finish(self) -> u64 {
        self.0
    }
}

/// Appends `sums` (little-endian `f64`) and an FNV-1a checksum of everything before it to
/// `header`: the tail of checkpoints and film files alike.
pub(crate) fn sealed(mut bytes: Vec<u8>, sums: &[[f64; 3]]) -> Vec<u8> {
    for sum in sums {
        for c in sum {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    let mut fnv = Fnv::default();
    fnv.write(&bytes);
    bytes.extend_from_slice(&fnv.finish().to_le_bytes());
    bytes
}

/// Writes `bytes` to `path` atomically: to a temporary file beside it, then renamed, so that an
/// interruption while writing leaves the previous file intact.
pub(crate) fn write_atomically(bytes: &[u8], path: &Path) -> std::io::Result<()> {
    let mut name = path.file_name().unwrap_or_default().to_owned();
    name.push(".partial");
    let partial = path.with_file_name(name);
    let mut file = std::fs::File::create(&partial)?;
    file.write_all(bytes)?;
    file.sync_all()?;
    std::fs::rename(&partial, path)
}

impl Checkpoint {
    /// Writes the checkpoint to `path` atomically: to a temporary file beside it, then renamed, so
    /// that an interruption while writing leaves the previous checkpoint intact.
    pub fn write(&self, path: &Path) -> Result<(), CheckpointError> {
        Self::write_film(path, self.fingerprint, self.seed, self.samples, &self.film)
    }

    /// Writes `film`, the sums of samples `0 .. samples` of a render of `fingerprint` and `seed`,
    /// as [`Checkpoint::write`] does, without first moving the film into a checkpoint.
    pub fn write_film(
        path: &Path,
        fingerprint: u64,
        seed: u32,
        samples: u32,
        film: &Film,
    ) -> Result<(), CheckpointError> {
        let io = |source| CheckpointError::Io {
            path: path.to_owned(),
            source,
        };
        let mut bytes = Vec::with_capacity(HEADER + film.sums.len() * 24 + 8);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&fingerprint.to_le_bytes());
        for v in [film.width, film.height, seed, samples] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        write_atomically(&sealed(bytes, &film.sums), path).map_err(io)
    }

    /// The header of the checkpoint at `path`, unchecked but for its magic: what a caller that
    /// knows no render reads it as ([`Checkpoint::read`] then checks the whole file against it).
    pub fn header(path: &Path) -> Result<Header, CheckpointError> {
        let corrupt = |problem: String| CheckpointError::Corrupt {
            path: path.to_owned(),
            problem,
        };
        let (file, length) =
            crate::regular::open_regular(path).map_err(|e| CheckpointError::Io {
                path: path.to_owned(),
                source: e.into(),
            })?;
        let mut header = [0u8; HEADER];
        if length < HEADER as u64 {
            return Err(corrupt(format!(
                "{length} bytes, shorter than a checkpoint's header ({HEADER})"
            )));
        }
        file.take(HEADER as u64)
            .read_exact(&mut header)
            .map_err(|source| CheckpointError::Io {
                path: path.to_owned(),
                source,
            })?;
        if &header[..8] != MAGIC {
            return Err(corrupt("it does not start with VOLPTCK1".into()));
        }
        let u32_at = |i: usize| u32::from_le_bytes(header[i..i + 4].try_into().expect("4 bytes"));
        Ok(Header {
            fingerprint: u64::from_le_bytes(header[8..16].try_into().expect("8 bytes")),
            width: u32_at(16),
            height: u32_at(20),
            seed: u32_at(24),
        })
    }

    /// Reads the checkpoint at `path` and checks that it belongs to a render of `fingerprint` and
    /// `seed` on a `width` x `height` film; a film whose sums would take more than `limit` bytes
    /// is refused before anything is read (the size may come from the file's own header).
    pub fn read(
        path: &Path,
        fingerprint: u64,
        (width, height): (u32, u32),
        seed: u32,
        limit: u64,
    ) -> Result<Self, CheckpointError> {
        let corrupt = |problem: String| CheckpointError::Corrupt {
            path: path.to_owned(),
            problem,
        };
        let mismatch = |field, expected: String, found: String| CheckpointError::Mismatch {
            path: path.to_owned(),
            field,
            expected,
            found,
        };
        let io = |source| CheckpointError::Io {
            path: path.to_owned(),
            source,
        };
        let sum_bytes = u64::from(width) * u64::from(height) * 24;
        if sum_bytes > limit {
            return Err(corrupt(format!(
                "a {width}x{height} film takes {sum_bytes} bytes, more than the memory limit of \
                 {limit} bytes (raise it with --memory-limit)"
            )));
        }
        let (file, length) = crate::regular::open_regular(path).map_err(|e| io(e.into()))?;
        // Only a checkpoint of this film's size can be this render's: anything else is refused
        // before it is read, whatever its header claims.
        let expected_len = HEADER as u64 + sum_bytes + 8;
        if length != expected_len {
            return Err(corrupt(format!(
                "{length} bytes, a {width}x{height} film's checkpoint has {expected_len}"
            )));
        }
        let mut bytes = Vec::with_capacity(length as usize);
        // `take`: a file that grows while it is read stops at the length checked above.
        file.take(length).read_to_end(&mut bytes).map_err(io)?;
        if bytes.len() as u64 != length {
            return Err(corrupt(format!(
                "{} bytes read of {length} (the file changed while read)",
                bytes.len()
            )));
        }
        let (payload, checksum) = bytes.split_at(bytes.len() - 8);
        let mut fnv = Fnv::default();
        fnv.write(payload);
        if fnv.finish().to_le_bytes() != checksum {
            return Err(corrupt("the checksum does not match its contents".into()));
        }
        if &payload[..8] != MAGIC {
            return Err(corrupt("it does not start with VOLPTCK1".into()));
        }
        let u64_at = |i: usize| u64::from_le_bytes(payload[i..i + 8].try_into().expect("8 bytes"));
        let u32_at = |i: usize| u32::from_le_bytes(payload[i..i + 4].try_into().expect("4 bytes"));
        let found_fingerprint = u64_at(8);
        if found_fingerprint != fingerprint {
            return Err(mismatch(
                "scene (fingerprint of the scene and its settings)",
                format!("{fingerprint:016x}"),
                format!("{found_fingerprint:016x}"),
            ));
        }
        let (w, h) = (u32_at(16), u32_at(20));
        if (w, h) != (width, height) {
            return Err(mismatch(
                "film",
                format!("{width}x{height}"),
                format!("{w}x{h}"),
            ));
        }
        let found_seed = u32_at(24);
        if found_seed != seed {
            return Err(mismatch("seed", seed.to_string(), found_seed.to_string()));
        }
        let samples = u32_at(28);
        let sums = payload[HEADER..]
            .chunks_exact(24)
            .map(|p| [0, 8, 16].map(|i| f64::from_le_bytes(p[i..i + 8].try_into().expect("8"))))
            .collect();
        Ok(Self {
            fingerprint,
            seed,
            samples,
            // `volpt render`, the one writer of checkpoints, always sums in f64.
            film: Film {
                width,
                height,
                sums,
                accumulation: Accumulation::F64,
            },
        })
    }
}
