//! A closed triangle mesh as the boundary's shape: its triangles in BVH order and the BVH's nodes,
//! both plain data that a GPU kernel reads as they are, traversed by the same code on every
//! backend with a bounded stack.
//!
//! The mesh must be closed and consistently oriented, each triangle's vertices counter-clockwise
//! seen from outside (the loaders check it). It may be non-convex and have several components (a
//! shell inside a shell): a ray meets it as often as it meets it, and each crossing flips inside
//! and outside.
//!
//! # The ray-triangle test
//!
//! Whether a ray crosses a triangle is decided by Woop, Benthin and Wald 2013's watertight test
//! ("Watertight ray/triangle intersection", JCGT 2(1)): in a frame where the ray runs along an
//! axis, the signs of the three 2D edge functions of the projected vertices; all three <= 0 for a
//! ray crossing the triangle from outside (against its normal), all >= 0 from inside. Each vertex
//! projects to the same bits in every triangle, and two triangles that share an edge list it in
//! opposite orders and compute the same edge function of opposite sign: a ray through an edge or a
//! vertex crosses at least one of the triangles there, never none (no leak). The distance is then the plane's, `(c - n.o) / (n.d)`, with the
//! unit normal `n` and offset `c` rounded once from f64 on the host: for a face in an axis plane
//! it is the box's slab arithmetic to the bit, so a mesh of a box traces the box's paths.

#[cfg(feature = "alloc")]
pub mod build;
pub mod distance;
#[cfg(feature = "alloc")]
pub mod primitives;

use core::mem::MaybeUninit;

use bytemuck::{Pod, Zeroable};

use crate::geometry::{Aabb, BoxHit, Ray};
use crate::math::{div_scalar, recip, recip_scalar};
use crate::shape::Shape;
use crate::Vec3;

/// The traversal stack's depth; the builder makes every leaf at most this deep.
pub const MAX_BVH_DEPTH: usize = 64;

/// A node of the BVH: its box, and either its two children (`count` 0: the first child follows
/// the node, the second is node `first`) or its triangles (`count` > 0: `first..first + count`).
///
/// Aligned to 16 bytes, so that a GPU reads each half (box corner and index) in one load.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub first: u32,
    pub max: [f32; 3],
    pub count: u32,
}

/// A triangle: its vertices counter-clockwise seen from outside, its outward unit normal and the
/// plane's offset (`normal . p = offset` on the plane).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct MeshTriangle {
    pub v: [[f32; 3]; 3],
    pub normal: [f32; 3],
    pub offset: f32,
}

/// Which crossings a ray cast reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// From outside to inside (against the triangle's normal).
    Entering,
    /// From inside to outside.
    Leaving,
    /// Either.
    Any,
}

pub use distance::SurfaceDistance;

/// A triangle's unit vertex normals at its three corners, in its vertices' order.
pub type CornerNormals = [[f32; 3]; 3];

/// A closed triangle mesh, its BVH and its distance grid, borrowed from memory the caller keeps
/// (host or device).
#[derive(Clone, Copy, Debug)]
pub struct TriangleMesh<'a> {
    pub nodes: &'a [BvhNode],
    pub triangles: &'a [MeshTriangle],
    /// Each triangle's vertex normals (in `triangles`' order), which the boundary's BSDF scatters
    /// about, interpolated ([`TriangleMesh::hit`]); empty: each triangle's own normal (Mitsuba's
    /// `face_normals`).
    pub normals: &'a [CornerNormals],
    pub bounds: Aabb,
    /// Lets a free flight that cannot reach the surface skip the ray cast.
    pub distance: SurfaceDistance<'a>,
}

