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
