//! `<sensor type="perspective">` and `<sensor type="orthographic">` (its `to_world` scale sets the
//! extent: camera-space x in [-1, 1], y in [-h/w, h/w], as Mitsuba 3 maps its film), with their
//! `<film>` and `<sampler>`.

use super::plugin::{parse_f64, quoted, Arg, Ctx, Plugin};
use super::transform::{to_f32, transform, IDENTITY_F64};
use super::xml::Element;
use crate::description::{CameraDesc, FilmDesc, FovAxis, Projection};
use crate::error::SceneError;

/// Mitsuba's film size when none is given.
const DEFAULT_FILM: FilmDesc = FilmDesc {
    width: 768,
    height: 576,
};
/// Mitsuba's sample count when no sampler is given.
const DEFAULT_SPP: u32 = 4;
/// Mitsuba's focal length when neither `fov` nor a focal length is given.
const DEFAULT_FOCAL_LENGTH: &str = "50mm";
/// Diagonal of a 35 mm film frame (36 x 24 mm), which Mitsuba's focal lengths refer to.
const FRAME_DIAGONAL_MM: f64 = 43.266_615_305_567_87;
/// Largest film side accepted: beyond this a typo is likelier than an intent, and the renderer
/// would spend its memory on it.
const MAX_FILM_SIDE: i64 = 1 << 16;

pub(crate) struct Sensor {
    pub camera: CameraDesc,
    pub film: FilmDesc,
    pub spp: u32,
}

pub(crate) fn sensor(el: &Element, ctx: &Ctx<'_>) -> Result<Sensor, SceneError> {
    let p = Plugin::new(el, ctx);
    let projection = match p.kind()? {
        "perspective" => Projection::Perspective,
        "orthographic" => Projection::Orthographic,
        _ => {
            return Err(p.unsupported(
                "volpt has the perspective (pinhole) and orthographic cameras: use \
                 type=\"perspective\" or type=\"orthographic\"",
            ))
        }
    };
    let to_world = match p.find(&["toWorld", "to_world"])? {
        Some(arg) => transform(&arg)?,
        None => IDENTITY_F64,
    };
    let fov_axis_arg = p.find(&["fovAxis", "fov_axis"])?;
    let fov = p.find(&["fov"])?;
    let focal = p.find(&["focalLength", "focal_length"])?;
    if projection == Projection::Orthographic {
        if let Some(arg) = fov.as_ref().or(focal.as_ref()).or(fov_axis_arg.as_ref()) {
            return Err(arg.invalid(
                "no field of view on an orthographic sensor (its to_world scale sets the extent)",
                quoted(arg.value()?),
            ));
        }
    }
    let (fov_degrees, fov_axis) = match projection {
        // Unused: an orthographic camera's rays are parallel.
        Projection::Orthographic => (0.0, FovAxis::X),
        Projection::Perspective => match (fov, focal) {
            (Some(_), Some(focal)) => {
                return Err(focal.invalid("either fov or a focal length, not both", "both"));
            }
            (Some(fov), None) => {
                let degrees = fov.float()?;
                if !(degrees > 0.0 && degrees < 180.0) {
                    return Err(
                        fov.invalid("an angle in degrees in (0, 180)", quoted(fov.value()?))
                    );
                }
                let axis = match fov_axis_arg {
                    Some(arg) => fov_axis(&arg)?,
                    None => FovAxis::X,
                };
                (degrees, axis)
            }
            (None, focal) => {
                // Mitsuba converts a focal length to a diagonal field of view, whatever fovAxis says.
                if let Some(arg) = fov_axis_arg {
                    tracing::warn!(
                    "{}:{}: {} is ignored: a focal length always sets the diagonal field of view",
                    arg.written.file.display(),
                    arg.written.line,
                    arg.written.describe()
                );
                }
                let mm = match focal {
                    Some(arg) => focal_length_mm(&arg)?,
                    None => parse_mm(DEFAULT_FOCAL_LENGTH).unwrap_or(50.0),
                };
                let degrees = (2.0 * (FRAME_DIAGONAL_MM / (2.0 * mm)).atan()).to_degrees();
                (degrees as f32, FovAxis::Diagonal)
            }
        },
    };
    p.ignore(&[
        "nearClip",
        "near_clip",
        "farClip",
        "far_clip",
        "shutterOpen",
        "shutter_open",
        "shutterClose",
        "shutter_close",
    ]);
    let film = match p.object("film")? {
        Some(arg) => film(arg.target, ctx)?,
        None => DEFAULT_FILM,
    };
    let spp = match p.object("sampler")? {
        Some(arg) => sampler(arg.target, ctx)?,
        None => DEFAULT_SPP,
    };
    p.finish()?;
    Ok(Sensor {
        camera: CameraDesc {
            to_world: to_f32(&to_world),
            fov_degrees,
            fov_axis,
            projection,
        },
        film,
        spp,
    })
}

