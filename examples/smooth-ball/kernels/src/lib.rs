//! The smooth ball's kernels: every volpt strategy for one scene type of the user's choice. The
//! names before the types are the parts' `Component::NAME`s; the host finds the kernels by them.
#![cfg_attr(target_arch = "nvptx64", no_std)]
#![cfg_attr(target_arch = "nvptx64", feature(abi_ptx))]

#[cfg(target_arch = "nvptx64")]
volpt_device::export_kernels!(
    smooth_ball: volpt_example_smooth_ball::SmoothBall,
    index_matched: volpt_core::NullBoundary,
    henyey_greenstein: volpt_core::HenyeyGreenstein,
    constant: volpt_core::ConstantEnvironment,
);