impl<'a> TriangleMesh<'a> {
    /// The nearest crossing of `ray` of the given kind at a distance >= 0: its distance and
    /// triangle.
    #[inline]
    pub fn nearest(&self, ray: &Ray, crossing: Crossing) -> Option<(f32, u32)> {
        if self.nodes.is_empty() {
            return None;
        }
        let inv = recip(ray.dir);
        let sheared = ShearedRay::new(ray);
        let mut best_t = f32::INFINITY;
        let mut best = None;
        // The far children still to visit, each with its entry distance (bits high, node low):
        // one popped once a nearer crossing was found is skipped, as its slab test would skip it
        // now. Uninitialised (zeroing it would be 256 bytes of local-memory stores per cast on
        // a GPU); only entries below `depth` are read.
        let mut stack = [MaybeUninit::<u64>::uninit(); MAX_BVH_DEPTH];
        let mut depth = 0usize;
        let mut node = 0u32;
        loop {
            let n = self.nodes[node as usize];
            let mut next = None;
            if n.count > 0 {
                for i in n.first..n.first + n.count {
                    let tri = &self.triangles[i as usize];
                    if let Some(t) = intersect(tri, ray, &sheared, crossing, best_t) {
                        best_t = t;
                        best = Some((t, i));
                    }
                }
            } else {
                let (a, b) = (node + 1, n.first);
                let ta = slab(&self.nodes[a as usize], ray, inv, best_t);
                let tb = slab(&self.nodes[b as usize], ray, inv, best_t);
                next = match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let ((near, _), (far, t_far)) = if ta <= tb {
                            ((a, ta), (b, tb))
                        } else {
                            ((b, tb), (a, ta))
                        };
                        if depth < MAX_BVH_DEPTH {
                            stack[depth] =
                                MaybeUninit::new(u64::from(t_far.to_bits()) << 32 | u64::from(far));
                            depth += 1;
                        }
                        Some(near)
                    }
                    (Some(_), None) => Some(a),
                    (None, Some(_)) => Some(b),
                    (None, None) => None,
                };
            }
            node = match next {
                Some(next) => next,
                None => loop {
                    if depth == 0 {
                        return best;
                    }
                    depth -= 1;
                    // SAFETY: every entry below `depth` was written by a push.
                    let entry = unsafe { stack[depth].assume_init() };
                    if f32::from_bits((entry >> 32) as u32) <= best_t {
                        break entry as u32;
                    }
                },
            };
        }
    }

    /// The hit record of a crossing of triangle `i` at distance `t`: the point, snapped onto the
    /// plane of a triangle in an axis plane (as the box snaps it onto its face) and clamped into
    /// the mesh's bounds, the outward normal, and the shading normal ([`shading_normal`]).
    #[inline]
    pub(crate) fn hit(&self, ray: &Ray, t: f32, i: u32) -> BoxHit {
        let tri = &self.triangles[i as usize];
        let n = Vec3::from(tri.normal);
        let mut point = ray.at(t);
        if n.y == 0.0 && n.z == 0.0 {
            point.x = tri.offset * n.x;
        } else if n.x == 0.0 && n.z == 0.0 {
            point.y = tri.offset * n.y;
        } else if n.x == 0.0 && n.y == 0.0 {
            point.z = tri.offset * n.z;
        }
        let point = point.max(self.bounds.min).min(self.bounds.max);
        let shading = match self.normals.get(i as usize) {
            Some(corners) => shading_normal(tri, corners, point),
            None => n,
        };
        BoxHit {
            t,
            point,
            normal: n,
            shading,
        }
    }

    /// Whether `nearest`, the nearest crossing of `ray` (from a point along
    /// [`CONTAINS_DIRECTION`]), leaves the mesh: the point is inside.
    #[inline(always)]
    pub(crate) fn contains_by(&self, ray: &Ray, nearest: Option<(f32, u32)>) -> bool {
        match nearest {
            Some((_, i)) => Vec3::from(self.triangles[i as usize].normal).dot(ray.dir) > 0.0,
            None => false,
        }
    }

    /// The exit of `ray` given `nearest`, its nearest leaving crossing: a ray from inside that
    /// finds no surface to leave by (its origin a rounding error outside, at a vertex) leaves
    /// where it stands, along its own direction.
    #[inline(always)]
    pub(crate) fn exit_by(&self, ray: &Ray, nearest: Option<(f32, u32)>) -> BoxHit {
        match nearest {
            Some((t, i)) => self.hit(ray, t, i),
            None => BoxHit {
                t: 0.0,
                point: ray.origin,
                normal: ray.dir,
                shading: ray.dir,
            },
        }
    }
}

