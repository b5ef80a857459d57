//! The camera, in Mitsuba's conventions: a pinhole (`perspective`) or, as a run-time branch of
//! the same type, Mitsuba's `orthographic` sensor.

use crate::{Ray, Vec2, Vec3};

/// Camera space looks along +z with +y up and +x to the image's *left* (Mitsuba's convention, which
/// its `lookat` builds); image x grows to the right and image y downwards.
#[derive(Clone, Copy, Debug)]
pub struct PerspectiveCamera {
    pub origin: Vec3,
    /// Images of the camera-space axes under the camera's to-world transform (not normalised: a
    /// mirroring or scaling transform acts on directions as in Mitsuba).
    pub axis_x: Vec3,
    pub axis_y: Vec3,
    pub axis_z: Vec3,
    /// `tan(fov_x / 2)` and `tan(fov_y / 2)`; for an orthographic camera, the film's half
    /// extents in camera space instead: `(1, height / width)`, as Mitsuba 3 spans them.
    pub tan_half_fov: Vec2,
    pub width: u32,
    pub height: u32,
    /// Mitsuba's `orthographic` sensor: parallel rays along `axis_z` from the film's position
    /// `axis_x * x + axis_y * y` (camera-space `(x, y, 0)`; Mitsuba starts them at its near clip,
    /// 0.01 along the axis, which differs only for a medium closer than that to the film).
    pub orthographic: bool,
}

impl PerspectiveCamera {
    /// The primary ray through the film position `(px + u.x, py + u.y)` in pixels.
    #[inline]
    pub fn generate_ray(&self, px: u32, py: u32, u: Vec2) -> Ray {
        let sx = (px as f32 + u.x) / self.width as f32;
        let sy = (py as f32 + u.y) / self.height as f32;
        let x = (1.0 - 2.0 * sx) * self.tan_half_fov.x;
        let y = (1.0 - 2.0 * sy) * self.tan_half_fov.y;
        let film = self.axis_x * x + self.axis_y * y;
        // Selects, not a branch: a branch here, inside the strategies' path loops, took smoke's
        // kernel from 80 to 95 registers and 5% more time on an H200
        // (bench/results/2026-11-29-h200-session10). The pinhole's arithmetic is the same as
        // without the orthographic case.
        let (origin, dir) = if self.orthographic {
            (self.origin + film, self.axis_z)
        } else {
            (self.origin, film + self.axis_z)
        };
        Ray::new(origin, crate::math::normalize(dir))
    }
}
