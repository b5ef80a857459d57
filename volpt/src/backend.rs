//! [`Backend`]: where a render runs, opened once and reused (a GPU's kernels compile once), and
//! [`Backend::render`], which adds a range of samples of a [`Scene`] to a [`Film`].
//!
//! Sample `s` of pixel `p` is the same path on every backend and in every chunk (counter-based
//! random numbers), and every backend adds a pixel's samples in sample order: so a render in
//! chunks, resumed, or split into ranges gives the uninterrupted render's sums.

use std::ops::{Range, RangeInclusive};
use std::time::{Duration, Instant};

use volpt_core::GridLayout;
use volpt_cuda::{CudaRenderer, Math, Schedule, Strategy};
use volpt_film::{Film, RenderOptions, RenderStats};
use volpt_gpu_mem::{VolumeMemory, VolumePolicy};
use volpt_render::{render_samples, with_scene_cached, RenderScene, SceneVisitor};
use volpt_scene::GridLookup;
use volpt_scene::GridStorage;

use crate::auto::{self, AutoCache};
use crate::scene::Reading;
use crate::{multi, Error, Named, Observer, RenderRequest, Scene};

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

/// The GPU's arithmetic when none is asked for: the fast kernels, which render images
/// statistically indistinguishable from the exact ones on every included scene at high sample
/// counts and are 1.1-2x faster (docs/accuracy.md, "Defaults"); `--math exact` gives the CPU's
/// bits (with naive-sk).
pub const DEFAULT_GPU_MATH: Math = Math::Fast;

/// How the GPU schedules, computes and places grids. Every field left `None` is the default; on
/// the CPU every field must be left so.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Default: auto's cached choice, a calibration for a render long enough to repay it, else
    /// regeneration-sk.
    pub strategy: Option<StrategyChoice>,
    /// Default: [`DEFAULT_GPU_MATH`], fast; `Some(Math::Exact)` is bit-identical to the CPU.
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
    /// The GPUs to render on together (default: GPU 0 alone).
    pub gpus: Gpus,
}

/// Which GPUs a CUDA backend renders on. With more than one, every GPU pulls batches of samples
/// from one queue into films of its own, added up in batch order ([`crate::multi`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Gpus {
    /// GPU 0 alone: one GPU's render, as without `--gpus`.
    #[default]
    First,
    /// Every GPU the driver sees.
    All,
    /// The GPUs whose ordinals are the set bits (`--gpus 0,2`: `0b101`).
    List(u64),
}

impl Gpus {
    /// The ordinals of these GPUs on a machine of `count` GPUs; a named GPU it lacks is refused.
    pub fn ordinals(&self, count: usize) -> Result<Vec<usize>, Error> {
        match *self {
            Gpus::First => Ok(vec![0]),
            Gpus::All if count == 0 => Err(Error::Setting {
                key: "gpus",
                expected: "GPUs the CUDA driver sees (it sees none on this machine)".into(),
                found: self.to_string(),
            }),
            Gpus::All => Ok((0..count).collect()),
            Gpus::List(0) => Err(Error::Setting {
                key: "gpus",
                expected: "at least one GPU".into(),
                found: "none".into(),
            }),
            Gpus::List(mask) => {
                let ordinals: Vec<usize> = (0..64).filter(|i| mask & (1 << i) != 0).collect();
                match ordinals.iter().find(|&&o| o >= count) {
                    Some(o) => Err(Error::Setting {
                        key: "gpus",
                        expected: format!(
                            "GPUs numbered 0 to {} (the CUDA driver sees {count} GPUs)",
                            count.saturating_sub(1)
                        ),
                        found: format!("GPU {o} in {self}"),
                    }),
                    None => Ok(ordinals),
                }
            }
        }
    }
}

