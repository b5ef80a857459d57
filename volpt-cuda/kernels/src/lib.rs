//! volpt's GPU kernels: `volpt-core`'s generic path step, instantiated for every scene variant and
//! every scheduling strategy, compiled by rustc's NVPTX backend (`cargo xtask ptx`).
//!
//! A kernel takes one argument, the device address of a [`volpt_core::launch::LaunchParams`]. It
//! copies the parameters, rebuilds the very `VolumeScene` type the CPU renders that variant with (see
//! [`volpt_core::launch::FromParams`]) and runs a strategy from [`strategy`] on it. Kernel names are
//! `<strategy>__<medium>__<boundary>__<phase>`, e.g. `naive_sk__homogeneous__rough_dielectric__hg`,
//! with `__envmap` appended for a lat-long environment: the host derives them from the render
//! factory's `Variant`. Every combination of the axes is instantiated (3 media x 3 boundaries x 2
//! phases x 2 environments x 2 strategies = 72 kernels) by the macros below, one module per axis.
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
/// `VolumeScene<$medium, $boundary, $phase, $environment>`, exported as `$name`.
#[cfg(target_arch = "nvptx64")]
macro_rules! kernel {
    ($name:expr, $entry:ident, $strategy:ident, $medium:ty, $boundary:ty, $phase:ty,
     $environment:ty) => {
        /// # Safety
        /// `params` must be the device address of an initialised `LaunchParams` whose buffers,
        /// grids and environment map stay allocated until the kernel ends.
        #[export_name = $name]
        pub unsafe extern "ptx-kernel" fn $entry(params: *const LaunchParams) {
            // SAFETY: the caller's contract.
            let lp = unsafe { *params };
            // SAFETY: the grid and map addresses in `lp` are device allocations the host keeps
            // alive.
            let scene: VolumeScene<$medium, $boundary, $phase, $environment> =
                unsafe { FromParams::from_params(&lp.scene) };
            // SAFETY: `lp`'s buffers are sized for this launch.
            unsafe { crate::strategy::$strategy(&scene, &lp) }
        }
    };
}

/// The cartesian product of the variant axes, one nested module per axis value (`macro_rules!`
/// cannot paste identifiers, so modules keep the entry points apart), ending in one `kernel!` per
/// strategy. Each level takes its own axis as `{name: Type, ...}` and passes the remaining axes on
/// untouched as token trees. A new strategy is one more `kernel!` line in the last level; a new
/// axis value is one more entry in the `kernels!` invocation.
#[cfg(target_arch = "nvptx64")]
macro_rules! kernels {
    (medium: {$($m:ident: $mt:ty),* $(,)?} boundary: $b:tt phase: $p:tt environment: $e:tt) => {$(
        pub mod $m {
            by_boundary!(($m: $mt) $b $p $e);
        }
    )*};
}

#[cfg(target_arch = "nvptx64")]
macro_rules! by_boundary {
    (($m:ident: $mt:ty) {$($b:ident: $bt:ty),* $(,)?} $p:tt $e:tt) => {$(
        pub mod $b {
            by_phase!(($m: $mt) ($b: $bt) $p $e);
        }
    )*};
}

#[cfg(target_arch = "nvptx64")]
macro_rules! by_phase {
    (($m:ident: $mt:ty) ($b:ident: $bt:ty) {$($p:ident: $pt:ty),* $(,)?} $e:tt) => {$(
        pub mod $p {
            by_environment!(($m: $mt) ($b: $bt) ($p: $pt) $e);
        }
    )*};
}

/// The last axis: `$suffix` ends the exported name (empty for the constant environment, whose
/// kernels keep their names from before environment maps).
#[cfg(target_arch = "nvptx64")]
macro_rules! by_environment {
    (($m:ident: $mt:ty) ($b:ident: $bt:ty) ($p:ident: $pt:ty)
     {$($e:ident: $et:ty => $suffix:literal),* $(,)?}) => {$(
        pub mod $e {
            use volpt_core::launch::{FromParams, LaunchParams};
            use volpt_core::VolumeScene;
            #[allow(unused_imports)]
            use volpt_core::{
                ConstantAlbedo, ConstantEnvironment, GridAlbedo, GridMedium, HenyeyGreenstein,
                HomogeneousMedium, Isotropic, LatLongEnvironment, NullBoundary, RoughDielectric,
                SmoothDielectric,
            };

            kernel!(
                concat!("naive_sk__", stringify!($m), "__", stringify!($b), "__",
                    stringify!($p), $suffix),
                naive_sk, naive, $mt, $bt, $pt, $et
            );
            kernel!(
                concat!("regeneration_sk__", stringify!($m), "__", stringify!($b), "__",
                    stringify!($p), $suffix),
                regeneration_sk, regeneration, $mt, $bt, $pt, $et
            );
        }
    )*};
}

// Axis value names are the render factory's `Variant` names with '-' as '_'.
#[cfg(target_arch = "nvptx64")]
kernels! {
    medium: {
        homogeneous: HomogeneousMedium,
        grid_density: GridMedium<'_, ConstantAlbedo>,
        grid_density_albedo: GridMedium<'_, GridAlbedo<'_>>,
    }
    boundary: {
        index_matched: NullBoundary,
        smooth_dielectric: SmoothDielectric,
        rough_dielectric: RoughDielectric,
    }
    phase: {
        isotropic: Isotropic,
        hg: HenyeyGreenstein,
    }
    environment: {
        constant: ConstantEnvironment => "",
        envmap: LatLongEnvironment<'_> => "__envmap",
    }
}
