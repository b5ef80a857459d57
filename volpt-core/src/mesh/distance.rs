//! A conservative distance-to-surface grid over a mesh's box, so that a free flight that cannot
//! reach the surface casts no ray.
//!
//! Each cell holds a lower bound of the distance from its centre `c` to the surface (the closest
//! point of any triangle, in f64, rounded down). The distance to a surface is 1-Lipschitz, so from
//! a point `p` in the cell the surface is at least `d(c) - |p - c|` away, and so is the exit along
//! any ray from `p`: a flight whose sampled distance is shorter collides inside, whatever the ray
//! cast would say ([`crate::flight::FlightEnd`]). The bound is shrunk by a relative `1e-5` and an
//! absolute margin of 64 f32 epsilons of the box's coordinates, which covers the rounding of the
//! lookup and of the ray cast's own distance (`(c - n.o) / (n.d)`), so the paths are exactly
//! those the ray cast alone traces.

use crate::{Aabb, Vec3};

/// The grid's cells along its longest axis (the others in proportion): 64^3 cells are 1 MiB.
pub const DISTANCE_RESOLUTION: u32 = 64;

/// A mesh's distance grid, borrowed from memory the caller keeps (host or device); empty (no
/// cells) where none was built, and then it knows nothing (every bound 0).
#[derive(Clone, Copy, Debug)]
pub struct SurfaceDistance<'a> {
    /// Per cell, x fastest: a lower bound of the distance from its centre to the surface.
    pub values: &'a [f32],
    pub res: [u32; 3],
    pub min: Vec3,
    /// A cell's size.
    pub cell: Vec3,
    pub inv_cell: Vec3,
    /// What rounding may take off a bound (see the module documentation).
    pub margin: f32,
}

impl SurfaceDistance<'_> {
    /// A grid that knows nothing.
    pub const NONE: SurfaceDistance<'static> = SurfaceDistance {
        values: &[],
        res: [0; 3],
        min: Vec3::ZERO,
        cell: Vec3::ONE,
        inv_cell: Vec3::ONE,
        margin: 0.0,
    };

    /// A distance from `p` within which no ray from `p` meets the surface; at most 0 where
    /// nothing is known (outside the grid, a NaN point, no grid).
    #[inline(always)]
    pub fn at(&self, p: Vec3) -> f32 {
        let g = (p - self.min) * self.inv_cell;
        let [rx, ry, rz] = self.res;
        // Not `g < res` on the negation: a NaN fails every comparison and knows nothing.
        let inside = g.x >= 0.0
            && g.y >= 0.0
            && g.z >= 0.0
            && g.x < rx as f32
            && g.y < ry as f32
            && g.z < rz as f32;
        if !inside {
            return 0.0;
        }
        let (x, y, z) = (g.x as u32, g.y as u32, g.z as u32);
        // `g < res` in f32 may still round to `res` when converted: clamp.
        let (x, y, z) = (x.min(rx - 1), y.min(ry - 1), z.min(rz - 1));
        let centre = self.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * self.cell;
        let index = ((z * ry + y) * rx + x) as usize;
        let bound = self.values[index] - (p - centre).length();
        bound * (1.0 - 1e-5) - self.margin
    }
}

/// The resolution of a distance grid over `bounds` with `longest` cells along its longest axis.
pub fn resolution_for(bounds: Aabb, longest: u32) -> [u32; 3] {
    let extent = bounds.max - bounds.min;
    let max = extent.max_element();
    [extent.x, extent.y, extent.z].map(|e| {
        let cells = libm::ceilf(e / max * longest as f32);
        if cells >= 1.0 {
            cells as u32
        } else {
            1
        }
    })
}

/// The geometry of a grid of `res` cells over `bounds`, without values.
pub fn layout(bounds: Aabb, res: [u32; 3]) -> SurfaceDistance<'static> {
    let extent = bounds.max - bounds.min;
    let cell = extent / Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
    let scale = bounds.min.abs().max(bounds.max.abs()).max_element() + extent.max_element();
    SurfaceDistance {
        values: &[],
        res,
        min: bounds.min,
        cell,
        inv_cell: Vec3::ONE / cell,
        margin: 64.0 * f32::EPSILON * scale,
    }
}

