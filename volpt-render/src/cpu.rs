//! The CPU backend: every core traces whole paths with the shared path step.
//!
//! Samples are taken in passes over the image, so the film always holds an equal number of samples per
//! pixel and a render stopped early is still unbiased. Each pass splits the image into rows for rayon;
//! a pixel's samples are traced and summed by the core's `sample_pixel`, the very loop the GPU's
//! naive strategy runs, so that the two agree bit for bit.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use thiserror::Error;
use volpt_core::path::{sample_pixel, PathCounters};
use volpt_core::Scene;
use volpt_film::{Film, Image, RenderOptions, RenderStats};

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

    let mut film = Film::new(width, height);
    let total = width as u64 * height as u64 * options.spp as u64;
    let done = AtomicU64::new(0);
    let start = Instant::now();
    let counters = pool.install(|| {
        let mut counters = PathCounters::default();
        let mut first = 0;
        while first < options.spp {
            let samples = first..(first + SAMPLES_PER_PASS).min(options.spp);
            let pass = film
                .sums
                .par_chunks_mut(width as usize)
                .enumerate()
                .map(|(y, row)| {
                    let mut row_counters = PathCounters::default();
                    for (x, sum) in row.iter_mut().enumerate() {
                        let pixel = (x as u32, y as u32);
                        let seed = options.seed;
                        sample_pixel(scene, pixel, samples.clone(), seed, sum, &mut row_counters);
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

    Ok((film.image(options.spp), RenderStats { elapsed, counters }))
}
