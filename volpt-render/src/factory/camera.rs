//! The camera of a description.

use super::*;

/// Mitsuba's perspective camera: the field of view spans `fov_axis`, the other axis follows from the
/// film's aspect ratio. Mitsuba 3's orthographic camera: the film spans camera-space x in [-1, 1]
/// and y in [-h/w, h/w] (its `orthographic_projection`), scaled by `to_world`.
pub fn camera(desc: &CameraDesc, film: &FilmDesc) -> PerspectiveCamera {
    let m = desc.to_world;
    let column = |j: usize| Vec3::new(m[0][j], m[1][j], m[2][j]);
    let (w, h) = (film.width as f32, film.height as f32);
    let tan_half = tan(0.5 * desc.fov_degrees.to_radians());
    let along_x = Vec2::new(tan_half, tan_half * h / w);
    let along_y = Vec2::new(tan_half * w / h, tan_half);
    let orthographic = desc.projection == Projection::Orthographic;
    let tan_half_fov = match desc.fov_axis {
        _ if orthographic => Vec2::new(1.0, h / w),
        FovAxis::X => along_x,
        FovAxis::Y => along_y,
        FovAxis::Smaller if w <= h => along_x,
        FovAxis::Smaller => along_y,
        FovAxis::Larger if w >= h => along_x,
        FovAxis::Larger => along_y,
        FovAxis::Diagonal => {
            let diagonal = (w * w + h * h).sqrt();
            Vec2::new(tan_half * w / diagonal, tan_half * h / diagonal)
        }
    };
    PerspectiveCamera {
        origin: column(3),
        axis_x: column(0),
        axis_y: column(1),
        axis_z: column(2),
        tan_half_fov,
        width: film.width,
        height: film.height,
        orthographic,
    }
}
