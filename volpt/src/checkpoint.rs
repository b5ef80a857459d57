//! Long renders that survive interruption, and films of disjoint sample ranges added up.
//!
//! [`render_checkpointed`] renders in chunks; after each, and when the observer cancels, the film's
//! sums and the sample count go to the checkpoint file (written atomically; the format is
//! `volpt-film`'s `checkpoint` module's). Resuming reads it back and continues with the next
//! sample: sample `s` of a pixel is the same path whenever it is traced and the sums are added in
//! sample order, so the resumed render's image is the uninterrupted one's bit for bit.

use std::ops::Range;
use std::path::PathBuf;
use std::time::Duration;

use volpt_film::checkpoint::Checkpoint;
use volpt_film::{Film, FilmFile};

use crate::films::{merge_films, MergeError, Merged};
use crate::{Backend, Error, Observer, Rendered, Scene};

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
        return Err(Error::Settings(
            "--checkpoint-interval must be a positive number of seconds".into(),
        ));
    }
    let spp = scene.spp();
    let fingerprint = scene.fingerprint();
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
                return Err(Error::Settings(format!(
                    "{}: the checkpoint holds {} samples per pixel, more than the {spp} asked for",
                    path.display(),
                    state.samples
                )));
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
        backend.render_chunks(scene, &mut film, start..spp, &chunked, &mut save)?
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
    /// The render's [`Scene::fingerprint`].
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
