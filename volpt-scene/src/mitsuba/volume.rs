//! Volume-valued parameters: `<volume type="gridvolume">`, `<volume type="constvolume">`, or a
//! plain colour/number where Mitsuba accepts one.
//!
//! Where a grid's samples sit differs between Mitsuba generations, and this is where the
//! difference is decided:
//! - Mitsuba 0.6: the grid spans the `.vol` file's bounding box (or `min`/`max` if given), mapped
//!   by `toWorld`, with samples on the box's faces ([`GridConvention::Vertex`]).
//! - Mitsuba 3: the grid spans the unit cube mapped by `to_world` (the file's box only with
//!   `use_grid_bbox`), with samples at cell centres ([`GridConvention::Cell`]).

use std::path::Path;

use super::boxes::scaled_box;
use super::plugin::{Arg, Ctx, Plugin};
use super::preprocess::Dialect;
use super::spectrum::rgb;
use super::transform::{transform, IDENTITY_F64};
use crate::description::{GridConvention, GridDesc};
use crate::error::{SceneError, VolProblem};
use crate::vol::{read_vol, VolGrid};

/// What a volume is used for, which decides the values and channel counts it may hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// Extinction: one channel, or three (a density per channel), values >= 0.
    Density,
    /// Single-scattering albedo: one (grey) or three channels, values in [0, 1]. A one-channel
    /// grid is expanded to three.
    Albedo,
}

pub(crate) enum VolumeValue {
    Constant([f32; 3]),
    /// A grid and how its `filter_type` reads it between samples.
    Grid(GridDesc, Filter),
}

/// A `gridvolume`'s `filter_type`: Mitsuba 3's `trilinear` (its default) or `nearest`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Filter {
    Trilinear,
    Nearest,
}

/// Reads a volume-valued parameter. Constants are returned unchecked (the caller knows its
/// ranges); grids are checked against `role` here, where the file name is known.
pub(crate) fn volume(arg: &Arg<'_>, ctx: &Ctx<'_>, role: Role) -> Result<VolumeValue, SceneError> {
    if arg.target.tag != "volume" {
        return rgb(arg).map(VolumeValue::Constant);
    }
    let p = Plugin::new(arg.target, ctx);
    let value = match p.kind()? {
        "constvolume" => {
            let value = p
                .find(&["value"])?
                .ok_or_else(|| p.missing("<float name=\"value\"> (or <rgb>)"))?;
            p.ignore(&["toWorld", "to_world"]); // a constant does not move
            VolumeValue::Constant(rgb(&value)?)
        }
        "gridvolume" => {
            let (grid, filter) = grid(&p, role)?;
            VolumeValue::Grid(grid, filter)
        }
        _ => return Err(p.unsupported("volpt's volumes are gridvolume and constvolume")),
    };
    p.finish()?;
    Ok(value)
}

/// A `gridvolume` whose file is a `.vdb`: the grid named by `<string name="grid">` (default: the
/// density, or for an albedo the file's vec3 grid), over the box its own transform gives
/// (voxel centres: cell-centred), mapped by `toWorld`/`to_world`, in either dialect.
fn vdb_grid(p: &Plugin<'_>, role: Role, path: &Path) -> Result<(GridDesc, Filter), SceneError> {
    let name = match p.find(&["grid"])? {
        Some(arg) => Some(arg.string()?.to_owned()),
        None => None,
    };
    let options = crate::vdb::VdbOptions {
        grid: name,
        vector: role == Role::Albedo,
        sparsity: crate::vdb::Sparsity::Auto,
    };
    own_box(p, crate::vdb::read_vdb(path, &options)?)
}

/// A grid read with its own box (a VDB file's, a scanner file's), mapped by `toWorld`/`to_world`.
fn own_box(p: &Plugin<'_>, mut grid: GridDesc) -> Result<(GridDesc, Filter), SceneError> {
    let to_world = match p.find(&["toWorld", "to_world"])? {
        Some(arg) => transform(&arg)?,
        None => IDENTITY_F64,
    };
    let (min, max) = (
        grid.bounds.min.map(f64::from),
        grid.bounds.max.map(f64::from),
    );
    grid.bounds = scaled_box(&to_world, min, max).ok_or_else(|| {
        p.unsupported(
            "its toWorld/to_world rotates, mirrors or shears the grid; volpt's grids are \
             axis-aligned, so only positive scales and translations are allowed",
        )
    })?;
    p.ignore(&[
        "use_grid_bbox",
        "sendData",
        "customStepSize",
        "raw",
        "accel",
    ]);
    Ok((grid, lookup_settings(p)?))
}

