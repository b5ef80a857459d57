//! Films of sample ranges rendered anywhere (`volpt render --samples A..B --film FILE`: another
//! process, machine or cluster task), read, checked and merged into the film of their union.
//!
//! Sample `s` of pixel `p` is the same path wherever it is traced, so films of disjoint ranges of
//! one render add up to the film of all their samples; the only difference from one uninterrupted
//! render is the order of the `f64` additions. [`merge_films`] adds films in a fixed order (by
//! their first sample), so the same films give the same bits in whatever order they are named.
//!
//! The file format is `volpt-film`'s [`volpt_film::film_file`] (`VOLPTFL1`); a checkpoint
//! (`VOLPTCK1`) reads as a film of samples `0..n`.

use std::ops::Range;
use std::path::Path;

use thiserror::Error;
pub use volpt_film::film_file::FilmFile;
use volpt_film::film_file::{format_ranges, normalize_ranges};

use crate::Error;

/// Reads the film file (or checkpoint) at `path`; a film larger than the process's memory limit
/// (`volpt_scene::limits`, `--memory-limit`) is refused before its sums are read.
pub fn read_film(path: &Path) -> Result<FilmFile, Error> {
    Ok(FilmFile::read(path, volpt_scene::limits::memory_limit())?)
}

/// Films that do not add up to one render, each reason with the files it concerns.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum MergeError {
    #[error("nothing to merge: no films")]
    Empty,
    /// A film of another render than the first film's.
    #[error(
        "{file} is a film of another render than {reference}: its {field} is {found}, \
         {reference}'s is {expected}"
    )]
    Mismatch {
        file: String,
        reference: String,
        field: &'static str,
        expected: String,
        found: String,
    },
    /// Two films hold the same samples: adding both would count them twice.
    #[error("{first} and {second} both hold samples {}..{}", overlap.start, overlap.end)]
    Overlap {
        first: String,
        second: String,
        overlap: Range<u32>,
    },
    /// A film holds samples beyond the render's sample count.
    #[error(
        "{file} holds samples {}..{}, beyond the {spp} samples per pixel expected",
        range.start, range.end
    )]
    Beyond {
        file: String,
        range: Range<u32>,
        spp: u32,
    },
    /// Samples of `0..spp` that no film holds.
    #[error(
        "samples {} are in no film (the films hold {}): render them (`volpt render SCENE \
         --samples A..B --film FILE`) and merge again, or merge the samples held into a noisier \
         image (`volpt merge --allow-gaps`)",
        format_ranges(missing),
        format_ranges(held)
    )]
    Gaps {
        missing: Vec<Range<u32>>,
        held: Vec<Range<u32>>,
    },
}

/// The films merged: their sums, the union of their ranges, and the samples no film holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    pub film: FilmFile,
    /// Samples of `0..spp` (`spp`: the one asked for, else the last sample held) in no film.
    pub missing: Vec<Range<u32>>,
}

impl Merged {
    /// The merged film if it holds every sample, else [`MergeError::Gaps`].
    pub fn complete(self) -> Result<FilmFile, MergeError> {
        if self.missing.is_empty() {
            Ok(self.film)
        } else {
            Err(MergeError::Gaps {
                missing: self.missing,
                held: self.film.ranges,
            })
        }
    }
}

/// Adds `films` (each with a name for messages: its file) into the film of all their samples.
///
/// Refused: no films; films of another render than the first (fingerprint, seed, film size);
/// films holding the same sample; with `spp`, samples at or beyond it. Gaps are not refused but
/// listed in [`Merged::missing`] (within `0..spp`, or up to the last sample held); see
/// [`Merged::complete`].
///
/// The films are added in the order of their first sample (then of their names), whatever order
/// they come in: one set of films always gives the same bits.
pub fn merge_films(
    mut films: Vec<(String, FilmFile)>,
    spp: Option<u32>,
) -> Result<Merged, MergeError> {
    films.sort_by(|(an, a), (bn, b)| {
        let first = |f: &FilmFile| f.ranges.first().map(|r| (r.start, r.end));
        first(a).cmp(&first(b)).then_with(|| an.cmp(bn))
    });
    let Some((reference, first)) = films.first() else {
        return Err(MergeError::Empty);
    };
    for (name, film) in &films[1..] {
        let mismatch = |field, expected: String, found: String| MergeError::Mismatch {
            file: name.clone(),
            reference: reference.clone(),
            field,
            expected,
            found,
        };
        if film.fingerprint != first.fingerprint {
            return Err(mismatch(
                "scene fingerprint (the scene and every setting that changes its image)",
                format!("{:016x}", first.fingerprint),
                format!("{:016x}", film.fingerprint),
            ));
        }
        if film.seed != first.seed {
            return Err(mismatch(
                "seed",
                first.seed.to_string(),
                film.seed.to_string(),
            ));
        }
        let size = |f: &FilmFile| (f.film.width, f.film.height);
        if size(film) != size(first) {
            let text = |(w, h): (u32, u32)| format!("{w}x{h}");
            return Err(mismatch("film size", text(size(first)), text(size(film))));
        }
    }
    // Every range of every film, by start: two that overlap are next to each other.
    let mut all: Vec<(Range<u32>, &str)> = films
        .iter()
        .flat_map(|(name, f)| f.ranges.iter().map(move |r| (r.clone(), name.as_str())))
        .collect();
    all.sort_by_key(|(r, _)| (r.start, r.end));
    for pair in all.windows(2) {
        let ((a, an), (b, bn)) = (&pair[0], &pair[1]);
        if b.start < a.end {
            return Err(MergeError::Overlap {
                first: an.to_string(),
                second: bn.to_string(),
                overlap: b.start..a.end.min(b.end),
            });
        }
    }
    if let Some(spp) = spp {
        if let Some((range, name)) = all.iter().find(|(r, _)| r.end > spp) {
            return Err(MergeError::Beyond {
                file: name.to_string(),
                range: range.clone(),
                spp,
            });
        }
    }
    let ranges = normalize_ranges(all.iter().map(|(r, _)| r.clone()).collect());
    let end = spp.unwrap_or_else(|| ranges.last().map_or(0, |r| r.end));
    let mut missing = Vec::new();
    let mut at = 0;
    for r in ranges.iter().chain(std::iter::once(&(end..end))) {
        if r.start > at {
            missing.push(at..r.start);
        }
        at = r.end;
    }

    let mut films = films.into_iter().map(|(_, f)| f);
    let mut merged = films.next().expect("checked: at least one film");
    for film in films {
        merged.film.add(&film.film);
    }
    merged.ranges = ranges;
    Ok(Merged {
        film: merged,
        missing,
    })
}
