//! [`RenderRequest`]: what one render chooses for itself, apart from the scene it renders.
//!
//! A [`crate::Scene`] is what was loaded (and what [`crate::Scene::set`] changed); a render's own
//! choices (which samples, which random streams, how paths are traced and the grids looked up)
//! are the request's, so that renders never change the scene they render: threads share one scene
//! and render it at once, each with its own request. A choice left `None` is the scene's.

use std::ops::Range;

use volpt_core::PathSettings;
use volpt_render::Effects;
use volpt_scene::GridLookup;

/// One render's samples and the choices it makes over the scene's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderRequest {
    /// The samples of every pixel to add to the film, which holds those before them.
    pub samples: Range<u32>,
    /// The seed of the random streams (default: the scene's).
    pub seed: Option<u32>,
    /// Tracking, estimator, roulette and depths (default: the scene's).
    pub path: Option<PathSettings>,
    /// How the grids are reconstructed (default: the scene's if chosen, else the backend's
    /// default, [`crate::Backend::default_lookup`]); refused where the grids cannot take it.
    pub lookup: Option<GridLookup>,
    /// The variant specialised to the scene's effects or the most general one (default: the
    /// scene's).
    pub effects: Option<Effects>,
}

impl RenderRequest {
    /// Samples `samples` with the scene's every other choice.
    pub fn samples(samples: Range<u32>) -> Self {
        Self {
            samples,
            ..Self::default()
        }
    }

    pub fn with_seed(self, seed: u32) -> Self {
        Self {
            seed: Some(seed),
            ..self
        }
    }

    pub fn with_path(self, path: PathSettings) -> Self {
        Self {
            path: Some(path),
            ..self
        }
    }

    pub fn with_lookup(self, lookup: GridLookup) -> Self {
        Self {
            lookup: Some(lookup),
            ..self
        }
    }

    pub fn with_effects(self, effects: Effects) -> Self {
        Self {
            effects: Some(effects),
            ..self
        }
    }
}

impl From<Range<u32>> for RenderRequest {
    fn from(samples: Range<u32>) -> Self {
        Self::samples(samples)
    }
}

impl From<&RenderRequest> for RenderRequest {
    fn from(request: &RenderRequest) -> Self {
        request.clone()
    }
}