#[cfg(feature = "alloc")]
pub use host::*;

#[cfg(feature = "alloc")]
mod host {
    use alloc::vec::Vec;

    use super::layout;
    use crate::mesh::{MeshTriangle, TriangleMesh};
    use crate::Vec3;

    /// A lower bound of every cell's distance (centre to surface) of the grid of `res` over
    /// `mesh`'s bounds, x fastest, in `O(triangles + cells * longest axis)` (no per-cell BVH
    /// query): the distance from the cell's centre to the nearest *surface cell*, a cell whose
    /// box the plane of a triangle crosses within the triangle's box. Every surface point lies
    /// in a surface cell, so that distance bounds its own from below. It is exact (in f64) by
    /// three passes of a separable 1D minimum (the distance to a box is a sum of per-axis
    /// terms; Felzenszwalb and Huttenlocher 2012, "Distance transforms of sampled functions",
    /// with the box's per-axis term in place of their parabola); then `slack` (what the
    /// grid's f32 layout may put a surface point outside its cell) is taken off.
    /// [`refine_slab`] then sharpens the cells near the surface.
    pub fn surface_bound(mesh: &TriangleMesh<'_>, res: [u32; 3]) -> Vec<f32> {
        let grid = Cells::new(mesh, res);
        let [rx, ry, rz] = res.map(|r| r as usize);
        let mut d2 = alloc::vec![f64::INFINITY; rx * ry * rz];
        for t in mesh.triangles {
            grid.mark(t, &mut d2);
        }
        // Along x, then y, then z: the squared distance to the nearest marked cell's box.
        let along_x: Vec<usize> = (0..ry * rz).map(|line| line * rx).collect();
        min_lines(&mut d2, &along_x, 1, rx, grid.cell[0]);
        let along_y: Vec<usize> = (0..rz)
            .flat_map(|z| (0..rx).map(move |x| z * rx * ry + x))
            .collect();
        min_lines(&mut d2, &along_y, rx, ry, grid.cell[1]);
        let along_z: Vec<usize> = (0..rx * ry).collect();
        min_lines(&mut d2, &along_z, rx * ry, rz, grid.cell[2]);
        d2.iter()
            .map(|&d2| round_down(libm::sqrt(d2) - grid.slack))
            .collect()
    }

    /// Raises the bounds of slab `z` (`out`, as [`surface_bound`] left them) where the surface
    /// is within [`NEAR_CELLS`] cells, to the exact distance from the cell's centre (in f64,
    /// rounded down) capped at that distance: a BVH query that prunes every node farther than
    /// the cap, so that its cost is the triangles near the cell, not the mesh's (a cell in a
    /// sphere's centre is equally far from all of them). Slabs are independent: a host may
    /// refine them on several threads.
    pub fn refine_slab(mesh: &TriangleMesh<'_>, res: [u32; 3], z: u32, out: &mut [f32]) {
        let grid = layout(mesh.bounds, res);
        let cap = f64::from(grid.cell.max_element()) * NEAR_CELLS;
        let mut stack = Vec::new();
        for y in 0..res[1] {
            // The previous cell's centre and distance along the row: the distance is
            // 1-Lipschitz, so the next is at most that plus the step between the centres, a
            // tighter start for the query's pruning than the cap. (Where rounding puts that
            // below the distance, the query returns it, a lower bound all the same.)
            let mut previous: Option<([f64; 3], f64)> = None;
            for x in 0..res[0] {
                let value = &mut out[(y * res[0] + x) as usize];
                if f64::from(*value) >= cap {
                    previous = None;
                    continue;
                }
                let centre = grid.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * grid.cell;
                let centre = centre.to_array().map(f64::from);
                let limit = previous.map_or(cap, |(p, d)| {
                    cap.min(d + libm::sqrt(dot(sub(centre, p), sub(centre, p))))
                });
                let d = closest(mesh, centre, limit, &mut stack);
                previous = (d < limit).then_some((centre, d));
                *value = value.max(round_down(d));
            }
        }
    }

