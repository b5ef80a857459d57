//! The typed device ABI: how a scene travels from the host to a GPU kernel.
//!
//! Every scene part is a [`Component`]: it names its own `#[repr(C)]` parameter type, writes itself
//! into it on the host ([`Component::to_params`]) and is rebuilt from it on the device
//! ([`Component::from_params`]). A whole scene's parameters, [`SceneParams`], are composed from its
//! parts' parameters, so a kernel receives exactly the fields its variant reads, and every scalar is
//! the very `f32` the host computed: a kernel's scene is bit for bit the CPU's scene.
//!
//! Layout is checked at compile time: parameter types are [`bytemuck::Pod`] (no padding, no
//! pointers), and each part's size is a multiple of 8 bytes, so that a composition of parts has no
//! padding either ([`SceneParams::LAYOUT`]). Device memory travels as `u64` addresses; only
//! `from_params` turns them back into references.
//!
//! [`Component::NAME`] is the part's name in kernel entry points (`homogeneous`, `rough_dielectric`;
//! a generic part's is composed from its parameters' names, [`name`]): the host derives the entry
//! point of a scene type from its parts' names ([`SceneAbi::names`]), and the kernels export the
//! same names from the variant registry ([`crate::variant`]).

pub mod name;

use bytemuck::{Pod, Zeroable};

use crate::camera::PerspectiveCamera;
use crate::geometry::Aabb;
use crate::grid::{Grid, GridLayout, GridLookup, GridMapping, GridPlacement, TexelFormat};
use crate::light::{Lights, LightsParams};
use crate::mesh::{BvhNode, MeshTriangle, SurfaceDistance, TriangleMesh};
use crate::path::{Estimator, PathSettings, Roulette};
use crate::scene::{Lit, Scene, VolumeScene};
use crate::shape::{BoundaryShape, DeviceBoundary, Shape};
use crate::{Bsdf, Environment, Medium, PhaseFunction};
use crate::{Vec2, Vec3};

/// Places grid or map values in memory a device can read and returns their device address; the
/// caller keeps that memory alive for as long as the parameters are used. Any
/// `FnMut(&[f32]) -> u64` (a copy to device memory) is one.
pub trait Uploader {
    /// Places `values`, in their order, and returns their device address.
    fn values(&mut self, values: &[f32]) -> u64;

    /// Places the samples of a dense grid of `res` samples of `channels` channels where
    /// `placement` (the medium's [`crate::GridReads::PLACEMENT`]) says: in a layout of the
    /// uploader's choice if any layout, else dense; in a texture of `texel`s if the uploader has
    /// textures, else (the CPU's uploaders) dense, where the CPU's filter reads them. By default
    /// dense, through [`Uploader::values`].
    fn grid(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        placement: GridPlacement,
        texel: TexelFormat,
    ) -> PlacedGrid {
        let _ = (res, channels, placement, texel);
        PlacedGrid {
            address: self.values(values),
            len: values.len() as u64,
            layout: GridLayout::Dense,
            texture: 0,
        }
    }

    /// Places sparse grid `data` of `res` samples of `channels` channels ([`GridLayout::Sparse`], checked by
    /// [`crate::sparse::parts`]). By default as it is, through [`Uploader::values`]: the CPU's
    /// uploaders, whose renders read the two-level table. A GPU's uploader must place it as
    /// [`GridLayout::SparseFlat`] ([`crate::sparse::flatten`]), the only sparse layout the
    /// kernels read, or fail.
    fn sparse(&mut self, data: &[f32], res: [u32; 3], channels: u32) -> PlacedGrid {
        let _ = (res, channels);
        PlacedGrid {
            address: self.values(data),
            len: data.len() as u64,
            layout: GridLayout::Sparse,
            texture: 0,
        }
    }
}

impl<F: FnMut(&[f32]) -> u64> Uploader for F {
    fn values(&mut self, values: &[f32]) -> u64 {
        self(values)
    }
}

