//! Running a strategy's kernel for a render-ready scene.
//!
//! The scene's grids are copied to device memory once per render, the film (`f64` sums, as on the
//! CPU) lives on the device for the whole render, and only the final sums come back. The kernel is
//! the scene type's own ([`scene_entry`]: in the kernel set its lights or mesh need), so the GPU
//! simulates exactly the effects the CPU would.

use std::cell::Cell;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use cudarc::driver::{
    sys, CudaContext, CudaFunction, CudaModule, CudaSlice, CudaStream, DevicePtr, LaunchConfig,
    PushKernelArg,
};
use cudarc::nvrtc::Ptx;
use volpt_core::abi::SceneAbi;
use volpt_core::path::PathCounters;
use volpt_device::launch::{
    next_launch_paths, Scheduling, Stage, Tile, Wavefront, BLOCK_SIZE, COUNTERS,
    FIRST_LAUNCH_PATHS, SLOT_BYTES,
};
use volpt_device::{LaunchParams, Math, Strategy};
use volpt_film::{Film, Image, RenderOptions, RenderStats};
use volpt_gpu_mem::{ResidentGrids, VolumePlacer, VolumePolicy};

use crate::entry::{scene_entry, single_kernel_ptx};
use crate::error::{CudaError, Doing};
use crate::kernels::{self, KernelPack};

/// How a render is scheduled on the GPU.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Schedule {
    pub strategy: Strategy,
    /// A cap on the kernel's registers per thread (the JIT's `.maxnreg`), or the compiler's choice.
    pub max_registers: Option<u32>,
    /// regeneration-sk's refill threshold ([`LaunchParams::refill_at`]), or [`DEFAULT_REFILL_AT`].
    pub refill_at: Option<u32>,
    /// `[columns, rows]`: the film cut into tiles, each rendered by its own launches, or whole.
    pub tiles: Option<[u32; 2]>,
}

/// regeneration-sk refills a warp's idle lanes once 8 of them are idle. Measured (H100,
/// 2026-11-23, `bench/device/refill.sh`, thresholds 1, 4, 8, 16, 24, 32): 8 is the fastest or
/// within 1% of it on every scene: against refilling at once (1), the index-matched cube 1.17x, the
/// rough cube 1.40x, cgg-logo 1.24x, smoke and bucky 1.06-1.07x, the thesis's cgg_logo with its
/// roulette 1.21x. A refill runs the camera ray, the box entry and the RNG's seeding for the lanes
/// that need them while the others wait; batching eight makes that divergent branch rarer, and
/// waiting for the whole warp (32, the thesis's warp level) idles lanes for the longest path.
pub const DEFAULT_REFILL_AT: u32 = 8;

/// Iterations a multi-kernel strategy queues between looks at its counters: a look waits for
/// the GPU, and the iterations queued beyond the last path's end cost a few microseconds each.
pub(crate) const WAVEFRONT_BATCH: u32 = 16;

impl From<Strategy> for Schedule {
    fn from(strategy: Strategy) -> Self {
        Self {
            strategy,
            max_registers: None,
            refill_at: None,
            tiles: None,
        }
    }
}

/// A compiled kernel: its entry point and register cap.
type KernelKey = (String, Option<u32>);

/// Where a renderer's kernels come from.
enum Kernels {
    /// A whole PTX module (`VOLPT_PTX`, a library user's kernels crate).
    Module(String),
    /// The kernels this build embeds, packed.
    Embedded {
        math: Math,
        pack: &'static KernelPack<'static>,
    },
}

impl Kernels {
    /// The PTX of the kernel `entry` alone, under the register cap `max_registers`.
    fn single_kernel(&self, entry: &str, max_registers: Option<u32>) -> Result<String, CudaError> {
        let ptx = match self {
            Self::Module(ptx) => single_kernel_ptx(ptx, entry, max_registers),
            Self::Embedded { math, pack } => {
                pack.kernel(entry, max_registers)
                    .map_err(|source| CudaError::CorruptKernels {
                        math: *math,
                        source,
                    })?
            }
        };
        ptx.ok_or_else(|| CudaError::MissingKernel(entry.to_owned()))
    }
}

/// The environment variable naming a PTX file whose kernels a renderer runs instead of the
/// embedded ones.
pub const PTX_OVERRIDE: &str = "VOLPT_PTX";

