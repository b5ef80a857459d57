//! volpt's CUDA backend: the generic `volpt-core` path step, compiled to PTX by `cargo xtask ptx`
//! (see the `kernels` crate), loaded through the CUDA driver and run on the GPU.
//!
//! - [`renderer`]: device volumes, the device film, launching a strategy's kernel for a scene type.
//! - [`entry`]: the kernel entry point of a scene type, derived from its parts' names.
//! - [`kernels`]: the kernels this build embeds, compressed, each decompressed on first use.
//! - [`Strategy`]: the GPU scheduling strategies, selectable at run time (`volpt_device`), and
//!   [`Math`]: exact or fast kernels.
//! - [`selftest`]: the strategies' collective building blocks, texture lookups and the kernels' math
//!   functions on the GPU against the CPU.
//! - [`in_flight`]: renders that stop at a deadline with paths in flight, continued by the next
//!   call (a viewer's frames do not wait for their longest path).
//! - [`tone`]: the viewer's frames tone mapped on the GPU, from the film a render left there.
//! - [`error`]: what can go wrong, from "no GPU here" to a failed launch.
//!
//! The CUDA driver is loaded at run time, so a binary with this crate builds and runs on machines
//! without CUDA; only `CudaRenderer::new` needs a GPU.

pub mod entry;
pub mod error;
pub mod in_flight;
pub mod kernels;
pub mod renderer;
pub mod selftest;
pub mod tone;

pub use error::CudaError;
pub use renderer::{CudaRenderer, Schedule, DEFAULT_REFILL_AT};
pub use volpt_device::{Math, Strategy};

/// Whether this build carries GPU kernels.
pub fn has_kernels() -> bool {
    kernels::is_embedded(Math::Exact)
}

/// How many GPUs the CUDA driver sees (`--gpus all`); [`CudaError::NoDriver`] without a driver.
pub fn device_count() -> Result<usize, CudaError> {
    use error::Doing;
    // SAFETY: only probes whether the driver library can be opened.
    if !unsafe { cudarc::driver::sys::is_culib_present() } {
        return Err(CudaError::NoDriver);
    }
    let count = cudarc::driver::CudaContext::device_count().doing("counting the GPUs")?;
    Ok(usize::try_from(count).unwrap_or(0))
}
