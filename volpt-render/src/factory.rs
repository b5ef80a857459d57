//! The render factory: decides which effects a scene needs and builds the monomorphised
//! [`VolumeScene`] that simulates exactly those.
//!
//! Each axis of the decision is a type parameter of the scene: constant or grid extinction, constant
//! or grid albedo, index-matched, smooth or rough boundary, isotropic or Henyey-Greenstein phase,
//! constant or lat-long environment. A backend receives the scene through [`SceneVisitor`], so one
//! generic function serves every variant.

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

use std::fmt;

use volpt_core::abi::SceneAbi;
use volpt_core::grid::{Grid, GridMapping};
use volpt_core::math::tan;
use volpt_core::microfacet::Ggx;
use volpt_core::{
    Aabb, ConstantAlbedo, ConstantEnvironment, GridAlbedo, GridMedium, HenyeyGreenstein,
    HomogeneousMedium, Isotropic, LatLongEnvironment, LatLongRows, NullBoundary, PathSettings,
    PerspectiveCamera, RoughDielectric, Scene, SmoothDielectric, Spectrum, Vec2, Vec3, VolumeScene,
};
use volpt_scene::description::{
    AlbedoDesc, Bounds, BsdfDesc, CameraDesc, DensityDesc, EnvironmentDesc, FilmDesc, FovAxis,
    GridConvention, GridDesc, LatLongDesc, PhaseDesc, SceneDescription,
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
    pub fn of(desc: &SceneDescription) -> Self {
        Parts::of(desc).variant()
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

/// The four variant parts of a scene, built from its description.
pub struct Parts<'a> {
    pub medium: MediumPart<'a>,
    pub boundary: BoundaryPart,
    pub phase: PhasePart,
    pub environment: EnvironmentPart<'a>,
}

impl<'a> Parts<'a> {
    /// Reads each axis of the description once; the parts borrow their grids from `desc`.
    pub fn of(desc: &'a SceneDescription) -> Self {
        Self {
            medium: medium(desc),
            boundary: boundary(&desc.boundary.bsdf),
            phase: phase(&desc.medium.phase),
            environment: environment(&desc.environment),
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

/// Builds the scene that `desc` describes, with `settings` for the integrator, and hands it to
/// `visitor`. The scene borrows its grids from `desc`.
pub fn with_scene<V: SceneVisitor>(
    desc: &SceneDescription,
    settings: PathSettings,
    visitor: V,
) -> V::Output {
    let shared = Shared {
        camera: camera(&desc.camera, &desc.film),
        bounds: aabb(&desc.boundary.bounds),
        settings,
    };
    dispatch(shared, Parts::of(desc), visitor)
}

fn medium(desc: &SceneDescription) -> MediumPart<'_> {
    let medium = &desc.medium;
    match (&medium.density, &medium.albedo) {
        (DensityDesc::Constant(density), AlbedoDesc::Constant(albedo)) => {
            MediumPart::Homogeneous(HomogeneousMedium {
                sigma_t: medium.scale * density,
                albedo: Spectrum::from_array(*albedo),
            })
        }
        (DensityDesc::Grid(density), AlbedoDesc::Constant(albedo)) => {
            MediumPart::GridDensity(GridMedium {
                density: grid::<1>(density),
                scale: medium.scale,
                majorant: medium.scale * density.max_value(),
                albedo: ConstantAlbedo(Spectrum::from_array(*albedo)),
            })
        }
        (density, AlbedoDesc::Grid(albedo)) => {
            let density = match density {
                DensityDesc::Grid(density) => grid::<1>(density),
                // A constant extinction under an albedo grid is rare: it becomes a one-voxel grid
                // over the medium's box.
                DensityDesc::Constant(sigma) => {
                    let bounds = aabb(&desc.boundary.bounds);
                    let mapping = GridMapping::cell_centred(bounds, [1, 1, 1]);
                    Grid::new(std::slice::from_ref(sigma), [1, 1, 1], mapping)
                }
            };
            let max_density = density.data.iter().copied().fold(0.0, f32::max);
            MediumPart::GridDensityAlbedo(GridMedium {
                density,
                scale: medium.scale,
                majorant: medium.scale * max_density,
                albedo: GridAlbedo(grid::<3>(albedo)),
            })
        }
    }
}

fn boundary(bsdf: &BsdfDesc) -> BoundaryPart {
    match *bsdf {
        BsdfDesc::Null => BoundaryPart::IndexMatched(NullBoundary),
        BsdfDesc::Dielectric { int_ior, ext_ior } => {
            BoundaryPart::SmoothDielectric(SmoothDielectric {
                eta: int_ior / ext_ior,
            })
        }
        BsdfDesc::RoughDielectric {
            alpha,
            int_ior,
            ext_ior,
        } => BoundaryPart::RoughDielectric(RoughDielectric {
            eta: int_ior / ext_ior,
            distribution: Ggx { alpha },
        }),
    }
}

fn phase(phase: &PhaseDesc) -> PhasePart {
    match *phase {
        PhaseDesc::Isotropic => PhasePart::Isotropic(Isotropic),
        PhaseDesc::HenyeyGreenstein { g } => PhasePart::HenyeyGreenstein(HenyeyGreenstein { g }),
    }
}

fn environment(environment: &EnvironmentDesc) -> EnvironmentPart<'_> {
    match environment {
        EnvironmentDesc::Constant(rgb) => {
            EnvironmentPart::Constant(ConstantEnvironment(Spectrum::from_array(*rgb)))
        }
        EnvironmentDesc::LatLong(map) => EnvironmentPart::LatLong(lat_long(map)),
    }
}

/// The map's world-to-map rotation is the transpose of its `to_world`'s linear part (a rotation,
/// as the loader checks); the translation does not matter for light from infinitely far away.
fn lat_long(map: &LatLongDesc) -> LatLongEnvironment<'_> {
    let m = map.to_world;
    let column = |j: usize| Vec3::new(m[0][j], m[1][j], m[2][j]);
    let rows = match map.rows {
        volpt_scene::description::LatLongRows::CellCentred => LatLongRows::CellCentred,
        volpt_scene::description::LatLongRows::PoleToPole => LatLongRows::PoleToPole,
    };
    LatLongEnvironment::new(
        &map.rgb,
        map.width,
        map.height,
        rows,
        [column(0), column(1), column(2)],
        map.scale,
    )
}

fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}

