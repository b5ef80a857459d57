//! Renders that stop at a deadline with paths in flight and continue them on the next call, so
//! that a viewer's frame need not wait for its longest path (a print's slab: paths of ~140
//! segments on average, a few of thousands).
//!
//! The multi-kernel strategies keep every path in flight in device queues between their
//! launches (`volpt_device::launch::Stage`): stopping between two iterations loses nothing. The
//! queues, their counters and the film stay on the GPU, and the next call of the same render
//! (same kernel, scene as the caller's fingerprint names it, camera included, grids, seed, samples
//! and size) runs the next iteration; any other render discards them. Every path of the range is traced once and added
//! once, so when the range is finished the film holds the uninterrupted render's sums (up to the
//! order of the film's additions); before, it holds the samples before the range and the paths of
//! the range that have ended. The other strategies finish what they start.

use std::ops::Range;
use std::time::Instant;

use cudarc::driver::{CudaSlice, DevicePtr, LaunchConfig, PushKernelArg};
use volpt_core::abi::SceneAbi;
use volpt_core::path::PathCounters;
use volpt_device::launch::{Scheduling, Stage, Tile, Wavefront, BLOCK_SIZE, SLOT_BYTES};
use volpt_device::LaunchParams;
use volpt_film::{Film, RenderOptions, RenderStats};

use crate::entry::scene_entry;
use crate::error::{CudaError, Doing};
use crate::renderer::{
    ByValue, FilmHeld, RenderBuffers, Schedule, DEFAULT_REFILL_AT, WAVEFRONT_BATCH,
};
use crate::CudaRenderer;

/// What a [`CudaRenderer::render_samples_until`] call did.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// This call's kernel time, and the range's path counters so far.
    pub stats: RenderStats,
    /// Every path of the range has ended: the film holds its samples.
    pub finished: bool,
}

/// The paths in flight of a render stopped at its deadline, and what they are of.
pub(crate) struct InFlight {
    key: Key,
    buffers: RenderBuffers,
    queues: CudaSlice<u8>,
    capacity: u64,
    /// Iterations run so far: the next one's parity.
    iteration: u64,
}

/// What makes a call the continuation of the render in flight.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Key {
    kernel: String,
    max_registers: Option<u32>,
    refill_at: u32,
    /// The caller's fingerprint of the scene as rendered (camera, film, medium, ...): not the
    /// launch parameters' bytes, whose small arrays are copied anew, to new addresses, each call.
    render: u64,
    grids: u64,
    seed: u32,
    samples: Range<u32>,
    size: (u32, u32),
}

impl InFlight {
    /// The device film, if a frame of a `size` image over `spp` samples shows it: the range in
    /// flight ends at `spp` (the samples before it and the paths of it that have ended).
    pub(crate) fn film_over(&self, size: (u32, u32), spp: u32) -> Option<&CudaSlice<f64>> {
        (self.key.size == size && self.key.samples.end == spp).then_some(&self.buffers.film)
    }
}

