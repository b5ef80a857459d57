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

    /// The values of slab `z` (cells `z * res_x * res_y ..` of the grid of `res` over `mesh`'s
    /// bounds) into `out`: for each cell, its centre's distance to the mesh, rounded down.
    /// Slabs are independent: a host may compute them on several threads.
    pub fn distance_slab(mesh: &TriangleMesh<'_>, res: [u32; 3], z: u32, out: &mut [f32]) {
        let grid = layout(mesh.bounds, res);
        let mut stack = Vec::new();
        for y in 0..res[1] {
            for x in 0..res[0] {
                let centre = grid.min + (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * grid.cell;
                let d = closest(mesh, centre.to_array().map(f64::from), &mut stack);
                let mut bound = d as f32;
                if f64::from(bound) > d {
                    bound = bound.next_down();
                }
                out[(y * res[0] + x) as usize] = bound.max(0.0);
            }
        }
    }

    /// The distance from `p` to the nearest triangle of `mesh`, by a BVH traversal that skips
    /// every node farther than the nearest triangle found so far.
    fn closest(mesh: &TriangleMesh<'_>, p: [f64; 3], stack: &mut Vec<u32>) -> f64 {
        let mut best = f64::INFINITY;
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
