//! What a render produces, whichever backend ran it.
//!
//! - [`Film`]: the per-pixel `f64` sums of the samples' radiance, and the image they average to.
//! - [`image`]: the image ([`Image`]) and its files (OpenEXR, PNG preview).
//! - [`RenderStats`]: time and path counters, with the throughputs reported from them.
//! - [`RenderOptions`]: how many samples, with which seed.
//! - [`checkpoint`]: a render's sums saved to a file, to resume it bit for bit.
//! - [`film_file`]: the sums of any sample ranges of a render, to merge with the other ranges'.
//! - [`regular`]: opening only regular files (a FIFO would block a reader for ever).
//! - [`tone`]: the viewer's frames (exposure, sRGB, 8 bits) on the CPU.

pub mod checkpoint;
pub mod film_file;
pub mod image;
pub mod regular;
pub mod tone;

use std::ops::Range;
use std::time::Duration;

use thiserror::Error;
use volpt_core::PathCounters;

pub use checkpoint::{Checkpoint, CheckpointError};
pub use film_file::{FilmFile, FilmFileError};
pub use image::{preview_path, Image, ImageError};

/// How many samples per pixel to trace, with which seed: the same seed gives the same paths on
/// every backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    pub spp: u32,
    pub seed: u32,
    /// CPU worker threads; `None` uses every core. GPU backends ignore it.
    pub threads: Option<usize>,
}

/// Per-pixel sums of sample radiance in `f64`, row-major from the top-left pixel: millions of `f32`
/// samples per pixel do not lose their low bits.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub sums: Vec<[f64; 3]>,
    /// The precision a backend adds samples in (the sums are stored in `f64` either way).
    pub accumulation: Accumulation,
}

/// The precision of a film's per-pixel sums.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Accumulation {
    /// Every sample is added in `f64`.
    #[default]
    F64,
    /// Every sample is added in `f32` and the sum rounded to `f32`, as an `f32` film would: once a
    /// sum is 2^24 times a sample, the sample's low bits are lost. CPU backend only; the GPU film
    /// sums in `f64`.
    F32,
}

impl Accumulation {
    /// `sum + sample` in this precision.
    #[inline]
    pub fn add(self, sum: f64, sample: f64) -> f64 {
        match self {
            Accumulation::F64 => sum + sample,
            Accumulation::F32 => (sum as f32 + sample as f32) as f64,
        }
    }
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            sums: vec![[0.0; 3]; width as usize * height as usize],
            accumulation: Accumulation::F64,
        }
    }

    /// Whether any sum is other than `+0.0`, the bits a new film starts with: a film that holds
    /// none holds no samples yet.
    pub fn holds_samples(&self) -> bool {
        self.flat_sums().iter().any(|sum| sum.to_bits() != 0)
    }

    /// The sums as one slice, red, green and blue of each pixel in turn (how devices store them).
    pub fn flat_sums(&self) -> &[f64] {
        self.sums.as_flattened()
    }

    /// The sums as one mutable slice, as [`Film::flat_sums`].
    pub fn flat_sums_mut(&mut self) -> &mut [f64] {
        self.sums.as_flattened_mut()
    }

    /// Adds `other`'s sums to this film's, pixel by pixel (a film of other samples of the same
    /// image: the sum of both).
    pub fn add(&mut self, other: &Film) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "films of one image"
        );
        for (sum, add) in self.flat_sums_mut().iter_mut().zip(other.flat_sums()) {
            *sum += add;
        }
    }

    /// The same film, adding samples in `accumulation`.
    pub fn with_accumulation(self, accumulation: Accumulation) -> Self {
        Self {
            accumulation,
            ..self
        }
    }

    /// Checks that samples `samples` of a `width` x `height` camera can be added to this film: the
    /// precondition of every backend's `render_samples`.
    ///
    /// # Panics
    /// If the film is not the camera's size (a caller's bug, not bad input).
    pub fn check_pass(
        &self,
        (width, height): (u32, u32),
        samples: &Range<u32>,
    ) -> Result<(), NothingToRender> {
        if width == 0 || height == 0 || samples.is_empty() {
            return Err(NothingToRender {
                width,
                height,
                spp: samples.len() as u32,
            });
        }
        assert_eq!(
            (self.width, self.height),
            (width, height),
            "the film must be the camera's"
        );
        Ok(())
    }

    /// The image of `spp` samples per pixel: each sum times `1 / spp`, rounded to `f32`.
    pub fn image(&self, spp: u32) -> Image {
        let inv_spp = 1.0 / spp as f64;
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .map(|sum| sum.map(|c| (c * inv_spp) as f32))
                .collect(),
        }
    }
}

/// A render of no pixels or no samples.
#[derive(Clone, Copy, Debug, Error, PartialEq, Eq)]
#[error("nothing to render: the image is {width}x{height} with {spp} samples per pixel")]
pub struct NothingToRender {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
}

/// How long a render took and what it traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderStats {
    pub elapsed: Duration,
    pub counters: PathCounters,
}

impl RenderStats {
    pub fn paths_per_second(&self) -> f64 {
        self.counters.paths as f64 / self.elapsed.as_secs_f64()
    }
    pub fn segments_per_second(&self) -> f64 {
        self.counters.segments as f64 / self.elapsed.as_secs_f64()
    }
    pub fn tracking_steps_per_second(&self) -> f64 {
        self.counters.tracking_steps as f64 / self.elapsed.as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Only a film of `+0.0` bits holds nothing: a `-0.0` or any other sum is something a
    /// device must continue from.
    #[test]
    fn a_film_holds_samples_once_any_sum_has_other_bits_than_zero() {
        let mut film = Film::new(3, 2);
        assert!(!film.holds_samples());
        film.sums[5][2] = -0.0;
        assert!(film.holds_samples());
        film.flat_sums_mut().fill(0.0);
        assert!(!film.holds_samples());
        film.flat_sums_mut()[1] = f64::MIN_POSITIVE;
        assert_eq!(film.sums[0][1], f64::MIN_POSITIVE);
        assert!(film.holds_samples());
    }

    /// At 2^24 an f32 sum no longer changes by 1; an f64 sum does.
    #[test]
    fn f32_accumulation_loses_what_f32_cannot_hold() {
        let big = (1u32 << 24) as f64;
        assert_eq!(Accumulation::F32.add(big, 1.0), big);
        assert_eq!(Accumulation::F64.add(big, 1.0), big + 1.0);
        assert_eq!(Accumulation::F32.add(0.1, 0.2), (0.1f32 + 0.2f32) as f64);
    }
}
