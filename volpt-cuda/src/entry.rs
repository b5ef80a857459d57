//! Kernel entry points, derived from types: the entry point of a scene type under a strategy is
//! `<strategy>__<medium>__<boundary>__<phase>__<environment>`, from the parts' `Component::NAME`s,
//! exactly as `volpt_device::export_kernels!` exports it.

use volpt_core::abi::SceneAbi;
use volpt_device::Strategy;

use crate::kernels::layout;

/// The entry point that renders scenes of type `S` with `strategy`.
pub fn entry_name<S: SceneAbi>(strategy: Strategy) -> String {
    kernel_entry_name::<S>(strategy.entry_prefix())
}

/// The entry point of kernel function `prefix` (one of [`Strategy::KERNELS`]) for scene type `S`.
fn kernel_entry_name<S: SceneAbi>(prefix: &str) -> String {
    let [m, b, p, e] = S::names();
    format!("{prefix}__{m}__{b}__{p}__{e}")
}

/// The entry points of every kernel function for every variant of the registry (strategies that
/// share a kernel function share its entry points): what the workspace's kernels crate must
/// export, no more and no less.
pub fn registry_entries() -> Vec<String> {
    macro_rules! entries {
        (axes $axes:tt variants [$([$(($camel:ident, $snake:ident, $ty:ty))*])*]) => {
            fn variant_entries(prefix: &str) -> Vec<String> {
                vec![$(kernel_entry_name::<volpt_core::VolumeScene<$($ty),*>>(prefix)),*]
            }
        };
    }
    volpt_core::variants!('static => entries {});
    Strategy::KERNELS
        .iter()
        .flat_map(|prefix| variant_entries(prefix))
        .collect()
}

/// The names of the `.entry` directives of a PTX module.
pub fn ptx_entries(ptx: &str) -> Vec<&str> {
    ptx.lines().filter_map(layout::entry_name).collect()
}

/// The module `ptx` reduced to one kernel, `entry`, with everything it may use (the header, globals,
/// shared variables and functions), or `None` if `ptx` has no such entry. The driver JIT-compiles a
/// module as a whole; one kernel compiles in a fraction of the time of every kernel of the registry.
///
/// With `max_registers`, the entry gets a `.maxnreg` directive: the JIT caps its registers per thread
/// there (spilling what does not fit), the register cap of the thesis's occupancy study.
///
/// The embedded kernels are cut the same way, from their pack ([`crate::kernels::KernelPack::kernel`]).
pub fn single_kernel_ptx(ptx: &str, entry: &str, max_registers: Option<u32>) -> Option<String> {
    let split = layout::split(ptx);
    let kept = split.entries.iter().find(|e| e.name == entry)?;
    Some(layout::assemble(
        &split.common,
        kept.at,
        kept.text,
        max_registers,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use volpt_core::{GridAlbedo, GridMedium, HenyeyGreenstein, LatLongEnvironment};
    use volpt_core::{RoughDielectric, VolumeScene};

    #[test]
    fn entry_names_follow_the_parts() {
        type Scene = VolumeScene<
            GridMedium<'static, GridAlbedo<'static>>,
            RoughDielectric,
            HenyeyGreenstein,
            LatLongEnvironment<'static>,
        >;
        assert_eq!(
            entry_name::<Scene>(Strategy::RegenerationSk),
            "regeneration_sk__grid_density__grid_albedo__dense_trilinear__rough_dielectric__henyey_greenstein__lat_long"
        );
    }

    #[test]
    fn the_registry_has_one_entry_per_kernel_function_and_variant() {
        let mut entries = registry_entries();
        assert_eq!(
            entries.len(),
            Strategy::KERNELS.len() * volpt_core::variant::COUNT
        );
        entries.sort();
        entries.dedup();
        assert_eq!(
            entries.len(),
            Strategy::KERNELS.len() * volpt_core::variant::COUNT
        );
    }

    /// Every strategy's kernel function is listed once, and every listed one serves a strategy.
    #[test]
    fn the_kernel_functions_are_the_strategies_own() {
        let mut kernels = Strategy::KERNELS.to_vec();
        kernels.sort();
        kernels.dedup();
        assert_eq!(kernels.len(), Strategy::KERNELS.len(), "listed twice");
        let mut used: Vec<&str> = Strategy::ALL.iter().map(|s| s.entry_prefix()).collect();
        used.sort();
        used.dedup();
        assert_eq!(used, kernels);
        assert_eq!(
            Strategy::NaiveMk.entry_prefix(),
            Strategy::StreamingMk.entry_prefix()
        );
    }

    const MODULE: &str = ".version 6.0\n.shared .align 8 .b64 s[5];\n.func f(\n)\n{\n\tret;\n}\n\
        \t// .globl\ta__x\n.visible .entry a__x(\n\t.param .u64 p\n)\n{\n\tcall f;\n}\n\
        .visible .entry b__y(\n\t.param .u64 p\n)\n{\n\t{\n\t}\n\tret;\n}\n.global .b8 g[1];\n";

    #[test]
    fn one_kernel_keeps_everything_but_the_other_entries() {
        let a = single_kernel_ptx(MODULE, "a__x", None).unwrap();
        assert_eq!(ptx_entries(&a), ["a__x"]);
        for kept in [
            ".version 6.0",
            ".shared .align 8 .b64 s[5];",
            ".func f(",
            "call f;",
            ".global .b8 g[1];",
        ] {
            assert!(a.contains(kept), "{kept} missing from {a}");
        }
        let b = single_kernel_ptx(MODULE, "b__y", None).unwrap();
        assert_eq!(ptx_entries(&b), ["b__y"]);
        // The nested block is inside b's body; the module's tail follows b.
        assert!(b.contains("\t{\n\t}\n\tret;\n}\n.global .b8 g[1];"), "{b}");
        assert!(!b.contains("call f;"));
        assert_eq!(single_kernel_ptx(MODULE, "c__z", None), None);
    }

    #[test]
    fn a_register_cap_goes_before_the_kernels_body() {
        let a = single_kernel_ptx(MODULE, "a__x", Some(64)).unwrap();
        assert!(
            a.contains("\t.param .u64 p\n)\n.maxnreg 64\n{\n\tcall f;"),
            "{a}"
        );
        assert_eq!(a.matches(".maxnreg").count(), 1);
    }

    #[test]
    fn ptx_entry_directives_are_read() {
        let ptx = ".visible .entry naive_sk__a__b__c__d(\n\t.param .u64 p\n)\n.func f(\n\
                   .visible .entry regeneration_sk__a__b__c__d(\n";
        assert_eq!(
            ptx_entries(ptx),
            ["naive_sk__a__b__c__d", "regeneration_sk__a__b__c__d"]
        );
    }
}
