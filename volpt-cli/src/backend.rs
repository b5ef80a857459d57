//! The backends a render can run on, behind one call.

use std::ops::Range;
use std::time::Duration;

use anyhow::Result;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use volpt_core::PathSettings;
use volpt_cuda::{CudaRenderer, Strategy};
use volpt_render::{
    render_samples, with_scene_as, Effects, Film, Image, RenderOptions, RenderScene, RenderStats,
    SceneVisitor,
};
use volpt_scene::SceneDescription;

use crate::volume::VolumeArgs;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BackendKind {
    /// Every CPU core, through rayon.
    Cpu,
    /// An NVIDIA GPU through the CUDA driver.
    Cuda,
}

/// One render: the scene, the integrator's limits and the sampling options.
pub struct RenderJob<'a> {
    pub desc: &'a SceneDescription,
    pub settings: PathSettings,
    pub options: RenderOptions,
    /// Specialised to the scene's effects, or the general variant (`--general`).
    pub effects: Effects,
    pub show_progress: bool,
}

/// An opened backend, reused across renders (a GPU's kernels are loaded once).
pub enum Backend {
    Cpu,
    Cuda {
        renderer: CudaRenderer,
        strategy: Strategy,
    },
}

impl Backend {
    /// Opens `kind`; `strategy` is the GPU scheduling strategy (regeneration-sk by default).
    pub fn open(kind: BackendKind, strategy: Option<Strategy>) -> Result<Self> {
        match kind {
            BackendKind::Cpu => {
                if let Some(strategy) = strategy {
                    anyhow::bail!(
                        "--strategy {strategy} schedules GPU work; the CPU backend has no \
                         strategies (use --backend cuda, or drop --strategy)"
                    );
                }
                Ok(Backend::Cpu)
            }
            BackendKind::Cuda => Ok(Backend::Cuda {
                renderer: CudaRenderer::new(0)?,
                strategy: strategy.unwrap_or(Strategy::RegenerationSk),
            }),
        }
    }

    /// Where the GPU reads the scene's grids from (`--volume-memory` and its companions).
    pub fn place_volumes(&mut self, volumes: &VolumeArgs) -> Result<()> {
        match self {
            Backend::Cpu => volumes.check_cpu(),
            Backend::Cuda { renderer, .. } => {
                renderer.set_volume_policy(volumes.policy());
                Ok(())
            }
        }
    }

    /// What the report calls the machine this backend runs on.
    pub fn device_name(&self) -> String {
        match self {
            Backend::Cpu => format!(
                "CPU, {} threads",
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
            Backend::Cuda { renderer, .. } => renderer.device_name().to_owned(),
        }
    }

    pub fn strategy(&self) -> Option<Strategy> {
        match self {
            Backend::Cpu => None,
            Backend::Cuda { strategy, .. } => Some(*strategy),
        }
    }

    pub fn render(&self, job: &RenderJob) -> Result<(Image, RenderStats)> {
        let mut film = Film::new(job.desc.film.width, job.desc.film.height);
        let stats = self.render_into(job, &mut film, 0..job.options.spp)?;
        Ok((film.image(job.options.spp), stats))
    }

    /// Adds samples `samples` of every pixel to `film`, which holds the samples before them.
    pub fn render_into(
        &self,
        job: &RenderJob,
        film: &mut Film,
        samples: Range<u32>,
    ) -> Result<RenderStats> {
        let visitor = Render {
            backend: self,
            options: job.options,
            film,
            samples,
            progress: progress_bar(job.show_progress),
        };
        with_scene_as(job.desc, job.settings, job.effects, visitor)
    }
}

struct Render<'a> {
    backend: &'a Backend,
    options: RenderOptions,
    film: &'a mut Film,
    samples: Range<u32>,
    progress: ProgressBar,
}

impl SceneVisitor for Render<'_> {
    type Output = Result<RenderStats>;

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let bar = &self.progress;
        let report = |done, total| {
            bar.set_length(total);
            bar.set_position(done);
        };
        let (film, samples, options) = (self.film, self.samples, &self.options);
        let stats = match self.backend {
            Backend::Cpu => render_samples(scene, film, samples, options, &report)?,
            Backend::Cuda { renderer, strategy } => {
                renderer.render_samples(scene, *strategy, film, samples, options, &report)?
            }
        };
        bar.finish_and_clear();
        Ok(stats)
    }
}

fn progress_bar(show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {wide_bar} {percent}% eta {eta}",
        )
        .expect("static template"),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}
