//! Kernel entry points, derived from types: the entry point of a scene type under a strategy is
//! `<strategy>__<medium>__<boundary>__<phase>__<environment>`, from the parts' `Component::NAME`s,
//! exactly as `volpt_device::export_kernels!` exports it.

use volpt_core::abi::SceneAbi;
use volpt_device::Strategy;

/// The entry point that renders scenes of type `S` with `strategy`.
pub fn entry_name<S: SceneAbi>(strategy: Strategy) -> String {
    let [m, b, p, e] = S::names();
    format!("{}__{m}__{b}__{p}__{e}", strategy.entry_prefix())
}

/// The entry points of every strategy for every variant of the registry: what the workspace's
/// kernels crate must export, no more and no less.
pub fn registry_entries() -> Vec<String> {
    macro_rules! entries {
        (axes $axes:tt variants [$([$(($camel:ident, $snake:ident, $ty:ty))*])*]) => {
            fn variant_entries(strategy: Strategy) -> Vec<String> {
                vec![$(entry_name::<volpt_core::VolumeScene<$($ty),*>>(strategy)),*]
            }
        };
    }
    volpt_core::variants!('static => entries {});
    Strategy::ALL
        .iter()
        .flat_map(|&strategy| variant_entries(strategy))
        .collect()
}

/// The names of the `.entry` directives of a PTX module.
pub fn ptx_entries(ptx: &str) -> Vec<&str> {
    ptx.lines()
        .filter_map(|line| line.split_once(".entry ").map(|(_, rest)| rest))
        .map(|rest| rest.trim_end_matches(['(', ' ']).trim())
        .collect()
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
            "regeneration_sk__grid_density_albedo__rough_dielectric__henyey_greenstein__lat_long"
        );
    }

    #[test]
    fn the_registry_has_one_entry_per_strategy_and_variant() {
        let mut entries = registry_entries();
        assert_eq!(entries.len(), Strategy::ALL.len() * 36);
        entries.sort();
        entries.dedup();
        assert_eq!(entries.len(), Strategy::ALL.len() * 36);
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