impl CudaRenderer {
    /// [`CudaRenderer::render_samples_keeping`] of the whole range `samples` (one launch) that
    /// returns at `deadline` (after the iteration running then) with paths still in flight, where
    /// the strategy keeps them (the multi-kernel ones; the others finish what they start). A call
    /// of the same render continues them; `film` must then be the one the previous call left
    /// (it gets the device film's sums back at every call: the samples before the range and
    /// the range's paths that have ended). `render` names the scene as rendered (with its camera:
    /// `volpt`'s fingerprint): paths continue only in a call of the same `render`.
    ///
    /// # Safety
    /// As [`CudaRenderer::render_samples_keeping`]; and `render` differs between renders of
    /// different scenes or views.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn render_samples_until<S: SceneAbi>(
        &self,
        scene: &S,
        schedule: impl Into<Schedule>,
        film: &mut Film,
        samples: Range<u32>,
        options: &RenderOptions,
        grids: u64,
        render: u64,
        deadline: Instant,
    ) -> Result<Progress, CudaError> {
        let schedule = schedule.into();
        let strategy = schedule.strategy;
        let Scheduling::Wavefront(regeneration) = strategy.scheduling() else {
            // SAFETY: the caller's contract.
            let stats = unsafe {
                self.render_samples_keeping(
                    scene,
                    schedule,
                    film,
                    samples,
                    options,
                    &|_, _| {},
                    grids,
                )
            }?;
            return Ok(Progress {
                stats,
                finished: true,
            });
        };
        let (width, height) = (scene.camera().width, scene.camera().height);
        film.check_pass((width, height), &samples)?;
        let name = scene_entry(scene, strategy)?;
        let kernel = self.kernel(&name, schedule.max_registers)?;
        let stream = self.stream();
        // SAFETY: the caller's contract; `volumes` is dropped before this returns.
        let (volumes, scene_params) = unsafe { self.place(scene, Some(grids)) }?;
        let pixels = u64::from(width) * u64::from(height);
        let refill_at = schedule.refill_at.unwrap_or(DEFAULT_REFILL_AT);
        let key = Key {
            kernel: name,
            max_registers: schedule.max_registers,
            refill_at,
            render,
            grids,
            seed: options.seed,
            samples: samples.clone(),
            size: (width, height),
        };
        let per_sm = kernel
            .occupancy_max_active_blocks_per_multiprocessor(BLOCK_SIZE, 0, None)
            .doing("querying the kernel's occupancy")?;
        let resident_blocks = per_sm * self.multiprocessors;
        let resident_threads = u64::from(resident_blocks) * u64::from(BLOCK_SIZE);

        let mut slot = self.in_flight.lock().unwrap_or_else(|e| e.into_inner());
        let mut flight = match slot.take() {
            Some(flight) if flight.key == key => flight,
            // Another render's paths (another view, size or range) are discarded.
            _ => {
                let (mut buffers, _) = self.buffers_for(film, &samples)?;
                stream
                    .memset_zeros(&mut buffers.queue_state)
                    .doing("resetting the queue counters")?;
                stream
                    .memset_zeros(&mut buffers.next_path)
                    .doing("resetting the path counter")?;
                let capacity = strategy.wavefront_capacity(pixels, resident_threads);
                let queues = stream
                    .alloc_zeros(2 * capacity as usize * SLOT_BYTES)
                    .doing("allocating the path queues")?;
                InFlight {
                    key,
                    buffers,
                    queues,
                    capacity,
                    iteration: 0,
                }
            }
        };

        let total_paths = pixels * samples.len() as u64;
        let params = LaunchParams {
            scene: scene_params,
            seed: options.seed,
            film: flight.buffers.film.device_ptr(stream).0,
            counters: flight.buffers.counters.device_ptr(stream).0,
            next_path: flight.buffers.next_path.device_ptr(stream).0,
            first_sample: samples.start,
            samples: samples.len() as u32,
            refill_at,
            stage: 0,
            capacity: flight.capacity as u32,
            total_paths,
            queues: flight.queues.device_ptr(stream).0,
            wavefront: flight.buffers.queue_state.device_ptr(stream).0,
            tile: Tile::whole(width, height),
        };
        let config = LaunchConfig {
            grid_dim: (strategy.blocks(pixels, resident_blocks), 1, 1),
            block_dim: (BLOCK_SIZE, 1, 1),
            shared_mem_bytes: 0,
        };
        let plan = LaunchConfig {
            grid_dim: (1, 1, 1),
            ..config
        };
        stream.synchronize().doing("copying the scene")?;
        let start = Instant::now();
        let finished = loop {
            for _ in 0..WAVEFRONT_BATCH {
                for stage in Stage::iteration(flight.iteration, regeneration) {
                    let params = LaunchParams {
                        stage: stage.code(),
                        ..params
                    };
                    let config = match stage {
                        Stage::Plan { .. } => plan,
                        _ => config,
                    };
                    // SAFETY: as `render_samples_placing`'s launches: one `LaunchParams` of this
                    // scene type by value, whose film, counters, queues and grids are the live
                    // allocations above, sized for this launch.
                    unsafe {
                        stream
                            .launch_builder(&kernel)
                            .arg(&ByValue(params.checked()))
                            .launch(config)
                    }
                    .doing("launching the kernel")?;
                }
                flight.iteration += 1;
            }
            let state = stream
                .clone_dtoh(&flight.buffers.queue_state)
                .doing("reading the queue counters")?;
            let state: Wavefront = bytemuck::pod_read_unaligned(bytemuck::cast_slice(&state));
            if state.done(total_paths) {
                break true;
            }
            if Instant::now() >= deadline {
                break false;
            }
        };
        let elapsed = start.elapsed();
        stream
            .memcpy_dtoh(&flight.buffers.film, film.flat_sums_mut())
            .doing("reading the film")?;
        let totals = stream
            .clone_dtoh(&flight.buffers.counters)
            .doing("reading the counters")?;
        drop(volumes);
        let stats = RenderStats {
            elapsed,
            counters: PathCounters {
                paths: totals[0],
                segments: totals[1],
                tracking_steps: totals[2],
                truncated: totals[3],
                truncated_tracking: totals[4],
            },
        };
        if finished {
            flight.buffers.holds = Some(FilmHeld {
                size: (width, height),
                spp: samples.end,
            });
            *self.buffers.lock().unwrap_or_else(|e| e.into_inner()) = Some(flight.buffers);
        } else {
            *slot = Some(flight);
        }
        Ok(Progress { stats, finished })
    }
}
