//! Where a free flight ends if it collides with nothing: the boundary's exit distance, known at
//! once for a box (one slab test) and found lazily for a mesh (a ray cast through its BVH, cast
//! only once a tentative collision gets past a distance the surface is known to lie beyond).
//!
//! The trackers compare distances with the end only through [`FlightEnd`], each comparison with
//! the result it has with the exact distance: a flight traces the same path whether the ray was
//! cast or not.

use crate::mesh::TriangleMesh;
use crate::Ray;

/// A free flight's end, as delta tracking compares with it. For an `f32` (the box's exit
/// distance) every method is the comparison itself.
pub trait FlightEnd {
    /// `t >= end`: the flight got past the end.
    fn reached(&mut self, t: f32) -> bool;
    /// `t < end`.
    fn before(&mut self, t: f32) -> bool;
    /// `t.min(end)` (`f32::min`: a NaN `t` gives the end).
    fn clip(&mut self, t: f32) -> f32;
    /// The end itself.
    fn exact(&mut self) -> f32;
}

impl FlightEnd for f32 {
    #[inline(always)]
    fn reached(&mut self, t: f32) -> bool {
        t >= *self
    }
    #[inline(always)]
    fn before(&mut self, t: f32) -> bool {
        t < *self
    }
    #[inline(always)]
    fn clip(&mut self, t: f32) -> f32 {
        t.min(*self)
    }
    #[inline(always)]
    fn exact(&mut self) -> f32 {
        *self
    }
}

/// A mesh's exit distance along `ray`, cast only when a comparison needs it: `safe` is a distance
/// the exit is known to lie beyond ([`crate::mesh::SurfaceDistance`]); a distance below it
/// compares as it would with the exit, without the cast.
#[derive(Clone, Copy, Debug)]
pub struct LazyExit<'a> {
    /// `<= exact`; equal to it once it is known.
    safe: f32,
    exact: f32,
    /// The mesh to cast the ray through, until it has been.
    mesh: Option<&'a TriangleMesh<'a>>,
    ray: &'a Ray,
}

impl<'a> LazyExit<'a> {
    /// An exit already known: `t`.
    #[inline(always)]
    pub fn known(t: f32, ray: &'a Ray) -> Self {
        Self {
            safe: t,
            exact: t,
            mesh: None,
            ray,
        }
    }

    /// `mesh`'s exit along `ray`, which lies beyond `safe`.
    #[inline(always)]
    pub fn cast_later(mesh: &'a TriangleMesh<'a>, ray: &'a Ray, safe: f32) -> Self {
        Self {
            safe,
            exact: 0.0,
            mesh: Some(mesh),
            ray,
        }
    }

    /// Whether the ray was cast (for measuring how many flights still cast one).
    pub fn was_cast(&self) -> bool {
        self.mesh.is_none()
    }
}

/// The ray cast, kept out of line: one copy for every variant.
#[inline(never)]
fn cast(mesh: &TriangleMesh<'_>, ray: &Ray) -> f32 {
    crate::shape::Shape::exit_distance(mesh, ray)
}

impl FlightEnd for LazyExit<'_> {
    #[inline(always)]
    fn reached(&mut self, t: f32) -> bool {
        // `t < safe` is `t < exact` too; a NaN `t` asks the exact distance (and is not past it).
        if t < self.safe {
            return false;
        }
        t >= self.exact()
    }
    #[inline(always)]
    fn before(&mut self, t: f32) -> bool {
        if t < self.safe {
            return true;
        }
        t < self.exact()
    }
    #[inline(always)]
    fn clip(&mut self, t: f32) -> f32 {
        if t <= self.safe {
            return t;
        }
        t.min(self.exact())
    }
    #[inline(always)]
    fn exact(&mut self) -> f32 {
        if let Some(mesh) = self.mesh.take() {
            self.exact = cast(mesh, self.ray);
            self.safe = self.exact;
        }
        self.exact
    }
}
