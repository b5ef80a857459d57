//! The kernel sets: what a scene needs beyond the box kernels gets kernels of its own, so that the
//! box kernels of scenes without it do not change at all.
//!
//! - [`KernelSet::Box`]: every strategy for every variant of the registry, of scene type
//!   [`BoxScene`]: a box boundary, no lights besides the environment.
//! - [`KernelSet::Lit`]: the lights besides the environment (sun, point, spot), of [`LitScene`],
//!   behind an index-matched boundary only (a dielectric cannot connect to a delta light: the
//!   factory refuses or warns), for the strategies of [`KernelSet::strategies`].
//! - [`KernelSet::Mesh`]: triangle-mesh boundaries, of [`MeshScene`] (a box or a mesh, chosen at
//!   run time: [`volpt_core::DeviceBoundary`]), for the variants of [`KernelSet::covers`] and the
//!   strategies of [`KernelSet::strategies`].
//!
//! Sampled at run time in every kernel, the lights raised smoke's index-matched kernel from 80 to
//! 158 registers and cost grey scenes without lights up to 41% (H200, 2026-11-29); the mesh's
//! BVH walk cost every box kernel 20 to 100 registers (`docs/gpu.md`, meshes). So each is a
//! property of a kernel's scene type ([`volpt_core::Scene::LIGHTS`], [`volpt_core::Scene::Shape`]),
//! and only its own, limited set of kernels has it. A set's entry points are its prefix, then the
//! box kernels' names (`lit__regeneration_sk__homogeneous__index_matched__isotropic__constant`).
//!
//! The sets' strategies are listed once, by [`kernel_sets!`](crate::kernel_sets): the host's
//! [`KernelSet::strategies`] and the kernels' exports ([`export_set_kernels!`]
//! (crate::export_set_kernels)) are both generated from that list.

use volpt_core::abi::SceneAbi;
use volpt_core::{DeviceBoundary, Lit, VolumeScene};

use crate::Strategy;

/// The box kernels' scene type: a box boundary, no lights besides the environment (in a kernel,
/// a `VolumeScene` has none: [`volpt_core::Scene::LIGHTS`]).
pub type BoxScene<M, B, P, E> = VolumeScene<M, B, P, E>;
/// The lit kernels' scene type: the lights that are on, sampled (a run-time branch).
pub type LitScene<M, B, P, E> = Lit<VolumeScene<M, B, P, E>>;
/// The mesh kernels' scene type: a box or a mesh at run time, no lights.
pub type MeshScene<M, B, P, E> = VolumeScene<M, B, P, E, DeviceBoundary<'static>>;

/// Calls `$callback!` with `$args` and each kernel set beyond the box kernels: its variant, its
/// entry prefix and its strategies as `(Strategy variant, kernel function)`.
///
/// Both sets trace with two strategies: regeneration-sk, the default one (`--strategy auto`
/// without a calibration runs it), and naive-sk, whose sums are the CPU's bit for bit (the
/// checks of exact math). The others would cost the binary ~70 KB a kernel.
#[macro_export]
macro_rules! kernel_sets {
    ($callback:path { $($args:tt)* }) => {
        $callback! { $($args)*
            sets [
                (Lit, lit, [(NaiveSk, naive_sk) (RegenerationSk, regeneration_sk)])
                (Mesh, mesh, [(NaiveSk, naive_sk) (RegenerationSk, regeneration_sk)])
            ]
        }
    };
}

macro_rules! define_kernel_set {
    (sets [$(($camel:ident, $prefix:ident, [$(($strategy:ident, $s:ident))*]))*]) => {
        /// A set of kernels ([module documentation](self)).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum KernelSet {
            /// Every strategy for every variant: box boundaries, no lights.
            Box,
            $($camel,)*
        }

        impl KernelSet {
            pub const ALL: &'static [KernelSet] = &[KernelSet::Box, $(KernelSet::$camel),*];

            /// The prefix of the set's entry points (before the box kernels' names); none for
            /// the box kernels.
            pub fn prefix(self) -> Option<&'static str> {
                match self {
                    KernelSet::Box => None,
                    $(KernelSet::$camel => Some(stringify!($prefix)),)*
                }
            }

            /// The strategies that have kernels in this set.
            pub fn strategies(self) -> &'static [Strategy] {
                match self {
                    KernelSet::Box => Strategy::ALL,
                    $(KernelSet::$camel => &[$(Strategy::$strategy),*],)*
                }
            }
        }
    };
}

kernel_sets!(define_kernel_set {});

