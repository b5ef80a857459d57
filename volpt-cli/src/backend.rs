//! The backends a render can run on, behind one call.

use std::time::Duration;

use anyhow::Result;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use volpt_core::{PathSettings, Scene};
use volpt_render::{render, with_scene, Image, RenderOptions, RenderStats, SceneVisitor};
use volpt_scene::SceneDescription;

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
    /// The GPU scheduling strategy (ignored by the CPU).
    pub strategy: Option<&'a str>,
    pub show_progress: bool,
}

pub fn run(backend: BackendKind, job: &RenderJob) -> Result<(Image, RenderStats)> {
    match backend {
        BackendKind::Cpu => {
            if let Some(strategy) = job.strategy {
                anyhow::bail!(
                    "--strategy {strategy} schedules GPU work; the CPU backend has no strategies \
                     (use --backend cuda, or drop --strategy)"
                );
            }
            with_scene(
                job.desc,
                job.settings,
                CpuRender {
                    options: job.options,
                    show_progress: job.show_progress,
                },
            )
        }
        BackendKind::Cuda => anyhow::bail!(
            "this volpt was built without the CUDA backend (see the GPU backend issue)"
        ),
    }
}

struct CpuRender {
    options: RenderOptions,
    show_progress: bool,
}

impl SceneVisitor for CpuRender {
    type Output = Result<(Image, RenderStats)>;

    fn visit<S: Scene + Sync>(self, scene: &S) -> Self::Output {
        let bar = if self.show_progress {
            let bar = ProgressBar::new(0);
            bar.set_style(
                ProgressStyle::with_template(
                    "{spinner} [{elapsed_precise}] {wide_bar} {percent}% eta {eta}",
                )
                .expect("static template"),
            );
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        } else {
            ProgressBar::hidden()
        };
        let result = render(scene, &self.options, &|done, total| {
            bar.set_length(total);
            bar.set_position(done);
        });
        bar.finish_and_clear();
        Ok(result?)
    }
}

/// What the report calls the machine a backend ran on.
pub fn device_name(backend: BackendKind) -> String {
    match backend {
        BackendKind::Cpu => format!(
            "CPU, {} threads",
            std::thread::available_parallelism().map_or(1, |n| n.get())
        ),
        BackendKind::Cuda => "CUDA (not built)".to_owned(),
    }
}
