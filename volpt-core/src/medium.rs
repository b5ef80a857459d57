//! Participating media: extinction and single-scattering albedo as functions of position.
//!
//! Extinction is grey (one `sigma_t` for all channels) in every medium here; albedo is RGB. Delta
//! tracking then needs one majorant and no spectral MIS, and coloured albedo only scales the path
//! throughput. A chromatic extinction is [`crate::chromatic`]'s ([`Medium::Spectral`]).

use bytemuck::{Pod, Zeroable};

use crate::abi::name::Joined;
use crate::abi::{Component, GridParams, Upload};
use crate::grid::{DenseTrilinear, Grid, GridReads};
use crate::majorant::{MajorantGrid, MajorantGridParams};
use crate::material::MaterialGrid;
use crate::spectral::SpectralState;
use crate::{Spectrum, Vec3};

pub trait Medium {
    /// The extinction is the same everywhere: delta tracking needs no rejection step.
    const HOMOGENEOUS: bool;
    /// The albedo is the same everywhere and reads no memory: a strategy that orders albedo reads
    /// (sorting-sk) has nothing to order.
    const CONSTANT_ALBEDO: bool = false;
    /// What a path carries for this medium's extinction ([`crate::spectral`]): `()` for a grey
    /// one. A chromatic one ([`crate::spectral::HeroChannel`]) differs between channels: paths
    /// track it by a hero channel with spectral MIS ([`crate::chromatic`]) and read
    /// [`Medium::sigma_t_rgb`]; [`Medium::sigma_t`] and the majorants bound every channel. A grey
    /// medium compiles none of that.
    type Spectral: SpectralState;

    /// An upper bound of `sigma_t` over the medium (the majorant of delta tracking).
    fn majorant(&self) -> f32;
    /// Tighter bounds cell by cell, if the medium has them; tracking then walks their cells
    /// instead of using [`Medium::majorant`].
    #[inline]
    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        None
    }
    fn sigma_t(&self, p: Vec3) -> f32;
    fn albedo(&self, p: Vec3) -> Spectrum;

    /// The extinction per channel (a chromatic medium's; a grey one's in all three).
    #[inline(always)]
    fn sigma_t_rgb(&self, p: Vec3) -> Spectrum {
        Spectrum::splat(self.sigma_t(p))
    }

    /// Each channel's majorant in a region whose bound of every channel is `bound`: the
    /// majorant-grid cell of index `cell`, or with `None` the whole medium ([`Medium::majorant`]).
    /// A chromatic medium's hero channel samples its free flights at its own
    /// ([`crate::tracking::spectral_delta_tracking`]); a grey medium's is `bound` in all three.
    #[inline(always)]
    fn majorant_rgb(&self, bound: f32, _cell: Option<usize>) -> Spectrum {
        Spectrum::splat(bound)
    }

    /// The extinction per channel if it is the same everywhere (transmittance is then exact).
    #[inline(always)]
    fn uniform_sigma_t_rgb(&self) -> Option<Spectrum> {
        None
    }

    /// An unbiased estimate of [`Medium::sigma_t`] at `p`, which may use the low 39 bits of
    /// `bits` (random, independent of everything else the caller draws): a stochastic grid
    /// lookup reads one sample instead of eight ([`crate::grid::GridLookup::Stochastic`]). The
    /// trackers call this; every other medium returns `sigma_t(p)`.
    #[inline(always)]
    fn sigma_t_random(&self, p: Vec3, _bits: u64) -> f32 {
        self.sigma_t(p)
    }

    /// [`Medium::albedo`] as an unbiased estimate, as [`Medium::sigma_t_random`].
    #[inline(always)]
    fn albedo_random(&self, p: Vec3, _bits: u64) -> Spectrum {
        self.albedo(p)
    }

    /// The Henyey-Greenstein asymmetry of the material at `p`, if the medium's materials carry
    /// their own ([`crate::material`]); `None`: the scene's phase function holds everywhere.
    #[inline(always)]
    fn phase_g(&self, _p: Vec3) -> Option<f32> {
        None
    }
}

/// What the host's factory derives from a medium for tracking: a medium with a density grid
/// tracks with a majorant grid of it, computed once per scene by the host and borrowed for `'a`;
/// the defaults fit a medium without grids. The device never calls these: it receives the
/// majorant grid through the part's parameters ([`Component`]).
pub trait TrackedMedium<'a> {
    /// The density grid and its scale, whose majorant grid tightens tracking.
    fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
        None
    }

    /// A density per channel and each channel's scale (a chromatic medium's three-channel
    /// grid), whose majorant grid tightens tracking, each channel's cells bounded on its own.
    fn channel_densities(&self) -> Option<(Grid<'a, 3>, Spectrum)> {
        None
    }

    /// Tracks with `grid` (`None`: with the global majorant).
    fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
        let _ = grid;
    }

    /// Tracks each channel with its own bound per cell of the majorant grid, three `f32`s a
    /// cell (`None`: in proportion to the grid's bound of every channel); only a chromatic
    /// medium's channels have their own.
    fn track_channels_with(&mut self, channels: Option<&'a [f32]>) {
        let _ = channels;
    }

    /// The material-indexed volume whose majorant grid tightens tracking
    /// ([`crate::material::build_material_majorants`]), if the medium is one.
    fn materials(&self) -> Option<MaterialGrid<'a>> {
        None
    }
}

