//! The render factory: decides which effects a scene needs and builds the monomorphised
//! [`VolumeScene`] that simulates exactly those.
//!
//! Each axis of the decision is a type parameter of the scene: constant or grid extinction, constant
//! or grid albedo, index-matched, smooth or rough boundary, isotropic or Henyey-Greenstein phase,
//! constant or lat-long environment. The axes and their values are the variant registry's
//! ([`volpt_core::variant`]): from it this module generates one enum per axis ([`MediumPart`], ...,
//! holding the built part), the choice of each axis's part (the first in registry order whose
//! rule represents the description: [`FromDescription`], in `volpt-scene`'s axis files) and the one
//! exhaustive `match` that turns four built parts into a scene type. Nothing here names a part: a registry line and the part's rule are all a new part
//! needs. A backend receives the scene through [`SceneVisitor`], so one generic function serves
//! every variant.
//!
//! - this file: the axis enums, the choice and the dispatch, [`Parts`] and what is derived from
//!   them;
//! - [`parts`]: what the media's rules read, with what the cache knows of the grids;
//! - [`cache`]: what the factory reads from a scene's grids, kept between builds of one scene
//!   ([`FactoryCache`]);
//! - [`camera`](camera()) and [`path_settings`]: the camera and integrator settings a file asks for;
//! - [`majorant_choice`]: the cost model that picks a global majorant or a majorant grid.

mod cache;
mod camera;
pub mod majorant_choice;
pub mod parts;
mod settings;

pub use cache::{FactoryCache, Majorants};
pub use camera::camera;
pub use majorant_choice::{
    default_majorants, tracking_cost, MajorantChoice, MajorantRule, TrackingCost,
};
pub use parts::{medium_input, MediumInput, ReadsRule};
pub use settings::{default_estimator, path_settings};
pub use volpt_scene::{FromDescription, Simplification};

use parts::aabb;
use volpt_core::{SampledEnvironment, TrackedMedium};
use volpt_scene::BoundaryInput;

use std::fmt;

use std::sync::Arc;
use volpt_core::abi::SceneAbi;
use volpt_core::grid::Grid;

use volpt_core::chromatic::build_channel_majorants;
use volpt_core::majorant::MajorantGrid;
use volpt_core::material::build_material_channel_majorants;
use volpt_core::math::tan;
use volpt_core::path::Estimator;
use volpt_core::{
    Aabb, BoundaryShape, PathSettings, PerspectiveCamera, Scene, Shape, Vec2, Vec3, VolumeScene,
};
use volpt_scene::description::{
    Bounds, BsdfDesc, CameraDesc, EnvironmentDesc, FilmDesc, FovAxis, PhaseDesc, Projection,
    SceneDescription,
};

/// What a backend can render: the CPU needs a [`Scene`] it can share between threads, a GPU backend
/// also ships it to its kernels through the device ABI.
pub trait RenderScene: Scene + Sync + SceneAbi<Kernel: Sync> {}

impl<S: Scene + Sync + SceneAbi<Kernel: Sync>> RenderScene for S {}

/// A computation over a render-ready scene of any variant.
pub trait SceneVisitor {
    type Output;
    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output;
}

