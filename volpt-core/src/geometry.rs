//! Rays and the axis-aligned box that bounds the medium.

use crate::math::{div, recip};
use crate::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    /// Unit propagation direction.
    pub dir: Vec3,
}

impl Ray {
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self { origin, dir }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Where a ray meets a face of the box: the distance, the point (snapped exactly onto the face's
/// plane, so that no later test sees it a rounding error inside or outside) and the outward normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxHit {
    pub t: f32,
    pub point: Vec3,
    /// The surface's outward geometric normal: which side is which.
    pub normal: Vec3,
    /// The outward normal the boundary's BSDF scatters about: `normal` itself, except on a mesh
    /// with vertex normals ([`crate::mesh::TriangleMesh::normals`]), where it is interpolated
    /// and lies in `normal`'s hemisphere.
    pub shading: Vec3,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    #[inline]
    pub fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    #[inline]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    #[inline]
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Where a ray from outside enters the box, if it does: the ray must run along a segment of
    /// positive length inside the closed box, starting at a distance >= 0. A ray whose origin lies
    /// inside or on the box and that points away from it does not enter (the slab test's entry
    /// distance is then negative, or, from an edge or corner, equal to the exit distance 0), and
    /// neither does a ray that only touches an edge or a corner. A ray in the plane of a face that
    /// crosses the face enters (the box is closed). Edges and corners resolve to one face, that of
    /// the last slab entered.
    #[inline]
    pub fn entry(&self, ray: &Ray) -> Option<BoxHit> {
        let inv = recip(ray.dir);
        let t0 = (self.min - ray.origin) * inv;
        let t1 = (self.max - ray.origin) * inv;
        let near = t0.min(t1);
        let far = t0.max(t1);
        // An axis the ray runs parallel to (a zero component of either sign, or one so small that
        // its reciprocal overflows) gives +-inf, or NaN (0 * inf) for a plane the ray lies in, and
        // `min`/`max` would let one plane's infinity or NaN decide. Such a slab puts no constraint on
        // a ray whose origin lies in it (the closed slab, planes included) and excludes any other.
        let parallel = inv.abs().cmpeq(Vec3::INFINITY);
        let in_slab = ray.origin.cmpge(self.min) & ray.origin.cmple(self.max);
        let inf = Vec3::INFINITY;
        let near = Vec3::select(parallel, Vec3::select(in_slab, -inf, inf), near);
        let far = Vec3::select(parallel, Vec3::select(in_slab, inf, -inf), far);
        let axis = argmax(near);
        let t_enter = component(near, axis);
        let t_leave = far.min_element();
        if !(t_enter >= 0.0 && t_enter < t_leave) {
            return None;
        }
        let entering_max_face = component(ray.dir, axis) < 0.0;
        let face = if entering_max_face {
            component(self.max, axis)
        } else {
            component(self.min, axis)
        };
        let point = with_component(ray.at(t_enter), axis, face);
        let normal = axis_normal(axis, entering_max_face);
        Some(BoxHit {
            t: t_enter,
            point: self.clamp(point),
            normal,
            shading: normal,
        })
    }

    /// Where a ray whose origin is inside (or on) the box leaves it. Only the far planes are used, so
    /// the answer is right for an origin on a face, edge or corner, and never negative.
    #[inline]
    pub fn exit(&self, ray: &Ray) -> BoxHit {
        let (far_plane, t) = self.far_planes(ray);
        let axis = argmin(t);
        let t_exit = component(t, axis).max(0.0);
        let point = with_component(ray.at(t_exit), axis, component(far_plane, axis));
        let normal = axis_normal(axis, component(ray.dir, axis) > 0.0);
        BoxHit {
            t: t_exit,
            point: self.clamp(point),
            normal,
            shading: normal,
        }
    }

    /// `exit(ray).t`, the same bits, without the exit point and face: a free flight needs only
    /// the distance, and the face only when the flight escapes (1 flight in ~86 on the
    /// index-matched cube). Computing point and face on every flight cost the GPU a third of the
    /// exit's instructions and three branches.
    #[inline]
    pub fn exit_distance(&self, ray: &Ray) -> f32 {
        let (_, t) = self.far_planes(ray);
        component(t, argmin(t)).max(0.0)
    }

    /// The far plane of each slab for `ray`'s direction and the distance to it; axes the ray runs
    /// parallel to (whose division gives +-inf or NaN) at +inf, never the exit face.
    #[inline(always)]
    fn far_planes(&self, ray: &Ray) -> (Vec3, Vec3) {
        let far_plane = Vec3::select(ray.dir.cmpgt(Vec3::ZERO), self.max, self.min);
        let t = div(far_plane - ray.origin, ray.dir);
        let t = Vec3::select(t.cmpeq(t), t, Vec3::splat(f32::INFINITY));
        let t = Vec3::select(ray.dir.cmpeq(Vec3::ZERO), Vec3::splat(f32::INFINITY), t);
        (far_plane, t)
    }

    #[inline]
    fn clamp(&self, p: Vec3) -> Vec3 {
        p.max(self.min).min(self.max)
    }
}

#[inline]
fn axis_normal(axis: usize, positive: bool) -> Vec3 {
    with_component(Vec3::ZERO, axis, if positive { 1.0 } else { -1.0 })
}

// Component access by a computed axis, written as selects: indexing a `Vec3` by a runtime
// `usize` makes the GPU compiler put the vector in local memory (an 88-byte stack frame in every
// kernel, stores and loads on each boundary hit).

#[inline(always)]
fn component(v: Vec3, axis: usize) -> f32 {
    match axis {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

#[inline(always)]
fn with_component(v: Vec3, axis: usize, value: f32) -> Vec3 {
    Vec3::new(
        if axis == 0 { value } else { v.x },
        if axis == 1 { value } else { v.y },
        if axis == 2 { value } else { v.z },
    )
}

#[inline]
fn argmax(v: Vec3) -> usize {
    if v.x >= v.y && v.x >= v.z {
        0
    } else if v.y >= v.z {
        1
    } else {
        2
    }
}

#[inline]
fn argmin(v: Vec3) -> usize {
    if v.x <= v.y && v.x <= v.z {
        0
    } else if v.y <= v.z {
        1
    } else {
        2
    }
}
