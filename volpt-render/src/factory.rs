//! The render factory: decides which effects a scene needs and builds the monomorphised
//! [`VolumeScene`] that simulates exactly those.
//!
//! Each axis of the decision is a type parameter of the scene: constant or grid extinction, constant
//! or grid albedo, index-matched, smooth or rough boundary, isotropic or Henyey-Greenstein phase,
//! constant or lat-long environment. A backend receives the scene through [`SceneVisitor`], so one
//! generic function serves every variant.

use std::fmt;

use volpt_core::grid::{Grid, GridMapping};
use volpt_core::launch::ToParams;
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

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MediumKind {
    /// Constant extinction and albedo: delta tracking samples one exponential and reads no memory.
    Homogeneous,
    /// Extinction from a grid, one albedo for the whole medium.
    GridDensity,
    /// Extinction and RGB albedo from grids.
    GridDensityAlbedo,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BoundaryKind {
    IndexMatched,
    SmoothDielectric,
    RoughDielectric,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PhaseKind {
    Isotropic,
    HenyeyGreenstein,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EnvironmentKind {
    /// The same radiance from every direction: no lookup.
    Constant,
    /// A latitude-longitude map, bilinearly interpolated.
    LatLong,
}

/// The monomorphised variant a scene renders with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Variant {
    pub medium: MediumKind,
    pub boundary: BoundaryKind,
    pub phase: PhaseKind,
    pub environment: EnvironmentKind,
}

impl Variant {
    pub fn of(desc: &SceneDescription) -> Self {
        let medium = match (&desc.medium.density, &desc.medium.albedo) {
            (DensityDesc::Constant(_), AlbedoDesc::Constant(_)) => MediumKind::Homogeneous,
            (DensityDesc::Grid(_), AlbedoDesc::Constant(_)) => MediumKind::GridDensity,
            // A constant extinction under an albedo grid is rare; it becomes a one-voxel density grid.
            (_, AlbedoDesc::Grid(_)) => MediumKind::GridDensityAlbedo,
        };
        let boundary = match desc.boundary.bsdf {
            BsdfDesc::Null => BoundaryKind::IndexMatched,
            BsdfDesc::Dielectric { .. } => BoundaryKind::SmoothDielectric,
            BsdfDesc::RoughDielectric { .. } => BoundaryKind::RoughDielectric,
        };
        let phase = match desc.medium.phase {
            PhaseDesc::Isotropic => PhaseKind::Isotropic,
            PhaseDesc::HenyeyGreenstein { .. } => PhaseKind::HenyeyGreenstein,
        };
        let environment = match desc.environment {
            EnvironmentDesc::Constant(_) => EnvironmentKind::Constant,
            EnvironmentDesc::LatLong(_) => EnvironmentKind::LatLong,
        };
        Self {
            medium,
            boundary,
            phase,
            environment,
        }
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let medium = match self.medium {
            MediumKind::Homogeneous => "homogeneous",
            MediumKind::GridDensity => "grid-density",
            MediumKind::GridDensityAlbedo => "grid-density-albedo",
        };
        let boundary = match self.boundary {
            BoundaryKind::IndexMatched => "index-matched",
            BoundaryKind::SmoothDielectric => "smooth-dielectric",
            BoundaryKind::RoughDielectric => "rough-dielectric",
        };
        let phase = match self.phase {
            PhaseKind::Isotropic => "isotropic",
            PhaseKind::HenyeyGreenstein => "hg",
        };
        write!(f, "{medium}/{boundary}/{phase}")?;
        // Only the lat-long map is named, so that the names of constant-environment variants (and
        // the GPU kernels derived from them) stay what they were before environment maps existed.
        match self.environment {
            EnvironmentKind::Constant => Ok(()),
            EnvironmentKind::LatLong => f.write_str("/envmap"),
        }
    }
}

/// A computation over a render-ready scene of any variant.
pub trait SceneVisitor {
    type Output;
    /// `ToParams` lets a GPU backend ship the very same scene to its kernels.
    fn visit<S: Scene + Sync + ToParams>(self, scene: &S) -> Self::Output;
}

/// Builds the scene that `desc` describes, with `settings` for the integrator, and hands it to
/// `visitor`. The scene borrows its grids from `desc`.
pub fn with_scene<V: SceneVisitor>(
    desc: &SceneDescription,
    settings: PathSettings,
    visitor: V,
) -> V::Output {
    match &desc.environment {
        EnvironmentDesc::Constant(rgb) => {
            let constant = ConstantEnvironment(Spectrum::from_array(*rgb));
            with_medium(desc, Parts::new(desc, settings, constant), visitor)
        }
        EnvironmentDesc::LatLong(map) => {
            with_medium(desc, Parts::new(desc, settings, lat_long(map)), visitor)
        }
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

fn with_medium<E, V>(desc: &SceneDescription, parts: Parts<E>, visitor: V) -> V::Output
where
    E: volpt_core::Environment + Sync + ToParams,
    V: SceneVisitor,
{
    let medium = &desc.medium;
    let one_voxel;
    let density_grid = match &medium.density {
        DensityDesc::Grid(grid) => grid,
        DensityDesc::Constant(sigma) => {
            one_voxel = GridDesc {
                resolution: [1, 1, 1],
                channels: 1,
                bounds: desc.boundary.bounds,
                convention: GridConvention::Cell,
                data: vec![*sigma],
            };
            &one_voxel
        }
    };
    match Variant::of(desc).medium {
        MediumKind::Homogeneous => {
            let (DensityDesc::Constant(density), AlbedoDesc::Constant(albedo)) =
                (&medium.density, &medium.albedo)
            else {
                unreachable!("Variant::of classified this medium as homogeneous")
            };
            let m = HomogeneousMedium {
                sigma_t: medium.scale * density,
                albedo: Spectrum::from_array(*albedo),
            };
            with_boundary(desc, parts, m, visitor)
        }
        MediumKind::GridDensity => {
            let AlbedoDesc::Constant(albedo) = &medium.albedo else {
                unreachable!("Variant::of classified this albedo as constant")
            };
            let m = grid_medium(
                density_grid,
                medium.scale,
                ConstantAlbedo(Spectrum::from_array(*albedo)),
            );
            with_boundary(desc, parts, m, visitor)
        }
        MediumKind::GridDensityAlbedo => {
            let AlbedoDesc::Grid(albedo) = &medium.albedo else {
                unreachable!("Variant::of classified this albedo as a grid")
            };
            let m = grid_medium(density_grid, medium.scale, GridAlbedo(grid::<3>(albedo)));
            with_boundary(desc, parts, m, visitor)
        }
    }
}

/// The parts every variant shares, and the environment, chosen first.
struct Parts<E> {
    camera: PerspectiveCamera,
    bounds: Aabb,
    settings: PathSettings,
    environment: E,
}

impl<E> Parts<E> {
    fn new(desc: &SceneDescription, settings: PathSettings, environment: E) -> Self {
        Self {
            camera: camera(&desc.camera, &desc.film),
            bounds: aabb(&desc.boundary.bounds),
            settings,
            environment,
        }
    }
}

fn with_boundary<E, M, V>(
    desc: &SceneDescription,
    parts: Parts<E>,
    medium: M,
    visitor: V,
) -> V::Output
where
    E: volpt_core::Environment + Sync + ToParams,
    M: volpt_core::Medium + Sync + ToParams,
    V: SceneVisitor,
{
    match desc.boundary.bsdf {
        BsdfDesc::Null => with_phase(desc, parts, medium, NullBoundary, visitor),
        BsdfDesc::Dielectric { int_ior, ext_ior } => {
            let b = SmoothDielectric {
                eta: int_ior / ext_ior,
            };
            with_phase(desc, parts, medium, b, visitor)
        }
        BsdfDesc::RoughDielectric {
            alpha,
            int_ior,
            ext_ior,
        } => {
            let b = RoughDielectric {
                eta: int_ior / ext_ior,
                distribution: Ggx { alpha },
            };
            with_phase(desc, parts, medium, b, visitor)
        }
    }
}

fn with_phase<E, M, B, V>(
    desc: &SceneDescription,
    parts: Parts<E>,
    medium: M,
    boundary: B,
    visitor: V,
) -> V::Output
where
    E: volpt_core::Environment + Sync + ToParams,
    M: volpt_core::Medium + Sync + ToParams,
    B: volpt_core::Bsdf + Sync + ToParams,
    V: SceneVisitor,
{
    match desc.medium.phase {
        PhaseDesc::Isotropic => visitor.visit(&assemble(parts, medium, boundary, Isotropic)),
        PhaseDesc::HenyeyGreenstein { g } => {
            visitor.visit(&assemble(parts, medium, boundary, HenyeyGreenstein { g }))
        }
    }
}

fn assemble<E, M, B, P>(
    parts: Parts<E>,
    medium: M,
    boundary: B,
    phase: P,
) -> VolumeScene<M, B, P, E> {
    VolumeScene {
        camera: parts.camera,
        bounds: parts.bounds,
        medium,
        boundary,
        phase,
        environment: parts.environment,
        settings: parts.settings,
    }
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

fn grid_medium<A>(density: &GridDesc, scale: f32, albedo: A) -> GridMedium<'_, A> {
    GridMedium {
        density: grid::<1>(density),
        scale,
        majorant: scale * density.max_value(),
        albedo,
    }
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