#[derive(Clone, Copy, Debug)]
pub struct HomogeneousMedium {
    pub sigma_t: f32,
    pub albedo: Spectrum,
}

impl Medium for HomogeneousMedium {
    type Spectral = ();
    const HOMOGENEOUS: bool = true;
    const CONSTANT_ALBEDO: bool = true;

    #[inline]
    fn majorant(&self) -> f32 {
        self.sigma_t
    }

    #[inline]
    fn sigma_t(&self, _p: Vec3) -> f32 {
        self.sigma_t
    }

    #[inline]
    fn albedo(&self, _p: Vec3) -> Spectrum {
        self.albedo
    }
}

/// Where a grid medium's albedo comes from: a constant never reads memory.
pub trait AlbedoField {
    /// See [`Medium::CONSTANT_ALBEDO`].
    const CONSTANT: bool;

    fn albedo(&self, p: Vec3) -> Spectrum;

    /// See [`Medium::albedo_random`].
    #[inline(always)]
    fn albedo_random(&self, p: Vec3, _bits: u64) -> Spectrum {
        self.albedo(p)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct ConstantAlbedo(pub Spectrum);

impl AlbedoField for ConstantAlbedo {
    const CONSTANT: bool = true;

    #[inline]
    fn albedo(&self, _p: Vec3) -> Spectrum {
        self.0
    }
}

/// An albedo grid, read as `R` says: the medium's own [`GridReads`] ([`ReadAs`]).
#[derive(Clone, Copy, Debug)]
pub struct GridAlbedo<'a, R = DenseTrilinear>(pub Grid<'a, 3>, pub R);

impl<R: GridReads> AlbedoField for GridAlbedo<'_, R> {
    const CONSTANT: bool = false;

    #[inline(always)]
    fn albedo(&self, p: Vec3) -> Spectrum {
        Spectrum::from_array(R::lookup(&self.0, p))
    }

    #[inline(always)]
    fn albedo_random(&self, p: Vec3, bits: u64) -> Spectrum {
        Spectrum::from_array(R::lookup_random(&self.0, p, bits))
    }
}

/// An albedo that a [`GridMedium`] reading its grids as `R` can carry: one that reads no grid,
/// or reads its grid as the medium does. The medium's name then names the reads once
/// (`grid_density__grid_albedo__any_layout`), and two media of one name are one type.
pub trait ReadAs<R: GridReads>: AlbedoField + Component {}

impl<R: GridReads> ReadAs<R> for ConstantAlbedo {}

impl<R: GridReads> ReadAs<R> for GridAlbedo<'_, R> {}

/// A heterogeneous medium: `sigma_t(p) = scale * density(p)` from a grid, read as `R` says.
#[derive(Clone, Copy, Debug)]
pub struct GridMedium<'a, A, R = DenseTrilinear> {
    pub density: Grid<'a, 1>,
    pub scale: f32,
    /// `scale * max(density)`: trilinear interpolation never exceeds the largest sample.
    pub majorant: f32,
    /// Per-cell bounds over the medium's box ([`crate::majorant`]); `None` tracks with `majorant`.
    pub majorants: Option<MajorantGrid<'a>>,
    pub albedo: A,
    pub reads: R,
}

impl<A: AlbedoField, R: GridReads> Medium for GridMedium<'_, A, R> {
    type Spectral = ();
    const HOMOGENEOUS: bool = false;
    const CONSTANT_ALBEDO: bool = A::CONSTANT;

    #[inline]
    fn majorant(&self) -> f32 {
        self.majorant
    }

    #[inline]
    fn majorant_grid(&self) -> Option<&MajorantGrid<'_>> {
        self.majorants.as_ref()
    }

    // Lookups are always inlined, as `Grid::lookup` says why.
    #[inline(always)]
    fn sigma_t(&self, p: Vec3) -> f32 {
        self.scale * R::lookup(&self.density, p)[0]
    }

    #[inline(always)]
    fn albedo(&self, p: Vec3) -> Spectrum {
        self.albedo.albedo(p)
    }

    #[inline(always)]
    fn sigma_t_random(&self, p: Vec3, bits: u64) -> f32 {
        self.scale * R::lookup_random(&self.density, p, bits)[0]
    }

    #[inline(always)]
    fn albedo_random(&self, p: Vec3, bits: u64) -> Spectrum {
        self.albedo.albedo_random(p, bits)
    }
}

impl TrackedMedium<'_> for HomogeneousMedium {}

