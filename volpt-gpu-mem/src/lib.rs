//! GPU memory for a render's grids: where they live while the kernels read them (device memory,
//! page-locked host memory mapped into the GPU, managed memory), in which layout, and as textures.
//! It knows grids only as `volpt-core` hands them to an uploader, never a scene file.
//!
//! - [`policy`]: `--volume-memory device|zerocopy|managed|auto` and the device memory budget, as a
//!   pure decision per grid ([`policy::decide`]), testable without a GPU.
//! - [`layout`]: the host side of the bricked grid layout ([`volpt_core::GridLayout::Bricked`]):
//!   dense samples rewritten brick by brick.
//! - [`memory`]: safe owners of the CUDA driver's host memory kinds: page-locked, device-mapped host
//!   memory ([`PinnedBuffer`], `cuMemHostAlloc`), a caller's own host memory page-locked and mapped in place
//!   ([`HostRegistration`], `cuMemHostRegister`), and managed memory ([`ManagedBuffer`],
//!   `cuMemAllocManaged` with advice and prefetch).
//! - [`placer`]: the [`volpt_core::abi::Uploader`] the CUDA backend hands to a scene's `to_params`:
//!   it places each grid as the policy decides and owns the memory for the render.
//! - [`texture`]: grids as CUDA arrays read through the texture unit (`--lookup texture`).
//!
//! `docs/out-of-core.md` describes the design and the measurements.

pub mod error;
pub mod layout;
pub mod memory;
pub mod placer;
pub mod policy;
pub mod texture;

pub use error::GpuMemError;
pub use memory::{HostRegistration, ManagedBuffer, PinnedBuffer};
pub use placer::{Placed, ResidentGrids, VolumePlacer};
pub use policy::{Placement, VolumeMemory, VolumePolicy};
pub use texture::GridTexture;
