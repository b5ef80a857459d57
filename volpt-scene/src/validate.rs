//! One check of an assembled scene, whatever built it: every number a renderer relies on is
//! finite and in range, the film and the data fit the memory limit, and the medium is thin enough
//! for delta tracking to cross it in bounded work.
//!
//! The loaders check what they read where they read it (and name the line); this is the backstop
//! that makes the formats agree (a TOML radiance is held to what an XML one is) and that covers
//! scenes built by code.

use crate::description::*;
use crate::error::SceneError;
use crate::limits::{bytes_of, check_memory, MAX_OPTICAL_DEPTH};

/// Bytes a renderer keeps per film pixel: f64 RGB sums, the f32 RGB image and the 8-bit preview,
/// rounded up.
pub const FILM_BYTES_PER_PIXEL: u64 = 40;

pub use crate::boundary::MAX_ALPHA;

/// What checking every value of a scene's data (its grids and environment map) found. The data
/// does not change once a scene is assembled, so a scene whose camera, film or parameters change
/// is checked again by [`validate_settings`] with this, without reading the data again (a viewer
/// moves the camera at every frame; the grids may be gigabytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CheckedData {
    /// The density grid's largest value (0 without a grid).
    pub largest_density: f32,
    /// The albedo grid's largest value (0 without a grid).
    pub largest_albedo: f32,
}

/// Checks `desc`, every value of its data included; `source` names the scene file (or builder) in
/// errors.
pub fn validate(desc: &SceneDescription, source: &str) -> Result<CheckedData, SceneError> {
    check(desc, source, None)
}

/// [`validate`] for a scene whose data `data` says was checked: the same checks, the data's values
/// taken from `data` instead of read. `data` must be what [`validate`] returned for this scene's
/// data (its settings may have changed since).
pub fn validate_settings(
    desc: &SceneDescription,
    source: &str,
    data: CheckedData,
) -> Result<(), SceneError> {
    check(desc, source, Some(data)).map(drop)
}

fn check(
    desc: &SceneDescription,
    source: &str,
    checked: Option<CheckedData>,
) -> Result<CheckedData, SceneError> {
    let invalid =
        |field: &str, expected: &str, found: String| invalid(source, field, expected, found);
    let path = std::path::Path::new(source);

    let FilmDesc { width, height } = desc.film;
    let pixels = u64::from(width) * u64::from(height);
    // Renderers index pixels with u32.
    if width == 0 || height == 0 || pixels > u64::from(u32::MAX) {
        return Err(invalid(
            "film",
            "between 1 and 2^32 - 1 pixels, at least 1 on each side",
            format!("{width} x {height}"),
        ));
    }
    check_memory(
        path,
        &format!("the film of {width} x {height} pixels"),
        bytes_of(pixels, FILM_BYTES_PER_PIXEL),
    )?;
    if desc.spp == 0 {
        return Err(invalid("spp", "at least 1 sample per pixel", "0".into()));
    }
    let camera = &desc.camera;
    // An orthographic camera's rays are parallel: it has no field of view.
    let perspective = camera.projection == crate::description::Projection::Perspective;
    if perspective && !(camera.fov_degrees > 0.0 && camera.fov_degrees < 180.0) {
        return Err(invalid(
            "camera fov",
            "an angle in degrees in (0, 180)",
            camera.fov_degrees.to_string(),
        ));
    }
    if !finite_matrix(&camera.to_world) {
        return Err(invalid(
            "camera to_world",
            "a matrix of finite numbers",
            format!("{:?}", camera.to_world),
        ));
    }

    let bounds = desc.boundary.bounds;
    check_bounds(bounds).map_err(|found| invalid("boundary box", BOX, found))?;
    desc.boundary.bsdf.check(source)?;

    let medium = &desc.medium;
    let (max_density, data) = medium.check(checked, &invalid)?;
    medium.phase.check(source)?;
    // Delta tracking takes about majorant x distance tentative collisions per crossing.
    let majorant = f64::from(medium.scale) * f64::from(max_density);
    let diagonal = (0..3)
        .map(|i| f64::from(bounds.max[i]) - f64::from(bounds.min[i]))
        .map(|e| e * e)
        .sum::<f64>()
        .sqrt();
    let depth = majorant * diagonal;
    // NaN (an infinite majorant times a zero diagonal) is refused too.
    if depth.is_nan() || depth > MAX_OPTICAL_DEPTH {
        return Err(invalid(
            "medium",
            &format!(
                "an optical depth (majorant extinction x box diagonal) of at most \
                 {MAX_OPTICAL_DEPTH:e}: delta tracking takes about that many steps to cross the \
                 box, and shorter steps fall below f32's precision"
            ),
            format!("majorant {majorant:e} x diagonal {diagonal} = {depth:e}"),
        ));
    }

    desc.environment.check(source, checked.is_none())?;
    desc.lights.check(source)?;
    Ok(data)
}

/// The error of a scene whose `field` is not what it must be; `source` names the scene.
pub(crate) fn invalid(source: &str, field: &str, expected: &str, found: String) -> SceneError {
    SceneError::InvalidScene {
        source_name: source.to_owned(),
        field: field.to_owned(),
        expected: expected.to_owned(),
        found,
    }
}

/// What a box must be.
pub(crate) const BOX: &str = "finite min < max on every axis";

/// `Ok` for a box with finite `min < max` on every axis, else the box as the error's "found".
pub(crate) fn check_bounds(b: Bounds) -> Result<(), String> {
    let ok = (0..3).all(|i| b.min[i].is_finite() && b.max[i].is_finite() && b.min[i] < b.max[i]);
    if ok {
        Ok(())
    } else {
        Err(format!("min {:?} max {:?}", b.min, b.max))
    }
}

pub(crate) fn finite_matrix(m: &Matrix4) -> bool {
    m.iter().flatten().all(|v| v.is_finite())
}

/// Checks a grid's shape, box and values (finite, in `[0, max]`); returns its largest value.
pub(crate) fn check_grid(
    grid: &GridDesc,
    role: &str,
    max: f32,
    invalid: &impl Fn(&str, &str, String) -> SceneError,
) -> Result<f32, SceneError> {
    let [x, y, z] = grid.resolution;
    let expected = [y, z, grid.channels]
        .iter()
        .try_fold(u64::from(x), |acc, &n| acc.checked_mul(u64::from(n)));
    if grid.layout == SampleLayout::Sparse {
        if let Err(found) = crate::sparse::check(grid) {
            return Err(invalid(
                role,
                "whole 8^3 bricks and a brick table naming them",
                found,
            ));
        }
    } else if expected != Some(grid.data.len() as u64) {
        return Err(invalid(
            role,
            "resolution x channels values",
            format!(
                "{} values for {x} x {y} x {z} x {}",
                grid.data.len(),
                grid.channels
            ),
        ));
    }
    check_bounds(grid.bounds).map_err(|found| invalid(&format!("{role} box"), BOX, found))?;
    let mut largest = 0.0f32;
    for &v in grid.samples() {
        if !(v >= 0.0 && v <= max) {
            return Err(invalid(
                role,
                &format!("values in [0, {max:e}]"),
                v.to_string(),
            ));
        }
        largest = largest.max(v);
    }
    Ok(largest)
}
