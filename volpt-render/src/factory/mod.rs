//! The render factory: decides which effects a scene needs and builds the monomorphised
//! [`VolumeScene`] that simulates exactly those.
//!
//! Each axis of the decision is a type parameter of the scene: constant or grid extinction, constant
//! or grid albedo, index-matched, smooth or rough boundary, isotropic or Henyey-Greenstein phase,
//! constant or lat-long environment. The axes and their values are the variant registry's
//! ([`volpt_core::variant`]): from it this module generates one enum per axis ([`MediumPart`], ...,
//! holding the built part) and the one exhaustive `match` that turns four built parts into a scene
//! type. The description is read once, by one function per axis ([`Parts::of`]); a backend receives
//! the scene through [`SceneVisitor`], so one generic function serves every variant.
//!
//! - this file: the axis enums, the dispatch, [`Parts`] and what is derived from them;
//! - [`parts`]: one function per axis from the description to a part, with the [`Simplification`]
//!   rules;
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
pub use parts::Simplification;
pub use settings::{default_estimator, path_settings};

use parts::{aabb, boundary, environment, general_medium, lat_long, medium, phase};

use std::fmt;

use std::sync::Arc;
use volpt_core::abi::SceneAbi;
use volpt_core::grid::{
    AnyLayout, DenseTrilinear, Grid, GridLookup, GridMapping, GridReads, TexelFormat,
    TextureTrilinear,
};

