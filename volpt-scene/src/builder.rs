//! From a scene source and the user's settings to a render-ready scene description.
//!
//! A [`SceneBuilder`] knows one source of scenes (a Mitsuba XML file, a volpt TOML scene, a bare
//! grid file, or anything a library user writes: a procedural volume, a database). The
//! [`SceneAssembler`] combines a builder with the [`Config`] the command line parsed: it passes the
//! parameters to the builder and applies the overrides to what the builder returns, so every source
//! gets `-D`, `--spp`, `--resolution` and the depth limits with the same meaning.

use std::path::{Path, PathBuf};

use crate::description::{Bounds, SceneDescription};
use crate::error::SceneError;
use crate::validate::CheckedData;
use crate::{mitsuba, toml_scene};

/// One source of scenes.
pub trait SceneBuilder {
    /// What the scene comes from, for logs and `volpt info` (a path, a generator's name).
    fn source(&self) -> String;

    /// Builds the scene (the [`SceneAssembler`] validates it, [`crate::validate`]); `params` are `(name, value)` pairs from `-D name=value`, which the source
    /// may use or ignore.
    fn build(&self, params: &[(String, String)]) -> Result<SceneDescription, SceneError>;
}

/// A Mitsuba 0.5/0.6 or 3 XML scene file.
pub struct MitsubaXml(pub PathBuf);

impl SceneBuilder for MitsubaXml {
    fn source(&self) -> String {
        self.0.display().to_string()
    }

    fn build(&self, params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        mitsuba::load(&self.0, params)
    }
}

/// A volpt TOML scene file (format: `docs/guide.md`, "volpt TOML scenes").
pub struct TomlScene(pub PathBuf);

impl SceneBuilder for TomlScene {
    fn source(&self) -> String {
        self.0.display().to_string()
    }

    fn build(&self, params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        toml_scene::load(&self.0, params)
    }
}

/// A grid file on its own (`.mha`, `.mhd`, `.vtk`, `.vti`, `.vol`, `.vdb`, `.nrrd`, `.nhdr`,
/// `.tif`, `.tiff`, `.dcm`, or a folder: a TIFF stack or a DICOM series): the volume is scaled and
/// centred into the unit cube at the origin (keeping its aspect), its values normalised onto
/// density `[0, 100]`, and rendered in the thesis setup of a TOML scene with only `[volume]`.
pub struct GridFile(pub PathBuf);

/// The density a bare grid file's maximum maps to: a dense, scattering unit cube.
pub const GRID_FILE_DENSITY: f32 = 100.0;

impl SceneBuilder for GridFile {
    fn source(&self) -> String {
        self.0.display().to_string()
    }

    fn build(&self, params: &[(String, String)]) -> Result<SceneDescription, SceneError> {
        let mut desc = toml_scene::load_volume_only(&self.0, params)?;
        let crate::DensityDesc::Grid(grid) = &mut desc.medium.density else {
            unreachable!("a grid file gives a grid density");
        };
        // Checked before it is scaled: an empty box has no longest side to scale by.
        crate::validate::check_bounds(grid.bounds).map_err(|found| SceneError::InvalidScene {
            source_name: self.source(),
            field: "the grid's bounding box".into(),
            expected: crate::validate::BOX.into(),
            found,
        })?;
        grid.bounds = fit_unit_cube(grid.bounds);
        desc.boundary.bounds = grid.bounds;
        *grid = crate::normalise(std::mem::replace(grid, empty_grid()), GRID_FILE_DENSITY);
        if let crate::AlbedoDesc::Grid(albedo) = &mut desc.medium.albedo {
            albedo.bounds = desc.boundary.bounds;
        }
        Ok(desc)
    }
}

fn empty_grid() -> crate::GridDesc {
    crate::GridDesc {
        layout: crate::description::SampleLayout::Dense,
        resolution: [1; 3],
        channels: 1,
        bounds: Bounds {
            min: [0.0; 3],
            max: [1.0; 3],
        },
        convention: crate::GridConvention::Cell,
        data: vec![0.0],
    }
}

