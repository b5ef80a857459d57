//! Long renders that survive interruption, and films of disjoint sample ranges added up.
//!
//! [`render_checkpointed`] renders in chunks; after each, and when the observer cancels, the film's
//! sums and the sample count go to the checkpoint file (written atomically; the format is
//! `volpt-film`'s `checkpoint` module's). Resuming reads it back and continues with the next
//! sample: sample `s` of a pixel is the same path whenever it is traced and the sums are added in
//! sample order, so the resumed render's image is the uninterrupted one's bit for bit.

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::Duration;

use volpt_film::checkpoint::{Checkpoint, CheckpointError};
use volpt_film::{Film, FilmFile, FilmFileError};

use crate::films::{merge_films, MergeError, Merged};
use crate::{Backend, Error, Observer, RenderRequest, Rendered, Scene};

/// Where to save and where to resume from, and how often to save.
#[derive(Clone, Debug)]
pub struct Checkpointing {
    pub save: PathBuf,
    pub resume: Option<PathBuf>,
    pub interval: Duration,
}

/// Renders `scene` to its full sample count, saving a checkpoint after every chunk of about
/// `interval`; returns the film and what was rendered. When the observer cancels, the film and the
/// checkpoint hold every finished sample ([`Rendered::samples`] ends early).
pub fn render_checkpointed(
    backend: &Backend,
    scene: &Scene,
    checkpointing: &Checkpointing,
    observer: &dyn Observer,
) -> Result<(Film, Rendered), Error> {
    if checkpointing.interval.is_zero() {
        return Err(Error::Setting {
            key: "checkpoint_interval",
            expected: "a positive number of seconds".into(),
            found: format!("{:?}", checkpointing.interval),
        });
    }
    let spp = scene.spp();
    let fingerprint = backend.fingerprint(scene, &RenderRequest::samples(0..spp))?;
    let state = match &checkpointing.resume {
        Some(path) => {
            let state = Checkpoint::read(
                path,
                fingerprint,
                scene.resolution(),
                scene.seed(),
                volpt_scene::limits::memory_limit(),
            )?;
            if state.samples > spp {
                return Err(Error::conflict(
                    "spp",
                    spp,
                    "resume",
                    path.display(),
                    format!(
                        "the checkpoint holds {} samples per pixel, more than the {spp} asked \
                         for",
                        state.samples
                    ),
                ));
            }
            observer.note(&format!(
                "resuming from {} at sample {}\n",
                path.display(),
                state.samples
            ));
            state
        }
        None => Checkpoint {
            fingerprint,
            seed: scene.seed(),
            samples: 0,
            film: scene.film(),
        },
    };
    let chunked = Chunked {
        inner: observer,
        every: checkpointing.interval,
    };
    let start = state.samples;
    let seed = state.seed;
    let mut film = state.film;
    let mut save = |film: &Film, samples: u32| {
        Checkpoint::write_film(&checkpointing.save, fingerprint, seed, samples, film)
            .map_err(Error::from)
    };
    let rendered = if start < spp {
        let request = RenderRequest::samples(start..spp).with_seed(seed);
        backend.render_chunks(scene, &mut film, &request, &chunked, &mut save)?
    } else {
        Rendered {
            stats: volpt_film::RenderStats {
                elapsed: Duration::ZERO,
                counters: Default::default(),
            },
            samples: start..start,
            schedule: None,
        }
    };
    Ok((film, rendered))
}

/// The caller's observer, asked to look at cancellation every checkpoint interval.
struct Chunked<'a> {
    inner: &'a dyn Observer,
    every: Duration,
}

impl Observer for Chunked<'_> {
    fn progress(&self, done: u64, total: u64) {
        self.inner.progress(done, total)
    }
    fn note(&self, text: &str) {
        self.inner.note(text)
    }
    fn cancelled(&self) -> bool {
        self.inner.cancelled()
    }
    fn check_every(&self) -> Option<Duration> {
        Some(self.every)
    }
}

/// A film of one render's samples `samples` (of every pixel), rendered anywhere.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The render's fingerprint ([`Backend::fingerprint`]).
    pub fingerprint: u64,
    pub seed: u32,
    pub samples: Range<u32>,
    pub film: Film,
}

