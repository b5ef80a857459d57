//! The boundary's geometry: the closed surface that bounds the medium. The path step asks a shape
//! four questions: its bounding box, whether a point is inside, where a ray from outside enters and
//! where a ray from inside leaves.
//!
//! An axis-aligned box ([`Aabb`]) is the special case: one slab test answers each question. A
//! closed triangle mesh ([`crate::mesh::TriangleMesh`]) answers them with a ray cast through its
//! BVH. Every answer's normal is the surface's outward geometric normal.

use crate::flight::{FlightEnd, LazyExit};
use crate::geometry::{Aabb, BoxHit, Ray};
use crate::mesh::{BvhNode, Crossing, MeshTriangle, SurfaceDistance, TriangleMesh};
use crate::Vec3;

/// A closed surface bounding the medium.
///
/// `entry` only reports surface a ray crosses from outside to inside, `exit` only surface it
/// crosses from inside to outside: a path that has just crossed the surface at a point on it asks
/// the other question next, so the surface element it stands on is never its next hit (no
/// self-intersection epsilon).
pub trait Shape {
    /// Whether every ray leaves the shape once and never meets it again: a path's light that
    /// leaves it reaches the environment, and a shadow ray needs one exit.
    const CONVEX: bool;

    /// Whether a hit's shading normal may differ from its geometric one ([`BoxHit::shading`]):
    /// only then does the path step check a scattered direction's side against both
    /// (`path::shading_normal`), so a shape without vertex normals carries no such test.
    const SHADING_NORMALS: bool = false;

    /// [`Shape::CONVEX`] for this shape: a shape chosen at run time ([`BoundaryShape`]) knows only
    /// then. A compile-time constant for every other shape.
    #[inline(always)]
    fn convex(&self) -> bool {
        Self::CONVEX
    }

    fn bounds(&self) -> Aabb;

    /// Whether `p` is inside (or on) the shape.
    fn contains(&self, p: crate::Vec3) -> bool;

    /// The first point where `ray`, from outside, enters the shape, if it does.
    fn entry(&self, ray: &Ray) -> Option<BoxHit>;

    /// Where `ray`, from inside (or on) the shape, leaves it.
    fn exit(&self, ray: &Ray) -> BoxHit;

    /// `exit(ray).t`, the same bits, for a free flight that needs only the distance.
    fn exit_distance(&self, ray: &Ray) -> f32;

    /// `exit_distance(ray)` as a free flight compares with it: the distance itself for a box, a
    /// mesh's found only if a flight gets far enough to need it ([`crate::flight`]).
    type Exit<'a>: FlightEnd + Copy
    where
        Self: 'a;

    fn flight_exit<'a>(&'a self, ray: &'a Ray) -> Self::Exit<'a>;

    /// `exit(ray)` for a free flight that escaped, given `end`, its [`Shape::flight_exit`]: a
    /// shape whose flight end holds the surface it found builds the hit from it instead of
    /// casting the same ray again.
    #[inline(always)]
    fn escaped_exit<'a>(&'a self, ray: &'a Ray, end: &Self::Exit<'a>) -> BoxHit {
        let _ = end;
        self.exit(ray)
    }
}

impl Shape for Aabb {
    const CONVEX: bool = true;

    type Exit<'a> = f32;

    #[inline(always)]
    fn flight_exit<'a>(&'a self, ray: &'a Ray) -> f32 {
        Aabb::exit_distance(self, ray)
    }

    #[inline(always)]
    fn bounds(&self) -> Aabb {
        *self
    }

    #[inline(always)]
    fn contains(&self, p: crate::Vec3) -> bool {
        Aabb::contains(self, p)
    }

    #[inline(always)]
    fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        Aabb::entry(self, ray)
    }

    #[inline(always)]
    fn exit(&self, ray: &Ray) -> BoxHit {
        Aabb::exit(self, ray)
    }

    #[inline(always)]
    fn exit_distance(&self, ray: &Ray) -> f32 {
        Aabb::exit_distance(self, ray)
    }
}

/// The boundary a scene file describes, chosen at run time: its box, or a closed triangle mesh.
/// One scene type serves both, so a mesh boundary costs no second copy of every variant's code;
/// a box pays one well-predicted branch per question. The mesh's questions are functions of their
/// own (`inline(never)`): one copy of the BVH traversal, whatever the variant.
#[derive(Clone, Copy, Debug)]
pub enum BoundaryShape<'a> {
    Box(Aabb),
    Mesh(TriangleMesh<'a>),
}

