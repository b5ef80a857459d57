//! Rescaling a grid's values onto `[0, target_max]`.
//!
//! Volume files store whatever their producer measured: `Bucky.raw` holds counts 0-255, a CT scan
//! Hounsfield-like integers, a simulation densities in its own units. volpt's extinction is
//! `scale * density` per world unit, so a file's numbers rarely are the density a scene wants.
//! [`normalise`] maps `[0, max]` linearly onto `[0, target_max]` (Bucky's 0-255 onto 0-40, say),
//! keeping zero at zero so empty space stays empty, which an affine `[min, max]` map would not.

use crate::description::GridDesc;

/// Scales every value by `target_max / max`, where `max` is the grid's largest value, so that
/// `[0, max]` maps onto `[0, target_max]`. A grid whose values are all zero is returned unchanged
/// (there is no scale that would reach `target_max`). `target_max` should be finite and >= 0, as
/// a density is; the readers already guarantee the grid's values are.
pub fn normalise(mut grid: GridDesc, target_max: f32) -> GridDesc {
    let max = grid.max_value();
    if max > 0.0 {
        // In f64, so that `max` itself lands exactly on `target_max` (255 -> 40.0, not 39.99999).
        let scale = f64::from(target_max) / f64::from(max);
        for v in grid.samples_mut() {
            *v = (f64::from(*v) * scale) as f32;
        }
    }
    grid
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::description::{Bounds, GridConvention};

    fn grid(data: Vec<f32>) -> GridDesc {
        GridDesc {
            layout: crate::description::SampleLayout::Dense,
            resolution: [data.len() as u32, 1, 1],
            channels: 1,
            bounds: Bounds {
                min: [0.0; 3],
                max: [1.0; 3],
            },
            convention: GridConvention::Cell,
            data,
        }
    }

    #[test]
    fn maps_zero_to_max_onto_zero_to_target() {
        let out = normalise(grid(vec![0.0, 51.0, 127.5, 255.0]), 40.0);
        assert_eq!(out.data, vec![0.0, 8.0, 20.0, 40.0]);
    }

    #[test]
    fn an_empty_grid_stays_empty() {
        assert_eq!(normalise(grid(vec![0.0; 4]), 40.0).data, vec![0.0; 4]);
    }
}
