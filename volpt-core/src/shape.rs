//! The boundary's geometry: the closed surface that bounds the medium. The path step asks a shape
//! four questions: its bounding box, whether a point is inside, where a ray from outside enters and
//! where a ray from inside leaves.
//!
//! An axis-aligned box ([`Aabb`]) is the special case: one slab test answers each question. A
//! closed triangle mesh ([`crate::mesh::TriangleMesh`]) answers them with a ray cast through its
//! BVH. Every answer's normal is the surface's outward geometric normal.

use crate::flight::{FlightEnd, LazyExit};
use crate::geometry::{Aabb, BoxHit, Ray};
use crate::mesh::TriangleMesh;

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
    type Exit<'a>: FlightEnd
    where
        Self: 'a;

    fn flight_exit<'a>(&'a self, ray: &'a Ray) -> Self::Exit<'a>;
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