/// Phong's interpolated normal (Phong 1975) of `tri` at `p`, a point on it: its corners' normals
/// weighted by `p`'s barycentric coordinates (clamped to the triangle, as a point a rounding error
/// outside it is on its edge), normalised. A normal that does not lie in the geometric normal's
/// hemisphere (strongly bent corner normals, or degenerate ones) would put the two sides of the
/// surface on one side: the geometric normal is used there.
#[inline]
pub fn shading_normal(tri: &MeshTriangle, corners: &CornerNormals, p: Vec3) -> Vec3 {
    let n = Vec3::from(tri.normal);
    let [a, b, c] = tri.v.map(Vec3::from);
    let twice_area = (b - a).cross(c - a).dot(n);
    let w0 = ((b - p).cross(c - p).dot(n) / twice_area).clamp(0.0, 1.0);
    let w1 = ((c - p).cross(a - p).dot(n) / twice_area).clamp(0.0, 1.0);
    let w2 = (1.0 - w0 - w1).max(0.0);
    let [n0, n1, n2] = corners.map(Vec3::from);
    let s = crate::math::normalize(n0 * w0 + n1 * w1 + n2 * w2);
    if s.dot(n) > 0.0 {
        s
    } else {
        n
    }
}

/// The direction a point's inside test casts along: not along an axis, since a ray in a face's
/// plane crosses nothing there.
pub const CONTAINS_DIRECTION: Vec3 = Vec3::new(0.267_261_24, 0.534_522_5, 0.801_783_7);

/// Where `ray` enters `node`'s box within `[0, t_max]`, if it does. An axis the ray runs parallel
/// to gives `0 * inf` (NaN) for an origin on one of its planes: that axis then does not constrain,
/// so the test errs towards visiting (a ray along a face's plane may cross its triangles' edges). The far distances are widened by `2 gamma_3`
/// (pbrt-v4 6.8.2) so that rounding never culls a node whose triangle the ray crosses on its face.
#[inline(always)]
fn slab(node: &BvhNode, ray: &Ray, inv: Vec3, t_max: f32) -> Option<f32> {
    const WIDEN: f32 = 1.0 + 2.0 * 3.0 * f32::EPSILON;
    let a = (Vec3::from(node.min) - ray.origin) * inv;
    let b = (Vec3::from(node.max) - ray.origin) * inv;
    let mut near = 0.0f32;
    let mut far = t_max;
    for (a, b) in [(a.x, b.x), (a.y, b.y), (a.z, b.z)] {
        let (lo, hi) = if a <= b {
            (a, b)
        } else if b < a {
            (b, a)
        } else {
            (f32::NEG_INFINITY, f32::INFINITY)
        };
        if lo > near {
            near = lo;
        }
        if hi * WIDEN < far {
            far = hi * WIDEN;
        }
    }
    if near <= far {
        Some(near)
    } else {
        None
    }
}

/// `ray` in the frame of Woop et al.'s watertight test: translated to its origin, axes permuted
/// so that its largest direction component is the last (`kz`, the others keeping the frame
/// right-handed), and sheared so that it runs along that axis.
#[derive(Clone, Copy)]
struct ShearedRay {
    origin: Vec3,
    kx: u8,
    ky: u8,
    kz: u8,
    sx: f32,
    sy: f32,
}

impl ShearedRay {
    #[inline(always)]
    fn new(ray: &Ray) -> Self {
        let a = ray.dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        if component(ray.dir, kz) < 0.0 {
            core::mem::swap(&mut kx, &mut ky);
        }
        let dz = component(ray.dir, kz);
        Self {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: component(ray.dir, kx) / dz,
            sy: component(ray.dir, ky) / dz,
        }
    }

    /// A vertex's 2D position across the ray: the same bits in every triangle that shares it.
    #[inline(always)]
    fn project(&self, v: [f32; 3]) -> (f32, f32) {
        let a = Vec3::from(v) - self.origin;
        let z = component(a, self.kz);
        (
            component(a, self.kx) - self.sx * z,
            component(a, self.ky) - self.sy * z,
        )
    }
}

