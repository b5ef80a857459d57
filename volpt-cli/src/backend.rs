//! The backends a render can run on, behind one call.

use std::ops::Range;
use std::time::Duration;

use anyhow::Result;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use volpt_core::PathSettings;
use volpt_cuda::{CudaRenderer, Math, Schedule, Strategy};
use volpt_render::{
    render_samples, with_scene_as, Effects, Film, Image, RenderOptions, RenderScene, RenderStats,
    SceneVisitor,
};
use volpt_scene::SceneDescription;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BackendKind {
    /// Every CPU core, through rayon.
    Cpu,
    /// An NVIDIA GPU through the CUDA driver.
    Cuda,
}

/// The flags that only the GPU backend takes: how it schedules and computes.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct GpuArgs {
    /// GPU scheduling strategy (default: regeneration-sk).
    #[arg(long, value_enum)]
    pub strategy: Option<Strategy>,
    /// GPU arithmetic: `exact` is bit-identical to the CPU (default), `fast` uses the GPU's
    /// approximate instructions.
    #[arg(long, value_enum)]
    pub math: Option<Math>,
    /// Cap the GPU kernel's registers per thread (the JIT spills the rest): more threads resident
    /// per multiprocessor, at the price of spills.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(16..=255))]
    pub max_registers: Option<u32>,
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
        schedule: Schedule,
        math: Math,
    },
}

impl Backend {
    /// Opens `kind`; `gpu` holds the GPU's flags (regeneration-sk and exact math by default).
    pub fn open(kind: BackendKind, gpu: GpuArgs) -> Result<Self> {
        match kind {
            BackendKind::Cpu => {
                if let Some(strategy) = gpu.strategy {
                    anyhow::bail!(
                        "--strategy {strategy} schedules GPU work; the CPU backend has no \
                         strategies (use --backend cuda, or drop --strategy)"
                    );
                }
                if let Some(n) = gpu.max_registers {
                    anyhow::bail!(
                        "--max-registers {n} caps the GPU kernels' registers; the CPU backend has \
                         none (use --backend cuda, or drop --max-registers)"
                    );
                }
                if let Some(math) = gpu.math {
                    anyhow::bail!(
                        "--math {math} chooses the GPU's kernels; the CPU backend always computes \
                         exactly (use --backend cuda, or drop --math)"
                    );
                }
                Ok(Backend::Cpu)
            }
            BackendKind::Cuda => {
                let math = gpu.math.unwrap_or_default();
                Ok(Backend::Cuda {
                    renderer: CudaRenderer::new(0, math)?,
                    schedule: Schedule {
                        strategy: gpu.strategy.unwrap_or(Strategy::RegenerationSk),
                        max_registers: gpu.max_registers,
                    },
                    math,
                })
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
            Backend::Cuda { schedule, .. } => Some(schedule.strategy),
        }
    }

    pub fn math(&self) -> Option<Math> {
        match self {
            Backend::Cpu => None,
            Backend::Cuda { math, .. } => Some(*math),
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
            Backend::Cuda {
                renderer, schedule, ..
            } => renderer.render_samples(scene, *schedule, film, samples, options, &report)?,
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
