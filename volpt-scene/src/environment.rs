//! The environment, everything about its descriptions in one place: what a description says
//! ([`EnvironmentDesc`]), how a Mitsuba `<emitter>` and a TOML scene's `[environment]` spell it,
//! its checks, its Mitsuba 3 export, how `volpt info` prints it, one example of each kind, and how
//! each registry environment part is built from it ([`FromDescription`]): a constant, or a
//! latitude-longitude map (the general one: a constant is a one-texel map).

use std::fmt;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use volpt_core::{ConstantEnvironment, LatLongEnvironment, Spectrum, Vec3};

use crate::description::Matrix4;
use crate::error::SceneError;
use crate::from_description::FromDescription;
use crate::limits::bytes_of;
use crate::mitsuba::emitter::read_exr;
use crate::mitsuba::export::{matrix_transform, rgb_element};
use crate::mitsuba::plugin::{Arg, Plugin};
use crate::mitsuba::preprocess::Dialect;
use crate::mitsuba::spectrum::rgb;
use crate::mitsuba::transform::{to_f32, transform, Transform, IDENTITY_F64};
use crate::output::write_rgb_exr;
use crate::simplification::Simplification;
use crate::toml_scene::{Cx, OneOrThree};
use crate::validate::{finite_matrix, invalid};

#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum EnvironmentDesc {
    /// Constant radiance from every direction.
    Constant([f32; 3]),
    /// A latitude-longitude environment map (Mitsuba's `envmap`).
    LatLong(LatLongDesc),
}

/// A latitude-longitude environment map. The look direction `d`, taken to the map's frame by the
/// inverse of `to_world`, is found at `u = atan2(d.x, -d.z) / 2 pi` (wrapping around) and
/// `v = acos(d.y) / pi`: the top row is the +y pole and the centre column looks along -z.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LatLongDesc {
    pub width: u32,
    pub height: u32,
    /// Linear RGB radiance, `3 * width * height` values, row-major from the top-left pixel. Not
    /// serialised, as a grid's values ([`crate::GridDesc::data`]).
    #[serde(skip)]
    pub rgb: Vec<f32>,
    /// Map-to-world transform; its linear part is a rotation (possibly a mirroring), and its
    /// translation does not matter for light from infinitely far away.
    pub to_world: Matrix4,
    /// Multiplies every texel.
    pub scale: f32,
    pub rows: LatLongRows,
}

/// Where a latitude-longitude map's rows sit between the poles; columns sit at
/// `u = (i + 0.5) / width` in every Mitsuba generation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum LatLongRows {
    /// Mitsuba 0.5/0.6: row `j` at `v = (j + 0.5) / height`.
    CellCentred,
    /// Mitsuba 3: row `j` at `v = j / (height - 1)`, the first and last rows on the poles.
    PoleToPole,
}

impl EnvironmentDesc {
    /// A Mitsuba `<emitter type="constant">` or `<emitter type="envmap">` (the emitter's
    /// parameters every kind shares are read by the caller).
    ///
    /// An `envmap` is read from an OpenEXR file, the one HDR image format volpt reads; PNG, RGBE
    /// and the like are an error that says to convert the map. Its `toWorld`/`to_world` may
    /// rotate or mirror the map. Its translation is ignored, as in Mitsuba: light from infinitely
    /// far away does not move. A scale or shear is an error rather than something to normalise
    /// away, because Mitsuba looks the map up at the transformed, unnormalised direction, which
    /// bends the mapping in a way volpt does not reproduce. Where the rows sit depends on the
    /// dialect ([`LatLongRows`]).
    pub(crate) fn from_mitsuba(p: &Plugin<'_>) -> Result<Self, SceneError> {
        Ok(match p.kind()? {
            "constant" => EnvironmentDesc::Constant(constant_radiance(p)?),
            "envmap" => EnvironmentDesc::LatLong(envmap(p)?),
            _ => {
                return Err(p.unsupported(
                    "volpt lights the scene with an environment: use type=\"constant\" or \
                     type=\"envmap\"",
                ))
            }
        })
    }

