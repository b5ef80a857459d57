//! Kernel launch parameters: plain `repr(C)` data that the host fills and a GPU kernel reads, and the
//! conversion from them to the same [`VolumeScene`] types the CPU renders with.
//!
//! The host fills one [`LaunchParams`] from its render-ready scene with [`ToParams`], copies it into
//! device memory and passes its address to the kernel. The kernel copies it back, rebuilds its
//! monomorphised scene with [`FromParams`] and runs the shared path step on it. Grids travel as
//! device addresses plus their shape and mapping; every scalar is the very `f32` the host's render
//! factory computed, so a kernel's scene is bit for bit the CPU's scene.
//!
//! Pointers are stored as `u64` addresses so that the structs are the same on every target and are
//! `Send + Sync` on the host. Only [`FromParams::from_params`] turns them back into references.

use crate::bsdf::{NullBoundary, RoughDielectric, SmoothDielectric};
use crate::camera::PerspectiveCamera;
use crate::environment::{ConstantEnvironment, LatLongEnvironment};
use crate::grid::{Grid, GridMapping};
use crate::medium::{ConstantAlbedo, GridAlbedo, GridMedium, HomogeneousMedium};
use crate::microfacet::Ggx;
use crate::path::PathSettings;
use crate::phase::{HenyeyGreenstein, Isotropic};
use crate::scene::VolumeScene;
use crate::{Aabb, Spectrum, Vec2, Vec3};

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraParams {
    pub origin: [f32; 3],
    pub axis_x: [f32; 3],
    pub axis_y: [f32; 3],
    pub axis_z: [f32; 3],
    pub tan_half_fov: [f32; 2],
    pub width: u32,
    pub height: u32,
}

impl From<&PerspectiveCamera> for CameraParams {
    fn from(c: &PerspectiveCamera) -> Self {
        Self {
            origin: c.origin.to_array(),
            axis_x: c.axis_x.to_array(),
            axis_y: c.axis_y.to_array(),
            axis_z: c.axis_z.to_array(),
            tan_half_fov: c.tan_half_fov.to_array(),
            width: c.width,
            height: c.height,
        }
    }
}

impl CameraParams {
    #[inline]
    pub fn camera(&self) -> PerspectiveCamera {
        PerspectiveCamera {
            origin: Vec3::from_array(self.origin),
            axis_x: Vec3::from_array(self.axis_x),
            axis_y: Vec3::from_array(self.axis_y),
            axis_z: Vec3::from_array(self.axis_z),
            tan_half_fov: Vec2::from_array(self.tan_half_fov),
            width: self.width,
            height: self.height,
        }
    }
}

/// A dense grid in device memory: `len` `f32` values at address `data`, laid out as [`Grid`] says,
/// and its world-to-index mapping as the host computed it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GridParams {
    pub data: u64,
    /// Number of `f32` values at `data` (`res_x * res_y * res_z * channels`).
    pub len: u64,
    pub res: [u32; 3],
    pub channels: u32,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub scale: [f32; 3],
    pub offset: [f32; 3],
}

impl GridParams {
    /// The parameters of `grid`, whose values were copied to device address `data`.
    pub fn new<const C: usize>(grid: &Grid<'_, C>, data: u64) -> Self {
        Self {
            data,
            len: grid.data.len() as u64,
            res: grid.res,
            channels: C as u32,
            bounds_min: grid.mapping.bounds.min.to_array(),
            bounds_max: grid.mapping.bounds.max.to_array(),
            scale: grid.mapping.scale().to_array(),
            offset: grid.mapping.offset().to_array(),
        }
    }

    /// The grid these parameters describe.
    ///
    /// # Safety
    /// `data` must point to `len` initialised `f32` values that stay valid and unchanged for `'a`,
    /// and `len` must equal `res_x * res_y * res_z * C`.
    #[inline]
    pub unsafe fn grid<'a, const C: usize>(&self) -> Grid<'a, C> {
        let bounds = Aabb::new(
            Vec3::from_array(self.bounds_min),
            Vec3::from_array(self.bounds_max),
        );
        Grid {
            // SAFETY: the caller guarantees the address range.
            data: unsafe {
                core::slice::from_raw_parts(self.data as *const f32, self.len as usize)
            },
            res: self.res,
            mapping: GridMapping::from_parts(
                bounds,
                Vec3::from_array(self.scale),
                Vec3::from_array(self.offset),
            ),
        }
    }
}

