//! The CPU backend: every core traces whole paths with the shared path step.
//!
//! Samples are taken in passes over the image, so the film always holds an equal number of samples per
//! pixel and a render stopped early is still unbiased. Each pass splits the image into rows for rayon;
//! a pixel's samples are traced and summed by the core's `sample_pixel`, the very loop the GPU's
//! naive strategy runs, so that the two agree bit for bit.

use std::ops::Range;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use thiserror::Error;
use volpt_core::path::{sample_pixel, PathCounters};
use volpt_core::Scene;
use volpt_film::{Accumulation, Film, Image, NothingToRender, RenderOptions, RenderStats};

#[derive(Debug, Error)]
pub enum RenderError {
    #[error("cannot start {threads} render threads: {source}")]
    ThreadPool {
        threads: usize,
        source: rayon::ThreadPoolBuildError,
    },
    #[error(transparent)]
    Empty(#[from] NothingToRender),
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
    let mut film = Film::new(width, height);
    let stats = render_samples(scene, &mut film, 0..options.spp, options, progress)?;
    Ok((film.image(options.spp), stats))
}

/// Adds samples `samples` of every pixel to `film` (which holds the samples before them, for a
/// resumed render), calling `progress(done, total)` with counts of this call's samples.
pub fn render_samples<S: Scene + Sync>(
    scene: &S,
    film: &mut Film,
    samples: Range<u32>,
    options: &RenderOptions,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<RenderStats, RenderError> {
    let (width, height) = (scene.camera().width, scene.camera().height);
    film.check_pass((width, height), &samples)?;
    let threads = options.threads.unwrap_or(0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|source| RenderError::ThreadPool { threads, source })?;

    let total = width as u64 * height as u64 * samples.len() as u64;
    let done = AtomicU64::new(0);
    let accumulation = film.accumulation;
    let start = Instant::now();
    let counters = pool.install(|| {
        let mut counters = PathCounters::default();
        let mut first = samples.start;
        while first < samples.end {
            // Saturating: a range ending at u32::MAX must not wrap its last pass's end to 0.
            let pass_samples = first..first.saturating_add(SAMPLES_PER_PASS).min(samples.end);
            let pass = film
                .sums
                .par_chunks_mut(width as usize)
                .enumerate()
                .map(|(y, row)| {
                    let mut row_counters = PathCounters::default();
                    for (x, sum) in row.iter_mut().enumerate() {
                        let pixel = (x as u32, y as u32);
                        let (range, seed) = (pass_samples.clone(), options.seed);
                        match accumulation {
                            Accumulation::F64 => {
                                sample_pixel(scene, pixel, range, seed, sum, &mut row_counters)
                            }
                            // One sample at a time: its f64 "sum" is the f32 radiance exactly.
                            Accumulation::F32 => {
                                for sample in range {
                                    let mut one = [0.0; 3];
                                    let range = sample..sample + 1;
                                    sample_pixel(
                                        scene,
                                        pixel,
                                        range,
                                        seed,
                                        &mut one,
                                        &mut row_counters,
                                    );
                                    for (s, o) in sum.iter_mut().zip(one) {
                                        *s = accumulation.add(*s, o);
                                    }
                                }
                            }
                        }
                    }
                    let n = width as u64 * pass_samples.len() as u64;
                    progress(done.fetch_add(n, Ordering::Relaxed) + n, total);
                    row_counters
                })
                .reduce(PathCounters::default, PathCounters::merge);
            counters = counters.merge(pass);
            first = pass_samples.end;
        }
        counters
    });
    Ok(RenderStats {
        elapsed: start.elapsed(),
        counters,
    })
}