    /// How near the surface (in the grid's largest cell size) [`refine_slab`] queries the BVH.
    pub const NEAR_CELLS: f64 = 3.0;

    /// `d` as an f32 no larger, and not below 0.
    fn round_down(d: f64) -> f32 {
        let mut bound = d as f32;
        if f64::from(bound) > d {
            bound = bound.next_down();
        }
        bound.max(0.0)
    }

    /// The per-axis squared distance from a cell's centre to the box of a cell `steps` away:
    /// `((|steps| - 1/2) cell)^2`, 0 for the cell itself.
    fn axis_term(steps: usize, cell: f64) -> f64 {
        if steps == 0 {
            0.0
        } else {
            let d = (steps as f64 - 0.5) * cell;
            d * d
        }
    }

    /// `min_p f(p) + axis_term(|q - p|)` along lines of `len` cells `stride` apart from each
    /// of `starts`, in place.
    fn min_lines(d2: &mut [f64], starts: &[usize], stride: usize, len: usize, cell: f64) {
        let mut line = Vec::with_capacity(len);
        for &start in starts {
            line.clear();
            line.extend((0..len).map(|i| d2[start + i * stride]));
            for q in 0..len {
                d2[start + q * stride] = line
                    .iter()
                    .enumerate()
                    .map(|(p, &f)| f + axis_term(p.abs_diff(q), cell))
                    .fold(f64::INFINITY, f64::min);
            }
        }
    }

    /// The grid's cells in f64, for marking the surface's.
    struct Cells {
        min: [f64; 3],
        cell: [f64; 3],
        res: [u32; 3],
        /// How far the f32 layout's rounding may put a point outside the cell the f64 one
        /// puts it in (the grid's own rounding margin, [`layout`]'s, is far larger than f64's).
        slack: f64,
    }

    impl Cells {
        fn new(mesh: &TriangleMesh<'_>, res: [u32; 3]) -> Self {
            let grid = layout(mesh.bounds, res);
            Self {
                min: grid.min.to_array().map(f64::from),
                cell: grid.cell.to_array().map(f64::from),
                res,
                slack: f64::from(grid.margin) / 16.0,
            }
        }

