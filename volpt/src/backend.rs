//! [`Backend`]: where a render runs, opened once and reused (a GPU's kernels compile once), and
//! [`Backend::render`], which adds a range of samples of a [`Scene`] to a [`Film`].
//!
//! Sample `s` of pixel `p` is the same path on every backend and in every chunk (counter-based
//! random numbers), and every backend adds a pixel's samples in sample order: so a render in
//! chunks, resumed, or split into ranges gives the uninterrupted render's sums.

use std::ops::Range;
use std::time::{Duration, Instant};

use volpt_core::GridLayout;
use volpt_cuda::{CudaRenderer, Math, Schedule, Strategy};
use volpt_film::{Film, RenderOptions, RenderStats};
use volpt_render::{render_samples, with_scene_as, RenderScene, SceneVisitor};
use volpt_scene::GridStorage;
use volpt_zerocopy::{VolumeMemory, VolumePolicy};

use crate::auto::{self, AutoCache};
use crate::{Error, Observer, Scene};

/// The kind of machine a render runs on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BackendKind {
    /// Every CPU core, through rayon.
    #[default]
    Cpu,
    /// An NVIDIA GPU through the CUDA driver.
    Cuda,
}

/// A GPU strategy: chosen by measurement, or fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrategyChoice {
    /// The fastest for the scene on this GPU, by calibration renders, cached ([`crate::auto`]).
    Auto,
    Fixed(Strategy),
}

impl std::fmt::Display for StrategyChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StrategyChoice::Auto => f.write_str("auto"),
            StrategyChoice::Fixed(s) => write!(f, "{s}"),
        }
    }
}

/// How the GPU schedules, computes and places grids. Every field left `None` is the default; on
/// the CPU every field must be left so.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Default: auto's cached choice, a calibration for a render long enough to repay it, else
    /// regeneration-sk.
    pub strategy: Option<StrategyChoice>,
    /// Default: exact (bit-identical to the CPU).
    pub math: Option<Math>,
    /// A cap on the kernel's registers per thread.
    pub max_registers: Option<u32>,
    /// regeneration-sk's refill threshold (idle lanes of a warp).
    pub refill_at: Option<u32>,
    /// `[columns, rows]`: the image in tiles, each rendered by its own launches.
    pub tiles: Option<[u32; 2]>,
    /// Where the GPU reads grids from (default: auto).
    pub volume_memory: Option<VolumeMemory>,
    /// The most GPU memory the grids may take (default: what the GPU has free, less 512M).
    pub device_memory_budget: Option<u64>,
    /// Grids in 8^3 bricks on the GPU (the same image bit for bit).
    pub bricked: bool,
}

/// What [`Backend::open`] opens.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BackendOptions {
    pub kind: BackendKind,
    pub gpu: GpuOptions,
}

impl BackendOptions {
    pub fn cuda(gpu: GpuOptions) -> Self {
        Self {
            kind: BackendKind::Cuda,
            gpu,
        }
    }
}

/// An opened backend.
pub struct Backend(Inner);

// One backend per process or per viewer: the GPU variant's size costs nothing worth a box.
#[allow(clippy::large_enum_variant)]
enum Inner {
    Cpu,
    Cuda {
        renderer: CudaRenderer,
        /// A fixed schedule, or `None` for `auto`.
        schedule: Option<Schedule>,
        /// `auto` by default (no strategy named): calibrates only a render that repays it.
        implicit_auto: bool,
        math: Math,
        storage: GridStorage,
        auto: AutoCache,
    },
}

/// What a [`Backend::render`] did.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub stats: RenderStats,
    /// The samples the film now holds of those asked for: all of them, or fewer when the
    /// observer cancelled.
    pub samples: Range<u32>,
    /// The GPU schedule that ran (`None` on the CPU).
    pub schedule: Option<Schedule>,
}

impl Rendered {
    pub fn cancelled(&self, asked: &Range<u32>) -> bool {
        self.samples.end < asked.end
    }
}

impl Backend {
    /// The CPU backend.
    pub fn cpu() -> Self {
        Backend(Inner::Cpu)
    }