/// `b` scaled uniformly so that its longest side is 1, centred at the origin.
fn fit_unit_cube(b: Bounds) -> Bounds {
    let extent = [0, 1, 2].map(|i| b.max[i] - b.min[i]);
    let longest = extent.iter().copied().fold(0.0f32, f32::max);
    let half = extent.map(|e| 0.5 * e / longest);
    Bounds {
        min: half.map(|h| -h),
        max: half,
    }
}

/// The builder for a scene file, chosen by its extension.
pub fn builder_for(path: &Path) -> Result<Box<dyn SceneBuilder>, SceneError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    Ok(match extension.as_deref() {
        Some("xml") => Box::new(MitsubaXml(path.to_owned())),
        Some("toml") => Box::new(TomlScene(path.to_owned())),
        Some(
            "mha" | "mhd" | "vtk" | "vti" | "vol" | "vdb" | "nrrd" | "nhdr" | "tif" | "tiff" | "dcm"
            | "dicom",
        ) => Box::new(GridFile(path.to_owned())),
        // A folder: a TIFF stack or a DICOM series.
        _ if path.is_dir() => Box::new(GridFile(path.to_owned())),
        _ => {
            return Err(SceneError::Unsupported {
                path: path.to_owned(),
                line: 0,
                what: "this kind of scene file".into(),
                reason: "expected a Mitsuba .xml, a volpt .toml scene, or a grid file \
                         (.mha, .mhd, .vtk, .vti, .vol, .vdb, .nrrd, .nhdr, .tif, .tiff, .dcm) or a folder \
                         (a TIFF stack or a DICOM series)"
                    .into(),
            })
        }
    })
}

/// What the user asked for on the command line, beyond the scene file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Config {
    /// `-D name=value`, in order: later ones win.
    pub params: Vec<(String, String)>,
    pub spp: Option<u32>,
    /// `(width, height)` of the film.
    pub resolution: Option<(u32, u32)>,
    /// Mitsuba's `max_depth`: `Some(None)` is unlimited (-1).
    pub max_depth: Option<Option<u32>>,
    /// Mitsuba's `rr_depth`: `Some(None)` disables Russian roulette (-1), but for paths of
    /// negligible weight.
    pub rr_depth: Option<Option<u32>>,
}

/// Combines a [`Config`] with a [`SceneBuilder`].
pub struct SceneAssembler {
    pub config: Config,
}

impl SceneAssembler {
    pub fn new(config: Config) -> Self {
        Self { config }
    }

    /// The builder's scene with the config's overrides applied, refused if `f32` positions cannot
    /// resolve its free flights ([`crate::numerics`]).
    pub fn assemble(&self, builder: &dyn SceneBuilder) -> Result<SceneDescription, SceneError> {
        self.assemble_checked(builder).map(|(desc, _)| desc)
    }

    /// [`SceneAssembler::assemble`], with what checking the scene's data found (to check the
    /// scene again after its settings change without reading the data: [`validate_settings`]).
    ///
    /// [`validate_settings`]: crate::validate::validate_settings
    pub fn assemble_checked(
        &self,
        builder: &dyn SceneBuilder,
    ) -> Result<(SceneDescription, CheckedData), SceneError> {
        let c = &self.config;
        let mut desc = builder.build(&c.params)?;
        tracing::debug!(source = %builder.source(), "built scene");
        if let Some(spp) = c.spp {
            desc.spp = spp;
        }
        if let Some((width, height)) = c.resolution {
            desc.film.width = width;
            desc.film.height = height;
        }
        if let Some(max_depth) = c.max_depth {
            desc.integrator.max_depth = max_depth;
        }
        if let Some(rr_depth) = c.rr_depth {
            desc.integrator.rr_depth = rr_depth;
        }
        // Too dense for f32 positions first: its message says how to rescale the scene.
        crate::numerics::check_position_resolution(&desc, Path::new(&builder.source()))?;
        let checked = crate::validate::validate(&desc, &builder.source())?;
        Ok((desc, checked))
    }
}
