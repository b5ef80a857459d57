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
use volpt_core::grid::{
    AnyLayout, DenseTrilinear, Grid, GridLookup, GridMapping, GridReads, TexelFormat,
    TextureTrilinear,
};
use volpt_core::majorant::{build_majorants, MajorantGrid};
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
    PhaseDesc, SceneDescription,
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

/// A rule that made the factory pick a simpler part than the description names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simplification {
    /// A density grid with one value everywhere, covering the medium's box, is a constant
    /// extinction: homogeneous with a constant albedo, a one-voxel density grid beside an albedo grid.
    ConstantDensityGrid,
    /// An albedo grid with one value everywhere, covering the medium's box, is a constant albedo.
    ConstantAlbedoGrid,
    /// Henyey-Greenstein with g = 0 is isotropic.
    ZeroAsymmetry,
    /// A smooth dielectric with relative IOR exactly 1 neither reflects nor bends: index-matched.
    /// Only where depth is not counted (unlimited max_depth, no roulette), because a dielectric
    /// crossing counts as an interaction and an index-matched one does not.
    UnitIorRatio,
}

impl fmt::Display for Simplification {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Simplification::ConstantDensityGrid => {
                "the density grid has one value over the whole box: constant extinction"
            }
            Simplification::ConstantAlbedoGrid => {
                "the albedo grid has one value over the whole box: constant albedo"
            }
            Simplification::ZeroAsymmetry => "Henyey-Greenstein with g = 0: isotropic phase",
            Simplification::UnitIorRatio => {
                "dielectric with IOR ratio 1, depth not limited: index-matched boundary"
            }
        })
    }
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
        let mut simplifications = Vec::new();
        let mut fired = |rule| simplifications.push(rule);
        let (medium, boundary, phase, environment) = match effects {
            Effects::Specialised => (
                medium(desc, &mut fired),
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
    let shared = Shared {
        camera: camera(&desc.camera, &desc.film),
        bounds: aabb(&desc.boundary.bounds),
        settings,
    };
    let parts = Parts::of(desc, effects);
    let derived = Derived::of(&parts, shared.bounds, &settings);
    dispatch(shared, parts.with(&derived), visitor)
}

/// What the factory computes from the built parts for the integrator: the majorant grid of a grid
/// medium and the sampling distribution of a lat-long map. Neither changes the variant.
pub struct Derived {
    /// Per-cell majorants and the grid's resolution, if the medium tracks with a grid.
    majorants: Option<(Vec<f32>, [u32; 3])>,
    bounds: Aabb,
    /// The lat-long map's sampling distribution, for next-event estimation.
    distribution: Vec<f32>,
}

impl Derived {
    pub fn of(parts: &Parts<'_>, bounds: Aabb, settings: &PathSettings) -> Self {
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
                let mut data = vec![0.0; res.iter().map(|&r| r as usize).product()];
                build_majorants(&density, scale, bounds, res, &mut data);
                (data, res)
            })
            // A grid whose every cell has the global bound (a uniform density, as ad's) saves no
            // step and costs the walk: track with the global majorant.
            .filter(|(data, _)| {
                let global = data.iter().copied().fold(0.0, f32::max);
                data.iter().any(|&m| m < global)
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
        self.majorants.as_ref().map(|(_, res)| *res)
    }
}

impl<'a> Parts<'a> {
    /// These parts with `derived`'s majorant grid and sampling distribution.
    pub fn with(mut self, derived: &'a Derived) -> Self {
        let grid = derived
            .majorants
            .as_ref()
            .map(|(data, res)| MajorantGrid::new(data, *res, derived.bounds));
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

/// The one value of `grid` per channel, if it has a single value everywhere and covers `bounds`
/// (outside its own box a grid is zero, so a smaller grid is not constant over the medium).
fn uniform<'g>(grid: &'g GridDesc, bounds: &Bounds) -> Option<&'g [f32]> {
    let covers =
        (0..3).all(|i| grid.bounds.min[i] <= bounds.min[i] && grid.bounds.max[i] >= bounds.max[i]);
    let channels = grid.channels as usize;
    let first = grid.data.get(..channels)?;
    let same = grid.data.chunks_exact(channels).all(|v| v == first);
    (covers && same).then_some(first)
}

fn medium<'a>(desc: &'a SceneDescription, fired: &mut dyn FnMut(Simplification)) -> MediumPart<'a> {
    let medium = &desc.medium;
    let bounds = &desc.boundary.bounds;
    let density = match &medium.density {
        DensityDesc::Grid(grid) => match uniform(grid, bounds) {
            Some(value) => {
                fired(Simplification::ConstantDensityGrid);
                Density::Constant(&value[0])
            }
            None => Density::Grid(grid),
        },
        DensityDesc::Constant(sigma) => Density::Constant(sigma),
    };
    let albedo = match &medium.albedo {
        AlbedoDesc::Grid(grid) => match uniform(grid, bounds) {
            Some(value) => {
                fired(Simplification::ConstantAlbedoGrid);
                Albedo::Constant(value)
            }
            None => Albedo::Grid(grid),
        },
        AlbedoDesc::Constant(rgb) => Albedo::Constant(rgb),
    };
    let dense_trilinear = texel(medium.lookup).is_none() && !any_layout(medium);
    match (density, albedo) {
        (Density::Constant(density), Albedo::Constant(albedo)) => {
            MediumPart::Homogeneous(HomogeneousMedium {
                sigma_t: medium.scale * density,
                albedo: Spectrum::new(albedo[0], albedo[1], albedo[2]),
            })
        }
        (Density::Grid(density), Albedo::Constant(albedo)) if dense_trilinear => {
            MediumPart::GridDensity(GridMedium {
                density: grid::<1>(density, medium.lookup),
                scale: medium.scale,
                majorant: medium.scale * density.max_value(),
                majorants: None,
                albedo: ConstantAlbedo(Spectrum::new(albedo[0], albedo[1], albedo[2])),
                reads: DenseTrilinear,
            })
        }
        // Textures and the any-layout reads take a constant albedo as a one-voxel grid (the
        // kernels read it only at real collisions, a few per path).
        (density, albedo) => {
            let albedo = match albedo {
                Albedo::Grid(albedo) => grid::<3>(albedo, medium.lookup),
                Albedo::Constant(rgb) => one_voxel(desc, rgb),
            };
            albedo_grid_medium(desc, density, albedo)
        }
    }
}