/// The medium: the fields a variant does not use are ignored (a homogeneous medium reads no grid).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MediumParams {
    /// Homogeneous extinction (already multiplied by the scale).
    pub sigma_t: f32,
    /// Constant albedo (homogeneous and grid-density media).
    pub albedo: [f32; 3],
    /// Grid media: `sigma_t(p) = density_scale * density(p)`.
    pub density_scale: f32,
    /// Grid media: `density_scale * max(density)`.
    pub majorant: f32,
    pub density: GridParams,
    /// Three channels, grid-density-albedo media only.
    pub albedo_grid: GridParams,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BoundaryParams {
    /// `n_inside / n_outside` (dielectric boundaries).
    pub eta: f32,
    /// GGX roughness (rough dielectric).
    pub alpha: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseParams {
    /// Henyey-Greenstein asymmetry.
    pub g: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SettingsParams {
    pub max_depth: u32,
    pub rr_depth: u32,
    pub max_segments: u32,
    pub max_tracking_steps: u32,
    /// Explicit, so that no byte of the struct is uninitialised padding when it is copied.
    pub padding: u32,
}

impl From<&PathSettings> for SettingsParams {
    fn from(s: &PathSettings) -> Self {
        Self {
            max_depth: s.max_depth,
            rr_depth: s.rr_depth,
            max_segments: s.max_segments,
            max_tracking_steps: s.max_tracking_steps,
            padding: 0,
        }
    }
}

impl SettingsParams {
    #[inline]
    pub fn settings(&self) -> PathSettings {
        PathSettings {
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
            max_segments: self.max_segments,
            max_tracking_steps: self.max_tracking_steps,
        }
    }
}

/// The environment: a constant reads `radiance` only, a lat-long map everything else.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnvironmentParams {
    /// Constant environment radiance.
    pub radiance: [f32; 3],
    /// Lat-long: the map's `scale`.
    pub scale: f32,
    /// Lat-long: rows of the world-to-map rotation.
    pub world_to_map: [[f32; 3]; 3],
    pub width: u32,
    pub height: u32,
    pub row_scale: f32,
    pub row_offset: f32,
    /// Explicit, so that no byte of the struct is uninitialised padding when it is copied.
    pub padding: u32,
    /// Device address of the map's `len` RGB `f32` values.
    pub texels: u64,
    pub len: u64,
}

/// Everything a kernel needs to rebuild any scene variant. Fields are ordered so that every one
/// is aligned without implicit padding.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneParams {
    pub camera: CameraParams,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub medium: MediumParams,
    pub environment: EnvironmentParams,
    pub boundary: BoundaryParams,
    pub phase: PhaseParams,
    pub settings: SettingsParams,
}

/// One launch: the scene, the sampling, and the device buffers the kernel writes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaunchParams {
    pub scene: SceneParams,
    /// This launch traces samples `first_sample .. first_sample + samples` of every pixel.
    pub first_sample: u32,
    pub samples: u32,
    pub seed: u32,
    /// Explicit, so that no byte of the struct is uninitialised padding when it is copied.
    pub padding: u32,
    /// `width * height * 3` `f64` sums of the samples' radiance, zeroed before the first launch;
    /// each launch adds its samples.
    pub film: u64,
    /// [`COUNTERS`] `u64` totals (paths, segments, tracking steps, truncated, truncated by tracking),
    /// zeroed before the launch.
    pub counters: u64,
    /// One `u64`, zeroed before the launch: the next path index a persistent thread takes.
    pub next_path: u64,
    /// Paths to trace in this launch: `width * height * samples`.
    pub total_paths: u64,
}

