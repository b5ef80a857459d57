//! The backends a render can run on, behind one call.

use std::ops::Range;
use std::time::Duration;

use anyhow::Result;
use clap::ValueEnum;
use indicatif::{ProgressBar, ProgressStyle};
use volpt_core::{GridLayout, PathSettings};
use volpt_cuda::{CudaRenderer, Math, Schedule, Strategy};

use crate::auto::{self, AutoCache};
use volpt_render::{
    render_samples, with_scene_as, Effects, Film, Image, RenderOptions, RenderScene, RenderStats,
    SceneVisitor,
};
use volpt_scene::{GridStorage, SceneDescription};

use crate::volume::VolumeArgs;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BackendKind {
    /// Every CPU core, through rayon.
    Cpu,
    /// An NVIDIA GPU through the CUDA driver.
    Cuda,
}

/// `--strategy`: `auto` (chosen by measurement, see `auto`) or one of the GPU's strategies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrategyArg {
    Auto,
    Fixed(Strategy),
}

impl ValueEnum for StrategyArg {
    fn value_variants<'a>() -> &'a [Self] {
        static VARIANTS: std::sync::LazyLock<Vec<StrategyArg>> = std::sync::LazyLock::new(|| {
            std::iter::once(StrategyArg::Auto)
                .chain(Strategy::ALL.iter().map(|&s| StrategyArg::Fixed(s)))
                .collect()
        });
        &VARIANTS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(match self {
            StrategyArg::Auto => clap::builder::PossibleValue::new("auto"),
            StrategyArg::Fixed(s) => clap::builder::PossibleValue::new(s.name()),
        })
    }
}

impl std::fmt::Display for StrategyArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StrategyArg::Auto => f.write_str("auto"),
            StrategyArg::Fixed(s) => write!(f, "{s}"),
        }
    }
}

/// The flags that only the GPU backend takes: how it schedules and computes.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct GpuArgs {
    /// GPU scheduling strategy; `auto` picks the fastest for the scene by calibration renders,
    /// cached per scene and GPU (default: auto's cached choice, a calibration for a render long
    /// enough to repay it, else regeneration-sk).
    #[arg(long, value_enum)]
    pub strategy: Option<StrategyArg>,
    /// GPU arithmetic: `exact` is bit-identical to the CPU (default), `fast` uses the GPU's
    /// approximate instructions.
    #[arg(long, value_enum)]
    pub math: Option<Math>,
    /// Cap the GPU kernel's registers per thread (the JIT spills the rest): more threads resident
    /// per multiprocessor, at the price of spills.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(16..=255))]
    pub max_registers: Option<u32>,
    /// regeneration-sk: refill a warp's idle lanes with new paths once at least N of them are
    /// idle (default 8; 1 refills at once, 32 waits for the whole warp): fewer, fuller refills
    /// against lanes idling in between.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=32))]
    pub refill_at: Option<u32>,
    /// Cut the image into COLUMNS x ROWS tiles, each rendered by its own launches one after the
    /// other (the thesis's tiling study: smaller launches, more tails; docs/strategies.md).
    #[arg(long, value_name = "COLUMNS,ROWS")]
    pub tiles: Option<Tiles>,
}

/// `--tiles COLUMNS,ROWS`, each from 1 to 4096.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles(pub [u32; 2]);

impl std::str::FromStr for Tiles {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let parse = |v: &str| -> Result<u32, String> {
            v.trim()
                .parse::<u32>()
                .ok()
                .filter(|n| (1..=4096).contains(n))
                .ok_or_else(|| format!("expected COLUMNS,ROWS of 1 to 4096 each, found {s:?}"))
        };
        match s.split_once(',') {
            Some((c, r)) => Ok(Tiles([parse(c)?, parse(r)?])),
            None => Err(format!("expected COLUMNS,ROWS (e.g. 4,4), found {s:?}")),
        }
    }
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

