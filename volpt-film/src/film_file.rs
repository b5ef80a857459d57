//! Film files: the sums of any set of sample ranges of one render, to be merged with the films of
//! the other ranges wherever those were rendered (another GPU, another machine, a cluster task).
//!
//! Sample `s` of pixel `p` is the same path whoever traces it, so films of disjoint sample ranges
//! of one render add up to the film of their union (up to the order of the `f64` additions).
//!
//! File layout, `VOLPTFL1` (little-endian):
//!
//! | offset | what |
//! |---|---|
//! | 0 | magic `VOLPTFL1` (the `1` is the format's version) |
//! | 8 | the scene's fingerprint, `u64` (everything that makes a render the same render) |
//! | 16 | width, height, seed, `u32` each |
//! | 28 | `n`, the number of sample ranges, `u32`, at least 1 |
//! | 32 | `n` ranges, each `start`, `end` (`u32`, half-open), sorted, non-empty, and neither overlapping nor touching (touching ranges are written as one) |
//! | 32 + 8n | `3 * width * height` sums, `f64`, row-major from the top-left pixel, r g b |
//! | end - 8 | FNV-1a (`u64`) of every byte before it |
//!
//! Reading checks, in this order, so that nothing is allocated for what a header merely claims:
//! the magic; the length the header implies against the file's length (and against the caller's
//! memory limit); then the checksum; then the ranges. Checkpoints (`VOLPTCK1`, samples `0..n`) read
//! as films of the one range `0..n`.

use std::io::{BufReader, Read};
use std::ops::Range;
use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::checkpoint::{sealed, write_atomically, Fnv};
use crate::{Accumulation, Film};

/// The film file's magic; the last byte is the format's version.
pub const MAGIC: &[u8; 8] = b"VOLPTFL1";
/// What errors of a film read from or encoded to bytes ([`FilmFile::from_bytes`]) name as its path.
pub const BYTES: &str = "<film bytes>";
/// A checkpoint's magic (`crate::checkpoint`): read as a film of samples `0..n`.
const CHECKPOINT_MAGIC: &[u8; 8] = b"VOLPTCK1";
/// Magic, fingerprint, width, height, seed, and the range count or (checkpoint) sample count.
const HEADER: u64 = 8 + 8 + 4 * 4;
/// Bytes of one sample range (`start`, `end`), in the file and in memory.
const RANGE_BYTES: u64 = 8;
/// Bytes of one pixel's sums (r, g, b as `f64`), in the file and in memory.
const SUM_BYTES: u64 = 24;
/// How much of a film file is read at once: the reader holds no more than this besides the film.
const CHUNK_BYTES: u64 = 1 << 20;

/// A film of the sample ranges `ranges` of the render of `fingerprint` with `seed`.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmFile {
    pub fingerprint: u64,
    pub seed: u32,
    /// Sorted, non-empty, neither overlapping nor touching ([`normalize_ranges`]).
    pub ranges: Vec<Range<u32>>,
    pub film: Film,
}

#[derive(Debug, Error)]
pub enum FilmFileError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Not a film file, or a damaged one: `field` is what was read, `expected` what it must be.
    #[error(
        "{}: not a volpt film file, or a damaged one: its {field} is {found}, expected {expected}",
        path.display()
    )]
    Corrupt {
        path: PathBuf,
        field: &'static str,
        expected: String,
        found: String,
    },
    /// A film of several sample ranges where one range was asked for.
    #[error(
        "{}: the film holds samples {}, not one range (merge it with the films of the samples \
         between them first)",
        path.display(), format_ranges(ranges)
    )]
    NotOneRange {
        path: PathBuf,
        ranges: Vec<Range<u32>>,
    },
    /// A film (its sums and its list of sample ranges) larger than the caller's memory limit
    /// (`--memory-limit`).
    #[error(
        "{}: the film is {width}x{height} with {ranges} sample ranges listed, {bytes} bytes, more \
         than the memory limit of {limit} bytes (raise it with --memory-limit)",
        path.display()
    )]
    TooLarge {
        path: PathBuf,
        width: u32,
        height: u32,
        ranges: u32,
        bytes: u64,
        limit: u64,
    },
    /// A film that cannot be written as it is (no ranges, or ranges out of order).
    #[error("{}: cannot write this film: {problem}", path.display())]
    Invalid { path: PathBuf, problem: String },
}