    /// Opens the backend `options` name; options that do not apply to it are refused.
    pub fn open(options: &BackendOptions) -> Result<Self, Error> {
        let gpu = &options.gpu;
        match options.kind {
            BackendKind::Cpu => {
                refuse_on_cpu(gpu)?;
                Ok(Self::cpu())
            }
            BackendKind::Cuda => {
                let math = gpu.math.unwrap_or_default();
                let schedule = schedule(gpu)?;
                let knobs =
                    gpu.tiles.is_some() || gpu.refill_at.is_some() || gpu.max_registers.is_some();
                let mut renderer = CudaRenderer::new(0, math)?;
                renderer.set_volume_policy(VolumePolicy {
                    memory: gpu.volume_memory.unwrap_or(VolumeMemory::Auto),
                    layout: if gpu.bricked {
                        GridLayout::Bricked
                    } else {
                        GridLayout::Dense
                    },
                    budget: gpu.device_memory_budget,
                });
                Ok(Backend(Inner::Cuda {
                    renderer,
                    schedule,
                    implicit_auto: gpu.strategy.is_none() && !knobs,
                    math,
                    storage: if gpu.bricked {
                        GridStorage::Bricked
                    } else {
                        GridStorage::Dense
                    },
                    auto: AutoCache::open(),
                }))
            }
        }
    }

    /// Gives `scene` the grid storage this backend renders from (bricks for `bricked`), so that
    /// the factory picks kernels that read it. [`Backend::render`] refuses a scene not prepared.
    pub fn prepare(&self, scene: &mut Scene) {
        scene.set_storage(self.storage());
    }

    fn storage(&self) -> GridStorage {
        match &self.0 {
            Inner::Cpu => GridStorage::Dense,
            Inner::Cuda { storage, .. } => *storage,
        }
    }