/// Where an [`Uploader`] put a grid: `len` `f32` values at device address `address`, ordered as
/// `layout` says, and/or texture object `texture` (0: none; `len` 0: only the texture).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlacedGrid {
    pub address: u64,
    pub len: u64,
    pub layout: GridLayout,
    pub texture: u64,
}

/// What the components' `to_params` receive.
pub type Upload<'u> = dyn Uploader + 'u;

/// A scene part that can travel to a GPU kernel.
pub trait Component {
    /// The part's name in kernel entry points: lower case, words joined by `_`; a generic part's
    /// is its own name and its type parameters' names, joined by [`name::SEPARATOR`]
    /// ([`name::Joined`]).
    const NAME: &'static str;
    /// What the kernel receives. Its size must be a multiple of 8 bytes.
    type Params: Pod;

    fn to_params(&self, upload: &mut Upload<'_>) -> Self::Params;

    /// The device side: rebuilds the part from its parameters.
    ///
    /// # Safety
    /// Every address in `p` must point to the values [`Component::to_params`] uploaded for it,
    /// valid and unchanged for as long as the part (and any lifetime in its type) lives.
    unsafe fn from_params(p: &Self::Params) -> Self;
}

/// The parameters of a part that reads nothing (index-matched boundary, isotropic phase).
pub type NoParams = ();

/// The camera, as [`PerspectiveCamera`] holds it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CameraParams {
    pub origin: [f32; 3],
    pub axis_x: [f32; 3],
    pub axis_y: [f32; 3],
    pub axis_z: [f32; 3],
    pub tan_half_fov: [f32; 2],
    pub width: u32,
    pub height: u32,
    /// 1 for an orthographic camera, 0 for a pinhole.
    pub orthographic: u32,
    /// Keeps the camera a multiple of 8 bytes ([`SceneParams::LAYOUT`]); always 0.
    pub pad: u32,
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
            orthographic: u32::from(c.orthographic),
            pad: 0,
        }
    }
}

impl From<&CameraParams> for PerspectiveCamera {
    #[inline]
    fn from(c: &CameraParams) -> Self {
        Self {
            origin: Vec3::from_array(c.origin),
            axis_x: Vec3::from_array(c.axis_x),
            axis_y: Vec3::from_array(c.axis_y),
            axis_z: Vec3::from_array(c.axis_z),
            tan_half_fov: Vec2::from_array(c.tan_half_fov),
            width: c.width,
            height: c.height,
            orthographic: c.orthographic != 0,
        }
    }
}

/// The integrator's limits.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SettingsParams {
    pub max_depth: u32,
    pub rr_depth: u32,
    pub max_segments: u32,
    pub max_tracking_steps: u32,
    pub majorant_resolution: u32,
    /// 0: path tracing, 1: next-event estimation.
    pub estimator: u32,
    /// 0: Mitsuba's roulette, 1: the thesis's ([`Roulette`]).
    pub roulette: u32,
    pub padding: u32,
}

impl From<&PathSettings> for SettingsParams {
    fn from(s: &PathSettings) -> Self {
        Self {
            max_depth: s.max_depth,
            rr_depth: s.rr_depth,
            max_segments: s.max_segments,
            max_tracking_steps: s.max_tracking_steps,
            majorant_resolution: s.majorant_resolution,
            estimator: match s.estimator {
                Estimator::PathTracing => 0,
                Estimator::NextEvent => 1,
            },
            roulette: match s.roulette {
                Roulette::Mitsuba => 0,
                Roulette::Throughput => 1,
            },
            padding: 0,
        }
    }
}

impl From<&SettingsParams> for PathSettings {
    #[inline]
    fn from(s: &SettingsParams) -> Self {
        Self {
            max_depth: s.max_depth,
            rr_depth: s.rr_depth,
            max_segments: s.max_segments,
            max_tracking_steps: s.max_tracking_steps,
            majorant_resolution: s.majorant_resolution,
            estimator: if s.estimator == 1 {
                Estimator::NextEvent
            } else {
                Estimator::PathTracing
            },
            roulette: if s.roulette == 1 {
                Roulette::Throughput
            } else {
                Roulette::Mitsuba
            },
        }
    }
}

