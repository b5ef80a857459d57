//! The kernels this build embeds are exactly the registry's: every variant has an entry point for
//! every strategy, and the PTX holds no entry point that no variant uses.
//!
//! CI builds the PTX (`cargo xtask ptx`) and sets `VOLPT_REQUIRE_PTX=1`, so a missing PTX fails
//! there; on a machine that never built the kernels the test says so and checks nothing.

use std::collections::BTreeSet;

use volpt_cuda::entry::{ptx_entries, registry_entries};

#[test]
fn the_ptx_exports_exactly_the_registry() {
    let Some(ptx) = volpt_cuda::kernels_ptx() else {
        assert!(
            std::env::var_os("VOLPT_REQUIRE_PTX").is_none(),
            "VOLPT_REQUIRE_PTX is set but this build embeds no PTX: run `cargo xtask ptx` first"
        );
        eprintln!("SKIPPED: this build embeds no PTX (run `cargo xtask ptx`, then test again)");
        return;
    };
    let exported: BTreeSet<&str> = ptx_entries(ptx).into_iter().collect();
    let registry = registry_entries();
    let registry: BTreeSet<&str> = registry.iter().map(String::as_str).collect();
    let missing: Vec<_> = registry.difference(&exported).collect();
    let unused: Vec<_> = exported.difference(&registry).collect();
    assert!(missing.is_empty(), "variants without a kernel: {missing:?}");
    assert!(unused.is_empty(), "kernels no variant uses: {unused:?}");
}