        /// Marks (distance 0) every cell whose box, widened by `slack`, `t` overlaps: the
        /// separating axis test of a triangle and a box (Akenine-Moeller 2001, "Fast 3D
        /// triangle-box overlap testing"): the box's axes (the cells in `t`'s box), `t`'s
        /// normal and the 9 products of an edge with an axis, each widened by a relative 1e-9
        /// so that f64 rounding only ever marks more.
        fn mark(&self, t: &MeshTriangle, d2: &mut [f64]) {
            let v = t.v.map(|p| p.map(f64::from));
            let range = |k: usize| {
                let lo = v[0][k].min(v[1][k]).min(v[2][k]) - self.slack;
                let hi = v[0][k].max(v[1][k]).max(v[2][k]) + self.slack;
                let last = self.res[k] - 1;
                let cell = |x: f64| {
                    (libm::floor((x - self.min[k]) / self.cell[k]).max(0.0) as u32).min(last)
                };
                cell(lo)..=cell(hi)
            };
            let edges = [sub(v[1], v[0]), sub(v[2], v[1]), sub(v[0], v[2])];
            let mut axes = [[0.0; 3]; 10];
            axes[0] = cross(edges[0], edges[1]);
            for (j, e) in edges.iter().enumerate() {
                for k in 0..3 {
                    let mut unit = [0.0; 3];
                    unit[k] = 1.0;
                    axes[1 + 3 * j + k] = cross(unit, *e);
                }
            }
            let half = self.cell.map(|c| c * 0.5 + self.slack);
            let reach =
                axes.map(|a| (0..3).map(|k| a[k].abs() * half[k]).sum::<f64>() * (1.0 + 1e-9));
            let [rx, ry, _] = self.res.map(|r| r as usize);
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let c = [x, y, z]
                            .map(|i| i as f64 + 0.5)
                            .iter()
                            .enumerate()
                            .map(|(k, i)| self.min[k] + i * self.cell[k])
                            .collect::<Vec<_>>();
                        let c = [c[0], c[1], c[2]];
                        let local = v.map(|p| sub(p, c));
                        let overlaps = axes.iter().zip(&reach).all(|(a, &r)| {
                            let p = local.map(|p| dot(*a, p));
                            let (lo, hi) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
                            lo <= r && hi >= -r
                        });
                        if overlaps {
                            d2[(z as usize * ry + y as usize) * rx + x as usize] = 0.0;
                        }
                    }
                }
            }
        }
    }

    fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    /// The distance from `p` to the nearest triangle of `mesh`, or `cap` if none is nearer, by a
    /// BVH traversal that skips every node farther than the nearest triangle found so far.
    fn closest(mesh: &TriangleMesh<'_>, p: [f64; 3], cap: f64, stack: &mut Vec<u32>) -> f64 {
        let mut best = cap * cap;
        stack.clear();
        stack.push(0);
        while let Some(i) = stack.pop() {
            let n = mesh.nodes[i as usize];
            if box_distance2(n.min, n.max, p) >= best {
                continue;
            }
            if n.count > 0 {
                for t in &mesh.triangles[n.first as usize..(n.first + n.count) as usize] {
                    best = best.min(triangle_distance2(t, p));
                }
            } else {
                let (a, b) = (i + 1, n.first);
                let da = box_distance2(mesh.nodes[a as usize].min, mesh.nodes[a as usize].max, p);
                let db = box_distance2(mesh.nodes[b as usize].min, mesh.nodes[b as usize].max, p);
                // The nearer child on top.
                if da <= db {
                    stack.extend([b, a]);
                } else {
                    stack.extend([a, b]);
                }
            }
        }
        libm::sqrt(best)
    }

    fn box_distance2(min: [f32; 3], max: [f32; 3], p: [f64; 3]) -> f64 {
        (0..3)
            .map(|k| {
                let d = (f64::from(min[k]) - p[k])
                    .max(p[k] - f64::from(max[k]))
                    .max(0.0);
                d * d
            })
            .sum()
    }

    fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    /// The squared distance from `p` to triangle `t`: its closest point by Voronoi regions
    /// (Ericson, Real-Time Collision Detection, 5.1.5), in f64.
    fn triangle_distance2(t: &MeshTriangle, p: [f64; 3]) -> f64 {
        let [a, b, c] = t.v.map(|v| v.map(f64::from));
        let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
        let (d1, d2) = (dot(ab, ap), dot(ac, ap));
        let closest = if d1 <= 0.0 && d2 <= 0.0 {
            a
        } else {
            let bp = sub(p, b);
            let (d3, d4) = (dot(ab, bp), dot(ac, bp));
            if d3 >= 0.0 && d4 <= d3 {
                b
            } else {
                let vc = d1 * d4 - d3 * d2;
                if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
                    let v = d1 / (d1 - d3);
                    [a[0] + v * ab[0], a[1] + v * ab[1], a[2] + v * ab[2]]
                } else {
                    let cp = sub(p, c);
                    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
                    if d6 >= 0.0 && d5 <= d6 {
                        c
                    } else {
                        let vb = d5 * d2 - d1 * d6;
                        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
                            let w = d2 / (d2 - d6);
                            [a[0] + w * ac[0], a[1] + w * ac[1], a[2] + w * ac[2]]
                        } else {
                            let va = d3 * d6 - d5 * d4;
                            if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
                                let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
                                let bc = sub(c, b);
                                [b[0] + w * bc[0], b[1] + w * bc[1], b[2] + w * bc[2]]
                            } else {
                                let denom = 1.0 / (va + vb + vc);
                                let (v, w) = (vb * denom, vc * denom);
                                [
                                    a[0] + ab[0] * v + ac[0] * w,
                                    a[1] + ab[1] * v + ac[1] * w,
                                    a[2] + ab[2] * v + ac[2] * w,
                                ]
                            }
                        }
                    }
                }
            }
        };
        let d = sub(p, closest);
        dot(d, d)
    }
}
