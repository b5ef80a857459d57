//! volpt's GPU kernels: `volpt-core`'s generic path step, instantiated for every scene variant and
//! every scheduling strategy, compiled by rustc's NVPTX backend (`cargo xtask ptx`).
//!
//! A kernel takes one argument, the device address of a [`volpt_core::launch::LaunchParams`]. It
//! copies the parameters, rebuilds the very `VolumeScene` type the CPU renders that variant with (see
//! [`volpt_core::launch::FromParams`]) and runs a strategy from [`strategy`] on it. Kernel names are
//! `<strategy>__<medium>__<boundary>__<phase>`, e.g. `naive_sk__homogeneous__rough_dielectric__hg`:
//! the host derives them from the render factory's `Variant`.
//!
//! On any target but nvptx64 this crate is empty, so that host builds of the workspace pass.
#![cfg_attr(target_arch = "nvptx64", no_std)]
#![cfg_attr(
    target_arch = "nvptx64",
    feature(abi_ptx, stdarch_nvptx, asm_experimental_arch)
)]

#[cfg(target_arch = "nvptx64")]
mod device;
#[cfg(target_arch = "nvptx64")]
pub mod strategy;

/// One kernel: strategy `$strategy` (a generic function of [`strategy`]) on the scene type
/// `VolumeScene<$medium, $boundary, $phase, ConstantEnvironment>`, exported as `$name`.
#[cfg(target_arch = "nvptx64")]
macro_rules! kernel {
    ($name:expr, $entry:ident, $strategy:ident, $medium:ty, $boundary:ty, $phase:ty) => {
        /// # Safety
        /// `params` must be the device address of an initialised `LaunchParams` whose buffers and
        /// grids stay allocated until the kernel ends.
        #[export_name = $name]
        pub unsafe extern "ptx-kernel" fn $entry(params: *const LaunchParams) {
            // SAFETY: the caller's contract.
            let lp = unsafe { *params };
            // SAFETY: the grid addresses in `lp` are device allocations the host keeps alive.
            let scene: VolumeScene<$medium, $boundary, $phase, ConstantEnvironment> =
                unsafe { FromParams::from_params(&lp.scene) };
            // SAFETY: `lp`'s buffers are sized for this launch.
            unsafe { crate::strategy::$strategy(&scene, &lp) }
        }
    };
}

/// Instantiates every strategy for each listed variant: `<name>: <medium>, <boundary>, <phase>;`.
/// A new strategy is one more `kernel!` line here, never a copied kernel body.
#[cfg(target_arch = "nvptx64")]
macro_rules! kernels {
    ($($variant:ident: $medium:ty, $boundary:ty, $phase:ty;)*) => {$(
        #[allow(non_snake_case)]
        pub mod $variant {
            use volpt_core::launch::{FromParams, LaunchParams};
            use volpt_core::{ConstantEnvironment, VolumeScene};
            #[allow(unused_imports)]
            use volpt_core::{
                ConstantAlbedo, GridAlbedo, GridMedium, HenyeyGreenstein, HomogeneousMedium,
                Isotropic, NullBoundary, RoughDielectric, SmoothDielectric,
            };

            kernel!(concat!("naive_sk__", stringify!($variant)), naive_sk, naive,
                $medium, $boundary, $phase);
            kernel!(concat!("regeneration_sk__", stringify!($variant)), regeneration_sk,
                regeneration, $medium, $boundary, $phase);
        }
    )*};
}

#[cfg(target_arch = "nvptx64")]
kernels! {
    homogeneous__index_matched__isotropic: HomogeneousMedium, NullBoundary, Isotropic;
    homogeneous__index_matched__hg: HomogeneousMedium, NullBoundary, HenyeyGreenstein;
    homogeneous__smooth_dielectric__isotropic: HomogeneousMedium, SmoothDielectric, Isotropic;
    homogeneous__smooth_dielectric__hg: HomogeneousMedium, SmoothDielectric, HenyeyGreenstein;
    homogeneous__rough_dielectric__isotropic: HomogeneousMedium, RoughDielectric, Isotropic;
    homogeneous__rough_dielectric__hg: HomogeneousMedium, RoughDielectric, HenyeyGreenstein;
    grid_density__index_matched__isotropic: GridMedium<'_, ConstantAlbedo>, NullBoundary, Isotropic;
    grid_density__index_matched__hg: GridMedium<'_, ConstantAlbedo>, NullBoundary, HenyeyGreenstein;
    grid_density__smooth_dielectric__isotropic: GridMedium<'_, ConstantAlbedo>, SmoothDielectric, Isotropic;
    grid_density__smooth_dielectric__hg: GridMedium<'_, ConstantAlbedo>, SmoothDielectric, HenyeyGreenstein;
    grid_density__rough_dielectric__isotropic: GridMedium<'_, ConstantAlbedo>, RoughDielectric, Isotropic;
    grid_density__rough_dielectric__hg: GridMedium<'_, ConstantAlbedo>, RoughDielectric, HenyeyGreenstein;
    grid_density_albedo__index_matched__isotropic: GridMedium<'_, GridAlbedo<'_>>, NullBoundary, Isotropic;
    grid_density_albedo__index_matched__hg: GridMedium<'_, GridAlbedo<'_>>, NullBoundary, HenyeyGreenstein;
    grid_density_albedo__smooth_dielectric__isotropic: GridMedium<'_, GridAlbedo<'_>>, SmoothDielectric, Isotropic;
    grid_density_albedo__smooth_dielectric__hg: GridMedium<'_, GridAlbedo<'_>>, SmoothDielectric, HenyeyGreenstein;
    grid_density_albedo__rough_dielectric__isotropic: GridMedium<'_, GridAlbedo<'_>>, RoughDielectric, Isotropic;
    grid_density_albedo__rough_dielectric__hg: GridMedium<'_, GridAlbedo<'_>>, RoughDielectric, HenyeyGreenstein;
}
