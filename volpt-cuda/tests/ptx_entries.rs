//! The kernels this build embeds are exactly the registry's: every variant has an entry point for
//! every strategy, and the PTX holds no entry point that no variant uses.
//!
//! CI builds the PTX (`cargo xtask ptx`) and sets `VOLPT_REQUIRE_PTX=1`, so a missing PTX fails
//! there; on a machine that never built the kernels the test says so and checks nothing.

use std::collections::BTreeSet;

use volpt_cuda::entry::{ptx_entries, registry_entries};
use volpt_cuda::Math;

#[test]
fn the_exact_ptx_exports_exactly_the_registry() {
    exports_exactly_the_registry(Math::Exact);
}

#[test]
fn the_fast_ptx_exports_exactly_the_registry() {
    exports_exactly_the_registry(Math::Fast);
}

fn exports_exactly_the_registry(math: Math) {
    let Some(ptx) = volpt_cuda::kernels_ptx(math) else {
        assert!(
            std::env::var_os("VOLPT_REQUIRE_PTX").is_none(),
            "VOLPT_REQUIRE_PTX is set but this build embeds no {math} PTX: run `cargo xtask ptx` first"
        );
        eprintln!(
            "SKIPPED: this build embeds no {math} PTX (run `cargo xtask ptx`, then test again)"
        );
        return;
    };
    let exported: BTreeSet<&str> = ptx_entries(ptx).into_iter().collect();
    let registry = registry_entries();
    let registry: BTreeSet<&str> = registry
        .iter()
        .map(String::as_str)
        .chain(volpt_device::selftest::ENTRIES)
        .collect();
    let missing: Vec<_> = registry.difference(&exported).collect();
    let unused: Vec<_> = exported.difference(&registry).collect();
    assert!(missing.is_empty(), "variants without a kernel: {missing:?}");
    assert!(unused.is_empty(), "kernels no variant uses: {unused:?}");
}

/// Every kernel of the registry can be cut out of the module on its own (the renderer JIT-compiles
/// one kernel at a time), and the cut keeps exactly that entry.
#[test]
fn every_kernel_compiles_alone() {
    for math in Math::ALL.iter().copied() {
        let Some(ptx) = volpt_cuda::kernels_ptx(math) else {
            continue;
        };
        for entry in registry_entries() {
            let alone = volpt_cuda::entry::single_kernel_ptx(ptx, &entry, Some(96))
                .unwrap_or_else(|| panic!("{math}: {entry} not in the PTX"));
            assert_eq!(ptx_entries(&alone), [entry.as_str()]);
            assert!(
                alone.len() < ptx.len() / 10,
                "{entry}: {} bytes",
                alone.len()
            );
        }
    }
}

/// No kernel keeps per-thread state in local memory beyond the 64 bytes of the path counters'
/// final warp reduction (an array walked once, at the kernel's end). A larger local depot means
/// LLVM left a scene part behind a pointer: a call it did not inline takes the scene by address,
/// or a vector is indexed at run time. That cost cgg-logo 1.5x its time on an H100 (a 456-byte
/// frame from a grid lookup that was not inlined, `docs/strategies.md`).
///
/// One kernel keeps local memory by design: regeneration-2p-sk walks its two paths in an array
/// with a loop, so that one copy of the step's code serves both (`strategy::regeneration_2p_sk`
/// says why); its frame may hold those paths, no more.
#[test]
fn no_kernel_keeps_the_scene_in_local_memory() {
    const COUNTER_FLUSH_BYTES: usize = 64;
    // The counters' 64 bytes and 192 of two paths with their pixels and flags (256 in every
    // regeneration-2p-sk kernel of both builds, 2026-11-24).
    const TWO_PATH_ARRAY_BYTES: usize = 256;
    for math in Math::ALL.iter().copied() {
        let Some(ptx) = volpt_cuda::kernels_ptx(math) else {
            continue;
        };
        let mut heavy = Vec::new();
        for entry in registry_entries() {
            let alone = volpt_cuda::entry::single_kernel_ptx(ptx, &entry, None)
                .unwrap_or_else(|| panic!("{math}: {entry} not in the PTX"));
            let depot = local_depot_bytes(&alone);
            let allowed = if entry.starts_with("regeneration_2p_sk__") {
                TWO_PATH_ARRAY_BYTES
            } else {
                COUNTER_FLUSH_BYTES
            };
            if depot > allowed {
                heavy.push(format!("{entry}: {depot} bytes"));
            }
        }
        assert!(
            heavy.is_empty(),
            "{math}: kernels with local memory: {heavy:?}"
        );
    }
}

/// The largest `.local ... __local_depotN[BYTES]` of a PTX module (0 without one).
fn local_depot_bytes(ptx: &str) -> usize {
    ptx.lines()
        .filter(|line| line.contains(".local") && line.contains("__local_depot"))
        .filter_map(|line| {
            let size = line.rsplit('[').next()?.split(']').next()?;
            size.parse::<usize>().ok()
        })
        .max()
        .unwrap_or(0)
}