    /// Checks the numbers a renderer relies on, a map's texels only with `texels`; `source` names
    /// the scene in errors.
    pub(crate) fn check(&self, source: &str, texels: bool) -> Result<(), SceneError> {
        match self {
            EnvironmentDesc::Constant(rgb) => {
                if !rgb.iter().all(|v| v.is_finite() && *v >= 0.0) {
                    return Err(invalid(
                        source,
                        "environment radiance",
                        "three finite numbers >= 0",
                        format!("{rgb:?}"),
                    ));
                }
            }
            EnvironmentDesc::LatLong(map) => {
                let count = bytes_of(u64::from(map.width), u64::from(map.height));
                if count.and_then(|t| bytes_of(t, 3)) != Some(map.rgb.len() as u64) {
                    return Err(invalid(
                        source,
                        "environment map",
                        "3 x width x height values",
                        format!("{} for {} x {}", map.rgb.len(), map.width, map.height),
                    ));
                }
                let unchecked = if texels { &map.rgb[..] } else { &[] };
                if let Some(v) = unchecked.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                    return Err(invalid(
                        source,
                        "environment map",
                        "finite radiances >= 0",
                        v.to_string(),
                    ));
                }
                if !(map.scale.is_finite() && map.scale >= 0.0 && finite_matrix(&map.to_world)) {
                    return Err(invalid(
                        source,
                        "environment map scale and to_world",
                        "finite numbers, the scale >= 0",
                        format!("scale {}, to_world {:?}", map.scale, map.to_world),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The `<emitter>` of a Mitsuba 3 scene written as `xml` in `dir`; a map is written beside it
    /// as `<name>-envmap.exr`, added to `written`.
    pub(crate) fn to_mitsuba3(
        &self,
        dir: &Path,
        name: &str,
        xml: &Path,
        written: &mut Vec<PathBuf>,
    ) -> Result<String, SceneError> {
        Ok(match self {
            EnvironmentDesc::Constant(rgb) => format!(
                "<emitter type=\"constant\">\n        {}\n    </emitter>",
                rgb_element("radiance", rgb)
            ),
            EnvironmentDesc::LatLong(map) => {
                if map.rows != LatLongRows::PoleToPole {
                    return Err(SceneError::Export {
                        path: xml.to_path_buf(),
                        reason:
                            "the environment map has Mitsuba 0.6's cell-centred rows, which Mitsuba 3 \
                             would read half a row apart; load the scene in Mitsuba 3 spelling"
                                .into(),
                    });
                }
                let file = format!("{name}-envmap.exr");
                let path = dir.join(&file);
                let width = map.width as usize;
                write_rgb_exr(&path, width, map.height as usize, |x, y| {
                    let i = 3 * (y * width + x);
                    (map.rgb[i], map.rgb[i + 1], map.rgb[i + 2])
                })?;
                written.push(path);
                format!(
                    "<emitter type=\"envmap\">\n        <string name=\"filename\" value=\"{file}\"/>\n        \
                     <float name=\"scale\" value=\"{}\"/>\n        {}\n    </emitter>",
                    map.scale,
                    matrix_transform(&map.to_world, "        ")
                )
            }
        })
    }

    /// The values the description's serialisation leaves out (a map's texels), which what
    /// fingerprints a scene hashes on their own (the facade's `fingerprint::content`).
    pub fn unserialised_values(&self) -> &[f32] {
        match self {
            EnvironmentDesc::Constant(_) => &[],
            EnvironmentDesc::LatLong(map) => &map.rgb,
        }
    }

    /// One description of each kind; together they select every registry environment part
    /// (tests cover the registry with them).
    pub fn examples() -> Vec<Self> {
        let (width, height) = (8, 4);
        let rgb = (0..3 * width * height)
            .map(|i| 0.1 + (i % 11) as f32 * 0.2)
            .collect();
        vec![
            EnvironmentDesc::Constant([1.0, 0.8, 0.6]),
            EnvironmentDesc::LatLong(LatLongDesc {
                width,
                height,
                rgb,
                to_world: [
                    [0.0, 0.0, 1.0, 0.0],
                    [0.0, 1.0, 0.0, 0.0],
                    [-1.0, 0.0, 0.0, 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ],
                scale: 1.5,
                rows: LatLongRows::PoleToPole,
            }),
        ]
    }
}

/// As `volpt info` prints it.
impl fmt::Display for EnvironmentDesc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EnvironmentDesc::Constant(rgb) => write!(f, "constant environment, radiance {rgb:?}"),
            EnvironmentDesc::LatLong(map) => write!(
                f,
                "lat-long environment map {}x{}, scale {}, rows {:?}",
                map.width, map.height, map.scale, map.rows
            ),
        }
    }
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

/// A TOML scene's `[environment]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Constant radiance, grey or RGB.
    #[serde(default = "unit_radiance")]
    pub radiance: OneOrThree,
}

impl Default for EnvironmentSpec {
    fn default() -> Self {
        Self {
            radiance: unit_radiance(),
        }
    }
}

fn unit_radiance() -> OneOrThree {
    OneOrThree::One(1.0)
}

impl EnvironmentSpec {
    pub(crate) fn environment(&self, cx: &Cx<'_>) -> Result<EnvironmentDesc, SceneError> {
        // As the XML loader requires of a constant emitter's radiance.
        let radiance = self.radiance.rgb();
        if !radiance.iter().all(|v| v.is_finite() && *v >= 0.0) {
            return Err(cx.invalid(
                "environment.radiance",
                "a finite radiance >= 0 (one number or three)",
                format!("{radiance:?}"),
            ));
        }
        Ok(EnvironmentDesc::Constant(radiance))
    }
}

impl<'a> FromDescription<'a> for ConstantEnvironment {
    type Input = &'a EnvironmentDesc;

    fn specialised(input: &&'a EnvironmentDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input {
            EnvironmentDesc::Constant(rgb) => Some(ConstantEnvironment(Spectrum::from_array(*rgb))),
            EnvironmentDesc::LatLong(_) => None,
        }
    }

    fn general(_: &&'a EnvironmentDesc) -> Option<Self> {
        None
    }
}

impl<'a> FromDescription<'a> for LatLongEnvironment<'a> {
    type Input = &'a EnvironmentDesc;

    fn specialised(input: &&'a EnvironmentDesc, _: &mut dyn FnMut(Simplification)) -> Option<Self> {
        match input {
            EnvironmentDesc::LatLong(map) => Some(lat_long(map)),
            EnvironmentDesc::Constant(_) => None,
        }
    }

    fn general(input: &&'a EnvironmentDesc) -> Option<Self> {
        Some(match input {
            EnvironmentDesc::Constant(rgb) => LatLongEnvironment::new(
                rgb,
                1,
                1,
                volpt_core::LatLongRows::CellCentred,
                [Vec3::X, Vec3::Y, Vec3::Z],
                1.0,
            ),
            EnvironmentDesc::LatLong(map) => lat_long(map),
        })
    }
}

/// The map's world-to-map rotation is the transpose of its `to_world`'s linear part (a rotation,
/// as the loader checks); the translation does not matter for light from infinitely far away.
fn lat_long(map: &LatLongDesc) -> LatLongEnvironment<'_> {
    let m = map.to_world;
    let column = |j: usize| Vec3::new(m[0][j], m[1][j], m[2][j]);
    let rows = match map.rows {
        LatLongRows::CellCentred => volpt_core::LatLongRows::CellCentred,
        LatLongRows::PoleToPole => volpt_core::LatLongRows::PoleToPole,
    };
    LatLongEnvironment::new(
        &map.rgb,
        map.width,
        map.height,
        rows,
        [column(0), column(1), column(2)],
        map.scale,
    )
}