/// One GPU and volpt's kernels, each JIT-compiled on first use.
pub struct CudaRenderer {
    ctx: Arc<CudaContext>,
    stream: Arc<CudaStream>,
    kernels: Kernels,
    /// The modules compiled so far, one kernel each, by entry point and register cap.
    modules: Mutex<HashMap<KernelKey, Arc<CudaModule>>>,
    device_name: String,
    pub(crate) multiprocessors: u32,
    volumes: VolumePolicy,
    /// The grids of the scene rendered last by [`CudaRenderer::render_samples_keeping`].
    resident: Arc<ResidentGrids>,
    /// The launch size the last render of a kept scene ended with, and what it was measured on
    /// (scene, kernel, image size): the next render of that scene starts there instead of with
    /// [`FIRST_LAUNCH_PATHS`] (several GPUs render many batches, each a render of its own).
    launch_budget: Mutex<Option<(BudgetKey, u64)>>,
    /// The last render's film and counters on the device, which the next render of an image of
    /// the same size zeroes and reuses: a viewer's frames and several GPUs' batches are many
    /// short renders, and allocating them anew cost milliseconds each.
    pub(crate) buffers: Mutex<Option<RenderBuffers>>,
    /// A render stopped at its deadline with paths in flight ([`crate::in_flight`]).
    pub(crate) in_flight: Mutex<Option<crate::in_flight::InFlight>>,
    /// The last 8-bit frame tone mapped on the device ([`crate::tone`]), three bytes a pixel.
    pub(crate) frame: Mutex<Option<CudaSlice<u8>>>,
}

/// A render's device memory besides its grids and queues.
pub(crate) struct RenderBuffers {
    /// Three `f64` sums per pixel.
    pub(crate) film: CudaSlice<f64>,
    pub(crate) counters: CudaSlice<u64>,
    pub(crate) next_path: CudaSlice<u64>,
    pub(crate) queue_state: CudaSlice<u64>,
    /// What `film` holds after the last render: the sums of samples `0..spp` of an image of
    /// `size`, or `None` (a batch of several GPUs holds later samples alone) ([`crate::tone`]).
    pub(crate) holds: Option<FilmHeld>,
}

/// A device film's image size and the samples `0..spp` it holds the sums of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct FilmHeld {
    pub(crate) size: (u32, u32),
    pub(crate) spp: u32,
}

impl RenderBuffers {
    pub(crate) fn new(stream: &Arc<CudaStream>, pixels: u64) -> Result<Self, CudaError> {
        Ok(Self {
            film: stream
                .alloc_zeros(3 * pixels as usize)
                .doing("allocating the film")?,
            counters: stream
                .alloc_zeros(COUNTERS)
                .doing("allocating the counters")?,
            next_path: stream.alloc_zeros(1).doing("allocating the path counter")?,
            queue_state: stream
                .alloc_zeros(size_of::<Wavefront>() / 8)
                .doing("allocating the queue counters")?,
            holds: None,
        })
    }

    /// Zeroes what a render reads before it writes: the counters, and the film unless the
    /// caller copies sums into it.
    pub(crate) fn zero(&mut self, stream: &Arc<CudaStream>, film: bool) -> Result<(), CudaError> {
        if film {
            stream
                .memset_zeros(&mut self.film)
                .doing("zeroing the film")?;
        }
        stream
            .memset_zeros(&mut self.counters)
            .doing("zeroing the counters")?;
        Ok(())
    }
}

/// What a launch budget was measured on.
#[derive(Clone, Debug, PartialEq, Eq)]
struct BudgetKey {
    grids: u64,
    kernel: String,
    max_registers: Option<u32>,
    size: (u32, u32),
}

impl CudaRenderer {
    /// Opens GPU `ordinal` with the workspace's kernels built for `math` (each JIT-compiled for
    /// this GPU on first use, and cached by the driver).
    pub fn new(ordinal: usize, math: Math) -> Result<Self, CudaError> {
        // `VOLPT_PTX=file.ptx` runs other kernels with this binary: A/B measurements of a kernel
        // change in one device session.
        let kernels = match std::env::var_os(PTX_OVERRIDE) {
            Some(path) => Kernels::Module(std::fs::read_to_string(&path).map_err(|source| {
                CudaError::PtxFile {
                    path: path.into(),
                    source,
                }
            })?),
            None => Kernels::Embedded {
                math,
                pack: kernels::shared(math)
                    .map_err(|source| CudaError::CorruptKernels { math, source })?
                    .ok_or(CudaError::NoKernels(math))?,
            },
        };
        Self::open(ordinal, kernels)
    }