fn grid<const C: usize>(g: &GridDesc) -> Grid<'_, C> {
    let bounds = aabb(&g.bounds);
    let mapping = match g.convention {
        GridConvention::Vertex => GridMapping::vertex_centred(bounds, g.resolution),
        GridConvention::Cell => GridMapping::cell_centred(bounds, g.resolution),
    };
    Grid::new(&g.data, g.resolution, mapping)
}

/// Mitsuba's perspective camera: the field of view spans `fov_axis`, the other axis follows from the
/// film's aspect ratio.
pub fn camera(desc: &CameraDesc, film: &FilmDesc) -> PerspectiveCamera {
    let m = desc.to_world;
    let column = |j: usize| Vec3::new(m[0][j], m[1][j], m[2][j]);
    let (w, h) = (film.width as f32, film.height as f32);
    let tan_half = tan(0.5 * desc.fov_degrees.to_radians());
    let along_x = Vec2::new(tan_half, tan_half * h / w);
    let along_y = Vec2::new(tan_half * w / h, tan_half);
    let tan_half_fov = match desc.fov_axis {
        FovAxis::X => along_x,
        FovAxis::Y => along_y,
        FovAxis::Smaller if w <= h => along_x,
        FovAxis::Smaller => along_y,
        FovAxis::Larger if w >= h => along_x,
        FovAxis::Larger => along_y,
        FovAxis::Diagonal => {
            let diagonal = (w * w + h * h).sqrt();
            Vec2::new(tan_half * w / diagonal, tan_half * h / diagonal)
        }
    };
    PerspectiveCamera {
        origin: column(3),
        axis_x: column(0),
        axis_y: column(1),
        axis_z: column(2),
        tan_half_fov,
        width: film.width,
        height: film.height,
    }
}

/// The integrator settings a scene file asks for.
pub fn path_settings(desc: &SceneDescription) -> PathSettings {
    PathSettings {
        max_depth: desc.integrator.max_depth.unwrap_or(PathSettings::UNLIMITED),
        rr_depth: desc.integrator.rr_depth.unwrap_or(PathSettings::UNLIMITED),
        ..PathSettings::default()
    }
}
