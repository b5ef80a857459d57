//! Colour-valued parameters, as linear RGB.
//!
//! volpt renders in RGB, like Mitsuba's `rgb` variants. Accepted: `<float>`/`<integer>` (grey),
//! `<rgb value="r, g, b">` or `<rgb value="v">`, `<spectrum value="v">` or `value="r, g, b"`
//! (what Mitsuba's RGB mode reads), and `<srgb>` (gamma-encoded numbers or `#rrggbb`, converted
//! to linear). Wavelength-sampled spectra and blackbodies would need a spectral-to-RGB
//! conversion volpt does not do.

use super::plugin::{numbers, quoted, Arg};
use crate::error::SceneError;

pub(crate) fn rgb(arg: &Arg<'_>) -> Result<[f32; 3], SceneError> {
    let el = arg.target;
    match el.tag.as_str() {
        "float" | "integer" => arg.float().map(|v| [v; 3]),
        "rgb" | "spectrum" => {
            if el.attr("filename").is_some() {
                return Err(unsupported(arg, "spectra read from files"));
            }
            let raw = arg.value()?;
            if raw.contains(':') {
                return Err(unsupported(
                    arg,
                    "wavelength:value spectra (give an RGB triple)",
                ));
            }
            one_or_three(arg, raw, "one number or three (r, g, b)")
        }
        "srgb" => {
            let raw = arg.value()?;
            let encoded = match raw.trim().strip_prefix('#') {
                Some(hex) => hex_triplet(hex).ok_or_else(|| arg.invalid("#rrggbb", quoted(raw)))?,
                None => one_or_three(arg, raw, "one number or three (r, g, b), or #rrggbb")?,
            };
            Ok(encoded.map(srgb_to_linear))
        }
        "blackbody" => Err(unsupported(arg, "blackbody spectra")),
        _ => Err(arg.wrong_type("a <float>, <rgb>, <srgb> or <spectrum>")),
    }
}

fn one_or_three(arg: &Arg<'_>, raw: &str, expected: &str) -> Result<[f32; 3], SceneError> {
    let values = numbers(raw).map(|v| v.into_iter().map(|x| x as f32).collect::<Vec<_>>());
    match values.as_deref() {
        Some(&[v]) if v.is_finite() => Ok([v; 3]),
        Some(&[r, g, b]) if [r, g, b].iter().all(|c| c.is_finite()) => Ok([r, g, b]),
        _ => Err(arg.invalid(expected, quoted(raw))),
    }
}

fn hex_triplet(hex: &str) -> Option<[f32; 3]> {
    if hex.len() != 6 || !hex.is_ascii() {
        return None;
    }
    let channel = |i: usize| {
        u8::from_str_radix(&hex[i..i + 2], 16)
            .ok()
            .map(|v| f32::from(v) / 255.0)
    };
    Some([channel(0)?, channel(2)?, channel(4)?])
}

/// The sRGB transfer function, inverted.
fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn unsupported(arg: &Arg<'_>, what: &str) -> SceneError {
    SceneError::Unsupported {
        path: arg.target.file.to_path_buf(),
        line: arg.target.line,
        what: arg.target.describe(),
        reason: format!("volpt renders in RGB and does not read {what}"),
    }
}