/// Whether the medium's grids need the any-layout reads ([`AnyLayout`]): nearest-sample lookups,
/// or bricked storage on a GPU. Every other grid is read dense and trilinear, with only that code
/// in the kernel.
fn any_layout(medium: &MediumDesc) -> bool {
    medium.lookup == GridLookupDesc::Nearest || medium.storage != GridStorage::Dense
}

/// What a texture holds per sample, if the lookup reads grids through textures
/// ([`TextureTrilinear`]).
fn texel(lookup: GridLookupDesc) -> Option<TexelFormat> {
    match lookup {
        GridLookupDesc::Texture => Some(TexelFormat::F32),
        GridLookupDesc::TextureHalf => Some(TexelFormat::F16),
        GridLookupDesc::Trilinear | GridLookupDesc::Nearest => None,
    }
}

/// The medium as grids of density and albedo, whatever the description holds: constants become
/// one-voxel grids over the medium's box, whose trilinear lookup is that constant everywhere.
fn general_medium(desc: &SceneDescription) -> MediumPart<'_> {
    let medium = &desc.medium;
    let density = match &medium.density {
        DensityDesc::Grid(grid) => Density::Grid(grid),
        DensityDesc::Constant(sigma) => Density::Constant(sigma),
    };
    let albedo = match &medium.albedo {
        AlbedoDesc::Grid(albedo) => grid::<3>(albedo, medium.lookup),
        AlbedoDesc::Constant(_) => one_voxel_albedo(desc),
    };
    albedo_grid_medium(desc, density, albedo)
}

/// A grid medium of `density` and an albedo grid, reading its grids as the description's lookup
/// and storage ask: through textures, in any layout, or dense and trilinear.
fn albedo_grid_medium<'a>(
    desc: &'a SceneDescription,
    density: Density<'a>,
    albedo: Grid<'a, 3>,
) -> MediumPart<'a> {
    if texel(desc.medium.lookup).is_some() {
        MediumPart::GridTexture(grid_medium(
            desc,
            density,
            GridAlbedo(albedo, TextureTrilinear),
        ))
    } else if any_layout(&desc.medium) {
        MediumPart::GridAnyLayout(grid_medium(desc, density, GridAlbedo(albedo, AnyLayout)))
    } else {
        MediumPart::GridDensityAlbedo(grid_medium(
            desc,
            density,
            GridAlbedo(albedo, DenseTrilinear),
        ))
    }
}