impl Shape for BoundaryShape<'_> {
    const CONVEX: bool = false;
    const SHADING_NORMALS: bool = true;

    type Exit<'e>
        = LazyExit<'e>
    where
        Self: 'e;

    #[inline(always)]
    fn flight_exit<'e>(&'e self, ray: &'e Ray) -> LazyExit<'e> {
        match self {
            BoundaryShape::Box(b) => LazyExit::known(Aabb::exit_distance(b, ray), ray),
            BoundaryShape::Mesh(m) => m.flight_exit(ray),
        }
    }

    #[inline(always)]
    fn convex(&self) -> bool {
        matches!(self, BoundaryShape::Box(_))
    }

    #[inline(always)]
    fn bounds(&self) -> Aabb {
        match self {
            BoundaryShape::Box(b) => *b,
            BoundaryShape::Mesh(m) => m.bounds,
        }
    }

    #[inline(always)]
    fn contains(&self, p: crate::Vec3) -> bool {
        match self {
            BoundaryShape::Box(b) => Aabb::contains(b, p),
            BoundaryShape::Mesh(m) => mesh_contains(m, p),
        }
    }

    #[inline(always)]
    fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        match self {
            BoundaryShape::Box(b) => Aabb::entry(b, ray),
            BoundaryShape::Mesh(m) => mesh_entry(m, ray),
        }
    }

    #[inline(always)]
    fn exit(&self, ray: &Ray) -> BoxHit {
        match self {
            BoundaryShape::Box(b) => Aabb::exit(b, ray),
            BoundaryShape::Mesh(m) => mesh_exit(m, ray),
        }
    }

    #[inline(always)]
    fn exit_distance(&self, ray: &Ray) -> f32 {
        match self {
            BoundaryShape::Box(b) => Aabb::exit_distance(b, ray),
            BoundaryShape::Mesh(m) => mesh_exit_distance(m, ray),
        }
    }
}

#[inline(never)]
fn mesh_contains(mesh: &TriangleMesh<'_>, p: crate::Vec3) -> bool {
    mesh.contains(p)
}

#[inline(never)]
fn mesh_entry(mesh: &TriangleMesh<'_>, ray: &Ray) -> Option<BoxHit> {
    mesh.entry(ray)
}

#[inline(never)]
fn mesh_exit(mesh: &TriangleMesh<'_>, ray: &Ray) -> BoxHit {
    mesh.exit(ray)
}

#[inline(never)]
fn mesh_exit_distance(mesh: &TriangleMesh<'_>, ray: &Ray) -> f32 {
    mesh.exit_distance(ray)
}

/// The boundary as a kernel that traces meshes rebuilds it from the launch parameters
/// ([`crate::abi::DeviceShape::Kernel`]): the box, and a mesh's BVH nodes and triangles (none for
/// a box), so that one kernel serves both and a box pays a test of a launch parameter (`nodes`
/// empty) per question. The mesh kernels take it (`volpt_device::KernelSet::Mesh`), the box
/// kernels not: it costs a kernel registers (docs/gpu.md, kernel sets); the CPU renders it to
/// check that it traces the CPU's paths.
///
/// A mesh's ray cast is one out-of-line function of scalars ([`device_nearest`]): an aggregate
/// argument (a `Vec3`, a `Ray`, a reference into the path or the scene) passed to a call that is
/// not inlined travels through the caller's local memory, and keeps the path state there; the
/// traversal's stack stays in the callee's frame. A free flight casts the mesh's exit as it
/// starts, so the trackers compare with an `f32`, as for the box ([`DeviceExit`], which keeps
/// the triangle for an escaped flight's exit): a lazy exit (the CPU's [`BoundaryShape`]) would
/// carry its state and a call through every tracking loop. Both trace the same paths
/// ([`crate::flight`]).
#[derive(Clone, Copy, Debug)]
pub struct DeviceBoundary<'a> {
    pub bounds: Aabb,
    pub nodes: &'a [BvhNode],
    pub triangles: &'a [MeshTriangle],
}

impl<'a> DeviceBoundary<'a> {
    /// The box `bounds`.
    pub const fn box_(bounds: Aabb) -> Self {
        Self {
            bounds,
            nodes: &[],
            triangles: &[],
        }
    }

    /// `mesh`, without its distance grid (the kernels cast every flight's exit) and without
    /// vertex normals: the GPU refuses a mesh that has them (`volpt_cuda`'s kernel sets).
    pub fn mesh(mesh: &TriangleMesh<'a>) -> Self {
        Self {
            bounds: mesh.bounds,
            nodes: mesh.nodes,
            triangles: mesh.triangles,
        }
    }

    #[inline(always)]
    fn is_box(&self) -> bool {
        self.nodes.is_empty()
    }

    #[inline(always)]
    fn as_mesh(&self) -> TriangleMesh<'a> {
        TriangleMesh {
            nodes: self.nodes,
            triangles: self.triangles,
            normals: &[],
            bounds: self.bounds,
            distance: SurfaceDistance::NONE,
        }
    }

    /// [`TriangleMesh::nearest`], out of line.
    #[inline(always)]
    fn nearest(&self, ray: &Ray, crossing: Crossing) -> Option<(f32, u32)> {
        let (o, d) = (ray.origin, ray.dir);
        let code = match crossing {
            Crossing::Entering => 0,
            Crossing::Leaving => 1,
            Crossing::Any => 2,
        };
        let found = device_nearest(
            self.nodes,
            self.triangles,
            o.x,
            o.y,
            o.z,
            d.x,
            d.y,
            d.z,
            code,
        );
        // The index's bits are `u32::MAX` where nothing was crossed.
        let index = found as u32;
        (index != u32::MAX).then_some((f32::from_bits((found >> 32) as u32), index))
    }
}

