//! Warps from the unit square to directions and disks (pbrt-v4, section A.5).

use crate::math::{safe_sqrt, sin_cos_2pi};
use crate::{Vec2, Vec3};

/// Uniform point on the unit disk in polar form.
#[inline]
pub fn sample_uniform_disk_polar(u: Vec2) -> Vec2 {
    let r = safe_sqrt(u.x);
    let (s, c) = sin_cos_2pi(u.y);
    Vec2::new(r * c, r * s)
}

/// Uniform direction on the unit sphere; pdf `1 / (4 pi)`.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = safe_sqrt(1.0 - z * z);
    let (s, c) = sin_cos_2pi(u.y);
    Vec3::new(r * c, r * s, z)
}

/// The direction with polar cosine `cos_theta` about `axis` and azimuth `2 pi u`.
#[inline]
pub fn direction_about(axis: Vec3, cos_theta: f32, u: f32) -> Vec3 {
    let frame = crate::frame::Frame::from_z(axis);
    let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
    let (s, c) = sin_cos_2pi(u);
    frame.to_world(Vec3::new(sin_theta * c, sin_theta * s, cos_theta))
}
