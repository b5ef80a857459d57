//! The pinhole camera's primary rays by their geometric properties: the film's centre looks along
//! the camera's axis, its corners at the field of view in Mitsuba's orientation (+x camera-space to
//! the image's left, image y downwards), and the jitter `u` in [0, 1)^2 covers exactly its pixel,
//! so pixels tile the film. The whole-renderer references check the camera through images; this
//! catches the same mistakes in volpt-core's own tests, in milliseconds (mutation testing, shard
//! 2/8: `camera.rs` mutants reached only the renderer stage).

use glam::DVec3;
use volpt_core::{PerspectiveCamera, Vec2, Vec3};

/// Not axis-aligned, not normalised (a scaling to-world transform acts on directions as in
/// Mitsuba), and a film whose sides differ.
fn camera() -> PerspectiveCamera {
    PerspectiveCamera {
        origin: Vec3::new(1.0, -2.0, 0.5),
        axis_x: Vec3::new(0.0, 0.0, -2.0),
        axis_y: Vec3::new(0.0, 2.0, 0.0),
        axis_z: Vec3::new(2.0, 0.0, 0.0),
        tan_half_fov: Vec2::new(0.75, 0.5),
        width: 12,
        height: 8,
        orthographic: false,
    }
}

fn d(v: Vec3) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// The direction, in f64, of camera-space `(x, y, 1)`.
fn camera_space(c: &PerspectiveCamera, x: f64, y: f64) -> DVec3 {
    (d(c.axis_x) * x + d(c.axis_y) * y + d(c.axis_z)).normalize()
}

fn assert_close(a: Vec3, b: DVec3, what: &str) {
    assert!(
        (d(a) - b).length() < 1e-6,
        "{what}: direction {a}, expected {b}"
    );
}

#[test]
fn film_centre_and_corners_look_where_the_field_of_view_says() {
    let c = camera();
    let (tx, ty) = (c.tan_half_fov.x as f64, c.tan_half_fov.y as f64);
    // Film position (w/2, h/2): the camera's axis.
    let centre = c.generate_ray(c.width / 2, c.height / 2, Vec2::ZERO);
    assert_eq!(centre.origin, c.origin);
    assert_close(centre.dir, camera_space(&c, 0.0, 0.0), "centre");
    // Film position (0, 0) is the image's top left: camera-space +x (left) and +y (up).
    let top_left = c.generate_ray(0, 0, Vec2::ZERO);
    assert_close(top_left.dir, camera_space(&c, tx, ty), "top left");
    // The last pixel's far corner, (w, h): bottom right.
    let bottom_right = c.generate_ray(c.width - 1, c.height - 1, Vec2::ONE);
    assert_close(bottom_right.dir, camera_space(&c, -tx, -ty), "bottom right");
    // A quarter across and three quarters down.
    let p = c.generate_ray(c.width / 4, 3 * c.height / 4, Vec2::ZERO);
    assert_close(p.dir, camera_space(&c, tx / 2.0, -ty / 2.0), "(w/4, 3h/4)");
}

/// `u` moves the ray across the pixel from its corner `(px, py)` towards `(px + 1, py + 1)`, so
/// each pixel's rays are its own and the pixels tile the film.
#[test]
fn jitter_covers_exactly_its_pixel() {
    let c = camera();
    for (px, py) in [(0, 0), (3, 5), (10, 2), (11, 7)] {
        let far = c.generate_ray(px, py, Vec2::ONE);
        let next = if px + 1 < c.width && py + 1 < c.height {
            c.generate_ray(px + 1, py + 1, Vec2::ZERO).dir
        } else {
            far.dir
        };
        assert_close(
            far.dir,
            d(next),
            &format!("pixel ({px}, {py}) at u = (1, 1)"),
        );
        // Half way: the pixel's centre, at the film position (px + 0.5, py + 0.5).
        let mid = c.generate_ray(px, py, Vec2::splat(0.5));
        let sx = (px as f64 + 0.5) / c.width as f64;
        let sy = (py as f64 + 0.5) / c.height as f64;
        let expected = camera_space(
            &c,
            (1.0 - 2.0 * sx) * c.tan_half_fov.x as f64,
            (1.0 - 2.0 * sy) * c.tan_half_fov.y as f64,
        );
        assert_close(mid.dir, expected, &format!("pixel ({px}, {py}) centre"));
        // u.x moves the ray along the image's x only (to the right: camera-space x decreases),
        // u.y along its y only (downwards: camera-space y decreases). Camera-space slopes
        // (x / z, y / z) are independent of the direction's length; the axes are orthogonal.
        let slopes = |u: Vec2| {
            let v = d(c.generate_ray(px, py, u).dir);
            let (x, y, z) = (v.dot(d(c.axis_x)), v.dot(d(c.axis_y)), v.dot(d(c.axis_z)));
            (x / z, y / z)
        };
        let (corner, right, down) = (
            slopes(Vec2::ZERO),
            slopes(Vec2::new(1.0, 0.0)),
            slopes(Vec2::new(0.0, 1.0)),
        );
        let step = (
            2.0 * c.tan_half_fov.x as f64 / c.width as f64,
            2.0 * c.tan_half_fov.y as f64 / c.height as f64,
        );
        assert!((corner.0 - right.0 - step.0).abs() < 1e-6 && (right.1 - corner.1).abs() < 1e-6);
        assert!((corner.1 - down.1 - step.1).abs() < 1e-6 && (down.0 - corner.0).abs() < 1e-6);
    }
}

/// Mitsuba 3's `orthographic` sensor: every ray along the camera's axis, starting on the film
/// plane at camera-space `(x, y)` with `x` in [-1, 1] (image left to right: +1 to -1) and `y` in
/// [-h/w, h/w], scaled by the to-world transform; `u` moves the start across its pixel.
#[test]
fn orthographic_rays_are_parallel_and_start_where_the_film_maps_them() {
    let c = PerspectiveCamera {
        orthographic: true,
        tan_half_fov: Vec2::new(1.0, 8.0 / 12.0),
        ..camera()
    };
    let axis = d(c.axis_z).normalize();
    let start = |px, py, u| {
        let r = c.generate_ray(px, py, u);
        assert!(
            (d(r.dir) - axis).length() < 1e-6,
            "({px}, {py}): direction {}",
            r.dir
        );
        d(r.origin)
    };
    let film = |x: f64, y: f64| d(c.origin) + d(c.axis_x) * x + d(c.axis_y) * y;
    let (hx, hy) = (1.0, 8.0 / 12.0);
    let close =
        |a: DVec3, b: DVec3, what: &str| assert!((a - b).length() < 1e-5, "{what}: {a} vs {b}");
    close(start(0, 0, Vec2::ZERO), film(hx, hy), "top left");
    close(
        start(c.width - 1, c.height - 1, Vec2::ONE),
        film(-hx, -hy),
        "bottom right",
    );
    close(
        start(c.width / 2, c.height / 2, Vec2::ZERO),
        film(0.0, 0.0),
        "centre",
    );
    // One pixel across is 2 / width of the film's x extent.
    let step = start(1, 0, Vec2::ZERO) - start(0, 0, Vec2::ZERO);
    close(
        step,
        d(c.axis_x) * (-2.0 * hx / f64::from(c.width)),
        "one pixel",
    );
}