    /// Opens GPU `ordinal` with kernels of the caller's own, e.g. a library user's kernels crate
    /// that exports its scene types with `volpt_device::export_kernels!`.
    pub fn with_ptx(ordinal: usize, ptx: String) -> Result<Self, CudaError> {
        Self::open(ordinal, Kernels::Module(ptx))
    }

    fn open(ordinal: usize, kernels: Kernels) -> Result<Self, CudaError> {
        // SAFETY: only probes whether the driver library can be opened.
        if !unsafe { sys::is_culib_present() } {
            return Err(CudaError::NoDriver);
        }
        let started = Instant::now();
        let ctx = CudaContext::new(ordinal).doing("opening the GPU")?;
        // Start-up's parts (with `RUST_LOG=volpt_cuda=debug`): this, the kernel's cut and JIT
        // below, the first launch.
        tracing::debug!(ordinal, context = ?started.elapsed(), "opened the GPU");
        let device_name = ctx.name().doing("reading the GPU's name")?;
        let multiprocessors = ctx
            .attribute(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT)
            .doing("reading the multiprocessor count")? as u32;
        Ok(Self {
            stream: ctx.default_stream(),
            ctx,
            kernels,
            modules: Mutex::default(),
            device_name,
            multiprocessors,
            volumes: VolumePolicy::default(),
            resident: Arc::default(),
            launch_budget: Mutex::default(),
            buffers: Mutex::default(),
            in_flight: Mutex::default(),
            frame: Mutex::default(),
        })
    }

    /// The kernel `entry` under the register cap `max_registers`, compiled on first use: the
    /// driver JIT-compiles only that kernel (and caches the result on disk).
    pub(crate) fn kernel(
        &self,
        entry: &str,
        max_registers: Option<u32>,
    ) -> Result<CudaFunction, CudaError> {
        let key = (entry.to_owned(), max_registers);
        let mut modules = self.modules.lock().unwrap_or_else(|e| e.into_inner());
        let module = match modules.get(&key) {
            Some(module) => module.clone(),
            None => {
                let started = Instant::now();
                let ptx = self.kernels.single_kernel(entry, max_registers)?;
                let cut = started.elapsed();
                let module = self
                    .ctx
                    .load_module(Ptx::from_src(ptx))
                    .doing("compiling the kernel's PTX")?;
                tracing::debug!(entry, ?max_registers, ?cut, jit = ?(started.elapsed() - cut), "loaded kernel");
                modules.insert(key, module.clone());
                module
            }
        };
        module
            .load_function(entry)
            .map_err(|_| CudaError::MissingKernel(entry.to_owned()))
    }