impl KernelSet {
    /// The set whose kernels render a scene with (`lights`) or without lights besides the
    /// environment, whose boundary is a mesh or not (`mesh`); `None` for both at once (no set has
    /// kernels for them: such a scene renders on the CPU).
    pub fn of(lights: bool, mesh: bool) -> Option<Self> {
        match (lights, mesh) {
            (false, false) => Some(KernelSet::Box),
            (true, false) => Some(KernelSet::Lit),
            (false, true) => Some(KernelSet::Mesh),
            (true, true) => None,
        }
    }

    /// The set of `scene`'s kernels, as [`KernelSet::of`]: with lights if its paths reach any
    /// ([`volpt_core::light::reached`]: a delta light behind a dielectric boundary adds nothing,
    /// and the box kernels render that scene exactly).
    pub fn of_scene<S: SceneAbi>(scene: &S) -> Option<Self> {
        Self::of(volpt_core::light::reached(scene), !scene.on_device())
    }

    /// Whether the set has kernels for the variant of parts `[medium, boundary, phase,
    /// environment]` (registry names, [`volpt_core::variant::NAMES`]).
    ///
    /// - Lit: an index-matched boundary (a dielectric one cannot connect to a delta light), any
    ///   medium, phase and environment.
    /// - Mesh: the grey media without an albedo grid in any layout but the dense one
    ///   (homogeneous, the dense grids), every boundary, phase and environment: the mesh is the
    ///   boundary, so every boundary kind; the chromatic, any-layout and texture media would
    ///   double the set for scenes that combine them with a mesh, which render on the CPU
    ///   ([`crate::export_set_kernels!`]'s filter is the same).
    pub fn covers(self, [medium, boundary, _phase, _environment]: [&str; 4]) -> bool {
        match self {
            KernelSet::Box => true,
            KernelSet::Lit => boundary == "index_matched",
            KernelSet::Mesh => {
                matches!(
                    medium,
                    "homogeneous"
                        | "grid_density__constant_albedo__dense_trilinear"
                        | "grid_density__grid_albedo__dense_trilinear"
                )
            }
        }
    }

    /// Whether the set has `strategy`'s kernel for the variant of parts `names`.
    pub fn has(self, strategy: Strategy, names: [&str; 4]) -> bool {
        self.covers(names) && self.strategies().contains(&strategy)
    }

    /// What the set's scenes have that the box kernels' do not, in words for errors.
    pub fn what(self) -> &'static str {
        match self {
            KernelSet::Box => "a box boundary and no lights",
            KernelSet::Lit => "a sun, point or spot light",
            KernelSet::Mesh => "a triangle-mesh boundary",
        }
    }
}

/// Exports kernel set `$set`'s kernels (`lit` or `mesh`) for the variant `VolumeScene<M, B, P, E>`
/// if the set covers it ([`KernelSet::covers`]; the same filter, by the parts' registry names),
/// else nothing.
#[macro_export]
macro_rules! export_set_kernels {
    (lit, $m:ident: $mt:ty, index_matched: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty) => {
        $crate::kernel_sets! { $crate::export_set_kernels {
            @set lit LitScene ($m: $mt, index_matched: $bt, $p: $pt, $e: $et)
        } }
    };
    (mesh, homogeneous: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty) => {
        $crate::kernel_sets! { $crate::export_set_kernels {
            @set mesh MeshScene (homogeneous: $mt, $b: $bt, $p: $pt, $e: $et)
        } }
    };
    (mesh, grid_density__constant_albedo__dense_trilinear: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty,
     $e:ident: $et:ty) => {
        $crate::kernel_sets! { $crate::export_set_kernels {
            @set mesh MeshScene (grid_density__constant_albedo__dense_trilinear: $mt, $b: $bt, $p: $pt, $e: $et)
        } }
    };
    (mesh, grid_density__grid_albedo__dense_trilinear: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty,
     $e:ident: $et:ty) => {
        $crate::kernel_sets! { $crate::export_set_kernels {
            @set mesh MeshScene (grid_density__grid_albedo__dense_trilinear: $mt, $b: $bt, $p: $pt, $e: $et)
        } }
    };
    ($set:ident, $m:ident: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty) => {};
    // The set's own strategies, from `kernel_sets!`.
    (@set $set:ident $scene:ident $variant:tt sets [$(($camel:ident, $prefix:ident, $strategies:tt))*]) => {
        $($crate::export_set_kernels! { @pick $set $prefix $scene $variant $strategies })*
    };
    (@pick lit lit $scene:ident $variant:tt [$(($strategy:ident, $s:ident))*]) => {
        $($crate::export_kernel! { lit $s $scene $variant })*
    };
    (@pick mesh mesh $scene:ident $variant:tt [$(($strategy:ident, $s:ident))*]) => {
        $($crate::export_kernel! { mesh $s $scene $variant })*
    };
    (@pick $set:ident $other:ident $scene:ident $variant:tt $strategies:tt) => {};
}
