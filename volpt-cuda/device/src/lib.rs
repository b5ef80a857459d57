//! The GPU side of volpt that host and kernels share, `no_std`.
//!
//! - [`launch`]: the launch parameters a kernel receives ([`LaunchParams`]), composed from the
//!   scene's typed device ABI ([`volpt_core::abi`]), and the scheduling arithmetic of every
//!   strategy as plain functions (tested on the CPU, used by host and kernels alike).
//! - [`Strategy`]: the scheduling strategies, generated from one list with their entry names.
//! - [`order`]: Morton codes of path positions, the keys of the sorting strategies.
//! - [`Math`]: exact (CPU-identical) or fast (approximate) kernels, two builds of one source.
//! - [`export_kernels!`]: exports the kernels of every strategy for one scene type. The workspace's
//!   kernels crate invokes it for every variant of the registry; a library user invokes it for a
//!   scene of their own parts (see `docs/extending.md`).
//! - [`KernelSet`]: the box kernels, and the limited sets of kernels for lights and for meshes
//!   ([`kernel_set`]; [`export_set_kernels!`] exports them), so that the box kernels of scenes
//!   without either compile none of their code.
//! - [`selftest`]: kernels that test the strategies' collective building blocks, texture lookups
//!   and `volpt_core::math` against the CPU.
//! - [`tone`]: the viewer's tone mapping (exposure, sRGB, 8 bits) on the GPU, beside the film.
//! - on nvptx64 only: [`strategy`] (the strategies' kernel bodies) and the PTX intrinsics they use.
#![no_std]
#![cfg_attr(
    target_arch = "nvptx64",
    feature(abi_ptx, stdarch_nvptx, asm_experimental_arch, stmt_expr_attributes)
)]

// The `clap` derive of `Strategy` (a host-only feature) expands to paths through `std`.
#[cfg(feature = "clap")]
extern crate std;

pub mod kernel_set;
pub mod launch;
mod math;
pub mod order;
pub mod selftest;
mod strategies;
pub mod tone;

#[cfg(target_arch = "nvptx64")]
pub mod nvptx;
#[cfg(target_arch = "nvptx64")]
pub mod strategy;

pub use kernel_set::KernelSet;
pub use launch::LaunchParams;
pub use math::Math;
pub use strategies::Strategy;