    /// Compiles the kernel that a render of `scene` under `schedule` launches, which the first
    /// such render would do (several GPUs do it at once, before their render starts).
    pub fn load_kernel<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
    ) -> Result<(), CudaError> {
        let schedule = schedule.into();
        self.kernel(
            &scene_entry(scene, schedule.strategy)?,
            schedule.max_registers,
        )
        .map(drop)
    }

    /// Places the grids of the scene numbered `grids` on this GPU now, where the next
    /// [`CudaRenderer::render_samples_keeping`] of it finds them: several GPUs copy their grids at
    /// once before their render's clock starts, as one GPU's render does before its own.
    ///
    /// # Safety
    /// As [`CudaRenderer::render_samples_keeping`].
    pub unsafe fn keep_grids<S: SceneAbi>(&self, scene: &S, grids: u64) -> Result<(), CudaError> {
        // SAFETY: the caller's contract; what is not kept is freed (synchronising) on return.
        unsafe { self.place(scene, Some(grids)) }.map(drop)
    }

    /// The device buffers of a render that adds `samples` to `film` (checked against the
    /// camera's size): the last render's where they fit, with the counters zeroed, and the sums
    /// of the samples before `samples` continuing on the device (as the CPU continues them),
    /// unless there are none yet, as in a batch of several GPUs, whose film starts empty; and
    /// whether they did continue.
    pub(crate) fn buffers_for(
        &self,
        film: &Film,
        samples: &Range<u32>,
    ) -> Result<(RenderBuffers, bool), CudaError> {
        let pixels = u64::from(film.width) * u64::from(film.height);
        let reused = self
            .buffers
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        let mut buffers = match reused {
            Some(buffers) if buffers.film.len() == 3 * pixels as usize => buffers,
            _ => RenderBuffers::new(&self.stream, pixels)?,
        };
        let resumed = samples.start > 0 && film.holds_samples();
        buffers.zero(&self.stream, !resumed)?;
        // Until this render has ended, the film holds nothing a frame may show.
        buffers.holds = None;
        if resumed {
            self.stream
                .memcpy_htod(film.flat_sums(), &mut buffers.film)
                .doing("copying the film to the GPU")?;
        }
        Ok((buffers, resumed))
    }

    /// `scene`'s launch parameters: its grids where the volume policy puts them (taken from and
    /// left in the kept grids of the scene numbered `keep`, if any), everything else by value.
    /// The parameters are valid while the placer lives.
    ///
    /// # Safety
    /// With `keep`, as [`CudaRenderer::render_samples_keeping`].
    pub(crate) unsafe fn place<S: SceneAbi>(
        &self,
        scene: &S,
        keep: Option<u64>,
    ) -> Result<(VolumePlacer, S::Params), CudaError> {
        // SAFETY: the grids are `scene`'s, borrowed by the caller for as long as it holds the
        // placer.
        let mut volumes = unsafe { VolumePlacer::new(self.stream.clone(), self.volumes) }?;
        if let Some(grids) = keep {
            // SAFETY: the caller's contract.
            volumes = unsafe { volumes.keeping(self.resident.clone(), grids) };
        }
        let params = scene.to_params(&mut volumes);
        volumes.check()?;
        Ok((volumes, params))
    }

    pub(crate) fn stream(&self) -> &Arc<CudaStream> {
        &self.stream
    }

    /// Where renders place their grids from now on (`--volume-memory`, docs/out-of-core.md).
    pub fn set_volume_policy(&mut self, policy: VolumePolicy) {
        self.volumes = policy;
        // Grids kept under another policy may be where this one would not put them.
        self.resident = Arc::default();
    }

    pub fn device_name(&self) -> &str {
        &self.device_name
    }

    /// The device memory free now (`cuMemGetInfo`), if the driver says.
    pub fn free_memory(&self) -> Option<u64> {
        self.ctx.mem_get_info().ok().map(|(free, _)| free as u64)
    }

    /// Renders `scene` as `schedule` says with the kernel of `S`, calling `progress(done, total)` in
    /// paths after each launch.
    pub fn render<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
        options: &RenderOptions,
        progress: &dyn Fn(u64, u64),
    ) -> Result<(Image, RenderStats), CudaError> {
        let (width, height) = (scene.camera().width, scene.camera().height);
        let mut film = Film::new(width, height);
        let samples = 0..options.spp;
        let stats = self.render_samples(scene, schedule, &mut film, samples, options, progress)?;
        Ok((film.image(options.spp), stats))
    }

    /// Adds samples `samples` of every pixel to `film`, which holds the sums of the samples before
    /// them (zeros when `samples` starts at 0); `progress(done, total)` counts this call's paths.
    pub fn render_samples<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
        film: &mut Film,
        samples: Range<u32>,
        options: &RenderOptions,
        progress: &dyn Fn(u64, u64),
    ) -> Result<RenderStats, CudaError> {
        self.render_samples_placing(scene, schedule, film, samples, options, progress, None)
    }

    /// [`CudaRenderer::render_samples`] for one of many renders of the scene numbered `grids` (a
    /// viewer's frames, the batches of several GPUs): its grids stay on the GPU from one render
    /// to the next instead of being copied each time, until a render of another scene.
    ///
    /// # Safety
    /// `grids` names one scene's grids for this renderer's lifetime: every render passing it has
    /// grids holding the same values wherever they are found at the same address and length
    /// ([`VolumePlacer::keeping`]).
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn render_samples_keeping<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
        film: &mut Film,
        samples: Range<u32>,
        options: &RenderOptions,
        progress: &dyn Fn(u64, u64),
        grids: u64,
    ) -> Result<RenderStats, CudaError> {
        self.render_samples_placing(
            scene,
            schedule,
            film,
            samples,
            options,
            progress,
            Some(grids),
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn render_samples_placing<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
        film: &mut Film,
        samples: Range<u32>,
        options: &RenderOptions,
        progress: &dyn Fn(u64, u64),
        keep: Option<u64>,
    ) -> Result<RenderStats, CudaError> {
        let called = Instant::now();
        let (width, height) = (scene.camera().width, scene.camera().height);
        film.check_pass((width, height), &samples)?;
        let schedule = schedule.into();
        let strategy = schedule.strategy;
        let name = scene_entry(scene, strategy)?;
        let kernel = self.kernel(&name, schedule.max_registers)?;
        let stream = &self.stream;

        // SAFETY: the grids are `scene`'s, borrowed for this whole call; `volumes` is dropped
        // before it returns; with `keep`, `render_samples_keeping`'s contract.
        let (volumes, scene_params) = unsafe { self.place(scene, keep) }?;

        let pixels = width as u64 * height as u64;
        let (mut buffers, resumed) = self.buffers_for(film, &samples)?;
        let RenderBuffers {
            film: device_film,
            counters,
            next_path,
            queue_state,
            ..
        } = &mut buffers;
        let per_sm = kernel
            .occupancy_max_active_blocks_per_multiprocessor(BLOCK_SIZE, 0, None)
            .doing("querying the kernel's occupancy")?;
        let [columns, rows] = schedule.tiles.unwrap_or([1, 1]);
        tracing::info!(kernel = %name, columns, rows, threads = BLOCK_SIZE, "launching");
        let resident_blocks = per_sm * self.multiprocessors;
        let resident_threads = resident_blocks as u64 * BLOCK_SIZE as u64;

        // A multi-kernel strategy's queues, sized for the largest tile, and their counters.
        let wavefront = match strategy.scheduling() {
            Scheduling::Wavefront(regeneration) => Some(regeneration),
            _ => None,
        };
        let capacity = Tile::grid(width, height, columns, rows)
            .map(|tile| strategy.wavefront_capacity(tile.pixels(), resident_threads))
            .max()
            .unwrap_or(1);
        let queue_bytes = if wavefront.is_some() {
            2 * capacity as usize * SLOT_BYTES
        } else {
            0
        };
        let queues: CudaSlice<u8> = stream
            .alloc_zeros(queue_bytes.max(1))
            .doing("allocating the path queues")?;

        let mut params = LaunchParams {
            scene: scene_params,
            seed: options.seed,
            film: device_film.device_ptr(stream).0,
            counters: counters.device_ptr(stream).0,
            next_path: next_path.device_ptr(stream).0,
            first_sample: samples.start,
            samples: 0,
            refill_at: schedule.refill_at.unwrap_or(DEFAULT_REFILL_AT),
            stage: 0,
            capacity: 0,
            total_paths: 0,
            queues: queues.device_ptr(stream).0,
            wavefront: queue_state.device_ptr(stream).0,
            tile: Tile::whole(width, height),
        };
        let total = pixels * samples.len() as u64;
        stream.synchronize().doing("copying the scene")?;
        let start = Instant::now();
        // The first launch's budget (what the last render of this kept scene measured), then
        // what the measured rate traces in `LAUNCH_SECONDS`.
        let budget_key = keep.map(|grids| BudgetKey {
            grids,
            kernel: name.clone(),
            max_registers: schedule.max_registers,
            size: (width, height),
        });
        let carried = {
            let last = self.launch_budget.lock().unwrap_or_else(|e| e.into_inner());
            match (&*last, &budget_key) {
                (Some((key, budget)), Some(now)) if key == now => Some(*budget),
                _ => None,
            }
        };
        let budget = Cell::new(carried.unwrap_or(FIRST_LAUNCH_PATHS));
        let mut done = 0;
        // Tiles one after the other, each with all its samples (the thesis's image tiling).
        for tile in Tile::grid(width, height, columns, rows) {
            let tile_pixels = tile.pixels();
            let blocks = strategy.blocks(tile_pixels, resident_blocks);
            let config = LaunchConfig {
                grid_dim: (blocks, 1, 1),
                block_dim: (BLOCK_SIZE, 1, 1),
                shared_mem_bytes: 0,
            };
            params.tile = tile;
            params.capacity = strategy.wavefront_capacity(tile_pixels, resident_threads) as u32;
            for (_, count) in strategy.launches(tile_pixels, samples.len() as u32, || budget.get())
            {
                let launched = Instant::now();
                params.samples = count;
                params.total_paths = tile_pixels * count as u64;
                stream
                    .memset_zeros(next_path)
                    .doing("resetting the path counter")?;
                // SAFETY: the kernel takes one `LaunchParams` of this scene type by value, whose
                // film, counters, path counter, queues and grids are the live allocations above,
                // sized for this launch.
                let launch = |params: LaunchParams<S::Params>, config| unsafe {
                    stream
                        .launch_builder(&kernel)
                        .arg(&ByValue(params.checked()))
                        .launch(config)
                        .doing("launching the kernel")
                };
                if let Some(regeneration) = wavefront {
                    stream
                        .memset_zeros(queue_state)
                        .doing("resetting the queue counters")?;
                    let plan = LaunchConfig {
                        grid_dim: (1, 1, 1),
                        ..config
                    };
                    // Iterations are queued without waiting, WAVEFRONT_BATCH at a time, until the
                    // counters say every path has ended; the extra iterations find empty queues.
                    let mut iteration = 0;
                    loop {
                        for _ in 0..WAVEFRONT_BATCH {
                            for stage in Stage::iteration(iteration, regeneration) {
                                params.stage = stage.code();
                                let config = match stage {
                                    Stage::Plan { .. } => plan,
                                    _ => config,
                                };
                                launch(params, config)?;
                            }
                            iteration += 1;
                        }
                        let state = stream
                            .clone_dtoh(queue_state)
                            .doing("reading the queue counters")?;
                        let state: Wavefront =
                            bytemuck::pod_read_unaligned(bytemuck::cast_slice(&state));
                        if state.done(params.total_paths) {
                            break;
                        }
                    }
                    tracing::debug!(
                        iterations = iteration,
                        paths = params.total_paths,
                        "wavefront launch"
                    );
                    params.stage = 0;
                } else {
                    launch(params, config)?;
                }
                stream.synchronize().doing("running the kernel")?;
                budget.set(next_launch_paths(
                    params.total_paths,
                    launched.elapsed().as_secs_f64(),
                ));
                params.first_sample += count;
                done += params.total_paths;
                progress(done, total);
            }
            params.first_sample = samples.start;
        }
        let elapsed = start.elapsed();
        if let Some(key) = budget_key {
            *self.launch_budget.lock().unwrap_or_else(|e| e.into_inner()) =
                Some((key, budget.get()));
        }

        stream
            .memcpy_dtoh(device_film, film.flat_sums_mut())
            .doing("reading the film")?;
        let totals = stream.clone_dtoh(counters).doing("reading the counters")?;
        drop(volumes);
        // The sums of every sample before `samples.end`: a render from sample 0, or one that
        // continued the caller's sums; a batch of several GPUs (a later range into an empty film)
        // holds its own samples alone.
        if samples.start == 0 || resumed {
            buffers.holds = Some(FilmHeld {
                size: (width, height),
                spp: samples.end,
            });
        }
        *self.buffers.lock().unwrap_or_else(|e| e.into_inner()) = Some(buffers);
        let counters = PathCounters {
            paths: totals[0],
            segments: totals[1],
            tracking_steps: totals[2],
            truncated: totals[3],
            truncated_tracking: totals[4],
        };
        // Where a short render's time goes outside its kernels (`RUST_LOG=volpt_cuda=debug`).
        tracing::debug!(
            setup_s = (start - called).as_secs_f64(),
            kernels_s = elapsed.as_secs_f64(),
            read_back_s = (called.elapsed() - (start - called) - elapsed).as_secs_f64(),
            "render"
        );
        Ok(RenderStats { elapsed, counters })
    }
}

/// Launch parameters passed by value: the driver copies their bytes into the kernel's parameter
/// space (the constant bank), as the kernel's signature asks.
#[repr(transparent)]
pub(crate) struct ByValue<P>(pub(crate) LaunchParams<P>);

// SAFETY: `LaunchParams<P>` of `Pod` scene parameters is plain `repr(C)` data without padding
// (`LaunchParams::LAYOUT`), the layout the kernel's parameter declares.
unsafe impl<P: Copy> cudarc::driver::DeviceRepr for ByValue<P> {}
