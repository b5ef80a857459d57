//! Emitters: a single environment, `<emitter type="constant">` or `<emitter type="envmap">`, or none
//! (black).
//!
//! An `envmap` is read from an OpenEXR file, the one HDR image format volpt reads; PNG, RGBE and the
//! like are an error that says to convert the map. Its `toWorld`/`to_world` may rotate or mirror the
//! map. Its translation is ignored, as in Mitsuba: light from infinitely far away does not move. A
//! scale or shear is an error rather than something to normalise away, because Mitsuba looks the map
//! up at the transformed, unnormalised direction, which bends the mapping in a way volpt does not
//! reproduce. Where the rows sit depends on the dialect ([`LatLongRows`]).

use std::path::Path;

use super::plugin::{Arg, Ctx, Plugin};
use super::preprocess::Dialect;
use super::spectrum::rgb;
use super::transform::{to_f32, transform, Transform, IDENTITY_F64};
use super::xml::Element;
use crate::description::{EnvironmentDesc, LatLongDesc, LatLongRows};
use crate::error::{EnvmapProblem, SceneError};

pub(crate) fn environment(
    emitters: &[&Element],
    ctx: &Ctx<'_>,
) -> Result<EnvironmentDesc, SceneError> {
    let el = match emitters {
        [] => return Ok(EnvironmentDesc::Constant([0.0; 3])),
        [el] => el,
        [_, second, ..] => {
            return Err(SceneError::Unsupported {
                path: second.file.to_path_buf(),
                line: second.line,
                what: format!("a second emitter {}", second.describe()),
                reason: "volpt lights the scene with one environment emitter".into(),
            })
        }
    };
    let p = Plugin::new(el, ctx);
    let environment = match p.kind()? {
        "constant" => EnvironmentDesc::Constant(constant_radiance(&p)?),
        "envmap" => EnvironmentDesc::LatLong(envmap(&p)?),
        _ => {
            return Err(p.unsupported(
                "volpt lights the scene with an environment: use type=\"constant\" or \
                 type=\"envmap\"",
            ))
        }
    };
    // These only steer light sampling, which volpt does per its own strategy; `cache` (Mitsuba
    // 0.6) only decides whether a MIP map is stored on disk.
    p.ignore(&[
        "samplingWeight",
        "sampling_weight",
        "mis_compensation",
        "cache",
    ]);
    p.finish()?;
    Ok(environment)
}

fn constant_radiance(p: &Plugin<'_>) -> Result<[f32; 3], SceneError> {
    match p.find(&["radiance"])? {
        None => Ok([1.0; 3]),
        Some(arg) => {
            let v = rgb(&arg)?;
            if v.iter().any(|&c| c < 0.0) {
                return Err(arg.invalid("a radiance >= 0", format!("{v:?}")));
            }
            Ok(v)
        }
    }
}

fn envmap(p: &Plugin<'_>) -> Result<LatLongDesc, SceneError> {
    let filename = p.find(&["filename"])?.ok_or_else(|| {
        p.missing("<string name=\"filename\"> (an OpenEXR latitude-longitude image)")
    })?;
    let path = p.el.dir().join(filename.string()?);
    let (min_size, rows) = match p.ctx.dialect {
        Dialect::Mitsuba06 => ([1, 1], LatLongRows::CellCentred),
        // Mitsuba 3 refuses smaller maps.
        Dialect::Mitsuba3 => ([2, 3], LatLongRows::PoleToPole),
    };
    let (width, height, rgb) = read_exr(&path, min_size).map_err(|error| {
        // The file's own error, prefixed with the parameter that named the file.
        SceneError::Referenced {
            path: filename.written.file.to_path_buf(),
            line: filename.written.line,
            element: filename.written.describe(),
            error: Box::new(error),
        }
    })?;
    let scale = match p.find(&["scale"])? {
        None => 1.0,
        Some(arg) => {
            let s = arg.float()?;
            if s < 0.0 {
                return Err(arg.invalid("a scale >= 0", s.to_string()));
            }
            s
        }
    };
    let to_world = match p.find(&["toWorld", "to_world"])? {
        None => IDENTITY_F64,
        Some(arg) => {
            let m = transform(&arg)?;
            check_rotation(&arg, &m)?;
            m
        }
    };
    Ok(LatLongDesc {
        // OpenEXR stores its data window in `i32` pixel coordinates, so sizes fit a `u32`.
        width: width as u32,
        height: height as u32,
        rgb,
        to_world: to_f32(&to_world),
        scale,
        rows,
    })
}