impl std::fmt::Display for Gpus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Gpus::First => f.write_str("0"),
            Gpus::All => f.write_str("all"),
            Gpus::List(mask) => {
                let names: Vec<String> = (0..64)
                    .filter(|i| mask & (1u64 << i) != 0)
                    .map(|i: u32| i.to_string())
                    .collect();
                f.write_str(&names.join(","))
            }
        }
    }
}

impl std::str::FromStr for Gpus {
    type Err = String;

    /// `all`, or GPU ordinals separated by commas (`0,1`).
    fn from_str(s: &str) -> Result<Self, String> {
        crate::multi::parse_gpus(s)
    }
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
    /// The CPU as `n` devices pulling batches from one queue, as several GPUs do: the multi-GPU
    /// scheduler, tested where there is no GPU ([`Backend::cpu_as_devices`]).
    CpuDevices(usize),
    Cuda {
        /// One per GPU, in ordinal order; at least one. With one, renders run as they always
        /// have (one film, samples added in order); with more, through [`crate::multi`].
        renderers: Vec<CudaRenderer>,
        /// A fixed schedule, or `None` for `auto`.
        schedule: Option<Schedule>,
        /// `auto` by default (no strategy named): calibrates only a render that repays it.
        implicit_auto: bool,
        math: Math,
        storage: GridStorage,
        /// Where grids go: textures (the stochastic lookup's default route) need device memory.
        volumes: VolumePolicy,
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

    /// The CPU as `devices` devices that pull batches of samples from one queue and add them up in
    /// batch order, exactly as several GPUs do (`--gpus`): the multi-GPU scheduling, cancellation
    /// and checkpoints, tested and shown without GPUs. Each device uses every core.
    #[doc(hidden)]
    pub fn cpu_as_devices(devices: usize) -> Self {
        Backend(Inner::CpuDevices(devices.max(1)))
    }

    /// Opens the backend `options` name; options out of their bounds ([`MAX_REGISTERS`],
    /// [`REFILL_AT`], [`TILES`]) or that do not apply to it are refused.
    pub fn open(options: &BackendOptions) -> Result<Self, Error> {
        let gpu = &options.gpu;
        check_bounds(gpu)?;
        match options.kind {
            BackendKind::Cpu => {
                refuse_on_cpu(gpu)?;
                Ok(Self::cpu())
            }
            BackendKind::Cuda => {
                let math = gpu.math.unwrap_or(DEFAULT_GPU_MATH);
                let schedule = schedule(gpu)?;
                let knobs =
                    gpu.tiles.is_some() || gpu.refill_at.is_some() || gpu.max_registers.is_some();
                let ordinals = match gpu.gpus {
                    // Without --gpus, GPU 0 as always (no device count asked of the driver).
                    Gpus::First => vec![0],
                    gpus => gpus.ordinals(volpt_cuda::device_count()?)?,
                };
                let policy = VolumePolicy {
                    memory: gpu.volume_memory.unwrap_or(VolumeMemory::Auto),
                    layout: if gpu.bricked {
                        GridLayout::Bricked
                    } else {
                        GridLayout::Dense
                    },
                    budget: gpu.device_memory_budget,
                };
                // The first render's kernel is of this strategy (`auto` without a calibration
                // runs auto::DEFAULT): its kernels decompress while the driver opens the GPUs.
                let first = schedule.map_or(auto::DEFAULT.strategy, |s| s.strategy);
                volpt_cuda::kernels::prefetch(math, first);
                let renderers = ordinals
                    .into_iter()
                    .map(|ordinal| {
                        let mut renderer = CudaRenderer::new(ordinal, math)?;
                        renderer.set_volume_policy(policy);
                        Ok(renderer)
                    })
                    .collect::<Result<Vec<_>, Error>>()?;
                Ok(Backend(Inner::Cuda {
                    renderers,
                    schedule,
                    implicit_auto: gpu.strategy.is_none() && !knobs,
                    math,
                    storage: if gpu.bricked {
                        GridStorage::Bricked
                    } else {
                        GridStorage::Dense
                    },
                    volumes: policy,
                    auto: AutoCache::open(),
                }))
            }
        }
    }

    /// Makes `scene` read its grids as this backend does (its storage; its default lookup where
    /// nobody chose one) in place. Optional: a render of a scene read otherwise renders the same
    /// image from a copy of the scene's description, kept until the scene changes; adopting
    /// saves that copy (the grids' size in host memory) where one owner renders on one backend.
    pub fn adopt(&self, scene: &mut Scene) {
        let reading = Reading {
            storage: self.storage(),
            lookup: self.default_lookup(scene),
        };
        scene.adopt(reading);
    }

    /// How this backend reads `scene`'s grids for `request`.
    fn reading(&self, scene: &Scene, request: &RenderRequest) -> Reading {
        let lookup = request.lookup.unwrap_or_else(|| {
            if scene.lookup_chosen() {
                scene.description().medium.lookup
            } else {
                self.default_lookup(scene)
            }
        });
        Reading {
            storage: self.storage(),
            lookup,
        }
    }

    /// What makes the render `request` asks of `scene` on this backend the same render
    /// ([`crate::fingerprint`]): a film's [`crate::Part::fingerprint`]. Refused where the
    /// request's lookup does not fit the grids.
    pub fn fingerprint(&self, scene: &Scene, request: &RenderRequest) -> Result<u64, Error> {
        let desc = scene.read_as(self.reading(scene, request))?;
        Ok(scene.fingerprint_of(
            &desc,
            &request.path.unwrap_or(scene.path_settings()),
            request.effects.unwrap_or(scene.effects()),
        ))
    }

    /// The lookup a render without `--lookup` uses: on a GPU with fast math, stochastic
    /// trilinear (one sample chosen by its trilinear weight: unbiased, 1.15-1.7x the efficiency
    /// of trilinear on the grid scenes, docs/accuracy.md "Defaults"), where its grids can be
    /// read as it reads them (bricked grids in software; dense ones through textures, which need
    /// device memory: not with `--volume-memory zero-copy|managed`, nor for grids over half the
    /// device budget). Everywhere else trilinear, so that `--math exact` renders the CPU's image
    /// bit for bit (naive-sk), and the CPU renders as it always has.
    pub fn default_lookup(&self, scene: &Scene) -> GridLookup {
        let Inner::Cuda {
            renderers,
            math: Math::Fast,
            storage,
            volumes,
            ..
        } = &self.0
        else {
            return GridLookup::Trilinear;
        };
        let fits = || {
            if matches!(
                volumes.memory,
                VolumeMemory::ZeroCopy | VolumeMemory::Managed
            ) {
                return false;
            }
            let bytes = scene.texture_bytes();
            renderers.iter().all(|r| {
                r.free_memory()
                    .is_some_and(|free| bytes <= volumes.effective_budget(free) / 2)
            })
        };
        if *storage == GridStorage::Bricked || fits() {
            GridLookup::Stochastic
        } else {
            GridLookup::Trilinear
        }
    }

    fn storage(&self) -> GridStorage {
        match &self.0 {
            Inner::Cpu | Inner::CpuDevices(_) => GridStorage::Dense,
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
            Inner::CpuDevices(n) => format!(
                "CPU as {n} devices, {} threads",
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
            Inner::Cuda { renderers, .. } => {
                let names: Vec<&str> = renderers.iter().map(|r| r.device_name()).collect();
                if names.len() > 1 && names.iter().all(|n| *n == names[0]) {
                    format!("{} x{}", names[0], names.len())
                } else {
                    names.join(" + ")
                }
            }
        }
    }

    /// How many devices render together (1 but for `--gpus` of several).
    pub fn devices(&self) -> usize {
        match &self.0 {
            Inner::Cpu => 1,
            Inner::CpuDevices(n) => *n,
            Inner::Cuda { renderers, .. } => renderers.len(),
        }
    }

    /// The frame of `film` over `spp` samples at 2^`exposure` (8-bit sRGB RGB, as
    /// [`volpt_film::tone::tone_map`] of its image gives it within one level), tone mapped where
    /// the last render left the film: on one GPU, which sends back the frame's bytes alone.
    /// `None` where this backend has no such film (the CPU, several GPUs, or a `film` that is
    /// not what the last render left): the caller tone maps on the CPU.
    pub fn tone_map(&self, film: &Film, spp: u32, exposure: f32) -> Result<Option<Vec<u8>>, Error> {
        match &self.0 {
            Inner::Cuda { renderers, .. } if renderers.len() == 1 => {
                Ok(renderers[0].tone_map_film((film.width, film.height), spp, exposure)?)
            }
            _ => Ok(None),
        }
    }

    pub fn kind(&self) -> BackendKind {
        match &self.0 {
            Inner::Cpu | Inner::CpuDevices(_) => BackendKind::Cpu,
            Inner::Cuda { .. } => BackendKind::Cuda,
        }
    }

    /// The strategy asked for (`auto` or a fixed one); `None` on the CPU.
    pub fn strategy(&self) -> Option<StrategyChoice> {
        match &self.0 {
            Inner::Cpu | Inner::CpuDevices(_) => None,
            Inner::Cuda { schedule, .. } => {
                Some(schedule.map_or(StrategyChoice::Auto, |s| StrategyChoice::Fixed(s.strategy)))
            }
        }
    }

    /// The GPU's kernels; `None` on the CPU.
    pub fn math(&self) -> Option<Math> {
        match &self.0 {
            Inner::Cpu | Inner::CpuDevices(_) => None,
            Inner::Cuda { math, .. } => Some(*math),
        }
    }

    /// The (first) GPU renderer, for what the facade does not wrap (self tests); `None` on the
    /// CPU.
    pub fn cuda(&self) -> Option<&CudaRenderer> {
        match &self.0 {
            Inner::Cpu | Inner::CpuDevices(_) => None,
            Inner::Cuda { renderers, .. } => renderers.first(),
        }
    }

    /// Adds the samples `request` names of every pixel of `scene` to `film`, which holds the
    /// samples before them (none, for a range that starts at 0), with the request's seed, path
    /// settings and lookup over the scene's. The scene is only read: threads may render one scene
    /// at once. The observer sees progress and notes and may stop the render between chunks
    /// ([`Observer::check_every`]).
    pub fn render(
        &self,
        scene: &Scene,
        film: &mut Film,
        request: impl Into<RenderRequest>,
        observer: &dyn Observer,
    ) -> Result<Rendered, Error> {
        self.render_chunks(scene, film, &request.into(), observer, &mut |_, _| Ok(()))
    }

    /// [`Backend::render`], calling `after_chunk(film, samples_done)` after every chunk: where a
    /// checkpoint is written.
    pub fn render_chunks(
        &self,
        scene: &Scene,
        film: &mut Film,
        request: &RenderRequest,
        observer: &dyn Observer,
        after_chunk: &mut dyn FnMut(&Film, u32) -> Result<(), Error>,
    ) -> Result<Rendered, Error> {
        self.render_with(scene, film, request, observer, after_chunk, None)
    }

    /// [`Backend::render`] of samples `samples` in one go that returns at `deadline` with paths
    /// still in flight where the GPU's strategy keeps them between its launches (the
    /// multi-kernel strategies on one GPU; elsewhere the render finishes as always). Then
    /// [`Rendered::samples`] ends where it starts, and `film` holds the samples before the range
    /// plus the range's paths that have ended (what a frame over `samples.end` shows, short of
    /// the paths in flight); calling again with the same scene, film and range continues them,
    /// and any other render discards them. Every path is traced once, so the finished film is
    /// the uninterrupted render's: a viewer's frame need not wait for its longest path.
    pub fn render_until(
        &self,
        scene: &Scene,
        film: &mut Film,
        samples: Range<u32>,
        deadline: Instant,
    ) -> Result<Rendered, Error> {
        let request = RenderRequest::samples(samples);
        self.render_with(
            scene,
            film,
            &request,
            &crate::Quiet,
            &mut |_, _| Ok(()),
            Some(deadline),
        )
    }

    fn render_with(
        &self,
        scene: &Scene,
        film: &mut Film,
        request: &RenderRequest,
        observer: &dyn Observer,
        after_chunk: &mut dyn FnMut(&Film, u32) -> Result<(), Error>,
        deadline: Option<Instant>,
    ) -> Result<Rendered, Error> {
        let (width, height) = scene.resolution();
        if (film.width, film.height) != (width, height) {
            return Err(Error::FilmSize {
                film: (film.width, film.height),
                scene: (width, height),
            });
        }
        let desc = scene.read_as(self.reading(scene, request))?;
        let path = request.path.unwrap_or(scene.path_settings());
        let effects = request.effects.unwrap_or(scene.effects());
        let mut options = scene.options();
        if let Some(seed) = request.seed {
            options.seed = seed;
        }
        let (factory, grids) = scene.kept_data();
        let visitor = Render {
            backend: self,
            fingerprint: &|| scene.fingerprint_of(&desc, &path, effects),
            grids,
            options,
            film,
            samples: request.samples.clone(),
            observer,
            after_chunk,
            deadline,
        };
        with_scene_cached(&desc, path, effects, factory, visitor)
    }

    /// The key of a scene's `auto` choice: the GPU, the math and the scene as rendered (of
    /// `fingerprint`).
    fn auto_key(&self, fingerprint: u64) -> String {
        self.auto_key_on(&self.device_name(), fingerprint)
    }

    /// Each GPU's `auto` key (one GPU: [`Backend::auto_key`]'s). Per GPU, because the fastest
    /// strategy is a property of the GPU model: GPUs of one model share one calibration (the
    /// second finds the first's choice cached), GPUs of different models each get their own.
    fn auto_keys(&self, fingerprint: u64) -> Vec<String> {
        match &self.0 {
            Inner::Cuda { renderers, .. } if renderers.len() > 1 => renderers
                .iter()
                .map(|r| self.auto_key_on(r.device_name(), fingerprint))
                .collect(),
            _ => vec![self.auto_key(fingerprint)],
        }
    }

    /// The `auto` key of the scene of `fingerprint` on the GPU named `device`.
    fn auto_key_on(&self, device: &str, fingerprint: u64) -> String {
        format!(
            "{}|{}|{:016x}",
            device,
            self.math().map_or("-", |m| m.name()),
            fingerprint
        )
    }
}

/// The register caps a GPU kernel may be compiled with ([`GpuOptions::max_registers`]): below 16
/// the JIT cannot fit the path state, above 255 no cap applies.
pub const MAX_REGISTERS: RangeInclusive<u32> = 16..=255;

/// regeneration-sk's refill thresholds ([`GpuOptions::refill_at`]): idle lanes of a 32-lane warp.
pub const REFILL_AT: RangeInclusive<u32> = 1..=32;

/// The columns and the rows of tiles an image may be cut into ([`GpuOptions::tiles`]).
pub const TILES: RangeInclusive<u32> = 1..=4096;

/// Refuses a GPU option out of its bounds with [`Error::Setting`], whichever backend it is for.
fn check_bounds(gpu: &GpuOptions) -> Result<(), Error> {
    let bound = |key, range: &RangeInclusive<u32>, value: Option<u32>| match value {
        Some(v) if !range.contains(&v) => Err(Error::Setting {
            key,
            expected: format!("{} to {}", range.start(), range.end()),
            found: v.to_string(),
        }),
        _ => Ok(()),
    };
    bound("max_registers", &MAX_REGISTERS, gpu.max_registers)?;
    bound("refill_at", &REFILL_AT, gpu.refill_at)?;
    match gpu.tiles {
        Some([c, r]) if !(TILES.contains(&c) && TILES.contains(&r)) => Err(Error::Setting {
            key: "tiles",
            expected: format!(
                "columns and rows of {} to {} each",
                TILES.start(),
                TILES.end()
            ),
            found: format!("{c},{r}"),
        }),
        _ => Ok(()),
    }
}

/// Refuses GPU options for the CPU backend, naming the option and why.
fn refuse_on_cpu(gpu: &GpuOptions) -> Result<(), Error> {
    let refuse = |key: &'static str, value: String, why: &str| {
        Err(
            Error::conflict(key, value, BackendKind::KEY, BackendKind::Cpu.name(), why)
                .or_use(BackendKind::KEY, BackendKind::Cuda.name()),
        )
    };
    if let Some(strategy) = gpu.strategy {
        return refuse(
            StrategyChoice::KEY,
            strategy.to_string(),
            "a strategy schedules GPU work, and the CPU backend has no strategies",
        );
    }
    if let Some(n) = gpu.max_registers {
        return refuse(
            "max_registers",
            n.to_string(),
            "the cap is on the GPU kernels' registers, and the CPU backend has none",
        );
    }
    if let Some(n) = gpu.refill_at {
        return refuse(
            "refill_at",
            n.to_string(),
            "the threshold is a GPU strategy's, and the CPU backend has no strategies",
        );
    }
    if let Some([c, r]) = gpu.tiles {
        return refuse(
            "tiles",
            format!("{c},{r}"),
            "tiles split the GPU's launches, and the CPU backend has no launches",
        );
    }
    if let Some(math) = gpu.math {
        return refuse(
            Math::KEY,
            math.name().to_owned(),
            "math chooses the GPU's kernels, and the CPU backend always computes exactly",
        );
    }
    if gpu.gpus != Gpus::First {
        return refuse(
            "gpus",
            gpu.gpus.to_string(),
            "the CPU backend uses every core already",
        );
    }
    let placement = "the volume options place grids for the GPU, and the CPU backend reads them \
                     where they were loaded";
    if let Some(memory) = gpu.volume_memory {
        return refuse(VolumeMemory::KEY, memory.name().to_owned(), placement);
    }
    if let Some(bytes) = gpu.device_memory_budget {
        return refuse("device_memory_budget", bytes.to_string(), placement);
    }
    if gpu.bricked {
        return refuse("bricked", "true".to_owned(), placement);
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
    let strategy = gpu.strategy.unwrap_or(default);
    let refuse = |key: &'static str, value: String, why: &str| {
        Err(
            Error::conflict(key, value, StrategyChoice::KEY, strategy, why)
                .or_use(StrategyChoice::KEY, Strategy::RegenerationSk),
        )
    };
    match strategy {
        StrategyChoice::Auto => {
            if let Some([c, r]) = gpu.tiles {
                return refuse(
                    "tiles",
                    format!("{c},{r}"),
                    "auto chooses the strategy, and tiles split one strategy's launches",
                );
            }
            if let Some(n) = gpu.refill_at {
                return refuse(
                    "refill_at",
                    n.to_string(),
                    "auto chooses the strategy, and the refill threshold is one strategy's",
                );
            }
            if let Some(n) = gpu.max_registers {
                return refuse(
                    "max_registers",
                    n.to_string(),
                    "auto chooses the register cap too",
                );
            }
            Ok(None)
        }
        StrategyChoice::Fixed(other)
            if gpu.refill_at.is_some() && other != Strategy::RegenerationSk =>
        {
            refuse(
                "refill_at",
                gpu.refill_at.unwrap_or_default().to_string(),
                "the refill threshold is regeneration-sk's; this strategy schedules paths \
                 otherwise",
            )
        }
        StrategyChoice::Fixed(strategy) => Ok(Some(Schedule {
            strategy,
            max_registers: gpu.max_registers,
            refill_at: gpu.refill_at,
            tiles: gpu.tiles,
        })),
    }
}

/// Refuses `strategy` for a scene whose kernel set ([`volpt_device::KernelSet`]: a light on, a
/// mesh boundary) has no kernel of it, naming the strategies that have one; `auto` chooses among
/// those ([`auto::calibrate`]).
fn refuse_strategy_without_kernels<S: RenderScene>(
    scene: &S,
    strategy: Strategy,
) -> Result<(), Error> {
    match volpt_device::KernelSet::of_scene(scene) {
        Some(set) if !set.strategies().contains(&strategy) => Err(Error::conflict(
            StrategyChoice::KEY,
            strategy,
            BackendKind::KEY,
            BackendKind::Cuda.name(),
            format!(
                "the GPU kernels for a scene with {} are those of {} only",
                set.what(),
                volpt_cuda::entry::strategy_names(set)
            ),
        )
        .or_use(StrategyChoice::KEY, auto::DEFAULT.strategy)),
        _ => Ok(()),
    }
}

/// One render, handed the monomorphised scene by the factory.
struct Render<'a> {
    backend: &'a Backend,
    /// The render's fingerprint, computed only where wanted (`auto`'s key): it hashes the grids
    /// once per scene.
    fingerprint: &'a dyn Fn() -> u64,
    /// The number naming its grids, for GPUs that keep them between renders.
    grids: u64,
    options: RenderOptions,
    film: &'a mut Film,
    samples: Range<u32>,
    observer: &'a dyn Observer,
    after_chunk: &'a mut dyn FnMut(&Film, u32) -> Result<(), Error>,
    /// [`Backend::render_until`]'s: one GPU's multi-kernel strategy stops there with paths in
    /// flight.
    deadline: Option<Instant>,
}