/// One axis: the enum of its built parts, the enum of its kinds (the part without its data), and
/// the choice of its part for a description: the first part of the registry's order whose
/// `$rule` ([`FromDescription`]) accepts. Axes whose parts borrow grids or maps from the
/// description take its lifetime `'a`.
macro_rules! axis {
    ($(#[$doc:meta])* $part:ident $(<$lt:lifetime>)?, $kind:ident, $input:ty, $rule:ident,
     [$(($camel:ident, $snake:ident, $ty:ty))*]) => {
        $(#[$doc])*
        // One built part per render, moved into the scene it renders: the chromatic medium's
        // grids and tables make its variant the largest, which costs nothing here.
        #[allow(clippy::large_enum_variant)]
        pub enum $part $(<$lt>)? {
            $($camel($ty),)*
        }

        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $kind {
            $($camel,)*
        }

        impl<'a> $part $(<$lt>)? {
            pub fn kind(&self) -> $kind {
                match self {
                    $($part::$camel(_) => $kind::$camel,)*
                }
            }

            /// The first part of the axis, in registry order, that represents `input` (its
            /// general form for [`Effects::General`]).
            ///
            /// # Panics
            /// If no part does: the registry's axis then leaves a description unrendered, which
            /// the device-ABI test's descriptions find.
            fn choose(
                input: &$input,
                effects: Effects,
                fired: &mut dyn FnMut(Simplification),
            ) -> Self {
                $(
                    let part = match effects {
                        Effects::Specialised => <$ty as $rule<'a>>::specialised(input, fired),
                        Effects::General => <$ty as $rule<'a>>::general(input),
                    };
                    if let Some(part) = part {
                        return $part::$camel(part);
                    }
                )*
                panic!(concat!("no part of the registry's ", stringify!($kind), " axis represents the description"))
            }
        }

        impl $kind {
            /// The part's name, as in kernel entry points.
            pub fn name(self) -> &'static str {
                match self {
                    $($kind::$camel => stringify!($snake),)*
                }
            }
        }
    };
}

/// The axis enums, what the factory derives from their parts, and the dispatch from built parts to
/// a scene type, from the variant registry.
macro_rules! factory {
    (axes {
        medium [$(($Mv:ident, $mv:ident, $mvt:ty))*]
        boundary [$(($Bv:ident, $bv:ident, $bvt:ty))*]
        phase $phases:tt
        environment [$(($Ev:ident, $ev:ident, $evt:ty))*]
    }
     variants [$([($M:ident, $m:ident, $mt:ty) ($B:ident, $b:ident, $bt:ty)
        ($P:ident, $p:ident, $pt:ty) ($E:ident, $e:ident, $et:ty)])*]) => {
        axis!(
            /// The medium: extinction and albedo.
            MediumPart<'a>, MediumKind, MediumInput<'a>, FromDescription, [$(($Mv, $mv, $mvt))*]
        );
        axis!(
            /// The boundary of the medium's box.
            BoundaryPart, BoundaryKind, BoundaryInput, FromDescription, [$(($Bv, $bv, $bvt))*]
        );
        axis!(
            /// The phase function.
            PhasePart, PhaseKind, PhaseDesc, FromDescription, $phases
        );
        axis!(
            /// The light: the environment.
            EnvironmentPart<'a>, EnvironmentKind, &'a EnvironmentDesc, FromDescription,
            [$(($Ev, $ev, $evt))*]
        );

        impl<'a> TrackedMedium<'a> for MediumPart<'a> {
            fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
                match self {
                    $(MediumPart::$Mv(m) => m.density(),)*
                }
            }

            fn channel_densities(&self) -> Option<(Grid<'a, 3>, volpt_core::Spectrum)> {
                match self {
                    $(MediumPart::$Mv(m) => m.channel_densities(),)*
                }
            }

            fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
                match self {
                    $(MediumPart::$Mv(m) => m.track_with(grid),)*
                }
            }

            fn track_channels_with(&mut self, channels: Option<&'a [f32]>) {
                match self {
                    $(MediumPart::$Mv(m) => m.track_channels_with(channels),)*
                }
            }

            fn materials(&self) -> Option<volpt_core::MaterialGrid<'a>> {
                match self {
                    $(MediumPart::$Mv(m) => m.materials(),)*
                }
            }
        }

        // The parts' types borrow for `'a`; what they say of themselves holds for every `'a`.
        impl<'a> MediumKind {
            /// The extinction is the same everywhere ([`volpt_core::Medium::HOMOGENEOUS`]).
            pub fn homogeneous(self) -> bool {
                match self {
                    $(MediumKind::$Mv => <$mvt as volpt_core::Medium>::HOMOGENEOUS,)*
                }
            }
        }

        impl BoundaryKind {
            /// Crossing the boundary changes nothing ([`volpt_core::Bsdf::IS_NULL`]).
            pub fn index_matched(self) -> bool {
                match self {
                    $(BoundaryKind::$Bv => <$bvt as volpt_core::Bsdf>::IS_NULL,)*
                }
            }

            /// The boundary's BSDF has no delta lobe, so paths can sample the environment where they
            /// meet it ([`volpt_core::Bsdf::IS_ROUGH`]).
            pub fn rough(self) -> bool {
                match self {
                    $(BoundaryKind::$Bv => <$bvt as volpt_core::Bsdf>::IS_ROUGH,)*
                }
            }
        }

        impl<'a> SampledEnvironment<'a> for EnvironmentPart<'a> {
            fn distribution_size(&self) -> usize {
                match self {
                    $(EnvironmentPart::$Ev(e) => e.distribution_size(),)*
                }
            }

            fn write_distribution(&self, out: &mut [f32]) {
                match self {
                    $(EnvironmentPart::$Ev(e) => e.write_distribution(out),)*
                }
            }

            fn sample_from(&mut self, distribution: &'a [f32]) {
                match self {
                    $(EnvironmentPart::$Ev(e) => e.sample_from(distribution),)*
                }
            }
        }

        /// Hands the scene made of `shared` and `parts` to `visitor`, monomorphised for its variant.
        fn dispatch<V: SceneVisitor>(shared: Shared<'_>, parts: Parts<'_>, visitor: V) -> V::Output {
            match (parts.medium, parts.boundary, parts.phase, parts.environment) {
                $((
                    MediumPart::$M(medium),
                    BoundaryPart::$B(boundary),
                    PhasePart::$P(phase),
                    EnvironmentPart::$E(environment),
                ) => visitor.visit(&VolumeScene {
                    camera: shared.camera,
                    bounds: shared.shape,
                    settings: shared.settings,
                    medium,
                    boundary,
                    phase,
                    environment,
                    lights: shared.lights,
                }),)*
            }
        }
    };
}

