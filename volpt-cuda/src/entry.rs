//! Kernel entry points, derived from types: the entry point of a scene type under a strategy is
//! `<strategy>__<medium>__<boundary>__<phase>__<environment>`, from the parts' `Component::NAME`s,
//! exactly as `volpt_device::export_kernels!` exports it; a kernel set's
//! ([`volpt_device::KernelSet`]: lights, meshes) has the set's prefix before it.

use volpt_core::abi::SceneAbi;
use volpt_device::{KernelSet, Strategy};

use crate::error::CudaError;
use crate::kernels::layout;

/// The entry point that renders scenes of type `S` with `strategy` in the box kernels.
pub fn entry_name<S: SceneAbi>(strategy: Strategy) -> String {
    set_entry_name::<S>(KernelSet::Box, strategy.entry_prefix())
}

/// The entry point of kernel function `prefix` (one of [`Strategy::KERNELS`]) for scene type `S`
/// in kernel set `set`.
fn set_entry_name<S: SceneAbi>(set: KernelSet, prefix: &str) -> String {
    let [m, b, p, e] = S::names();
    match set.prefix() {
        None => format!("{prefix}__{m}__{b}__{p}__{e}"),
        Some(set) => format!("{set}__{prefix}__{m}__{b}__{p}__{e}"),
    }
}

/// The entry point that renders `scene` with `strategy`: the box kernels' unless the scene has a
/// light on or a mesh boundary, then its kernel set's. An error where no kernel of this build
/// traces it: a mesh shaded with vertex normals, lights and a mesh at once, a strategy the set has no kernels for (naming those it
/// has), a variant the set does not cover.
pub fn scene_entry<S: SceneAbi>(scene: &S, strategy: Strategy) -> Result<String, CudaError> {
    if scene.shading_normals() {
        return Err(CudaError::ShadingNormals);
    }
    let set = KernelSet::of_scene(scene).ok_or(CudaError::LightsAndMesh)?;
    if !set.strategies().contains(&strategy) {
        return Err(CudaError::SetStrategy {
            what: set.what(),
            strategy,
            strategies: strategy_names(set),
        });
    }
    if !set.covers(S::names()) {
        return Err(CudaError::SetVariant {
            what: set.what(),
            variant: S::names().join(", "),
        });
    }
    Ok(set_entry_name::<S>(set, strategy.entry_prefix()))
}

/// The names of the strategies kernel set `set` has, as a user types them: `naive-sk,
/// regeneration-sk`.
pub fn strategy_names(set: KernelSet) -> String {
    let names: Vec<&str> = set.strategies().iter().map(|s| s.name()).collect();
    names.join(", ")
}