// The host copies these structs to the device as bytes: they must have no implicit padding.
const _: () = assert!(core::mem::size_of::<CameraParams>() == 64);
const _: () = assert!(core::mem::size_of::<GridParams>() == 16 + 4 * 4 + 4 * 12);
const _: () = assert!(core::mem::size_of::<MediumParams>() == 24 + 2 * 80);
const _: () = assert!(core::mem::size_of::<EnvironmentParams>() == 16 + 36 + 20 + 16);
const _: () = assert!(core::mem::size_of::<SceneParams>() == 64 + 24 + 184 + 88 + 8 + 4 + 20);
const _: () = assert!(core::mem::size_of::<LaunchParams>() == 392 + 16 + 4 * 8);

/// Number of `u64` counters a launch reduces: paths, segments, tracking steps, truncated paths, and
/// of those the paths cut by the tracking-step bound.
pub const COUNTERS: usize = 5;

/// Rebuilds a scene component from launch parameters.
pub trait FromParams<'a>: Sized {
    /// # Safety
    /// The grid addresses in `p` that this component reads must satisfy [`GridParams::grid`]'s
    /// contract for `'a`, and so must an environment map's `texels` and `len`.
    unsafe fn from_params(p: &'a SceneParams) -> Self;
}

impl FromParams<'_> for HomogeneousMedium {
    #[inline]
    unsafe fn from_params(p: &SceneParams) -> Self {
        Self {
            sigma_t: p.medium.sigma_t,
            albedo: Spectrum::from_array(p.medium.albedo),
        }
    }
}

impl<'a> FromParams<'a> for GridMedium<'a, ConstantAlbedo> {
    #[inline]
    unsafe fn from_params(p: &'a SceneParams) -> Self {
        Self {
            // SAFETY: forwarded to the caller.
            density: unsafe { p.medium.density.grid::<1>() },
            scale: p.medium.density_scale,
            majorant: p.medium.majorant,
            albedo: ConstantAlbedo(Spectrum::from_array(p.medium.albedo)),
        }
    }
}

impl<'a> FromParams<'a> for GridMedium<'a, GridAlbedo<'a>> {
    #[inline]
    unsafe fn from_params(p: &'a SceneParams) -> Self {
        Self {
            // SAFETY: forwarded to the caller.
            density: unsafe { p.medium.density.grid::<1>() },
            scale: p.medium.density_scale,
            majorant: p.medium.majorant,
            // SAFETY: forwarded to the caller.
            albedo: GridAlbedo(unsafe { p.medium.albedo_grid.grid::<3>() }),
        }
    }
}

impl FromParams<'_> for NullBoundary {
    #[inline]
    unsafe fn from_params(_p: &SceneParams) -> Self {
        NullBoundary
    }
}

impl FromParams<'_> for SmoothDielectric {
    #[inline]
    unsafe fn from_params(p: &SceneParams) -> Self {
        Self {
            eta: p.boundary.eta,
        }
    }
}

impl FromParams<'_> for RoughDielectric {
    #[inline]
    unsafe fn from_params(p: &SceneParams) -> Self {
        Self {
            eta: p.boundary.eta,
            distribution: Ggx {
                alpha: p.boundary.alpha,
            },
        }
    }
}

impl FromParams<'_> for Isotropic {
    #[inline]
    unsafe fn from_params(_p: &SceneParams) -> Self {
        Isotropic
    }
}

impl FromParams<'_> for HenyeyGreenstein {
    #[inline]
    unsafe fn from_params(p: &SceneParams) -> Self {
        Self { g: p.phase.g }
    }
}

impl FromParams<'_> for ConstantEnvironment {
    #[inline]
    unsafe fn from_params(p: &SceneParams) -> Self {
        ConstantEnvironment(Spectrum::from_array(p.environment.radiance))
    }
}

impl<'a> FromParams<'a> for LatLongEnvironment<'a> {
    #[inline]
    unsafe fn from_params(p: &'a SceneParams) -> Self {
        let e = &p.environment;
        Self {
            // SAFETY: the caller guarantees the address range.
            rgb: unsafe { core::slice::from_raw_parts(e.texels as *const f32, e.len as usize) },
            width: e.width,
            height: e.height,
            world_to_map: e.world_to_map.map(Vec3::from_array),
            scale: e.scale,
            row_scale: e.row_scale,
            row_offset: e.row_offset,
        }
    }
}