/// The linear part of `m` must be orthonormal: a rotation, possibly mirrored.
fn check_rotation(arg: &Arg<'_>, m: &Transform) -> Result<(), SceneError> {
    // Loose enough for matrices written out with six decimals, tight enough to catch any scale a
    // user meant.
    const TOLERANCE: f64 = 1e-4;
    let column = |j: usize| [m[0][j], m[1][j], m[2][j]];
    for i in 0..3 {
        for j in 0..3 {
            let (a, b) = (column(i), column(j));
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            let expected = if i == j { 1.0 } else { 0.0 };
            if (dot - expected).abs() > TOLERANCE {
                let linear = [0, 1, 2].map(|r| [m[r][0], m[r][1], m[r][2]].map(|v| v as f32));
                return Err(arg.invalid(
                    "a rotation or mirroring (an environment map cannot be scaled or sheared; \
                     its translation is ignored)",
                    format!("the linear part {linear:?}"),
                ));
            }
        }
    }
    Ok(())
}

/// Reads the first layer of an OpenEXR image as linear RGB, row-major from the top-left pixel,
/// checking that it has at least `min_size` pixels and that every value is a radiance.
fn read_exr(path: &Path, min_size: [usize; 2]) -> Result<(usize, usize, Vec<f32>), SceneError> {
    let problem = |problem| SceneError::Envmap {
        path: path.to_path_buf(),
        problem,
    };
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    // Formats Mitsuba reads and volpt does not: say so, rather than that the file is corrupt.
    const OTHER_FORMATS: &[&str] = &[
        "hdr", "rgbe", "pic", "pfm", "png", "jpg", "jpeg", "tga", "bmp", "ppm",
    ];
    if OTHER_FORMATS.contains(&extension.as_str()) {
        return Err(problem(EnvmapProblem::Format { extension }));
    }
    // The map is decoded (the stored channels), then split into three f32 planes and interleaved
    // into one RGB f32 buffer.
    crate::limits::check_exr(path, "the environment map", 24)?;
    // exr asserts (in debug builds) on some malformed files: a decode error like any other.
    let decoded =
        crate::contain::contain_panics(|| exr::prelude::read_first_flat_layer_from_file(path))
            .unwrap_or_else(|_| {
                Err(exr::error::Error::Invalid(
                    "malformed data (the exr decoder gave up)".into(),
                ))
            });
    let image = decoded.map_err(|e| match e {
        exr::error::Error::Io(error) => SceneError::Io {
            path: path.to_path_buf(),
            error,
        },
        other => problem(EnvmapProblem::Decode {
            message: other.to_string(),
        }),
    })?;
    let layer = image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let channels = &layer.channel_data.list;
    let find = |name: &str| channels.iter().find(|c| c.name.eq(name));
    // A luminance-only image is grey, as Mitsuba converts it.
    let planes = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => [r, g, b],
        (None, None, None, Some(y)) => [y; 3],
        _ => {
            return Err(problem(EnvmapProblem::Channels {
                found: channels.iter().map(|c| c.name.to_string()).collect(),
            }))
        }
    };
    if width < min_size[0] || height < min_size[1] {
        return Err(problem(EnvmapProblem::TooSmall {
            width,
            height,
            min_width: min_size[0],
            min_height: min_size[1],
        }));
    }
    let values = planes.map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>());
    let mut rgb = Vec::with_capacity(3 * width * height);
    for i in 0..width * height {
        for (plane, values) in planes.iter().zip(&values) {
            let value = values[i];
            if !(value.is_finite() && value >= 0.0) {
                return Err(problem(EnvmapProblem::BadTexel {
                    x: i % width,
                    y: i / width,
                    channel: plane.name.to_string(),
                    value,
                }));
            }
            rgb.push(value);
        }
    }
    Ok((width, height, rgb))
}
