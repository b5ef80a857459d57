//! Trilinear grid lookups for both sample conventions, against an independent f64 reference.
//!
//! Tolerances: lookups are f32 (positions of size ~5 are rounded to ~5e-7, interpolation weights to
//! ~1e-7) with sample values in [-1, 1] or a linear function of size <= 10, so 1e-5 relative to the
//! value range is tens of ulps; an indexing or weighting error is off by O(1).

mod common;

use common::*;
use volpt_core::{Aabb, Grid, GridLookup, GridMapping, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Convention {
    Vertex,
    Cell,
}

const CONVENTIONS: [Convention; 2] = [Convention::Vertex, Convention::Cell];

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5))
}

fn mapping(convention: Convention, res: [u32; 3]) -> GridMapping {
    match convention {
        Convention::Vertex => GridMapping::vertex_centred(bounds(), res),
        Convention::Cell => GridMapping::cell_centred(bounds(), res),
    }
}

/// World position of sample `i` along `axis`: `min + i / (res - 1) * extent` (vertex) or
/// `min + (i + 0.5) / res * extent` (cell), in f64.
fn sample_position(convention: Convention, res: [u32; 3], axis: usize, i: u32) -> f64 {
    let b = bounds();
    let (lo, hi) = (b.min[axis] as f64, b.max[axis] as f64);
    let n = res[axis] as f64;
    let frac = match convention {
        Convention::Vertex if res[axis] == 1 => 0.0,
        Convention::Vertex => i as f64 / (n - 1.0),
        Convention::Cell => (i as f64 + 0.5) / n,
    };
    lo + frac * (hi - lo)
}

/// The box spanned by the samples, where interpolation (rather than clamping) happens.
fn sample_hull(convention: Convention, res: [u32; 3]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for a in 0..3 {
        lo[a] = sample_position(convention, res, a, 0);
        hi[a] = sample_position(convention, res, a, res[a] - 1);
    }
    (lo, hi)
}

/// Trilinear interpolation in f64, written from the definition: the continuous index along each
/// axis is the position mapped so that sample i sits at i, clamped to [0, res - 1].
fn reference<const C: usize>(
    data: &[f32],
    res: [u32; 3],
    convention: Convention,
    p: [f64; 3],
) -> [f64; C] {
    let b = bounds();
    let mut lower = [0usize; 3];
    let mut upper = [0usize; 3];
    let mut frac = [0.0; 3];
    for a in 0..3 {
        let (lo, hi) = (b.min[a] as f64, b.max[a] as f64);
        if p[a] < lo || p[a] > hi {
            return [0.0; C];
        }
        let n = res[a] as f64;
        let u = match convention {
            Convention::Vertex => (p[a] - lo) / (hi - lo) * (n - 1.0),
            Convention::Cell => (p[a] - lo) / (hi - lo) * n - 0.5,
        }
        .clamp(0.0, n - 1.0);
        let i0 = (u.floor() as usize).min(res[a].saturating_sub(2) as usize);
        lower[a] = i0;
        upper[a] = (i0 + 1).min(res[a] as usize - 1);
        frac[a] = u - i0 as f64;
    }
    let mut out = [0.0; C];
    for corner in 0..8 {
        let mut w = 1.0;
        let mut idx = [0usize; 3];
        for a in 0..3 {
            let high = corner >> a & 1 == 1;
            idx[a] = if high { upper[a] } else { lower[a] };
            w *= if high { frac[a] } else { 1.0 - frac[a] };
        }
        let i = ((idx[2] * res[1] as usize + idx[1]) * res[0] as usize + idx[0]) * C;
        for c in 0..C {
            out[c] += w * data[i + c] as f64;
        }
    }
    out
}

fn random_data(rng: &mut TestRng, res: [u32; 3], channels: usize) -> Vec<f32> {
    let n = (res[0] * res[1] * res[2]) as usize * channels;
    (0..n).map(|_| rng.range(-1.0, 1.0) as f32).collect()
}

fn random_point(rng: &mut TestRng, lo: [f64; 3], hi: [f64; 3]) -> [f64; 3] {
    [
        rng.range(lo[0], hi[0]),
        rng.range(lo[1], hi[1]),
        rng.range(lo[2], hi[2]),
    ]
}

fn to_vec3(p: [f64; 3]) -> Vec3 {
    Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
}