/// A grid in device memory: `len` `f32` values at address `data`, ordered as `layout`
/// ([`GridLayout::to_u32`]) says, and its world-to-index mapping as the host computed it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
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
    /// [`GridLayout`], as [`GridLayout::to_u32`] writes it.
    pub layout: u32,
    /// [`GridLookup`]: 0 trilinear, 1 nearest, 2 stochastic.
    pub lookup: u32,
    /// The texture object of a grid in a texture ([`GridPlacement::Texture`]), else 0.
    pub texture: u64,
    /// [`TexelFormat`], as [`TexelFormat::to_u32`] writes it.
    pub texel: u32,
    pub padding: u32,
}

impl GridLookup {
    /// The code of [`GridParams::lookup`].
    pub const fn code(self) -> u32 {
        match self {
            GridLookup::Trilinear => 0,
            GridLookup::Nearest => 1,
            GridLookup::Stochastic => 2,
        }
    }

    /// The lookup of a code the host wrote with [`GridLookup::code`].
    #[inline]
    pub const fn from_code(code: u32) -> Self {
        if code == GridLookup::Nearest.code() {
            GridLookup::Nearest
        } else if code == GridLookup::Stochastic.code() {
            GridLookup::Stochastic
        } else {
            GridLookup::Trilinear
        }
    }
}

impl GridParams {
    /// The parameters of `grid`, whose values `upload` places on the device as `placement` (the
    /// reading medium's) says. `grid` must be dense or sparse (the host's grids are).
    pub fn new<const C: usize>(
        grid: &Grid<'_, C>,
        upload: &mut Upload<'_>,
        placement: GridPlacement,
    ) -> Self {
        // A sparse grid is already laid out for the any-layout reads (the factory gives it no
        // other): the uploader places its bricks and table, or their flat copy.
        let placed = if grid.layout == GridLayout::Sparse {
            debug_assert_eq!(placement, GridPlacement::AnyLayout);
            upload.sparse(grid.data, grid.res, C as u32)
        } else {
            debug_assert_eq!(grid.layout, GridLayout::Dense);
            upload.grid(grid.data, grid.res, C as u32, placement, grid.texel)
        };
        debug_assert!(placement == GridPlacement::AnyLayout || placed.layout == GridLayout::Dense);
        Self {
            data: placed.address,
            len: placed.len,
            texture: placed.texture,
            texel: grid.texel.to_u32(),
            padding: 0,
            layout: placed.layout.to_u32(),
            res: grid.res,
            channels: C as u32,
            bounds_min: grid.mapping.bounds.min.to_array(),
            bounds_max: grid.mapping.bounds.max.to_array(),
            scale: grid.mapping.scale().to_array(),
            offset: grid.mapping.offset().to_array(),
            lookup: grid.lookup.code(),
        }
    }

    /// The grid these parameters describe.
    ///
    /// # Safety
    /// `data` must point to `len` initialised `f32` values that stay valid and unchanged for `'a`,
    /// and `len` must equal `GridLayout::values(res, C)` of the layout, or be 0 for a grid only
    /// in a texture (which must stay valid for `'a`).
    #[inline]
    pub unsafe fn grid<'a, const C: usize>(&self) -> Grid<'a, C> {
        let bounds = Aabb::new(
            Vec3::from_array(self.bounds_min),
            Vec3::from_array(self.bounds_max),
        );
        let data = if self.len == 0 {
            &[]
        } else {
            // SAFETY: the caller guarantees the address range.
            unsafe { core::slice::from_raw_parts(self.data as *const f32, self.len as usize) }
        };
        Grid {
            data,
            res: self.res,
            mapping: GridMapping::from_parts(
                bounds,
                Vec3::from_array(self.scale),
                Vec3::from_array(self.offset),
            ),
            layout: GridLayout::from_u32(self.layout),
            lookup: GridLookup::from_code(self.lookup),
            texture: self.texture,
            texel: TexelFormat::from_u32(self.texel),
        }
    }
}