// A computed axis read by selects, not by indexing (which puts the vector in a GPU thread's
// local memory).
#[inline(always)]
fn component(v: Vec3, axis: u8) -> f32 {
    match axis {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// The edge function of the edge from `a` to `b`: twice the signed area of the ray's point and
/// the edge across the ray, exactly negated for the edge from `b` to `a` (products commute and
/// `x - y = -(y - x)` exactly); recomputed exactly in f64 where f32 rounds it to 0 (Woop et al.'s
/// fallback: the products of two f32 are exact in f64).
#[inline(always)]
fn edge_function(a: (f32, f32), b: (f32, f32)) -> f32 {
    let w = a.0 * b.1 - a.1 * b.0;
    if w != 0.0 {
        return w;
    }
    let w = f64::from(a.0) * f64::from(b.1) - f64::from(a.1) * f64::from(b.0);
    if w > 0.0 {
        1.0
    } else if w < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The distance at which `ray` crosses `tri` in the direction `crossing` asks for, if it does,
/// at a distance in `[0, t_max)` (see the module documentation).
///
/// The cheap tests come first, each deciding as the full test would: the crossing's direction is
/// the sign of `n . d` (a triangle facing the wrong way is no crossing, whatever its edges), and
/// the distance is the plane's alone, so a triangle behind the ray or beyond `t_max` is rejected
/// before its vertices are read; the edge functions run for the few that remain.
#[inline(always)]
fn intersect(
    tri: &MeshTriangle,
    ray: &Ray,
    sheared: &ShearedRay,
    crossing: Crossing,
    t_max: f32,
) -> Option<f32> {
    let n = Vec3::from(tri.normal);
    let cos = n.dot(ray.dir);
    let entering = match crossing {
        Crossing::Entering => cos < 0.0,
        Crossing::Leaving => false,
        Crossing::Any => cos < 0.0,
    };
    let leaving = match crossing {
        Crossing::Entering => false,
        Crossing::Leaving | Crossing::Any => cos > 0.0,
    };
    if !entering && !leaving {
        return None;
    }
    let distance = tri.offset - n.dot(ray.origin);
    // Entering is the box's near slab (times the reciprocal), leaving its far slab (a quotient).
    let t = if entering {
        distance * recip_scalar(cos)
    } else {
        div_scalar(distance, cos)
    };
    // A NaN distance (a degenerate plane) is no crossing.
    if !(t >= 0.0 && t < t_max) {
        return None;
    }
    let p = tri.v.map(|v| sheared.project(v));
    let w0 = edge_function(p[1], p[2]);
    let w1 = edge_function(p[2], p[0]);
    let w2 = edge_function(p[0], p[1]);
    let inside = if entering {
        w0 <= 0.0 && w1 <= 0.0 && w2 <= 0.0
    } else {
        w0 >= 0.0 && w1 >= 0.0 && w2 >= 0.0
    };
    inside.then_some(t)
}

impl Shape for TriangleMesh<'_> {
    const CONVEX: bool = false;
    const SHADING_NORMALS: bool = true;

    type Exit<'e>
        = crate::flight::LazyExit<'e>
    where
        Self: 'e;

    #[inline(always)]
    fn flight_exit<'e>(&'e self, ray: &'e Ray) -> Self::Exit<'e> {
        crate::flight::LazyExit::cast_later(self, ray, self.distance.at(ray.origin))
    }

    #[inline(always)]
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Inside if the nearest crossing along a fixed direction leaves the mesh; a point outside
    /// the mesh's box (a camera's) is outside without a cast.
    #[inline]
    fn contains(&self, p: Vec3) -> bool {
        if !self.bounds.contains(p) {
            return false;
        }
        let ray = Ray::new(p, CONTAINS_DIRECTION);
        self.contains_by(&ray, self.nearest(&ray, Crossing::Any))
    }

    #[inline]
    fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        let (t, i) = self.nearest(ray, Crossing::Entering)?;
        Some(self.hit(ray, t, i))
    }

    /// See [`TriangleMesh::exit_by`].
    #[inline]
    fn exit(&self, ray: &Ray) -> BoxHit {
        self.exit_by(ray, self.nearest(ray, Crossing::Leaving))
    }

    #[inline]
    fn exit_distance(&self, ray: &Ray) -> f32 {
        match self.nearest(ray, Crossing::Leaving) {
            Some((t, _)) => t,
            None => 0.0,
        }
    }
}