/// `ranges` sorted and with touching or overlapping ranges joined, empty ranges dropped: the form
/// a film file holds. (Overlaps are a caller's concern: merging refuses them before this.)
pub fn normalize_ranges(mut ranges: Vec<Range<u32>>) -> Vec<Range<u32>> {
    ranges.retain(|r| r.start < r.end);
    ranges.sort_by_key(|r| (r.start, r.end));
    let mut out: Vec<Range<u32>> = Vec::with_capacity(ranges.len());
    for r in ranges {
        match out.last_mut() {
            Some(last) if r.start <= last.end => last.end = last.end.max(r.end),
            _ => out.push(r),
        }
    }
    out
}

/// `ranges` as text: `0..4, 8..16`.
pub fn format_ranges(ranges: &[Range<u32>]) -> String {
    if ranges.is_empty() {
        return "none".into();
    }
    ranges
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why `ranges` is not in a film file's form, or `None`.
fn ranges_problem(ranges: &[Range<u32>]) -> Option<String> {
    if ranges.is_empty() {
        return Some("no sample ranges".into());
    }
    for (i, r) in ranges.iter().enumerate() {
        if r.start >= r.end {
            return Some(format!("range {}..{} is empty", r.start, r.end));
        }
        if i > 0 && ranges[i - 1].end >= r.start {
            return Some(format!(
                "ranges {}..{} and {}..{} are out of order, overlap or touch",
                ranges[i - 1].start,
                ranges[i - 1].end,
                r.start,
                r.end
            ));
        }
    }
    None
}

impl FilmFile {
    /// How many samples of every pixel the film holds: the image's divisor.
    pub fn samples(&self) -> u64 {
        self.ranges.iter().map(|r| u64::from(r.end - r.start)).sum()
    }

    /// The image: every pixel's sums over the samples held. A film with gaps gives an unbiased
    /// image of fewer samples (every sample estimates the pixel), not the full render's.
    pub fn image(&self) -> crate::Image {
        let samples = self.samples();
        let inv = 1.0 / samples as f64;
        crate::Image {
            width: self.film.width,
            height: self.film.height,
            pixels: self
                .film
                .sums
                .iter()
                .map(|sum| sum.map(|c| (c * inv) as f32))
                .collect(),
        }
    }

    /// Writes the film to `path` atomically (a temporary file beside it, then renamed), so that an
    /// interruption leaves no half-written film under the name.
    pub fn write(&self, path: &Path) -> Result<(), FilmFileError> {
        let bytes = self.encode(path)?;
        write_atomically(&bytes, path).map_err(|source| FilmFileError::Io {
            path: path.to_owned(),
            source,
        })
    }

    /// The film file's bytes, as [`FilmFile::write`] writes them: how a film travels between
    /// processes (Python's pickling) without a file. Errors name the film [`BYTES`].
    pub fn to_bytes(&self) -> Result<Vec<u8>, FilmFileError> {
        self.encode(Path::new(BYTES))
    }

    /// The film of [`FilmFile::to_bytes`]'s bytes, checked as [`FilmFile::read`] checks a file
    /// (magic, length against `limit`, checksum, ranges).
    pub fn from_bytes(bytes: &[u8], limit: u64) -> Result<Self, FilmFileError> {
        Self::read_from(bytes, bytes.len() as u64, Path::new(BYTES), limit)
    }

    /// The bytes of the film file, or why it has none; `path` names it in errors.
    fn encode(&self, path: &Path) -> Result<Vec<u8>, FilmFileError> {
        if let Some(problem) = ranges_problem(&self.ranges) {
            return Err(FilmFileError::Invalid {
                path: path.to_owned(),
                problem,
            });
        }
        let pixels = self.film.width as usize * self.film.height as usize;
        if self.film.sums.len() != pixels {
            return Err(FilmFileError::Invalid {
                path: path.to_owned(),
                problem: format!(
                    "{} sums for a {}x{} film",
                    self.film.sums.len(),
                    self.film.width,
                    self.film.height
                ),
            });
        }
        let count = u32::try_from(self.ranges.len()).map_err(|_| FilmFileError::Invalid {
            path: path.to_owned(),
            problem: format!("{} ranges, more than a u32 counts", self.ranges.len()),
        })?;
        let mut bytes =
            Vec::with_capacity(HEADER as usize + 8 * self.ranges.len() + pixels * 24 + 8);
        bytes.extend_from_slice(MAGIC);
        bytes.extend_from_slice(&self.fingerprint.to_le_bytes());
        for v in [self.film.width, self.film.height, self.seed, count] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        for r in &self.ranges {
            bytes.extend_from_slice(&r.start.to_le_bytes());
            bytes.extend_from_slice(&r.end.to_le_bytes());
        }
        Ok(sealed(bytes, &self.film.sums))
    }

    /// Reads the film file (or checkpoint) at `path`, refusing one whose sample ranges and sums
    /// would take more than `limit` bytes before reading them.
    ///
    /// The file is read as a stream (its checksum computed as it goes), so that nothing but the
    /// film itself is allocated, and a list of ranges is refused at its first bad range.
    pub fn read(path: &Path, limit: u64) -> Result<Self, FilmFileError> {
        let (file, length) = crate::regular::open_regular(path).map_err(|e| FilmFileError::Io {
            path: path.to_owned(),
            source: e.into(),
        })?;
        // `take`: a file that grows while it is read stops at its length here.
        Self::read_from(file.take(length), length, path, limit)
    }

    /// Reads a film file of `length` bytes from `file`, named `path` in errors.
    fn read_from(
        file: impl Read,
        length: u64,
        path: &Path,
        limit: u64,
    ) -> Result<Self, FilmFileError> {
        let corrupt = |field, expected: String, found: String| FilmFileError::Corrupt {
            path: path.to_owned(),
            field,
            expected,
            found,
        };
        let io = |source| FilmFileError::Io {
            path: path.to_owned(),
            source,
        };
        let mut header = [0u8; HEADER as usize];
        if length < HEADER + 8 {
            return Err(corrupt(
                "length",
                format!("at least {} bytes (header and checksum)", HEADER + 8),
                format!("{length} bytes"),
            ));
        }
        let mut file = BufReader::with_capacity(1 << 16, file);
        file.read_exact(&mut header).map_err(io)?;
        let magic = &header[..8];
        let checkpoint = magic == CHECKPOINT_MAGIC;
        if magic != MAGIC && !checkpoint {
            return Err(corrupt(
                "magic",
                "VOLPTFL1 (or a VOLPTCK1 checkpoint)".into(),
                format!("{:?}", String::from_utf8_lossy(magic)),
            ));
        }
        let u32_at = |b: &[u8], i: usize| u32::from_le_bytes(b[i..i + 4].try_into().expect("4"));
        let (width, height, count) = (
            u32_at(&header, 16),
            u32_at(&header, 20),
            u32_at(&header, 28),
        );
        // A checkpoint has no range list: its last header field is its sample count.
        let range_count = if checkpoint { 0 } else { count };
        let range_bytes = RANGE_BYTES * u64::from(range_count);
        // width * height fits a u64 for any u32 header; 24 times it may not, hence checked.
        let sum_bytes = (u64::from(width) * u64::from(height)).checked_mul(SUM_BYTES);
        let expected = sum_bytes.and_then(|s| s.checked_add(HEADER + range_bytes + 8));
        match expected {
            Some(e) if e == length => {}
            _ => {
                return Err(corrupt(
                    "length",
                    match expected {
                        Some(e) => format!(
                            "{e} bytes, as its header says ({width}x{height} film{})",
                            if checkpoint {
                                String::new()
                            } else {
                                format!(", {count} ranges")
                            }
                        ),
                        None => format!("a header of a possible size, {width}x{height}"),
                    },
                    format!("{length} bytes (truncated, or a damaged header)"),
                ))
            }
        }
        // The length matched, so neither sum overflows: what the film takes in memory (a range
        // is 8 bytes there too, a pixel 24) is the file's length less its header and checksum.
        let sum_bytes = u64::from(width) * u64::from(height) * SUM_BYTES;
        let bytes = sum_bytes + range_bytes;
        if bytes > limit {
            return Err(FilmFileError::TooLarge {
                path: path.to_owned(),
                width,
                height,
                ranges: range_count,
                bytes,
                limit,
            });
        }
        let mut fnv = Fnv::default();
        fnv.write(&header);
        let fingerprint = u64::from_le_bytes(header[8..16].try_into().expect("8 bytes"));
        let seed = u32_at(&header, 24);
        let mut chunk = Vec::new();
        let mut ranges: Vec<Range<u32>> = Vec::new();
        if checkpoint {
            ranges.push(0..count);
        }
        // Ranges in chunks, each checked as it comes: a claimed list of a billion ranges is
        // refused at its first bad one, not allocated first.
        let mut left = range_bytes;
        while left > 0 {
            let n = left.min(CHUNK_BYTES);
            read_chunk(&mut file, &mut chunk, n, &mut fnv).map_err(io)?;
            for r in chunk.chunks_exact(RANGE_BYTES as usize) {
                ranges.push(u32_at(r, 0)..u32_at(r, 4));
                // This range and the one before it: the list so far was in order.
                let last = &ranges[ranges.len().saturating_sub(2)..];
                if let Some(problem) = ranges_problem(last) {
                    return Err(corrupt(
                        "sample ranges",
                        "sorted, non-empty ranges that neither overlap nor touch".into(),
                        format!("... {} ({problem})", format_ranges(last)),
                    ));
                }
            }
            left -= n;
        }
        if let Some(problem) = ranges_problem(&ranges) {
            return Err(corrupt(
                "sample ranges",
                "sorted, non-empty ranges that neither overlap nor touch".into(),
                format!("{} ({problem})", format_ranges(&ranges)),
            ));
        }
        // Within the limit, and the file holds the bytes: the sums may be allocated.
        let mut sums = Vec::with_capacity((sum_bytes / SUM_BYTES) as usize);
        let mut left = sum_bytes;
        while left > 0 {
            let n = left.min(CHUNK_BYTES / SUM_BYTES * SUM_BYTES);
            read_chunk(&mut file, &mut chunk, n, &mut fnv).map_err(io)?;
            sums.extend(chunk.chunks_exact(SUM_BYTES as usize).map(|p| {
                [0, 8, 16].map(|i| f64::from_le_bytes(p[i..i + 8].try_into().expect("8")))
            }));
            left -= n;
        }
        let mut checksum = [0u8; 8];
        file.read_exact(&mut checksum).map_err(io)?;
        let stored = u64::from_le_bytes(checksum);
        if fnv.finish() != stored {
            return Err(corrupt(
                "checksum",
                format!("{:016x}, the FNV-1a of its contents", fnv.finish()),
                format!("{stored:016x}"),
            ));
        }
        Ok(Self {
            fingerprint,
            seed,
            ranges,
            // Every backend's film file sums in f64 (`volpt render`, the only writer).
            film: Film {
                width,
                height,
                sums,
                accumulation: Accumulation::F64,
            },
        })
    }
}

/// Reads the next `n` bytes of `file` into `chunk` and adds them to the checksum; a file that
/// ends early (shortened while read) is an [`std::io::ErrorKind::UnexpectedEof`] error.
fn read_chunk(
    file: &mut impl Read,
    chunk: &mut Vec<u8>,
    n: u64,
    fnv: &mut Fnv,
) -> std::io::Result<()> {
    chunk.resize(n as usize, 0);
    file.read_exact(chunk)?;
    fnv.write(chunk);
    Ok(())
}

#[cfg(test)]
// Lists of sample ranges, some of one range.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;
    use crate::checkpoint::Checkpoint;

    fn film(width: u32, height: u32) -> Film {
        let mut film = Film::new(width, height);
        for (i, s) in film.sums.iter_mut().enumerate() {
            *s = [i as f64 + 0.25, -(i as f64), 1e300 / (i as f64 + 1.0)];
        }
        film
    }

    fn example() -> FilmFile {
        FilmFile {
            fingerprint: 0x0123_4567_89ab_cdef,
            seed: 7,
            ranges: vec![0..4, 9..12],
            film: film(5, 3),
        }
    }

    fn written(dir: &Path) -> (PathBuf, Vec<u8>) {
        let path = dir.join("part.vfilm");
        example().write(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        (path, bytes)
    }

    /// `bytes` with the checksum recomputed: a damage the checksum cannot see.
    fn resealed(mut bytes: Vec<u8>) -> Vec<u8> {
        let n = bytes.len() - 8;
        let mut fnv = Fnv::default();
        fnv.write(&bytes[..n]);
        bytes[n..].copy_from_slice(&fnv.finish().to_le_bytes());
        bytes
    }

    fn corrupt_field(result: Result<FilmFile, FilmFileError>) -> &'static str {
        match result {
            Err(FilmFileError::Corrupt { field, .. }) => field,
            other => panic!("expected a corrupt-file error, got {other:?}"),
        }
    }

    #[test]
    fn a_written_film_reads_back_bit_for_bit_with_its_ranges() {
        let dir = tempfile::tempdir().unwrap();
        let (path, bytes) = written(dir.path());
        assert_eq!(&bytes[..8], MAGIC);
        assert_eq!(FilmFile::read(&path, u64::MAX).unwrap(), example());
        assert_eq!(example().samples(), 7);
    }

    /// The bytes a film travels as between processes are the file's, read back with the
    /// file's checks.
    #[test]
    fn a_films_bytes_are_its_files_and_read_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let (_, file_bytes) = written(dir.path());
        let bytes = example().to_bytes().unwrap();
        assert_eq!(bytes, file_bytes);
        assert_eq!(FilmFile::from_bytes(&bytes, u64::MAX).unwrap(), example());
        let mut damaged = bytes.clone();
        damaged[40] ^= 1;
        let error = FilmFile::from_bytes(&damaged, u64::MAX).unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("<film bytes>: not a volpt film file")
                && error.to_string().contains("checksum"),
            "{error}"
        );
        assert!(matches!(
            FilmFile::from_bytes(&bytes, 10),
            Err(FilmFileError::TooLarge { .. })
        ));
        assert!(matches!(
            FilmFile::from_bytes(&bytes[..bytes.len() - 1], u64::MAX),
            Err(FilmFileError::Corrupt {
                field: "length",
                ..
            })
        ));
    }

    #[test]
    fn bad_magic_truncation_and_checksum_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let (path, bytes) = written(dir.path());
        let mut other = bytes.clone();
        other[..8].copy_from_slice(b"NOTAFILM");
        std::fs::write(&path, &other).unwrap();
        assert_eq!(corrupt_field(FilmFile::read(&path, u64::MAX)), "magic");

        std::fs::write(&path, &bytes[..bytes.len() - 1]).unwrap();
        let err = FilmFile::read(&path, u64::MAX).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
        std::fs::write(&path, &bytes[..10]).unwrap();
        assert_eq!(corrupt_field(FilmFile::read(&path, u64::MAX)), "length");

        let mut flipped = bytes.clone();
        flipped[100] ^= 1;
        std::fs::write(&path, &flipped).unwrap();
        assert_eq!(corrupt_field(FilmFile::read(&path, u64::MAX)), "checksum");
    }

    /// A header that claims a huge film is refused by its length before anything is allocated
    /// (a 4 GiB x 4 GiB film would abort the process if allocated); a real film over the limit
    /// is refused by the limit.
    #[test]
    fn a_header_claiming_a_huge_film_is_refused_before_allocation() {
        let dir = tempfile::tempdir().unwrap();
        let (path, bytes) = written(dir.path());
        let mut huge = bytes.clone();
        huge[16..20].copy_from_slice(&u32::MAX.to_le_bytes());
        huge[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, resealed(huge)).unwrap();
        let err = FilmFile::read(&path, u64::MAX).unwrap_err();
        assert!(
            matches!(
                &err,
                FilmFileError::Corrupt {
                    field: "length",
                    ..
                }
            ),
            "{err}"
        );
        let mut many = bytes.clone();
        many[28..32].copy_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, resealed(many)).unwrap();
        assert_eq!(corrupt_field(FilmFile::read(&path, u64::MAX)), "length");

        std::fs::write(&path, &bytes).unwrap();
        // The film in memory: 24 bytes a pixel, 8 a range (two ranges).
        let film_bytes = 5 * 3 * 24 + 2 * 8;
        match FilmFile::read(&path, film_bytes - 1) {
            Err(FilmFileError::TooLarge { bytes, .. }) => assert_eq!(bytes, film_bytes),
            other => panic!("expected TooLarge, got {other:?}"),
        }
        FilmFile::read(&path, film_bytes).unwrap();
    }

    /// A header claiming 2^27 sample ranges, in a (sparse) file of exactly the length that
    /// claims: the list's 1 GiB counts against the memory limit, and without a limit the list is
    /// refused at its first range (zeros: empty), before the rest is read or allocated.
    #[test]
    fn a_claimed_list_of_ranges_counts_against_the_limit_and_is_refused_at_its_first_bad_range() {
        let dir = tempfile::tempdir().unwrap();
        let (path, bytes) = written(dir.path());
        let count: u32 = 1 << 27;
        let mut header = bytes[..HEADER as usize].to_vec();
        header[28..32].copy_from_slice(&count.to_le_bytes());
        let length = HEADER + 8 * u64::from(count) + 5 * 3 * 24 + 8;
        let file = std::fs::File::create(&path).unwrap();
        std::io::Write::write_all(&mut &file, &header).unwrap();
        file.set_len(length).unwrap();
        match FilmFile::read(&path, 1 << 30) {
            Err(FilmFileError::TooLarge { bytes, ranges, .. }) => {
                assert_eq!((bytes, ranges), (8 * u64::from(count) + 5 * 3 * 24, count))
            }
            other => panic!("expected TooLarge, got {other:?}"),
        }
        let started = std::time::Instant::now();
        assert_eq!(
            corrupt_field(FilmFile::read(&path, u64::MAX)),
            "sample ranges"
        );
        assert!(
            started.elapsed().as_secs_f64() < 1.0,
            "{:?}",
            started.elapsed()
        );
    }

    /// A FIFO named as a film file is refused, not opened (opening it blocks until a writer
    /// comes: for ever).
    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_not_waited_on() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("film.vfilm");
        assert!(std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success());
        let (send, receive) = std::sync::mpsc::channel();
        let read = fifo.clone();
        std::thread::spawn(move || send.send(FilmFile::read(&read, u64::MAX).map(|_| ())));
        let result = receive
            .recv_timeout(std::time::Duration::from_secs(10))
            .expect("reading a FIFO returns");
        let err = result.unwrap_err();
        assert!(err.to_string().contains("FIFO"), "{err}");
        let checkpoint = Checkpoint::read(&fifo, 0, (1, 1), 0, u64::MAX).unwrap_err();
        assert!(checkpoint.to_string().contains("FIFO"), "{checkpoint}");
    }

    #[test]
    fn ranges_out_of_order_or_overlapping_are_refused_even_with_a_good_checksum() {
        let dir = tempfile::tempdir().unwrap();
        let (path, bytes) = written(dir.path());
        for (a, b) in [(1u32, 2u32), (3, 6), (4, 6), (12, 12)] {
            let mut bad = bytes.clone();
            bad[40..44].copy_from_slice(&a.to_le_bytes());
            bad[44..48].copy_from_slice(&b.to_le_bytes());
            std::fs::write(&path, resealed(bad)).unwrap();
            assert_eq!(
                corrupt_field(FilmFile::read(&path, u64::MAX)),
                "sample ranges",
                "second range {a}..{b}"
            );
        }
        let mut none = example();
        none.ranges.clear();
        assert!(matches!(
            none.write(&path),
            Err(FilmFileError::Invalid { .. })
        ));
    }

    #[test]
    fn a_checkpoint_reads_as_a_film_of_samples_from_zero() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("render.ckpt");
        let checkpoint = Checkpoint {
            fingerprint: 42,
            seed: 3,
            samples: 17,
            film: film(4, 2),
        };
        checkpoint.write(&path).unwrap();
        let read = FilmFile::read(&path, u64::MAX).unwrap();
        assert_eq!(read.ranges, vec![0..17]);
        assert_eq!((read.fingerprint, read.seed), (42, 3));
        assert_eq!(read.film, checkpoint.film);
    }

    #[test]
    fn ranges_normalise_to_sorted_joined_runs() {
        assert_eq!(
            normalize_ranges(vec![8..9, 0..2, 2..4, 5..5, 3..6]),
            vec![0..6, 8..9]
        );
        assert_eq!(format_ranges(&[0..2, 4..6]), "0..2, 4..6");
    }
}
