//! `volpt render --checkpoint FILE` / `--resume FILE`: long renders that survive interruption.
//!
//! The render runs in chunks of samples; after each chunk, and when Ctrl-C arrives, the film's sums
//! and the sample count go to the checkpoint file (written atomically). `--resume` reads one back
//! and continues with the next sample. Sample `s` of a pixel is the same path whenever it is traced
//! and the sums are added in sample order, so the resumed render's image is the uninterrupted one's
//! bit for bit (`volpt-film`'s `checkpoint` module has the file format).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use volpt_film::checkpoint::{Checkpoint, Fnv};
use volpt_render::{Effects, Film, Image, RenderStats};
use volpt_scene::{AlbedoDesc, DensityDesc, EnvironmentDesc, GridLookup, SceneDescription};

use crate::backend::{Backend, RenderJob};

/// Where to save and where to resume from, and how often to save.
pub struct Checkpointing {
    pub save: PathBuf,
    pub resume: Option<PathBuf>,
    pub interval: Duration,
}

/// What an interrupted render returns instead of an image.
pub struct Interrupted {
    pub samples: u32,
    pub path: PathBuf,
}

/// Renders `job` to its full sample count in chunks, saving after each; `Ok(Err(..))` when Ctrl-C
/// stopped it (the checkpoint holds every finished sample).
pub fn render(
    backend: &Backend,
    job: &RenderJob,
    checkpointing: &Checkpointing,
) -> Result<std::result::Result<(Image, RenderStats), Interrupted>> {
    let spp = job.options.spp;
    let (width, height) = (job.desc.film.width, job.desc.film.height);
    let fingerprint = fingerprint(job);
    let mut state = match &checkpointing.resume {
        Some(path) => {
            let state = Checkpoint::read(path, fingerprint, (width, height), job.options.seed)?;
            if state.samples > spp {
                bail!(
                    "{}: the checkpoint holds {} samples per pixel, more than the {spp} asked for",
                    path.display(),
                    state.samples
                );
            }
            eprintln!(
                "resuming from {} at sample {}",
                path.display(),
                state.samples
            );
            state
        }
        None => Checkpoint {
            fingerprint,
            seed: job.options.seed,
            samples: 0,
            film: Film::new(width, height),
        },
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    // A second Ctrl-C while the first chunk finishes ends the process at once.
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
        eprintln!("\ninterrupted: saving the samples finished so far (Ctrl-C again to quit now)");
    })
    .context("installing the Ctrl-C handler")?;

    let mut stats = RenderStats {
        elapsed: Duration::ZERO,
        counters: Default::default(),
    };
    let mut chunk = 1;
    while state.samples < spp {
        let samples = state.samples..(state.samples + chunk).min(spp);
        let started = Instant::now();
        let done = backend.render_into(job, &mut state.film, samples.clone())?;
        stats.elapsed += done.elapsed;
        stats.counters = stats.counters.merge(done.counters);
        state.samples = samples.end;
        state.write(&checkpointing.save)?;
        if interrupted.load(Ordering::SeqCst) && state.samples < spp {
            return Ok(Err(Interrupted {
                samples: state.samples,
                path: checkpointing.save.clone(),
            }));
        }
        // Chunks grow towards one checkpoint interval of work.
        let per_sample = started.elapsed().as_secs_f64() / samples.len() as f64;
        let fit = checkpointing.interval.as_secs_f64() / per_sample.max(1e-9);
        chunk = (fit as u32).clamp(1, chunk.saturating_mul(4));
    }
    Ok(Ok((state.film.image(spp), stats)))
}

/// What makes two renders the same render: the scene as loaded (film, camera, integrator limits,
/// boundary, medium with its grids, environment with its map), the variant choice and the
/// integrator settings. The seed and the film size are checked on their own, with clearer messages.
pub fn fingerprint(job: &RenderJob) -> u64 {
    let desc: &SceneDescription = job.desc;
    let mut h = Fnv::default();
    let mut text = |t: String| h.write(t.as_bytes());
    text(format!(
        "{:?}{:?}{:?}{:?}{:?}{:?}",
        desc.camera, desc.film, desc.integrator, desc.boundary, desc.medium.phase, job.settings
    ));
    text(format!(
        "{}{}",
        desc.medium.scale,
        job.effects == Effects::General
    ));
    // Only a non-default lookup enters, so that checkpoints of trilinear renders written before
    // the lookup existed still resume.
    if desc.medium.lookup != GridLookup::Trilinear {
        text(format!("{:?}", desc.medium.lookup));
    }
    let mut floats = |values: &[f32]| {
        for v in values {
            h.write(&v.to_bits().to_le_bytes());
        }
    };
    match &desc.medium.density {
        DensityDesc::Constant(v) => floats(&[*v]),
        DensityDesc::Grid(g) => {
            floats(&g.data);
            h_grid(&mut floats, g);
        }
    }
    match &desc.medium.albedo {
        AlbedoDesc::Constant(rgb) => floats(rgb),
        AlbedoDesc::Grid(g) => {
            floats(&g.data);
            h_grid(&mut floats, g);
        }
    }
    match &desc.environment {
        EnvironmentDesc::Constant(rgb) => floats(rgb),
        EnvironmentDesc::LatLong(map) => {
            floats(&map.rgb);
            floats(&[map.scale, map.width as f32, map.height as f32]);
            floats(map.to_world.as_flattened());
        }
    }
    h.finish()
}

/// A grid's shape and placement, as numbers for the fingerprint.
fn h_grid(floats: &mut impl FnMut(&[f32]), g: &volpt_scene::GridDesc) {
    let shape = [
        g.resolution[0],
        g.resolution[1],
        g.resolution[2],
        g.channels,
    ];
    floats(&shape.map(|n| n as f32));
    floats(&g.bounds.min);
    floats(&g.bounds.max);
    floats(&[matches!(g.convention, volpt_scene::GridConvention::Vertex) as u8 as f32]);
}

/// `FILE` of `--checkpoint FILE`, or the resumed file when only `--resume` is given.
pub fn save_path(checkpoint: Option<&Path>, resume: Option<&Path>) -> Option<PathBuf> {
    checkpoint.or(resume).map(Path::to_owned)
}