impl<'a, A, R> TrackedMedium<'a> for GridMedium<'a, A, R> {
    fn density(&self) -> Option<(Grid<'a, 1>, f32)> {
        Some((self.density, self.scale))
    }

    fn track_with(&mut self, grid: Option<MajorantGrid<'a>>) {
        self.majorants = grid;
    }
}

/// Device parameters of a homogeneous medium.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct HomogeneousParams {
    pub sigma_t: f32,
    pub albedo: [f32; 3],
}

impl Component for HomogeneousMedium {
    const NAME: &'static str = "homogeneous";
    type Params = HomogeneousParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> HomogeneousParams {
        HomogeneousParams {
            sigma_t: self.sigma_t,
            albedo: self.albedo.to_array(),
        }
    }
    #[inline]
    unsafe fn from_params(p: &HomogeneousParams) -> Self {
        Self {
            sigma_t: p.sigma_t,
            albedo: Spectrum::from_array(p.albedo),
        }
    }
}

/// Device parameters of a constant albedo, padded to a multiple of 8 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ConstantAlbedoParams {
    pub albedo: [f32; 3],
    pub padding: u32,
}

impl Component for ConstantAlbedo {
    const NAME: &'static str = "constant_albedo";
    type Params = ConstantAlbedoParams;

    fn to_params(&self, _upload: &mut Upload<'_>) -> ConstantAlbedoParams {
        ConstantAlbedoParams {
            albedo: self.0.to_array(),
            padding: 0,
        }
    }
    #[inline]
    unsafe fn from_params(p: &ConstantAlbedoParams) -> Self {
        Self(Spectrum::from_array(p.albedo))
    }
}

/// Named without its reads, which are its medium's ([`ReadAs`]).
impl<R: GridReads> Component for GridAlbedo<'_, R> {
    const NAME: &'static str = "grid_albedo";
    type Params = GridParams;

    fn to_params(&self, upload: &mut Upload<'_>) -> GridParams {
        GridParams::new(&self.0, upload, R::PLACEMENT)
    }
    #[inline]
    unsafe fn from_params(p: &GridParams) -> Self {
        // SAFETY: forwarded to the caller.
        Self(unsafe { p.grid::<3>() }, R::default())
    }
}

/// Device parameters of a grid medium with albedo parameters `A`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GridMediumParams<A> {
    pub density: GridParams,
    pub scale: f32,
    pub majorant: f32,
    pub majorants: MajorantGridParams,
    pub albedo: A,
}

impl<A: Pod> GridMediumParams<A> {
    /// `GridParams` and the two scalars are a multiple of 8 bytes, the majorant grid's 56; an
    /// albedo of a multiple of 8 bytes follows without padding.
    const LAYOUT: () = assert!(
        core::mem::size_of::<A>().is_multiple_of(8)
            && core::mem::size_of::<GridParams>().is_multiple_of(8)
            && core::mem::size_of::<MajorantGridParams>() == 56
            && core::mem::size_of::<Self>()
                == core::mem::size_of::<GridParams>() + 8 + 56 + core::mem::size_of::<A>()
    );
}

// SAFETY: `repr(C)` of `Pod` fields without padding, as `LAYOUT` (evaluated in `to_params`) proves.
unsafe impl<A: Pod> Zeroable for GridMediumParams<A> {}
// SAFETY: as above.
unsafe impl<A: Pod> Pod for GridMediumParams<A> {}

impl<A: ReadAs<R>, R: GridReads> GridMedium<'_, A, R> {
    /// The density grid's name, then the albedo's and the reads'.
    const COMPOSED_NAME: Joined = Joined::new(&["grid_density", A::NAME, R::NAME]);
}

impl<A: ReadAs<R>, R: GridReads> Component for GridMedium<'_, A, R> {
    const NAME: &'static str = Self::COMPOSED_NAME.as_str();
    type Params = GridMediumParams<A::Params>;

    fn to_params(&self, upload: &mut Upload<'_>) -> Self::Params {
        #[allow(clippy::let_unit_value)]
        let () = GridMediumParams::<A::Params>::LAYOUT;
        GridMediumParams {
            density: GridParams::new(&self.density, upload, R::PLACEMENT),
            scale: self.scale,
            majorant: self.majorant,
            majorants: MajorantGridParams::new(self.majorants.as_ref(), upload),
            albedo: self.albedo.to_params(upload),
        }
    }
    #[inline]
    unsafe fn from_params(p: &Self::Params) -> Self {
        Self {
            // SAFETY: forwarded to the caller.
            density: unsafe { p.density.grid::<1>() },
            scale: p.scale,
            majorant: p.majorant,
            // SAFETY: forwarded to the caller.
            majorants: unsafe { p.majorants.grid() },
            // SAFETY: forwarded to the caller.
            albedo: unsafe { A::from_params(&p.albedo) },
            reads: R::default(),
        }
    }
}
