//! volpt's physics, generic over the scene's parts and free of `std`, so that the same source is
//! monomorphised into the CPU renderer and into GPU kernels.
//!
//! Read [`path`] first: one step of a volumetric path, the algorithm every backend runs. Then
//! [`variant`], the registry of scene parts every backend is instantiated for, and [`abi`], how a
//! scene travels to a GPU kernel.
#![no_std]
// Inline PTX for exact hardware instructions (math::sqrt); nvptx builds already need nightly features.
#![cfg_attr(target_arch = "nvptx64", feature(asm_experimental_arch))]

// The host builds meshes' BVHs (`mesh::build`); the kernels never enable it.
#[cfg(feature = "alloc")]
extern crate alloc;

pub mod abi;
pub mod bsdf;
pub mod camera;
pub mod chromatic;
pub mod environment;
pub mod flight;
pub mod frame;
pub mod fresnel;
pub mod geometry;
pub mod grid;
pub mod light;
pub mod majorant;
pub mod material;
pub mod math;
pub mod medium;
pub mod mesh;
pub mod microfacet;
pub mod path;
pub mod phase;
pub mod rng;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod sparse;
pub mod spectral;
pub mod tracking;
pub mod variant;

pub use abi::{Component, SceneAbi};
pub use bsdf::{Bsdf, BsdfEval, BsdfSample, NullBoundary, RoughDielectric, SmoothDielectric};
pub use camera::PerspectiveCamera;
pub use chromatic::ChromaticMedium;
pub use environment::{
    ConstantEnvironment, Environment, LatLongEnvironment, LatLongRows, SampledEnvironment,
};
pub use geometry::{Aabb, Ray};
pub use grid::{
    AnyLayout, DenseTrilinear, Grid, GridLayout, GridLookup, GridMapping, GridPlacement, GridReads,
    TexelFormat, TextureTrilinear,
};
pub use light::{DirectionalLight, Lights, SpotLight};
pub use majorant::MajorantGrid;
pub use material::{Material, MaterialGrid};
pub use medium::{
    AlbedoField, ConstantAlbedo, GridAlbedo, GridMedium, HomogeneousMedium, Medium, ReadAs,
    TrackedMedium,
};
pub use mesh::{BvhNode, MeshTriangle, TriangleMesh};
pub use path::{Estimator, PathCounters, PathOf, PathSettings, PathState, Roulette};
pub use phase::{HenyeyGreenstein, Isotropic, PhaseFunction};
pub use rng::Rng;
pub use scene::{Lit, Scene, VolumeScene, WithShape};
pub use shape::{BoundaryShape, DeviceBoundary, DeviceExit, Shape};
pub use spectral::{HeroChannel, SpectralState};

/// Linear RGB radiance, throughput or albedo.
pub type Spectrum = glam::Vec3;
pub use glam::{Vec2, Vec3};
