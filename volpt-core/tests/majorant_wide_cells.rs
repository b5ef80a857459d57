//! `build_majorants` when a majorant cell spans many density samples (a 32-cell majorant grid over
//! a 512^3 density is 16 samples a cell): the cell's margin then covers whole samples, and a bound
//! computed from the wrong side of the margin misses samples that lookups inside the cell read.
//! `majorant_grid.rs` checks cells narrower than two samples, where the margin is a fraction of a
//! sample and the range's extra sample on each side hides such a mistake (mutation testing, shard
//! 2/8: `b.max - margin` for `b.max + margin` left it green).

use volpt_core::majorant::{build_majorants, MajorantGrid};
use volpt_core::{Aabb, Grid, GridMapping, Vec3};

fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::new(3.0, 1.0, 2.0))
}

/// A slab of density 1 at sample column `spike` along x, zero elsewhere, over `res` samples.
fn slab(res: [u32; 3], spike: u32) -> Vec<f32> {
    (0..res[0] * res[1] * res[2])
        .map(|i| if i % res[0] == spike { 1.0 } else { 0.0 })
        .collect()
}

/// For every position of the slab and every cell along x: the cell's bound holds the largest
/// lookup inside the cell (a trilinear lookup of a slab is piecewise linear in x, so its largest
/// value in a cell is at a face or at the slab), and a cell whose sample range lies well away from
/// the slab gets bound 0.
#[test]
fn majorants_of_cells_many_samples_wide_bound_every_lookup() {
    let b = bounds();
    let scale = 3.0;
    for cells in [2u32, 3] {
        let majorant_res = [cells, 1, 1];
        for samples in [9u32, 64, 401] {
            let res = [samples, 2, 3];
            for (name, mapping) in [
                ("vertex-centred", GridMapping::vertex_centred(b, res)),
                ("cell-centred", GridMapping::cell_centred(b, res)),
            ] {
                for spike in 0..samples {
                    let data = slab(res, spike);
                    let density = Grid::<1>::new(&data, res, mapping);
                    let mut out = vec![f32::NAN; cells as usize];
                    build_majorants(&density, scale, b, majorant_res, &mut out);
                    let grid = MajorantGrid::new(&out, majorant_res, b);
                    for x in 0..cells {
                        let what = format!(
                            "{name}, {samples} samples, {cells} cells, slab at {spike}, cell {x}"
                        );
                        let cb = grid.cell_bounds(x, 0, 0);
                        let bound = grid.at(x, 0, 0);
                        let y_z = (cb.min + cb.max) * 0.5;
                        let at_x = |px: f32| Vec3::new(px, y_z.y, y_z.z);
                        let slab_x = mapping_x(&mapping, spike as f32);
                        let mut probes = vec![cb.min.x, cb.max.x];
                        if (cb.min.x..=cb.max.x).contains(&slab_x) {
                            probes.push(slab_x);
                        }
                        for px in probes {
                            let sigma = scale * density.lookup(at_x(px))[0];
                            assert!(
                                sigma <= bound,
                                "{what}: lookup {sigma} at x = {px} above bound {bound}"
                            );
                        }
                        // In index units: the cell's range, and the slab's distance from it.
                        let lo = mapping.to_index_space(at_x(cb.min.x)).x;
                        let hi = mapping.to_index_space(at_x(cb.max.x)).x;
                        let spike = spike as f32;
                        let far = 0.05 * (hi - lo) + 2.5;
                        if spike < lo - far || spike > hi + far {
                            assert_eq!(bound, 0.0, "{what}: far from the slab");
                        }
                    }
                }
            }
        }
    }
}

/// The x coordinate at which `mapping` puts index-space x `i`, within the box (inverting
/// `to_index_space` by bisection, so the test does not restate the mapping's formula).
fn mapping_x(mapping: &GridMapping, i: f32) -> f32 {
    let b = mapping.bounds;
    let index = |x: f32| mapping.to_index_space(Vec3::new(x, b.min.y, b.min.z)).x;
    let (mut lo, mut hi) = (b.min.x, b.max.x);
    if index(lo) > i || index(hi) < i {
        return f32::NAN;
    }
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if index(mid) < i {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}