/// Everything a kernel needs to rebuild a `VolumeScene<M, B, P, E>`: the parts every scene has,
/// then each variant part's own parameters.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SceneParams<M, B, P, E> {
    pub camera: CameraParams,
    pub bounds_min: [f32; 3],
    pub bounds_max: [f32; 3],
    pub settings: SettingsParams,
    /// The boundary's BVH if it is a mesh (its box is `bounds_min`, `bounds_max`).
    pub mesh: MeshParams,
    pub lights: LightsParams,
    pub medium: M,
    pub boundary: B,
    pub phase: P,
    pub environment: E,
}

impl<M: Pod, B: Pod, P: Pod, E: Pod> SceneParams<M, B, P, E> {
    /// Evaluated for every composition the host builds: the fixed part is a multiple of 8 bytes
    /// and so is every variant part, so `repr(C)` inserts no padding and the struct is plain bytes.
    pub const LAYOUT: () = {
        let fixed = core::mem::size_of::<CameraParams>()
            + 24
            + core::mem::size_of::<SettingsParams>()
            + core::mem::size_of::<MeshParams>()
            + core::mem::size_of::<LightsParams>();
        let parts = [
            core::mem::size_of::<M>(),
            core::mem::size_of::<B>(),
            core::mem::size_of::<P>(),
            core::mem::size_of::<E>(),
        ];
        assert!(fixed.is_multiple_of(8));
        let mut sum = fixed;
        let mut i = 0;
        while i < parts.len() {
            assert!(
                parts[i].is_multiple_of(8),
                "a part's parameters must be a multiple of 8 bytes"
            );
            sum += parts[i];
            i += 1;
        }
        assert!(
            core::mem::size_of::<Self>() == sum,
            "SceneParams has padding"
        );
        assert!(core::mem::align_of::<Self>() <= 8);
    };
}

// SAFETY: `repr(C)` of `Pod` fields; `LAYOUT`, which `SceneAbi::to_params` evaluates for every
// composition it builds, proves that no padding byte lies between or after them.
unsafe impl<M: Pod, B: Pod, P: Pod, E: Pod> Zeroable for SceneParams<M, B, P, E> {}
// SAFETY: as above.
unsafe impl<M: Pod, B: Pod, P: Pod, E: Pod> Pod for SceneParams<M, B, P, E> {}

