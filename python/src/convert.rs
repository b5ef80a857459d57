//! Python values as the library's: integers in range, the library's named choices, sample
//! ranges, `volpt.load`'s settings mapping; and images and grids as numpy arrays.

use std::ops::Range;

use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyDict, PyRange};
use volpt::{Named, RenderSettings};

use crate::errors::SettingsError;

/// The keys of `volpt.load`'s `settings` mapping (the `volpt render` flags of the same names).
pub const SETTINGS: &[&str] = &[
    "spp",
    "seed",
    "resolution",
    "max_depth",
    "rr_depth",
    "tracking",
    "majorant_resolution",
    "estimator",
    "lookup",
    "roulette",
    "effects",
    "threads",
];

/// An integer argument in `lo..=hi`, or a `SettingsError` naming `what`.
pub fn int_in(value: &Bound<'_, PyAny>, what: &str, lo: i64, hi: i64) -> PyResult<i64> {
    let found = describe(value);
    let wrong = || {
        SettingsError::new_err(format!(
            "{what}: expected an integer from {lo} to {hi}, found {found}"
        ))
    };
    if value.is_instance_of::<pyo3::types::PyBool>() {
        return Err(wrong());
    }
    match value.extract::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(wrong()),
    }
}

/// An optional `u32` argument in `lo..=u32::MAX`.
pub fn u32_from(value: Option<Bound<'_, PyAny>>, what: &str, lo: u32) -> PyResult<Option<u32>> {
    value
        .map(|v| int_in(&v, what, i64::from(lo), i64::from(u32::MAX)).map(|v| v as u32))
        .transpose()
}

/// A short description of a Python value for messages: its type and repr.
pub fn describe(value: &Bound<'_, PyAny>) -> String {
    let ty = value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into());
    let repr = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    let repr = if repr.chars().count() > 60 {
        format!("{}...", repr.chars().take(57).collect::<String>())
    } else {
        repr
    };
    format!("{ty} {repr}")
}

/// A name of one of the library's choices ([`Named`]), or a `SettingsError` naming `what` and
/// the names (the library's words: `volpt::names`).
pub fn choice<T: Named>(value: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    let name = value.extract::<String>().ok();
    name.and_then(|s| volpt::names::parse::<T>(&s).ok())
        .ok_or_else(|| {
            SettingsError::new_err(format!(
                "{what}: expected {}, found {}",
                volpt::names::expected::<T>(),
                describe(value)
            ))
        })
}

/// The choice `name` names ([`Named`]), or a `SettingsError` naming `what` and the names.
pub fn named<T: Named>(name: &str, what: &str) -> PyResult<T> {
    volpt::names::parse::<T>(name).map_err(|_| {
        SettingsError::new_err(format!(
            "{what}: expected {}, found {name:?}",
            volpt::names::expected::<T>()
        ))
    })
}

