//! Recognising axis-aligned boxes: volpt's boundary and grids must be ones.

use super::transform::{apply_point, Transform};
use crate::description::Bounds;

/// Relative tolerance for "lies on the box's corner" and "is zero".
const TOLERANCE: f64 = 1e-5;

/// The axis-aligned box whose corners are exactly `points` (repeats allowed, as meshes often list
/// a corner once per face), or `None` if some point is not a corner, some corner is absent or
/// the box is flat.
pub(crate) fn box_from_corners(points: &[[f64; 3]]) -> Option<Bounds> {
    let first = points.first()?;
    let (mut min, mut max) = (*first, *first);
    for p in points {
        for a in 0..3 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    // Relative to the box's size, not to its distance from the origin: a unit box at 1e5 is a box.
    let extent = (0..3).map(|a| max[a] - min[a]).fold(0.0, f64::max);
    let tol = TOLERANCE * extent;
    if extent == 0.0 || (0..3).any(|a| max[a] - min[a] <= tol) {
        return None;
    }
    let mut corners_seen = 0u8;
    for p in points {
        let mut corner = 0;
        for a in 0..3 {
            if (p[a] - max[a]).abs() <= tol {
                corner |= 1 << a;
            } else if (p[a] - min[a]).abs() > tol {
                return None;
            }
        }
        corners_seen |= 1 << corner;
    }
    (corners_seen == 0xff).then(|| to_bounds(min, max))
}

/// The image of the box `[min, max]` under `m`, if it is still an axis-aligned box.
pub(crate) fn transformed_box(m: &Transform, min: [f64; 3], max: [f64; 3]) -> Option<Bounds> {
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|c| {
            let pick = |a: usize| if c & (1 << a) != 0 { max[a] } else { min[a] };
            apply_point(m, [pick(0), pick(1), pick(2)])
        })
        .collect();
    box_from_corners(&corners)
}

/// The image of `[min, max]` under `m` if `m` only scales each axis by a positive factor and
/// translates: a grid's samples stay in x-fastest order only under such transforms.
pub(crate) fn scaled_box(m: &Transform, min: [f64; 3], max: [f64; 3]) -> Option<Bounds> {
    let diagonal = (0..3).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    let tol = TOLERANCE * diagonal;
    let off_diagonal_zero = (0..3).all(|i| (0..3).all(|j| i == j || m[i][j].abs() <= tol));
    let positive = (0..3).all(|i| m[i][i] > tol);
    let affine = m[3] == [0.0, 0.0, 0.0, 1.0];
    if !(off_diagonal_zero && positive && affine) {
        return None;
    }
    let lo = apply_point(m, min);
    let hi = apply_point(m, max);
    (0..3).all(|a| hi[a] > lo[a]).then(|| to_bounds(lo, hi))
}

fn to_bounds(min: [f64; 3], max: [f64; 3]) -> Bounds {
    Bounds {
        min: min.map(|v| v as f32),
        max: max.map(|v| v as f32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_corners(lo: f64, hi: f64) -> Vec<[f64; 3]> {
        (0..8)
            .map(|c| [0, 1, 2].map(|a| if c & (1 << a) != 0 { hi } else { lo }))
            .collect()
    }

    #[test]
    fn accepts_corners_with_repeats() {
        let mut pts = cube_corners(-1.0, 2.0);
        pts.extend(cube_corners(-1.0, 2.0));
        let b = box_from_corners(&pts).unwrap();
        assert_eq!(b.min, [-1.0; 3]);
        assert_eq!(b.max, [2.0; 3]);
    }

    #[test]
    fn rejects_missing_corner_extra_point_and_flat_box() {
        let pts = cube_corners(0.0, 1.0);
        assert!(box_from_corners(&pts[..7]).is_none());
        let mut extra = pts.clone();
        extra.push([0.5, 0.5, 0.5]);
        assert!(box_from_corners(&extra).is_none());
        let flat: Vec<_> = pts.iter().map(|p| [p[0], p[1], 0.0]).collect();
        assert!(box_from_corners(&flat).is_none());
        assert!(box_from_corners(&[]).is_none());
    }

    /// The tolerance scales with the box: a box 1e-4 across is a box, and so is one 1e4 across
    /// whose corners are off by a relative 1e-6 (1e-2), as a mesh's rounded corners are.
    #[test]
    fn tolerance_is_relative_to_the_box_size() {
        let small = box_from_corners(&cube_corners(0.0, 1e-4)).expect("a small box");
        assert_eq!(small.max, [1e-4; 3]);
        let mut large = cube_corners(-5e3, 5e3);
        large[3][0] += 1e-2;
        large[5][2] -= 1e-2;
        assert!(box_from_corners(&large).is_some());
        large[6][1] += 1.0;
        assert!(box_from_corners(&large).is_none());
    }
}