/// The description's constant albedo as a one-voxel grid over the medium's box.
fn one_voxel_albedo(desc: &SceneDescription) -> Grid<'_, 3> {
    match &desc.medium.albedo {
        AlbedoDesc::Constant(rgb) => one_voxel(desc, rgb),
        AlbedoDesc::Grid(albedo) => grid::<3>(albedo, desc.medium.lookup),
    }
}

/// A medium's density as the description has it, before it becomes a part.
enum Density<'a> {
    Constant(&'a f32),
    Grid(&'a GridDesc),
}

enum Albedo<'a> {
    /// Three channels.
    Constant(&'a [f32]),
    Grid(&'a GridDesc),
}

/// A grid medium with `albedo`; a constant density becomes a one-voxel grid over the medium's box.
fn grid_medium<'a, R: GridReads>(
    desc: &'a SceneDescription,
    density: Density<'a>,
    albedo: GridAlbedo<'a, R>,
) -> GridMedium<'a, GridAlbedo<'a, R>, R> {
    let density = match density {
        Density::Grid(density) => grid::<1>(density, desc.medium.lookup),
        Density::Constant(sigma) => one_voxel(desc, std::slice::from_ref(sigma)),
    };
    let max_density = density.data.iter().copied().fold(0.0, f32::max);
    GridMedium {
        density,
        scale: desc.medium.scale,
        majorant: desc.medium.scale * max_density,
        majorants: None,
        albedo,
        reads: R::default(),
    }
}

/// A one-voxel grid of `value` (its channels) over the medium's box.
fn one_voxel<'a, const C: usize>(desc: &SceneDescription, value: &'a [f32]) -> Grid<'a, C> {
    let bounds = aabb(&desc.boundary.bounds);
    Grid::new(
        value,
        [1, 1, 1],
        GridMapping::cell_centred(bounds, [1, 1, 1]),
    )
    .with_texel(texel(desc.medium.lookup).unwrap_or_default())
}