/// Adds `parts` of one render into the film of all their samples, as [`merge_films`] adds film
/// files (in the order of their ranges, so the same partition gives the same bits whatever order
/// the parts arrive in; parts of another render, overlapping ranges refused). The merged samples
/// must be one range: a gap between two parts is refused, naming it.
pub fn merge(parts: Vec<Part>) -> Result<Part, Error> {
    let films = parts
        .into_iter()
        .map(|p| {
            let name = format!("the film of samples {:?}", p.samples);
            let file = FilmFile {
                fingerprint: p.fingerprint,
                seed: p.seed,
                ranges: vec![p.samples],
                film: p.film,
            };
            (name, file)
        })
        .collect();
    let Merged { film, missing } = merge_films(films, None)?;
    // `merge_films` counts from sample 0; parts may start later.
    let first = film.ranges.first().map_or(0, |r| r.start);
    let missing: Vec<_> = missing.into_iter().filter(|r| r.start >= first).collect();
    if !missing.is_empty() {
        return Err(MergeError::Gaps {
            missing,
            held: film.ranges,
        }
        .into());
    }
    let FilmFile {
        fingerprint,
        seed,
        ranges,
        film,
    } = film;
    let samples = ranges.first().map_or(0..0, |r| r.clone());
    Ok(Part {
        fingerprint,
        seed,
        samples,
        film,
    })
}

impl Part {
    /// Saves the part as a checkpoint, which `volpt render --resume` continues: a checkpoint holds
    /// samples `0..n`, so a part of later samples is refused.
    pub fn save_checkpoint(&self, path: &Path) -> Result<(), Error> {
        if self.samples.start != 0 {
            return Err(CheckpointError::NotFromZero {
                path: path.to_owned(),
                samples: self.samples.clone(),
            }
            .into());
        }
        Ok(Checkpoint::write_film(
            path,
            self.fingerprint,
            self.seed,
            self.samples.end,
            &self.film,
        )?)
    }

    /// The checkpoint at `path` as the part of its samples `0..n`. With `scene`, a checkpoint of
    /// another scene (fingerprint) or film size is refused; without, the checkpoint is read as
    /// its header says, and its checksum checked.
    pub fn read_checkpoint(path: &Path, scene: Option<&Scene>) -> Result<Part, Error> {
        let header = Checkpoint::header(path);
        let (fingerprint, size, seed) = match (scene, header) {
            // The scene's, where the header is unreadable: the reader then says why.
            (Some(scene), header) => (
                scene.fingerprint(),
                scene.resolution(),
                header.map_or(scene.seed(), |h| h.seed),
            ),
            (None, header) => {
                let h = header?;
                (h.fingerprint, (h.width, h.height), h.seed)
            }
        };
        let limit = volpt_scene::limits::memory_limit();
        let checkpoint = Checkpoint::read(path, fingerprint, size, seed, limit)?;
        Ok(Part {
            fingerprint: checkpoint.fingerprint,
            seed: checkpoint.seed,
            samples: 0..checkpoint.samples,
            film: checkpoint.film,
        })
    }

    /// The part as a film file ([`FilmFile`]) of its one range.
    pub fn film_file(&self) -> FilmFile {
        FilmFile {
            fingerprint: self.fingerprint,
            seed: self.seed,
            ranges: vec![self.samples.clone()],
            film: self.film.clone(),
        }
    }

    /// The part of a film file of one range; `path` names it in the refusal of several.
    fn of_film_file(file: FilmFile, path: &Path) -> Result<Part, Error> {
        let samples = match file.ranges.as_slice() {
            [range] => range.clone(),
            ranges => {
                return Err(FilmFileError::NotOneRange {
                    path: path.to_owned(),
                    ranges: ranges.to_vec(),
                }
                .into())
            }
        };
        Ok(Part {
            fingerprint: file.fingerprint,
            seed: file.seed,
            samples,
            film: file.film,
        })
    }

    /// Writes the part as a film file (`VOLPTFL1`, what `volpt render --film` writes), atomically.
    pub fn write_film(&self, path: &Path) -> Result<(), Error> {
        Ok(self.film_file().write(path)?)
    }

    /// The part of the film file (or checkpoint) at `path`; a film of several ranges (a merge
    /// with gaps) is refused.
    pub fn read_film(path: &Path) -> Result<Part, Error> {
        Self::of_film_file(crate::read_film(path)?, path)
    }

    /// The part as the film file's bytes: how it travels between processes without a file.
    pub fn to_bytes(&self) -> Result<Vec<u8>, Error> {
        Ok(self.film_file().to_bytes()?)
    }

    /// The part of [`Part::to_bytes`]'s bytes, checked as a film file is.
    pub fn from_bytes(bytes: &[u8]) -> Result<Part, Error> {
        let limit = volpt_scene::limits::memory_limit();
        let file = FilmFile::from_bytes(bytes, limit)?;
        Self::of_film_file(file, Path::new(volpt_film::film_file::BYTES))
    }
}
