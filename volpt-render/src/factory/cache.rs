//! [`FactoryCache`]: what the factory reads from a scene's grids, kept between builds of one scene.
//!
//! The factory builds a scene again for every render (a viewer's every frame, every batch of
//! several GPUs), but a scene's grids do not change once assembled: whether a grid holds one value
//! and the majorant grid of its density need not be computed again unless the density's scale,
//! the box or the majorant resolution changed. Each result is kept with the identity (address and
//! length) of the data it was computed from, and served only for that data.

use std::sync::{Arc, Mutex};

use volpt_core::grid::{Grid, GridLookup, GridMapping};
use volpt_core::majorant::build_majorants;
use volpt_core::Aabb;

/// One scene's factory results. A cache belongs to one scene (one description's grids): with
/// another description's grids it computes afresh and keeps nothing, but it cannot tell a freed
/// grid from a new one at the same address, so it must not outlive its scene's grids.
#[derive(Debug, Default)]
pub struct FactoryCache {
    /// Whether each grid, by its data's identity, holds a single value (per channel).
    uniform: Mutex<Vec<(DataId, bool)>>,
    /// The last majorant grid built and what it was built from.
    majorants: Mutex<Option<(MajorantKey, Arc<Majorants>)>>,
}

/// A grid's data: its address and length.
type DataId = (usize, usize);

fn id_of(data: &[f32]) -> DataId {
    (data.as_ptr() as usize, data.len())
}

/// A majorant grid's per-cell bounds and resolution.
#[derive(Debug)]
pub struct Majorants {
    pub data: Vec<f32>,
    pub res: [u32; 3],
}

/// Everything [`build_majorants`] reads.
#[derive(Debug, PartialEq)]
struct MajorantKey {
    density: DataId,
    density_res: [u32; 3],
    mapping: GridMapping,
    lookup: GridLookup,
    scale: u32,
    bounds: Aabb,
    res: [u32; 3],
}

impl FactoryCache {
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether `data`, of `channels` values per sample, holds one value everywhere.
    pub fn is_uniform(&self, data: &[f32], channels: usize) -> bool {
        let id = id_of(data);
        let mut known = self.uniform.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&(_, uniform)) = known.iter().find(|(d, _)| *d == id) {
            return uniform;
        }
        let uniform = data
            .get(..channels)
            .is_some_and(|first| data.chunks_exact(channels).all(|v| v == first));
        known.push((id, uniform));
        uniform
    }

    /// The majorant grid of `density` x `scale` over `bounds` at `res`.
    pub fn majorants(
        &self,
        density: &Grid<'_, 1>,
        scale: f32,
        bounds: Aabb,
        res: [u32; 3],
    ) -> Arc<Majorants> {
        let key = MajorantKey {
            density: id_of(density.data),
            density_res: density.res,
            mapping: density.mapping,
            lookup: density.lookup,
            scale: scale.to_bits(),
            bounds,
            res,
        };
        let mut last = self.majorants.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((k, built)) = last.as_ref() {
            if *k == key {
                return built.clone();
            }
        }
        let mut data = vec![0.0; res.iter().map(|&r| r as usize).product()];
        build_majorants(density, scale, bounds, res, &mut data);
        let built = Arc::new(Majorants { data, res });
        *last = Some((key, built.clone()));
        built
    }
}
