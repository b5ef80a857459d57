//! The majorant grid on its own (`volpt_core::majorant`): cell indexing, cell boxes, the bounds
//! `build_majorants` computes and the DDA walk through the cells. Mutation testing (shard 1/8 of
//! scope `core`, docs/testing.md) found every mutant of the module unseen by volpt-core's tests;
//! the whole-renderer tests see it only through rendered images.

use volpt_core::majorant::{build_majorants, Dda, MajorantGrid};
use volpt_core::rng::Rng;
use volpt_core::{Aabb, Grid, GridMapping, Ray, Vec3};

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 1.5, 4.5))
}

const RES: [u32; 3] = [4, 3, 5];

/// One distinct value per cell, so that a majorant names the cell it came from.
fn cell_values() -> Vec<f32> {
    (0..RES[0] * RES[1] * RES[2])
        .map(|i| i as f32 + 1.0)
        .collect()
}

fn cell_centre(grid: &MajorantGrid<'_>, x: u32, y: u32, z: u32) -> Vec3 {
    let b = grid.cell_bounds(x, y, z);
    (b.min + b.max) * 0.5
}

#[test]
fn resolution_follows_the_longest_axis() {
    let b = Aabb::new(Vec3::ZERO, Vec3::new(4.0, 2.0, 1.0));
    assert_eq!(MajorantGrid::resolution_for(b, 8), [8, 4, 2]);
    let thin = Aabb::new(Vec3::ZERO, Vec3::new(3.0, 1.0, 0.001));
    assert_eq!(MajorantGrid::resolution_for(thin, 10), [10, 4, 1]);
    // A box of no extent still gets one cell along each axis, never 0 / 0.
    let point = Aabb::new(Vec3::ONE, Vec3::ONE);
    assert_eq!(MajorantGrid::resolution_for(point, 10), [1, 1, 1]);
}

#[test]
fn cells_are_indexed_x_fastest_and_tile_the_box() {
    let data = cell_values();
    let grid = MajorantGrid::new(&data, RES, bounds());
    let cell = bounds().extent() / Vec3::new(RES[0] as f32, RES[1] as f32, RES[2] as f32);
    for z in 0..RES[2] {
        for y in 0..RES[1] {
            for x in 0..RES[0] {
                let expected = data[((z * RES[1] + y) * RES[0] + x) as usize];
                assert_eq!(grid.at(x, y, z), expected, "cell {x},{y},{z}");
                let b = grid.cell_bounds(x, y, z);
                let min = bounds().min + cell * Vec3::new(x as f32, y as f32, z as f32);
                assert!(
                    (b.min - min).abs().max_element() < 1e-5
                        && (b.max - (min + cell)).abs().max_element() < 1e-5,
                    "cell {x},{y},{z}: box {b:?}, expected from {min} by {cell}"
                );
                assert_eq!(grid.at_point(cell_centre(&grid, x, y, z)), expected);
            }
        }
    }
    // Outside the box: the nearest cell.
    assert_eq!(grid.at_point(Vec3::new(-5.0, -5.0, -5.0)), grid.at(0, 0, 0));
    assert_eq!(grid.at_point(Vec3::new(9.0, 9.0, 9.0)), grid.at(3, 2, 4));
}

