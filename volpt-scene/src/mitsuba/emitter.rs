//! Emitters: a single `<emitter type="constant">` environment, or none (black).

use super::plugin::{Ctx, Plugin};
use super::spectrum::rgb;
use super::xml::Element;
use crate::description::EnvironmentDesc;
use crate::error::SceneError;

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
                reason: "volpt lights the scene with one constant environment emitter".into(),
            })
        }
    };
    let p = Plugin::new(el, ctx);
    if p.kind()? != "constant" {
        return Err(p.unsupported(
            "volpt lights the scene with a constant environment: use type=\"constant\"",
        ));
    }
    let radiance = match p.find(&["radiance"])? {
        None => [1.0; 3],
        Some(arg) => {
            let v = rgb(&arg)?;
            if v.iter().any(|&c| c < 0.0) {
                return Err(arg.invalid("a radiance >= 0", format!("{v:?}")));
            }
            v
        }
    };
    // Only steers light sampling, which volpt does per its own strategy.
    p.ignore(&["samplingWeight", "sampling_weight"]);
    p.finish()?;
    Ok(EnvironmentDesc::Constant(radiance))
}
