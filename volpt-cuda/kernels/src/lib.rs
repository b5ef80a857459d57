//! volpt's GPU kernels: every strategy for every variant of the registry
//! ([`volpt_core::variant`]), compiled by rustc's NVPTX backend (`cargo xtask ptx`).
//!
//! The list of variants is the registry's, the list of strategies `volpt_device`'s, and the kernel
//! bodies and entry names come from [`volpt_device::export_kernels!`]: this crate only asks for the
//! cartesian product. Beside these box kernels, the kernel sets for lights and meshes
//! ([`volpt_device::KernelSet`]) export their strategies for the variants they cover
//! ([`volpt_device::export_set_kernels!`]). The host launches a scene type's kernel by the names
//! of its parts (`volpt_core::abi::SceneAbi::names`). Besides, one kernel serves every scene: the viewer's
//! tone mapping (`volpt_device::tone`).
//!
//! On any target but nvptx64 this crate is empty, so that host builds of the workspace pass.
//! With `--cfg volpt_selftests_only` (`cargo xtask ptx-selftests`) it exports the selftest
//! kernels (and the tone mapping, which they check) alone: a build in a minute, for judging
//! mutants of volpt-core's GPU-only code.
#![cfg_attr(target_arch = "nvptx64", no_std)]
#![cfg_attr(target_arch = "nvptx64", feature(abi_ptx))]

/// `export_kernels!` for each variant of the registry.
#[cfg(all(target_arch = "nvptx64", not(volpt_selftests_only)))]
macro_rules! export_registry {
    (axes $axes:tt variants [$([($M:ident, $m:ident, $mt:ty) ($B:ident, $b:ident, $bt:ty)
        ($P:ident, $p:ident, $pt:ty) ($E:ident, $e:ident, $et:ty)])*]) => {$(
        volpt_device::export_kernels!($m: $mt, $b: $bt, $p: $pt, $e: $et);
    )*};
}

/// Each kernel set's kernels for the variants of the registry it covers.
#[cfg(all(target_arch = "nvptx64", not(volpt_selftests_only)))]
macro_rules! export_registry_sets {
    (axes $axes:tt variants [$([($M:ident, $m:ident, $mt:ty) ($B:ident, $b:ident, $bt:ty)
        ($P:ident, $p:ident, $pt:ty) ($E:ident, $e:ident, $et:ty)])*]) => {$(
        volpt_device::export_set_kernels!(lit, $m: $mt, $b: $bt, $p: $pt, $e: $et);
        volpt_device::export_set_kernels!(mesh, $m: $mt, $b: $bt, $p: $pt, $e: $et);
    )*};
}

#[cfg(all(target_arch = "nvptx64", not(volpt_selftests_only)))]
volpt_core::variants!('static => export_registry {});

// After the box kernels, so that theirs stay the very text they were (a module numbers its
// functions' labels in order).
#[cfg(all(target_arch = "nvptx64", not(volpt_selftests_only)))]
volpt_core::variants!('static => export_registry_sets {});

#[cfg(target_arch = "nvptx64")]
volpt_device::export_selftests!();

// The viewer's tone mapping: with the selftests too, which check it (`volpt selftest`).
#[cfg(target_arch = "nvptx64")]
volpt_device::export_tone_map!();