fn boundary(desc: &SceneDescription, fired: &mut dyn FnMut(Simplification)) -> BoundaryPart {
    let depth_not_counted =
        desc.integrator.max_depth.is_none() && desc.integrator.rr_depth.is_none();
    match desc.boundary.bsdf {
        BsdfDesc::Null => BoundaryPart::IndexMatched(NullBoundary),
        BsdfDesc::Dielectric { int_ior, ext_ior } if int_ior == ext_ior && depth_not_counted => {
            fired(Simplification::UnitIorRatio);
            BoundaryPart::IndexMatched(NullBoundary)
        }
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

fn phase(phase: &PhaseDesc, fired: &mut dyn FnMut(Simplification)) -> PhasePart {
    match *phase {
        PhaseDesc::Isotropic => PhasePart::Isotropic(Isotropic),
        PhaseDesc::HenyeyGreenstein { g: 0.0 } => {
            fired(Simplification::ZeroAsymmetry);
            PhasePart::Isotropic(Isotropic)
        }
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

fn grid<const C: usize>(g: &GridDesc, lookup: GridLookupDesc) -> Grid<'_, C> {
    let bounds = aabb(&g.bounds);
    let mapping = match g.convention {
        GridConvention::Vertex => GridMapping::vertex_centred(bounds, g.resolution),
        GridConvention::Cell => GridMapping::cell_centred(bounds, g.resolution),
    };
    let grid =
        Grid::new(&g.data, g.resolution, mapping).with_texel(texel(lookup).unwrap_or_default());
    if lookup == GridLookupDesc::Nearest {
        grid.with_lookup(GridLookup::Nearest)
    } else {
        grid
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

/// The integrator settings a scene file asks for, with the estimator chosen for the scene.
pub fn path_settings(desc: &SceneDescription) -> PathSettings {
    PathSettings {
        max_depth: desc.integrator.max_depth.unwrap_or(PathSettings::UNLIMITED),
        rr_depth: desc.integrator.rr_depth.unwrap_or(PathSettings::UNLIMITED),
        estimator: default_estimator(desc),
        majorant_resolution: default_majorants(desc).resolution,
        ..PathSettings::default()
    }
}

/// Next-event estimation where it pays: a lat-long map behind an index-matched boundary (3x the
/// efficiency of path tracing on envmap-cube with an index-matched boundary). Under a constant
/// environment a path tracer's escaping path already sees the whole light, and NEE's shadow rays
/// cost more than its lower variance saves (smoke: 0.6x); a dielectric boundary rules NEE out
/// (`docs/heterogeneous.md`).
pub fn default_estimator(desc: &SceneDescription) -> Estimator {
    match (&desc.boundary.bsdf, &desc.environment) {
        (BsdfDesc::Null, EnvironmentDesc::LatLong(_)) => Estimator::NextEvent,
        _ => Estimator::PathTracing,
    }
}

/// What tracking costs along camera rays, per real collision: the integrals of the majorant and of
/// the extinction, and the majorant-grid cells entered, summed over a 16 x 16 fan of rays through
/// the film between their entry into the box and their exit (256 points each for the integrals, the
/// DDA's own walk for the cells).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackingCost {
    /// Tentative collisions per real one with the scene's majorants (delta tracking takes this
    /// many): the majorant's integral over the extinction's.
    pub majorant_ratio: f64,
    /// The same under the one global majorant.
    pub global_ratio: f64,
    /// Majorant-grid cells entered per real collision; 0 with the global majorant.
    pub crossings_ratio: f64,
    /// Whether the medium tracks with a majorant grid (the factory drops one that saves nothing).
    pub grid: bool,
}

impl TrackingCost {
    /// A cell crossing costs about what a tentative collision does: both draw a random number and
    /// a logarithm (sampling restarts at each cell boundary) and read a majorant or a density.
    pub const CROSSING_COST: f64 = 1.0;

    /// Work per real collision, in tentative collisions.
    pub fn per_collision(&self) -> f64 {
        self.majorant_ratio + Self::CROSSING_COST * self.crossings_ratio
    }
}

/// [`TrackingCost`] of `desc` under `settings`' majorants, or `None` when the camera rays see no
/// extinction.
pub fn tracking_cost(desc: &SceneDescription, settings: PathSettings) -> Option<TrackingCost> {
    struct Cost;
    impl SceneVisitor for Cost {
        type Output = Option<TrackingCost>;
        fn visit<S: RenderScene>(self, scene: &S) -> Self::Output {
            use volpt_core::majorant::Dda;
            use volpt_core::Medium;
            const FAN: u32 = 16;
            const POINTS: u32 = 256;
            let camera = scene.camera();
            let medium = scene.medium();
            let (mut majorant, mut global, mut extinction) = (0.0f64, 0.0f64, 0.0f64);
            let mut crossings = 0u64;
            for j in 0..FAN {
                for i in 0..FAN {
                    let px = ((i as f32 + 0.5) / FAN as f32 * camera.width as f32) as u32;
                    let py = ((j as f32 + 0.5) / FAN as f32 * camera.height as f32) as u32;
                    let ray = camera.generate_ray(px, py, Vec2::splat(0.5));
                    let bounds = scene.bounds();
                    let start = if bounds.contains(ray.origin) {
                        0.0
                    } else {
                        match bounds.entry(&ray) {
                            Some(hit) => hit.t,
                            None => continue,
                        }
                    };
                    let inside = volpt_core::Ray::new(ray.at(start), ray.dir);
                    let length = bounds.exit(&inside).t;
                    let dt = (length / POINTS as f32) as f64;
                    for k in 0..POINTS {
                        let p = inside.at((k as f32 + 0.5) / POINTS as f32 * length);
                        let bound = medium
                            .majorant_grid()
                            .map_or(medium.majorant(), |g| g.at_point(p));
                        majorant += bound as f64 * dt;
                        global += medium.majorant() as f64 * dt;
                        extinction += medium.sigma_t(p) as f64 * dt;
                    }
                    if let Some(grid) = medium.majorant_grid() {
                        let mut dda = Dda::new(grid, &inside);
                        while dda.segment(grid).1 < length {
                            dda.advance(grid, inside.dir);
                            crossings += 1;
                        }
                    }
                }
            }
            (extinction > 0.0).then(|| TrackingCost {
                majorant_ratio: majorant / extinction,
                global_ratio: global / extinction,
                crossings_ratio: crossings as f64 / extinction,
                grid: medium.majorant_grid().is_some(),
            })
        }
    }
    with_scene(desc, settings, Cost)
}

/// Why the factory tracks with the majorants it does ([`default_majorants`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MajorantRule {
    /// The extinction is one value everywhere: every tentative collision is real.
    Homogeneous,
    /// The camera rays see no extinction to weigh the majorants with.
    NoExtinction,
    /// No grid has a cell below the global bound (a uniform density, as ad's and cgg-logo's).
    NoTighterGrid,
    /// The cheapest grid's work per real collision is at most `1 / GRID_MARGIN` of the global
    /// majorant's.
    GridSavesEnough,
    /// The cheapest grid's work per real collision is more than `1 / GRID_MARGIN` of the global
    /// majorant's (or more than the global majorant's).
    GridSavesTooLittle,
}

/// The majorant resolution the factory chooses for a scene (1: the global majorant), the rule that
/// fired, and its input: the [`TrackingCost::per_collision`] of the global majorant (resolution 1)
/// and of each grid tried.
#[derive(Clone, Debug, PartialEq)]
pub struct MajorantChoice {
    pub resolution: u32,
    pub rule: MajorantRule,
    pub costs: Vec<(u32, f64)>,
}

impl MajorantChoice {
    /// Resolutions tried, cells along the box's longest axis, finest first.
    pub const RESOLUTIONS: [u32; 4] = [64, 32, 16, 8];
    /// How much cheaper than the global majorant a grid must look, per [`TrackingCost`], to be
    /// chosen. The cost model counts tracking work only, and the rest of a path (the walk's
    /// bookkeeping; on a GPU, threads of a warp in different cells) favours the global majorant:
    /// on an H100 bucky's grid of 32 (7.61 against 6.5 per real collision here) was 1.25x slower,
    /// smoke's (88.35 against 7.22) 5.4x faster (`docs/heterogeneous.md`).
    pub const GRID_MARGIN: f64 = 2.0;
}

/// The default majorants of `desc`: the resolution among [`MajorantChoice::RESOLUTIONS`] with the
/// least tracking work per real collision along camera rays ([`TrackingCost::per_collision`]), if
/// it is at most `1 / GRID_MARGIN` of the global majorant's; else the global majorant.
pub fn default_majorants(desc: &SceneDescription) -> MajorantChoice {
    let choice = |resolution, rule, costs| MajorantChoice {
        resolution,
        rule,
        costs,
    };
    if Parts::of(desc, Effects::Specialised).medium.kind() == MediumKind::Homogeneous {
        return choice(1, MajorantRule::Homogeneous, Vec::new());
    }
    let cost = |resolution| {
        let settings = PathSettings {
            majorant_resolution: resolution,
            estimator: Estimator::PathTracing,
            ..PathSettings::default()
        };
        tracking_cost(desc, settings)
    };
    let Some(global) = cost(1).map(|c| c.per_collision()) else {
        return choice(1, MajorantRule::NoExtinction, Vec::new());
    };
    let mut costs = vec![(1, global)];
    for resolution in MajorantChoice::RESOLUTIONS {
        // A grid no cell of which is below the global bound is dropped (`Derived::of`); then every
        // coarser grid, whose cells hold the finer cells' maxima, is dropped too.
        match cost(resolution) {
            Some(c) if c.grid => costs.push((resolution, c.per_collision())),
            _ => break,
        }
    }
    let (best, best_cost) = costs
        .iter()
        .copied()
        .fold((1, global), |a, b| if b.1 < a.1 { b } else { a });
    if costs.len() == 1 {
        choice(1, MajorantRule::NoTighterGrid, costs)
    } else if best_cost * MajorantChoice::GRID_MARGIN <= global {
        choice(best, MajorantRule::GridSavesEnough, costs)
    } else {
        choice(1, MajorantRule::GridSavesTooLittle, costs)
    }
}