/// Conservative: no trilinear lookup inside a cell exceeds its bound; and tight: a cell more than
/// two samples away from the only nonzero sample has bound 0, one containing it has the sample's.
#[test]
fn built_majorants_bound_every_lookup_and_no_more() {
    let b = bounds();
    let density_res = [7, 6, 8];
    for spike in [[1u32, 1, 1], [5, 4, 6], [3, 0, 7]] {
        let mut density = vec![0.0f32; (density_res[0] * density_res[1] * density_res[2]) as usize];
        // A gentle ramp, so that every cell's bound is positive, and one spike.
        for (i, d) in density.iter_mut().enumerate() {
            *d = 0.01 * (i % 5) as f32;
        }
        let j = (spike[2] * density_res[1] + spike[1]) * density_res[0] + spike[0];
        density[j as usize] = 7.0;
        let mapping = GridMapping::vertex_centred(b, density_res);
        let grid = Grid::<1>::new(&density, density_res, mapping);
        let scale = 2.5;
        let mut bounds_out = vec![f32::NAN; (RES[0] * RES[1] * RES[2]) as usize];
        build_majorants(&grid, scale, b, RES, &mut bounds_out);
        let majorants = MajorantGrid::new(&bounds_out, RES, b);
        let spike_at = mapping_point(b, density_res, spike);
        let samples = 6;
        for z in 0..RES[2] {
            for y in 0..RES[1] {
                for x in 0..RES[0] {
                    let bound = majorants.at(x, y, z);
                    let cb = majorants.cell_bounds(x, y, z);
                    let mut largest = 0.0f32;
                    for k in 0..=samples {
                        for j in 0..=samples {
                            for i in 0..=samples {
                                let f = Vec3::new(i as f32, j as f32, k as f32) / samples as f32;
                                let sigma = scale * grid.lookup(cb.min + cb.extent() * f)[0];
                                largest = largest.max(sigma);
                            }
                        }
                    }
                    assert!(
                        largest <= bound,
                        "spike {spike:?}, cell {x},{y},{z}: lookup {largest} above bound {bound}"
                    );
                    // Two sample spacings (plus the cell's margin) from the spike, nothing of it
                    // can be reached: the bound is the ramp's at most.
                    let spacing = b.extent() / Vec3::new(6.0, 5.0, 7.0);
                    let far = (0..3).any(|a| {
                        spike_at[a] < cb.min[a] - 2.1 * spacing[a]
                            || spike_at[a] > cb.max[a] + 2.1 * spacing[a]
                    });
                    if far {
                        assert!(bound <= scale * 0.04 + 1e-6, "cell {x},{y},{z}: {bound}");
                    }
                    if cb.contains(spike_at) {
                        assert_eq!(bound, scale * 7.0, "cell {x},{y},{z} holds the spike");
                    }
                }
            }
        }
    }
}

/// Where sample `s` of a vertex-centred grid of `res` samples over `b` lies.
fn mapping_point(b: Aabb, res: [u32; 3], s: [u32; 3]) -> Vec3 {
    let f = Vec3::new(
        s[0] as f32 / (res[0] - 1) as f32,
        s[1] as f32 / (res[1] - 1) as f32,
        s[2] as f32 / (res[2] - 1) as f32,
    );
    b.min + b.extent() * f
}

/// The DDA's segments tile the ray from its origin to the box's exit, each lies in one cell, and
/// the majorant it reports is that cell's; axis-parallel rays (with negative zero components too)
/// included.
#[test]
fn dda_walks_the_cells_the_ray_crosses() {
    let data = cell_values();
    let grid = MajorantGrid::new(&data, RES, bounds());
    let mut rng = Rng::new(7, 0, 0);
    let mut rays = vec![
        Ray::new(Vec3::new(0.1, 0.7, 3.1), Vec3::new(1.0, -0.0, 0.0)),
        Ray::new(Vec3::new(2.9, 0.7, 3.1), Vec3::new(-1.0, 0.0, -0.0)),
        Ray::new(Vec3::new(0.3, 0.1, 2.2), Vec3::new(-0.0, 0.0, 1.0)),
    ];
    // Rays entering through each of the three far faces (a camera ray's entry point lies exactly
    // on the box), whose grid coordinate along that axis is the resolution itself: the DDA must
    // start in the last cell, not one past it.
    for axis in 0..3 {
        for _ in 0..20 {
            let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
            let mut origin = bounds().min + bounds().extent() * u;
            origin[axis] = bounds().max[axis];
            let mut d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
            d[axis] = -0.5 - rng.next_f32();
            rays.push(Ray::new(origin, d.normalize()));
        }
    }
    for _ in 0..200 {
        let u = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let origin = bounds().min + bounds().extent() * u;
        let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        if d.length() > 0.1 {
            rays.push(Ray::new(origin, d.normalize()));
        }
    }
    for ray in &rays {
        let exit = bounds().exit(ray).t;
        let mut dda = Dda::new(&grid, ray);
        let mut start = 0.0f32;
        let mut segments = 0;
        loop {
            let (majorant, end) = dda.segment(&grid);
            let stop = end.min(exit);
            assert!(stop > start, "{ray:?}: segment [{start}, {end}]");
            for f in [0.01, 0.5, 0.99] {
                let t = start + (stop - start) * f;
                assert_eq!(
                    grid.at_point(ray.at(t)),
                    majorant,
                    "{ray:?}: segment {segments} [{start}, {end}] at t = {t}"
                );
            }
            segments += 1;
            assert!(
                segments < 20,
                "{ray:?}: more segments than cells along the way"
            );
            if end >= exit {
                break;
            }
            start = end;
            dda.advance(&grid, ray.dir);
        }
    }
}