/// `volpt.load`'s `settings` mapping as the library's [`RenderSettings`].
pub fn render_settings(
    settings: Option<&Bound<'_, PyDict>>,
    params: Vec<(String, String)>,
) -> PyResult<RenderSettings> {
    let mut out = RenderSettings {
        params,
        ..RenderSettings::default()
    };
    let Some(settings) = settings else {
        return Ok(out);
    };
    let u32_max = i64::from(u32::MAX);
    let depth = |v: i64| u32::try_from(v).ok();
    for (key, value) in settings.iter() {
        let key: String = key.extract().map_err(|_| {
            SettingsError::new_err(format!(
                "settings: keys are strings, found {}",
                describe(&key)
            ))
        })?;
        let what = format!("settings[{key:?}]");
        let what = what.as_str();
        match key.as_str() {
            "spp" => out.spp = Some(int_in(&value, what, 1, u32_max)? as u32),
            "seed" => out.seed = int_in(&value, what, 0, u32_max)? as u32,
            "resolution" => {
                let pair = value
                    .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
                    .map_err(|_| {
                        SettingsError::new_err(format!(
                            "{what}: expected (width, height), found {}",
                            describe(&value)
                        ))
                    })?;
                out.resolution = Some((
                    int_in(&pair.0, what, 1, u32_max)? as u32,
                    int_in(&pair.1, what, 1, u32_max)? as u32,
                ));
            }
            "max_depth" => out.max_depth = Some(depth(int_in(&value, what, -1, u32_max)?)),
            "rr_depth" => out.rr_depth = Some(depth(int_in(&value, what, -1, u32_max)?)),
            "tracking" => out.tracking = Some(choice(&value, what)?),
            "majorant_resolution" => {
                // Its range is the library's to check (volpt::MAJORANT_RESOLUTION).
                out.majorant_resolution = Some(int_in(&value, what, 0, u32_max)? as u32)
            }
            "estimator" => out.estimator = Some(choice(&value, what)?),
            "lookup" => out.lookup = Some(choice(&value, what)?),
            "roulette" => out.roulette = Some(choice(&value, what)?),
            "effects" => out.effects = choice(&value, what)?,
            "threads" => out.threads = Some(int_in(&value, what, 1, u32_max)? as usize),
            _ => {
                return Err(SettingsError::new_err(format!(
                    "settings: expected one of {}, found {key:?}",
                    SETTINGS.join(", ")
                )))
            }
        }
    }
    Ok(out)
}

/// `samples=`: a `range` of step 1, or `(start, stop)`.
pub fn sample_range(value: &Bound<'_, PyAny>) -> PyResult<Range<u32>> {
    let wrong = |why: &str| {
        SettingsError::new_err(format!(
            "samples: expected a range(start, stop) with 0 <= start < stop <= 2^32 - 1{why}, \
             found {}",
            describe(value)
        ))
    };
    let (start, stop) = if let Ok(range) = value.downcast::<PyRange>() {
        if range.getattr("step")?.extract::<i64>()? != 1 {
            return Err(wrong(" and step 1"));
        }
        (range.getattr("start")?, range.getattr("stop")?)
    } else if let Ok((a, b)) = value.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
        (a, b)
    } else {
        return Err(wrong(""));
    };
    match (start.extract::<i64>(), stop.extract::<i64>()) {
        (Ok(a), Ok(b)) if 0 <= a && a < b && b <= i64::from(u32::MAX) => Ok(a as u32..b as u32),
        _ => Err(wrong("")),
    }
}

/// `bytes` (native-endian numbers of `dtype`) as a writable numpy array of `shape`.
pub fn to_numpy<'py>(
    py: Python<'py>,
    bytes: &[u8],
    dtype: &str,
    shape: Vec<usize>,
) -> PyResult<Bound<'py, PyAny>> {
    let buffer = PyByteArray::new(py, bytes);
    py.import("numpy")?
        .call_method1("frombuffer", (buffer, dtype))?
        .call_method1("reshape", (shape,))
}

/// An image's shape in numpy: (height, width, 3).
pub fn image_shape((width, height): (u32, u32)) -> Vec<usize> {
    vec![height as usize, width as usize, 3]
}

/// Pixels as native-endian bytes.
pub fn f32_bytes(pixels: &[[f32; 3]]) -> Vec<u8> {
    pixels
        .iter()
        .flatten()
        .flat_map(|c| c.to_ne_bytes())
        .collect()
}

/// Sums as native-endian bytes.
pub fn f64_bytes(sums: &[[f64; 3]]) -> Vec<u8> {
    sums.iter()
        .flatten()
        .flat_map(|c| c.to_ne_bytes())
        .collect()
}

/// A grid's numpy shape: (z, y, x), with its channels last where it has several.
pub fn grid_shape(grid: &volpt::GridDesc) -> Vec<usize> {
    let [x, y, z] = grid.resolution.map(|n| n as usize);
    let mut shape = vec![z, y, x];
    if grid.channels > 1 {
        shape.push(grid.channels as usize);
    }
    shape
}
