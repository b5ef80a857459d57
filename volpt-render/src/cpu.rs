//! The CPU backend: every core traces whole paths with the shared path step.
//!
//! Samples are taken in passes over the image, so the film always holds an equal number of samples per
//! pixel and a render stopped early is still unbiased. Each pass splits the image into rows for rayon;
//! sums are kept in f64, so that millions of f32 samples per pixel do not lose low bits.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rayon::prelude::*;
use thiserror::Error;
use volpt_core::path::{trace, PathCounters, PathState};
use volpt_core::Scene;

use crate::image::Image;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderOptions {
    pub spp: u32,
    pub seed: u32,
    /// Worker threads; `None` uses every core.
    pub threads: Option<usize>,
}

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

#[derive(Debug, Error)]
pub enum RenderError {
    #[error("cannot start {threads} render threads: {source}")]
    ThreadPool {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error("nothing to render: the image is {width}x{height} with {spp} samples per pixel")]
    Empty { width: u32, height: u32, spp: u32 },
}

/// Samples per pixel in one pass: small enough for a live progress report, large enough that the
/// per-pass overhead stays negligible.
const SAMPLES_PER_PASS: u32 = 4;

/// Renders `scene`, calling `progress(done, total)` with sample counts as passes finish rows.
pub fn render<S: Scene + Sync>(
    scene: &S,
    options: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<(Image, RenderStats), RenderError> {
    let (width, height) = (scene.camera().width, scene.camera().height);
    if width == 0 || height == 0 || options.spp == 0 {
        return Err(RenderError::Empty {
            width,
            height,
            spp: options.spp,
        });
    }
    let threads = options.threads.unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|source| RenderError::ThreadPool { threads, source })?;

    let mut film = vec![[0.0f64; 3]; (width * height) as usize];
    let total = width as u64 * height as u64 * options.spp as u64;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let counters = pool.install(|| {
        let mut counters = PathCounters::default();
        let mut first = 0;
        while first < options.spp {
            let samples = first..(first + SAMPLES_PER_PASS).min(options.spp);
            let pass = film
                .par_chunks_mut(width as usize)
                .enumerate()
                .map(|(y, row)| {
                    let mut row_counters = PathCounters::default();
                    for (x, sum) in row.iter_mut().enumerate() {
                        for sample in samples.clone() {
                            let mut path = PathState::from_camera(
                                scene,
                                x as u32,
                                y as u32,
                                sample,
                                options.seed,
                            );
                            trace(scene, &mut path);
                            row_counters.record(&path);
                            for (s, r) in sum.iter_mut().zip(path.radiance.to_array()) {
                                *s += r as f64;
                            }
                        }
                    }
                    let n = done.fetch_add(width as u64 * samples.len() as u64, Ordering::Relaxed);
                    progress(n + width as u64 * samples.len() as u64, total);
                    row_counters
                })
                .reduce(PathCounters::default, PathCounters::merge);
            counters = counters.merge(pass);
            first = samples.end;
        }
        counters
    });
    let elapsed = start.elapsed();

    let inv_spp = 1.0 / options.spp as f64;
    let pixels = film
        .iter()
        .map(|sum| sum.map(|c| (c * inv_spp) as f32))
        .collect();
    Ok((
        Image {
            width,
            height,
            pixels,
        },
        RenderStats { elapsed, counters },
    ))
}