/// The entry points of every kernel function for every variant of the registry (strategies that
/// share a kernel function share its entry points), and of every kernel set's strategies for the
/// variants it covers: what the workspace's kernels crate must export, no more and no less.
pub fn registry_entries() -> Vec<String> {
    macro_rules! entries {
        (axes $axes:tt variants [$([$(($camel:ident, $snake:ident, $ty:ty))*])*]) => {
            fn variant_entries(set: KernelSet, prefix: &str) -> Vec<String> {
                let mut entries = Vec::new();
                $(
                    if set.covers(<volpt_core::VolumeScene<$($ty),*> as SceneAbi>::names()) {
                        entries.push(set_entry_name::<volpt_core::VolumeScene<$($ty),*>>(set, prefix));
                    }
                )*
                entries
            }
        };
    }
    volpt_core::variants!('static => entries {});
    KernelSet::ALL
        .iter()
        .flat_map(|&set| kernel_functions(set).map(move |prefix| (set, prefix)))
        .flat_map(|(set, prefix)| variant_entries(set, prefix))
        .collect()
}

/// The kernel functions of kernel set `set`'s strategies, each once.
fn kernel_functions(set: KernelSet) -> impl Iterator<Item = &'static str> {
    Strategy::KERNELS
        .iter()
        .copied()
        .filter(move |prefix| set.strategies().iter().any(|s| s.entry_prefix() == *prefix))
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
    fn the_registry_has_one_entry_per_kernel_function_and_variant_of_each_set() {
        let expected: usize = KernelSet::ALL
            .iter()
            .map(|&set| {
                let variants = volpt_core::variant::NAMES
                    .iter()
                    .filter(|&&names| set.covers(names))
                    .count();
                kernel_functions(set).count() * variants
            })
            .sum();
        let mut entries = registry_entries();
        assert_eq!(entries.len(), expected);
        entries.sort();
        entries.dedup();
        assert_eq!(entries.len(), expected);
        let boxes = Strategy::KERNELS.len() * volpt_core::variant::COUNT;
        // The lit set: two strategies for the 24 index-matched variants.
        assert_eq!(
            entries.iter().filter(|e| e.starts_with("lit__")).count(),
            2 * volpt_core::variant::COUNT / 3
        );
        assert!(entries.len() > boxes);
    }

    #[test]
    fn a_scene_with_lights_or_a_mesh_gets_its_sets_kernel_or_an_error() {
        use volpt_core::{
            Aabb, ConstantEnvironment, DirectionalLight, HomogeneousMedium, Isotropic,
            NullBoundary, PerspectiveCamera, SmoothDielectric, Vec2, Vec3,
        };
        let scene = volpt_core::VolumeScene {
            camera: PerspectiveCamera {
                origin: Vec3::new(0.0, 0.0, -3.0),
                axis_x: Vec3::X,
                axis_y: Vec3::Y,
                axis_z: Vec3::Z,
                tan_half_fov: Vec2::splat(0.3),
                width: 4,
                height: 4,
                orthographic: false,
            },
            bounds: Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5)),
            medium: HomogeneousMedium {
                sigma_t: 1.0,
                albedo: Vec3::splat(0.5),
            },
            boundary: NullBoundary,
            phase: Isotropic,
            environment: ConstantEnvironment(Vec3::ONE),
            lights: volpt_core::Lights::NONE,
            settings: Default::default(),
        };
        let box_entry = "regeneration_sk__homogeneous__index_matched__isotropic__constant";
        assert_eq!(
            scene_entry(&scene, Strategy::RegenerationSk).unwrap(),
            box_entry
        );
        let mut lit = scene;
        lit.lights.sun = DirectionalLight::new(-Vec3::Z, 0.0, Vec3::ONE);
        assert_eq!(
            scene_entry(&lit, Strategy::RegenerationSk).unwrap(),
            format!("lit__{box_entry}")
        );
        assert_eq!(
            scene_entry(&lit, Strategy::NaiveSk).unwrap(),
            "lit__naive_sk__homogeneous__index_matched__isotropic__constant"
        );
        let refused = scene_entry(&lit, Strategy::StreamingSk).unwrap_err();
        assert!(
            matches!(refused, CudaError::SetStrategy { .. })
                && refused.to_string().contains("naive-sk, regeneration-sk"),
            "{refused}"
        );
        // Behind a dielectric a delta sun adds nothing: the box kernel renders that scene
        // exactly. A sun disc is seen there, and no lit kernel has a dielectric boundary.
        let mut dielectric = volpt_core::VolumeScene {
            boundary: SmoothDielectric { eta: 1.5 },
            camera: lit.camera,
            bounds: lit.bounds,
            medium: lit.medium,
            phase: lit.phase,
            environment: lit.environment,
            lights: lit.lights,
            settings: lit.settings,
        };
        assert_eq!(
            scene_entry(&dielectric, Strategy::RegenerationSk).unwrap(),
            "regeneration_sk__homogeneous__smooth_dielectric__isotropic__constant"
        );
        dielectric.lights.sun = DirectionalLight::new(-Vec3::Z, 0.1, Vec3::ONE);
        assert!(matches!(
            scene_entry(&dielectric, Strategy::RegenerationSk),
            Err(CudaError::SetVariant { .. })
        ));
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