volpt_core::variants!('a => factory {});

/// The monomorphised variant a scene renders with: one kind per axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variant {
    pub medium: MediumKind,
    pub boundary: BoundaryKind,
    pub phase: PhaseKind,
    pub environment: EnvironmentKind,
}

impl Variant {
    /// The variant the factory picks for `desc` (specialised).
    pub fn of(desc: &SceneDescription) -> Self {
        Parts::of(desc, Effects::Specialised).variant()
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}/{}/{}/{}",
            self.medium.name(),
            self.boundary.name(),
            self.phase.name(),
            self.environment.name()
        )
    }
}

/// How the factory chooses parts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub enum Effects {
    /// Simulate only the effects the scene calls for: a value that makes an effect trivial selects
    /// the simpler part ([`Simplification`]).
    #[default]
    Specialised,
    /// The most general part of every axis that represents the scene exactly: grid density and
    /// albedo, Henyey-Greenstein, a lat-long map. The boundary stays as described: no other boundary
    /// equals an index-matched or a smooth one exactly. For measuring what specialisation saves.
    General,
}

/// The four variant parts of a scene, built from its description.
pub struct Parts<'a> {
    pub medium: MediumPart<'a>,
    pub boundary: BoundaryPart,
    pub phase: PhasePart,
    pub environment: EnvironmentPart<'a>,
    /// The rules that made a part simpler than the description names, in axis order.
    pub simplifications: Vec<Simplification>,
}

impl<'a> Parts<'a> {
    /// Reads each axis of the description once; the parts borrow their grids from `desc`.
    pub fn of(desc: &'a SceneDescription, effects: Effects) -> Self {
        Self::of_cached(desc, effects, &FactoryCache::new())
    }