    /// The machine this backend runs on, as reports name it.
    pub fn device_name(&self) -> String {
        match &self.0 {
            Inner::Cpu => format!(
                "CPU, {} threads",
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
            Inner::Cuda { renderer, .. } => renderer.device_name().to_owned(),
        }
    }

    pub fn kind(&self) -> BackendKind {
        match &self.0 {
            Inner::Cpu => BackendKind::Cpu,
            Inner::Cuda { .. } => BackendKind::Cuda,
        }
    }

    /// The strategy asked for (`auto` or a fixed one); `None` on the CPU.
    pub fn strategy(&self) -> Option<StrategyChoice> {
        match &self.0 {
            Inner::Cpu => None,
            Inner::Cuda { schedule, .. } => {
                Some(schedule.map_or(StrategyChoice::Auto, |s| StrategyChoice::Fixed(s.strategy)))
            }
        }
    }

    /// The GPU's kernels; `None` on the CPU.
    pub fn math(&self) -> Option<Math> {
        match &self.0 {
            Inner::Cpu => None,
            Inner::Cuda { math, .. } => Some(*math),
        }
    }

    /// The GPU renderer, for what the facade does not wrap (self tests); `None` on the CPU.
    pub fn cuda(&self) -> Option<&CudaRenderer> {
        match &self.0 {
            Inner::Cpu => None,
            Inner::Cuda { renderer, .. } => Some(renderer),
        }
    }

    /// Adds samples `samples` of every pixel of `scene` to `film`, which holds the samples before
    /// them (none, for a range that starts at 0). The observer sees progress and notes and may
    /// stop the render between chunks ([`Observer::check_every`]).
    pub fn render(
        &self,
        scene: &Scene,
        film: &mut Film,
        samples: Range<u32>,
        observer: &dyn Observer,
    ) -> Result<Rendered, Error> {
        self.render_chunks(scene, film, samples, observer, &mut |_, _| Ok(()))
    }

    /// [`Backend::render`], calling `after_chunk(film, samples_done)` after every chunk: where a
    /// checkpoint is written.
    pub fn render_chunks(
        &self,
        scene: &Scene,
        film: &mut Film,
        samples: Range<u32>,
        observer: &dyn Observer,
        after_chunk: &mut dyn FnMut(&Film, u32) -> Result<(), Error>,
    ) -> Result<Rendered, Error> {
        let desc = scene.description();
        if desc.medium.storage != self.storage() {
            return Err(Error::Settings(format!(
                "the scene's grids are stored {:?} but this backend reads them {:?}: call \
                 Backend::prepare on the scene first",
                desc.medium.storage,
                self.storage()
            )));
        }
        let (width, height) = scene.resolution();
        if (film.width, film.height) != (width, height) {
            return Err(Error::Settings(format!(
                "the film is {}x{} but the scene renders {width}x{height}",
                film.width, film.height
            )));
        }
        let visitor = Render {
            backend: self,
            auto_key: self.auto_key(scene),
            options: scene.options(),
            film,
            samples,
            observer,
            after_chunk,
        };
        with_scene_as(desc, scene.path_settings(), scene.effects(), visitor)
    }

    /// The key of a scene's `auto` choice: the GPU, the math and the scene as rendered.
    fn auto_key(&self, scene: &Scene) -> String {
        format!(
            "{}|{}|{:016x}",
            self.device_name(),
            self.math().map_or("-", |m| m.name()),
            scene.fingerprint()
        )
    }
}

/// Refuses GPU options for the CPU backend, naming the option and what to do.
fn refuse_on_cpu(gpu: &GpuOptions) -> Result<(), Error> {
    let refuse = |message: String| Err(Error::Settings(message));
    if let Some(strategy) = gpu.strategy {
        return refuse(format!(
            "--strategy {strategy} schedules GPU work; the CPU backend has no strategies (use \
             --backend cuda, or drop --strategy)"
        ));
    }
    if let Some(n) = gpu.max_registers {
        return refuse(format!(
            "--max-registers {n} caps the GPU kernels' registers; the CPU backend has none (use \
             --backend cuda, or drop --max-registers)"
        ));
    }
    if let Some(n) = gpu.refill_at {
        return refuse(format!(
            "--refill-at {n} sets a GPU strategy's refill threshold; the CPU backend has no \
             strategies (use --backend cuda, or drop --refill-at)"
        ));
    }
    if let Some([c, r]) = gpu.tiles {
        return refuse(format!(
            "--tiles {c},{r} splits the GPU's launches; the CPU backend has no launches (use \
             --backend cuda, or drop --tiles)"
        ));
    }
    if let Some(math) = gpu.math {
        return refuse(format!(
            "--math {math} chooses the GPU's kernels; the CPU backend always computes exactly \
             (use --backend cuda, or drop --math)"
        ));
    }
    if gpu.volume_memory.is_some() || gpu.device_memory_budget.is_some() || gpu.bricked {
        return refuse(
            "--volume-memory, --device-memory-budget and --bricked place grids for the GPU; the \
             CPU backend reads them where they were loaded (use --backend cuda, or drop them)"
                .into(),
        );
    }
    Ok(())
}

/// The fixed schedule the GPU options name, or `None` for `auto`. A flag that sets one
/// strategy's knob names that strategy's default, regeneration-sk.
fn schedule(gpu: &GpuOptions) -> Result<Option<Schedule>, Error> {
    let knobs = gpu.tiles.is_some() || gpu.refill_at.is_some() || gpu.max_registers.is_some();
    let default = if knobs {
        StrategyChoice::Fixed(Strategy::RegenerationSk)
    } else {
        StrategyChoice::Auto
    };
    let refuse = |message: String| Err(Error::Settings(message));
    match gpu.strategy.unwrap_or(default) {
        StrategyChoice::Auto => {
            if let Some([c, r]) = gpu.tiles {
                return refuse(format!(
                    "--tiles {c},{r} with --strategy auto: name a strategy to tile its launches"
                ));
            }
            if let Some(n) = gpu.refill_at {
                return refuse(format!(
                    "--refill-at {n} with --strategy auto: name the strategy (--strategy \
                     regeneration-sk) to set its refill threshold"
                ));
            }
            if let Some(n) = gpu.max_registers {
                return refuse(format!(
                    "--max-registers {n} with --strategy auto: auto chooses the register cap too \
                     (name a strategy to set it)"
                ));
            }
            Ok(None)
        }
        StrategyChoice::Fixed(strategy)
            if gpu.refill_at.is_some() && strategy != Strategy::RegenerationSk =>
        {
            refuse(format!(
                "--refill-at sets regeneration-sk's refill threshold; {strategy} schedules paths \
                 otherwise (use --strategy regeneration-sk)"
            ))
        }
        StrategyChoice::Fixed(strategy) => Ok(Some(Schedule {
            strategy,
            max_registers: gpu.max_registers,
            refill_at: gpu.refill_at,
            tiles: gpu.tiles,
        })),
    }
}

/// One render, handed the monomorphised scene by the factory.
struct Render<'a> {
    backend: &'a Backend,
    auto_key: String,
    options: RenderOptions,
    film: &'a mut Film,
    samples: Range<u32>,
    observer: &'a dyn Observer,
    after_chunk: &'a mut dyn FnMut(&Film, u32) -> Result<(), Error>,
}

