//! The media: a homogeneous medium where density and albedo are constants, else a grid medium
//! whose reads ([`GridReads`]) are the ones the description's lookup and storage ask for
//! ([`ReadsRule`]).

use super::*;

/// What the factory reads for the medium axis: the description's density and albedo, each a
/// constant where the specialised factory found a grid of one value over the box.
pub struct MediumInput<'a> {
    desc: &'a SceneDescription,
    density: Density<'a>,
    albedo: Albedo<'a>,
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

impl<'a> MediumInput<'a> {
    /// `desc`'s medium; for [`Effects::Specialised`], a grid of one value over the box as that
    /// constant (each such grid reported to `fired`).
    pub fn of(
        desc: &'a SceneDescription,
        effects: Effects,
        cache: &FactoryCache,
        fired: &mut dyn FnMut(Simplification),
    ) -> Self {
        let medium = &desc.medium;
        let uniform = |grid: &'a GridDesc| match effects {
            Effects::Specialised => uniform(grid, &desc.boundary.bounds, cache),
            Effects::General => None,
        };
        let density = match &medium.density {
            DensityDesc::Grid(grid) => match uniform(grid) {
                Some(value) => {
                    fired(Simplification::ConstantDensityGrid);
                    Density::Constant(&value[0])
                }
                None => Density::Grid(grid),
            },
            DensityDesc::Constant(sigma) => Density::Constant(sigma),
        };
        let albedo = match &medium.albedo {
            AlbedoDesc::Grid(grid) => match uniform(grid) {
                Some(value) => {
                    fired(Simplification::ConstantAlbedoGrid);
                    Albedo::Constant(value)
                }
                None => Albedo::Grid(grid),
            },
            AlbedoDesc::Constant(rgb) => Albedo::Constant(rgb),
        };
        Self {
            desc,
            density,
            albedo,
        }
    }

    fn medium(&self) -> &'a MediumDesc {
        &self.desc.medium
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

/// What the factory derives from a medium for tracking: a medium with a density grid tracks with
/// a majorant grid of it ([`Derived`]); any other medium keeps the defaults.
pub trait TrackedMedium<'a> {
    /// The density grid and its scale, whose majorant grid tightens tracking.
    fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
        None
    }

    /// Tracks with `grid` (`None`: with the global majorant).
    fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
        let _ = grid;
    }
}

impl<'a> Part<'a> for HomogeneousMedium {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match (&input.density, &input.albedo) {
            (Density::Constant(density), Albedo::Constant(albedo)) => Some(HomogeneousMedium {
                sigma_t: input.medium().scale * **density,
                albedo: Spectrum::new(albedo[0], albedo[1], albedo[2]),
            }),
            _ => None,
        }
    }

    fn general(_: &MediumInput<'a>) -> Option<Self> {
        None
    }
}

impl TrackedMedium<'_> for HomogeneousMedium {}

/// A constant albedo never reads memory: the specialised part for grids of the reads `R` asks.
impl<'a, R: ReadsRule> Part<'a> for GridMedium<'a, ConstantAlbedo, R> {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input.albedo {
            Albedo::Constant(albedo) if R::asked_by(input.medium()) => Some(grid_medium(
                input,
                ConstantAlbedo(Spectrum::new(albedo[0], albedo[1], albedo[2])),
            )),
            _ => None,
        }
    }

    fn general(_: &MediumInput<'a>) -> Option<Self> {
        None
    }
}

/// The general medium of the reads `R` asks: a constant albedo becomes a one-voxel grid (read
/// only at real collisions, a few per path).
impl<'a, R: ReadsRule> Part<'a> for GridMedium<'a, GridAlbedo<'a, R>, R> {
    type Input = MediumInput<'a>;

    fn specialised(input: &MediumInput<'a>, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        Self::general(input)
    }

    fn general(input: &MediumInput<'a>) -> Option<Self> {
        if !R::asked_by(input.medium()) {
            return None;
        }
        let albedo = match input.albedo {
            Albedo::Grid(albedo) => grid::<3>(albedo, input.medium().lookup),
            Albedo::Constant(rgb) => one_voxel(input.desc, rgb),
        };
        Some(grid_medium(input, GridAlbedo(albedo, R::default())))
    }
}

impl<'a, A, R> TrackedMedium<'a> for GridMedium<'a, A, R> {
    fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
        Some((self.density, self.scale))
    }

    fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
        self.majorants = grid;
    }
}

/// A grid medium with `albedo`; a constant density becomes a one-voxel grid over the medium's box.
fn grid_medium<'a, A, R: GridReads>(input: &MediumInput<'a>, albedo: A) -> GridMedium<'a, A, R> {
    let medium = input.medium();
    let density = match input.density {
        Density::Grid(density) => grid::<1>(density, medium.lookup),
        Density::Constant(sigma) => one_voxel(input.desc, std::slice::from_ref(sigma)),
    };
    let max_density = density.samples().iter().copied().fold(0.0, f32::max);
    GridMedium {
        density,
        scale: medium.scale,
        majorant: medium.scale * max_density,
        majorants: None,
        albedo,
        reads: R::default(),
    }
}

/// Which [`GridReads`] a description's lookup and storage ask for: exactly one of them for every
/// medium. A kernel carries the code of its reads alone.
pub trait ReadsRule: GridReads {
    fn asked_by(medium: &MediumDesc) -> bool;
}

/// Every grid that needs neither textures nor the any-layout reads.
impl ReadsRule for DenseTrilinear {
    fn asked_by(medium: &MediumDesc) -> bool {
        !texture_reads(medium) && !any_layout(medium)
    }
}

/// Nearest-sample lookups, bricked storage on a GPU, or a sparse grid, unless read through
/// textures.
impl ReadsRule for AnyLayout {
    fn asked_by(medium: &MediumDesc) -> bool {
        !texture_reads(medium) && any_layout(medium)
    }
}

impl ReadsRule for TextureTrilinear {
    fn asked_by(medium: &MediumDesc) -> bool {
        texture_reads(medium)
    }
}

/// Whether the medium's grids need the any-layout reads ([`AnyLayout`]): nearest-sample lookups,
/// bricked storage on a GPU, or a sparse grid.
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