    /// [`Parts::of`], with what `cache` knows of `desc`'s grids.
    pub fn of_cached(desc: &'a SceneDescription, effects: Effects, cache: &FactoryCache) -> Self {
        let mut simplifications = Vec::new();
        let mut fired = |rule| simplifications.push(rule);
        let medium = medium_input(desc, effects, cache, &mut fired);
        Self {
            medium: MediumPart::choose(&medium, effects, &mut fired),
            boundary: BoundaryPart::choose(&BoundaryInput::of(desc), effects, &mut fired),
            phase: PhasePart::choose(&desc.medium.phase, effects, &mut fired),
            environment: EnvironmentPart::choose(&&desc.environment, effects, &mut fired),
            simplifications,
        }
    }

    pub fn variant(&self) -> Variant {
        Variant {
            medium: self.medium.kind(),
            boundary: self.boundary.kind(),
            phase: self.phase.kind(),
            environment: self.environment.kind(),
        }
    }
}

/// The parts every variant shares. The boundary's geometry is chosen at run time, box or mesh
/// ([`BoundaryShape`]): a second scene type per variant would double every backend's code.
struct Shared<'a> {
    camera: PerspectiveCamera,
    shape: BoundaryShape<'a>,
    settings: PathSettings,
    /// The lights besides the environment: a run-time part of every variant.
    lights: volpt_core::Lights,
}

/// The boundary's geometry `desc` describes, borrowing its mesh.
pub fn boundary_shape(desc: &SceneDescription) -> BoundaryShape<'_> {
    match &desc.boundary.mesh {
        Some(mesh) => BoundaryShape::Mesh(mesh.buffers.mesh()),
        None => BoundaryShape::Box(aabb(&desc.boundary.bounds)),
    }
}

/// Builds the scene that `desc` describes, with `settings` for the integrator, specialised to its
/// effects, and hands it to `visitor`. The scene borrows its grids from `desc`.
pub fn with_scene<V: SceneVisitor>(
    desc: &SceneDescription,
    settings: PathSettings,
    visitor: V,
) -> V::Output {
    with_scene_as(desc, settings, Effects::Specialised, visitor)
}

/// [`with_scene`], choosing parts as `effects` says.
pub fn with_scene_as<V: SceneVisitor>(
    desc: &SceneDescription,
    settings: PathSettings,
    effects: Effects,
    visitor: V,
) -> V::Output {
    with_scene_cached(desc, settings, effects, &FactoryCache::new(), visitor)
}

/// [`with_scene_as`] for a scene built again and again (its camera or parameters changed between
/// renders): what `cache` knows of its grids is not computed again.
pub fn with_scene_cached<V: SceneVisitor>(
    desc: &SceneDescription,
    settings: PathSettings,
    effects: Effects,
    cache: &FactoryCache,
    visitor: V,
) -> V::Output {
    let shared = Shared {
        camera: camera(&desc.camera, &desc.film),
        shape: boundary_shape(desc),
        settings,
        lights: desc.lights.lights(),
    };
    let parts = Parts::of_cached(desc, effects, cache);
    let derived = Derived::of_cached(&parts, shared.shape.bounds(), &settings, cache);
    dispatch(shared, parts.with(&derived), visitor)
}

/// What the factory computes from the built parts for the integrator: the majorant grid of a
/// medium with a density grid ([`TrackedMedium`]) and the sampling distribution of an environment
/// that has one ([`SampledEnvironment`]). Neither changes the variant.
pub struct Derived {
    /// Per-cell majorants and the grid's resolution, if the medium tracks with a grid.
    majorants: Option<Arc<Majorants>>,
    /// Each channel's bound per cell of `majorants` (three a cell), for a medium whose channels'
    /// bounds are not in proportion (a material-indexed volume's, a density per channel's).
    channel_majorants: Option<Vec<f32>>,
    bounds: Aabb,
    /// The environment's sampling distribution, for next-event estimation.
    distribution: Option<Vec<f32>>,
}

