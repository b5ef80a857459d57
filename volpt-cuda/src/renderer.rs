//! Running a strategy's kernel for a render-ready scene.
//!
//! The scene's grids are copied to device memory once per render, the film (`f64` sums, as on the
//! CPU) lives on the device for the whole render, and only the final sums come back. The kernel is
//! chosen by name from the scene's variant, so the GPU simulates exactly the effects the CPU would.

use std::sync::Arc;
use std::time::Instant;

use cudarc::driver::{
    sys, CudaContext, CudaModule, CudaSlice, CudaStream, DevicePtr, LaunchConfig, PushKernelArg,
};
use cudarc::nvrtc::Ptx;
use volpt_core::launch::{LaunchParams, SceneParams, ToParams, COUNTERS};
use volpt_core::path::PathCounters;
use volpt_core::Scene;
use volpt_render::{Image, RenderOptions, RenderStats};

use crate::error::{CudaError, Doing};
use crate::strategy::{Strategy, BLOCK_SIZE};

/// One GPU with volpt's kernels loaded.
pub struct CudaRenderer {
    stream: Arc<CudaStream>,
    module: Arc<CudaModule>,
    device_name: String,
    multiprocessors: u32,
}

impl CudaRenderer {
    /// Opens GPU `ordinal` and loads the kernels (the driver JIT-compiles the PTX for this GPU on
    /// first use and caches the result).
    pub fn new(ordinal: usize) -> Result<Self, CudaError> {
        // SAFETY: only probes whether the driver library can be opened.
        if !unsafe { sys::is_culib_present() } {
            return Err(CudaError::NoDriver);
        }
        // `VOLPT_PTX=file.ptx` runs other kernels with this binary: A/B measurements of a kernel
        // change in one device session.
        let ptx = match std::env::var_os("VOLPT_PTX") {
            Some(path) => std::fs::read_to_string(&path).map_err(|source| CudaError::PtxFile {
                path: path.into(),
                source,
            })?,
            None => crate::ptx::PTX.ok_or(CudaError::NoKernels)?.to_owned(),
        };
        let ctx = CudaContext::new(ordinal).doing("opening the GPU")?;
        let device_name = ctx.name().doing("reading the GPU's name")?;
        let multiprocessors = ctx
            .attribute(sys::CUdevice_attribute::CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT)
            .doing("reading the multiprocessor count")? as u32;
        let started = Instant::now();
        let module = ctx
            .load_module(Ptx::from_src(ptx))
            .doing("loading the kernels' PTX")?;
        tracing::debug!(elapsed = ?started.elapsed(), "loaded PTX");
        Ok(Self {
            stream: ctx.default_stream(),
            module,
            device_name,
            multiprocessors,
        })
    }

    pub fn device_name(&self) -> &str {
        &self.device_name
    }