impl SceneVisitor for Render<'_> {
    type Output = Result<Rendered, Error>;

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let Render {
            backend,
            auto_key,
            options,
            film,
            samples,
            observer,
            after_chunk,
        } = self;
        let camera = scene.camera();
        let pixels = u64::from(camera.width) * u64::from(camera.height);
        let total = pixels * u64::from(samples.end - samples.start);
        // Once for the whole range, so that `auto` weighs the whole render against a calibration.
        let schedule = match &backend.0 {
            Inner::Cpu => None,
            Inner::Cuda {
                schedule: Some(schedule),
                ..
            } => Some(*schedule),
            Inner::Cuda {
                renderer,
                schedule: None,
                implicit_auto,
                auto,
                ..
            } => Some(auto_schedule(
                renderer,
                auto,
                &auto_key,
                scene,
                &options,
                *implicit_auto && !auto::repays_calibration(total),
                observer,
            )?),
        };

        let mut stats = RenderStats {
            elapsed: Duration::ZERO,
            counters: Default::default(),
        };
        let mut done = samples.start;
        let mut chunk = match observer.check_every() {
            Some(_) => 1,
            None => samples.end - samples.start,
        };
        while done < samples.end {
            let range = done..done.saturating_add(chunk).min(samples.end);
            let before = pixels * u64::from(done - samples.start);
            let chunk_paths = pixels * u64::from(range.end - range.start);
            // Backends report their own counts of this chunk; scaled to paths of the whole range.
            let report = |d: u64, t: u64| {
                let part = (u128::from(d) * u128::from(chunk_paths))
                    .checked_div(u128::from(t))
                    .map_or(0, |p| p as u64);
                observer.progress(before + part, total);
            };
            let started = Instant::now();
            let chunk_stats = match (&backend.0, schedule) {
                (Inner::Cuda { renderer, .. }, Some(schedule)) => renderer.render_samples(
                    scene,
                    schedule,
                    film,
                    range.clone(),
                    &options,
                    &report,
                )?,
                _ => render_samples(scene, film, range.clone(), &options, &report)?,
            };
            stats.elapsed += chunk_stats.elapsed;
            stats.counters = stats.counters.merge(chunk_stats.counters);
            done = range.end;
            after_chunk(film, done)?;
            if done < samples.end && observer.cancelled() {
                break;
            }
            // Chunks grow towards one `check_every` of work, at most fourfold each time.
            if let Some(every) = observer.check_every() {
                let per_sample =
                    started.elapsed().as_secs_f64() / f64::from(range.end - range.start);
                let fit = every.as_secs_f64() / per_sample.max(1e-9);
                chunk = (fit as u32).clamp(1, chunk.saturating_mul(4));
            }
        }
        Ok(Rendered {
            stats,
            samples: samples.start..done,
            schedule,
        })
    }
}

/// The cached `auto` choice for `key`, or a new calibration (noted and cached); without a cached
/// choice and with `skip_calibration`, regeneration-sk ([`auto::DEFAULT`]).
fn auto_schedule<S: RenderScene>(
    renderer: &CudaRenderer,
    cache: &AutoCache,
    key: &str,
    scene: &S,
    options: &RenderOptions,
    skip_calibration: bool,
    observer: &dyn Observer,
) -> Result<Schedule, Error> {
    if let Some((choice, schedule)) = cache.get(key).and_then(|c| c.schedule().map(|s| (c, s))) {
        observer.note(&format!("(cached) {}", choice.report()));
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
    observer.note("auto: calibrating the GPU strategies on this scene (cached afterwards)\n");
    let choice = auto::calibrate(renderer, scene, options)?;
    observer.note(&choice.report());
    let schedule = choice
        .schedule()
        .expect("calibration chooses among the strategies");
    cache.insert(key.to_owned(), choice);
    Ok(schedule)
}
