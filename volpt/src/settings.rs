//! [`RenderSettings`]: what a user overrides of a scene file's own values.
//!
//! Precedence: the scene file (with its `-D` parameters), then these settings. A field left `None`
//! keeps the scene file's value; `volpt render`'s flags, the Python package's keyword arguments and
//! the viewer's controls all fill this one type. [`crate::Scene::load`] resolves it once into the
//! scene's description and its [`PathSettings`].

use volpt_core::{Estimator, PathSettings, Roulette};
use volpt_render::{path_settings, Effects};
use volpt_scene::{Config, GridLookup, SceneDescription};

use crate::{Error, Named};

/// How a render traces and samples, over the scene file's values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderSettings {
    /// Mitsuba's `-D name=value` scene parameters, in order: later ones win.
    pub params: Vec<(String, String)>,
    /// Samples per pixel (the scene's sampler).
    pub spp: Option<u32>,
    /// Film `(width, height)`.
    pub resolution: Option<(u32, u32)>,
    /// Longest path (Mitsuba's `max_depth`); `Some(None)` is unlimited (-1).
    pub max_depth: Option<Option<u32>>,
    /// Depth from which Russian roulette starts (Mitsuba's `rr_depth`); `Some(None)` disables it,
    /// except for paths of negligible weight (`volpt_core::path::NEGLIGIBLE_WEIGHT`).
    pub rr_depth: Option<Option<u32>>,
    /// One global majorant or a majorant grid (default: chosen per scene by the factory).
    pub tracking: Option<Tracking>,
    /// Cells of the majorant grid along the box's longest axis (1 is the global majorant).
    pub majorant_resolution: Option<u32>,
    /// How paths gather the environment's light (default: NEE for a lat-long map behind an
    /// index-matched boundary, path tracing elsewhere).
    pub estimator: Option<Estimator>,
    /// How the medium's grids are reconstructed between samples (default: the scene's).
    pub lookup: Option<GridLookup>,
    /// Russian roulette's survival probability (default: Mitsuba's).
    pub roulette: Option<Roulette>,
    /// The variant specialised to the scene's effects (default) or the most general one.
    pub effects: Effects,
    /// Seed of the random streams: the same seed gives the same image on every backend.
    pub seed: u32,
    /// CPU worker threads (default: every core); GPUs ignore it.
    pub threads: Option<usize>,
}

/// The cells of a majorant grid along the box's longest axis a setting may ask for
/// ([`RenderSettings::majorant_resolution`]; 1 is the global majorant).
pub const MAJORANT_RESOLUTION: std::ops::RangeInclusive<u32> = 1..=1024;

/// `cells` if a majorant grid may have so many cells along its longest axis
/// ([`MAJORANT_RESOLUTION`]), else [`Error::Setting`].
pub fn check_majorant_resolution(cells: u32) -> Result<u32, Error> {
    if MAJORANT_RESOLUTION.contains(&cells) {
        return Ok(cells);
    }
    Err(Error::Setting {
        key: "majorant_resolution",
        expected: format!(
            "{} to {} cells",
            MAJORANT_RESOLUTION.start(),
            MAJORANT_RESOLUTION.end()
        ),
        found: cells.to_string(),
    })
}

/// Delta and ratio tracking under one majorant or a grid of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tracking {
    /// One majorant, the densest voxel's extinction, everywhere.
    Global,
    /// A majorant per cell of a coarse grid, walked by a 3D DDA.
    Grid,
}

impl RenderSettings {
    /// The part the scene assembler applies while it builds the description.
    pub fn config(&self) -> Config {
        Config {
            params: self.params.clone(),
            spp: self.spp,
            resolution: self.resolution,
            max_depth: self.max_depth,
            rr_depth: self.rr_depth,
        }
    }

    /// The scene's integrator settings with these tracking, estimator and roulette choices.
    pub fn path_settings(&self, desc: &SceneDescription) -> Result<PathSettings, Error> {
        self.path_over(path_settings(desc))
    }

    /// `base` (a scene's path settings, [`crate::Scene::path_settings`]) with these settings'
    /// choices of depths, tracking and majorant resolution, estimator and roulette over it,
    /// checked as [`crate::Scene::load`] checks them: the path settings of a
    /// [`crate::RenderRequest`] that asks for other choices than its scene's.
    pub fn path_over(&self, base: PathSettings) -> Result<PathSettings, Error> {
        let mut settings = base;
        let depth = |d: Option<u32>| d.unwrap_or(PathSettings::UNLIMITED);
        if let Some(max_depth) = self.max_depth {
            settings.max_depth = depth(max_depth);
        }
        if let Some(rr_depth) = self.rr_depth {
            settings.rr_depth = depth(rr_depth);
        }
        settings.majorant_resolution =
            match (self.tracking, self.majorant_resolution) {
                (Some(Tracking::Global), Some(r)) if r > 1 => return Err(Error::conflict(
                    "majorant_resolution",
                    r,
                    Tracking::KEY,
                    Tracking::Global.name(),
                    "global tracking uses one majorant, and a resolution above 1 asks for a grid \
                     of them",
                )
                .or_use(Tracking::KEY, Tracking::Grid.name())),
                (Some(Tracking::Global), _) => 1,
                (_, Some(r)) => check_majorant_resolution(r)?,
                (Some(Tracking::Grid), None) if settings.majorant_resolution <= 1 => {
                    PathSettings::DEFAULT_MAJORANT_RESOLUTION
                }
                (_, None) => settings.majorant_resolution,
            };
        if let Some(roulette) = self.roulette {
            settings.roulette = roulette;
        }
        if let Some(estimator) = self.estimator {
            settings.estimator = estimator;
        }
        Ok(settings)
    }

    /// Refuses a thread count that is no CPU render: threads beyond the cores only cost memory and
    /// start-up, and tens of thousands of them exhaust the system before the render starts.
    pub fn check_threads(&self) -> Result<(), Error> {
        let Some(threads) = self.threads else {
            return Ok(());
        };
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        let most = 4 * cores;
        if !(1..=most).contains(&threads) {
            return Err(Error::Setting {
                key: "threads",
                expected: format!("1 to {most} (4 x the {cores} cores of this machine)"),
                found: threads.to_string(),
            });
        }
        Ok(())
    }
}