    /// Renders `scene` (of render-factory variant `variant`, e.g. `homogeneous/null/hg`) with
    /// `strategy`, calling `progress(done, total)` in paths after each launch.
    pub fn render<S: Scene + ToParams>(
        &self,
        scene: &S,
        variant: &str,
        strategy: Strategy,
        options: &RenderOptions,
        progress: &dyn Fn(u64, u64),
    ) -> Result<(Image, RenderStats), CudaError> {
        let (width, height) = (scene.camera().width, scene.camera().height);
        if width == 0 || height == 0 || options.spp == 0 {
            return Err(CudaError::Empty {
                width,
                height,
                spp: options.spp,
            });
        }
        let name = strategy.kernel_name(variant);
        let kernel = self
            .module
            .load_function(&name)
            .map_err(|_| CudaError::MissingKernel(name.clone()))?;
        let stream = &self.stream;

        // The scene: grids to the device, everything else by value.
        let mut grids: Vec<CudaSlice<f32>> = Vec::new();
        let mut upload_error = None;
        let mut scene_params = SceneParams::default();
        scene.to_params(
            &mut scene_params,
            &mut |values| match stream.clone_htod(values) {
                Ok(slice) => {
                    let (address, _) = slice.device_ptr(stream);
                    grids.push(slice);
                    address
                }
                Err(e) => {
                    upload_error.get_or_insert(e);
                    0
                }
            },
        );
        if let Some(e) = upload_error {
            return Err(e).doing("copying the volume to the GPU");
        }

        let pixels = width as u64 * height as u64;
        let film: CudaSlice<f64> = stream
            .alloc_zeros(3 * pixels as usize)
            .doing("allocating the film")?;
        let counters: CudaSlice<u64> = stream
            .alloc_zeros(COUNTERS)
            .doing("allocating the counters")?;
        let mut next_path: CudaSlice<u64> =
            stream.alloc_zeros(1).doing("allocating the path counter")?;
        let blocks = match strategy {
            Strategy::NaiveSk => pixels.div_ceil(BLOCK_SIZE as u64) as u32,
            // Persistent threads: exactly as many blocks as the GPU keeps resident at once.
            Strategy::RegenerationSk => {
                let per_sm = kernel
                    .occupancy_max_active_blocks_per_multiprocessor(BLOCK_SIZE, 0, None)
                    .doing("querying the kernel's occupancy")?;
                per_sm.max(1) * self.multiprocessors
            }
        };
        let config = LaunchConfig {
            grid_dim: (blocks, 1, 1),
            block_dim: (BLOCK_SIZE, 1, 1),
            shared_mem_bytes: 0,
        };
        tracing::info!(kernel = %name, blocks, threads = BLOCK_SIZE, "launching");

        let mut params = LaunchParams {
            scene: scene_params,
            seed: options.seed,
            film: film.device_ptr(stream).0,
            counters: counters.device_ptr(stream).0,
            next_path: next_path.device_ptr(stream).0,
            ..LaunchParams::default()
        };
        let total = pixels * options.spp as u64;
        stream.synchronize().doing("copying the scene")?;
        let start = Instant::now();
        while params.first_sample < options.spp {
            params.samples = strategy.samples_per_launch(pixels, options.spp - params.first_sample);
            params.total_paths = pixels * params.samples as u64;
            stream
                .memset_zeros(&mut next_path)
                .doing("resetting the path counter")?;
            // The kernel reads its parameters from device memory, copied once per launch.
            let params_device = stream
                .clone_htod(as_bytes(&params))
                .doing("copying the launch parameters")?;
            let address = params_device.device_ptr(stream).0;
            // SAFETY: the kernel takes one pointer to a `LaunchParams` whose film, counters, path
            // counter and grids are the live allocations above, sized for this launch.
            unsafe { stream.launch_builder(&kernel).arg(&address).launch(config) }
                .doing("launching the kernel")?;
            stream.synchronize().doing("running the kernel")?;
            params.first_sample += params.samples;
            progress(pixels * params.first_sample as u64, total);
        }
        let elapsed = start.elapsed();

        let sums = stream.clone_dtoh(&film).doing("reading the film")?;
        let totals = stream.clone_dtoh(&counters).doing("reading the counters")?;
        drop(grids);
        let inv_spp = 1.0 / options.spp as f64;
        let pixels = sums
            .chunks_exact(3)
            .map(|s| [s[0], s[1], s[2]].map(|c| (c * inv_spp) as f32))
            .collect();
        let counters = PathCounters {
            paths: totals[0],
            segments: totals[1],
            tracking_steps: totals[2],
            truncated: totals[3],
            truncated_tracking: totals[4],
        };
        Ok((
            Image {
                width,
                height,
                pixels,
            },
            RenderStats { elapsed, counters },
        ))
    }
}

/// The bytes of a plain `repr(C)` value, for copying to the device.
fn as_bytes(params: &LaunchParams) -> &[u8] {
    // SAFETY: `LaunchParams` is `repr(C)`, `Copy`, made of integers and floats, and has no implicit
    // padding (asserted in `volpt_core::launch`), so every byte is initialised.
    unsafe {
        std::slice::from_raw_parts(
            (params as *const LaunchParams).cast::<u8>(),
            std::mem::size_of::<LaunchParams>(),
        )
    }
}
