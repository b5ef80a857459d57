//! From a description's plain data to the parts of a scene, one function per axis, with the
//! simplification rules: a part is replaced by a cheaper one only where the two are exactly equal.

use super::*;

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

/// The one value of `grid` per channel, if it has a single value everywhere and covers `bounds`
/// (outside its own box a grid is zero, so a smaller grid is not constant over the medium).
fn uniform<'g>(grid: &'g GridDesc, bounds: &Bounds, cache: &FactoryCache) -> Option<&'g [f32]> {
    let covers =
        (0..3).all(|i| grid.bounds.min[i] <= bounds.min[i] && grid.bounds.max[i] >= bounds.max[i]);
    let channels = grid.channels as usize;
    let samples = grid.samples();
    let first = samples.get(..channels)?;
    (covers && cache.is_uniform(samples, channels)).then_some(first)
}

pub(super) fn medium<'a>(
    desc: &'a SceneDescription,
    cache: &FactoryCache,
    fired: &mut dyn FnMut(Simplification),
) -> MediumPart<'a> {
    let medium = &desc.medium;
    let bounds = &desc.boundary.bounds;
    let density = match &medium.density {
        DensityDesc::Grid(grid) => match uniform(grid, bounds, cache) {
            Some(value) => {
                fired(Simplification::ConstantDensityGrid);
                Density::Constant(&value[0])
            }
            None => Density::Grid(grid),
        },
        DensityDesc::Constant(sigma) => Density::Constant(sigma),
    };
    let albedo = match &medium.albedo {
        AlbedoDesc::Grid(grid) => match uniform(grid, bounds, cache) {
            Some(value) => {
                fired(Simplification::ConstantAlbedoGrid);
                Albedo::Constant(value)
            }
            None => Albedo::Grid(grid),
        },
        AlbedoDesc::Constant(rgb) => Albedo::Constant(rgb),
    };
    let dense_trilinear = !texture_reads(medium) && !any_layout(medium);
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
/// bricked storage on a GPU, or a sparse grid. Every other grid is read dense and trilinear, with
/// only that code in the kernel.
fn any_layout(medium: &MediumDesc) -> bool {
    medium.lookup == GridLookupDesc::Nearest
        || medium.storage != GridStorage::Dense
        || sparse_grids(medium)
}

/// Whether a grid of the medium is sparse (read in software: a texture holds dense samples).
fn sparse_grids(medium: &MediumDesc) -> bool {
    let sparse = |g: &GridDesc| g.layout == SampleLayout::Sparse;
    matches!(&medium.density, DensityDesc::Grid(g) if sparse(g))
        || matches!(&medium.albedo, AlbedoDesc::Grid(g) if sparse(g))
}

/// Whether the medium's grids are read through textures ([`TextureTrilinear`]): the texture
/// lookups, and stochastic lookups of dense grids (one unfiltered texel; bricked and sparse grids
/// are read in software by [`AnyLayout`]).
fn texture_reads(medium: &MediumDesc) -> bool {
    match medium.lookup {
        GridLookupDesc::Stochastic => medium.storage == GridStorage::Dense && !sparse_grids(medium),
        lookup => texel(lookup).is_some(),
    }
}

/// What a texture holds per sample, if the lookup reads grids through textures
/// ([`TextureTrilinear`]).
fn texel(lookup: GridLookupDesc) -> Option<TexelFormat> {
    match lookup {
        GridLookupDesc::Texture | GridLookupDesc::Stochastic => Some(TexelFormat::F32),
        GridLookupDesc::TextureHalf => Some(TexelFormat::F16),
        GridLookupDesc::Trilinear | GridLookupDesc::Nearest => None,
    }
}

/// The medium as grids of density and albedo, whatever the description holds: constants become
/// one-voxel grids over the medium's box, whose trilinear lookup is that constant everywhere.
pub(super) fn general_medium(desc: &SceneDescription) -> MediumPart<'_> {
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
    if texture_reads(&desc.medium) {
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
    let max_density = density.samples().iter().copied().fold(0.0, f32::max);
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

pub(super) fn boundary(
    desc: &SceneDescription,
    fired: &mut dyn FnMut(Simplification),
) -> BoundaryPart {
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

pub(super) fn phase(phase: &PhaseDesc, fired: &mut dyn FnMut(Simplification)) -> PhasePart {
    match *phase {
        PhaseDesc::Isotropic => PhasePart::Isotropic(Isotropic),
        PhaseDesc::HenyeyGreenstein { g: 0.0 } => {
            fired(Simplification::ZeroAsymmetry);
            PhasePart::Isotropic(Isotropic)
        }
        PhaseDesc::HenyeyGreenstein { g } => PhasePart::HenyeyGreenstein(HenyeyGreenstein { g }),
    }
}

pub(super) fn environment(environment: &EnvironmentDesc) -> EnvironmentPart<'_> {
    match environment {
        EnvironmentDesc::Constant(rgb) => {
            EnvironmentPart::Constant(ConstantEnvironment(Spectrum::from_array(*rgb)))
        }
        EnvironmentDesc::LatLong(map) => EnvironmentPart::LatLong(lat_long(map)),
    }
}

/// The map's world-to-map rotation is the transpose of its `to_world`'s linear part (a rotation,
/// as the loader checks); the translation does not matter for light from infinitely far away.
pub(super) fn lat_long(map: &LatLongDesc) -> LatLongEnvironment<'_> {
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

pub(super) fn aabb(b: &Bounds) -> Aabb {
    Aabb::new(Vec3::from_array(b.min), Vec3::from_array(b.max))
}

fn grid<const C: usize>(g: &GridDesc, lookup: GridLookupDesc) -> Grid<'_, C> {
    let bounds = aabb(&g.bounds);
    let mapping = match g.convention {
        GridConvention::Vertex => GridMapping::vertex_centred(bounds, g.resolution),
        GridConvention::Cell => GridMapping::cell_centred(bounds, g.resolution),
    };
    let grid = match g.layout {
        SampleLayout::Dense => Grid::new(&g.data, g.resolution, mapping),
        SampleLayout::Sparse => Grid::sparse(&g.data, g.resolution, mapping),
    }
    .with_texel(texel(lookup).unwrap_or_default());
    match lookup {
        GridLookupDesc::Nearest => grid.with_lookup(GridLookup::Nearest),
        GridLookupDesc::Stochastic => grid.with_lookup(GridLookup::Stochastic),
        _ => grid,
    }
}