/// The f32 position actually looked up, back in f64 (so that the reference sees the same point).
fn rounded(p: [f64; 3]) -> [f64; 3] {
    let v = to_vec3(p);
    [v.x as f64, v.y as f64, v.z as f64]
}

const RESOLUTIONS: [[u32; 3]; 4] = [[4, 3, 5], [2, 2, 2], [1, 4, 3], [1, 1, 1]];

#[test]
fn samples_are_reproduced_at_their_positions() {
    let mut rng = TestRng::new(31);
    for convention in CONVENTIONS {
        for res in RESOLUTIONS {
            let data = random_data(&mut rng, res, 1);
            let grid = Grid::<1>::new(&data, res, mapping(convention, res));
            for z in 0..res[2] {
                for y in 0..res[1] {
                    for x in 0..res[0] {
                        let p = [
                            sample_position(convention, res, 0, x),
                            sample_position(convention, res, 1, y),
                            sample_position(convention, res, 2, z),
                        ];
                        let expected = data[((z * res[1] + y) * res[0] + x) as usize];
                        let got = grid.lookup(to_vec3(p))[0];
                        assert!(
                            (got - expected).abs() < 1e-5,
                            "{convention:?} {res:?} sample {:?}: {got} vs {expected}",
                            (x, y, z)
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn linear_functions_are_reproduced_inside_the_sample_hull() {
    // Trilinear interpolation is exact for f = a x + b y + c z + d; between the hull and the box's
    // faces (cell-centred samples) the outermost samples are held constant, so the lookup is f at
    // the point clamped to the hull.
    let (a, b, c, d) = (1.3f64, -2.1, 0.7, 0.25);
    let f = |p: [f64; 3]| a * p[0] + b * p[1] + c * p[2] + d;
    let mut rng = TestRng::new(32);
    let bx = bounds();
    let box_lo = [bx.min.x as f64, bx.min.y as f64, bx.min.z as f64];
    let box_hi = [bx.max.x as f64, bx.max.y as f64, bx.max.z as f64];
    for convention in CONVENTIONS {
        let res = [4u32, 3, 5];
        let mut data = Vec::new();
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    data.push(f([
                        sample_position(convention, res, 0, x),
                        sample_position(convention, res, 1, y),
                        sample_position(convention, res, 2, z),
                    ]) as f32);
                }
            }
        }
        let grid = Grid::<1>::new(&data, res, mapping(convention, res));
        let (hull_lo, hull_hi) = sample_hull(convention, res);
        for _ in 0..10_000 {
            let p = rounded(random_point(&mut rng, hull_lo, hull_hi));
            let got = grid.lookup(to_vec3(p))[0] as f64;
            // |f| <= 10 here: 1e-5 is ~ten f32 ulps of the inputs and the result.
            assert!(
                (got - f(p)).abs() < 1e-5 * 10.0,
                "{convention:?} {p:?}: {got} vs {}",
                f(p)
            );
            let q = rounded(random_point(&mut rng, box_lo, box_hi));
            let clamped = [0, 1, 2].map(|i| q[i].clamp(hull_lo[i], hull_hi[i]));
            let got = grid.lookup(to_vec3(q))[0] as f64;
            assert!(
                (got - f(clamped)).abs() < 1e-4,
                "{convention:?} {q:?}: {got} vs {}",
                f(clamped)
            );
        }
    }
}

#[test]
fn random_grids_match_the_f64_reference() {
    let mut rng = TestRng::new(33);
    let b = bounds();
    let lo = [b.min.x as f64, b.min.y as f64, b.min.z as f64];
    let hi = [b.max.x as f64, b.max.y as f64, b.max.z as f64];
    for convention in CONVENTIONS {
        for res in RESOLUTIONS {
            let data = random_data(&mut rng, res, 1);
            let grid = Grid::<1>::new(&data, res, mapping(convention, res));
            for _ in 0..5_000 {
                let p = rounded(random_point(&mut rng, lo, hi));
                let expected = reference::<1>(&data, res, convention, p)[0];
                let got = grid.lookup(to_vec3(p))[0] as f64;
                assert!(
                    (got - expected).abs() < 1e-5,
                    "{convention:?} {res:?} {p:?}: {got} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn zero_outside_the_box_and_defined_on_its_faces() {
    let mut rng = TestRng::new(34);
    let b = bounds();
    for convention in CONVENTIONS {
        let res = [4u32, 3, 5];
        // Strictly positive data, so that zero can only mean "outside".
        let data: Vec<f32> = random_data(&mut rng, res, 1)
            .iter()
            .map(|x| 2.0 + x)
            .collect();
        let grid = Grid::<1>::new(&data, res, mapping(convention, res));
        let centre = (b.min + b.max) * 0.5;
        for a in 0..3 {
            for max_side in [false, true] {
                let mut on_face = centre;
                on_face[a] = if max_side { b.max[a] } else { b.min[a] };
                let p = [on_face.x as f64, on_face.y as f64, on_face.z as f64];
                let expected = reference::<1>(&data, res, convention, p)[0];
                let got = grid.lookup(on_face)[0] as f64;
                assert!(
                    got > 0.0 && (got - expected).abs() < 1e-5,
                    "{convention:?} face: {got}"
                );
                let mut outside = on_face;
                let step = if max_side { 1e-4 } else { -1e-4 };
                outside[a] += step;
                assert_eq!(grid.lookup(outside)[0], 0.0, "{convention:?} {outside:?}");
                outside[a] += 1000.0 * step;
                assert_eq!(grid.lookup(outside)[0], 0.0, "{convention:?} {outside:?}");
            }
        }
        assert_eq!(grid.lookup(Vec3::splat(1e30))[0], 0.0);
        assert_eq!(grid.lookup(Vec3::splat(-1e30))[0], 0.0);
    }
}

#[test]
fn continuous_across_cell_borders() {
    // On either side of a sample plane (a cell border of the interpolation), at index distance
    // eps, the lookups differ by at most 2 eps times the largest sample difference (the trilinear
    // function's Lipschitz bound along the axis, here <= 2 for data in [-1, 1]), plus f32 rounding.
    let mut rng = TestRng::new(35);
    let eps_index = 1e-3;
    for convention in CONVENTIONS {
        let res = [4u32, 3, 5];
        let data = random_data(&mut rng, res, 1);
        let grid = Grid::<1>::new(&data, res, mapping(convention, res));
        let b = bounds();
        for a in 0..3 {
            let spacing = (sample_position(convention, res, a, 1)
                - sample_position(convention, res, a, 0))
            .abs();
            for k in 1..res[a] - 1 {
                for _ in 0..200 {
                    let mut p = random_point(
                        &mut rng,
                        [b.min.x as f64, b.min.y as f64, b.min.z as f64],
                        [b.max.x as f64, b.max.y as f64, b.max.z as f64],
                    );
                    p[a] = sample_position(convention, res, a, k);
                    let (mut below, mut above) = (p, p);
                    below[a] -= eps_index * spacing;
                    above[a] += eps_index * spacing;
                    let at = grid.lookup(to_vec3(p))[0];
                    let lo = grid.lookup(to_vec3(below))[0];
                    let hi = grid.lookup(to_vec3(above))[0];
                    let bound = (2.0 * eps_index * 2.0 + 1e-5) as f32;
                    assert!(
                        (at - lo).abs() <= bound && (at - hi).abs() <= bound,
                        "{convention:?} axis {a} plane {k}: {lo} {at} {hi}"
                    );
                }
            }
        }
    }
}

#[test]
fn rgb_channels_are_independent() {
    let mut rng = TestRng::new(36);
    let b = bounds();
    for convention in CONVENTIONS {
        for res in RESOLUTIONS {
            let rgb = random_data(&mut rng, res, 3);
            let channels: Vec<Vec<f32>> = (0..3)
                .map(|c| rgb.iter().skip(c).step_by(3).copied().collect())
                .collect();
            let m = mapping(convention, res);
            let grid3 = Grid::<3>::new(&rgb, res, m);
            let singles: Vec<Grid<1>> =
                channels.iter().map(|d| Grid::<1>::new(d, res, m)).collect();
            for _ in 0..2000 {
                let p = rounded(random_point(
                    &mut rng,
                    [b.min.x as f64, b.min.y as f64, b.min.z as f64],
                    [b.max.x as f64, b.max.y as f64, b.max.z as f64],
                ));
                let v = grid3.lookup(to_vec3(p));
                let expected = reference::<3>(&rgb, res, convention, p);
                for c in 0..3 {
                    assert_eq!(
                        v[c],
                        singles[c].lookup(to_vec3(p))[0],
                        "{convention:?} {res:?} channel {c}"
                    );
                    assert!((v[c] as f64 - expected[c]).abs() < 1e-5);
                }
            }
        }
    }
}

#[test]
fn resolution_one_along_an_axis_is_constant_along_it() {
    let mut rng = TestRng::new(37);
    let b = bounds();
    for convention in CONVENTIONS {
        let res = [1u32, 4, 3];
        let data = random_data(&mut rng, res, 1);
        let grid = Grid::<1>::new(&data, res, mapping(convention, res));
        for _ in 0..1000 {
            let y = rng.range(b.min.y as f64, b.max.y as f64) as f32;
            let z = rng.range(b.min.z as f64, b.max.z as f64) as f32;
            let first = grid.lookup(Vec3::new(b.min.x, y, z))[0];
            assert!(first.is_finite());
            for x in [
                b.max.x,
                0.5 * (b.min.x + b.max.x),
                rng.range(b.min.x as f64, b.max.x as f64) as f32,
            ] {
                assert_eq!(
                    grid.lookup(Vec3::new(x, y, z))[0],
                    first,
                    "{convention:?} x = {x}"
                );
            }
        }
        // All axes of resolution 1: a constant over the whole box.
        let grid = Grid::<1>::new(&[0.75], [1, 1, 1], mapping(convention, [1, 1, 1]));
        for _ in 0..1000 {
            let p = to_vec3(random_point(
                &mut rng,
                [b.min.x as f64, b.min.y as f64, b.min.z as f64],
                [b.max.x as f64, b.max.y as f64, b.max.z as f64],
            ));
            assert_eq!(grid.lookup(p)[0], 0.75);
        }
    }
}

/// No lookup exceeds the largest sample (the majorant of delta tracking is `scale * max`): without
/// a clamp, rounding carries `a + (b - a) * t` one ulp above `max(a, b)` for many pairs.
#[test]
fn lookups_never_exceed_the_largest_sample() {
    let mut rng = TestRng::new(41);
    for convention in CONVENTIONS {
        for _ in 0..200 {
            let res = [2, 2, 2];
            let data = random_data(&mut rng, res, 1)
                .iter()
                .map(|v| v.abs() * 1e-3)
                .collect::<Vec<f32>>();
            let largest = data.iter().copied().fold(0.0, f32::max);
            let grid = Grid::<1>::new(&data, res, mapping(convention, res));
            let b = bounds();
            let (lo, hi) = (
                b.min.to_array().map(f64::from),
                b.max.to_array().map(f64::from),
            );
            for _ in 0..500 {
                let p = to_vec3(random_point(&mut rng, lo, hi));
                let v = grid.lookup(p)[0];
                assert!(
                    v <= largest,
                    "{v} above the largest sample {largest} at {p}"
                );
            }
        }
    }
}

/// Nearest lookup returns the sample whose position is closest along every axis (in f64, from the
/// sample positions of the convention), so never more than the largest sample; positions within
/// 1e-4 of a midpoint between samples are skipped, where f32 rounding may pick either side.
#[test]
fn nearest_lookup_returns_the_nearest_sample() {
    let mut rng = TestRng::new(43);
    for convention in CONVENTIONS {
        for res in RESOLUTIONS {
            let data = random_data(&mut rng, res, 1);
            let grid = Grid::<1>::new(&data, res, mapping(convention, res))
                .with_lookup(GridLookup::Nearest);
            let b = bounds();
            let (lo, hi) = (
                b.min.to_array().map(f64::from),
                b.max.to_array().map(f64::from),
            );
            let mut checked = 0;
            for _ in 0..2000 {
                let p = rounded(random_point(&mut rng, lo, hi));
                let mut index = [0u32; 3];
                let mut ambiguous = false;
                for a in 0..3 {
                    let mut by_distance: Vec<(f64, u32)> = (0..res[a])
                        .map(|i| ((sample_position(convention, res, a, i) - p[a]).abs(), i))
                        .collect();
                    by_distance.sort_by(|x, y| x.0.total_cmp(&y.0));
                    index[a] = by_distance[0].1;
                    ambiguous |=
                        by_distance.len() > 1 && by_distance[1].0 - by_distance[0].0 < 1e-4;
                }
                if ambiguous {
                    continue;
                }
                let i = ((index[2] * res[1] + index[1]) * res[0] + index[0]) as usize;
                assert_eq!(
                    grid.lookup(to_vec3(p))[0],
                    data[i],
                    "{convention:?} {res:?} at {p:?}: expected sample {index:?}"
                );
                checked += 1;
            }
            assert!(checked > 1000, "{checked} unambiguous points");
        }
    }
}