impl Derived {
    pub fn of(parts: &Parts<'_>, bounds: Aabb, settings: &PathSettings) -> Self {
        Self::of_cached(parts, bounds, settings, &FactoryCache::new())
    }

    /// [`Derived::of`], the majorant grid from `cache` if it holds the one these parts need.
    pub fn of_cached(
        parts: &Parts<'_>,
        bounds: Aabb,
        settings: &PathSettings,
        cache: &FactoryCache,
    ) -> Self {
        // A material-indexed volume's bounds come from its index grid, replaced between renders
        // by a printing application: built anew each time, not cached.
        // Its channels' bounds are not in proportion from cell to cell: each has its own.
        let indexed = |res: [u32; 3]| {
            parts.medium.materials().map(|grid| {
                let cells = res.iter().map(|&r| r as usize).product::<usize>();
                let mut channels = vec![0.0; 3 * cells];
                build_material_channel_majorants(&grid, bounds, res, &mut channels);
                let data = channels
                    .chunks_exact(3)
                    .map(|c| c[0].max(c[1]).max(c[2]))
                    .collect();
                (Arc::new(Majorants { data, res }), Some(channels))
            })
        };
        // A density per channel: each channel's bounds from its own samples (built anew each
        // time, as an indexed volume's).
        let per_channel = |res: [u32; 3]| {
            parts
                .medium
                .channel_densities()
                .map(|(density, extinction)| {
                    let cells = res.iter().map(|&r| r as usize).product::<usize>();
                    let (mut channels, mut data) = (vec![0.0; 3 * cells], vec![0.0; cells]);
                    let mut plane = vec![0.0; density.data.len() / 3];
                    build_channel_majorants(
                        &density,
                        extinction,
                        bounds,
                        res,
                        &mut plane,
                        &mut channels,
                        &mut data,
                    );
                    (Arc::new(Majorants { data, res }), Some(channels))
                })
        };
        let majorants = (settings.majorant_resolution > 1)
            .then(|| MajorantGrid::resolution_for(bounds, settings.majorant_resolution))
            .and_then(|res| match parts.medium.density() {
                Some((density, scale)) => {
                    Some((cache.majorants(&density, scale, bounds, res), None))
                }
                None => per_channel(res).or_else(|| indexed(res)),
            })
            // A grid whose every cell has the global bound (a uniform density, as ad's) saves no
            // step and costs the walk: track with the global majorant.
            .filter(|(m, _)| {
                let global = m.data.iter().copied().fold(0.0, f32::max);
                m.data.iter().any(|&v| v < global)
            });
        let (majorants, channel_majorants) = majorants.unzip();
        let distribution = match settings.estimator {
            Estimator::NextEvent => distribution(&parts.environment),
            Estimator::PathTracing => None,
        };
        Self {
            majorants,
            channel_majorants: channel_majorants.flatten(),
            bounds,
            distribution,
        }
    }

    /// The majorant grid's resolution, if the medium tracks with one.
    pub fn majorant_resolution(&self) -> Option<[u32; 3]> {
        self.majorants.as_ref().map(|m| m.res)
    }
}

/// The distribution next-event estimation samples `environment` from, if it has one.
fn distribution<'a>(environment: &impl SampledEnvironment<'a>) -> Option<Vec<f32>> {
    let size = environment.distribution_size();
    (size > 0).then(|| {
        let mut values = vec![0.0; size];
        environment.write_distribution(&mut values);
        values
    })
}

impl<'a> Parts<'a> {
    /// These parts with `derived`'s majorant grid and sampling distribution.
    pub fn with(mut self, derived: &'a Derived) -> Self {
        let grid = derived
            .majorants
            .as_ref()
            .map(|m| MajorantGrid::new(&m.data, m.res, derived.bounds));
        self.medium.track_with(grid);
        self.medium
            .track_channels_with(derived.channel_majorants.as_deref());
        if let Some(distribution) = &derived.distribution {
            self.environment.sample_from(distribution);
        }
        self
    }
}
