//! `<phase>`: Henyey-Greenstein (`hg`) or `isotropic`.

use super::plugin::{quoted, Ctx, Plugin};
use super::xml::Element;
use crate::description::PhaseDesc;
use crate::error::SceneError;

/// Mitsuba's default asymmetry for `hg` (0.6 and 3 alike).
const DEFAULT_G: f32 = 0.8;

pub(crate) fn phase(el: &Element, ctx: &Ctx<'_>) -> Result<PhaseDesc, SceneError> {
    let p = Plugin::new(el, ctx);
    let phase = match p.kind()? {
        "isotropic" => PhaseDesc::Isotropic,
        "hg" => {
            let g = match p.find(&["g"])? {
                None => DEFAULT_G,
                Some(arg) => {
                    let g = arg.float()?;
                    // |g| = 1 is a delta distribution, which HG sampling cannot represent.
                    if !(g > -1.0 && g < 1.0) {
                        return Err(arg.invalid("a number in (-1, 1)", quoted(arg.value()?)));
                    }
                    g
                }
            };
            PhaseDesc::HenyeyGreenstein { g }
        }
        _ => return Err(p.unsupported("volpt's phase functions are hg and isotropic")),
    };
    p.finish()?;
    Ok(phase)
}