/// [`TriangleMesh::nearest`] of the ray from `o` along `d` and crossing `crossing` (0 entering,
/// 1 leaving, 2 any), packed: the distance's bits high, the triangle low (`u32::MAX`: none).
/// Scalars in and out: an aggregate (a `Vec3`, a tuple, an array) would be passed through the
/// caller's local memory.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn device_nearest(
    nodes: &[BvhNode],
    triangles: &[MeshTriangle],
    ox: f32,
    oy: f32,
    oz: f32,
    dx: f32,
    dy: f32,
    dz: f32,
    crossing: u8,
) -> u64 {
    let mesh = TriangleMesh {
        nodes,
        triangles,
        normals: &[],
        bounds: Aabb::new(Vec3::ZERO, Vec3::ZERO),
        distance: SurfaceDistance::NONE,
    };
    let ray = Ray::new(Vec3::new(ox, oy, oz), Vec3::new(dx, dy, dz));
    let crossing = match crossing {
        0 => Crossing::Entering,
        1 => Crossing::Leaving,
        _ => Crossing::Any,
    };
    match mesh.nearest(&ray, crossing) {
        Some((t, i)) => (u64::from(t.to_bits()) << 32) | u64::from(i),
        None => u64::from(u32::MAX),
    }
}

/// A [`DeviceBoundary`]'s free-flight end: the exit distance, cast as the flight starts, and the
/// triangle it leaves by (`u32::MAX`: none, or a box), so that an escaped flight's exit is built
/// without a second cast ([`Shape::escaped_exit`]). Compares as its distance does.
#[derive(Clone, Copy, Debug)]
pub struct DeviceExit {
    t: f32,
    triangle: u32,
}

impl FlightEnd for DeviceExit {
    #[inline(always)]
    fn reached(&mut self, t: f32) -> bool {
        t >= self.t
    }
    #[inline(always)]
    fn before(&mut self, t: f32) -> bool {
        t < self.t
    }
    #[inline(always)]
    fn clip(&mut self, t: f32) -> f32 {
        t.min(self.t)
    }
    #[inline(always)]
    fn exact(&mut self) -> f32 {
        self.t
    }
}

impl Shape for DeviceBoundary<'_> {
    const CONVEX: bool = false;

    type Exit<'e>
        = DeviceExit
    where
        Self: 'e;

    /// [`Shape::exit_distance`], with the triangle.
    #[inline(always)]
    fn flight_exit<'e>(&'e self, ray: &'e Ray) -> DeviceExit {
        if self.is_box() {
            return DeviceExit {
                t: Aabb::exit_distance(&self.bounds, ray),
                triangle: u32::MAX,
            };
        }
        match self.nearest(ray, Crossing::Leaving) {
            Some((t, triangle)) => DeviceExit { t, triangle },
            None => DeviceExit {
                t: 0.0,
                triangle: u32::MAX,
            },
        }
    }

    /// [`Shape::exit`] from the cast `end` already made.
    #[inline(always)]
    fn escaped_exit<'e>(&'e self, ray: &'e Ray, end: &DeviceExit) -> BoxHit {
        if self.is_box() {
            return Aabb::exit(&self.bounds, ray);
        }
        let found = (end.triangle != u32::MAX).then_some((end.t, end.triangle));
        self.as_mesh().exit_by(ray, found)
    }

    #[inline(always)]
    fn convex(&self) -> bool {
        self.is_box()
    }

    #[inline(always)]
    fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline(always)]
    fn contains(&self, p: Vec3) -> bool {
        // A point outside the box is outside the mesh too, without a cast.
        if self.is_box() || !Aabb::contains(&self.bounds, p) {
            return Aabb::contains(&self.bounds, p);
        }
        let ray = Ray::new(p, crate::mesh::CONTAINS_DIRECTION);
        self.as_mesh()
            .contains_by(&ray, self.nearest(&ray, Crossing::Any))
    }

    #[inline(always)]
    fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        if self.is_box() {
            return Aabb::entry(&self.bounds, ray);
        }
        let (t, i) = self.nearest(ray, Crossing::Entering)?;
        Some(self.as_mesh().hit(ray, t, i))
    }

    #[inline(always)]
    fn exit(&self, ray: &Ray) -> BoxHit {
        if self.is_box() {
            return Aabb::exit(&self.bounds, ray);
        }
        self.as_mesh()
            .exit_by(ray, self.nearest(ray, Crossing::Leaving))
    }

    #[inline(always)]
    fn exit_distance(&self, ray: &Ray) -> f32 {
        if self.is_box() {
            return Aabb::exit_distance(&self.bounds, ray);
        }
        match self.nearest(ray, Crossing::Leaving) {
            Some((t, _)) => t,
            None => 0.0,
        }
    }
}
