//! Indices of refraction: numbers or the names Mitsuba knows.

use super::plugin::{parse_f32, quoted, Arg};
use crate::error::SceneError;

/// Mitsuba's table of named IORs (`ior.h` in Mitsuba 0.6 and 3), values as Mitsuba has them.
const NAMED_IORS: &[(&str, f32)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.3330),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.470),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.5750),
    ("diamond", 2.419),
];

/// The IOR of a named material (case-insensitive), as Mitsuba's `lookupIOR` resolves it.
pub fn named_ior(name: &str) -> Option<f32> {
    let name = name.trim().to_ascii_lowercase();
    NAMED_IORS.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
}

/// An IOR parameter: `<float>` or `<string>` holding a number or one of the names.
pub(crate) fn ior(arg: &Arg<'_>) -> Result<f32, SceneError> {
    let value = match arg.target.tag.as_str() {
        "string" => {
            let raw = arg.string()?;
            named_ior(raw).or_else(|| parse_f32(raw)).ok_or_else(|| {
                let names: Vec<&str> = NAMED_IORS.iter().map(|(n, _)| *n).collect();
                arg.invalid(
                    &format!("a number or a named IOR ({})", names.join(", ")),
                    quoted(raw),
                )
            })?
        }
        "float" | "integer" => arg.float()?,
        _ => return Err(arg.wrong_type("a <float> or a <string> naming a material")),
    };
    if value > 0.0 {
        Ok(value)
    } else {
        Err(arg.invalid("a positive index of refraction", value.to_string()))
    }
}
