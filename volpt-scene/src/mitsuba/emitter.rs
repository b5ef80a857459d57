//! Emitters: a single environment (its kinds are read by [`EnvironmentDesc::from_mitsuba`]), or
//! none (black); and the OpenEXR images an `envmap` names.

use std::path::Path;

use super::plugin::{Ctx, Plugin};
use super::xml::Element;
use crate::description::EnvironmentDesc;
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
    let environment = EnvironmentDesc::from_mitsuba(&p)?;
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

/// Reads the first layer of an OpenEXR image as linear RGB, row-major from the top-left pixel,
/// checking that it has at least `min_size` pixels and that every value is a radiance.
pub(crate) fn read_exr(
    path: &Path,
    min_size: [usize; 2],
) -> Result<(usize, usize, Vec<f32>), SceneError> {
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