impl SceneVisitor for Render<'_> {
    type Output = Result<Rendered, Error>;

    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
        let Render {
            backend,
            fingerprint,
            grids,
            options,
            film,
            samples,
            observer,
            after_chunk,
            deadline,
        } = self;
        let camera = scene.camera();
        let pixels = u64::from(camera.width) * u64::from(camera.height);
        let total = pixels * u64::from(samples.end - samples.start);
        // Once for the whole range, so that `auto` weighs the whole render against a calibration;
        // per GPU, one calibration per GPU model (the others find it cached).
        let schedules: Vec<Option<Schedule>> = match &backend.0 {
            Inner::Cpu | Inner::CpuDevices(_) => vec![None],
            Inner::Cuda {
                renderers,
                schedule: Some(schedule),
                ..
            } => vec![Some(*schedule); renderers.len()],
            Inner::Cuda {
                renderers,
                schedule: None,
                implicit_auto,
                auto,
                ..
            } => {
                // One key per GPU ([`Backend::auto_keys`]), computed only here: it fingerprints
                // the scene.
                let auto_keys = backend.auto_keys(fingerprint());
                let mut chosen: Vec<(&str, Schedule)> = Vec::new();
                let mut schedules = Vec::with_capacity(renderers.len());
                for (renderer, key) in renderers.iter().zip(&auto_keys) {
                    let schedule = match chosen.iter().find(|(k, _)| k == key) {
                        Some((_, schedule)) => *schedule,
                        None => {
                            let schedule = auto_schedule(
                                renderer,
                                auto,
                                key,
                                scene,
                                &options,
                                *implicit_auto && !auto::repays_calibration(total),
                                observer,
                            )?;
                            chosen.push((key, schedule));
                            schedule
                        }
                    };
                    schedules.push(Some(schedule));
                }
                schedules
            }
        };

        for schedule in schedules.iter().flatten() {
            refuse_strategy_without_kernels(scene, schedule.strategy)?;
        }

        // Several devices: batches from one queue, added in batch order.
        let devices: Vec<multi::Device<'_>> = match &backend.0 {
            Inner::CpuDevices(n) => (0..*n)
                .map(|_| -> multi::Device<'_> {
                    Box::new(
                        |film: &mut Film, range: Range<u32>, report: &(dyn Fn(u64, u64) + Sync)| {
                            Ok(render_samples(scene, film, range, &options, report)?)
                        },
                    )
                })
                .collect(),
            Inner::Cuda { renderers, .. } if renderers.len() > 1 => renderers
                .iter()
                .zip(&schedules)
                .map(|(renderer, schedule)| -> multi::Device<'_> {
                    let schedule = schedule.expect("every GPU has a schedule");
                    let options = &options;
                    Box::new(
                        move |film: &mut Film,
                              range: Range<u32>,
                              report: &(dyn Fn(u64, u64) + Sync)| {
                            // SAFETY: `grids` names this scene's grids' values, which no one
                            // writes: new values get a new number ([`Scene::kept_data`]).
                            Ok(unsafe {
                                renderer.render_samples_keeping(
                                    scene, schedule, film, range, options, report, grids,
                                )
                            }?)
                        },
                    )
                })
                .collect(),
            _ => Vec::new(),
        };
        if !devices.is_empty() {
            // Every GPU compiles its kernel and copies the scene's grids at once, before the
            // render's clock starts (as one GPU's render does before its own).
            if let Inner::Cuda { renderers, .. } = &backend.0 {
                std::thread::scope(|threads| {
                    let loads: Vec<_> = renderers
                        .iter()
                        .zip(&schedules)
                        .filter_map(|(renderer, schedule)| {
                            let schedule = (*schedule)?;
                            Some(threads.spawn(move || {
                                renderer.load_kernel(scene, schedule)?;
                                // SAFETY: as the batches' renders below.
                                unsafe { renderer.keep_grids(scene, grids) }
                            }))
                        })
                        .collect();
                    loads.into_iter().try_for_each(|load| {
                        load.join().unwrap_or_else(|p| std::panic::resume_unwind(p))
                    })
                })?;
            }
            let (stats, done) =
                multi::render_shared(&devices, film, samples.clone(), observer, after_chunk)?;
            return Ok(Rendered {
                stats,
                samples: samples.start..done,
                schedule: schedules[0],
            });
        }
        let schedule = schedules[0];
        if let (Some(deadline), Inner::Cuda { renderers, .. }, Some(schedule)) =
            (deadline, &backend.0, schedule)
        {
            // SAFETY: as the chunks' renders below; the fingerprint names the scene as rendered,
            // its camera and film included.
            let progress = unsafe {
                renderers[0].render_samples_until(
                    scene,
                    schedule,
                    film,
                    samples.clone(),
                    &options,
                    grids,
                    fingerprint(),
                    deadline,
                )
            }?;
            let done = if progress.finished {
                samples.end
            } else {
                samples.start
            };
            if progress.finished {
                after_chunk(film, done)?;
            }
            return Ok(Rendered {
                stats: progress.stats,
                samples: samples.start..done,
                schedule: Some(schedule),
            });
        }

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
                // SAFETY: as above.
                (Inner::Cuda { renderers, .. }, Some(schedule)) => unsafe {
                    renderers[0].render_samples_keeping(
                        scene,
                        schedule,
                        film,
                        range.clone(),
                        &options,
                        &report,
                        grids,
                    )
                }?,
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
/// choice and with `skip_calibration`, [`auto::DEFAULT`].
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
            "strategy {} with {}: this render is too short to repay auto's calibration \
             (--strategy auto calibrates anyway)",
            auto::DEFAULT.strategy.name(),
            auto::registers(auto::DEFAULT.max_registers)
        );
        return Ok(auto::DEFAULT);
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
