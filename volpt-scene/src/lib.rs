//! volpt's scenes: the plain-data description a renderer consumes, and the loaders that build it.
//!
//! - [`description`]: the scene as plain data ([`SceneDescription`]).
//! - [`medium`], [`phase`], [`boundary`], [`environment`]: one axis of the scene each, everything about its
//!   descriptions: what they say, how each format spells them, their checks, their export, how
//!   `volpt info` prints them, and how each registry part of the axis is built from them.
//! - [`light`]: the lights besides the environment (a sun, a point or spot light), as the
//!   environment's file does it for the environment (no registry axis: a run-time part).
//! - [`from_description`]: the rule from a description to a registry part ([`FromDescription`]),
//!   and [`simplification`]: where a part is simpler than the description names.
//! - [`param`]: the numbers of a description a scene takes between renders.
//! - [`builder`]: [`SceneBuilder`]s (one per source) and the [`SceneAssembler`] that applies the
//!   command line's [`Config`] to what they build.
//! - [`material`]: material-indexed volumes (a table of materials and an index per voxel).
//! - [`slices`]: voxel-print slice stacks (a folder of PNG images whose colours name materials).
//! - [`toml_scene`]: volpt's own TOML scene files: one grid file, a transfer function, defaults.
//! - [`error`]: what can go wrong loading one ([`SceneError`]); every message names the file and,
//!   for XML, the line.
//! - [`vol`]: Mitsuba's `.vol` grid files, read and written.
//! - [`mitsuba`]: Mitsuba 0.5/0.6 and Mitsuba 3 XML scene files, read; Mitsuba 3 scenes, written.
//! - [`generate`]: the thesis's printed-block grids (`cgg-logo`, `ad`), generated rather than stored.
//! - [`raw`]: raw voxel files with a caller-given layout (such as `Bucky.raw`), read and written.
//! - [`metaimage`]: MetaImage `.mha`/`.mhd` grids, read and written.
//! - [`vdb`]: OpenVDB `.vdb` grids (float density, vec3 albedo), read sparse.
//! - [`sparse`]: sparse grids: stored 8^3 bricks and a brick table.
//! - [`nrrd`]: NRRD `.nrrd`/`.nhdr` grids (3D Slicer, ITK, pynrrd), read.
//! - [`tiff_stack`]: TIFF stacks (a multi-page TIFF or a folder of TIFFs), read.
//! - [`dicom`]: DICOM series (a folder of CT slices), read, in Hounsfield units above air.
//! - [`scanner`]: which of those reads a file or folder named without a format.
//! - [`orient`]: placing a scanner's grid, stepping along signed or permuted axes, on volpt's axes.
//! - [`vtk`]: VTK image data (legacy `STRUCTURED_POINTS` `.vtk`, XML `.vti`), read and written.
//! - [`transfer`]: transfer functions from density to RGB albedo, and their text files.
//! - [`limits`]: what untrusted input may make volpt allocate or do, checked before it does.
//! - [`validate`]: the check every assembled scene passes, whatever its format.
//! - [`normalise`]: rescaling a grid's values onto `[0, target]` (raw counts to densities).
//! - [`numerics`]: whether `f32` positions resolve a scene's free flights (checked on assembly).

pub mod boundary;
pub mod builder;
mod contain;
pub mod description;
pub mod dicom;
pub mod environment;
pub mod error;
pub mod from_description;
pub mod generate;
pub mod light;
pub mod limits;
pub mod material;
pub mod medium;
pub mod mesh;
pub mod metaimage;
pub mod mitsuba;
pub mod normalise;
pub mod nrrd;
pub mod numerics;
mod orient;
mod output;
pub mod param;
pub mod phase;
pub mod raw;
pub mod scanner;
pub mod simplification;
pub mod slices;
pub mod sparse;
pub mod tiff_stack;
pub mod toml_scene;
pub mod transfer;
pub mod validate;
pub mod vdb;
pub mod vol;
pub mod vtk;

use std::path::Path;

pub use boundary::BoundaryInput;
pub use builder::{builder_for, Config, SceneAssembler, SceneBuilder};
pub use description::*;
pub use dicom::read_dicom_series;
pub use error::{GridProblem, MaterialProblem, SceneError, VolProblem};
pub use from_description::FromDescription;
pub use medium::{MediumInput, ReadsRule};
pub use metaimage::{read_metaimage, write_metaimage, MetaImageOptions};
pub use normalise::normalise;
pub use nrrd::read_nrrd;
pub use param::NumberParam;
pub use raw::{read_raw, read_raw_into, write_raw, ByteOrder, RawLayout, ScalarType};
pub use simplification::Simplification;
pub use tiff_stack::read_tiff_stack;
pub use transfer::TransferFunction;
pub use vdb::{read_vdb, Sparsity, VdbOptions};
pub use vol::{read_vol, write_vol, VolGrid};
pub use vtk::{read_vtk, write_vtk};

/// Loads a Mitsuba XML scene with the `<default>` values it declares.
pub fn load_mitsuba(path: &Path) -> Result<SceneDescription, SceneError> {
    mitsuba::load(path, &[])
}

/// Loads a Mitsuba XML scene; `params` are `(name, value)` pairs, as `mitsuba -D name=value`
/// passes them, and take precedence over the scene's `<default>`s.
pub fn load_mitsuba_with(
    path: &Path,
    params: &[(String, String)],
) -> Result<SceneDescription, SceneError> {
    mitsuba::load(path, params)
}
