//! Participating media: extinction and single-scattering albedo as functions of position.
//!
//! Extinction is grey (one `sigma_t` for all channels); albedo is RGB. Delta tracking then needs one
//! majorant and no spectral MIS, and coloured albedo only scales the path throughput.

use crate::grid::Grid;
use crate::{Spectrum, Vec3};

pub trait Medium {
    /// The extinction is the same everywhere: delta tracking needs no rejection step.
    const HOMOGENEOUS: bool;

    /// An upper bound of `sigma_t` over the medium (the majorant of delta tracking).
    fn majorant(&self) -> f32;
    fn sigma_t(&self, p: Vec3) -> f32;
    fn albedo(&self, p: Vec3) -> Spectrum;
}

#[derive(Clone, Copy, Debug)]
pub struct HomogeneousMedium {
    pub sigma_t: f32,
    pub albedo: Spectrum,
}

impl Medium for HomogeneousMedium {
    const HOMOGENEOUS: bool = true;

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
    fn albedo(&self, p: Vec3) -> Spectrum;
}

#[derive(Clone, Copy, Debug)]
pub struct ConstantAlbedo(pub Spectrum);

impl AlbedoField for ConstantAlbedo {
    #[inline]
    fn albedo(&self, _p: Vec3) -> Spectrum {
        self.0
    }
}

#[derive(Clone, Copy, Debug)]
pub struct GridAlbedo<'a>(pub Grid<'a, 3>);

impl AlbedoField for GridAlbedo<'_> {
    #[inline]
    fn albedo(&self, p: Vec3) -> Spectrum {
        Spectrum::from_array(self.0.lookup(p))
    }
}

/// A heterogeneous medium: `sigma_t(p) = scale * density(p)` from a trilinear grid.
#[derive(Clone, Copy, Debug)]
pub struct GridMedium<'a, A> {
    pub density: Grid<'a, 1>,
    pub scale: f32,
    /// `scale * max(density)`: trilinear interpolation never exceeds the largest sample.
    pub majorant: f32,
    pub albedo: A,
}

impl<A: AlbedoField> Medium for GridMedium<'_, A> {
    const HOMOGENEOUS: bool = false;

    #[inline]
    fn majorant(&self) -> f32 {
        self.majorant
    }

    #[inline]
    fn sigma_t(&self, p: Vec3) -> f32 {
        self.scale * self.density.lookup(p)[0]
    }

    #[inline]
    fn albedo(&self, p: Vec3) -> Spectrum {
        self.albedo.albedo(p)
    }
}