impl<'a, M, B, P, E> FromParams<'a> for VolumeScene<M, B, P, E>
where
    M: FromParams<'a>,
    B: FromParams<'a>,
    P: FromParams<'a>,
    E: FromParams<'a>,
{
    #[inline]
    unsafe fn from_params(p: &'a SceneParams) -> Self {
        // SAFETY: forwarded to the caller.
        unsafe {
            Self {
                camera: p.camera.camera(),
                bounds: Aabb::new(
                    Vec3::from_array(p.bounds_min),
                    Vec3::from_array(p.bounds_max),
                ),
                medium: M::from_params(p),
                boundary: B::from_params(p),
                phase: P::from_params(p),
                environment: E::from_params(p),
                settings: p.settings.settings(),
            }
        }
    }
}

/// The host side of [`FromParams`]: writes a scene component into launch parameters.
///
/// `upload` copies a grid's (or an environment map's) values to device memory and returns their device address; the caller
/// keeps that memory alive for as long as the parameters are used.
pub trait ToParams {
    fn to_params(&self, p: &mut SceneParams, upload: &mut dyn FnMut(&[f32]) -> u64);
}

impl ToParams for HomogeneousMedium {
    fn to_params(&self, p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.medium.sigma_t = self.sigma_t;
        p.medium.albedo = self.albedo.to_array();
    }
}

impl ToParams for GridMedium<'_, ConstantAlbedo> {
    fn to_params(&self, p: &mut SceneParams, upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.medium.density = GridParams::new(&self.density, upload(self.density.data));
        p.medium.density_scale = self.scale;
        p.medium.majorant = self.majorant;
        p.medium.albedo = self.albedo.0.to_array();
    }
}

impl ToParams for GridMedium<'_, GridAlbedo<'_>> {
    fn to_params(&self, p: &mut SceneParams, upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.medium.density = GridParams::new(&self.density, upload(self.density.data));
        p.medium.density_scale = self.scale;
        p.medium.majorant = self.majorant;
        p.medium.albedo_grid = GridParams::new(&self.albedo.0, upload(self.albedo.0.data));
    }
}

impl ToParams for NullBoundary {
    fn to_params(&self, _p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {}
}

impl ToParams for SmoothDielectric {
    fn to_params(&self, p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.boundary.eta = self.eta;
    }
}

impl ToParams for RoughDielectric {
    fn to_params(&self, p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.boundary.eta = self.eta;
        p.boundary.alpha = self.distribution.alpha;
    }
}

impl ToParams for Isotropic {
    fn to_params(&self, _p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {}
}

impl ToParams for HenyeyGreenstein {
    fn to_params(&self, p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.phase.g = self.g;
    }
}

impl ToParams for ConstantEnvironment {
    fn to_params(&self, p: &mut SceneParams, _upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.environment.radiance = self.0.to_array();
    }
}

impl ToParams for LatLongEnvironment<'_> {
    fn to_params(&self, p: &mut SceneParams, upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.environment = EnvironmentParams {
            scale: self.scale,
            world_to_map: self.world_to_map.map(|row| row.to_array()),
            width: self.width,
            height: self.height,
            row_scale: self.row_scale,
            row_offset: self.row_offset,
            texels: upload(self.rgb),
            len: self.rgb.len() as u64,
            ..EnvironmentParams::default()
        };
    }
}

impl<M: ToParams, B: ToParams, P: ToParams, E: ToParams> ToParams for VolumeScene<M, B, P, E> {
    fn to_params(&self, p: &mut SceneParams, upload: &mut dyn FnMut(&[f32]) -> u64) {
        p.camera = CameraParams::from(&self.camera);
        p.bounds_min = self.bounds.min.to_array();
        p.bounds_max = self.bounds.max.to_array();
        p.settings = SettingsParams::from(&self.settings);
        self.medium.to_params(p, upload);
        self.boundary.to_params(p, upload);
        self.phase.to_params(p, upload);
        self.environment.to_params(p, upload);
    }
}