/// An opened backend, reused across renders (a GPU's kernels are compiled once).
// One backend per process: the size of the GPU variant costs nothing worth a box.
#[allow(clippy::large_enum_variant)]
pub enum Backend {
    Cpu,
    Cuda {
        renderer: CudaRenderer,
        /// A fixed schedule, or `None` for `auto`.
        schedule: Option<Schedule>,
        /// `auto` by default (no `--strategy`): calibrates only a render that repays it.
        implicit_auto: bool,
        math: Math,
        auto: AutoCache,
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
                if let Some(n) = gpu.refill_at {
                    anyhow::bail!(
                        "--refill-at {n} sets a GPU strategy's refill threshold; the CPU backend \
                         has no strategies (use --backend cuda, or drop --refill-at)"
                    );
                }
                if let Some(Tiles([c, r])) = gpu.tiles {
                    anyhow::bail!(
                        "--tiles {c},{r} splits the GPU's launches; the CPU backend has no \
                         launches (use --backend cuda, or drop --tiles)"
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
                // A flag that sets one strategy's knob names that strategy's default.
                let knobs =
                    gpu.tiles.is_some() || gpu.refill_at.is_some() || gpu.max_registers.is_some();
                let implicit_auto = gpu.strategy.is_none() && !knobs;
                let default = if knobs {
                    StrategyArg::Fixed(Strategy::RegenerationSk)
                } else {
                    StrategyArg::Auto
                };
                let schedule = match gpu.strategy.unwrap_or(default) {
                    StrategyArg::Auto => {
                        if let Some(Tiles([c, r])) = gpu.tiles {
                            anyhow::bail!(
                                "--tiles {c},{r} with --strategy auto: name a strategy to tile \
                                 its launches"
                            );
                        }
                        if let Some(n) = gpu.refill_at {
                            anyhow::bail!(
                                "--refill-at {n} with --strategy auto: name the strategy \
                                 (--strategy regeneration-sk) to set its refill threshold"
                            );
                        }
                        if let Some(n) = gpu.max_registers {
                            anyhow::bail!(
                                "--max-registers {n} with --strategy auto: auto chooses the \
                                 register cap too (name a strategy to set it)"
                            );
                        }
                        None
                    }
                    StrategyArg::Fixed(strategy)
                        if gpu.refill_at.is_some() && strategy != Strategy::RegenerationSk =>
                    {
                        anyhow::bail!(
                            "--refill-at sets regeneration-sk's refill threshold; {strategy} \
                             schedules paths otherwise (use --strategy regeneration-sk)"
                        );
                    }
                    StrategyArg::Fixed(strategy) => Some(Schedule {
                        strategy,
                        max_registers: gpu.max_registers,
                        refill_at: gpu.refill_at,
                        tiles: gpu.tiles.map(|t| t.0),
                    }),
                };
                Ok(Backend::Cuda {
                    renderer: CudaRenderer::new(0, math)?,
                    schedule,
                    implicit_auto,
                    math,
                    auto: AutoCache::open(),
                })
            }
        }
    }

    /// Where the GPU reads the scene's grids from (`--volume-memory` and its companions). Bricked
    /// storage is recorded in `desc`, so that the factory picks kernels that read bricks.
    pub fn place_volumes(
        &mut self,
        volumes: &VolumeArgs,
        desc: &mut SceneDescription,
    ) -> Result<()> {
        match self {
            Backend::Cpu => volumes.check_cpu(),
            Backend::Cuda { renderer, .. } => {
                let policy = volumes.policy();
                if policy.layout == GridLayout::Bricked {
                    desc.medium.storage = GridStorage::Bricked;
                }
                renderer.set_volume_policy(policy);
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

    /// The strategy flag's value (`auto` or a strategy's name); `None` on the CPU.
    pub fn strategy(&self) -> Option<StrategyArg> {
        match self {
            Backend::Cpu => None,
            Backend::Cuda { schedule, .. } => {
                Some(schedule.map_or(StrategyArg::Auto, |s| StrategyArg::Fixed(s.strategy)))
            }
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
            auto_key: self.auto_key(job),
            options: job.options,
            film,
            samples,
            progress: progress_bar(job.show_progress),
        };
        with_scene_as(job.desc, job.settings, job.effects, visitor)
    }
}

impl Backend {
    /// The key of `job`'s `auto` choice: the GPU, the math and the scene as rendered.
    fn auto_key(&self, job: &RenderJob) -> String {
        format!(
            "{}|{}|{:016x}",
            self.device_name(),
            self.math().map_or("-", |m| m.name()),
            crate::checkpoint::fingerprint(job)
        )
    }
}

struct Render<'a> {
    backend: &'a Backend,
    auto_key: String,
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
                renderer,
                schedule,
                implicit_auto,
                auto,
                ..
            } => {
                let paths = render_paths(scene, &samples);
                let schedule = match schedule {
                    Some(schedule) => *schedule,
                    None => auto_schedule(
                        renderer,
                        auto,
                        &self.auto_key,
                        scene,
                        options,
                        *implicit_auto && !auto::repays_calibration(paths),
                    )?,
                };
                renderer.render_samples(scene, schedule, film, samples, options, &report)?
            }
        };
        bar.finish_and_clear();
        Ok(stats)
    }
}

/// Paths a render of `samples` of `scene`'s film traces.
fn render_paths<S: RenderScene>(scene: &S, samples: &Range<u32>) -> u64 {
    let camera = scene.camera();
    u64::from(camera.width) * u64::from(camera.height) * u64::from(samples.len() as u32)
}

/// The cached `auto` choice for `key`, or a new calibration (printed and cached); without a
/// cached choice and with `skip_calibration`, regeneration-sk (`auto::DEFAULT`).
fn auto_schedule<S: RenderScene>(
    renderer: &CudaRenderer,
    cache: &AutoCache,
    key: &str,
    scene: &S,
    options: &RenderOptions,
    skip_calibration: bool,
) -> Result<Schedule> {
    if let Some((choice, schedule)) = cache.get(key).and_then(|c| c.schedule().map(|s| (c, s))) {
        eprint!("(cached) {}", choice.report());
        return Ok(schedule);
    }
    if skip_calibration {
        tracing::debug!(
            "strategy {}: this render is too short to repay auto's calibration (--strategy auto \
             calibrates anyway)",
            auto::DEFAULT.name()
        );
        return Ok(auto::DEFAULT.into());
    }
    eprintln!("auto: calibrating the GPU strategies on this scene (cached afterwards)");
    let choice = auto::calibrate(renderer, scene, options)?;
    eprint!("{}", choice.report());
    let schedule = choice
        .schedule()
        .expect("calibration chooses among the strategies");
    cache.insert(key.to_owned(), choice);
    Ok(schedule)
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
