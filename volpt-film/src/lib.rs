//! What a render produces, whichever backend ran it.
//!
//! - [`Film`]: the per-pixel `f64` sums of the samples' radiance, and the image they average to.
//! - [`image`]: the image ([`Image`]) and its files (OpenEXR, PNG preview).
//! - [`RenderStats`]: time and path counters, with the throughputs reported from them.
//! - [`RenderOptions`]: how many samples, with which seed.
//! - [`checkpoint`]: a render's sums saved to a file, to resume it bit for bit.

pub mod checkpoint;
pub mod image;

use std::time::Duration;

use volpt_core::PathCounters;

pub use checkpoint::{Checkpoint, CheckpointError};
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
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            sums: vec![[0.0; 3]; width as usize * height as usize],
        }
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
