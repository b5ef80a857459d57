//! Scanner grids placed on volpt's axes: a grid whose file axes step along signed, possibly
//! permuted world axes (NRRD's `space directions`, DICOM's `ImageOrientationPatient`), stored
//! again x fastest along +x, +y, +z, as [`GridDesc`] holds every grid.
//!
//! A file gives voxel `(i, j, k)`'s centre as `origin + i d0 + j d1 + k d2`. volpt's grids are
//! axis-aligned, so each step `d` must lie along one world axis (its other components below
//! [`AXIS_TOLERANCE`] of its length), each axis taken once; a negative step mirrors that axis, which
//! the reordering undoes, so the voxel at a world position is the one the file puts there. The
//! result is cell-centred: its box is the voxel centres' span widened by half a spacing.

use std::path::Path;

use crate::description::{GridConvention, GridDesc, SampleLayout};
use crate::error::{GridProblem, SceneError};
use crate::raw::{centred_bounds, grid_error};

/// How far from a world axis a step may point, relative to its length: scanners write direction
/// cosines with a few digits (`0.99999998`), and anything beyond this is a rotated grid.
pub const AXIS_TOLERANCE: f64 = 1e-4;

/// Places a grid of `resolution` voxels (file order, x fastest) with `channels` values each: voxel
/// `(i, j, k)` centred at `origin + i * steps[0] + j * steps[1] + k * steps[2]`. `field` names
/// the header field the steps came from, in errors.
pub(crate) fn place(
    path: &Path,
    field: &str,
    resolution: [u32; 3],
    channels: u32,
    data: Vec<f32>,
    origin: [f64; 3],
    steps: [[f64; 3]; 3],
) -> Result<GridDesc, SceneError> {
    let mut axis_of = [0usize; 3];
    let mut taken = [false; 3];
    for (i, step) in steps.iter().enumerate() {
        let axis = (0..3)
            .max_by(|&a, &b| step[a].abs().total_cmp(&step[b].abs()))
            .unwrap_or(0);
        let length = step.iter().map(|c| c * c).sum::<f64>().sqrt();
        let aligned = length > 0.0
            && length.is_finite()
            && (0..3).all(|a| a == axis || step[a].abs() <= AXIS_TOLERANCE * length);
        if !aligned || taken[axis] {
            return Err(grid_error(
                path,
                GridProblem::Unsupported {
                    what: format!("{field} {steps:?}"),
                    reason: "volpt's grids are axis-aligned: each file axis must step along a \
                             different world axis (a rotated or sheared grid needs resampling first)"
                        .into(),
                },
            ));
        }
        taken[axis] = true;
        axis_of[i] = axis;
    }

    let mut world_resolution = [0u32; 3];
    let mut spacing = [0.0f64; 3];
    let mut first_centre = [0.0f64; 3];
    for i in 0..3 {
        let w = axis_of[i];
        let step = steps[i][w];
        world_resolution[w] = resolution[i];
        spacing[w] = step.abs();
        // The lowest centre along w: the first voxel's, or the last's when the axis is mirrored.
        first_centre[w] = origin[w]
            + if step < 0.0 {
                f64::from(resolution[i] - 1) * step
            } else {
                0.0
            };
    }
    let bounds = centred_bounds(first_centre, spacing, world_resolution).ok_or_else(|| {
        grid_error(
            path,
            GridProblem::BadField {
                line: None,
                field: field.into(),
                expected: "steps and an origin giving a box with finite f32 bounds".into(),
                found: format!("steps {steps:?}, origin {origin:?}"),
            },
        )
    })?;

    let identity = (0..3).all(|i| axis_of[i] == i && steps[i][i] > 0.0);
    let data = if identity {
        data
    } else {
        reorder(&data, resolution, channels, axis_of, steps)
    };
    Ok(GridDesc {
        layout: SampleLayout::Dense,
        resolution: world_resolution,
        channels,
        bounds,
        convention: GridConvention::Cell,
        data,
    })
}

/// The file-ordered `data` stored along +x, +y, +z: world voxel `p` takes file voxel `f` with
/// `f[i] = p[axis_of[i]]`, counted from the far end where file axis `i` steps backwards.
fn reorder(
    data: &[f32],
    resolution: [u32; 3],
    channels: u32,
    axis_of: [usize; 3],
    steps: [[f64; 3]; 3],
) -> Vec<f32> {
    let n = resolution.map(|r| r as usize);
    let c = channels as usize;
    let mut world_n = [0usize; 3];
    for i in 0..3 {
        world_n[axis_of[i]] = n[i];
    }
    let mut out = Vec::with_capacity(data.len());
    for z in 0..world_n[2] {
        for y in 0..world_n[1] {
            for x in 0..world_n[0] {
                let p = [x, y, z];
                let f = [0, 1, 2].map(|i| {
                    let along = p[axis_of[i]];
                    if steps[i][axis_of[i]] < 0.0 {
                        n[i] - 1 - along
                    } else {
                        along
                    }
                });
                let at = ((f[2] * n[1] + f[1]) * n[0] + f[0]) * c;
                out.extend_from_slice(&data[at..at + c]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steps(d: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
        d
    }

    #[test]
    fn a_mirrored_axis_is_stored_forwards_with_the_box_where_the_file_puts_it() {
        // Two voxels along x stepping -2 from x = 10: centres at 10 and 8.
        let grid = place(
            Path::new("t"),
            "steps",
            [2, 1, 1],
            1,
            vec![1.0, 2.0],
            [10.0, 0.0, 0.0],
            steps([[-2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
        )
        .unwrap();
        assert_eq!(grid.data, vec![2.0, 1.0]);
        assert_eq!(grid.bounds.min, [7.0, -0.5, -0.5]);
        assert_eq!(grid.bounds.max, [11.0, 0.5, 0.5]);
    }

    #[test]
    fn permuted_axes_swap_the_resolution_and_transpose_the_data() {
        // File axis 0 steps along world y, file axis 1 along world x.
        let grid = place(
            Path::new("t"),
            "steps",
            [3, 2, 1],
            1,
            (0..6).map(|v| v as f32).collect(),
            [0.0; 3],
            steps([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
        )
        .unwrap();
        assert_eq!(grid.resolution, [2, 3, 1]);
        // World (x, y) takes file (i = y, j = x): file value j * 3 + i.
        assert_eq!(grid.data, vec![0.0, 3.0, 1.0, 4.0, 2.0, 5.0]);
    }

    #[test]
    fn a_rotated_grid_is_refused() {
        let err = place(
            Path::new("t"),
            "steps",
            [1, 1, 1],
            1,
            vec![0.0],
            [0.0; 3],
            steps([[0.7, 0.7, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]),
        )
        .unwrap_err();
        assert!(err.to_string().contains("axis-aligned"), "{err}");
    }
}