/// A whole scene that can travel to a GPU kernel.
pub trait SceneAbi: Scene + Sized {
    type Params: Pod;
    /// The part names of the scene's variant, in registry order (medium, boundary, phase,
    /// environment): the kernel entry point of this scene type under strategy `s` is
    /// `s__medium__boundary__phase__environment`.
    fn names() -> [&'static str; 4];
    fn to_params(&self, upload: &mut Upload<'_>) -> Self::Params;

    /// Whether the box kernels can render this scene: not one whose boundary is a mesh. The
    /// parameters carry a mesh's BVH, but the box kernels rebuild every scene as a box scene;
    /// the mesh kernels (`volpt_device::KernelSet::Mesh`), of [`SceneAbi::Kernel`] types, trace
    /// meshes too (a run-time branch there would cost every box kernel registers: docs/gpu.md,
    /// meshes).
    fn on_device(&self) -> bool;

    /// Whether the boundary scatters about vertex normals ([`crate::mesh::TriangleMesh::normals`]),
    /// which no kernel traces: the parameters do not carry them.
    fn shading_normals(&self) -> bool;

    /// This scene rebuilt from its parameters with its boundary a [`DeviceBoundary`], the shape a
    /// kernel traces a box or a mesh as (the CPU renders it too, to check that code).
    type Kernel: Scene + SceneAbi<Params = Self::Params>;

    /// The device side of [`SceneAbi::to_params`].
    ///
    /// # Safety
    /// As [`Component::from_params`], for every part.
    unsafe fn from_params(p: &Self::Params) -> Self;
}

/// A mesh boundary's BVH in device memory: `node_count` [`BvhNode`]s at `nodes` and
/// `triangle_count` [`MeshTriangle`]s at `triangles`; all 0 for a box.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshParams {
    pub nodes: u64,
    pub triangles: u64,
    pub node_count: u32,
    pub triangle_count: u32,
}

/// A boundary shape as it travels to the kernels: its box ([`SceneParams::bounds_min`] and
/// `bounds_max`) and, for a mesh, its BVH ([`MeshParams`]). A box scene's kernel rebuilds the
/// box; a [`DeviceBoundary`] ([`DeviceShape::Kernel`]) rebuilds either, chosen at run time.
pub trait DeviceShape: Sized {
    /// The shape a mesh-capable kernel rebuilds from this one's parameters.
    type Kernel: DeviceShape + Shape;
    /// Whether the kernels (box scenes) trace this shape: not a mesh.
    fn on_device(&self) -> bool;
    /// The box: a mesh's bounding box.
    fn device_box(&self) -> Aabb;
    /// Places a mesh's BVH with `upload`; a box has none.
    fn mesh_params(&self, upload: &mut Upload<'_>) -> MeshParams;
    /// Whether this is a mesh with vertex normals ([`SceneAbi::shading_normals`]).
    fn shading_normals(&self) -> bool {
        false
    }
    /// The device side: the shape of box `bounds` and BVH `mesh`.
    ///
    /// # Safety
    /// `mesh`'s addresses must point to its counts of nodes and triangles that
    /// [`DeviceShape::mesh_params`] uploaded, valid and unchanged for the shape's lifetime.
    unsafe fn from_device(bounds: Aabb, mesh: &MeshParams) -> Self;
}

impl DeviceShape for Aabb {
    type Kernel = DeviceBoundary<'static>;
    fn on_device(&self) -> bool {
        true
    }
    #[inline(always)]
    fn device_box(&self) -> Aabb {
        *self
    }
    fn mesh_params(&self, _: &mut Upload<'_>) -> MeshParams {
        MeshParams::default()
    }
    #[inline(always)]
    unsafe fn from_device(bounds: Aabb, _: &MeshParams) -> Self {
        bounds
    }
}

/// A mesh's slices as [`MeshParams`].
fn upload_mesh(
    nodes: &[BvhNode],
    triangles: &[MeshTriangle],
    upload: &mut Upload<'_>,
) -> MeshParams {
    if nodes.is_empty() {
        return MeshParams::default();
    }
    MeshParams {
        nodes: upload.values(bytemuck::cast_slice(nodes)),
        triangles: upload.values(bytemuck::cast_slice(triangles)),
        node_count: nodes.len() as u32,
        triangle_count: triangles.len() as u32,
    }
}

/// The slices [`upload_mesh`] placed; empty for a box.
///
/// # Safety
/// As [`DeviceShape::from_device`].
#[inline(always)]
unsafe fn mesh_slices<'a>(mesh: &MeshParams) -> (&'a [BvhNode], &'a [MeshTriangle]) {
    if mesh.node_count == 0 {
        return (&[], &[]);
    }
    // SAFETY: the caller guarantees the address ranges.
    unsafe {
        (
            core::slice::from_raw_parts(mesh.nodes as *const BvhNode, mesh.node_count as usize),
            core::slice::from_raw_parts(
                mesh.triangles as *const MeshTriangle,
                mesh.triangle_count as usize,
            ),
        )
    }
}

impl<'a> DeviceShape for DeviceBoundary<'a> {
    type Kernel = Self;
    fn on_device(&self) -> bool {
        self.nodes.is_empty()
    }
    #[inline(always)]
    fn device_box(&self) -> Aabb {
        self.bounds
    }
    fn mesh_params(&self, upload: &mut Upload<'_>) -> MeshParams {
        upload_mesh(self.nodes, self.triangles, upload)
    }
    #[inline(always)]
    unsafe fn from_device(bounds: Aabb, mesh: &MeshParams) -> Self {
        // SAFETY: forwarded to the caller.
        let (nodes, triangles) = unsafe { mesh_slices(mesh) };
        Self {
            bounds,
            nodes,
            triangles,
        }
    }
}

impl<'a> DeviceShape for BoundaryShape<'a> {
    type Kernel = DeviceBoundary<'a>;
    fn on_device(&self) -> bool {
        matches!(self, BoundaryShape::Box(_))
    }
    fn device_box(&self) -> Aabb {
        Shape::bounds(self)
    }
    fn mesh_params(&self, upload: &mut Upload<'_>) -> MeshParams {
        match self {
            BoundaryShape::Box(_) => MeshParams::default(),
            BoundaryShape::Mesh(m) => upload_mesh(m.nodes, m.triangles, upload),
        }
    }
    fn shading_normals(&self) -> bool {
        matches!(self, BoundaryShape::Mesh(m) if !m.normals.is_empty())
    }
    /// A mesh comes back without its distance grid (which the kernels do not read): every
    /// flight casts its exit, and traces the same path.
    unsafe fn from_device(bounds: Aabb, mesh: &MeshParams) -> Self {
        // SAFETY: forwarded to the caller.
        let (nodes, triangles) = unsafe { mesh_slices(mesh) };
        if nodes.is_empty() {
            return BoundaryShape::Box(bounds);
        }
        BoundaryShape::Mesh(TriangleMesh {
            nodes,
            triangles,
            normals: &[],
            bounds,
            distance: SurfaceDistance::NONE,
        })
    }
}

impl<M, B, P, E, S> SceneAbi for VolumeScene<M, B, P, E, S>
where
    S: DeviceShape + Shape,
    M: Component + Medium,
    B: Component + Bsdf,
    P: Component + PhaseFunction,
    E: Component + Environment,
{
    type Params = SceneParams<M::Params, B::Params, P::Params, E::Params>;

    fn names() -> [&'static str; 4] {
        [M::NAME, B::NAME, P::NAME, E::NAME]
    }

    type Kernel = VolumeScene<M, B, P, E, S::Kernel>;

    fn on_device(&self) -> bool {
        self.bounds.on_device()
    }

    fn shading_normals(&self) -> bool {
        self.bounds.shading_normals()
    }

    fn to_params(&self, upload: &mut Upload<'_>) -> Self::Params {
        #[allow(clippy::let_unit_value)]
        let () = Self::Params::LAYOUT;
        SceneParams {
            camera: CameraParams::from(&self.camera),
            bounds_min: self.bounds.device_box().min.to_array(),
            bounds_max: self.bounds.device_box().max.to_array(),
            settings: SettingsParams::from(&self.settings),
            mesh: self.bounds.mesh_params(upload),
            lights: LightsParams::from(&self.lights),
            medium: self.medium.to_params(upload),
            boundary: self.boundary.to_params(upload),
            phase: self.phase.to_params(upload),
            environment: self.environment.to_params(upload),
        }
    }

    #[inline]
    unsafe fn from_params(p: &Self::Params) -> Self {
        // SAFETY: forwarded to the caller.
        unsafe {
            Self {
                camera: PerspectiveCamera::from(&p.camera),
                bounds: S::from_device(
                    Aabb::new(
                        Vec3::from_array(p.bounds_min),
                        Vec3::from_array(p.bounds_max),
                    ),
                    &p.mesh,
                ),
                medium: M::from_params(&p.medium),
                boundary: B::from_params(&p.boundary),
                phase: P::from_params(&p.phase),
                environment: E::from_params(&p.environment),
                lights: Lights::from(&p.lights),
                settings: PathSettings::from(&p.settings),
            }
        }
    }
}

/// A scene with its lights travels as the scene does (its parameters always carry them).
impl<S: SceneAbi> SceneAbi for Lit<S> {
    type Params = S::Params;

    fn names() -> [&'static str; 4] {
        S::names()
    }

    type Kernel = Lit<S::Kernel>;

    fn on_device(&self) -> bool {
        self.0.on_device()
    }

    fn shading_normals(&self) -> bool {
        self.0.shading_normals()
    }

    fn to_params(&self, upload: &mut Upload<'_>) -> Self::Params {
        self.0.to_params(upload)
    }

    #[inline(always)]
    unsafe fn from_params(p: &Self::Params) -> Self {
        // SAFETY: forwarded to the caller.
        Lit(unsafe { S::from_params(p) })
    }
}
