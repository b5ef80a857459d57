//! volpt's CUDA backend: the generic `volpt-core` path step, compiled to PTX by `cargo xtask ptx`
//! (see the `kernels` crate), loaded through the CUDA driver and run on the GPU.
//!
//! - [`strategy`]: the GPU scheduling strategies (who traces which path), selectable at run time.
//! - [`renderer`]: device volumes, the device film, launching a strategy's kernel for a scene.
//! - [`error`]: what can go wrong, from "no GPU here" to a failed launch.
//!
//! The CUDA driver is loaded at run time, so a binary with this crate builds and runs on machines
//! without CUDA; only `CudaRenderer::new` needs a GPU.

pub mod error;
pub mod renderer;
pub mod strategy;

pub use error::CudaError;
pub use renderer::CudaRenderer;
pub use strategy::Strategy;

/// The kernels' PTX, if `cargo xtask ptx` wrote it before this crate was built.
mod ptx {
    include!(concat!(env!("OUT_DIR"), "/ptx.rs"));
}

/// Whether this build carries GPU kernels.
pub fn has_kernels() -> bool {
    ptx::PTX.is_some()
}