fn grid(p: &Plugin<'_>, role: Role) -> Result<(GridDesc, Filter), SceneError> {
    let el = p.el;
    let filename = p
        .find(&["filename"])?
        .ok_or_else(|| p.missing("<string name=\"filename\">"))?;
    let path = el.dir().join(filename.string()?);
    let referenced = |error| SceneError::Referenced {
        path: el.file.to_path_buf(),
        line: el.line,
        element: el.describe(),
        error: Box::new(error),
    };
    if crate::vdb::is_vdb(&path) {
        return vdb_grid(p, role, &path).map_err(referenced);
    }
    // NRRD, TIFF stacks and DICOM series: their own box, as a VDB file's.
    if let Some(format) = crate::scanner::scanner_format(&path).map_err(referenced)? {
        let grid = crate::scanner::read_scanned(&path, format).expect("a scanner format");
        return own_box(p, grid.map_err(referenced)?);
    }
    let vol = read_vol(&path).map_err(referenced)?;
    match role {
        Role::Density => vol.check_density(&path),
        Role::Albedo => vol.check_albedo(&path),
    }
    .map_err(referenced)?;

    let to_world = match p.find(&["toWorld", "to_world"])? {
        Some(arg) => transform(&arg)?,
        None => IDENTITY_F64,
    };
    let (min, max, convention) = match p.ctx.dialect {
        Dialect::Mitsuba06 => {
            let (min, max) = legacy_box(p, &vol)?;
            (min, max, GridConvention::Vertex)
        }
        Dialect::Mitsuba3 => {
            let use_grid_bbox = match p.find(&["use_grid_bbox"])? {
                Some(arg) => arg.boolean()?,
                None => false,
            };
            let (min, max) = if use_grid_bbox {
                file_box(&vol)
            } else {
                ([0.0; 3], [1.0; 3])
            };
            (min, max, GridConvention::Cell)
        }
    };
    if (0..3).any(|a| max[a] <= min[a]) {
        return Err(referenced(SceneError::Vol {
            path: path.clone(),
            problem: VolProblem::BadBounds {
                min: min.map(|v| v as f32),
                max: max.map(|v| v as f32),
            },
        }));
    }
    if convention == GridConvention::Vertex && vol.resolution.iter().any(|&r| r < 2) {
        return Err(p.unsupported(format!(
            "{}: a Mitsuba 0.6 grid places samples on the box's faces and needs at least 2 per \
             axis, found {:?}",
            path.display(),
            vol.resolution
        )));
    }
    let bounds = scaled_box(&to_world, min, max).ok_or_else(|| {
        p.unsupported(
            "its toWorld/to_world rotates, mirrors or shears the grid; volpt's grids are \
             axis-aligned, so only positive scales and translations are allowed",
        )
    })?;
    let filter = lookup_settings(p)?;
    // Settings of Mitsuba's own storage and acceleration.
    p.ignore(&["sendData", "customStepSize", "raw", "accel"]);

    let (channels, data) = match (role, vol.channels) {
        (Role::Albedo, 1) => (3, expand_grey(&vol.data, &path)?),
        _ => (vol.channels, vol.data),
    };
    Ok((
        GridDesc {
            layout: crate::description::SampleLayout::Dense,
            resolution: vol.resolution,
            channels,
            bounds,
            convention,
            data,
        },
        filter,
    ))
}

/// Mitsuba 0.6: the file's box, unless both `min` and `max` points override it.
fn legacy_box(p: &Plugin<'_>, vol: &VolGrid) -> Result<([f64; 3], [f64; 3]), SceneError> {
    match (p.find(&["min"])?, p.find(&["max"])?) {
        (None, None) => Ok(file_box(vol)),
        (Some(min), Some(max)) => Ok((min.point()?, max.point()?)),
        (Some(one), None) | (None, Some(one)) => Err(one.invalid(
            "min and max given together (they override the file's bounding box)",
            "only one",
        )),
    }
}

fn file_box(vol: &VolGrid) -> ([f64; 3], [f64; 3]) {
    (vol.bbox.min.map(f64::from), vol.bbox.max.map(f64::from))
}

/// The grid's `filter_type`, `trilinear` (Mitsuba 3's default) or `nearest`; another is warned
/// about and read trilinearly. volpt clamps at the edges (Mitsuba 3's default `wrap_mode`).
fn lookup_settings(p: &Plugin<'_>) -> Result<Filter, SceneError> {
    p.warn_unless(&["wrap_mode"], "clamp", "clamp")?;
    if let Some(arg) = p.find(&["filter_type"])? {
        if arg.string()?.trim().eq_ignore_ascii_case("nearest") {
            return Ok(Filter::Nearest);
        }
    }
    p.warn_unless(&["filter_type"], "trilinear", "trilinear (or nearest)")?;
    Ok(Filter::Trilinear)
}

/// One grey channel to three equal ones, allocating fallibly (the grid may be large).
fn expand_grey(data: &[f32], path: &Path) -> Result<Vec<f32>, SceneError> {
    let mut out = Vec::new();
    let too_large = || SceneError::Io {
        path: path.to_path_buf(),
        error: std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            "not enough memory to expand the grey albedo grid to RGB",
        ),
    };
    let len = data.len().checked_mul(3).ok_or_else(too_large)?;
    out.try_reserve_exact(len).map_err(|_| too_large())?;
    out.extend(data.iter().flat_map(|&v| [v; 3]));
    Ok(out)
}

/// Used by media to say a constant is out of range, with the element that wrote it.
pub(crate) fn constant_error(arg: &Arg<'_>, expected: &str, value: [f32; 3]) -> SceneError {
    let found = if value[0] == value[1] && value[1] == value[2] {
        value[0].to_string()
    } else {
        format!("({}, {}, {})", value[0], value[1], value[2])
    };
    let target = if arg.target.tag == "volume" {
        // A constvolume: point at its value rather than the volume element.
        arg.target
            .children
            .iter()
            .find(|c| c.attr("name") == Some("value"))
            .unwrap_or(arg.target)
    } else {
        arg.target
    };
    super::plugin::invalid(target, &target.describe(), expected, found)
}