use volpt_core::majorant::MajorantGrid;
use volpt_core::math::tan;
use volpt_core::microfacet::Ggx;
use volpt_core::path::Estimator;
use volpt_core::{
    Aabb, ConstantAlbedo, ConstantEnvironment, GridAlbedo, GridMedium, HenyeyGreenstein,
    HomogeneousMedium, Isotropic, LatLongEnvironment, LatLongRows, NullBoundary, PathSettings,
    PerspectiveCamera, RoughDielectric, Scene, SmoothDielectric, Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_scene::description::{
    AlbedoDesc, Bounds, BsdfDesc, CameraDesc, DensityDesc, EnvironmentDesc, FilmDesc, FovAxis,
    GridConvention, GridDesc, GridLookup as GridLookupDesc, GridStorage, LatLongDesc, MediumDesc,
    PhaseDesc, SampleLayout, SceneDescription,
};

/// What a backend can render: the CPU needs a [`Scene`] it can share between threads, a GPU backend
/// also ships it to its kernels through the device ABI.
pub trait RenderScene: Scene + Sync + SceneAbi {}

impl<S: Scene + Sync + SceneAbi> RenderScene for S {}

/// A computation over a render-ready scene of any variant.
pub trait SceneVisitor {
    type Output;
    fn visit<S: RenderScene>(self, scene: &S) -> Self::Output;
}

/// One axis: the enum of its built parts and the enum of its kinds (the part without its data).
/// Axes whose parts borrow grids or maps from the description take its lifetime `'a`.
macro_rules! axis {
    ($(#[$doc:meta])* $part:ident $(<$lt:lifetime>)?, $kind:ident,
     [$(($camel:ident, $snake:ident, $ty:ty))*]) => {
        $(#[$doc])*
        pub enum $part $(<$lt>)? {
            $($camel($ty),)*
        }

        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum $kind {
            $($camel,)*
        }

        impl $(<$lt>)? $part $(<$lt>)? {
            pub fn kind(&self) -> $kind {
                match self {
                    $($part::$camel(_) => $kind::$camel,)*
                }
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

/// The axis enums and the dispatch from built parts to a scene type, from the variant registry.
macro_rules! factory {
    (axes {
        medium $media:tt boundary $boundaries:tt phase $phases:tt environment $environments:tt
    }
     variants [$([($M:ident, $m:ident, $mt:ty) ($B:ident, $b:ident, $bt:ty)
        ($P:ident, $p:ident, $pt:ty) ($E:ident, $e:ident, $et:ty)])*]) => {
        axis!(
            /// The medium: extinction and albedo.
            MediumPart<'a>, MediumKind, $media
        );
        axis!(
            /// The boundary of the medium's box.
            BoundaryPart, BoundaryKind, $boundaries
        );
        axis!(
            /// The phase function.
            PhasePart, PhaseKind, $phases
        );
        axis!(
            /// The light: the environment.
            EnvironmentPart<'a>, EnvironmentKind, $environments
        );

        /// Hands the scene made of `shared` and `parts` to `visitor`, monomorphised for its variant.
        fn dispatch<V: SceneVisitor>(shared: Shared, parts: Parts<'_>, visitor: V) -> V::Output {
            match (parts.medium, parts.boundary, parts.phase, parts.environment) {
                $((
                    MediumPart::$M(medium),
                    BoundaryPart::$B(boundary),
                    PhasePart::$P(phase),
                    EnvironmentPart::$E(environment),
                ) => visitor.visit(&VolumeScene {
                    camera: shared.camera,
                    bounds: shared.bounds,
                    settings: shared.settings,
                    medium,
                    boundary,
                    phase,
                    environment,
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
        let (medium, boundary, phase, environment) = match effects {
            Effects::Specialised => (
                medium(desc, cache, &mut fired),
                boundary(desc, &mut fired),
                phase(&desc.medium.phase, &mut fired),
                environment(&desc.environment),
            ),
            Effects::General => (
                general_medium(desc),
                boundary(desc, &mut |_| ()),
                PhasePart::HenyeyGreenstein(match desc.medium.phase {
                    PhaseDesc::Isotropic => HenyeyGreenstein { g: 0.0 },
                    PhaseDesc::HenyeyGreenstein { g } => HenyeyGreenstein { g },
                }),
                EnvironmentPart::LatLong(match &desc.environment {
                    EnvironmentDesc::Constant(rgb) => LatLongEnvironment::new(
                        rgb,
                        1,
                        1,
                        LatLongRows::CellCentred,
                        [Vec3::X, Vec3::Y, Vec3::Z],
                        1.0,
                    ),
                    EnvironmentDesc::LatLong(map) => lat_long(map),
                }),
            ),
        };
        Self {
            medium,
            boundary,
            phase,
            environment,
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

/// The parts every variant shares.
struct Shared {
    camera: PerspectiveCamera,
    bounds: Aabb,
    settings: PathSettings,
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
        bounds: aabb(&desc.boundary.bounds),
        settings,
    };
    let parts = Parts::of_cached(desc, effects, cache);
    let derived = Derived::of_cached(&parts, shared.bounds, &settings, cache);
    dispatch(shared, parts.with(&derived), visitor)
}

/// What the factory computes from the built parts for the integrator: the majorant grid of a grid
/// medium and the sampling distribution of a lat-long map. Neither changes the variant.
pub struct Derived {
    /// Per-cell majorants and the grid's resolution, if the medium tracks with a grid.
    majorants: Option<Arc<Majorants>>,
    bounds: Aabb,
    /// The lat-long map's sampling distribution, for next-event estimation.
    distribution: Vec<f32>,
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
        let density = match &parts.medium {
            MediumPart::Homogeneous(_) => None,
            MediumPart::GridDensity(m) => Some((m.density, m.scale)),
            MediumPart::GridDensityAlbedo(m) => Some((m.density, m.scale)),
            MediumPart::GridAnyLayout(m) => Some((m.density, m.scale)),
            MediumPart::GridTexture(m) => Some((m.density, m.scale)),
        };
        let majorants = density
            .filter(|_| settings.majorant_resolution > 1)
            .map(|(density, scale)| {
                let res = MajorantGrid::resolution_for(bounds, settings.majorant_resolution);
                cache.majorants(&density, scale, bounds, res)
            })
            // A grid whose every cell has the global bound (a uniform density, as ad's) saves no
            // step and costs the walk: track with the global majorant.
            .filter(|m| {
                let global = m.data.iter().copied().fold(0.0, f32::max);
                m.data.iter().any(|&v| v < global)
            });
        let distribution = match &parts.environment {
            EnvironmentPart::LatLong(map) if settings.estimator == Estimator::NextEvent => {
                let mut data =
                    vec![0.0; LatLongEnvironment::distribution_len(map.width, map.height)];
                map.fill_distribution(&mut data);
                data
            }
            _ => Vec::new(),
        };
        Self {
            majorants,
            bounds,
            distribution,
        }
    }

    /// The majorant grid's resolution, if the medium tracks with one.
    pub fn majorant_resolution(&self) -> Option<[u32; 3]> {
        self.majorants.as_ref().map(|m| m.res)
    }
}

impl<'a> Parts<'a> {
    /// These parts with `derived`'s majorant grid and sampling distribution.
    pub fn with(mut self, derived: &'a Derived) -> Self {
        let grid = derived
            .majorants
            .as_ref()
            .map(|m| MajorantGrid::new(&m.data, m.res, derived.bounds));
        match &mut self.medium {
            MediumPart::Homogeneous(_) => {}
            MediumPart::GridDensity(m) => m.majorants = grid,
            MediumPart::GridDensityAlbedo(m) => m.majorants = grid,
            MediumPart::GridAnyLayout(m) => m.majorants = grid,
            MediumPart::GridTexture(m) => m.majorants = grid,
        }
        if let EnvironmentPart::LatLong(map) = &mut self.environment {
            map.distribution = &derived.distribution;
        }
        self
    }
}
