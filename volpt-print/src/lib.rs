//! Colour 3D printing on volpt: predicting a voxel print's appearance and compensating the
//! scattering that blurs its texture (Elek et al. 2017, "Scattering-aware texture reproduction
//! for 3D printing"). `docs/printing.md` states what exists and the model choices.
//!
//! - [`colour`]: sRGB, linear RGB, CIE XYZ, CIE L*a*b* (D65) and CIEDE2000.
//! - [`material`]: a print's material table (volpt-scene's [`MaterialDesc`]) and where its five inks are.
//! - [`print`]: a voxel print, one material index per voxel.
//! - [`slices`]: slice stacks (one PNG per layer and `materials.toml`), written and read.
//! - [`halftone`]: the printer's naive ink mix and its 3D ordered dithering into voxels.
//! - [`compensate`]: the scattering compensation loop, against a [`compensate::Predictor`].
//! - [`crosstalk`]: its update through the print's cross-texel response, fitted from its predictions.
//! - [`predict`]: the real predictor, a volpt render of the print from straight above.
//! - [`target`]: a compensation's target image, read from a PNG.
//! - [`regions`]: a target's texels classed by their distance to its ink (where an error lies).
//! - [`record`]: a compensation's record (predictions, ΔE maps and plot, the slice stack).
//! - [`job`]: a whole compensation as the front ends run it (CLI and Python).
//! - [`error`]: what reading or writing a print can refuse ([`PrintError`]).

pub mod colour;
pub mod compensate;
pub mod crosstalk;
pub mod error;
pub mod halftone;
pub mod job;
pub mod material;
pub mod predict;
pub mod print;
pub mod record;
pub mod regions;
pub mod slices;
pub mod target;

pub use error::PrintError;
pub use material::{Inks, MaterialFile};
pub use print::VoxelPrint;
pub use volpt_scene::material::MaterialDesc;