fn fov_axis(arg: &Arg<'_>) -> Result<FovAxis, SceneError> {
    let raw = arg.string()?;
    match raw.trim().to_ascii_lowercase().as_str() {
        "x" => Ok(FovAxis::X),
        "y" => Ok(FovAxis::Y),
        "diagonal" => Ok(FovAxis::Diagonal),
        "smaller" => Ok(FovAxis::Smaller),
        "larger" => Ok(FovAxis::Larger),
        _ => Err(arg.invalid("x, y, diagonal, smaller or larger", quoted(raw))),
    }
}

/// A 35 mm-equivalent focal length such as `"50mm"` (the unit is optional).
fn focal_length_mm(arg: &Arg<'_>) -> Result<f64, SceneError> {
    let raw = match arg.target.tag.as_str() {
        "string" => arg.string()?,
        _ => arg.value()?,
    };
    parse_mm(raw).ok_or_else(|| {
        arg.invalid(
            "a positive length in millimetres such as \"50mm\"",
            quoted(raw),
        )
    })
}

fn parse_mm(raw: &str) -> Option<f64> {
    let raw = raw.trim();
    parse_f64(raw.strip_suffix("mm").unwrap_or(raw)).filter(|&mm| mm > 0.0)
}

fn film(el: &Element, ctx: &Ctx<'_>) -> Result<FilmDesc, SceneError> {
    let p = Plugin::new(el, ctx);
    let kind = p.kind()?;
    if kind != "hdrfilm" && kind != "ldrfilm" {
        return Err(p.unsupported("expected hdrfilm or ldrfilm"));
    }
    let side = |names: &[&str], default: u32| -> Result<u32, SceneError> {
        let Some(arg) = p.find(names)? else {
            return Ok(default);
        };
        let v = arg.integer()?;
        if (1..=MAX_FILM_SIDE).contains(&v) {
            Ok(v as u32)
        } else {
            Err(arg.invalid(
                &format!("a size in pixels in [1, {MAX_FILM_SIDE}]"),
                quoted(arg.value()?),
            ))
        }
    };
    let width = side(&["width"], DEFAULT_FILM.width)?;
    let height = side(&["height"], DEFAULT_FILM.height)?;
    if let Some(filter) = p.object("rfilter")? {
        let kind = filter.target.attr("type").unwrap_or("");
        if kind != "box" {
            tracing::warn!(
                "{}:{}: {}: volpt reconstructs pixels with a box filter",
                filter.target.file.display(),
                filter.target.line,
                filter.target.describe()
            );
        }
    }
    // Output encoding and metadata: volpt writes its own formats.
    p.ignore(&[
        "fileFormat",
        "file_format",
        "pixelFormat",
        "pixel_format",
        "componentFormat",
        "component_format",
        "banner",
        "attachLog",
        "highQualityEdges",
    ]);
    p.finish()?;
    Ok(FilmDesc { width, height })
}

fn sampler(el: &Element, ctx: &Ctx<'_>) -> Result<u32, SceneError> {
    let p = Plugin::new(el, ctx);
    match p.kind()? {
        "independent" => {}
        kind @ ("stratified" | "ldsampler" | "multijitter" | "orthogonal" | "halton"
        | "hammersley" | "sobol") => {
            tracing::warn!(
                "{}:{}: <sampler type=\"{kind}\">: volpt uses independent samples",
                el.file.display(),
                el.line
            );
        }
        _ => return Err(p.unsupported("expected independent (or another Mitsuba sampler)")),
    }
    let spp = match p.find(&["sampleCount", "sample_count"])? {
        Some(arg) => {
            let v = arg.integer()?;
            u32::try_from(v)
                .ok()
                .filter(|&v| v >= 1)
                .ok_or_else(|| arg.invalid("a positive sample count", v.to_string()))?
        }
        None => DEFAULT_SPP,
    };
    // Settings of the samplers volpt replaces.
    p.ignore(&["seed", "scramble", "dimension", "jitter"]);
    p.finish()?;
    Ok(spp)
}
