//! The scene as plain data: what a loader produces and what a renderer's factory consumes.
//!
//! Nothing here knows about a file format or about a backend. Units are Mitsuba's: world space is
//! whatever the scene file says, extinction coefficients are per world unit, colours are linear RGB.
//! Every type serialises (serde), so that a render's fingerprint can take in all of it. The
//! medium, its phase, the boundary's surface and the environment are described in their axes'
//! files ([`crate::medium`], [`crate::phase`], [`crate::boundary`], [`crate::environment`]) and
//! named here.

use serde::Serialize;

pub use crate::boundary::BsdfDesc;
pub use crate::environment::{EnvironmentDesc, LatLongDesc, LatLongRows};
pub use crate::light::{LightsDesc, SpotCone, SpotDesc, SunDesc};
pub use crate::medium::{AlbedoDesc, DensityDesc, GridLookup, GridStorage, MediumDesc};
pub use crate::mesh::MeshDesc;
pub use crate::phase::PhaseDesc;

/// An axis-aligned box in world space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bounds {
    pub min: [f32; 3],
    pub max: [f32; 3],
}

/// A 4x4 affine transform, row-major: `p' = m * [p, 1]`.
pub type Matrix4 = [[f32; 4]; 4];

pub const IDENTITY: Matrix4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Everything needed to render one image.
#[derive(Clone, Debug, Serialize)]
pub struct SceneDescription {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    /// Samples per pixel the scene file asks for (the sampler's sample count).
    pub spp: u32,
    pub integrator: IntegratorDesc,
    pub boundary: BoundaryDesc,
    pub medium: MediumDesc,
    pub environment: EnvironmentDesc,
    /// The lights besides the environment (a sun, a point or spot light).
    pub lights: LightsDesc,
}

/// Which image axis the field of view spans (Mitsuba's `fovAxis` / `fov_axis`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum FovAxis {
    X,
    Y,
    /// The smaller of the two image axes.
    Smaller,
    /// The larger of the two image axes.
    Larger,
    /// The diagonal of the image.
    Diagonal,
}

/// A camera: a pinhole (Mitsuba's `perspective`) or Mitsuba's `orthographic` sensor. Camera space
/// is Mitsuba's: it looks along +z with +y up and +x to the left of the image; `to_world` maps
/// camera space to world space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CameraDesc {
    pub to_world: Matrix4,
    /// Full field of view in degrees along `fov_axis` (a pinhole's; unused by an orthographic
    /// camera).
    pub fov_degrees: f32,
    pub fov_axis: FovAxis,
    pub projection: Projection,
}

/// How a camera maps the film to rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum Projection {
    /// A pinhole: rays from `to_world`'s origin through the film (Mitsuba's `perspective`).
    #[default]
    Perspective,
    /// Parallel rays along camera-space +z from the film at camera-space `(x, y, 0)`, `x` in
    /// [-1, 1] and `y` in [-h/w, h/w], scaled by `to_world` (Mitsuba 3's `orthographic`: its
    /// `to_world` scale sets the extent).
    Orthographic,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct FilmDesc {
    pub width: u32,
    pub height: u32,
}

/// Mitsuba's `volpath` settings. `None` means unlimited (Mitsuba's -1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct IntegratorDesc {
    /// Longest path, counted in segments: 1 shows only directly visible light.
    pub max_depth: Option<u32>,
    /// Depth from which Russian roulette is used; `None` disables it (but for paths of negligible
    /// weight, `volpt_core::path::NEGLIGIBLE_WEIGHT`).
    pub rr_depth: Option<u32>,
}

/// The shape that encloses the medium, and its surface: the box `bounds`, or a closed triangle
/// mesh whose bounding box `bounds` is.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BoundaryDesc {
    pub bounds: Bounds,
    pub bsdf: BsdfDesc,
    /// The mesh, if the boundary is one; shared, not copied, by the scenes made from this one.
    #[serde(serialize_with = "serialize_mesh")]
    pub mesh: Option<std::sync::Arc<MeshDesc>>,
}

fn serialize_mesh<S: serde::Serializer>(
    mesh: &Option<std::sync::Arc<MeshDesc>>,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    mesh.as_deref().serialize(serializer)
}

impl BoundaryDesc {
    /// The box `bounds` with surface `bsdf`.
    pub fn box_(bounds: Bounds, bsdf: BsdfDesc) -> Self {
        Self {
            bounds,
            bsdf,
            mesh: None,
        }
    }

    /// `mesh` with surface `bsdf`; its bounding box is the boundary's box.
    pub fn mesh(mesh: std::sync::Arc<MeshDesc>, bsdf: BsdfDesc) -> Self {
        let b = mesh.buffers.bounds;
        Self {
            bounds: Bounds {
                min: b.min.to_array(),
                max: b.max.to_array(),
            },
            bsdf,
            mesh: Some(mesh),
        }
    }
}

/// Where the grid's samples sit inside its bounding box.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum GridConvention {
    /// Mitsuba 0.5/0.6: sample `i` at `min + i / (res - 1) * extent` (samples on the box's faces).
    Vertex,
    /// Mitsuba 3: sample `i` at `min + (i + 0.5) / res * extent` (samples at cell centres).
    Cell,
}

/// A 3D grid: dense, x fastest (`data[((z * res_y + y) * res_x + x) * channels + c]`), or sparse
/// ([`SampleLayout::Sparse`], [`crate::sparse`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GridDesc {
    pub resolution: [u32; 3],
    pub channels: u32,
    pub bounds: Bounds,
    pub convention: GridConvention,
    /// Not serialised: the values of gigabyte grids are hashed on their own, once per scene, by
    /// what fingerprints a scene (the facade's `fingerprint::content`).
    #[serde(skip)]
    pub data: Vec<f32>,
    pub layout: SampleLayout,
}

/// How a [`GridDesc`]'s `data` holds its samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum SampleLayout {
    /// Every sample of the box, x fastest.
    #[default]
    Dense,
    /// Only the 8^3 bricks that hold something, then a table of every brick's slot
    /// (`volpt_core::GridLayout::Sparse`): a VDB's leaves without a dense copy of its box.
    Sparse,
}

impl GridDesc {
    /// The largest sample (0 for a grid of negative values).
    pub fn max_value(&self) -> f32 {
        self.samples().iter().copied().fold(0.0, f32::max)
    }
}
