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
use volpt_film::Film;

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
            let state = Checkpoint::read(path, fingerprint, scene.resolution(), scene.seed())?;
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

/// Adds `parts` of one render into the film of all their samples, in the order of their ranges
/// (so the same partition gives the same bits whatever order the parts arrive in). Parts of
/// another render (fingerprint, seed, film size), overlapping ranges and gaps between ranges are
/// refused, each named.
pub fn merge(mut parts: Vec<Part>) -> Result<Part, Error> {
    parts.sort_by_key(|p| (p.samples.start, p.samples.end));
    let mut parts = parts.into_iter();
    let Some(mut merged) = parts.next() else {
        return Err(Error::Merge("nothing to merge: no films".into()));
    };
    for part in parts {
        let mismatch = |field: &str, expected: String, found: String| {
            Error::Merge(format!(
                "the film of samples {:?} is of another render: its {field} is {found}, the \
                 first film's is {expected}",
                part.samples
            ))
        };
        if part.fingerprint != merged.fingerprint {
            return Err(mismatch(
                "scene fingerprint",
                format!("{:016x}", merged.fingerprint),
                format!("{:016x}", part.fingerprint),
            ));
        }
        if part.seed != merged.seed {
            return Err(mismatch(
                "seed",
                merged.seed.to_string(),
                part.seed.to_string(),
            ));
        }
        let size = |f: &Film| format!("{}x{}", f.width, f.height);
        if (part.film.width, part.film.height) != (merged.film.width, merged.film.height) {
            return Err(mismatch("film", size(&merged.film), size(&part.film)));
        }
        if part.samples.start < merged.samples.end {
            return Err(Error::Merge(format!(
                "the films of samples {:?} and {:?} overlap",
                merged.samples, part.samples
            )));
        }
        if part.samples.start > merged.samples.end {
            return Err(Error::Merge(format!(
                "samples {:?} are in no film (between {:?} and {:?})",
                merged.samples.end..part.samples.start,
                merged.samples,
                part.samples
            )));
        }
        for (sum, add) in merged.film.sums.iter_mut().zip(&part.film.sums) {
            for c in 0..3 {
                sum[c] += add[c];
            }
        }
        merged.samples.end = part.samples.end;
    }
    Ok(merged)
}
